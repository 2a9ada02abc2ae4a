// The one-line message of a failed call (status names come from proto/status_name.h).
#pragma once

#include <grpcpp/grpcpp.h>

#include <string>

#include "status_name.h"

namespace k4reg::cli {

using k4reg::status_code_name;

// "<CODE>: <message>". A call that failed because no connection could be made (UNAVAILABLE while the channel
// is not READY) reads "UNAVAILABLE: cannot reach <server> (<gRPC's reason>)": gRPC's own text names resolver
// and subchannel internals, not the address the user typed. UNAVAILABLE over a working connection is the
// server's own answer (e.g. draining) and keeps its message.
std::string describe_failure(const grpc::Status& status, grpc::Channel& channel, const std::string& server);

}  // namespace k4reg::cli
