// Optional shared-secret bearer token ("authorization: Bearer <token>" gRPC metadata or HTTP header). The
// registration calls and, unless --public-metrics, HTTP /metrics and /v1/version check it: the health service
// stays open so that probes (kubelet, load balancers) need no secret; reflection is off unless --reflection.
#pragma once

#include <grpcpp/server_context.h>

#include <optional>
#include <string>
#include <string_view>

namespace k4reg::service {

// OK when no token is configured or `authorization` (the value of the gRPC metadata or HTTP header, nullopt
// when the call has none) carries it; UNAUTHENTICATED otherwise.
grpc::Status check_bearer_token(std::optional<std::string_view> authorization, const std::string& token);
grpc::Status check_bearer_token(const grpc::ServerContextBase& context, const std::string& token);

}  // namespace k4reg::service
