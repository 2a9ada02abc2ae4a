// TLS on both API listeners (--tls-cert, --tls-key, --tls-client-ca), the plaintext health-only listener
// (--health-listen) and `k4reg health` following K4REG_SERVER / K4REG_TLS / K4REG_CA_CERT / K4REG_HEALTH_LISTEN.
// Certificates are made at test time with Debian's openssl (EC P-256: milliseconds each).
#include <gtest/gtest.h>

#include "grpc/health/v1/health.grpc.pb.h"
#include "test_support.h"

namespace k4reg::test {
namespace {

// A test CA with a server certificate (localhost, 127.0.0.1) and a client certificate it signed, and a
// client certificate of another CA.
struct Certificates {
  TempDir dir;
  fs::path ca, server_cert, server_key, client_cert, client_key, stranger_cert, stranger_key;
  fs::path replica_cert, replica_key;  // server and client: replicas that send each other pair jobs
};

void openssl(const std::vector<std::string>& arguments) {
  std::vector<std::string> command{"/usr/bin/openssl"};
  command.insert(command.end(), arguments.begin(), arguments.end());
  const CommandRun run = run_command(command);
  ASSERT_EQ(run.exit_code, 0) << run.err;
}

// A self-signed CA certificate `name`.pem with its key `name`.key.
void make_ca(const fs::path& dir, const std::string& name) {
  openssl({"req", "-x509", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1", "-nodes", "-days", "1",
           "-subj", "/CN=k4reg test " + name, "-keyout", (dir / (name + ".key")).string(), "-out",
           (dir / (name + ".pem")).string()});
}

// A leaf certificate `name`.pem (key `name`.key) signed by the CA `ca`.
void make_leaf(const fs::path& dir, const std::string& name, const std::string& ca, const std::string& extensions) {
  const fs::path request = dir / (name + ".csr"), extension_file = dir / (name + ".ext");
  write_file(extension_file, extensions + "\n");
  openssl({"req", "-new", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1", "-nodes", "-subj",
           "/CN=" + name, "-keyout", (dir / (name + ".key")).string(), "-out", request.string()});
  openssl({"x509", "-req", "-in", request.string(), "-CA", (dir / (ca + ".pem")).string(), "-CAkey",
           (dir / (ca + ".key")).string(), "-CAcreateserial", "-days", "1", "-extfile", extension_file.string(),
           "-out", (dir / (name + ".pem")).string()});
}

std::unique_ptr<Certificates> make_certificates() {
  auto c = std::make_unique<Certificates>();
  {
    const fs::path& d = c->dir.path();
    make_ca(d, "ca");
    make_ca(d, "stranger-ca");
    make_leaf(d, "server", "ca", "subjectAltName=DNS:localhost,IP:127.0.0.1\nextendedKeyUsage=serverAuth");
    make_leaf(d, "client", "ca", "extendedKeyUsage=clientAuth");
    make_leaf(d, "replica", "ca", "subjectAltName=DNS:localhost,IP:127.0.0.1\nextendedKeyUsage=serverAuth,clientAuth");
    make_leaf(d, "stranger", "stranger-ca", "extendedKeyUsage=clientAuth");
    c->ca = d / "ca.pem";
    c->server_cert = d / "server.pem", c->server_key = d / "server.key";
    c->client_cert = d / "client.pem", c->client_key = d / "client.key";
    c->stranger_cert = d / "stranger.pem", c->stranger_key = d / "stranger.key";
    c->replica_cert = d / "replica.pem", c->replica_key = d / "replica.key";
  }
  return c;
}

std::vector<std::string> tls_flags(const Certificates& c, bool mutual = false) {
  std::vector<std::string> flags{"--tls-cert", c.server_cert.string(), "--tls-key", c.server_key.string(),
                                 "--data-root", bunny_dir().string()};
  if (mutual) flags.insert(flags.end(), {"--tls-client-ca", c.ca.string()});
  return flags;
}

// A TLS channel trusting the test CA, with an optional client certificate; the certificate names localhost.
std::shared_ptr<grpc::Channel> tls_channel(const ServerProcess& server, const Certificates& c,
                                           const fs::path& cert = {}, const fs::path& key = {}) {
  grpc::SslCredentialsOptions options;
  options.pem_root_certs = read_file(c.ca);
  if (!cert.empty()) options.pem_cert_chain = read_file(cert), options.pem_private_key = read_file(key);
  grpc::ChannelArguments arguments;
  arguments.SetSslTargetNameOverride("localhost");
  return grpc::CreateCustomChannel(server.address(), grpc::SslCredentials(options), arguments);
}

grpc::Status check_health(const std::shared_ptr<grpc::Channel>& channel, const std::string& service = "liveness") {
  auto stub = grpc::health::v1::Health::NewStub(channel);
  grpc::ClientContext context;
  set_timeout(context, std::chrono::seconds(5));
  grpc::health::v1::HealthCheckRequest request;
  request.set_service(service);
  grpc::health::v1::HealthCheckResponse reply;
  return stub->Check(&context, request, &reply);
}

std::string https_url(const ServerProcess& server, const std::string& path) {
  return "https://127.0.0.1:" + std::to_string(server.http_port()) + path;
}

// curl's arguments for a multipart registration uploading the bunny pair.
std::vector<std::string> upload_form() {
  return {"-F", "source=@" + (bunny_dir() / "bun045.ply").string(), "-F",
          "target=@" + (bunny_dir() / "bun000.ply").string(), "-F", "min_scale_m=0.001", "-F", "overlap=0.9"};
}

int health_port(const ServerProcess& server) { return server.log_lines("serving").at(0)["health_port"].get<int>(); }

TEST(ServiceTls, HttpsRegistersAndPlaintextIsRefusedOnBothListeners) {
  const auto c = make_certificates();
  ServerProcess server(tls_flags(*c));
  std::vector<std::string> https{"--cacert", c->ca.string()};
  const std::vector<std::string> form = upload_form();
  https.insert(https.end(), form.begin(), form.end());
  https.push_back(https_url(server, "/v1/register"));
  const HttpReply reply = curl(https);
  ASSERT_EQ(reply.status, 200) << reply.body;
  EXPECT_EQ(reply.json()["result"]["transform"].size(), 16u) << reply.body;
  // Plain HTTP to the HTTPS port gets no answer; an untrusted certificate is refused by the client.
  EXPECT_THROW(curl({"http://127.0.0.1:" + std::to_string(server.http_port()) + "/healthz"}), std::runtime_error);
  EXPECT_THROW(curl({https_url(server, "/healthz")}), std::runtime_error);

  EXPECT_TRUE(check_health(tls_channel(server, *c)).ok());
  auto stub = v1::Registration::NewStub(tls_channel(server, *c));
  v1::RegisterResponse registered;
  const auto context = context_with_deadline();
  ASSERT_TRUE(stub->Register(context.get(), bunny_request(bunny_params()), &registered).ok());
  EXPECT_EQ(check_health(server.channel()).error_code(), grpc::StatusCode::UNAVAILABLE);
}

TEST(ServiceTls, MutualTlsRefusesClientsWithoutAValidCertificate) {
  const auto certificates = make_certificates();
  const Certificates& c = *certificates;
  ServerProcess server(tls_flags(c, /*mutual=*/true));
  EXPECT_TRUE(check_health(tls_channel(server, c, c.client_cert, c.client_key)).ok());
  EXPECT_EQ(check_health(tls_channel(server, c)).error_code(), grpc::StatusCode::UNAVAILABLE);
  EXPECT_EQ(check_health(tls_channel(server, c, c.stranger_cert, c.stranger_key)).error_code(),
            grpc::StatusCode::UNAVAILABLE);

  const std::vector<std::string> trust{"--cacert", c.ca.string()};
  auto with = [&](std::vector<std::string> extra) {
    extra.insert(extra.begin(), trust.begin(), trust.end());
    return extra;
  };
  EXPECT_EQ(curl(with({"--cert", c.client_cert.string(), "--key", c.client_key.string(), https_url(server, "/v1/version")}))
                .status,
            200);
  EXPECT_THROW(curl(with({https_url(server, "/v1/version")})), std::runtime_error);
  EXPECT_THROW(curl(with({"--cert", c.stranger_cert.string(), "--key", c.stranger_key.string(),
                          https_url(server, "/v1/version")})),
               std::runtime_error);
}

TEST(ServiceTls, RefusesToStartWithABadKeyOrCertificate) {
  const auto certificates = make_certificates();
  const Certificates& c = *certificates;
  TempDir dir;
  const fs::path garbage = dir.path() / "garbage.pem";
  write_file(garbage, "not PEM\n");
  const struct {
    fs::path cert, key;
    std::string message;
  } cases[] = {{c.server_cert, c.client_key, "--tls-key " + c.client_key.string()},
               {c.server_cert, garbage, "--tls-key " + garbage.string()},
               {garbage, c.server_key, "--tls-cert " + garbage.string() + ": not a PEM certificate"}};
  for (const auto& bad : cases) {
    const CommandRun run = run_command({K4REG_BIN_DIR "/k4reg-server", "--grpc-listen", "127.0.0.1:0", "--http-listen",
                                        "127.0.0.1:0", "--tls-cert", bad.cert.string(), "--tls-key", bad.key.string()});
    EXPECT_EQ(run.exit_code, 1) << run.err;
    EXPECT_NE(run.err.find(bad.message), std::string::npos) << run.err;
    EXPECT_EQ(run.err.find("\"serving\""), std::string::npos) << run.err;
  }
}

TEST(ServiceTls, ReplicasSendPairJobsToEachOtherOverMutualTls) {
  const auto certificates = make_certificates();
  const Certificates& c = *certificates;
  const std::vector<std::string> replica{"--tls-cert", c.replica_cert.string(), "--tls-key", c.replica_key.string(),
                                         "--tls-client-ca", c.ca.string(), "--data-root", bunny_dir().string()};
  ServerProcess peer(replica);
  std::vector<std::string> coordinator = replica;
  coordinator.insert(coordinator.end(), {"--peers", "ipv4:" + peer.address()});
  ServerProcess server(coordinator);
  v1::RegisterProjectRequest request;
  for (const char* scan : {"bun000.ply", "bun045.ply", "bun090.ply"}) request.add_scans()->set_path(scan);
  request.mutable_params()->mutable_pairwise()->set_min_scale_m(0.002);
  request.mutable_params()->mutable_pairwise()->set_overlap(0.5);
  auto stub = v1::Registration::NewStub(tls_channel(server, c, c.client_cert, c.client_key));
  grpc::ClientContext context;
  auto reader = stub->RegisterProject(&context, request);
  v1::RegisterProjectResponse response;
  for (v1::RegisterProjectEvent event; reader->Read(&event);)
    if (event.has_result()) response = event.result();
  const grpc::Status status = reader->Finish();
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(response.pairs_on_peers(), 3u) << "the peer took the coordinator's certificate";
  EXPECT_EQ(response.pairs_local(), 0u);
}

TEST(HealthListener, AnswersHealthOnlyAndInPlaintextWithTlsOn) {
  const auto certificates = make_certificates();
  ServerProcess server(
      [&] {
        std::vector<std::string> flags = tls_flags(*certificates, /*mutual=*/true);
        flags.insert(flags.end(), {"--health-listen", "127.0.0.1:0"});
        return flags;
      }());
  const std::string address = "127.0.0.1:" + std::to_string(health_port(server));
  const auto channel = grpc::CreateChannel(address, grpc::InsecureChannelCredentials());
  for (const char* service : {"liveness", "readiness"}) EXPECT_TRUE(check_health(channel, service).ok()) << service;
  auto stub = v1::Registration::NewStub(channel);
  v1::RegisterResponse reply;
  const auto context = context_with_deadline();
  EXPECT_EQ(stub->Register(context.get(), bunny_request(bunny_params()), &reply).error_code(),
            grpc::StatusCode::UNIMPLEMENTED);

  const std::string url = "http://" + address;
  EXPECT_EQ(curl({url + "/healthz"}).json()["status"], "SERVING");
  EXPECT_EQ(curl({url + "/readyz"}).status, 200);
  EXPECT_EQ(curl({"-I", url + "/healthz"}).status, 200);
  for (const char* path : {"/metrics", "/v1/version", "/openapi.json"}) EXPECT_EQ(curl({url + path}).status, 404) << path;
  std::vector<std::string> upload = upload_form();
  upload.push_back(url + "/v1/register");
  EXPECT_EQ(curl(upload).status, 404);
}

TEST(HealthCommand, FollowsTheEnvironment) {
  const auto certificates = make_certificates();
  const Certificates& c = *certificates;
  ServerProcess server([&] {
    std::vector<std::string> flags = tls_flags(c);
    flags.insert(flags.end(), {"--health-listen", "127.0.0.1:0"});
    return flags;
  }());
  const std::string k4reg = K4REG_BIN_DIR "/k4reg";
  const std::string tls_server = "localhost:" + std::to_string(server.port());
  const struct {
    std::map<std::string, std::string> env;
    int exit_code;
    std::string out;
  } cases[] = {
      {{{"K4REG_SERVER", tls_server}, {"K4REG_CA_CERT", c.ca.string()}}, 0, "readiness: SERVING"},
      {{{"K4REG_SERVER", tls_server}, {"K4REG_TLS", "1"}, {"K4REG_CA_CERT", c.ca.string()}}, 0, "readiness: SERVING"},
      {{{"K4REG_SERVER", server.address()}}, 1, ""},  // plaintext to the TLS port
      // What the image's HEALTHCHECK relies on: the health listener, plaintext whatever K4REG_TLS says.
      {{{"K4REG_HEALTH_LISTEN", "0.0.0.0:" + std::to_string(health_port(server))}, {"K4REG_TLS", "1"}}, 0,
       "liveness: SERVING"},
      {{}, 1, ""},
  };
  for (const auto& run_case : cases) {
    const CommandRun run = run_command({k4reg, "health"}, run_case.env);
    EXPECT_EQ(run.exit_code, run_case.exit_code) << run.out << run.err;
    EXPECT_NE(run.out.find(run_case.out), std::string::npos) << run.out << run.err;
  }
  EXPECT_NE(run_command({k4reg, "health"}).err.find("K4REG_HEALTH_LISTEN"), std::string::npos);
}

}  // namespace
}  // namespace k4reg::test
