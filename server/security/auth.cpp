#include "security/auth.h"

#include <string_view>

namespace k4reg::service {
namespace {

// Compares in time independent of where the strings differ, so the token cannot be guessed byte by byte
// (only its length can be learnt).
bool equal_constant_time(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  unsigned char difference = 0;
  for (std::size_t i = 0; i < a.size(); ++i) difference |= static_cast<unsigned char>(a[i] ^ b[i]);
  return difference == 0;
}

}  // namespace

grpc::Status check_bearer_token(std::optional<std::string_view> authorization, const std::string& token) {
  if (token.empty()) return grpc::Status::OK;
  if (!authorization) return {grpc::StatusCode::UNAUTHENTICATED, "missing 'authorization: Bearer' metadata or header"};
  constexpr std::string_view kScheme = "Bearer ";
  if (authorization->substr(0, kScheme.size()) != kScheme ||
      !equal_constant_time(authorization->substr(kScheme.size()), token))
    return {grpc::StatusCode::UNAUTHENTICATED, "invalid bearer token"};
  return grpc::Status::OK;
}

grpc::Status check_bearer_token(const grpc::ServerContextBase& context, const std::string& token) {
  const auto& metadata = context.client_metadata();
  const auto it = metadata.find("authorization");
  if (it == metadata.end()) return check_bearer_token(std::nullopt, token);
  return check_bearer_token(std::string_view(it->second.data(), it->second.size()), token);
}

}  // namespace k4reg::service
