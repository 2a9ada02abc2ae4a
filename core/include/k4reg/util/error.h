// Typed errors of the registration library. The server maps ErrorCode once to gRPC/HTTP codes;
// core code throws k4reg::Error and never returns sentinel values for bad input.
#pragma once

#include <stdexcept>
#include <string>

namespace k4reg {

enum class ErrorCode {
  kInvalidArgument,     // malformed file, bad parameter, NaN coordinates, empty cloud
  kNotFound,            // a referenced file does not exist
  kPermissionDenied,    // a path outside the allowed roots
  kResourceExhausted,   // over a point / byte / memory budget
  kFailedPrecondition,  // valid input, but no alignment could be found
  kDataLoss,            // checksum or page CRC mismatch in a file
  kCancelled,           // the caller's cancellation token fired
  kDeadlineExceeded,    // the time budget ran out
  kInternal,            // a bug: never for user input
};

const char* to_string(ErrorCode code);

class Error : public std::runtime_error {
 public:
  Error(ErrorCode code, const std::string& message) : std::runtime_error(message), code_(code) {}
  ErrorCode code() const { return code_; }

 private:
  ErrorCode code_;
};

[[noreturn]] inline void fail(ErrorCode code, const std::string& message) { throw Error(code, message); }

}  // namespace k4reg
