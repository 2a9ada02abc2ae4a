// --tls-cert, --tls-key and --tls-client-ca: read and checked once at start-up, then used by every listener that
// carries data or secrets (gRPC and HTTP), so both present the same certificate and verify clients alike.
#pragma once

#include <grpcpp/security/server_credentials.h>
#include <openssl/ssl.h>

#include <memory>
#include <optional>
#include <string>

#include "server_config.h"

namespace k4reg::service {

struct TlsConfig {
  std::string cert_file, key_file, client_ca_file;  // client_ca_file "" = no client certificates asked for
  std::string cert_pem, key_pem, client_ca_pem;     // the files' contents (gRPC takes PEM text)
};

// nullopt without --tls-cert. Throws std::runtime_error naming the flag and file when a file is unreadable, is
// not PEM, or the key does not belong to the certificate: the server refuses to start rather than fail on the
// first handshake.
std::optional<TlsConfig> load_tls(const ServerConfig& config);

// An OpenSSL server context with the certificate chain and key, TLS 1.2 or newer, and with a client CA: a
// client certificate required and verified against it. Throws std::runtime_error (load_tls already checked).
void configure_ssl_context(SSL_CTX& context, const TlsConfig& tls);

// Insecure without TLS; otherwise the same material and client verification as configure_ssl_context.
std::shared_ptr<grpc::ServerCredentials> grpc_credentials(const std::optional<TlsConfig>& tls);

}  // namespace k4reg::service
