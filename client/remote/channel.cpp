#include "remote/channel.h"

#include <arpa/inet.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "commands/command_error.h"

namespace k4reg::cli {
namespace {

// Targets gRPC resolves by scheme; anything else is a host:port (or a list of them).
constexpr std::array kSchemes{"dns:", "ipv4:", "ipv6:", "unix:", "unix-abstract:", "vsock:", "xds:"};

bool has_scheme(const std::string& server) {
  for (const char* scheme : kSchemes)
    if (server.rfind(scheme, 0) == 0) return true;
  return false;
}

std::vector<std::string> split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::istringstream in(text);
  for (std::string part; std::getline(in, part, separator);) parts.push_back(part);
  return parts;
}

enum class HostKind { kName, kIpv4, kIpv6 };

// Checks "host:port" ("[v6]:port" for IPv6) and tells what the host is.
HostKind check_address(const std::string& address) {
  const auto colon = address.rfind(':');
  if (colon == std::string::npos || colon == 0) throw std::invalid_argument("'" + address + "' is not host:port");
  const std::string host = address.substr(0, colon), port = address.substr(colon + 1);
  if (port.empty() || port.size() > 5 || port.find_first_not_of("0123456789") != std::string::npos ||
      std::stoi(port) == 0 || std::stoi(port) > 65535)
    throw std::invalid_argument("'" + address + "': port must be 1-65535");
  unsigned char buffer[16];
  if (host.front() == '[' && host.back() == ']') {
    if (inet_pton(AF_INET6, host.substr(1, host.size() - 2).c_str(), buffer) != 1)
      throw std::invalid_argument("'" + address + "': not an IPv6 address");
    return HostKind::kIpv6;
  }
  if (host.find(':') != std::string::npos)
    throw std::invalid_argument("'" + address + "': write IPv6 addresses in brackets, [::1]:50051");
  return inet_pton(AF_INET, host.c_str(), buffer) == 1 ? HostKind::kIpv4 : HostKind::kName;
}

std::string read_pem(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  if (in) bytes << in.rdbuf();
  if (!in || bytes.str().empty()) throw CommandError("cannot read the CA certificate " + path);
  return bytes.str();
}

}  // namespace

void add_connection_flags(CLI::App& command, ConnectionOptions& options) {
  command
      .add_option("--server", options.server,
                  "HOST:PORT, a comma list IP:PORT,IP:PORT (round robin), or a gRPC target such as dns:///NAME:PORT")
      ->envname("K4REG_SERVER")
      ->required()
      ->check([](const std::string& server) {
        try {
          channel_target(server);
          return std::string();
        } catch (const std::invalid_argument& e) {
          return std::string(e.what());
        }
      });
  command.add_flag("--tls", options.tls, "connect with TLS (server certificate checked against the system's roots)")
      ->envname("K4REG_TLS");
  command.add_option("--ca-cert", options.ca_cert, "PEM file of the roots to trust instead; implies --tls")
      ->envname("K4REG_CA_CERT");
  command.add_option("--token", options.token, "bearer token for servers started with --auth-token")
      ->envname("K4REG_TOKEN");
}

std::string channel_target(const std::string& server) {
  if (server.empty()) throw std::invalid_argument("empty server address");
  if (has_scheme(server)) return server;
  const std::vector<std::string> addresses = split(server, ',');
  if (addresses.size() == 1) {
    check_address(server);
    return server;
  }
  HostKind family = HostKind::kName;
  for (const std::string& address : addresses) {
    const HostKind kind = check_address(address);
    if (kind == HostKind::kName)
      throw std::invalid_argument("'" + address +
                                  "': a list of servers takes IP addresses; for a name that resolves to several "
                                  "replicas use dns:///NAME:PORT");
    if (family != HostKind::kName && kind != family)
      throw std::invalid_argument("a list of servers takes either IPv4 or IPv6 addresses, not both");
    family = kind;
  }
  return (family == HostKind::kIpv4 ? "ipv4:" : "ipv6:") + server;
}

std::shared_ptr<grpc::Channel> make_channel(const ConnectionOptions& options) {
  grpc::ChannelArguments arguments;
  arguments.SetLoadBalancingPolicyName("round_robin");
  // A reply with a preview of the largest size (kMaxPreviewPoints, 32 MB, plus keypoints) must get through.
  arguments.SetMaxReceiveMessageSize(kMaxReplyBytes);
  std::shared_ptr<grpc::ChannelCredentials> credentials;
  if (options.tls || !options.ca_cert.empty()) {
    grpc::SslCredentialsOptions ssl;
    if (!options.ca_cert.empty()) ssl.pem_root_certs = read_pem(options.ca_cert);
    credentials = grpc::SslCredentials(ssl);
  } else {
    credentials = grpc::InsecureChannelCredentials();
  }
  return grpc::CreateCustomChannel(channel_target(options.server), credentials, arguments);
}

void add_call_metadata(grpc::ClientContext& context, const ConnectionOptions& options, const std::string& request_id) {
  // Plain metadata rather than call credentials: gRPC refuses call credentials on insecure channels, and a
  // loopback or in-cluster server may require a token without TLS.
  if (!options.token.empty()) context.AddMetadata("authorization", "Bearer " + options.token);
  if (!request_id.empty()) context.AddMetadata("x-request-id", request_id);
}

std::chrono::system_clock::time_point deadline_after(double seconds) {
  return std::chrono::system_clock::now() +
         std::chrono::duration_cast<std::chrono::system_clock::duration>(std::chrono::duration<double>(seconds));
}

std::string new_request_id() {
  std::random_device entropy;
  std::mt19937_64 random(static_cast<std::uint64_t>(entropy()) << 32 | entropy());
  std::uint64_t high = random(), low = random();
  high = (high & ~0xF000ULL) | 0x4000ULL;            // version 4
  low = (low & ~(0xC0ULL << 56)) | (0x80ULL << 56);  // variant 10
  char text[37];
  std::snprintf(text, sizeof text, "%08llx-%04llx-%04llx-%04llx-%012llx", static_cast<unsigned long long>(high >> 32),
                static_cast<unsigned long long>((high >> 16) & 0xFFFF), static_cast<unsigned long long>(high & 0xFFFF),
                static_cast<unsigned long long>(low >> 48), static_cast<unsigned long long>(low & 0xFFFFFFFFFFFFULL));
  return text;
}

}  // namespace k4reg::cli
