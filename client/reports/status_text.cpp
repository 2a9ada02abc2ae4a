#include "reports/status_text.h"

namespace k4reg::cli {


std::string describe_failure(const grpc::Status& status, grpc::Channel& channel, const std::string& server) {
  std::string line = std::string(status_code_name(status.error_code())) + ": ";
  if (status.error_code() == grpc::StatusCode::UNAVAILABLE && channel.GetState(false) != GRPC_CHANNEL_READY)
    return line + "cannot reach " + server + " (" + status.error_message() + ")";
  return line + status.error_message();
}

}  // namespace k4reg::cli
