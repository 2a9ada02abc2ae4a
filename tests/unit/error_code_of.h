// The ErrorCode a call throws, for tests of typed errors (a test failure when it throws none).
#pragma once

#include <gtest/gtest.h>

#include <functional>

#include "k4reg/util/error.h"

namespace k4reg::test {

inline ErrorCode error_code_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.code();
  }
  ADD_FAILURE() << "expected a k4reg::Error";
  return ErrorCode::kInternal;
}

}  // namespace k4reg::test
