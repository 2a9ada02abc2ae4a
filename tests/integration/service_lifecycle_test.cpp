// Queueing, cancellation, deadlines and draining against the real server. Slow jobs are made slow
// deterministically (many 4PCS bases); the tests synchronise on the server's own progress events
// ("queued", stage started), not on sleeps.
#include <gtest/gtest.h>
#include <signal.h>

#include <future>
#include <thread>

#include "test_support.h"

namespace k4reg::test {
namespace {

using namespace std::chrono_literals;

grpc::Status register_once(const ServerProcess& server, const v1::RegistrationParams& params,
                           v1::RegisterResponse& reply, std::chrono::milliseconds timeout = 120s) {
  grpc::ClientContext context;
  set_timeout(context, timeout);
  return server.stub()->Register(&context, bunny_request(params), &reply);
}

std::vector<std::string> request_codes(const ServerProcess& server) {
  std::vector<std::string> codes;
  for (const auto& line : server.log_lines("request")) codes.push_back(line["code"]);
  return codes;
}

// Polls for server-side state that follows a client action asynchronously (a signal, a cancellation).
bool becomes(const ServerProcess& server, const std::string& service, const std::string& status) {
  for (auto end = std::chrono::steady_clock::now() + 10s; std::chrono::steady_clock::now() < end;
       std::this_thread::sleep_for(20ms))
    if (health_status(server, service) == status) return true;
  return false;
}

TEST(Queue, FullQueueIsResourceExhaustedAtOnceAndReadinessDrops) {
  ServerProcess server({"--data-root", bunny_dir().string(), "--workers", "1", "--queue-size", "1"});
  auto stub = server.stub();
  auto running_context = context_with_deadline(), queued_context = context_with_deadline();
  StreamCall running(*stub, *running_context, bunny_reference_header(slow_params(3)), {});
  ASSERT_TRUE(running.wait_for_stage("load", v1::StageEvent::PHASE_STARTED));
  StreamCall queued(*stub, *queued_context, bunny_reference_header(quick_params()), {});
  ASSERT_TRUE(queued.wait_for_queued());
  EXPECT_EQ(queued.events().back().queued().position(), 0u);

  EXPECT_EQ(health_status(server, "readiness"), "NOT_SERVING");
  EXPECT_EQ(health_status(server, "liveness"), "SERVING");
  const auto start = std::chrono::steady_clock::now();
  v1::RegisterResponse reply;
  EXPECT_TRUE(has_status(register_once(server, quick_params(), reply), grpc::StatusCode::RESOURCE_EXHAUSTED,
                         "--queue-size"));
  EXPECT_LT(std::chrono::steady_clock::now() - start, 1s);

  // Nothing accepted is lost.
  EXPECT_TRUE(running.finish().ok());
  ASSERT_NE(running.result(), nullptr);
  EXPECT_TRUE(queued.finish().ok());
  ASSERT_NE(queued.result(), nullptr);
  EXPECT_GT(queued.result()->timings().queue_wait_s(), 0.5);
  EXPECT_EQ(health_status(server, "readiness"), "SERVING");
}

TEST(Queue, BurstBeyondTheQueueLosesNoAcceptedJob) {
  ServerProcess server({"--data-root", bunny_dir().string(), "--workers", "1", "--queue-size", "2"});
  constexpr int kCalls = 8;
  std::vector<std::future<std::pair<grpc::Status, v1::RegisterResponse>>> calls;
  for (int i = 0; i < kCalls; ++i)
    calls.push_back(std::async(std::launch::async, [&] {
      v1::RegisterResponse reply;
      grpc::Status status = register_once(server, bunny_params(), reply);
      return std::make_pair(status, reply);
    }));
  int ok = 0, exhausted = 0;
  for (auto& call : calls) {
    const auto [status, reply] = call.get();
    if (status.ok()) {
      ++ok;
      EXPECT_EQ(reply.result().transform_size(), 16);
    } else {
      EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << status.error_message();
      ++exhausted;
    }
  }
  EXPECT_EQ(ok + exhausted, kCalls);
  EXPECT_GE(ok, 1);
  EXPECT_GE(exhausted, 1);
  const std::vector<std::string> codes = request_codes(server);
  EXPECT_EQ(std::count(codes.begin(), codes.end(), "OK"), ok);
  EXPECT_EQ(std::count(codes.begin(), codes.end(), "RESOURCE_EXHAUSTED"), exhausted);
}

TEST(Cancellation, CancellingARunningJobFreesTheWorker) {
  ServerProcess server({"--data-root", bunny_dir().string(), "--workers", "1"});
  auto stub = server.stub();
  auto context = context_with_deadline();
  StreamCall slow(*stub, *context, bunny_reference_header(slow_params(120)), {});
  ASSERT_TRUE(slow.wait_for_stage("matching", v1::StageEvent::PHASE_STARTED));
  context->TryCancel();
  EXPECT_EQ(slow.finish().error_code(), grpc::StatusCode::CANCELLED);

  v1::RegisterResponse reply;
  ASSERT_TRUE(register_once(server, quick_params(), reply).ok());
  // The worker was free almost at once: the core polls the token every few milliseconds.
  EXPECT_LT(reply.timings().queue_wait_s(), 0.5);
  EXPECT_EQ(request_codes(server), (std::vector<std::string>{"CANCELLED", "OK"}));
}

TEST(Cancellation, CancellingAQueuedJobTakesItOutOfTheQueue) {
  ServerProcess server({"--data-root", bunny_dir().string(), "--workers", "1", "--queue-size", "1"});
  auto stub = server.stub();
  auto running_context = context_with_deadline(), queued_context = context_with_deadline();
  StreamCall running(*stub, *running_context, bunny_reference_header(slow_params(120)), {});
  ASSERT_TRUE(running.wait_for_stage("load", v1::StageEvent::PHASE_STARTED));
  StreamCall queued(*stub, *queued_context, bunny_reference_header(quick_params()), {});
  ASSERT_TRUE(queued.wait_for_queued());
  queued_context->TryCancel();
  EXPECT_EQ(queued.finish().error_code(), grpc::StatusCode::CANCELLED);
  // Its slot is free again while the first job still runs.
  ASSERT_TRUE(becomes(server, "readiness", "SERVING"));
  auto next_context = context_with_deadline();
  StreamCall next(*stub, *next_context, bunny_reference_header(quick_params()), {});
  ASSERT_TRUE(next.wait_for_queued());
  running_context->TryCancel();
  EXPECT_EQ(running.finish().error_code(), grpc::StatusCode::CANCELLED);
  EXPECT_TRUE(next.finish().ok());
  const auto lines = server.log_lines("request");
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0]["error"], "cancelled while queued");
}

TEST(Deadline, AnExpiredDeadlineStopsTheJob) {
  ServerProcess server({"--data-root", bunny_dir().string(), "--workers", "1"});
  v1::RegisterResponse reply;
  EXPECT_EQ(register_once(server, slow_params(120), reply, 1500ms).error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  ASSERT_TRUE(register_once(server, quick_params(), reply).ok());
  EXPECT_LT(reply.timings().queue_wait_s(), 0.5);
  const std::vector<std::string> codes = request_codes(server);
  ASSERT_EQ(codes.size(), 2u);
  EXPECT_TRUE(codes[0] == "DEADLINE_EXCEEDED" || codes[0] == "CANCELLED") << codes[0];
}

TEST(Drain, SigtermLetsTheRunningJobFinishRefusesNewWorkAndExitsZero) {
  ServerProcess server({"--data-root", bunny_dir().string(), "--workers", "1", "--drain-grace-s", "60"});
  const std::string source = read_file(bunny_dir() / "bun045.ply"), target = read_file(bunny_dir() / "bun000.ply");
  auto stub = server.stub();
  auto context = context_with_deadline();
  StreamCall running(*stub, *context, upload_header("bun045.ply", source, "bun000.ply", target, slow_params(3)),
                     {source, target});
  ASSERT_TRUE(running.wait_for_stage("load", v1::StageEvent::PHASE_FINISHED));

  server.signal(SIGTERM);
  ASSERT_TRUE(becomes(server, "readiness", "NOT_SERVING"));
  EXPECT_EQ(health_status(server, ""), "NOT_SERVING");
  EXPECT_EQ(health_status(server, "liveness"), "SERVING");
  v1::RegisterResponse reply;
  EXPECT_TRUE(has_status(register_once(server, quick_params(), reply), grpc::StatusCode::UNAVAILABLE, "draining"));

  const grpc::Status status = running.finish();
  EXPECT_TRUE(status.ok()) << status.error_message();
  ASSERT_NE(running.result(), nullptr);
  EXPECT_EQ(server.wait(), 0);
  EXPECT_EQ(server.log_lines("draining").size(), 1u);
  EXPECT_EQ(server.log_lines("stopped").size(), 1u);
  // The per-process spool folder is gone with the process.
  EXPECT_TRUE(fs::is_empty(server.spool_parent() / "spool"));
}

TEST(Drain, JobsOverTheGracePeriodAreCancelled) {
  ServerProcess server({"--data-root", bunny_dir().string(), "--workers", "1", "--drain-grace-s", "0.5"});
  auto stub = server.stub();
  auto context = context_with_deadline();
  StreamCall running(*stub, *context, bunny_reference_header(slow_params(120)), {});
  ASSERT_TRUE(running.wait_for_stage("matching", v1::StageEvent::PHASE_STARTED));
  const auto start = std::chrono::steady_clock::now();
  server.signal(SIGINT);
  EXPECT_EQ(running.finish().error_code(), grpc::StatusCode::CANCELLED);
  EXPECT_EQ(server.wait(), 0);
  EXPECT_LT(std::chrono::steady_clock::now() - start, 10s);
}

}  // namespace
}  // namespace k4reg::test
