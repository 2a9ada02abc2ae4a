// Uploads over the limits are refused with 413 while the server's memory stays flat: the body is spooled or
// discarded as it arrives, never held. 1 GB bodies come from generators (no 1 GB file is ever written), with
// Content-Length (refused from the header) and chunked (refused when the spooled file passes the limit).
#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <atomic>
#include <thread>

#include "test_support.h"

namespace k4reg::test {
namespace {

using namespace std::chrono_literals;

constexpr std::uint64_t kGigabyte = 1'000'000'000;
constexpr const char* kBoundary = "k4reg-upload-boundary";
// "A few MB": the server's whole resident set may grow by this much while it takes a 1 GB body.
constexpr std::size_t kAllowedGrowthKib = 8 << 10;

const std::string kPartHeader = std::string("--") + kBoundary +
                                "\r\nContent-Disposition: form-data; name=\"source\"; filename=\"huge.ply\"\r\n"
                                "Content-Type: application/octet-stream\r\n\r\n";
const std::string kFormEnd = std::string("\r\n--") + kBoundary + "--\r\n";
const std::string kMultipartType = std::string("multipart/form-data; boundary=") + kBoundary;

// Samples the server's VmRSS every few milliseconds while it lives; reports the peak above the baseline.
class ResidentMemoryWatch {
 public:
  explicit ResidentMemoryWatch(pid_t pid) : pid_(pid), baseline_kib_(resident_kib(pid)), peak_kib_(baseline_kib_) {
    thread_ = std::thread([this] {
      while (!done_) {
        peak_kib_ = std::max(peak_kib_.load(), resident_kib(pid_));
        std::this_thread::sleep_for(2ms);
      }
    });
  }
  ~ResidentMemoryWatch() { stop(); }
  std::size_t growth_kib() {
    stop();
    return peak_kib_ - baseline_kib_;
  }

 private:
  void stop() {
    done_ = true;
    if (thread_.joinable()) thread_.join();
  }
  const pid_t pid_;
  const std::size_t baseline_kib_;
  std::atomic<std::size_t> peak_kib_;
  std::atomic<bool> done_{false};
  std::thread thread_;
};

// The multipart body of a `file_bytes` zero file, produced piece by piece at `offset`.
bool write_form(std::uint64_t file_bytes, std::size_t offset, httplib::DataSink& sink) {
  static const std::string zeros(1 << 16, '\0');
  const std::uint64_t file_end = kPartHeader.size() + file_bytes;
  if (offset < kPartHeader.size()) return sink.write(kPartHeader.data() + offset, kPartHeader.size() - offset);
  if (offset < file_end) return sink.write(zeros.data(), std::min<std::uint64_t>(zeros.size(), file_end - offset));
  const std::size_t end_offset = offset - file_end;
  if (end_offset < kFormEnd.size()) return sink.write(kFormEnd.data() + end_offset, kFormEnd.size() - end_offset);
  sink.done();
  return true;
}

class UploadLimits : public ::testing::Test {
 protected:
  UploadLimits() : server_({"--data-root", bunny_dir().string(), "--workers", "1", "--max-upload-mb", "16"}) {
    signal(SIGPIPE, SIG_IGN);  // a server that closes early must fail the test, not kill it
    // Warm up: the first requests allocate the server's buffers and thread stacks for good.
    auto http = server_.http();
    for (int i = 0; i < 3; ++i) {
      reply_of(http.Get("/metrics"));
      reply_of(http.Post("/v1/register", kPartHeader + std::string(1 << 20, '\0') + kFormEnd, kMultipartType));
    }
  }

  void expect_refused(const HttpReply& reply, const std::string& text) {
    EXPECT_EQ(reply.status, 413) << reply.body;
    EXPECT_EQ(reply.json()["code"], "RESOURCE_EXHAUSTED");
    EXPECT_NE(reply.body.find(text), std::string::npos) << reply.body;
    EXPECT_EQ(server_.spooled_files(), 0u);
  }

  ServerProcess server_;
};

TEST_F(UploadLimits, OneGigabyteWithContentLengthIs413WithoutMemoryGrowth) {
  const std::uint64_t total = kPartHeader.size() + kGigabyte + kFormEnd.size();
  ResidentMemoryWatch watch(server_.pid());
  const auto start = std::chrono::steady_clock::now();
  // cpp-httplib's client sends the whole body before it reads the answer: the server reads it to the end,
  // discarding it, so that the client gets the 413 instead of a reset connection.
  auto http = server_.http();
  const HttpReply reply = reply_of(http.Post(
      "/v1/register", total, [](std::size_t offset, std::size_t, httplib::DataSink& sink) {
        return write_form(kGigabyte, offset, sink);
      },
      kMultipartType));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::size_t growth_kib = watch.growth_kib();
  expect_refused(reply, "--max-upload-mb");
  std::cout << "[ measured ] 1 GB with Content-Length: 413 after " << seconds << " s, server VmRSS peak growth "
            << growth_kib << " KiB\n";
  RecordProperty("rss_growth_kib", std::to_string(growth_kib));
  EXPECT_LT(growth_kib, kAllowedGrowthKib);
  // The whole body went through the server (and was counted), not into it.
  const auto lines = server_.log_lines("request");
  EXPECT_GE(lines.back()["upload_bytes"].get<std::uint64_t>(), kGigabyte);
  EXPECT_EQ(lines.back()["http_status"], 413);
}

TEST_F(UploadLimits, CurlWithExpectContinueIsRefusedBeforeSendingTheBody) {
  ResidentMemoryWatch watch(server_.pid());
  const auto start = std::chrono::steady_clock::now();
  const HttpReply reply = curl({"-X", "POST", "-T", "-", "-H", "Content-Type: " + kMultipartType, "-H",
                                std::string("Content-Length: ").append(std::to_string(kGigabyte)), server_.http_url() + "/v1/register"},
                               std::string("head -c ").append(std::to_string(kGigabyte)).append(" /dev/zero"));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::size_t growth_kib = watch.growth_kib();
  expect_refused(reply, "request body of 1000000000 bytes");
  std::cout << "[ measured ] curl, 1 GB declared: 413 after " << seconds << " s, server VmRSS peak growth "
            << growth_kib << " KiB\n";
  EXPECT_LT(growth_kib, kAllowedGrowthKib);
  EXPECT_EQ(server_.log_lines("request").back().value("upload_bytes", 0), 0) << "no body byte was sent";
}

TEST_F(UploadLimits, ChunkedOneGigabyteIs413OnceTheFilePassesTheLimit) {
  ResidentMemoryWatch watch(server_.pid());
  const auto start = std::chrono::steady_clock::now();
  auto http = server_.http();
  const HttpReply reply = reply_of(http.Post(
      "/v1/register", [](std::size_t offset, httplib::DataSink& sink) { return write_form(kGigabyte, offset, sink); },
      kMultipartType));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::size_t growth_kib = watch.growth_kib();
  expect_refused(reply, "source: more than the upload limit of 16 MiB (--max-upload-mb)");
  std::cout << "[ measured ] chunked 1 GB: 413 after " << seconds << " s, server VmRSS peak growth " << growth_kib
            << " KiB\n";
  EXPECT_LT(growth_kib, kAllowedGrowthKib);

  // The same through curl (a chunked upload of a generated multipart stream).
  const std::string generator = "{ printf '%s' '" + kPartHeader + "'; head -c 200000000 /dev/zero; printf '%s' '" +
                                kFormEnd + "'; }";
  expect_refused(curl({"-X", "POST", "-T", "-", "-H", "Content-Type: " + kMultipartType,
                       server_.http_url() + "/v1/register"},
                      generator),
                 "--max-upload-mb");
  // The connection is still usable: the next request on it is answered.
  EXPECT_EQ(reply_of(http.Get("/healthz")).status, 200);
}

}  // namespace
}  // namespace k4reg::test
