// The server's building blocks in-process: checksum, path policy, spool, queue, memory budget, parameter
// conversion and status mapping.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <future>
#include <thread>

#include "k4reg/util/crc32c.h"
#include "jobs/job_queue.h"
#include "k4reg/util/error.h"
#include "jobs/memory_budget.h"
#include "security/path_policy.h"
#include "api/proto_convert.h"
#include "jobs/spool.h"
#include "api/status_mapping.h"
#include "test_support.h"

namespace k4reg::test {
namespace {

using namespace std::chrono_literals;
using service::JobQueue;

ErrorCode code_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.code();
  }
  return ErrorCode::kInternal;  // "did not throw" (kInternal is never expected here)
}

TEST(Crc32c, KnownValues) {
  EXPECT_EQ(crc32c(""), 0x00000000u);
  EXPECT_EQ(crc32c("123456789"), 0xE3069283u);  // the standard check value of CRC-32C
  EXPECT_EQ(crc32c(std::string(32, '\0')), 0x8A9136AAu);  // RFC 3720 B.4
  EXPECT_EQ(crc32c(std::string(32, '\xFF')), 0x62A8AB43u);
  // Pieces of any size give the same value as the whole.
  std::string data(100000, '\0');
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<char>(i * 7 + i / 251);
  Crc32c pieces;
  for (std::size_t offset = 0, step = 1; offset < data.size(); offset += step, step = step * 3 % 1013 + 1)
    pieces.update(std::string_view(data).substr(offset, step));
  EXPECT_EQ(pieces.value(), crc32c(data));
}

class PathPolicyTest : public ::testing::Test {
 protected:
  PathPolicyTest() {
    fs::create_directories(root_ / "scans");
    fs::create_directory(dir_.path() / "outside");
    write_file(root_ / "scans" / "a.ply", "x");
    write_file(dir_.path() / "outside" / "secret.ply", "x");
    fs::create_directory_symlink(dir_.path() / "outside", root_ / "link-out");
    fs::create_symlink(root_ / "scans" / "a.ply", root_ / "link-in.ply");
    fs::create_directory(dir_.path() / "root-sibling");
    write_file(dir_.path() / "root-sibling" / "b.ply", "x");
  }
  TempDir dir_;
  fs::path root_ = dir_.path() / "root";
  bool made_ = fs::create_directory(root_);
};

TEST_F(PathPolicyTest, ResolvesInsideAndRefusesEverythingElse) {
  const service::PathPolicy policy({root_.string()});
  const std::string a = fs::canonical(root_ / "scans" / "a.ply").string();
  EXPECT_EQ(policy.resolve("scans/a.ply"), a);
  EXPECT_EQ(policy.resolve((root_ / "scans" / "a.ply").string()), a);
  EXPECT_EQ(policy.resolve("scans/../scans/./a.ply"), a);
  EXPECT_EQ(policy.resolve("link-in.ply"), a);  // a symlink that stays inside is fine
  for (const std::string& path : {std::string("../outside/secret.ply"), std::string("link-out/secret.ply"),
                                  std::string("/etc/passwd"), std::string("../root-sibling/b.ply"),
                                  (dir_.path() / "outside" / "secret.ply").string(), std::string("../../../../etc/passwd")})
    EXPECT_EQ(code_of([&] { policy.resolve(path); }), ErrorCode::kPermissionDenied) << path;
  EXPECT_EQ(code_of([&] { policy.resolve("scans/missing.ply"); }), ErrorCode::kNotFound);
  EXPECT_EQ(code_of([&] { policy.resolve("link-out/missing.ply"); }), ErrorCode::kPermissionDenied);
  EXPECT_EQ(code_of([&] { policy.resolve("scans"); }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code_of([&] { policy.resolve(""); }), ErrorCode::kInvalidArgument);
  // A root "/x/root" does not contain "/x/root-sibling".
  EXPECT_EQ(code_of([&] { policy.resolve((dir_.path() / "root-sibling" / "b.ply").string()); }),
            ErrorCode::kPermissionDenied);
}

TEST_F(PathPolicyTest, TriesRootsInOrderAndNeedsAtLeastOne) {
  const service::PathPolicy policy({(dir_.path() / "outside").string(), root_.string()});
  EXPECT_EQ(policy.resolve("scans/a.ply"), fs::canonical(root_ / "scans" / "a.ply").string());
  EXPECT_EQ(policy.resolve("secret.ply"), fs::canonical(dir_.path() / "outside" / "secret.ply").string());
  EXPECT_EQ(code_of([] { service::PathPolicy({}).resolve("a.ply"); }), ErrorCode::kPermissionDenied);
  EXPECT_EQ(code_of([&] { service::PathPolicy({(root_ / "nope").string()}); }), ErrorCode::kInvalidArgument);
}

TEST(Spool, FilesVanishWhenDroppedAndStaleFoldersAtStartUp) {
  TempDir parent;
  std::string prefix;
  {
    service::SpoolDir spool(parent.path());
    const std::string name = spool.path().filename().string();
    prefix = name.substr(0, name.rfind('-') + 1);  // k4reg-spool-<host>-
    auto file = spool.create("../../evil name.PLY");
    EXPECT_EQ(file->path().find(".."), std::string::npos);
    EXPECT_EQ(fs::path(file->path()).extension(), ".PLY");
    file->append("hello ");
    file->append("world");
    file->close();
    EXPECT_EQ(file->size(), 11u);
    EXPECT_EQ(file->crc32c(), crc32c("hello world"));
    EXPECT_EQ(read_file(file->path()), "hello world");
    const std::string path = file->path();
    file.reset();
    EXPECT_FALSE(fs::exists(path));
  }
  EXPECT_TRUE(fs::is_empty(parent.path()));  // the process folder goes with the SpoolDir

  // A folder of a dead process of this host goes at start-up; a live one's stays.
  const pid_t child = fork();
  if (child == 0) _exit(0);
  waitpid(child, nullptr, 0);
  const fs::path dead = parent.path() / (prefix + std::to_string(child));
  const fs::path alive = parent.path() / (prefix + std::to_string(getppid()));
  fs::create_directory(dead);
  write_file(dead / "upload-1.ply", "left over");
  fs::create_directory(alive);
  const service::SpoolDir spool(parent.path());
  EXPECT_FALSE(fs::exists(dead));
  EXPECT_TRUE(fs::exists(alive));
}

TEST(JobQueueTest, BoundedWithdrawableAndDraining) {
  JobQueue queue(1, 2);
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  std::atomic<int> ran{0};
  auto blocking = std::make_shared<service::Job>([&](service::Job&) {
    released.wait();
    ++ran;
  });
  auto counting = [&] { return std::make_shared<service::Job>([&](service::Job&) { ++ran; }); };
  EXPECT_EQ(queue.submit(blocking).admission, JobQueue::Admission::kAccepted);
  while (queue.running() == 0) std::this_thread::yield();
  auto second = counting(), third = counting();
  EXPECT_EQ(queue.submit(second).position, 0u);
  EXPECT_EQ(queue.submit(third).position, 1u);
  EXPECT_TRUE(queue.full());
  EXPECT_EQ(queue.submit(counting()).admission, JobQueue::Admission::kQueueFull);
  EXPECT_TRUE(queue.withdraw(second.get()));
  EXPECT_FALSE(queue.withdraw(second.get()));
  EXPECT_FALSE(queue.full());
  queue.stop_accepting();
  EXPECT_EQ(queue.submit(counting()).admission, JobQueue::Admission::kDraining);
  EXPECT_FALSE(queue.wait_idle(std::chrono::steady_clock::now() + 50ms));
  release.set_value();
  EXPECT_TRUE(queue.wait_idle(std::chrono::steady_clock::now() + 10s));
  EXPECT_EQ(ran, 2);  // the blocking one and the third; the withdrawn one never ran
}

TEST(JobQueueTest, CancelAllFiresRunningAndWaitingTokens) {
  JobQueue queue(1, 4);
  auto spin = [](service::Job& job) {
    while (!job.token().cancelled()) std::this_thread::yield();
  };
  auto running = std::make_shared<service::Job>(spin), waiting = std::make_shared<service::Job>(spin);
  queue.submit(running);
  queue.submit(waiting);
  queue.cancel_all();
  EXPECT_TRUE(queue.wait_idle(std::chrono::steady_clock::now() + 10s));
  EXPECT_TRUE(running->token().cancelled() && waiting->token().cancelled());
}

TEST(MemoryBudgetTest, ReservesWaitsAndRefuses) {
  service::MemoryBudget budget(1000);
  CancellationToken token;
  EXPECT_EQ(code_of([&] { budget.reserve(1001, token); }), ErrorCode::kResourceExhausted);
  std::optional<service::MemoryBudget::Reservation> first(budget.reserve(600, token));
  EXPECT_EQ(budget.in_use(), 600u);
  auto second = std::async(std::launch::async, [&] {
    const service::MemoryBudget::Reservation reservation = budget.reserve(600, token);
    return budget.in_use();
  });
  EXPECT_EQ(second.wait_for(100ms), std::future_status::timeout);  // waits for the first to finish
  first.reset();
  ASSERT_EQ(second.wait_for(10s), std::future_status::ready);
  EXPECT_EQ(second.get(), 600u);
  EXPECT_EQ(budget.in_use(), 0u);
  // A cancelled waiter gives up.
  std::optional<service::MemoryBudget::Reservation> hog(budget.reserve(1000, token));
  CancellationToken cancelled;
  cancelled.cancel();
  EXPECT_EQ(code_of([&] { budget.reserve(1, cancelled); }), ErrorCode::kCancelled);
}

TEST(ProtoConvert, UnsetFieldsTakeTheCoreDefaults) {
  const RegistrationParams defaults;
  const RegistrationParams p = service::params_from_proto(v1::RegistrationParams{});
  EXPECT_EQ(p.min_scale_m, 0.0);  // automatic
  EXPECT_EQ(p.overlap, 0.0);      // automatic
  EXPECT_TRUE(p.icp);
  EXPECT_TRUE(p.search_other_side);
  EXPECT_EQ(p.seed, defaults.seed);
  EXPECT_EQ(p.octaves, defaults.octaves);
  EXPECT_EQ(p.hypotheses_kept, defaults.hypotheses_kept);
  EXPECT_EQ(p.signal, KeypointSignal::kAuto);
  EXPECT_EQ(p.method, CoarseMethod::kKeypoint4pcs);

  v1::RegistrationParams m;
  m.set_icp(false);
  m.set_seed(7);
  m.set_min_scale_m(0.1);
  m.set_signal(v1::KEYPOINT_SIGNAL_INTENSITY);
  m.set_method(v1::COARSE_METHOD_PLAIN_4PCS);
  m.set_time_budget_s(3);
  m.set_search_other_side(false);
  const RegistrationParams q = service::params_from_proto(m);
  EXPECT_FALSE(q.icp);
  EXPECT_FALSE(q.search_other_side);
  EXPECT_EQ(q.seed, 7u);
  EXPECT_EQ(q.min_scale_m, 0.1);
  EXPECT_EQ(q.signal, KeypointSignal::kIntensity);
  EXPECT_EQ(q.method, CoarseMethod::kPlain4pcs);
  EXPECT_EQ(q.time_budget_s, 3.0);

  m.set_overlap(-0.5);
  EXPECT_EQ(code_of([&] { service::params_from_proto(m); }), ErrorCode::kInvalidArgument);
}

// What a coordinating replica sends its peers (params_to_proto) reads back as the same parameters, for every
// value of every enum; a value the schema does not know is refused, naming the field.
TEST(ProtoConvert, EveryEnumValueRoundTripsAndUnknownValuesAreRefused) {
  for (const KeypointSignal signal : {KeypointSignal::kAuto, KeypointSignal::kIntensity, KeypointSignal::kGeometric}) {
    for (const CoarseMethod method : {CoarseMethod::kKeypoint4pcs, CoarseMethod::kPlain4pcs}) {
      for (const FreeSpaceCheck check : {FreeSpaceCheck::kAuto, FreeSpaceCheck::kOn, FreeSpaceCheck::kOff}) {
        RegistrationParams p;
        p.signal = signal;
        p.method = method;
        p.free_space = check;
        v1::RegistrationParams m;
        service::params_to_proto(p, &m);
        const RegistrationParams q = service::params_from_proto(m);
        EXPECT_EQ(q.signal, signal);
        EXPECT_EQ(q.method, method);
        EXPECT_EQ(q.free_space, check);
      }
    }
  }
  RegistrationParams one_sided;  // as a project sends its pairs
  one_sided.search_other_side = false;
  v1::RegistrationParams sent;
  service::params_to_proto(one_sided, &sent);
  EXPECT_FALSE(service::params_from_proto(sent).search_other_side);
  v1::RegistrationParams m;
  m.set_free_space(static_cast<v1::FreeSpaceCheck>(42));
  try {
    service::params_from_proto(m);
    ADD_FAILURE() << "an unknown free_space value was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("params.free_space"), std::string::npos) << e.what();
  }
}

TEST(StatusMapping, EveryCoreCodeHasItsGrpcCode) {
  EXPECT_EQ(service::to_grpc_code(ErrorCode::kInvalidArgument), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(service::to_grpc_code(ErrorCode::kNotFound), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(service::to_grpc_code(ErrorCode::kPermissionDenied), grpc::StatusCode::PERMISSION_DENIED);
  EXPECT_EQ(service::to_grpc_code(ErrorCode::kResourceExhausted), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_EQ(service::to_grpc_code(ErrorCode::kFailedPrecondition), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_EQ(service::to_grpc_code(ErrorCode::kDataLoss), grpc::StatusCode::DATA_LOSS);
  EXPECT_EQ(service::to_grpc_code(ErrorCode::kCancelled), grpc::StatusCode::CANCELLED);
  EXPECT_EQ(service::to_grpc_code(ErrorCode::kDeadlineExceeded), grpc::StatusCode::DEADLINE_EXCEEDED);
  EXPECT_EQ(service::to_grpc_code(ErrorCode::kInternal), grpc::StatusCode::INTERNAL);
  try {
    throw std::bad_alloc();
  } catch (...) {
    EXPECT_EQ(service::status_from_current_exception().error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  }
}

}  // namespace
}  // namespace k4reg::test
