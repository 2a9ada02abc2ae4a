// What the QA page relies on, on the real server: progress events over HTTP (Accept: application/x-ndjson),
// previews of the registered clouds (gRPC and HTTP), project uploads as multipart/form-data, and GET / serving
// the self-contained page.
#include <gtest/gtest.h>

#include <sstream>

#include "http/http_json.h"
#include "test_support.h"

namespace k4reg::test {
namespace {

const std::vector<std::string> kProject{"bun000.ply", "bun045.ply", "bun090.ply"};

// The NDJSON lines of an answer, each parsed into Event.
template <typename Event>
std::vector<Event> events_of(const std::string& body) {
  std::vector<Event> events;
  std::istringstream lines(body);
  for (std::string line; std::getline(lines, line);) {
    if (line.empty()) continue;
    Event event;
    service::from_json(line, event);
    events.push_back(std::move(event));
  }
  return events;
}

std::size_t preview_points(const v1::Preview& preview) {
  std::size_t points = 0;
  for (const v1::PreviewCloud& cloud : preview.clouds()) {
    EXPECT_EQ(cloud.xyz().size(), 3 * cloud.distance_m().size()) << cloud.name();
    points += cloud.distance_m().size() / sizeof(float);
  }
  return points;
}

class HttpEvents : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { server_ = new ServerProcess({"--data-root", bunny_dir().string(), "--workers", "2"}); }
  static void TearDownTestSuite() { delete server_; }
  static std::string url(const std::string& path) { return server_->http_url() + path; }
  static ServerProcess* server_;
};

ServerProcess* HttpEvents::server_ = nullptr;

TEST_F(HttpEvents, PairUploadStreamsQueuedStagesThenTheResultWithItsPreview) {
  const HttpReply reply = curl({"-N", "-H", "Accept: application/x-ndjson", "-F",
                                "source=@" + (bunny_dir() / "bun045.ply").string(), "-F", "target=bun000.ply", "-F",
                                "min_scale_m=0.001", "-F", "overlap=0.9", "-F", "seed=7", "-F", "preview_points=5000",
                                url("/v1/register")});
  ASSERT_EQ(reply.status, 200) << reply.body;
  EXPECT_EQ(reply.header("content-type"), "application/x-ndjson");
  const auto events = events_of<v1::RegisterStreamResponse>(reply.body);
  ASSERT_GE(events.size(), 4u) << reply.body;
  EXPECT_TRUE(events.front().has_queued());
  std::set<std::string> stages;
  for (const auto& event : events)
    if (event.has_stage()) stages.insert(event.stage().stage());
  for (const char* stage : {"load", "keypoints", "matching", "icp", "preview"}) EXPECT_TRUE(stages.count(stage)) << stage;
  ASSERT_TRUE(events.back().has_result()) << reply.body;
  const v1::RegisterResponse& streamed = events.back().result();

  // The same job over gRPC, with the same preview, bit for bit.
  v1::RegistrationParams params = bunny_params();
  params.set_seed(7);
  v1::RegisterRequest request = bunny_request(params);
  request.set_preview_points(5000);
  grpc::ClientContext context;
  set_timeout(context, std::chrono::seconds(120));
  v1::RegisterResponse unary;
  ASSERT_TRUE(server_->stub()->Register(&context, request, &unary).ok());
  for (int i = 0; i < 16; ++i) EXPECT_EQ(streamed.result().transform(i), unary.result().transform(i));
  EXPECT_EQ(streamed.preview().SerializeAsString(), unary.preview().SerializeAsString());
  ASSERT_EQ(unary.preview().clouds_size(), 2);
  EXPECT_EQ(unary.preview().clouds(0).name(), "source");
  EXPECT_EQ(preview_points(unary.preview()), 5000u);
  EXPECT_GT(unary.preview().distance_cap_m(), 0.0);
  EXPECT_GT(unary.preview().clouds(0).keypoints_xyz().size(), 0u);
  EXPECT_EQ(unary.result().hypotheses(0).base_source_m_size(), 12);
  // Every request line of the access log carries the points, the streamed one too.
  bool logged = false;
  for (const nlohmann::json& line : server_->log_lines("request"))
    logged |= line.value("method", "") == "POST /v1/register" && line.value("source_points", 0) > 0;
  EXPECT_TRUE(logged);
}

TEST_F(HttpEvents, NoPreviewUnlessAskedAndTooLargeIsRefused) {
  grpc::ClientContext context;
  set_timeout(context, std::chrono::seconds(120));
  v1::RegisterResponse reply;
  ASSERT_TRUE(server_->stub()->Register(&context, bunny_request(bunny_params()), &reply).ok());
  EXPECT_FALSE(reply.has_preview());
  v1::RegisterRequest request = bunny_request(bunny_params());
  request.set_preview_points(2000001);
  grpc::ClientContext too_many;
  const grpc::Status status = server_->stub()->Register(&too_many, request, &reply);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(status.error_message().find("preview_points"), std::string::npos) << status.error_message();
}

TEST_F(HttpEvents, RefusalsBeforeTheJobAreStatusesAndFailuresAfterItAreErrorEvents) {
  const HttpReply refused = curl({"-H", "Accept: application/x-ndjson", "-F", "source=bun045.ply", "-F",
                                  "target=bun000.ply", "-F", "bogus=1", url("/v1/register")});
  EXPECT_EQ(refused.status, 400) << refused.body;
  EXPECT_EQ(refused.json()["code"], "INVALID_ARGUMENT");
  // Out of time while running: the stream has begun, so the failure is its last event.
  const HttpReply expired = curl({"-H", "Accept: application/x-ndjson", "-F", "source=bun045.ply", "-F",
                                  "target=bun000.ply", "-F", "max_bases=200000", "-F", "time_budget_s=0.3",
                                  url("/v1/register")});
  ASSERT_EQ(expired.status, 200) << expired.body;
  const std::string last = expired.body.substr(expired.body.rfind('\n', expired.body.size() - 2) + 1);
  const nlohmann::json error = nlohmann::json::parse(last);
  EXPECT_EQ(error["error"]["code"], "DEADLINE_EXCEEDED") << expired.body;
  EXPECT_EQ(error["error"]["request_id"], expired.header("x-request-id"));
}

TEST_F(HttpEvents, ProjectUploadIsTheJsonProjectWithPairEventsAndAPreview) {
  std::vector<std::string> args{"-N", "-H", "Accept: application/x-ndjson"};
  for (const std::string& scan : kProject) args.insert(args.end(), {"-F", "scans=@" + (bunny_dir() / scan).string()});
  // Screened pairs by their short name: with 2 partners each of the 3 scans keeps both others, so all 3 pairs run.
  for (const char* field :
       {"min_scale_m=0.002", "overlap=0.5", "seed=1", "pairs=screened", "partners=2", "reference=0", "preview_points=3000"})
    args.insert(args.end(), {"-F", field});
  args.push_back(url("/v1/register-project"));
  const HttpReply reply = curl(args);
  ASSERT_EQ(reply.status, 200) << reply.body;
  const auto events = events_of<v1::RegisterProjectEvent>(reply.body);
  ASSERT_FALSE(events.empty());
  EXPECT_TRUE(events.front().has_queued());
  int pairs = 0;
  for (const auto& event : events) pairs += event.has_pair();
  EXPECT_EQ(pairs, 3);
  ASSERT_TRUE(events.back().has_result()) << reply.body;
  const v1::RegisterProjectResponse& uploaded = events.back().result();
  ASSERT_EQ(uploaded.preview().clouds_size(), 3);
  EXPECT_EQ(uploaded.preview().clouds(1).name(), "bun045.ply");
  EXPECT_EQ(preview_points(uploaded.preview()), 3000u);
  EXPECT_EQ(uploaded.result().pairs_used(), v1::PAIR_SELECTION_SCREENED);
  EXPECT_EQ(uploaded.result().pairs_screened(), 3u);

  // The same scans by path as JSON, answered at once.
  nlohmann::json body = {{"params",
                          {{"pairwise", {{"min_scale_m", 0.002}, {"overlap", 0.5}, {"seed", "1"}}},
                           {"pairs", "PAIR_SELECTION_SCREENED"},
                           {"partners", 2}}}};
  for (const std::string& scan : kProject) body["scans"].push_back({{"path", scan}});
  const HttpReply json = curl({"-H", "Content-Type: application/json", "--data-binary", body.dump(), url("/v1/register-project")});
  ASSERT_EQ(json.status, 200) << json.body;
  v1::RegisterProjectResponse by_path;
  service::from_json(json.body, by_path);
  EXPECT_FALSE(by_path.has_preview());
  EXPECT_EQ(by_path.result().pairs_used(), v1::PAIR_SELECTION_SCREENED);
  ASSERT_EQ(by_path.result().scans_size(), 3);
  for (int s = 0; s < 3; ++s) {
    ASSERT_EQ(uploaded.result().scans(s).pose_size(), by_path.result().scans(s).pose_size());
    for (int i = 0; i < uploaded.result().scans(s).pose_size(); ++i)
      EXPECT_EQ(uploaded.result().scans(s).pose(i), by_path.result().scans(s).pose(i)) << "scan " << s;
  }
}

TEST_F(HttpEvents, MalformedProjectFormsAreRefused) {
  const std::string scan = "scans=@" + (bunny_dir() / "bun000.ply").string();
  const struct {
    std::vector<std::string> fields;
    std::string message;
  } cases[] = {
      {{scan}, "at least 2 scans"},
      {{scan, "scans=bun045.ply", "reference=5"}, "out of range"},
      {{scan, "scans=bun045.ply", "pairs=sometimes"}, "pairs"},
      {{scan, "scans=bun045.ply", "partners=0"}, "partners"},
      {{scan, "scans=../etc/passwd"}, ""},
      {{scan, "scans=bun045.ply", "source=bun090.ply"}, "unknown form field 'source'"},
      {{scan, "scans=bun045.ply", "preview_points=lots"}, "preview_points"},
  };
  for (const auto& c : cases) {
    std::vector<std::string> args;
    for (const std::string& field : c.fields) args.insert(args.end(), {"-F", field});
    args.push_back(url("/v1/register-project"));
    const HttpReply reply = curl(args);
    EXPECT_GE(reply.status, 400) << reply.body;
    EXPECT_LT(reply.status, 500) << reply.body;
    EXPECT_NE(reply.json().value("message", "").find(c.message), std::string::npos) << reply.body;
  }
}

TEST_F(HttpEvents, TheRootServesTheSelfContainedPage) {
  const HttpReply page = curl({url("/")});
  ASSERT_EQ(page.status, 200);
  EXPECT_EQ(page.header("content-type"), "text/html; charset=utf-8");
  EXPECT_NE(page.body.find("id=\"k4reg-document\""), std::string::npos);
  EXPECT_NE(page.body.find("k4regView"), std::string::npos) << "the view code inlined";
  EXPECT_NE(page.body.find("THREE"), std::string::npos) << "three.js inlined";
  EXPECT_EQ(page.body.find("/*K4REG:"), std::string::npos) << "every marker filled in";
  EXPECT_EQ(page.body.find("http://"), std::string::npos);
  EXPECT_EQ(page.body.find("https://"), std::string::npos);
}

}  // namespace
}  // namespace k4reg::test
