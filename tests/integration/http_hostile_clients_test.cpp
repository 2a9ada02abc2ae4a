// The HTTP listener (--http-listen, server/http/http_server.h) against hostile clients over loopback, on the real
// server: empty, oversized, duplicated and flooded header fields, odd methods, junk after a multipart form's
// closing delimiter, stalled bodies and slow heads each cost their own connection and nothing else, within the
// listener's limits (server/http/http_connection.h), with the status that names them; and what is open without a
// token: --public-metrics, --reflection, the page's headers and the same-origin rule.
#include <grpcpp/generic/generic_stub.h>
#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <fstream>
#include <future>
#include <string>
#include <thread>
#include <vector>

#include "http/http_connection.h"
#include "raw_connection.h"
#include "test_support.h"

namespace k4reg::test {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

// The server's resident set may grow by this much while it refuses a hostile request: main grew by 72-509 MB on
// these requests; a sanitizer build's allocator keeps freed blocks in quarantine and grows by ~11 MB on any.
constexpr std::size_t kAllowedGrowthKib = 32 << 10;

// The answer's JSON error, from a raw answer ("" if it has none).
std::string body_of(const std::string& answer) {
  const std::size_t end = answer.find("\r\n\r\n");
  return end == std::string::npos ? "" : answer.substr(end + 4);
}

class HttpHostileClients : public ::testing::Test {
 protected:
  HttpHostileClients() { signal(SIGPIPE, SIG_IGN); }

  // The server still serves: /healthz on the HTTP listener and the gRPC health service.
  void expect_still_serving() {
    expect_quick_probe(server_.http_port());
    EXPECT_EQ(health_status(server_, "liveness"), "SERVING");
  }

  // Sends `request` (streaming `body_bytes` of filler after it) and returns the raw answer; the server's peak
  // resident set must not grow past kAllowedGrowthKib meanwhile.
  std::string send_without_growth(const std::string& request, std::size_t body_bytes = 0) {
    const std::size_t peak_before = peak_resident_kib(server_.pid());
    Connection connection(server_.http_port());
    connection.send_bytes(request);
    const std::string filler(1 << 16, 'j');
    for (std::size_t sent = 0; sent < body_bytes && connection.send_bytes(filler);) sent += filler.size();
    const std::string answer = connection.read_until_closed(5s);
    const std::size_t growth = peak_resident_kib(server_.pid()) - peak_before;
    EXPECT_LT(growth, kAllowedGrowthKib) << request.substr(0, 80);
    RecordProperty("peak_growth_kib", std::to_string(growth));
    return answer;
  }

  ServerProcess server_{{"--data-root", bunny_dir().string(), "--workers", "1", "--queue-size", "2",
                         "--health-listen", "127.0.0.1:0", "--max-upload-mb", "64"}};
};

TEST_F(HttpHostileClients, EmptyOversizedAndDuplicatedHeadersGetTheirStatus) {
  EXPECT_EQ(curl({"-H", "X-Empty;", server_.http_url() + "/healthz"}).status, 200);
  EXPECT_EQ(answer_status(server_.http_port(), "GET /healthz HTTP/1.1\r\nX-Blank:   \r\nHost: a\r\nHost: b\r\n\r\n"),
            200);
  const std::string big_field = "GET /healthz HTTP/1.1\r\nX-Big: " + std::string(64 << 10, 'v') + "\r\n\r\n";
  const std::string answer = send_without_growth(big_field);
  EXPECT_EQ(status_of(answer), 431) << answer;
  EXPECT_NE(body_of(answer).find("request head over"), std::string::npos) << answer;
  std::string many = "GET /healthz HTTP/1.1\r\n";
  for (std::size_t i = 0; i <= service::kMaxHeaderFields; ++i) many += "X-" + std::to_string(i) + ": v\r\n";
  EXPECT_EQ(answer_status(server_.http_port(), many + "\r\n"), 431);
  EXPECT_EQ(answer_status(server_.http_port(), "GET /" + std::string(40 << 10, 'a') + " HTTP/1.1\r\n\r\n"), 414);
  // Two Content-Lengths that disagree: refused or read by the first, never a crash or a hang.
  const int twice = answer_status(server_.http_port(),
                                  "POST /v1/register HTTP/1.1\r\nContent-Type: application/json\r\n"
                                  "Content-Length: 2\r\nContent-Length: 900000000\r\n\r\n{}");
  EXPECT_GE(twice, 400);
  EXPECT_LT(twice, 500);
  expect_still_serving();
}

TEST_F(HttpHostileClients, AHeaderFloodIsRefusedWithoutMemoryGrowth) {
  std::string flood = "GET /healthz HTTP/1.1\r\n";
  while (flood.size() < (16 << 20)) flood += "X-Flood: yyyyyyyyyyyyyyyyyyyyyyyyyyyyyyyy\r\n";
  EXPECT_EQ(status_of(send_without_growth(flood)), 431);
  expect_still_serving();
}

TEST_F(HttpHostileClients, OddMethodsAreRefusedBeforeTheirBodies) {
  // cpp-httplib would read a PRI body whole into memory: 256 MB of it must not get there.
  const std::string pri = send_without_growth(
      "PRI /v1/register HTTP/1.1\r\nContent-Length: " + std::to_string(256 << 20) + "\r\n\r\n", 256 << 20);
  EXPECT_EQ(status_of(pri), 405) << pri;
  EXPECT_NE(body_of(pri).find("not served by the HTTP listener"), std::string::npos) << pri;
  EXPECT_EQ(answer_status(server_.http_port(), "TRACE / HTTP/1.1\r\n\r\n"), 405);
  EXPECT_EQ(answer_status(server_.http_port(), "CONNECT 127.0.0.1:1 HTTP/1.1\r\n\r\n"), 405);
  EXPECT_EQ(answer_status(server_.http_port(), "JUNK / HTTP/1.1\r\n\r\n"), 400);
  EXPECT_EQ(answer_status(server_.http_port(), std::string("\0\xff\xfe junk\r\n\r\n", 12)), 400);
  EXPECT_EQ(answer_status(server_.http_port(), "PRI * HTTP/2.0\r\n\r\nSM\r\n\r\n"), 400);
  expect_still_serving();
}

TEST_F(HttpHostileClients, JunkAfterTheClosingDelimiterIs413WithoutMemoryGrowth) {
  const std::string form =
      "--b\r\nContent-Disposition: form-data; name=\"source\"; filename=\"a.ply\"\r\n\r\nply\r\n--b--\r\n";
  const std::size_t junk = 64 << 20;
  const std::string answer = send_without_growth(
      "POST /v1/register HTTP/1.1\r\nHost: x\r\nContent-Type: multipart/form-data; boundary=b\r\n"
      "Content-Length: " + std::to_string(form.size() + junk) + "\r\n\r\n" + form,
      junk);
  EXPECT_EQ(status_of(answer), 413) << answer;
  EXPECT_NE(body_of(answer).find("besides its parts' contents"), std::string::npos) << answer;
  EXPECT_EQ(server_.spooled_files(), 0u);
  expect_still_serving();
}

TEST(HttpHostileClientsWithToken, AStalledBodyIsRefusedAtOnceAndOthersGoOn) {
  ServerProcess server({"--workers", "1", "--auth-token", "s3cret"});
  Connection stalled(server.http_port());
  stalled.send_bytes("POST /v1/register HTTP/1.1\r\nHost: x\r\nContent-Type: multipart/form-data; boundary=b\r\n"
                     "Content-Length: 100000\r\n\r\n--b\r\nContent-Disposition: form-data; name=\"source\"\r\n\r\nab");
  const auto start = Clock::now();
  const std::string answer = stalled.read_until_closed(5s);
  EXPECT_EQ(status_of(answer), 401) << answer;
  EXPECT_LT(Clock::now() - start, service::kDiscardPause + 2s);
  EXPECT_TRUE(stalled.closed());
  expect_quick_probe(server.http_port());
}

// Slowloris: many more clients than the old pool's threads dribble their heads; /healthz on both listeners
// answers meanwhile, and the heads' deadline ends every slow connection.
TEST_F(HttpHostileClients, SlowHeadsNeitherStarveProbesNorOutstayTheirDeadline) {
  const int health_port = server_.log_lines("serving").at(0)["health_port"].get<int>();
  std::vector<Connection> slow;
  for (int i = 0; i < 40; ++i) slow.emplace_back(server_.http_port()).send_bytes("GET /healthz HTTP/1.1\r\nX-Slow: ");
  const auto end = Clock::now() + service::kHeadDeadline + 1s;
  for (auto next_byte = Clock::now() + 500ms; Clock::now() < end;) {
    if (Clock::now() >= next_byte) {
      for (Connection& connection : slow) connection.send_bytes("a");
      next_byte += 500ms;
    }
    expect_quick_probe(health_port);
    expect_quick_probe(server_.http_port());
    std::this_thread::sleep_for(200ms);
  }
  for (Connection& connection : slow) {
    const std::string answer = connection.read_until_closed(1s);
    EXPECT_TRUE(connection.closed()) << "a slow client outstayed the head's deadline";
    EXPECT_EQ(status_of(answer), 408) << answer;
  }
  expect_still_serving();
}

// A body of a size no route takes is refused from its Content-Length, and a chunked one once it passes the
// JSON limit, both without the server holding them.
TEST_F(HttpHostileClients, LargeStreamedBodiesAre413WithoutMemoryGrowth) {
  const std::string declared = send_without_growth(
      "POST /v1/register HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\nContent-Length: 2000000000000\r\n\r\n",
      16 << 20);
  EXPECT_EQ(status_of(declared), 413) << declared;
  EXPECT_NE(body_of(declared).find("--max-inline-mb"), std::string::npos) << declared;
  const HttpReply chunked = curl({"-H", "Content-Type: application/json", "-H", "Transfer-Encoding: chunked", "-T", "-",
                                  "-X", "POST", server_.http_url() + "/v1/register"},
                                 "head -c 200000000 /dev/zero");
  EXPECT_EQ(chunked.status, 413) << chunked.body;
  expect_still_serving();
}

TEST(HttpOpenRoutes, MetricsAndVersionAreOpenOnlyWithPublicMetrics) {
  ServerProcess server({"--workers", "1", "--auth-token", "s3cret", "--public-metrics"});
  for (const char* path : {"/metrics", "/v1/version"}) EXPECT_EQ(curl({server.http_url() + path}).status, 200) << path;
  const HttpReply registration = curl({"-X", "POST", server.http_url() + "/v1/register"});
  EXPECT_EQ(registration.status, 401) << registration.body;
}

// grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo with one request: list_services "" (field 7).
grpc::StatusCode reflection_code(const ServerProcess& server) {
  grpc::GenericStub stub(server.channel());
  grpc::ClientContext context;
  set_timeout(context, 10s);
  grpc::Slice list_services(std::string("\x3a\x00", 2));
  grpc::ByteBuffer request(&list_services, 1), response;
  std::promise<grpc::Status> done;
  stub.UnaryCall(&context, "/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo", {}, &request, &response,
                 [&done](grpc::Status status) { done.set_value(status); });
  return done.get_future().get().error_code();
}

TEST(HttpOpenRoutes, ReflectionIsOffUnlessAskedFor) {
  EXPECT_EQ(reflection_code(ServerProcess({"--workers", "1"})), grpc::StatusCode::UNIMPLEMENTED);
  EXPECT_EQ(reflection_code(ServerProcess({"--workers", "1", "--reflection"})), grpc::StatusCode::OK);
}

TEST(HttpOpenRoutes, ThePageCarriesItsSecurityHeaders) {
  ServerProcess server({"--workers", "1"});
  const HttpReply page = curl({server.http_url() + "/"});
  EXPECT_EQ(page.status, 200);
  EXPECT_NE(page.header("content-security-policy").find("frame-ancestors 'none'"), std::string::npos);
  EXPECT_EQ(page.header("x-frame-options"), "DENY");
  EXPECT_EQ(page.header("x-content-type-options"), "nosniff");
  EXPECT_EQ(curl({server.http_url() + "/healthz"}).header("x-content-type-options"), "nosniff");
}

TEST(HttpOpenRoutes, WithoutATokenCrossOriginPostsAre403) {
  ServerProcess server({"--workers", "1"});
  const std::string url = server.http_url() + "/v1/register";
  const std::string host = url.substr(7, url.find('/', 7) - 7);
  const HttpReply foreign = curl({"-H", "Origin: http://evil.example", "-H", "Content-Type: application/json",
                                  "--data", "{}", url});
  EXPECT_EQ(foreign.status, 403) << foreign.body;
  EXPECT_NE(foreign.body.find("--auth-token"), std::string::npos) << foreign.body;
  EXPECT_EQ(curl({"-H", "Origin: null", "--data", "{}", url}).status, 403);
  // Refused before "100 Continue": the body is never sent.
  EXPECT_EQ(curl({"-H", "Origin: http://evil.example", "-H", "Expect: 100-continue", "-F", "source=@/dev/null", url})
                .status,
            403);
  // The server's own page (same origin) and clients without Origin get through to the usual checks.
  EXPECT_EQ(curl({"-H", "Origin: http://" + host, "-H", "Content-Type: application/json", "--data", "{}", url}).status,
            400);
  EXPECT_EQ(curl({"-H", "Content-Type: application/json", "--data", "{}", url}).status, 400);
  // With a token, the token decides.
  ServerProcess guarded({"--workers", "1", "--auth-token", "s3cret"});
  EXPECT_EQ(curl({"-H", "Origin: http://evil.example", "--data", "{}", guarded.http_url() + "/v1/register"}).status,
            401);
}

}  // namespace
}  // namespace k4reg::test
