// The gRPC listener against large unauthenticated messages (issue 47): grpc++ 1.51 reads a whole message before
// the handler checks the token, so several large messages at once must not take the server down or its resident
// set past the memory budget; each call gets a clear status, and /healthz on the health listener answers within
// a second throughout.
#include <grpcpp/generic/generic_stub.h>
#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <mutex>
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

constexpr int kCalls = 4;
constexpr std::size_t kMessageBytes = std::size_t(100) << 20;
constexpr std::size_t kBudgetMib = 256;
// The server's peak resident set may pass the budget by this much: its own code, gRPC's and the allocator's
// (about 25 MB idle) and the copy of the one message admitted while it is parsed; gRPC's receive quota is half the
// budget and soft. Measured 340-390 MiB; main, bounded only by its 1 GiB receive limit, reached 918 MiB.
constexpr std::size_t kMarginMib = 256;
// Under AddressSanitizer the server also holds freed blocks in quarantine (256 MiB by default) and shadow memory
// (an eighth of what it maps); this allowance for them is reasoned, not measured.
#if defined(__SANITIZE_ADDRESS__)
constexpr std::size_t kSanitizerMib = 320;
#elif defined(__has_feature)
constexpr std::size_t kSanitizerMib = __has_feature(address_sanitizer) ? 320 : 0;
#else
constexpr std::size_t kSanitizerMib = 0;
#endif

// A serialized RegisterRequest whose source is an inline cloud of `bytes` bytes.
std::string large_register_request(std::size_t bytes) {
  v1::RegisterRequest request;
  request.mutable_source()->mutable_inline_cloud()->mutable_data()->assign(bytes, 'x');
  request.mutable_target()->set_path("bun000.ply");
  return request.SerializeAsString();
}

// Sends `message` as a Register call without a token on a connection of its own; the call's status.
grpc::Status unauthenticated_call(const std::string& address, const std::string& message) {
  grpc::ChannelArguments arguments;
  arguments.SetInt(GRPC_ARG_USE_LOCAL_SUBCHANNEL_POOL, 1);  // a connection per call
  arguments.SetMaxReceiveMessageSize(-1);
  grpc::GenericStub stub(grpc::CreateCustomChannel(address, grpc::InsecureChannelCredentials(), arguments));
  grpc::ClientContext context;
  set_timeout(context, 120s);
  grpc::Slice slice(message.data(), message.size(), grpc::Slice::STATIC_SLICE);
  grpc::ByteBuffer request(&slice, 1), reply;
  grpc::CompletionQueue queue;
  auto call = stub.PrepareUnaryCall(&context, "/k4reg.v1.Registration/Register", request, &queue);
  call->StartCall();
  grpc::Status status;
  call->Finish(&reply, &status, reinterpret_cast<void*>(1));
  void* tag = nullptr;
  bool ok = false;
  queue.Next(&tag, &ok);
  queue.Shutdown();
  while (queue.Next(&tag, &ok)) {
  }
  return status;
}

// GET /healthz on the health listener every 100 ms while it lives: the worst latency, and probes not answered 200.
class HealthProber {
 public:
  explicit HealthProber(int port)
      : thread_([this, port] {
          while (!done_) {
            const Probe probe = probe_healthz(port);
            if (probe.status != 200) ++failed_;
            worst_ = std::max(worst_.load(), probe.took.count());
            std::this_thread::sleep_for(100ms);
          }
        }) {}
  ~HealthProber() { stop(); }
  void stop() {
    done_ = true;
    if (thread_.joinable()) thread_.join();
  }
  int failed() const { return failed_; }
  std::chrono::milliseconds worst() const {
    return std::chrono::duration_cast<std::chrono::milliseconds>(Clock::duration(worst_.load()));
  }

 private:
  std::atomic<bool> done_ = false;
  std::atomic<int> failed_ = 0;
  std::atomic<Clock::duration::rep> worst_ = 0;
  std::thread thread_;
};

// Runs `call(i)` for i < count on threads of their own; what they returned.
template <typename Result>
std::vector<Result> concurrently(int count, const std::function<Result(int)>& call) {
  std::vector<Result> results(count);
  std::vector<std::thread> threads;
  for (int i = 0; i < count; ++i) threads.emplace_back([&, i] { results[i] = call(i); });
  for (std::thread& thread : threads) thread.join();
  return results;
}

int health_port_of(const ServerProcess& server) { return server.log_lines("serving").at(0)["health_port"].get<int>(); }

TEST(GrpcHostileClients, ConcurrentLargeUnauthenticatedMessagesStayWithinTheBudget) {
  signal(SIGPIPE, SIG_IGN);
  ServerProcess server({"--auth-token", "s3cret", "--memory-budget-mb", std::to_string(kBudgetMib),
                        "--health-listen", "127.0.0.1:0"});
  const std::string message = large_register_request(kMessageBytes);
  HealthProber prober(health_port_of(server));
  const std::vector<grpc::Status> statuses = concurrently<grpc::Status>(
      kCalls, [&](int) { return unauthenticated_call(server.address(), message); });
  prober.stop();

  for (const grpc::Status& status : statuses) {
    // Refused, never accepted nor cut: the token's absence, or the receive budget, named.
    EXPECT_TRUE(status.error_code() == grpc::StatusCode::UNAUTHENTICATED ||
                status.error_code() == grpc::StatusCode::RESOURCE_EXHAUSTED)
        << status.error_code() << " " << status.error_message();
  }
  EXPECT_EQ(prober.failed(), 0);
  const std::chrono::milliseconds worst = prober.worst();
  EXPECT_LT(worst, 1s) << worst.count() << " ms";
  const std::size_t peak_mib = peak_resident_kib(server.pid()) >> 10;
  EXPECT_LT(peak_mib, kBudgetMib + kMarginMib + kSanitizerMib);
  RecordProperty("peak_rss_mib", std::to_string(peak_mib));
  RecordProperty("worst_probe_ms", std::to_string(worst.count()));
  EXPECT_EQ(health_status(server, "liveness"), "SERVING");
  // An authorized call still goes through afterwards.
  grpc::ClientContext context;
  set_timeout(context, 60s);
  context.AddMetadata("authorization", "Bearer s3cret");
  v1::RegisterRequest request = sphere_request();
  v1::RegisterResponse reply;
  EXPECT_TRUE(has_status(server.stub()->Register(&context, request, &reply), grpc::StatusCode::FAILED_PRECONDITION, ""));
}


// "3 x 431, 1 x 0": how many clients got each answer.
std::string tally(const std::vector<std::string>& answers) {
  std::map<std::string, int> counts;
  for (const std::string& answer : answers) ++counts[answer];
  std::string text;
  for (const auto& [answer, count] : counts) text += (text.empty() ? "" : ", ") + std::to_string(count) + " x " + answer;
  return text;
}

std::string http_status_name(const std::string& answer) {
  const int status = status_of(answer);
  return status == 0 ? "no answer" : "HTTP " + std::to_string(status);
}

// Sends `head`, then `body_bytes` of filler (as 1 MiB chunks if `chunked`); the answer's status.
std::string send_body(int port, const std::string& head, std::size_t body_bytes, bool chunked) {
  Connection connection(port);
  connection.send_bytes(head);
  const std::string filler(1 << 20, 'j');
  const std::string chunk = chunked ? "100000\r\n" + filler + "\r\n" : filler;
  for (std::size_t sent = 0; sent < body_bytes && connection.send_bytes(chunk);) sent += filler.size();
  return http_status_name(connection.read_until_closed(30s));
}

// bench/hostile_clients.sh: the hostile sequences against a server with --memory-budget-mb 512 and a token; per
// sequence, the server's peak resident set (VmHWM, reset before each) and the worst /healthz latency on the
// health listener (probed every 100 ms), as a Markdown table. Skipped unless K4REG_HOSTILE_BENCH is set.
TEST(HostileClientsBench, Sequences) {
  if (!std::getenv("K4REG_HOSTILE_BENCH")) GTEST_SKIP() << "set K4REG_HOSTILE_BENCH=1 (bench/hostile_clients.sh)";
  signal(SIGPIPE, SIG_IGN);
  ServerProcess server({"--auth-token", "s3cret", "--memory-budget-mb", "512", "--health-listen", "127.0.0.1:0"});
  const int http = server.http_port();
  std::cout << "| sequence | peak RSS (MB) | worst probe (ms) | failed probes | what each client got |\n"
            << "|---|---:|---:|---:|---|\n";
  std::size_t overall_peak_kib = 0;
  auto measure = [&](const std::string& name, const std::function<std::string()>& sequence) {
    std::ofstream("/proc/" + std::to_string(server.pid()) + "/clear_refs") << "5";  // resets VmHWM
    HealthProber prober(health_port_of(server));
    const std::string got = sequence();
    prober.stop();
    const std::size_t peak_kib = peak_resident_kib(server.pid());
    overall_peak_kib = std::max(overall_peak_kib, peak_kib);
    std::cout << "| " << name << " | " << (peak_kib * 1024) / 1'000'000 << " | " << prober.worst().count() << " | "
              << prober.failed() << " | " << got << " |" << std::endl;
    EXPECT_EQ(prober.failed(), 0) << name;
    EXPECT_EQ(health_status(server, "liveness"), "SERVING") << name;
  };

  measure("idle (baseline)", [] {
    std::this_thread::sleep_for(1s);
    return std::string("-");
  });
  measure("header floods: 8 at once, 16 MB of header fields each", [&] {
    std::string flood = "GET /healthz HTTP/1.1\r\n";
    while (flood.size() < (16 << 20)) flood += "X-Flood: yyyyyyyyyyyyyyyyyyyyyyyyyyyyyyyy\r\n";
    return tally(concurrently<std::string>(8, [&](int) { return send_body(http, flood, 0, false); }));
  });
  measure("oversized bodies: 4 x Content-Length 2 TB (64 MB sent) + 4 x chunked 512 MB, no token", [&] {
    return tally(concurrently<std::string>(8, [&](int i) {
      const std::string json = "POST /v1/register HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n";
      return i < 4 ? send_body(http, json + "Content-Length: 2000000000000\r\n\r\n", 64 << 20, false)
                   : send_body(http, json + "Transfer-Encoding: chunked\r\n\r\n", 512 << 20, true);
    }));
  });
  measure("the same 8 bodies with the token", [&] {
    return tally(concurrently<std::string>(8, [&](int i) {
      const std::string json =
          "POST /v1/register HTTP/1.1\r\nHost: x\r\nAuthorization: Bearer s3cret\r\nContent-Type: application/json\r\n";
      return i < 4 ? send_body(http, json + "Content-Length: 2000000000000\r\n\r\n", 64 << 20, false)
                   : send_body(http, json + "Transfer-Encoding: chunked\r\n\r\n", 512 << 20, true);
    }));
  });
  measure("multipart junk: 4 x 256 MB after the closing delimiter, with the token", [&] {
    const std::string form =
        "--b\r\nContent-Disposition: form-data; name=\"source\"; filename=\"a.ply\"\r\n\r\nply\r\n--b--\r\n";
    const std::size_t junk = 256 << 20;
    const std::string head = "POST /v1/register HTTP/1.1\r\nHost: x\r\nAuthorization: Bearer s3cret\r\n"
                             "Content-Type: multipart/form-data; boundary=b\r\nContent-Length: " +
                             std::to_string(form.size() + junk) + "\r\n\r\n" + form;
    return tally(concurrently<std::string>(4, [&](int) { return send_body(http, head, junk, false); }));
  });
  measure("slow clients: 50 HTTP heads dribbling a byte per 500 ms + 50 gRPC connections idle after the preface", [&] {
    std::vector<Connection> slow, grpc_idle;
    for (int i = 0; i < 50; ++i) slow.emplace_back(http).send_bytes("GET /healthz HTTP/1.1\r\nX-Slow: ");
    for (int i = 0; i < 50; ++i) grpc_idle.emplace_back(server.port()).send_bytes("PRI * HTTP/2.0\r\n\r\nSM\r\n\r\n");
    const auto end = Clock::now() + service::kHeadDeadline + 2s;
    while (Clock::now() < end) {
      for (Connection& connection : slow) connection.send_bytes("a");
      std::this_thread::sleep_for(500ms);
    }
    std::vector<std::string> got;
    for (Connection& connection : slow) got.push_back(http_status_name(connection.read_until_closed(1s)));
    int open = 0;
    for (Connection& connection : grpc_idle) {
      connection.read_until_closed(10ms);
      if (!connection.closed()) ++open;
    }
    return "HTTP: " + tally(got) + "; gRPC: " + std::to_string(open) + " of 50 still open (idle, no stream)";
  });
  for (const std::size_t mb : {200, 900}) {
    measure("large unauthenticated gRPC Register: 4 x " + std::to_string(mb) + " MB at once", [&] {
      const std::string message = large_register_request(mb * 1'000'000);
      std::vector<std::string> got;
      for (const grpc::Status& status : concurrently<grpc::Status>(
               4, [&](int) { return unauthenticated_call(server.address(), message); }))
        got.push_back("code " + std::to_string(status.error_code()) + " (" + status.error_message() + ")");
      return tally(got);
    });
  }
  std::cout << "overall peak RSS " << (overall_peak_kib * 1024) / 1'000'000 << " MB" << std::endl;
}

}  // namespace
}  // namespace k4reg::test
