// Configuration through K4REG_* environment variables, the start-up log line, and TLS.
#include <gtest/gtest.h>

#include <cstdlib>

#include "test_support.h"

namespace k4reg::test {
namespace {

TEST(Config, EnvironmentVariablesConfigureTheServerAndTheTokenIsNeverLogged) {
  TempDir second_root;
  ServerProcess server({}, {{"K4REG_DATA_ROOT", bunny_dir().string() + ":" + second_root.path().string()},
                            {"K4REG_WORKERS", "3"},
                            {"K4REG_QUEUE_SIZE", "5"},
                            {"K4REG_MAX_POINTS", "123456"},
                            {"K4REG_MEMORY_BUDGET_MB", "777"},
                            {"K4REG_GRPC_RECEIVE_QUOTA_MB", "300"},
                            {"K4REG_MAX_PAIR_MB", "128"},  // the quota holds the largest message
                            {"K4REG_DRAIN_GRACE_S", "4.5"},
                            {"K4REG_AUTH_TOKEN", "hunter2-token"},
                            {"K4REG_MAX_UPLOAD_MB", "99"},
                            {"K4REG_LOG_LEVEL", "debug"},
                            {"K4REG_HTTP_LISTEN", "127.0.0.1:0"},
                            {"K4REG_SERVER_ID", "from-env"}});
  const auto lines = server.log_lines("starting");
  ASSERT_EQ(lines.size(), 1u);
  const nlohmann::json& config = lines[0]["config"];
  EXPECT_EQ(config["data_roots"].size(), 2u);
  EXPECT_EQ(config["workers"], 3);
  EXPECT_EQ(config["queue_size"], 5);
  EXPECT_EQ(config["max_points"], 123456);
  EXPECT_EQ(config["memory_budget_mb"], 777);
  EXPECT_EQ(config["grpc_receive_quota_mb"], 300);
  EXPECT_EQ(config["drain_grace_s"], 4.5);
  EXPECT_EQ(config["auth"], true);
  EXPECT_EQ(config["max_upload_mb"], 99);
  EXPECT_EQ(config["log_level"], "debug");
  EXPECT_EQ(config["server_id"], "from-env");
  EXPECT_EQ(server.log().find("hunter2-token"), std::string::npos);
  // Port 0 was bound to a real port, which the log names as well.
  EXPECT_EQ(server.log_lines("serving").at(0)["grpc_port"], server.port());
  EXPECT_EQ(server.log_lines("serving").at(0)["grpc_receive_quota_mb"], 300);
}

TEST(Config, TlsWithCertificateAndKey) {
  TempDir dir;
  const fs::path cert = dir.path() / "cert.pem", key = dir.path() / "key.pem";
  const std::string command = "openssl req -x509 -newkey rsa:2048 -nodes -days 1 -subj /CN=localhost "
                              "-addext subjectAltName=DNS:localhost,IP:127.0.0.1 -keyout " +
                              key.string() + " -out " + cert.string() + " 2>/dev/null";
  if (std::system(command.c_str()) != 0) GTEST_SKIP() << "openssl cannot make a test certificate";
  ServerProcess server({"--data-root", bunny_dir().string(), "--tls-cert", cert.string(), "--tls-key", key.string()});

  grpc::SslCredentialsOptions options;
  options.pem_root_certs = read_file(cert);
  auto stub = v1::Registration::NewStub(grpc::CreateChannel(server.address(), grpc::SslCredentials(options)));
  grpc::ClientContext context;
  set_timeout(context, std::chrono::seconds(60));
  v1::RegisterResponse reply;
  const grpc::Status status = stub->Register(&context, bunny_request(quick_params()), &reply);
  EXPECT_TRUE(status.ok()) << status.error_message();
  // Plaintext clients do not get through.
  grpc::ClientContext plain_context;
  set_timeout(plain_context, std::chrono::seconds(5));
  EXPECT_FALSE(server.stub()->Register(&plain_context, bunny_request(quick_params()), &reply).ok());
}

}  // namespace
}  // namespace k4reg::test
