// The health listener (--health-listen, server/observability/health_listener.h) against hostile clients over
// loopback, on the real server: odd, malformed and oversized requests get their status and cost nothing else,
// and slow or idle connections never keep GET /healthz from answering within a second. Its request parser
// (server/observability/health_request.h) on its own first.
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include "observability/health_listener.h"
#include "observability/health_request.h"
#include "raw_connection.h"
#include "test_support.h"

namespace k4reg::test {
namespace {

using namespace std::chrono_literals;
using namespace std::string_view_literals;
using Clock = std::chrono::steady_clock;
using service::HealthRequestHead;
using service::parse_health_request;
using State = HealthRequestHead::State;

TEST(HealthRequest, ParsesAHeadAndRefusesWhatIsNotOne) {
  const HealthRequestHead probe =
      parse_health_request("GET /readyz?verbose HTTP/1.1\r\nHost: x\r\nX-Empty:\r\nX-Blank: \t \r\n\r\nbody");
  ASSERT_EQ(probe.state, State::kComplete) << probe.refusal;
  EXPECT_EQ(probe.method, "GET");
  EXPECT_EQ(probe.path, "/readyz");
  const std::vector<std::pair<std::string, std::string>> fields{{"Host", "x"}, {"X-Empty", ""}, {"X-Blank", ""}};
  EXPECT_EQ(probe.fields, fields);
  EXPECT_EQ(parse_health_request("GET /healthz HTTP/1.0\n\n").state, State::kComplete);  // bare LF
  EXPECT_EQ(parse_health_request("GET /healthz HTTP/1.1\r\nHost: x\r\n").state, State::kIncomplete);
  EXPECT_EQ(parse_health_request("").state, State::kIncomplete);

  const struct {
    std::string_view head;
    int status;
  } refused[] = {
      {"\r\n\r\n", 400},
      {"GET /healthz\r\n\r\n", 400},
      {"GET  /healthz HTTP/1.1\r\n\r\n", 400},
      {"GET /healthz HTTP/1.1 \r\n\r\n", 400},
      {"G(T /healthz HTTP/1.1\r\n\r\n", 400},
      {"GET /health\x7fz HTTP/1.1\r\n\r\n", 400},
      {"GET /healthz HTTP/1.1\r\nNoColon\r\n\r\n", 400},
      {"GET /healthz HTTP/1.1\r\n: no name\r\n\r\n", 400},
      {"GET /healthz HTTP/1.1\r\nName : space before the colon\r\n\r\n", 400},
      {"GET /healthz HTTP/1.1\r\nX-A: 1\r\n folded\r\n\r\n", 400},
      {"GET /healthz HTTP/1.1\r\nX-Nul: a\0b\r\n\r\n"sv, 400},
      {"GET /healthz HTTP/1.1\r\nX-Cr: a\rb\r\n\r\n", 400},
      {"\0\xff\xfe junk\r\n\r\n"sv, 400},
  };
  for (const auto& [head, status] : refused) {
    const HealthRequestHead parsed = parse_health_request(head);
    EXPECT_EQ(parsed.state, State::kRefused) << head;
    EXPECT_EQ(parsed.refusal_status, status) << head;
  }
}

TEST(HealthRequest, BoundsTheRequestLineTheFieldsAndTheHead) {
  const auto request_line = [](std::size_t bytes) {
    return "GET /" + std::string(bytes - std::string_view("GET / HTTP/1.1").size(), 'a') + " HTTP/1.1\r\n";
  };
  EXPECT_EQ(parse_health_request(request_line(service::kMaxHealthRequestLineBytes) + "\r\n").state, State::kComplete);
  EXPECT_EQ(parse_health_request(request_line(service::kMaxHealthRequestLineBytes + 1) + "\r\n").refusal_status, 414);
  // A request line that never ends is refused once it passes the head's limit.
  EXPECT_EQ(parse_health_request("GET /" + std::string(service::kMaxHealthHeadBytes, 'a')).refusal_status, 414);

  std::string fields = "GET /healthz HTTP/1.1\r\n";
  for (std::size_t i = 0; i < service::kMaxHealthHeaderFields; ++i) fields += "X-" + std::to_string(i) + ": v\r\n";
  EXPECT_EQ(parse_health_request(fields + "\r\n").state, State::kComplete);
  EXPECT_EQ(parse_health_request(fields + "X-One-More: v\r\n\r\n").refusal_status, 431);

  const std::string big_field = "GET /healthz HTTP/1.1\r\nX-Big: " + std::string(service::kMaxHealthHeadBytes, 'v');
  EXPECT_EQ(parse_health_request(big_field).refusal_status, 431);
  EXPECT_EQ(parse_health_request(big_field + "\r\n\r\n").refusal_status, 431);
}

// The server still serves: a probe on the health listener and the gRPC health service on the API port.
void expect_still_serving(const ServerProcess& server, int port) {
  expect_quick_probe(port);
  EXPECT_EQ(health_status(server, "liveness"), "SERVING");
}

class HealthListenerClients : public ::testing::Test {
 protected:
  ServerProcess server_{{"--health-listen", "127.0.0.1:0"}};
  const int port_ = server_.log_lines("serving").at(0)["health_port"].get<int>();
};

TEST_F(HealthListenerClients, EmptyHeaderValuesAreAnsweredAndTheServerStaysUp) {
  // What curl sends for -H 'X-Empty;': "X-Empty:" with nothing after the colon.
  EXPECT_EQ(curl({"-H", "X-Empty;", "http://127.0.0.1:" + std::to_string(port_) + "/healthz"}).status, 200);
  EXPECT_EQ(answer_status(port_, "GET /healthz HTTP/1.1\r\nX-Blank:   \r\n\r\n"), 200);
  expect_still_serving(server_, port_);
}

TEST_F(HealthListenerClients, OddAndMalformedRequestsGetTheirStatus) {
  const struct {
    std::string_view request;
    int status;
  } cases[] = {
      {"FOO /healthz HTTP/1.1\r\n\r\n", 405},
      {"PRI /healthz HTTP/1.1\r\n\r\n", 405},
      {"POST /readyz HTTP/1.1\r\nContent-Length: 5\r\n\r\nhello", 405},
      {"PRI * HTTP/1.1\r\n\r\n", 404},
      {"GET /metrics HTTP/1.1\r\n\r\n", 404},
      {"GET /healthz HTTP/1.1\r\nNoColon\r\n\r\n", 400},
      {"GET /healthz HTTP/1.1\r\nX-A: 1\r\n folded\r\n\r\n", 400},
      {"GET /healthz HTTP/1.1\r\nX-Nul: a\0b\r\n\r\n"sv, 400},
      {"\0\xff\xfe junk\r\n\r\n"sv, 400},
      {"hello\n\n", 400},
      {"GET /healthz HTTP/1.1\n\n", 200},
      {"HEAD /healthz HTTP/1.0\r\n\r\n", 200},
  };
  for (const auto& [request, status] : cases) EXPECT_EQ(answer_status(port_, request), status) << request;
  expect_still_serving(server_, port_);
}

TEST_F(HealthListenerClients, OversizedHeadsGet414Or431) {
  std::string many_fields = "GET /healthz HTTP/1.1\r\n";
  for (int i = 0; i < 40; ++i) many_fields += "X-" + std::to_string(i) + ": v\r\n";
  EXPECT_EQ(answer_status(port_, many_fields + "\r\n"), 431);
  EXPECT_EQ(answer_status(port_, "GET /healthz HTTP/1.1\r\nX-Big: " + std::string(20 << 10, 'v') + "\r\n\r\n"), 431);
  std::string flood = "GET /healthz HTTP/1.1\r\n";
  while (flood.size() < (1 << 20)) flood += "X-Flood: y\r\n";
  EXPECT_EQ(answer_status(port_, flood), 431);
  EXPECT_EQ(answer_status(port_, "GET /" + std::string(2 << 10, 'a') + " HTTP/1.1\r\n\r\n"), 414);
  EXPECT_EQ(answer_status(port_, "GET /" + std::string(9 << 10, 'a')), 414);  // a request line that never ends
  expect_still_serving(server_, port_);
}

// Slowloris: clients that send a byte every half second, on the HTTP path and as a gRPC preface, hold only
// their own connections, and only until the listener's deadline.
TEST_F(HealthListenerClients, SlowClientsNeitherDelayProbesNorOutstayTheDeadline) {
  std::vector<Connection> slow;
  for (int i = 0; i < 6; ++i) slow.emplace_back(port_).send_bytes("GET /healthz HTTP/1.1\r\nX-Slow: ");
  for (int i = 0; i < 2; ++i) slow.emplace_back(port_).send_bytes("PRI * HT");
  const auto end = Clock::now() + service::HealthListener::kRequestDeadline + 1s;
  for (auto next_byte = Clock::now() + 500ms; Clock::now() < end;) {
    if (Clock::now() >= next_byte) {
      for (Connection& connection : slow) connection.send_bytes("a");
      next_byte += 500ms;
    }
    expect_quick_probe(port_);
    std::this_thread::sleep_for(100ms);
  }
  for (Connection& connection : slow) {
    connection.read_until_closed(500ms);
    EXPECT_TRUE(connection.closed()) << "a slow client outstayed the deadline";
  }
  expect_still_serving(server_, port_);
}

// 50 idle connections, fewer than the listener serves at once; then twice as many as it serves, and the oldest
// make room for the probes.
TEST_F(HealthListenerClients, IdleConnectionsDoNotLockProbesOut) {
  std::vector<Connection> idle;
  for (const std::size_t count : {std::size_t(50), 2 * service::HealthListener::kMaxConnections}) {
    while (idle.size() < count) idle.emplace_back(port_);
    for (int i = 0; i < 3; ++i) {
      expect_quick_probe(port_);
      std::this_thread::sleep_for(100ms);
    }
  }
  expect_still_serving(server_, port_);
}

}  // namespace
}  // namespace k4reg::test
