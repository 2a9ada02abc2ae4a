// Optional shared-secret bearer token ("authorization: Bearer <token>" metadata). Only the Registration
// methods check it: the health service stays open so that probes (kubelet, load balancers) need no secret,
// and reflection reveals only the public API.
#pragma once

#include <grpcpp/server_context.h>

#include <string>

namespace k4reg::service {

// OK when no token is configured or the call carries it; UNAUTHENTICATED otherwise.
grpc::Status check_bearer_token(const grpc::ServerContextBase& context, const std::string& token);

}  // namespace k4reg::service
