// What the service does with a decoded request before any job runs, checked for the fuzz targets of both
// front ends (gRPC bytes, HTTP JSON): parameters through params_from_proto (the one conversion both use), and
// inline clouds through read_cloud_bytes as the worker reads them. Path references are not resolved: that would
// touch the real filesystem (PathPolicy is covered by the integration tests).
#pragma once

#include <chrono>
#include <cmath>
#include <string>

#include "fuzz_checks.h"
#include "k4reg/io/cloud_io.h"
#include "k4reg/v1/registration.pb.h"
#include "api/proto_convert.h"

namespace k4reg::fuzz {

// Accepted parameters must be usable as they are: finite, in range (validate() agrees), the time budget a
// duration the core can turn into a deadline.
inline void check_params(const v1::RegistrationParams& message) {
  RegistrationParams params;
  try {
    params = service::params_from_proto(message);
  } catch (const Error& e) {
    check_error(e, "params.");
    return;
  }
  try {
    validate(params);
  } catch (const Error& e) {
    finding(std::string("params_from_proto accepted what validate() refuses: ") + e.what());
  }
  if (!std::isfinite(params.min_scale_m) || !std::isfinite(params.overlap) || !std::isfinite(params.min_contrast) ||
      !std::isfinite(params.plain_voxel_m) || !std::isfinite(params.time_budget_s))
    finding("accepted a non-finite parameter");
  // register_clouds turns the budget into a steady_clock deadline (64-bit nanoseconds): a larger value would
  // overflow in the conversion, which is undefined behaviour.
  if (std::chrono::duration<double>(params.time_budget_s) >= std::chrono::steady_clock::duration::max() / 2)
    finding("accepted a time budget that overflows a steady_clock deadline");
}

inline void check_inline_cloud(const v1::InlineCloud& cloud, const char* role) {
  const std::string name = cloud.file_name().empty() ? role : cloud.file_name();
  check_read(name, [&] { return read_cloud_bytes(cloud.data(), name); });
}

inline void check_register_request(const v1::RegisterRequest& request) {
  check_params(request.params());
  if (request.source().has_inline_cloud()) check_inline_cloud(request.source().inline_cloud(), "source");
  if (request.target().has_inline_cloud()) check_inline_cloud(request.target().inline_cloud(), "target");
}

}  // namespace k4reg::fuzz
