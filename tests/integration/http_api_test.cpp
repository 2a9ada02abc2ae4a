// The HTTP/JSON API of the real server on loopback, driven by two independent clients (cpp-httplib's and the
// curl program): every route, the OpenAPI description against the served routes and the proto messages,
// registration by JSON and by multipart upload of simulated scans, with results identical to gRPC's.
#include <google/protobuf/descriptor.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <Eigen/LU>
#include <set>

#include "http/http_json.h"
#include "http/http_routes.h"
#include "k4reg/registration/metrics.h"
#include "test_support.h"

namespace k4reg::test {
namespace {

using Route = std::pair<std::string, std::string>;  // method, path

v1::RegisterResponse response_of(const HttpReply& reply) {
  v1::RegisterResponse response;
  service::from_json(reply.body, response);
  return response;
}

// Bit for bit: the same doubles, not merely close ones.
void expect_same_result(const v1::RegistrationResult& a, const v1::RegistrationResult& b) {
  ASSERT_EQ(a.transform_size(), 16);
  for (int i = 0; i < 16; ++i) EXPECT_EQ(a.transform(i), b.transform(i)) << "transform[" << i << "]";
  EXPECT_EQ(a.rmse_m(), b.rmse_m());
  EXPECT_EQ(a.overlap(), b.overlap());
  EXPECT_EQ(a.inliers(), b.inliers());
  EXPECT_EQ(a.ambiguity_margin(), b.ambiguity_margin());
  EXPECT_EQ(a.hypotheses_size(), b.hypotheses_size());
  EXPECT_EQ(a.seed(), b.seed());
}

class HttpApi : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    server_ = new ServerProcess({"--data-root", bunny_dir().string(), "--workers", "2", "--server-id", "http-test"});
  }
  static void TearDownTestSuite() { delete server_; }

  static std::string url(const std::string& path) { return server_->http_url() + path; }

  static ServerProcess* server_;
};

ServerProcess* HttpApi::server_ = nullptr;

TEST_F(HttpApi, ProbesVersionAndMetricsWithBothClients) {
  auto http = server_->http();
  for (const char* path : {"/healthz", "/readyz"}) {
    for (const HttpReply& reply : {reply_of(http.Get(path)), curl({url(path)})}) {
      EXPECT_EQ(reply.status, 200) << path;
      EXPECT_EQ(reply.json(), nlohmann::json({{"status", "SERVING"}})) << reply.body;
      EXPECT_EQ(reply.header("content-type"), "application/json");
      EXPECT_EQ(reply.header("x-request-id").size(), 36u) << "a new UUID";
    }
  }
  for (const HttpReply& reply : {reply_of(http.Get("/v1/version")), curl({url("/v1/version")})}) {
    EXPECT_EQ(reply.status, 200);
    EXPECT_EQ(reply.json()["server_id"], "http-test");
    EXPECT_FALSE(reply.json()["version"].get<std::string>().empty());
  }
  for (const HttpReply& reply : {reply_of(http.Get("/metrics")), curl({url("/metrics")})}) {
    EXPECT_EQ(reply.status, 200);
    EXPECT_EQ(reply.header("content-type"), "text/plain; version=0.0.4; charset=utf-8");
    EXPECT_NE(reply.body.find("k4reg_build_info{version=\""), std::string::npos);
  }
}

TEST_F(HttpApi, RequestIdIsHonouredWhenSaneAndEchoed) {
  auto http = server_->http();
  EXPECT_EQ(reply_of(http.Get("/healthz", {{"x-request-id", "job-42.a_b"}})).header("x-request-id"), "job-42.a_b");
  EXPECT_EQ(curl({"-H", "x-request-id: from-curl", url("/healthz")}).header("x-request-id"), "from-curl");
  // Spaces, quotes and overlong ids are replaced by a new UUID.
  EXPECT_EQ(reply_of(http.Get("/healthz", {{"x-request-id", "a b"}})).header("x-request-id").size(), 36u);
  EXPECT_EQ(reply_of(http.Get("/healthz", {{"x-request-id", std::string(129, 'x')}})).header("x-request-id").size(),
            36u);
}

TEST_F(HttpApi, OpenApiDescribesExactlyTheServedRoutes) {
  auto http = server_->http();
  const HttpReply reply = reply_of(http.Get("/openapi.json"));
  ASSERT_EQ(reply.status, 200);
  EXPECT_EQ(reply.body, service::openapi_document());
  EXPECT_EQ(curl({url("/openapi.json")}).body, reply.body);
  const nlohmann::json document = reply.json();
  ASSERT_FALSE(document.is_discarded());
  EXPECT_EQ(document["openapi"].get<std::string>().rfind("3.", 0), 0u);

  std::set<Route> described, served;
  for (const auto& [path, operations] : document["paths"].items())
    for (const auto& [method, operation] : operations.items()) {
      std::string upper = method;
      for (char& c : upper) c = char(std::toupper(static_cast<unsigned char>(c)));
      described.emplace(upper, path);
    }
  for (const service::HttpRoute& route : service::http_routes()) served.emplace(route.method, route.path);
  EXPECT_EQ(described, served);

  // Each served route answers (none falls through to 404/405); anything else does not.
  for (const auto& [method, path] : served) {
    const HttpReply answer = reply_of(method == "GET" ? http.Get(path) : http.Post(path, "{}", "application/json"));
    EXPECT_NE(answer.status, 404) << method << " " << path;
    EXPECT_NE(answer.status, 405) << method << " " << path;
  }
  const HttpReply unknown = reply_of(http.Get("/v2/register"));
  EXPECT_EQ(unknown.status, 404);
  EXPECT_EQ(unknown.json()["code"], "NOT_FOUND");
  const HttpReply wrong_method = curl({url("/v1/register")});
  EXPECT_EQ(wrong_method.status, 405);
  EXPECT_EQ(wrong_method.header("allow"), "POST");
  EXPECT_EQ(reply_of(http.Post("/healthz", "x", "text/plain")).status, 405);
}

// The JSON type the protobuf JSON mapping gives a field (64-bit integers are strings).
std::string openapi_type(const google::protobuf::FieldDescriptor& field) {
  using F = google::protobuf::FieldDescriptor;
  if (field.is_repeated()) return "array";
  switch (field.cpp_type()) {
    case F::CPPTYPE_DOUBLE:
    case F::CPPTYPE_FLOAT:
      return "number";
    case F::CPPTYPE_INT32:
    case F::CPPTYPE_UINT32:
      return "integer";
    case F::CPPTYPE_BOOL:
      return "boolean";
    case F::CPPTYPE_MESSAGE:
      return "object";
    default:  // 64-bit integers, strings, bytes, enums
      return "string";
  }
}

TEST_F(HttpApi, OpenApiSchemasMatchTheProtoMessages) {
  const nlohmann::json schemas = nlohmann::json::parse(service::openapi_document())["components"]["schemas"];
  const auto* pool = google::protobuf::DescriptorPool::generated_pool();
  std::set<std::string> checked;
  for (const auto& [name, schema] : schemas.items()) {
    const google::protobuf::Descriptor* message = pool->FindMessageTypeByName("k4reg.v1." + name);
    if (!message) message = pool->FindMessageTypeByName("grpc.health.v1." + name);
    if (!message) continue;  // an enum, the error body or the upload form
    checked.insert(name);
    std::set<std::string> properties, fields;
    for (const auto& [property, description] : schema["properties"].items()) {
      properties.insert(property);
      const google::protobuf::FieldDescriptor* field = message->FindFieldByName(property);
      if (!field) continue;
      const nlohmann::json resolved =
          description.contains("$ref")
              ? schemas[description["$ref"].get<std::string>().substr(std::string("#/components/schemas/").size())]
              : description;
      EXPECT_EQ(resolved["type"], openapi_type(*field)) << name << "." << property;
    }
    for (int i = 0; i < message->field_count(); ++i) fields.insert(message->field(i)->name());
    EXPECT_EQ(properties, fields) << name;
  }
  // Every message of the API's JSON bodies.
  EXPECT_EQ(checked, (std::set<std::string>{"CloudInput", "HealthCheckResponse", "Hypothesis", "InlineCloud",
                                            "PairEvent", "Preview", "PreviewCloud", "ProjectLink", "ProjectParams",
                                            "ProjectResult", "ProjectScan", "QueuedEvent", "RegisterProjectEvent",
                                            "RegisterProjectRequest", "RegisterProjectResponse", "RegisterRequest",
                                            "RegisterResponse", "RegisterStreamResponse", "RegistrationParams",
                                            "RegistrationResult", "ScanPair", "ScanPlacement", "ScannerPosition", "ServerInfo",
                                            "ServerTimings",
                                            "StageEvent", "StageTiming"}));
}

TEST_F(HttpApi, JsonRegistrationIsIdenticalToGrpc) {
  v1::RegistrationParams params = bunny_params();
  params.set_seed(7);
  const v1::RegisterRequest request = bunny_request(params);
  grpc::ClientContext context;
  set_timeout(context, std::chrono::seconds(120));
  v1::RegisterResponse grpc_reply;
  ASSERT_TRUE(server_->stub()->Register(&context, request, &grpc_reply).ok());

  auto http = server_->http();
  const std::string json = service::to_json(request);
  EXPECT_NE(json.find("\"min_scale_m\""), std::string::npos) << "proto field names: " << json;
  const HttpReply by_httplib = reply_of(http.Post("/v1/register", {{"x-request-id", "json-1"}}, json, "application/json"));
  ASSERT_EQ(by_httplib.status, 200) << by_httplib.body;
  TempDir dir;
  write_file(dir.path() / "request.json", json);
  const HttpReply by_curl = curl({"-H", "Content-Type: application/json", "--data-binary",
                                  std::string("@").append((dir.path() / "request.json").string()), url("/v1/register")});
  ASSERT_EQ(by_curl.status, 200) << by_curl.body;

  for (const HttpReply* reply : {&by_httplib, &by_curl}) {
    const v1::RegisterResponse response = response_of(*reply);
    expect_same_result(response.result(), grpc_reply.result());
    EXPECT_EQ(response.server().server_id(), "http-test");
    EXPECT_GT(response.timings().registration_s(), 0.0);
    EXPECT_EQ(response.request_id(), reply->header("x-request-id"));
  }
  EXPECT_EQ(response_of(by_httplib).request_id(), "json-1");
  // The JSON uses the proto field names and prints every field.
  const nlohmann::json body = by_curl.json();
  EXPECT_TRUE(body["result"].contains("rmse_m"));
  EXPECT_TRUE(body["result"].contains("ambiguity_margin"));
  EXPECT_TRUE(body["timings"].contains("queue_wait_s"));

  // One access-log format for both protocols.
  const auto lines = server_->log_lines("request");
  const auto line = std::find_if(lines.begin(), lines.end(), [](const auto& l) { return l["request_id"] == "json-1"; });
  ASSERT_NE(line, lines.end());
  EXPECT_EQ((*line)["protocol"], "http");
  EXPECT_EQ((*line)["method"], "POST /v1/register");
  EXPECT_EQ((*line)["code"], "OK");
  EXPECT_EQ((*line)["http_status"], 200);
  EXPECT_EQ((*line)["source_points"], grpc_reply.result().source_points());
  EXPECT_EQ((*line)["peer"].get<std::string>().rfind("ipv4:127.0.0.1:", 0), 0u);
  EXPECT_TRUE(std::any_of(lines.begin(), lines.end(), [](const auto& l) {
    return l["protocol"] == "grpc" && l["method"] == "/k4reg.v1.Registration/Register" && l["code"] == "OK";
  }));
}

TEST_F(HttpApi, MultipartMixesAnUploadAndAPathReference) {
  const std::string source = read_file(bunny_dir() / "bun045.ply");
  auto http = server_->http();
  const HttpReply reply = reply_of(http.Post("/v1/register", httplib::MultipartFormDataItems{
                                                                 {"source", source, "bun045.ply", ""},
                                                                 {"target", "bun000.ply", "", ""},
                                                                 {"min_scale_m", "0.001", "", ""},
                                                                 {"overlap", "0.9", "", ""},
                                                                 {"seed", "7", "", ""},
                                                             }));
  ASSERT_EQ(reply.status, 200) << reply.body;
  v1::RegistrationParams params = bunny_params();
  params.set_seed(7);
  grpc::ClientContext context;
  set_timeout(context, std::chrono::seconds(120));
  v1::RegisterResponse grpc_reply;
  ASSERT_TRUE(server_->stub()->Register(&context, bunny_request(params), &grpc_reply).ok());
  expect_same_result(response_of(reply).result(), grpc_reply.result());
  EXPECT_GT(response_of(reply).timings().upload_s(), 0.0);
}

TEST(HttpUpload, MultipartUploadOfSimulatedScansMatchesGrpcAndGroundTruth) {
  TempDir data;
  const LabPair lab = simulate_lab_pair(data.path(), 60000);
  const sim::SimulatedScan &source = lab.source, &target = lab.target;
  const fs::path &source_file = lab.source_file, &target_file = lab.target_file;
  v1::RegistrationParams params;
  params.set_min_scale_m(0.05);
  params.set_overlap(0.8);
  params.set_seed(3);
  params.set_signal(v1::KEYPOINT_SIGNAL_INTENSITY);

  ServerProcess server({"--workers", "1"});
  const HttpReply by_curl =
      curl({"-F", "source=@" + source_file.string(), "-F", "target=@" + target_file.string(), "-F", "min_scale_m=0.05",
            "-F", "overlap=0.8", "-F", "seed=3", "-F", "signal=KEYPOINT_SIGNAL_INTENSITY", "-H", "x-request-id: lab-upload",
            server.http_url() + "/v1/register"});
  ASSERT_EQ(by_curl.status, 200) << by_curl.body;
  const std::string source_bytes = read_file(source_file), target_bytes = read_file(target_file);
  auto http = server.http();
  const HttpReply by_httplib = reply_of(http.Post("/v1/register", httplib::MultipartFormDataItems{
                                                                      {"seed", "3", "", ""},
                                                                      {"source", source_bytes, "lab0.ply", ""},
                                                                      {"overlap", "0.8", "", ""},
                                                                      {"target", target_bytes, "lab2.ply", ""},
                                                                      {"min_scale_m", "0.05", "", ""},
                                                                      {"signal", "2", "", ""},
                                                                  }));
  ASSERT_EQ(by_httplib.status, 200) << by_httplib.body;

  // The same bytes streamed over gRPC give the same result, bit for bit.
  grpc::ClientContext context;
  set_timeout(context, std::chrono::seconds(120));
  auto stub = server.stub();
  StreamCall call(*stub, context, upload_header("lab0.ply", source_bytes, "lab2.ply", target_bytes, params),
                  {source_bytes, target_bytes});
  ASSERT_TRUE(call.finish().ok());
  ASSERT_NE(call.result(), nullptr);
  for (const HttpReply* reply : {&by_curl, &by_httplib}) {
    const v1::RegisterResponse response = response_of(*reply);
    expect_same_result(response.result(), call.result()->result());
    EXPECT_EQ(response.result().source_points(), source.cloud.size());
    EXPECT_GT(response.timings().upload_s(), 0.0);
  }
  const Eigen::Matrix4d truth = target.scan_to_scene.inverse() * source.scan_to_scene;
  const TransformError error =
      transform_error(source.cloud.points, to_matrix(response_of(by_curl).result().transform()), truth);
  EXPECT_LT(error.rmse_m, 0.02) << "against ground truth";

  // Spooled, then deleted once answered; the access log counts the uploaded bytes.
  EXPECT_EQ(server.spooled_files(), 0u);
  const auto lines = server.log_lines("request");
  const auto line =
      std::find_if(lines.begin(), lines.end(), [](const auto& l) { return l["request_id"] == "lab-upload"; });
  ASSERT_NE(line, lines.end());
  EXPECT_GT((*line)["upload_bytes"].get<std::uint64_t>(), source_bytes.size() + target_bytes.size());
}

TEST(HttpConfig, AnEmptyAddressDisablesHttpAndABusyPortIsFatal) {
  {
    ServerProcess server({"--http-listen", ""});
    EXPECT_EQ(health_status(server, "liveness"), "SERVING");
    const auto serving = server.log_lines("serving");
    ASSERT_EQ(serving.size(), 1u);
    EXPECT_FALSE(serving[0].contains("http_port"));
  }
  // Someone else listens on the port: the server does not start (exit 1) and says why.
  const int taken = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(bind(taken, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
  ASSERT_EQ(listen(taken, 1), 0);
  socklen_t size = sizeof address;
  getsockname(taken, reinterpret_cast<sockaddr*>(&address), &size);
  const std::string listen_address = "127.0.0.1:" + std::to_string(ntohs(address.sin_port));
  TempDir spool;
  const CommandRun run = run_command({K4REG_BIN_DIR "/k4reg-server", "--grpc-listen", "127.0.0.1:0", "--http-listen",
                                      listen_address, "--spool-dir", spool.path().string()});
  close(taken);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("cannot listen on " + listen_address + " (HTTP)"), std::string::npos) << run.err;
}

}  // namespace
}  // namespace k4reg::test
