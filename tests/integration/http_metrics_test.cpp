// GET /metrics: one registry for both protocols, values that follow the requests and jobs as they run, and an
// exposition that Prometheus' own linter (promtool check metrics) accepts.
#include <gtest/gtest.h>

#include <map>
#include <sstream>
#include <thread>

#include "http/http_json.h"
#include "test_support.h"

namespace k4reg::test {
namespace {

using namespace std::chrono_literals;

// "name{labels}" -> value, from the text exposition (comments skipped).
std::map<std::string, double> parse_exposition(const std::string& text) {
  std::map<std::string, double> samples;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (line.empty() || line[0] == '#') continue;
    const auto space = line.rfind(' ');
    samples[line.substr(0, space)] = std::stod(line.substr(space + 1));
  }
  return samples;
}

class Scrape {
 public:
  explicit Scrape(const ServerProcess& server) {
    auto http = server.http();
    const HttpReply reply = reply_of(http.Get("/metrics"));
    EXPECT_EQ(reply.status, 200);
    text = reply.body;
    samples = parse_exposition(text);
  }
  double operator[](const std::string& key) const {
    const auto it = samples.find(key);
    return it == samples.end() ? 0.0 : it->second;
  }
  std::string text;
  std::map<std::string, double> samples;
};

const std::string kGrpcRegister = R"(k4reg_requests_total{protocol="grpc",method="/k4reg.v1.Registration/Register",code="OK"})";
const std::string kHttpRegister = R"(k4reg_requests_total{protocol="http",method="POST /v1/register",code="OK"})";
const std::string kHttpNotFound = R"(k4reg_requests_total{protocol="http",method="POST /v1/register",code="NOT_FOUND"})";

TEST(Metrics, FollowRequestsOfBothProtocolsAndJobs) {
  ServerProcess server({"--data-root", bunny_dir().string(), "--workers", "1", "--queue-size", "1"});
  const Scrape before(server);
  EXPECT_EQ(before[R"(k4reg_build_info{version="0.1.0"})"], 1.0) << before.text;
  EXPECT_EQ(before["k4reg_workers"], 1.0);
  EXPECT_EQ(before["k4reg_queue_capacity"], 1.0);

  // One registration per protocol, one refused, one upload.
  grpc::ClientContext context;
  set_timeout(context, 60s);
  v1::RegisterResponse grpc_reply;
  ASSERT_TRUE(server.stub()->Register(&context, bunny_request(quick_params()), &grpc_reply).ok());
  auto http = server.http();
  const HttpReply by_http =
      reply_of(http.Post("/v1/register", service::to_json(bunny_request(quick_params())), "application/json"));
  ASSERT_EQ(by_http.status, 200);
  v1::RegisterRequest missing = bunny_request(quick_params());
  missing.mutable_target()->set_path("missing.ply");
  EXPECT_EQ(reply_of(http.Post("/v1/register", service::to_json(missing), "application/json")).status, 404);
  const std::string source = read_file(bunny_dir() / "bun045.ply");
  const HttpReply upload = reply_of(http.Post("/v1/register", httplib::MultipartFormDataItems{
                                                                  {"source", source, "bun045.ply", ""},
                                                                  {"target", "bun000.ply", "", ""},
                                                                  {"min_scale_m", "0.004", "", ""},
                                                                  {"overlap", "0.9", "", ""},
                                                              }));
  ASSERT_EQ(upload.status, 200);

  const Scrape after(server);
  EXPECT_EQ(after[kGrpcRegister] - before[kGrpcRegister], 1.0);
  EXPECT_EQ(after[kHttpRegister] - before[kHttpRegister], 2.0);
  EXPECT_EQ(after[kHttpNotFound] - before[kHttpNotFound], 1.0);
  EXPECT_EQ(after["k4reg_job_duration_seconds_count"] - before["k4reg_job_duration_seconds_count"], 3.0);
  EXPECT_EQ(after["k4reg_job_queue_wait_seconds_count"] - before["k4reg_job_queue_wait_seconds_count"], 3.0);
  // Every point loaded by the three jobs (the 404 never loaded one).
  const double points = 3.0 * double(grpc_reply.result().source_points() + grpc_reply.result().target_points());
  EXPECT_EQ(after["k4reg_points_processed_total"] - before["k4reg_points_processed_total"], points);
  EXPECT_GT(after[R"(k4reg_upload_bytes_total{protocol="http"})"], double(source.size()));
  EXPECT_EQ(after[R"(k4reg_request_duration_seconds_count{protocol="http",method="POST /v1/register"})"], 3.0);
  EXPECT_GT(after[R"(k4reg_request_duration_seconds_sum{protocol="grpc",method="/k4reg.v1.Registration/Register"})"], 0.0);
  EXPECT_GT(after["process_resident_memory_bytes"], 1e6);
}

TEST(Metrics, GaugesShowTheQueueAndCountersRefusalsAndCancellations) {
  ServerProcess server({"--data-root", bunny_dir().string(), "--workers", "1", "--queue-size", "1"});
  // The first core stage starts once the running job has loaded both clouds and reserved their memory.
  FullQueue full(server, "voxel_grid");

  const Scrape busy(server);
  EXPECT_EQ(busy["k4reg_workers_busy"], 1.0);
  EXPECT_EQ(busy["k4reg_queue_depth"], 1.0);
  EXPECT_EQ(busy["k4reg_memory_reserved_bytes"], 60.0 * (40097 + 40256));  // bun045 + bun000 at 60 B per point
  // Refused by the full queue, over HTTP and gRPC: both counted.
  auto http = server.http();
  EXPECT_EQ(reply_of(http.Post("/v1/register", service::to_json(bunny_request(quick_params())), "application/json")).status,
            429);
  grpc::ClientContext refused_context;
  v1::RegisterResponse refused_reply;
  EXPECT_EQ(server.stub()->Register(&refused_context, bunny_request(quick_params()), &refused_reply).error_code(),
            grpc::StatusCode::RESOURCE_EXHAUSTED);
  // The queued call is cancelled while it waits (withdrawn), the running one while it runs: both counted.
  full.queued_context().TryCancel();
  EXPECT_EQ(full.queued().finish().error_code(), grpc::StatusCode::CANCELLED);
  full.running_context().TryCancel();
  EXPECT_EQ(full.running().finish().error_code(), grpc::StatusCode::CANCELLED);

  // The client sees its cancellation at once; the server's side follows, and a worker counts itself idle just
  // after its job has ended.
  const auto idle_now = [&server] {
    const Scrape scrape(server);
    return scrape["k4reg_workers_busy"] == 0.0 && scrape["k4reg_queue_depth"] == 0.0;
  };
  for (auto end = std::chrono::steady_clock::now() + 10s; std::chrono::steady_clock::now() < end && !idle_now();
       std::this_thread::sleep_for(10ms)) {
  }
  const Scrape idle(server);
  EXPECT_EQ(idle[R"(k4reg_jobs_rejected_total{reason="queue_full"})"] - busy[R"(k4reg_jobs_rejected_total{reason="queue_full"})"],
            2.0);
  EXPECT_EQ(idle[R"(k4reg_requests_total{protocol="http",method="POST /v1/register",code="RESOURCE_EXHAUSTED"})"], 1.0);
  EXPECT_EQ(idle["k4reg_jobs_cancelled_total"] - busy["k4reg_jobs_cancelled_total"], 2.0);
  EXPECT_EQ(idle["k4reg_workers_busy"], 0.0);
  EXPECT_EQ(idle["k4reg_queue_depth"], 0.0);

  // A job stopped by its time budget is a cancelled job too.
  v1::RegistrationParams budget = slow_params(5);
  budget.set_time_budget_s(0.2);
  EXPECT_EQ(reply_of(http.Post("/v1/register", service::to_json(bunny_request(budget)), "application/json")).status, 504);
  EXPECT_EQ(Scrape(server)["k4reg_jobs_cancelled_total"] - idle["k4reg_jobs_cancelled_total"], 1.0);
}

TEST(Metrics, PromtoolAcceptsTheExposition) {
  if (!fs::exists("/usr/bin/promtool")) GTEST_SKIP() << "promtool not installed (Debian package prometheus)";
  ServerProcess server({"--data-root", bunny_dir().string(), "--workers", "1"});
  // Samples in every family: requests of both protocols, a refusal, a job.
  grpc::ClientContext context;
  v1::RegisterResponse reply;
  ASSERT_TRUE(server.stub()->Register(&context, bunny_request(quick_params()), &reply).ok());
  auto http = server.http();
  reply_of(http.Post("/v1/register", "{}", "application/json"));
  reply_of(http.Get("/healthz", {{"x-request-id", "with \"quotes\""}}));
  TempDir dir;
  const HttpReply by_curl = curl({server.http_url() + "/metrics"});
  ASSERT_EQ(by_curl.status, 200);
  write_file(dir.path() / "metrics.txt", by_curl.body);
  const CommandRun check =
      run_command({"/bin/sh", "-c", "/usr/bin/promtool check metrics < " + (dir.path() / "metrics.txt").string()});
  EXPECT_EQ(check.exit_code, 0) << check.out << check.err << "\n" << by_curl.body;
  EXPECT_EQ(check.out + check.err, "") << "lint findings";
}

}  // namespace
}  // namespace k4reg::test
