// The k4reg command line's remote commands (register, health, load), run as the real binary against the real
// server on loopback: what a user or a script sees on stdout, stderr and in the exit code.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdlib>
#include <sstream>
#include <thread>

#include "k4reg/io/cloud_io.h"
#include "k4reg/io/e57_io.h"
#include "test_support.h"

extern char** environ;

namespace k4reg::test {
namespace {

// Runs build/bin/k4reg with `args` (see run_command).
CommandRun k4reg(const std::vector<std::string>& args, const std::map<std::string, std::string>& env = {}) {
  std::vector<std::string> arguments{K4REG_BIN_DIR "/k4reg"};
  arguments.insert(arguments.end(), args.begin(), args.end());
  return run_command(std::move(arguments), env);
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> result;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) result.push_back(line);
  return result;
}

// A loopback port nobody listens on: bound and released again.
int dead_port() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address);
  socklen_t size = sizeof address;
  getsockname(fd, reinterpret_cast<sockaddr*>(&address), &size);
  close(fd);
  return ntohs(address.sin_port);
}

std::string bunny(const std::string& name) { return (bunny_dir() / name).string(); }

// The bunny pair's parameters (test_support's bunny_params) as flags, with a seed other than the default.
const std::vector<std::string> kBunnyFlags{"--min-scale", "0.001", "--overlap", "0.9", "--seed", "7"};
// A quick job (test_support's quick_params) for load and error tests.
const std::vector<std::string> kQuickFlags{"--min-scale", "0.004", "--overlap", "0.9"};

std::vector<std::string> concat(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

class ClientCommands : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    server_ = new ServerProcess({"--data-root", bunny_dir().string(), "--workers", "2", "--server-id", "client-test"});
    // The local reference: what `k4reg align` computes in-process with the same flags.
    const CommandRun align = k4reg(concat({"align", bunny("bun045.ply"), bunny("bun000.ply"), "--json"}, kBunnyFlags));
    ASSERT_EQ(align.exit_code, 0) << align.err;
    local_ = new nlohmann::json(nlohmann::json::parse(align.out));
  }
  static void TearDownTestSuite() {
    delete server_;
    delete local_;
  }

  static ServerProcess* server_;
  static nlohmann::json* local_;
};

ServerProcess* ClientCommands::server_ = nullptr;
nlohmann::json* ClientCommands::local_ = nullptr;

TEST_F(ClientCommands, RegisterByUploadGivesAlignsTransformAndJsonLayout) {
  TempDir dir;
  const fs::path out = dir.path() / "T.txt", local_out = dir.path() / "local.txt";
  const CommandRun run =
      k4reg(concat({"register", bunny("bun045.ply"), bunny("bun000.ply"), "--server", server_->address(), "--json",
                    "--out", out.string(), "--request-id", "client-test-42"},
                   kBunnyFlags));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json remote = nlohmann::json::parse(run.out);
  EXPECT_EQ(remote["transform"], (*local_)["transform"]);  // bit-identical: JSON keeps every digit
  for (const auto& [key, value] : local_->items()) EXPECT_TRUE(remote.contains(key)) << key;
  for (const char* key : {"ambiguous", "well_supported", "free_space_used", "min_scale_m_used", "overlap_used"})
    EXPECT_EQ(remote[key], (*local_)[key]) << key;
  EXPECT_EQ(remote["request_id"], "client-test-42");
  EXPECT_EQ(remote["server"]["server_id"], "client-test");
  EXPECT_GT(remote["server_timings"]["upload_s"].get<double>(), 0.0);
  EXPECT_GT(remote["server_timings"]["registration_s"].get<double>(), 0.0);
  const auto requests = server_->log_lines("request");
  EXPECT_TRUE(std::any_of(requests.begin(), requests.end(),
                          [](const nlohmann::json& line) { return line.value("request_id", "") == "client-test-42"; }));

  // --out writes the same file as align's --out.
  const CommandRun align =
      k4reg(concat({"align", bunny("bun045.ply"), bunny("bun000.ply"), "--out", local_out.string()}, kBunnyFlags));
  ASSERT_EQ(align.exit_code, 0) << align.err;
  EXPECT_EQ(read_file(out), read_file(local_out));

  // stderr is not a terminal: plain event lines, no bar.
  EXPECT_NE(run.err.find("uploaded 964.6 kB in "), std::string::npos) << run.err;  // both files
  EXPECT_NE(run.err.find("queued at position"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("icp finished at"), std::string::npos) << run.err;
  EXPECT_EQ(run.err.find('\r'), std::string::npos);
}

TEST_F(ClientCommands, RegisterByReferencePrintsTheTable) {
  const CommandRun run =
      k4reg(concat({"register", "bun045.ply", "bun000.ply", "--ref", "--server", server_->address()}, kBunnyFlags));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::vector<std::string> out = lines(run.out);
  ASSERT_GE(out.size(), 5u);
  EXPECT_EQ(out[0], "transform (source -> target):");
  // The matrix rows are align's, digit for digit.
  const CommandRun align = k4reg(concat({"align", bunny("bun045.ply"), bunny("bun000.ply")}, kBunnyFlags));
  ASSERT_EQ(align.exit_code, 0);
  const std::vector<std::string> local = lines(align.out);
  for (int row = 1; row <= 4; ++row) EXPECT_EQ(out[row], local[row]);
  EXPECT_NE(run.out.find("client-test"), std::string::npos);
  EXPECT_NE(run.out.find("request id"), std::string::npos);
  EXPECT_EQ(run.err.find("uploaded"), std::string::npos);  // nothing to upload
}

// The document a --report page carries (web/report_document.h).
nlohmann::json report_document(const fs::path& page_file) {
  const std::string page = read_file(page_file);
  const std::string open = "<script id=\"k4reg-document\" type=\"application/json\">";
  const std::size_t begin = page.find(open);
  if (begin == std::string::npos) return nullptr;
  std::string json = page.substr(begin + open.size(), page.find("</script>", begin) - begin - open.size());
  for (std::size_t at = json.find("<\\/"); at != std::string::npos; at = json.find("<\\/", at)) json.erase(at + 1, 1);
  return nlohmann::json::parse(json);
}

TEST_F(ClientCommands, RegisterWritesAlignsReportWithTheServersPreview) {
  TempDir work;
  const CommandRun local = k4reg(concat({"align", bunny("bun045.ply"), bunny("bun000.ply"), "--report",
                                         (work.path() / "local.html").string(), "--report-points", "4000"},
                                        kBunnyFlags));
  ASSERT_EQ(local.exit_code, 0) << local.err;
  const CommandRun remote =
      k4reg(concat({"register", "bun045.ply", "bun000.ply", "--ref", "--server", server_->address(), "--report",
                    (work.path() / "remote.html").string(), "--report-points", "4000"},
                   kBunnyFlags));
  ASSERT_EQ(remote.exit_code, 0) << remote.err;
  const nlohmann::json a = report_document(work.path() / "local.html"), b = report_document(work.path() / "remote.html");
  ASSERT_TRUE(a.is_object() && b.is_object());
  EXPECT_EQ(a["kind"], "pair");
  EXPECT_EQ(b["generator"], "k4reg register");
  EXPECT_EQ(a["result"]["transform"], b["result"]["transform"]);
  EXPECT_EQ(a["result"]["hypotheses"][0]["base_source_m"], b["result"]["hypotheses"][0]["base_source_m"]);
  EXPECT_EQ(a["result"]["hypotheses"][0]["base_source_m"].size(), 12u);
  // The server's preview is the local one, byte for byte (the same subsample of the same clouds).
  ASSERT_EQ(b["preview"]["clouds"].size(), 2u);
  EXPECT_EQ(a["preview"], b["preview"]);
  EXPECT_EQ(b["result"]["request_id"].get<std::string>().size(), 36u);

  const CommandRun project = k4reg({"register-project", "bun000.ply", "bun045.ply", "bun090.ply", "--ref", "--server",
                                    server_->address(), "--min-scale", "0.002", "--overlap", "0.5", "--report",
                                    (work.path() / "project.html").string(), "--report-points", "3000"});
  ASSERT_EQ(project.exit_code, 0) << project.err;
  const nlohmann::json c = report_document(work.path() / "project.html");
  EXPECT_EQ(c["kind"], "project");
  EXPECT_EQ(c["result"]["scans"].size(), 3u);
  EXPECT_EQ(c["preview"]["clouds"].size(), 3u);
  EXPECT_EQ(c["files"][1], "bun045.ply");
  // A report that cannot be written fails the command, and says where.
  const CommandRun unwritable = k4reg(concat({"align", bunny("bun045.ply"), bunny("bun000.ply"), "--report",
                                              "/nonexistent-folder/r.html"},
                                             kQuickFlags));
  EXPECT_EQ(unwritable.exit_code, 1);
  EXPECT_NE(unwritable.err.find("/nonexistent-folder/r.html"), std::string::npos) << unwritable.err;
}

TEST_F(ClientCommands, ProgressFlagDrawsTheBarWithoutATerminal) {
  const CommandRun run = k4reg(concat(
      {"register", bunny("bun045.ply"), bunny("bun000.ply"), "--server", server_->address(), "--progress", "--json"},
      kQuickFlags));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("\r\x1b[Kupload"), std::string::npos);
  EXPECT_NE(run.err.find("MB/s"), std::string::npos);
  EXPECT_NE(run.err.find("\r\x1b[Kicp"), std::string::npos);
  EXPECT_EQ(run.err.back(), '\n');  // the bar's line is ended
}

TEST_F(ClientCommands, HealthIsZeroOnALiveServerAndOneOnADeadPort) {
  const CommandRun live = k4reg({"health", "--server", server_->address()});
  EXPECT_EQ(live.exit_code, 0) << live.err;
  EXPECT_EQ(live.out, "liveness: SERVING\nreadiness: SERVING\n");

  const CommandRun one = k4reg({"health", "--server", server_->address(), "--service", "readiness"});
  EXPECT_EQ(one.exit_code, 0);
  EXPECT_EQ(one.out, "readiness: SERVING\n");

  const std::string dead = "127.0.0.1:" + std::to_string(dead_port());
  const CommandRun down = k4reg({"health", "--server", dead});
  EXPECT_EQ(down.exit_code, 1);
  ASSERT_EQ(lines(down.err).size(), 1u) << down.err;
  EXPECT_EQ(down.err.rfind("k4reg: UNAVAILABLE: cannot reach " + dead + " (", 0), 0u) << down.err;
}

// While the server drains: health says not ready (exit 1), and a call gets the server's own UNAVAILABLE reason,
// not "cannot reach" (the connection works).
TEST_F(ClientCommands, DrainingServerIsNotReadyAndSaysWhy) {
  // A job long enough to hold the server in its drain while health is asked.
  ServerProcess server({"--data-root", bunny_dir().string(), "--workers", "1", "--drain-grace-s", "30"});
  auto stub = server.stub();
  grpc::ClientContext context;
  set_timeout(context, std::chrono::seconds(60));
  StreamCall call(*stub, context,
                  [] {
                    v1::UploadHeader header;
                    header.mutable_source()->set_path("bun045.ply");
                    header.mutable_target()->set_path("bun000.ply");
                    *header.mutable_params() = slow_params(4);
                    return header;
                  }(),
                  {});
  ASSERT_TRUE(call.wait_for_stage("load", v1::StageEvent::PHASE_STARTED));
  server.signal(SIGTERM);
  for (int i = 0; i < 200 && health_status(server, "readiness") == "SERVING"; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  const CommandRun draining = k4reg({"health", "--server", server.address()});
  EXPECT_EQ(draining.exit_code, 1) << draining.err;
  EXPECT_EQ(draining.out, "liveness: SERVING\nreadiness: NOT_SERVING\n");
  EXPECT_EQ(draining.err, "");
  const CommandRun refused =
      k4reg({"register", "bun045.ply", "bun000.ply", "--ref", "--server", server.address(), "--retries", "0"});
  EXPECT_EQ(refused.exit_code, 1);
  EXPECT_EQ(refused.err.rfind("k4reg: UNAVAILABLE: ", 0), 0u) << refused.err;
  EXPECT_EQ(refused.err.find("cannot reach"), std::string::npos) << refused.err;
  context.TryCancel();
  call.finish();
}

TEST_F(ClientCommands, AlignPicksScansOfAMultiScanFileByNameOrIndex) {
  // Both bunny scans in one E57 (as a project export holds its stations): the same result as the two files.
  const TempDir dir;
  const std::string project = (dir.path() / "project.e57").string();
  auto scan = [](const char* name) { return E57Scan{name, read_cloud(bunny(std::string(name) + ".ply")), Eigen::Isometry3d::Identity(), {}}; };
  write_e57(project, {scan("bun045"), scan("bun000")});
  const CommandRun align =
      k4reg(concat({"align", project, project, "--source-scan", "bun045", "--target-scan", "1", "--json"}, kBunnyFlags));
  ASSERT_EQ(align.exit_code, 0) << align.err;
  EXPECT_EQ(nlohmann::json::parse(align.out)["transform"], (*local_)["transform"]);

  const CommandRun missing = k4reg(concat({"align", project, project, "--source-scan", "bun999"}, kBunnyFlags));
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("bun999"), std::string::npos) << missing.err;
}

TEST_F(ClientCommands, MissingLocalFileIsOneLineAndExitOne) {
  const std::string missing = bunny("no-such-scan.ply");
  const CommandRun run = k4reg({"register", missing, bunny("bun000.ply"), "--server", server_->address()});
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_EQ(run.err, "k4reg: cannot read " + missing + ": No such file or directory\n");
  EXPECT_EQ(run.out, "");
}

TEST_F(ClientCommands, UnreachableServerIsOneLineAndExitOne) {
  const std::string dead = "127.0.0.1:" + std::to_string(dead_port());
  const CommandRun run =
      k4reg({"register", bunny("bun045.ply"), bunny("bun000.ply"), "--server", dead, "--retries", "0"});
  EXPECT_EQ(run.exit_code, 1);
  ASSERT_EQ(lines(run.err).size(), 1u) << run.err;
  EXPECT_EQ(run.err.rfind("k4reg: UNAVAILABLE: cannot reach " + dead + " (", 0), 0u) << run.err;
}

TEST_F(ClientCommands, RetriesOnUnavailableThenGivesUp) {
  const std::string dead = "127.0.0.1:" + std::to_string(dead_port());
  const CommandRun run =
      k4reg({"register", bunny("bun045.ply"), bunny("bun000.ply"), "--server", dead, "--retries", "1"});
  EXPECT_EQ(run.exit_code, 1);
  const std::vector<std::string> err = lines(run.err);
  ASSERT_EQ(err.size(), 2u) << run.err;
  EXPECT_EQ(err[0], "UNAVAILABLE: retrying in 1.0 s (attempt 2 of 2)");
  EXPECT_EQ(err[1].rfind("k4reg: UNAVAILABLE: cannot reach " + dead, 0), 0u);
}

TEST_F(ClientCommands, PathOutsideTheDataRootsIsPermissionDenied) {
  const CommandRun run = k4reg({"register", "../../secret.ply", "bun000.ply", "--ref", "--server", server_->address()});
  EXPECT_EQ(run.exit_code, 1);
  ASSERT_EQ(lines(run.err).size(), 1u) << run.err;
  EXPECT_EQ(run.err.rfind("k4reg: PERMISSION_DENIED: ", 0), 0u) << run.err;
  EXPECT_EQ(run.out, "");
}

TEST_F(ClientCommands, UsageErrorsExitTwo) {
  EXPECT_EQ(k4reg({"register", bunny("bun045.ply"), bunny("bun000.ply")}).exit_code, 2);  // no --server
  EXPECT_EQ(k4reg({"health", "--server", "localhost"}).exit_code, 2);                     // no port
  EXPECT_EQ(k4reg({"load", "--server", "127.0.0.1:1", "--pair", "a"}).exit_code, 2);      // half a pair
  EXPECT_EQ(k4reg({"load", "--server", "a:1,b:2", "--pair", "a", "b"}).exit_code, 2);     // names in a list
}

TEST(ClientLoad, OverloadShowsResourceExhaustedAndEveryOtherCallOk) {
  ServerProcess server({"--data-root", bunny_dir().string(), "--workers", "1", "--queue-size", "1"});
  const CommandRun run = k4reg(concat({"load", "--server", server.address(), "--pair", "bun045.ply", "bun000.ply",
                                       "--concurrency", "6", "--requests", "12", "--json"},
                                      kQuickFlags));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json report = nlohmann::json::parse(run.out);
  const nlohmann::json& counts = report["status_counts"];
  EXPECT_EQ(counts.size(), 2u) << counts;
  const std::size_t ok = counts.value("OK", 0u), refused = counts.value("RESOURCE_EXHAUSTED", 0u);
  EXPECT_EQ(ok + refused, 12u) << counts;
  EXPECT_GE(ok, 2u);       // one running, one queued
  EXPECT_GE(refused, 1u);  // the other callers of the first burst
  EXPECT_EQ(report["calls"], 12);
  EXPECT_EQ(report["latency_s"]["count"], ok);
  EXPECT_GT(report["latency_s"]["p50"].get<double>(), 0.0);
  EXPECT_GT(report["calls_per_s"].get<double>(), 0.0);
  EXPECT_GE(report["client_cpu_percent"].get<double>(), 0.0);
  EXPECT_EQ(report["server_timings_s"]["overhead"]["count"], ok);
  EXPECT_LT(report["server_timings_s"]["overhead"]["p99"].get<double>(), 0.05);
}

TEST(ClientLoad, TextReportAndRoundRobinOverTwoReplicasWithUploads) {
  ServerProcess a({"--workers", "1", "--server-id", "replica-a"}), b({"--workers", "1", "--server-id", "replica-b"});
  const CommandRun run = k4reg(concat({"load", "--server", a.address() + "," + b.address(), "--upload", "--pair",
                                       bunny("bun045.ply"), bunny("bun000.ply"), "--pair", bunny("bun000.ply"),
                                       bunny("bun045.ply"), "--concurrency", "2", "--requests", "8"},
                                      kQuickFlags));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  for (const char* text : {"closed loop, concurrency 2", "calls/s", "client CPU", "p99", "Latency histogram",
                           "OK                    8", "overhead", "replica-a", "replica-b"})
    EXPECT_NE(run.out.find(text), std::string::npos) << text << "\n" << run.out;
}

TEST(ClientLoad, OpenLoopForADurationStopsByItself) {
  ServerProcess server({"--data-root", bunny_dir().string(), "--workers", "2"});
  const CommandRun run = k4reg(concat({"load", "--server", server.address(), "--pair", "bun045.ply", "bun000.ply",
                                       "--rate", "4", "--duration", "1.5", "--json"},
                                      kQuickFlags));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json report = nlohmann::json::parse(run.out);
  EXPECT_EQ(report["mode"], "open");
  EXPECT_EQ(report["calls"], 6);  // scheduled at 0, 0.25, ... 1.25 s
  EXPECT_EQ(report["status_counts"]["OK"], 6);
}

TEST(ClientLoad, NothingGettingThroughIsAnError) {
  ServerProcess server({"--data-root", bunny_dir().string(), "--workers", "1"});
  const CommandRun run =
      k4reg({"load", "--server", server.address(), "--pair", "missing.ply", "bun000.ply", "--requests", "2"});
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.out.find("NOT_FOUND"), std::string::npos) << run.out;
  EXPECT_EQ(run.err.rfind("k4reg: NOT_FOUND: ", 0), 0u) << run.err;
}

TEST(ClientAuth, TokenFromTheEnvironmentOrTheFlag) {
  ServerProcess server({"--data-root", bunny_dir().string(), "--workers", "1", "--auth-token", "s3cret"});
  const std::vector<std::string> call =
      concat({"register", "bun045.ply", "bun000.ply", "--ref", "--server", server.address(), "--json"}, kQuickFlags);
  const CommandRun without = k4reg(call);
  EXPECT_EQ(without.exit_code, 1);
  EXPECT_EQ(without.err.rfind("k4reg: UNAUTHENTICATED: ", 0), 0u) << without.err;
  EXPECT_EQ(k4reg(call, {{"K4REG_TOKEN", "s3cret"}}).exit_code, 0);
  EXPECT_EQ(k4reg(concat(call, {"--token", "s3cret"})).exit_code, 0);
  EXPECT_EQ(k4reg({"health", "--server", server.address()}).exit_code, 0);  // probes carry no secret
}

TEST(ClientTls, CaCertVerifiesTheServer) {
  TempDir dir;
  const fs::path key = dir.path() / "key.pem", cert = dir.path() / "cert.pem";
  const std::string command =
      "openssl req -x509 -newkey rsa:2048 -nodes -days 1 -subj /CN=localhost -addext "
      "subjectAltName=IP:127.0.0.1 -keyout " +
      key.string() + " -out " + cert.string() + " >/dev/null 2>&1";
  if (std::system(command.c_str()) != 0) GTEST_SKIP() << "openssl not available";
  ServerProcess server(
      {"--data-root", bunny_dir().string(), "--workers", "1", "--tls-cert", cert.string(), "--tls-key", key.string()});
  const CommandRun ok = k4reg(concat({"register", "bun045.ply", "bun000.ply", "--ref", "--server", server.address(),
                                      "--ca-cert", cert.string(), "--json"},
                                     kQuickFlags));
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_EQ(k4reg({"health", "--server", server.address(), "--ca-cert", cert.string()}).exit_code, 0);
  const CommandRun plain = k4reg({"health", "--server", server.address()});
  EXPECT_EQ(plain.exit_code, 1);
  EXPECT_EQ(plain.err.rfind("k4reg: UNAVAILABLE: cannot reach ", 0), 0u) << plain.err;
}

}  // namespace
}  // namespace k4reg::test
