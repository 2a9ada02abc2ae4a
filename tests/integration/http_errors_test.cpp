// Every error the HTTP API promises, each sent by both cpp-httplib's client and curl: the HTTP status from the
// same typed errors as gRPC, and the JSON body {code, message, request_id}. Also the drain: in-flight HTTP
// jobs finish, new ones get 503.
#include <gtest/gtest.h>
#include <signal.h>

#include <thread>

#include "http/http_json.h"
#include "test_support.h"

namespace k4reg::test {
namespace {

using namespace std::chrono_literals;

struct HttpCall {
  std::string method = "POST", path = "/v1/register";
  std::string content_type = "application/json", body;
  httplib::Headers headers;
};

HttpReply send_with_httplib(const ServerProcess& server, const HttpCall& call) {
  auto http = server.http();
  if (call.method == "GET") return reply_of(http.Get(call.path, call.headers));
  return reply_of(http.Post(call.path, call.headers, call.body, call.content_type));
}

HttpReply send_with_curl(const ServerProcess& server, const HttpCall& call) {
  TempDir dir;
  std::vector<std::string> args{"-X", call.method};
  for (const auto& [name, value] : call.headers) args.insert(args.end(), {"-H", name + ": " + value});
  if (call.method != "GET") {
    write_file(dir.path() / "body", call.body);
    args.insert(args.end(), {"-H", "Content-Type: " + call.content_type, "--data-binary", std::string("@").append((dir.path() / "body").string())});
  }
  args.push_back(server.http_url() + call.path);
  return curl(args);
}

// Both clients get `status` and the JSON error of `code` whose message contains `text`.
void expect_error(const ServerProcess& server, const HttpCall& call, int status, const std::string& code,
                  const std::string& text) {
  for (const auto& [client, reply] : {std::pair{"cpp-httplib", send_with_httplib(server, call)},
                                      std::pair{"curl", send_with_curl(server, call)}}) {
    SCOPED_TRACE(client);
    EXPECT_EQ(reply.status, status) << reply.body;
    EXPECT_EQ(reply.header("content-type"), "application/json");
    const nlohmann::json body = reply.json();
    ASSERT_TRUE(body.is_object()) << reply.body;
    EXPECT_EQ(body["code"], code);
    EXPECT_NE(body["message"].get<std::string>().find(text), std::string::npos) << body;
    EXPECT_EQ(body["request_id"], reply.header("x-request-id"));
  }
}

HttpCall json_call(const v1::RegisterRequest& request) {
  HttpCall call;
  call.body = service::to_json(request);
  return call;
}

HttpCall path_call(const std::string& source, const std::string& target, const v1::RegistrationParams& params = quick_params()) {
  v1::RegisterRequest request;
  request.mutable_source()->set_path(source);
  request.mutable_target()->set_path(target);
  *request.mutable_params() = params;
  return json_call(request);
}

struct Part {
  std::string name, content, file_name;
};

// The same multipart/form-data bytes for both clients.
HttpCall multipart_call(const std::vector<Part>& parts) {
  HttpCall call;
  const std::string boundary = "k4reg-test-boundary";
  call.content_type = "multipart/form-data; boundary=" + boundary;
  for (const Part& part : parts) {
    call.body += "--" + boundary + "\r\nContent-Disposition: form-data; name=\"" + part.name + "\"";
    if (!part.file_name.empty()) call.body += "; filename=\"" + part.file_name + "\"";
    call.body += "\r\n\r\n" + part.content + "\r\n";
  }
  call.body += "--" + boundary + "--\r\n";
  return call;
}

class HttpErrors : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    server_ = new ServerProcess({"--data-root", bunny_dir().string(), "--workers", "1", "--max-upload-mb", "1",
                                 "--max-inline-mb", "1"});
  }
  static void TearDownTestSuite() { delete server_; }
  static ServerProcess* server_;
};

ServerProcess* HttpErrors::server_ = nullptr;

TEST_F(HttpErrors, BadRequestsAre400NamingTheProblem) {
  HttpCall malformed;
  malformed.body = "{\"source\": ";
  expect_error(*server_, malformed, 400, "INVALID_ARGUMENT", "invalid JSON for RegisterRequest");
  HttpCall unknown_field;
  unknown_field.body = R"({"source": {"path": "bun045.ply"}, "target": {"path": "bun000.ply"}, "prams": {}})";
  expect_error(*server_, unknown_field, 400, "INVALID_ARGUMENT", "prams");
  v1::RegistrationParams params = quick_params();
  params.set_overlap(2.0);
  expect_error(*server_, path_call("bun045.ply", "bun000.ply", params), 400, "INVALID_ARGUMENT", "params.overlap");
  expect_error(*server_, json_call(v1::RegisterRequest{}), 400, "INVALID_ARGUMENT", "source: give either path");

  v1::RegisterRequest broken;
  broken.mutable_source()->mutable_inline_cloud()->set_data("ply\nformat ascii 1.0\nelement vertex 3\nend_header\n1 2\n");
  broken.mutable_source()->mutable_inline_cloud()->set_file_name("broken.ply");
  broken.mutable_target()->set_path("bun000.ply");
  expect_error(*server_, json_call(broken), 400, "INVALID_ARGUMENT", "broken.ply");

  HttpCall text = path_call("bun045.ply", "bun000.ply");
  text.content_type = "text/plain";
  expect_error(*server_, text, 400, "INVALID_ARGUMENT", "unsupported Content-Type 'text/plain'");

  const std::string bytes = read_file(bunny_dir() / "bun045.ply");
  expect_error(*server_, multipart_call({{"source", bytes, "a.ply"}, {"target", "bun000.ply", ""}, {"min_scale", "1", ""}}),
               400, "INVALID_ARGUMENT", "unknown form field 'min_scale'");
  expect_error(*server_, multipart_call({{"source", bytes, "a.ply"}}), 400, "INVALID_ARGUMENT", "missing form part 'target'");
  expect_error(*server_, multipart_call({{"source", bytes, "a.ply"}, {"target", "bun000.ply", ""}, {"icp", "maybe", ""}}),
               400, "INVALID_ARGUMENT", "icp");
  expect_error(*server_, multipart_call({{"source", bytes, "a.ply"}, {"source", bytes, "b.ply"}}), 400,
               "INVALID_ARGUMENT", "given twice");
  HttpCall truncated = multipart_call({{"source", bytes, "a.ply"}, {"target", "bun000.ply", ""}});
  truncated.body.resize(truncated.body.size() / 2);
  expect_error(*server_, truncated, 400, "INVALID_ARGUMENT", "multipart");
  EXPECT_EQ(server_->spooled_files(), 0u);
}

TEST_F(HttpErrors, PathsOutsideTheDataRootsAre403AndMissingFiles404) {
  for (const std::string path : {"../x.ply", "/etc/passwd"})
    expect_error(*server_, path_call(path, "bun000.ply"), 403, "PERMISSION_DENIED", "outside");
  expect_error(*server_, path_call("bun045.ply", "missing.ply"), 404, "NOT_FOUND", "missing.ply");
  // A path part of a multipart form goes through the same check.
  expect_error(*server_, multipart_call({{"source", "/etc/passwd", ""}, {"target", "bun000.ply", ""}}), 403,
               "PERMISSION_DENIED", "outside");
  HttpCall unknown_route;
  unknown_route.method = "GET";
  unknown_route.path = "/v1/registrations";
  expect_error(*server_, unknown_route, 404, "NOT_FOUND", "/openapi.json");
}

TEST_F(HttpErrors, OverTheLimitsIs413) {
  // A JSON body beyond --max-inline-mb of base64, refused from its Content-Length (curl sends
  // "Expect: 100-continue" for it and gets the answer before sending the body).
  HttpCall big_json = path_call("bun045.ply", "bun000.ply");
  big_json.body.insert(1, "\"padding\": \"" + std::string(2 << 20, 'x') + "\", ");
  expect_error(*server_, big_json, 413, "RESOURCE_EXHAUSTED", "--max-inline-mb");
  // An uploaded file beyond --max-upload-mb, refused while it arrives.
  const std::string big_file((3 << 20) / 2, 'x');
  expect_error(*server_, multipart_call({{"source", big_file, "big.ply"}, {"target", "bun000.ply", ""}}), 413,
               "RESOURCE_EXHAUSTED", "--max-upload-mb");
  EXPECT_EQ(server_->spooled_files(), 0u);
}

TEST(HttpLimits, PointAndMemoryBudgetsAre413) {
  ServerProcess server({"--data-root", bunny_dir().string(), "--workers", "1", "--max-points", "40100",
                        "--memory-budget-mb", "4"});
  expect_error(server, path_call("bun000.ply", "bun045.ply"), 413, "RESOURCE_EXHAUSTED", "--max-points");
  expect_error(server, path_call("bun045.ply", "bun045.ply"), 413, "RESOURCE_EXHAUSTED", "--memory-budget-mb");
}

TEST_F(HttpErrors, CloudsWithoutAlignmentAre422) {
  expect_error(*server_, json_call(sphere_request()), 422, "FAILED_PRECONDITION", "too few keypoints");
}

TEST_F(HttpErrors, AnExhaustedTimeBudgetIs504) {
  v1::RegistrationParams params = slow_params(5);
  params.set_time_budget_s(0.2);
  expect_error(*server_, path_call("bun045.ply", "bun000.ply", params), 504, "DEADLINE_EXCEEDED", "time budget");
}

TEST(HttpAuth, RegistrationMetricsAndVersionNeedTheBearerTokenButProbesDoNot) {
  ServerProcess server({"--data-root", bunny_dir().string(), "--workers", "1", "--auth-token", "s3cret"});
  HttpCall call = path_call("bun045.ply", "bun000.ply");
  expect_error(server, call, 401, "UNAUTHENTICATED", "authorization");
  call.headers = {{"Authorization", "Bearer wrong"}};
  expect_error(server, call, 401, "UNAUTHENTICATED", "invalid bearer token");
  // Refused from the headers: a multipart upload is answered without its body (curl: Expect: 100-continue).
  HttpCall upload = multipart_call({{"source", std::string(2 << 20, 'x'), "a.ply"}, {"target", "bun000.ply", ""}});
  expect_error(server, upload, 401, "UNAUTHENTICATED", "authorization");
  call.headers = {{"Authorization", "Bearer s3cret"}};
  EXPECT_EQ(send_with_httplib(server, call).status, 200);
  EXPECT_EQ(send_with_curl(server, call).status, 200);
  for (const char* path : {"/healthz", "/readyz", "/openapi.json", "/"}) {
    EXPECT_EQ(reply_of(server.http().Get(path)).status, 200) << path;
    EXPECT_EQ(curl({server.http_url() + path}).status, 200) << path;
  }
  for (const char* path : {"/metrics", "/v1/version"}) {
    const HttpReply refused = curl({server.http_url() + path});
    EXPECT_EQ(refused.status, 401) << path;
    EXPECT_NE(refused.body.find("--public-metrics"), std::string::npos) << refused.body;
    EXPECT_EQ(curl({"-H", "Authorization: Bearer s3cret", server.http_url() + path}).status, 200) << path;
  }
  EXPECT_EQ(server.log().find("s3cret"), std::string::npos);
}

TEST(HttpQueue, AFullQueueIs429WithRetryAfterAndReadinessDrops) {
  ServerProcess server({"--data-root", bunny_dir().string(), "--workers", "1", "--queue-size", "1"});
  // One job runs, one waits (gRPC calls): the queue both protocols share is full.
  FullQueue full(server);

  const auto start = std::chrono::steady_clock::now();
  expect_error(server, path_call("bun045.ply", "bun000.ply"), 429, "RESOURCE_EXHAUSTED", "--queue-size");
  EXPECT_LT(std::chrono::steady_clock::now() - start, 5s);
  const HttpReply refused = send_with_curl(server, path_call("bun045.ply", "bun000.ply"));
  EXPECT_EQ(refused.header("retry-after"), "1");
  HttpCall readiness;
  readiness.method = "GET";
  readiness.path = "/readyz";
  expect_error(server, readiness, 503, "UNAVAILABLE", "queue full");
  EXPECT_EQ(reply_of(server.http().Get("/healthz")).status, 200);

  // Room in the queue again: ready.
  full.queued_context().TryCancel();
  EXPECT_EQ(full.queued().finish().error_code(), grpc::StatusCode::CANCELLED);
  EXPECT_TRUE(http_status_becomes(server, "/readyz", 200));
}

TEST(HttpDrain, InFlightJobsFinishAndNewOnesGet503) {
  ServerProcess server({"--data-root", bunny_dir().string(), "--workers", "1", "--drain-grace-s", "60"});
  const HttpCall slow = path_call("bun045.ply", "bun000.ply", slow_params(2));
  HttpReply in_flight;
  std::thread client([&] { in_flight = send_with_httplib(server, slow); });
  // Wait until its job runs (the worker is busy), then ask the server to stop.
  auto http = server.http();
  bool busy = false;
  for (auto end = std::chrono::steady_clock::now() + 30s; !busy && std::chrono::steady_clock::now() < end;
       std::this_thread::sleep_for(20ms))
    busy = reply_of(http.Get("/metrics")).body.find("\nk4reg_workers_busy 1\n") != std::string::npos;
  EXPECT_TRUE(busy) << "the job did not start";
  server.signal(SIGTERM);
  EXPECT_TRUE(http_status_becomes(server, "/readyz", 503));
  HttpCall readiness;
  readiness.method = "GET";
  readiness.path = "/readyz";
  expect_error(server, readiness, 503, "UNAVAILABLE", "draining");
  expect_error(server, path_call("bun045.ply", "bun000.ply"), 503, "UNAVAILABLE", "draining");
  EXPECT_EQ(reply_of(http.Get("/healthz")).status, 200);  // alive while draining

  client.join();
  EXPECT_EQ(in_flight.status, 200) << in_flight.body;
  EXPECT_EQ(server.wait(), 0);
  const auto lines = server.log_lines("request");
  EXPECT_TRUE(std::any_of(lines.begin(), lines.end(), [](const auto& line) {
    return line["method"] == "POST /v1/register" && line["code"] == "OK";
  }));
}

}  // namespace
}  // namespace k4reg::test
