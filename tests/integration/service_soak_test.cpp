// Soak: one real k4reg-server on loopback and several client threads for K4REG_SOAK_SECONDS (default 20), each
// on its own connection, sending a random mix of
//   valid requests   two bunny pairs by path, inline and streamed; every result must match the ground truth and
//                    be bit-identical to the pair's first result (registration is deterministic),
//   invalid requests missing files, paths outside the data root, bad parameters, garbage and oversized uploads,
//                    garbage inline clouds, checksum mismatches, streams that end early, each with its own code,
//   interruptions    client-side cancellation after a random delay and short deadlines (the result, if one
//                    arrives first, must still be correct).
// Afterwards the server is healthy and still correct, no upload is left in the spool, its threads are back to the
// baseline taken after a warm-up (gRPC's executors may have grown to their bound), its RSS is close to that
// baseline, and it drains and exits 0 on SIGTERM (under AddressSanitizer: with no leak reported).
// bench/soak.sh runs the same test for longer and records the summary line in bench/RESULTS.md.
#include <gtest/gtest.h>
#include <signal.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <mutex>
#include <numeric>
#include <random>
#include <set>
#include <sstream>
#include <thread>

#include "k4reg/util/crc32c.h"
#include "test_support.h"

namespace k4reg::test {
namespace {

using Clock = std::chrono::steady_clock;
using grpc::StatusCode;

constexpr int kClientThreads = 4;
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#elif defined(__has_feature)
constexpr bool kSanitized = __has_feature(address_sanitizer);
#else
constexpr bool kSanitized = false;
#endif
constexpr std::size_t kMaxUploadMb = 1;  // bunny scans are ~480 KB: an oversized upload is easy to make

double soak_seconds() {
  const char* value = std::getenv("K4REG_SOAK_SECONDS");
  return value != nullptr ? std::atof(value) : 20.0;
}

// VmRSS (kB) and Threads of a process, from /proc/<pid>/status.
struct ProcessStatus {
  long rss_kb = 0;
  long threads = 0;
};

// The names of a process's threads (/proc/<pid>/task/*/comm), for the message when threads are left over.
std::multiset<std::string> thread_names(pid_t pid) {
  std::multiset<std::string> names;
  std::error_code ec;
  for (const auto& task : fs::directory_iterator("/proc/" + std::to_string(pid) + "/task", ec)) {
    std::string name;
    std::getline(std::ifstream(task.path() / "comm"), name);
    names.insert(name);
  }
  return names;
}

// gRPC's executors ("default-executor", "resolver-executor"; comm keeps 15 characters) start threads on demand,
// up to 2 x cores each, and keep them until shutdown (src/core/lib/iomgr/executor.cc): a bounded pool, not a leak.
bool grpc_executor_thread(const std::string& name) {
  return name.rfind("default-execut", 0) == 0 || name.rfind("resolver-execu", 0) == 0;
}

// The threads that are not back to the baseline: every name at most as often as then, except gRPC's executors,
// which may have grown up to their bound. "" when none.
std::string leftover_threads(const std::multiset<std::string>& now, const std::multiset<std::string>& baseline) {
  const std::size_t executor_bound = 2 * std::max(1u, std::thread::hardware_concurrency());
  std::string text;
  for (auto it = now.begin(); it != now.end(); it = now.upper_bound(*it)) {
    const std::size_t count = now.count(*it), before = baseline.count(*it);
    if (count > (grpc_executor_thread(*it) ? std::max(before, executor_bound) : before))
      text += " " + *it + " x" + std::to_string(count) + " (baseline " + std::to_string(before) + ")";
  }
  return text;
}

ProcessStatus process_status(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  ProcessStatus status;
  for (std::string line; std::getline(in, line);) {
    std::istringstream fields(line);
    std::string key;
    fields >> key;
    if (key == "VmRSS:") fields >> status.rss_kb;
    if (key == "Threads:") fields >> status.threads;
  }
  return status;
}

// A bunny pair: the scans' bytes, its ground truth and parameters under which it registers.
struct Pair {
  std::string source, target;
  std::string source_bytes, target_bytes;
  Eigen::Matrix4d truth;
  v1::RegistrationParams params;
};

Pair make_pair(const std::string& source, const std::string& target, double overlap) {
  Pair pair{source, target, read_file(bunny_dir() / source), read_file(bunny_dir() / target),
            bunny_truth(source, target), bunny_params()};
  pair.params.set_overlap(overlap);
  return pair;
}

enum class Kind {
  kValidPath,
  kValidInline,
  kValidStream,
  kCancelled,
  kShortDeadline,
  kMissingFile,
  kOutsideRoot,
  kBadParams,
  kGarbageInline,
  kGarbageUpload,
  kOversizedUpload,
  kChecksumMismatch,
  kEarlyEnd,
};

// Weights in the schedule: about 40 % of the calls are valid registrations (each ~1 s of server CPU), the rest fast
// refusals.
const std::vector<std::pair<Kind, int>> kMix = {
    {Kind::kValidPath, 3},     {Kind::kValidInline, 2},    {Kind::kValidStream, 2},      {Kind::kCancelled, 2},
    {Kind::kShortDeadline, 2}, {Kind::kMissingFile, 1},    {Kind::kOutsideRoot, 1},      {Kind::kBadParams, 1},
    {Kind::kGarbageInline, 1}, {Kind::kGarbageUpload, 1},  {Kind::kOversizedUpload, 1}, {Kind::kChecksumMismatch, 1},
    {Kind::kEarlyEnd, 1},
};

const char* kind_name(Kind kind) {
  switch (kind) {
    case Kind::kValidPath: return "valid_path";
    case Kind::kValidInline: return "valid_inline";
    case Kind::kValidStream: return "valid_stream";
    case Kind::kCancelled: return "cancelled";
    case Kind::kShortDeadline: return "short_deadline";
    case Kind::kMissingFile: return "missing_file";
    case Kind::kOutsideRoot: return "outside_root";
    case Kind::kBadParams: return "bad_params";
    case Kind::kGarbageInline: return "garbage_inline";
    case Kind::kGarbageUpload: return "garbage_upload";
    case Kind::kOversizedUpload: return "oversized_upload";
    case Kind::kChecksumMismatch: return "checksum_mismatch";
    case Kind::kEarlyEnd: return "early_end";
  }
  return "?";
}

class Soak : public ::testing::Test {
 protected:
  Soak() : pairs_{make_pair("bun045.ply", "bun000.ply", 0.9), make_pair("bun090.ply", "bun045.ply", 0.636)} {
    fs::create_directory(root());
    for (const char* scan : {"bun000.ply", "bun045.ply", "bun090.ply"}) fs::copy_file(bunny_dir() / scan, root() / scan);
    server_ = std::make_unique<ServerProcess>(std::vector<std::string>{
        "--data-root", root().string(), "--workers", "2", "--queue-size", "32", "--max-upload-mb",
        std::to_string(kMaxUploadMb)});
  }

  fs::path root() const { return data_.path() / "root"; }

  // One call of `kind` with a random pair, random delays; returns a failure description, or "" when the outcome
  // is one the kind allows.
  std::string run(Kind kind, v1::Registration::Stub& stub, std::mt19937& random) {
    const Pair& pair = pairs_[random() % pairs_.size()];
    grpc::ClientContext context;
    set_timeout(context, std::chrono::seconds(120));
    std::thread canceller;
    if (kind == Kind::kCancelled) {
      const auto delay = std::chrono::milliseconds(random() % 1500);
      canceller = std::thread([&context, delay] {
        std::this_thread::sleep_for(delay);
        context.TryCancel();
      });
    }
    if (kind == Kind::kShortDeadline) set_timeout(context, std::chrono::milliseconds(20 + random() % 400));
    const bool uploads = kind == Kind::kValidStream || kind == Kind::kGarbageUpload || kind == Kind::kOversizedUpload ||
                         kind == Kind::kChecksumMismatch || kind == Kind::kEarlyEnd;
    const bool stream = uploads || ((kind == Kind::kCancelled || kind == Kind::kShortDeadline) && random() % 2);
    Outcome outcome = stream ? call_stream(kind, pair, stub, context, random) : call_unary(kind, pair, stub, context, random);
    if (canceller.joinable()) canceller.join();
    record(kind, outcome.status.error_code());
    return judge(kind, pair, outcome);
  }

  struct Outcome {
    grpc::Status status;
    v1::RegisterResponse reply;
  };

  Outcome call_unary(Kind kind, const Pair& pair, v1::Registration::Stub& stub, grpc::ClientContext& context,
                     std::mt19937& random) {
    v1::RegisterRequest request;
    request.mutable_source()->set_path(pair.source);
    request.mutable_target()->set_path(pair.target);
    *request.mutable_params() = pair.params;
    switch (kind) {
      case Kind::kValidInline:
        request.mutable_source()->mutable_inline_cloud()->set_data(pair.source_bytes);
        request.mutable_source()->mutable_inline_cloud()->set_file_name(pair.source);
        break;
      case Kind::kMissingFile:
        request.mutable_target()->set_path("missing-" + std::to_string(random() % 1000) + ".ply");
        break;
      case Kind::kOutsideRoot:
        request.mutable_source()->set_path(random() % 2 ? "../" + pair.source : (bunny_dir() / pair.source).string());
        break;
      case Kind::kBadParams:
        request.mutable_params()->set_overlap(1.01 + (random() % 100) / 10.0);
        break;
      case Kind::kGarbageInline:
        request.mutable_target()->mutable_inline_cloud()->set_data(garbage(random, 1000 + random() % 100000));
        request.mutable_target()->mutable_inline_cloud()->set_file_name("garbage.ply");
        break;
      default:
        break;
    }
    Outcome outcome;
    outcome.status = stub.Register(&context, request, &outcome.reply);
    return outcome;
  }

  Outcome call_stream(Kind kind, const Pair& pair, v1::Registration::Stub& stub, grpc::ClientContext& context,
                      std::mt19937& random) {
    StreamUpload upload{pair.source_bytes, pair.target_bytes, std::size_t{16} << (10 + random() % 7)};
    v1::UploadHeader header = upload_header(pair.source, pair.source_bytes, pair.target, pair.target_bytes, pair.params);
    switch (kind) {
      case Kind::kGarbageUpload:
        upload.source_bytes = garbage(random, 1000 + random() % 300000);
        header = upload_header("garbage.pcd", upload.source_bytes, pair.target, pair.target_bytes, pair.params);
        break;
      case Kind::kOversizedUpload:
        upload.target_bytes = std::string((kMaxUploadMb << 20) + 1 + random() % 1000, 'x');
        header = upload_header(pair.source, pair.source_bytes, "big.ply", upload.target_bytes, pair.params);
        break;
      case Kind::kChecksumMismatch:
        header.mutable_source()->mutable_upload()->set_crc32c(crc32c(pair.source_bytes) ^ (1u << (random() % 32)));
        break;
      case Kind::kEarlyEnd:
        upload.target_bytes.resize(random() % upload.target_bytes.size());
        break;
      default:
        break;
    }
    StreamCall call(stub, context, header, upload);
    Outcome outcome;
    outcome.status = call.finish();
    if (call.result() != nullptr) outcome.reply = *call.result();
    return outcome;
  }

  static std::string garbage(std::mt19937& random, std::size_t size) {
    std::string bytes(size, '\0');
    for (char& c : bytes) c = static_cast<char>(random());
    return bytes;
  }

  std::string judge(Kind kind, const Pair& pair, const Outcome& outcome) {
    const StatusCode code = outcome.status.error_code();
    const bool valid = kind == Kind::kValidPath || kind == Kind::kValidInline || kind == Kind::kValidStream;
    const bool interrupted = kind == Kind::kCancelled || kind == Kind::kShortDeadline;
    if (valid || (interrupted && code == StatusCode::OK)) return check_result(pair, outcome);
    const StatusCode expected = kind == Kind::kCancelled        ? StatusCode::CANCELLED
                                : kind == Kind::kShortDeadline  ? StatusCode::DEADLINE_EXCEEDED
                                : kind == Kind::kMissingFile    ? StatusCode::NOT_FOUND
                                : kind == Kind::kOutsideRoot    ? StatusCode::PERMISSION_DENIED
                                : kind == Kind::kOversizedUpload ? StatusCode::RESOURCE_EXHAUSTED
                                : kind == Kind::kChecksumMismatch ? StatusCode::DATA_LOSS
                                                                  : StatusCode::INVALID_ARGUMENT;
    if (code == expected) return "";
    return std::string(kind_name(kind)) + ": status " + std::to_string(code) + " \"" + outcome.status.error_message() +
           "\", expected " + std::to_string(expected);
  }

  // Close to the ground truth, and bit-identical to the first result of the same pair.
  std::string check_result(const Pair& pair, const Outcome& outcome) {
    if (!outcome.status.ok())
      return "valid " + pair.source + " -> " + pair.target + ": status " + std::to_string(outcome.status.error_code()) +
             " \"" + outcome.status.error_message() + "\"";
    const Eigen::Matrix4d transform = to_matrix(outcome.reply.result().transform());
    const double translation_error_m = (transform.topRightCorner<3, 1>() - pair.truth.topRightCorner<3, 1>()).norm();
    const double rotation_error_deg =
        Eigen::AngleAxisd(Eigen::Matrix3d(transform.topLeftCorner<3, 3>().transpose() * pair.truth.topLeftCorner<3, 3>()))
            .angle() * 180.0 / M_PI;
    std::lock_guard lock(mutex_);
    ++correct_;
    const auto [first, inserted] = first_results_.emplace(pair.source, transform);
    if (translation_error_m > 0.003 || rotation_error_deg > 1.0 || (!inserted && first->second != transform)) {
      --correct_;
      std::ostringstream message;
      message << pair.source << " -> " << pair.target << ": translation error " << translation_error_m
              << " m, rotation error " << rotation_error_deg << " deg, same as the first result: "
              << (first->second == transform);
      return message.str();
    }
    return "";
  }

  void record(Kind kind, StatusCode code) {
    std::lock_guard lock(mutex_);
    ++counts_[std::string(kind_name(kind)) + ":" + std::to_string(code)];
  }

  TempDir data_;
  std::vector<Pair> pairs_;
  std::unique_ptr<ServerProcess> server_;
  std::mutex mutex_;
  std::map<std::string, int> counts_;
  std::map<std::string, Eigen::Matrix4d> first_results_;
  int correct_ = 0;
};

// Waits until `done` holds or `timeout` passes; returns whether it held.
template <typename Predicate>
bool eventually(Predicate done, std::chrono::seconds timeout) {
  const auto deadline = Clock::now() + timeout;
  while (!done()) {
    if (Clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return true;
}

TEST_F(Soak, MixedValidInvalidCancelledAndExpiredCallsLeaveTheServerAsItWas) {
  // Warm-up: every client connection and both workers have run a registration, so the baseline includes the
  // threads and memory pools a busy server keeps.
  std::vector<std::unique_ptr<v1::Registration::Stub>> stubs;
  for (int t = 0; t < kClientThreads; ++t) stubs.push_back(server_->stub());
  {
    std::vector<std::thread> warm_up;
    std::vector<std::string> failures(kClientThreads);
    for (int t = 0; t < kClientThreads; ++t)
      warm_up.emplace_back([&, t] {
        std::mt19937 random(t);
        failures[t] = run(Kind::kValidPath, *stubs[t], random);
      });
    for (auto& thread : warm_up) thread.join();
    for (const std::string& failure : failures) ASSERT_EQ(failure, "");
  }
  std::this_thread::sleep_for(std::chrono::seconds(1));
  const ProcessStatus baseline = process_status(server_->pid());
  const std::multiset<std::string> baseline_threads = thread_names(server_->pid());

  // Every kind, whatever the speed (a sanitizer build makes few calls): the weighted mix in a shuffled cycle that
  // client t walks from position t in steps of kClientThreads (coprime to its length), each client making at least
  // min_calls, so that together they cover the whole cycle.
  std::vector<Kind> schedule;
  for (const auto& [kind, weight] : kMix) schedule.insert(schedule.end(), weight, kind);
  std::shuffle(schedule.begin(), schedule.end(), std::mt19937(99));
  ASSERT_EQ(std::gcd(schedule.size(), std::size_t{kClientThreads}), 1u);
  const std::size_t min_calls = (schedule.size() + kClientThreads - 1) / kClientThreads;
  const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(soak_seconds()));
  std::vector<std::vector<std::string>> failures(kClientThreads);
  std::atomic<long> peak_rss_kb{baseline.rss_kb}, peak_threads{baseline.threads};
  std::vector<std::thread> clients;
  for (int t = 0; t < kClientThreads; ++t)
    clients.emplace_back([&, t] {
      std::mt19937 random(1000 + t);
      for (std::size_t call = 0; Clock::now() < end || call < min_calls; ++call) {
        const std::size_t position = t + call * kClientThreads;
        std::string failure = run(schedule[position % schedule.size()], *stubs[t], random);
        if (!failure.empty()) failures[t].push_back(std::move(failure));
        const ProcessStatus now = process_status(server_->pid());
        peak_rss_kb = std::max<long>(peak_rss_kb, now.rss_kb);
        peak_threads = std::max<long>(peak_threads, now.threads);
      }
    });
  for (auto& client : clients) client.join();

  int calls = 0;
  std::ostringstream summary;
  for (const auto& [key, count] : counts_) {
    calls += count;
    summary << ' ' << key << '=' << count;
  }
  for (const auto& thread_failures : failures)
    for (const std::string& failure : thread_failures) ADD_FAILURE() << failure;
  for (const auto& [kind, weight] : kMix) {
    const std::string prefix = std::string(kind_name(kind)) + ":";
    EXPECT_NE(counts_.lower_bound(prefix), counts_.lower_bound(prefix + "~")) << "no call of kind " << kind_name(kind);
  }
  EXPECT_EQ(counts_.count("cancelled:1"), 1u) << "no call was actually cancelled";

  // The server as it was: healthy, still correct, nothing spooled, threads and memory back.
  EXPECT_EQ(health_status(*server_, "liveness"), "SERVING");
  EXPECT_EQ(health_status(*server_, "readiness"), "SERVING");
  std::mt19937 random(7);
  EXPECT_EQ(run(Kind::kValidStream, *server_->stub(), random), "");
  EXPECT_TRUE(eventually([&] { return server_->spooled_files() == 0; }, std::chrono::seconds(5)))
      << server_->spooled_files() << " files left in the spool";
  EXPECT_TRUE(eventually([&] { return leftover_threads(thread_names(server_->pid()), baseline_threads).empty(); },
                         std::chrono::seconds(10)))
      << "threads left over:" << leftover_threads(thread_names(server_->pid()), baseline_threads);
  // RSS: freed memory stays in glibc's per-thread arenas instead of going back to the kernel, so "back to the
  // baseline" means within 64 MB: the soak's peak stays ~15 MB above the baseline (two bunny jobs at once), while a
  // leak of the clouds (~2 MB per valid request, dozens of them) exceeds it. Under AddressSanitizer RSS measures its
  // quarantine rather than the server; LeakSanitizer checks the server's exit instead (wait() below).
  const ProcessStatus after = process_status(server_->pid());
  if (!kSanitized) {
    EXPECT_LE(after.rss_kb, baseline.rss_kb + 64 * 1024) << "RSS baseline " << baseline.rss_kb << " kB, after "
                                                         << after.rss_kb << " kB";
  }
  std::printf("soak: %.0f s, %d client threads, %d calls, %d correct results; RSS baseline %ld kB, peak %ld kB, "
              "after %ld kB; threads baseline %ld, peak %ld, after %ld; by kind:status%s\n",
              soak_seconds(), kClientThreads, calls, correct_, baseline.rss_kb, peak_rss_kb.load(), after.rss_kb,
              baseline.threads, peak_threads.load(), process_status(server_->pid()).threads, summary.str().c_str());

  server_->signal(SIGTERM);
  EXPECT_EQ(server_->wait(), 0) << server_->log().substr(0, 4000);
}

}  // namespace
}  // namespace k4reg::test
