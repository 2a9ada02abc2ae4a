// A failure the user can act on, reported by main() as one line "k4reg: <message>" on stderr with exit code 1.
// Remote failures start the message with the gRPC status name (UNAVAILABLE, PERMISSION_DENIED, ...) so
// scripts can match it; local ones name the file.
#pragma once

#include <stdexcept>

namespace k4reg::cli {

class CommandError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace k4reg::cli
