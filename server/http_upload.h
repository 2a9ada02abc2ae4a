// POST /v1/register as multipart/form-data, the HTTP way to send large clouds: the `source` and `target`
// parts are files, spooled to disk as they arrive (never held in memory), at most --max-upload-mb each; a
// part without a file name is a path under the data roots instead (as StreamCloud's oneof: path or upload).
// Every other part is a parameter named as in RegistrationParams (min_scale_m=0.05, overlap=0.8, seed=7,
// signal=KEYPOINT_SIGNAL_GEOMETRIC, icp=false, ...), converted through the protobuf JSON mapping.
#pragma once

#include <array>
#include <cstdint>
#include <memory>

#include "http_body.h"
#include "k4reg/v1/registration.pb.h"
#include "registration_job.h"
#include "service_context.h"
#include "spool.h"

namespace k4reg::service {

struct UploadForm {
  std::array<std::unique_ptr<SpoolFile>, 2> files;  // source, target; null for a path reference
  std::array<CloudSource, 2> clouds;                // source, target, as the worker reads them
  v1::RegistrationParams params;
};

// Longest parameter or path part.
inline constexpr std::size_t kMaxFormFieldBytes = 4096;

// Reads the whole form. Throws k4reg::Error: kInvalidArgument (a missing or repeated part, an unknown or
// malformed parameter), kResourceExhausted (a file over --max-upload-mb, a field over kMaxFormFieldBytes, a
// full disk), and the path errors of PathPolicy::resolve. Spool files are deleted with the form.
UploadForm read_upload_form(RequestBody& body, const ServiceContext& service);

}  // namespace k4reg::service
