// A cloud's bytes as the worker reads them, once its job runs: a file mapped read-only (a data-root file opened
// where its path leads now, PathPolicy::open; a spool file) or the request's own inline bytes.
#pragma once

#include <cstddef>
#include <string_view>

#include "jobs/registration_job.h"

namespace k4reg::service {

class CloudBytes {
 public:
  // Throws k4reg::Error naming source.name (never a server path): the errors of PathPolicy::open, kNotFound for a
  // spool file gone, kInvalidArgument for one that is no regular file.
  explicit CloudBytes(const CloudSource& source);
  ~CloudBytes();
  CloudBytes(const CloudBytes&) = delete;
  CloudBytes& operator=(const CloudBytes&) = delete;
  CloudBytes(CloudBytes&& other) noexcept;
  CloudBytes& operator=(CloudBytes&&) = delete;

  std::string_view bytes() const { return bytes_; }

 private:
  void* mapping_ = nullptr;  // null: `bytes_` are the request's
  std::string_view bytes_;
};

}  // namespace k4reg::service
