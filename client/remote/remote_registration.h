// `k4reg register` on the wire: one RegisterStream call that uploads local files in chunks (or names files
// on the server), reports progress, and is retried with exponential backoff while the service is UNAVAILABLE.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "remote/channel.h"
#include "k4reg/v1/registration.grpc.pb.h"

namespace k4reg::cli {

struct RemoteRegistration {
  std::string source, target;  // local files to upload, or with by_reference paths under the server's data roots
  bool by_reference = false;
  v1::RegistrationParams params;
  std::uint32_t preview_points = 0;  // > 0: the response carries a preview of the registered clouds
};

struct CallPolicy {
  double deadline_s = 0;   // for the whole command, retries included; 0 = none
  int retries = 0;         // further attempts after UNAVAILABLE (server draining or not reachable)
  std::string request_id;  // x-request-id of every attempt: a retry is the same request in the server's log
};

// What a caller sees of a running call (the progress display).
class RegistrationObserver {
 public:
  virtual ~RegistrationObserver() = default;
  // Called with 0 bytes sent when an upload starts, then after every chunk.
  virtual void on_upload(std::uint64_t sent_bytes, std::uint64_t total_bytes) = 0;
  // QueuedEvent and StageEvent messages; the final result is returned instead.
  virtual void on_event(const v1::RegisterStreamResponse& event) = 0;
  // `code` is the status name of the attempt that failed; `attempt` the one about to start.
  virtual void on_retry(const std::string& code, double backoff_s, int attempt, int attempts) = 0;
};

// Throws CommandError for an unreadable local file and, after the retries, for the call's failure
// ("PERMISSION_DENIED: ...", "UNAVAILABLE: cannot reach ...").
v1::RegisterResponse register_remote(const std::shared_ptr<grpc::Channel>& channel, const ConnectionOptions& connection,
                                     const RemoteRegistration& job, const CallPolicy& policy,
                                     RegistrationObserver& observer);

}  // namespace k4reg::cli
