// gRPC status codes as the names scripts and people know (OK, RESOURCE_EXHAUSTED, ...), and the one-line
// message of a failed call.
#pragma once

#include <grpcpp/grpcpp.h>

#include <string>

namespace k4reg::cli {

const char* status_code_name(grpc::StatusCode code);

// "<CODE>: <message>". A call that failed because no connection could be made (UNAVAILABLE while the channel
// is not READY) reads "UNAVAILABLE: cannot reach <server> (<gRPC's reason>)": gRPC's own text names resolver
// and subchannel internals, not the address the user typed. UNAVAILABLE over a working connection is the
// server's own answer (e.g. draining) and keeps its message.
std::string describe_failure(const grpc::Status& status, grpc::Channel& channel, const std::string& server);

}  // namespace k4reg::cli
