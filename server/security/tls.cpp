#include "security/tls.h"

#include <openssl/err.h>

#include <fstream>
#include <sstream>
#include <stdexcept>

namespace k4reg::service {
namespace {

std::string read_pem(const std::string& flag, const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  if (in) text << in.rdbuf();
  if (!in || text.str().empty()) throw std::runtime_error(flag + " " + path + ": cannot read the file");
  return text.str();
}

// The reason of OpenSSL's most recent error ("no start line", "key values mismatch"), clearing its queue.
std::string openssl_reason() {
  const unsigned long code = ERR_peek_last_error();
  ERR_clear_error();
  const char* reason = code ? ERR_reason_error_string(code) : nullptr;
  return reason ? std::string(" (OpenSSL: ") + reason + ")" : "";
}

}  // namespace

std::optional<TlsConfig> load_tls(const ServerConfig& config) {
  if (config.tls_cert.empty()) return std::nullopt;
  TlsConfig tls{config.tls_cert, config.tls_key, config.tls_client_ca,
                read_pem("--tls-cert", config.tls_cert), read_pem("--tls-key", config.tls_key),
                config.tls_client_ca.empty() ? "" : read_pem("--tls-client-ca", config.tls_client_ca)};
  // A scratch context runs the same checks the HTTP listener's will, and gRPC gets only checked material.
  const std::unique_ptr<SSL_CTX, decltype(&SSL_CTX_free)> scratch(SSL_CTX_new(TLS_server_method()), SSL_CTX_free);
  if (!scratch) throw std::runtime_error("cannot create an OpenSSL context" + openssl_reason());
  configure_ssl_context(*scratch, tls);
  return tls;
}

void configure_ssl_context(SSL_CTX& context, const TlsConfig& tls) {
  SSL_CTX_set_min_proto_version(&context, TLS1_2_VERSION);
  SSL_CTX_set_options(&context, SSL_OP_NO_COMPRESSION | SSL_OP_NO_RENEGOTIATION);
  if (SSL_CTX_use_certificate_chain_file(&context, tls.cert_file.c_str()) != 1)
    throw std::runtime_error("--tls-cert " + tls.cert_file + ": not a PEM certificate (chain)" + openssl_reason());
  if (SSL_CTX_use_PrivateKey_file(&context, tls.key_file.c_str(), SSL_FILETYPE_PEM) != 1)
    throw std::runtime_error("--tls-key " + tls.key_file + ": not a PEM private key matching --tls-cert " +
                             tls.cert_file + openssl_reason());
  if (SSL_CTX_check_private_key(&context) != 1)
    throw std::runtime_error("--tls-key " + tls.key_file + " does not belong to the certificate of --tls-cert " +
                             tls.cert_file + openssl_reason());
  if (tls.client_ca_file.empty()) return;
  STACK_OF(X509_NAME)* names = SSL_load_client_CA_file(tls.client_ca_file.c_str());
  if (!names || SSL_CTX_load_verify_locations(&context, tls.client_ca_file.c_str(), nullptr) != 1) {
    if (names) sk_X509_NAME_pop_free(names, X509_NAME_free);
    throw std::runtime_error("--tls-client-ca " + tls.client_ca_file + ": no PEM CA certificate" + openssl_reason());
  }
  SSL_CTX_set_client_CA_list(&context, names);  // takes ownership; tells clients which certificate to send
  SSL_CTX_set_verify(&context, SSL_VERIFY_PEER | SSL_VERIFY_FAIL_IF_NO_PEER_CERT, nullptr);
}

std::shared_ptr<grpc::ServerCredentials> grpc_credentials(const std::optional<TlsConfig>& tls) {
  if (!tls) return grpc::InsecureServerCredentials();
  grpc::SslServerCredentialsOptions options(tls->client_ca_file.empty()
                                                ? GRPC_SSL_DONT_REQUEST_CLIENT_CERTIFICATE
                                                : GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY);
  options.pem_root_certs = tls->client_ca_pem;
  options.pem_key_cert_pairs.push_back({tls->key_pem, tls->cert_pem});
  return grpc::SslServerCredentials(options);
}

}  // namespace k4reg::service
