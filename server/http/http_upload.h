// POST /v1/register and /v1/register-project as multipart/form-data, the HTTP way to send large clouds. The
// cloud parts are files, spooled to disk as they arrive (never held in memory), at most --max-upload-mb each; a
// part without a file name is a path under the data roots instead (as StreamCloud's oneof: path or upload).
//   pair:    parts `source` and `target`, once each;
//   project: one part `scans` per scan, in order (at least 2).
// Every other part is a parameter: `preview_points` (as the request's field), for a project `reference` and
// `pairs` (all, sequence), and otherwise a RegistrationParams field by name (min_scale_m=0.05, overlap=0.8,
// seed=7, signal=KEYPOINT_SIGNAL_GEOMETRIC, icp=false, ...), converted through the protobuf JSON mapping.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "http/http_body.h"
#include "k4reg/v1/registration.pb.h"
#include "jobs/registration_job.h"
#include "service_context.h"
#include "jobs/spool.h"

namespace k4reg::service {

enum class FormKind { kPair, kProject };

struct UploadForm {
  std::vector<std::unique_ptr<SpoolFile>> files;  // one per cloud; null for a path reference
  std::vector<CloudSource> clouds;                // pair: source, target; project: the scans in order
  v1::ProjectParams params;                       // pair: only `pairwise` is set
  std::uint32_t preview_points = 0;
};

// Longest parameter or path part.
inline constexpr std::size_t kMaxFormFieldBytes = 4096;
// Parts of one form: a project's scans (each a file or a path) and the parameters, with room to spare.
inline constexpr std::size_t kMaxFormParts = 256;

// Reads the whole form. Throws k4reg::Error: kInvalidArgument (a missing or repeated part, an unknown or
// malformed parameter), kResourceExhausted (a file over --max-upload-mb, a field over kMaxFormFieldBytes, more
// than kMaxFormParts parts, a full disk), and the path errors of PathPolicy::resolve. Spool files are deleted with the form.
UploadForm read_upload_form(RequestBody& body, const ServiceContext& service, FormKind kind);

}  // namespace k4reg::service
