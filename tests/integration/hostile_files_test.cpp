// Files a request references, as the server meets them once the job runs, and what clouds declare: a symlink or a
// FIFO swapped in during the queue wait is refused (never followed out of the data roots, never waited on), a
// NaN intensity is refused, memory is reserved from the points a header declares before anything is decoded, and
// a project's scans and points are capped, each refusal naming its flag.
#include <sys/stat.h>

#include <fstream>
#include <functional>
#include <string>
#include <thread>

#include "k4reg/io/cloud_io.h"
#include "k4reg/util/crc32c.h"
#include "k4reg/util/error.h"
#include "test_support.h"

namespace k4reg::test {
namespace {

using namespace std::chrono_literals;

// A binary_compressed PCD of `points` points at the origin: 12 bytes each unpacked, 88 times fewer as LZF (one
// literal zero, then back references of 264 bytes at distance 1). 30 M points: 360 MB unpacked from 4 MB.
std::string compressed_pcd(std::uint64_t points) {
  const std::uint64_t raw = points * 12;
  std::string lzf(2, '\0');  // a literal run of one byte: 0
  std::uint64_t left = raw - 1;
  for (; left >= 264; left -= 264) lzf += std::string("\xe0\xff\x00", 3);
  for (std::uint64_t run; left > 0; left -= run) {
    run = std::min<std::uint64_t>(left, 32);
    lzf += char(run - 1);
    lzf.append(run, '\0');
  }
  std::string pcd = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH " + std::to_string(points) +
                    "\nHEIGHT 1\nPOINTS " + std::to_string(points) + "\nDATA binary_compressed\n";
  for (const std::uint64_t size : {std::uint64_t(lzf.size()), raw})
    for (int byte = 0; byte < 4; ++byte) pcd += char((size >> (8 * byte)) & 0xff);
  return pcd + lzf;
}

// A data root holding the bunny pair, and a folder outside it.
class HostileFiles : public ::testing::Test {
 protected:
  explicit HostileFiles(std::vector<std::string> extra_args = {}) {
    fs::create_directory(root());
    fs::create_directory(outside());
    for (const char* scan : {"bun045.ply", "bun000.ply"}) fs::copy_file(bunny_dir() / scan, root() / scan);
    std::vector<std::string> args{"--data-root", root().string(), "--workers", "1"};
    args.insert(args.end(), extra_args.begin(), extra_args.end());
    server_ = std::make_unique<ServerProcess>(args);
    stub_ = server_->stub();
  }
  fs::path root() const { return dir_.path() / "root"; }
  fs::path outside() const { return dir_.path() / "outside"; }

  // Registers victim.ply (a copy of bun045.ply when the request arrives) onto bun000.ply, and calls `swap` on
  // victim.ply while the job waits in the queue behind a slow one.
  grpc::Status register_swapped_during_the_queue_wait(const std::function<void(const fs::path&)>& swap) {
    fs::copy_file(bunny_dir() / "bun045.ply", root() / "victim.ply");
    const auto running_context = context_with_deadline(30s);
    StreamCall running(*stub_, *running_context, bunny_reference_header(slow_params(3)), StreamUpload{});
    EXPECT_TRUE(running.wait_for_stage("load", v1::StageEvent::PHASE_STARTED));
    v1::UploadHeader header = bunny_reference_header(quick_params());
    header.mutable_source()->set_path("victim.ply");
    const auto context = context_with_deadline(20s);
    StreamCall queued(*stub_, *context, header, StreamUpload{});
    EXPECT_TRUE(queued.wait_for_queued());
    swap(root() / "victim.ply");
    running_context->TryCancel();  // the worker moves on to the queued job
    return queued.finish();
  }

  // A RegisterProjectStream call that declares `uploads` uploads and ends without sending a byte of them.
  grpc::Status stream_project_header(int uploads) {
    v1::RegisterProjectStreamRequest header;
    for (int i = 0; i < uploads; ++i) {
      v1::UploadedFile& upload = *header.mutable_header()->add_scans()->mutable_upload();
      upload.set_file_name("scan.xyz");
      upload.set_size_bytes(1000);
    }
    const auto context = context_with_deadline(30s);
    auto stream = stub_->RegisterProjectStream(context.get());
    stream->Write(header);
    stream->WritesDone();
    for (v1::RegisterProjectEvent event; stream->Read(&event);) {
    }
    return stream->Finish();
  }

  grpc::Status register_project(const v1::RegisterProjectRequest& request) {
    const auto context = context_with_deadline(30s);
    auto reader = stub_->RegisterProject(context.get(), request);
    for (v1::RegisterProjectEvent event; reader->Read(&event);) {
    }
    return reader->Finish();
  }

  TempDir dir_;
  std::unique_ptr<ServerProcess> server_;
  std::unique_ptr<v1::Registration::Stub> stub_;
};

TEST_F(HostileFiles, ASymlinkSwappedInDuringTheQueueWaitDoesNotLeadOutOfTheDataRoot) {
  fs::copy_file(bunny_dir() / "bun045.ply", outside() / "secret.ply");
  const grpc::Status status = register_swapped_during_the_queue_wait([&](const fs::path& victim) {
    fs::remove(victim);
    fs::create_symlink(outside() / "secret.ply", victim);
  });
  EXPECT_TRUE(has_status(status, grpc::StatusCode::PERMISSION_DENIED, "victim.ply: outside the server's data roots"));
  EXPECT_EQ(status.error_message().find(outside().string()), std::string::npos) << status.error_message();
}

TEST_F(HostileFiles, AFifoSwappedInDuringTheQueueWaitIsRefusedWithoutWaitingForAWriter) {
  const auto start = std::chrono::steady_clock::now();
  const grpc::Status status = register_swapped_during_the_queue_wait([](const fs::path& victim) {
    fs::remove(victim);
    ASSERT_EQ(mkfifo(victim.c_str(), 0600), 0);
  });
  EXPECT_TRUE(has_status(status, grpc::StatusCode::INVALID_ARGUMENT, "victim.ply: not a regular file"));
  EXPECT_LT(std::chrono::steady_clock::now() - start, 15s);
  // The worker is free: the next job runs.
  grpc::ClientContext context;
  set_timeout(context, 30s);
  v1::RegisterResponse reply;
  EXPECT_TRUE(stub_->Register(&context, bunny_request(quick_params()), &reply).ok());
}

TEST_F(HostileFiles, ANaNIntensityIsRefusedNamingThePoint) {
  std::string xyz;
  for (int i = 0; i < 200; ++i)
    xyz += std::to_string(i % 10) + " " + std::to_string(i / 10) + " " + std::to_string(i % 7) + (i == 17 ? " nan\n" : " 0.5\n");
  v1::RegisterRequest request = bunny_request(quick_params());
  request.mutable_source()->mutable_inline_cloud()->set_data(xyz);
  request.mutable_source()->mutable_inline_cloud()->set_file_name("nan.xyz");
  grpc::ClientContext context;
  set_timeout(context, 30s);
  v1::RegisterResponse reply;
  EXPECT_TRUE(has_status(stub_->Register(&context, request, &reply), grpc::StatusCode::INVALID_ARGUMENT,
                         "nan.xyz: point 17 has a NaN/Inf intensity"));
  // The readers of every format refuse it, here a PLY's infinite intensity.
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
      "property float intensity\nend_header\n0 0 0 1\n1 0 0 inf\n";
  try {
    read_cloud_bytes(ply, "inf.ply");
    ADD_FAILURE() << "an infinite intensity was read";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("inf.ply: point 1 has a NaN/Inf intensity"), std::string::npos) << e.what();
  }
}

class DeclaredPoints : public HostileFiles {
 protected:
  DeclaredPoints() : HostileFiles({"--memory-budget-mb", "256"}) {}
};

TEST_F(DeclaredPoints, MemoryIsReservedFromTheDeclaredCountBeforeDecoding) {
  // 4 MB on disk that decode to 30 M points: 1.8 GB at 60 bytes per point, far over the 256 MiB budget.
  write_file(root() / "bomb.pcd", compressed_pcd(30'000'000));
  const std::size_t peak_before = peak_resident_kib(server_->pid());
  v1::RegisterRequest request = bunny_request(quick_params());
  request.mutable_source()->set_path("bomb.pcd");
  grpc::ClientContext context;
  set_timeout(context, 60s);
  v1::RegisterResponse reply;
  EXPECT_TRUE(has_status(stub_->Register(&context, request, &reply), grpc::StatusCode::RESOURCE_EXHAUSTED,
                         "--memory-budget-mb"));
  // Refused from the header: nothing of the 360 MB of unpacked points was ever held.
  EXPECT_LT(peak_resident_kib(server_->pid()), peak_before + 64 * 1024);
}

class ProjectCaps : public HostileFiles {
 protected:
  // The bunny pair holds 80353 points.
  ProjectCaps() : HostileFiles({"--max-project-scans", "2", "--max-project-points", "80000"}) {}
};

TEST_F(ProjectCaps, AProjectOverItsScansOrPointsIsRefusedNamingTheFlag) {
  v1::RegisterProjectRequest request;
  for (const char* scan : {"bun045.ply", "bun000.ply", "bun045.ply"}) request.add_scans()->set_path(scan);
  EXPECT_TRUE(has_status(register_project(request), grpc::StatusCode::RESOURCE_EXHAUSTED, "--max-project-scans"));
  request.mutable_scans()->RemoveLast();
  EXPECT_TRUE(has_status(register_project(request), grpc::StatusCode::RESOURCE_EXHAUSTED, "--max-project-points"));

  // A streamed project is refused from its header, before any upload is spooled.
  EXPECT_TRUE(has_status(stream_project_header(3), grpc::StatusCode::RESOURCE_EXHAUSTED, "--max-project-scans"));
  EXPECT_EQ(server_->spooled_files(), 0u);

  // Over HTTP, the form's third scan part is refused with 413.
  const HttpReply reply = curl({"-F", "scans=bun045.ply", "-F", "scans=bun000.ply", "-F", "scans=bun045.ply",
                                server_->http_url() + "/v1/register-project"});
  EXPECT_EQ(reply.status, 413) << reply.body;
  EXPECT_NE(reply.body.find("--max-project-scans"), std::string::npos) << reply.body;
}

class SpoolFiles : public HostileFiles {
 protected:
  SpoolFiles() : HostileFiles({"--max-spool-files", "2"}) {}
};

TEST_F(SpoolFiles, UploadsDeclaredBeyondTheServersSpoolFilesAreRefusedNamingTheFlag) {
  EXPECT_TRUE(has_status(stream_project_header(3), grpc::StatusCode::RESOURCE_EXHAUSTED, "--max-spool-files"));
  EXPECT_EQ(server_->spooled_files(), 0u);  // the two it had created went with the call
  // Two files held by one call in flight leave none for the next.
  const auto holding_context = context_with_deadline(30s);
  auto holding = stub_->RegisterStream(holding_context.get());
  v1::RegisterStreamRequest header;  // the header only: the uploads never come
  *header.mutable_header() = upload_header("a.xyz", sphere_xyz(), "b.xyz", sphere_xyz(), quick_params());
  ASSERT_TRUE(holding->Write(header));
  for (const auto until = std::chrono::steady_clock::now() + 10s;
       server_->spooled_files() < 2 && std::chrono::steady_clock::now() < until;)
    std::this_thread::sleep_for(10ms);
  EXPECT_TRUE(has_status(stream_project_header(2), grpc::StatusCode::RESOURCE_EXHAUSTED, "--max-spool-files"));
  holding_context->TryCancel();
  EXPECT_EQ(holding->Finish().error_code(), grpc::StatusCode::CANCELLED);
}

class IdleUploads : public HostileFiles {
 protected:
  IdleUploads() : HostileFiles({"--upload-idle-timeout-s", "1"}) {}
};

TEST_F(IdleUploads, AnUploadThatStopsSendingIsEndedAndItsSpoolFilesGo) {
  const auto context = context_with_deadline(30s);
  auto stream = stub_->RegisterStream(context.get());
  v1::RegisterStreamRequest header;  // the header, then nothing
  *header.mutable_header() = upload_header("a.xyz", sphere_xyz(), "b.xyz", sphere_xyz(), quick_params());
  ASSERT_TRUE(stream->Write(header));
  const auto start = std::chrono::steady_clock::now();
  EXPECT_FALSE(stream->Finish().ok());
  EXPECT_LT(std::chrono::steady_clock::now() - start, 5s);
  // The client sees the cancellation at once; the server's account of it follows.
  std::vector<nlohmann::json> requests;
  for (const auto until = std::chrono::steady_clock::now() + 5s;
       requests.empty() && std::chrono::steady_clock::now() < until; requests = server_->log_lines("request"))
    std::this_thread::sleep_for(20ms);
  ASSERT_EQ(requests.size(), 1u);
  EXPECT_EQ(server_->spooled_files(), 0u);
  EXPECT_EQ(requests[0].value("code", ""), "DEADLINE_EXCEEDED");
  EXPECT_NE(requests[0].value("error", "").find("--upload-idle-timeout-s"), std::string::npos) << requests[0].dump();
}

}  // namespace
}  // namespace k4reg::test
