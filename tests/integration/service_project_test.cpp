// RegisterProject over gRPC and POST /v1/register-project over HTTP against the real server: the same poses
// as `k4reg align-project` for the same request and seed, the events of the stream, and malformed projects.
#include <gtest/gtest.h>

#include "http/http_json.h"
#include "k4reg/io/cloud_io.h"
#include "k4reg/util/crc32c.h"
#include "test_support.h"

namespace k4reg::test {
namespace {

const std::vector<std::string> kScans{"bun000.ply", "bun045.ply", "bun315.ply"};

v1::ProjectParams project_params() {
  v1::ProjectParams params;
  params.mutable_pairwise()->set_min_scale_m(0.002);
  params.mutable_pairwise()->set_overlap(0.5);
  params.mutable_pairwise()->set_seed(1);
  return params;
}

v1::RegisterProjectRequest by_path(const std::vector<std::string>& files) {
  v1::RegisterProjectRequest request;
  for (const std::string& file : files) request.add_scans()->set_path(file);
  *request.mutable_params() = project_params();
  return request;
}

struct ProjectCall {
  grpc::Status status;
  std::vector<v1::RegisterProjectEvent> events;
};

ProjectCall register_project(const ServerProcess& server, const v1::RegisterProjectRequest& request) {
  auto stub = server.stub();
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::minutes(3));
  ProjectCall call;
  auto reader = stub->RegisterProject(&context, request);
  for (v1::RegisterProjectEvent event; reader->Read(&event);) call.events.push_back(event);
  call.status = reader->Finish();
  return call;
}

class ServiceProject : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    server_ = new ServerProcess({"--data-root", bunny_dir().string(), "--workers", "2", "--server-id", "project-test"});
    // The local reference: what `k4reg align-project` computes with the same parameters.
    std::vector<std::string> args{K4REG_BIN_DIR "/k4reg", "align-project"};
    for (const std::string& scan : kScans) args.push_back((bunny_dir() / scan).string());
    for (const char* flag : {"--min-scale", "0.002", "--overlap", "0.5", "--seed", "1", "--json"}) args.push_back(flag);
    const CommandRun cli = run_command(args);
    ASSERT_EQ(cli.exit_code, 0) << cli.err;
    local_ = new nlohmann::json(nlohmann::json::parse(cli.out));
  }
  static void TearDownTestSuite() {
    delete server_;
    delete local_;
  }
  static void expect_cli_poses(const v1::ProjectResult& result) {
    ASSERT_EQ(result.scans_size(), 3);
    for (int i = 0; i < 3; ++i) {
      const nlohmann::json& scan = (*local_)["scans"][i];
      ASSERT_EQ(result.scans(i).registered(), scan["registered"].get<bool>()) << i;
      ASSERT_EQ(result.scans(i).pose_size(), 16) << i;
      for (int k = 0; k < 16; ++k) EXPECT_EQ(result.scans(i).pose(k), scan["pose"][k].get<double>()) << i << " " << k;
    }
  }

  static ServerProcess* server_;
  static nlohmann::json* local_;
};
ServerProcess* ServiceProject::server_ = nullptr;
nlohmann::json* ServiceProject::local_ = nullptr;

TEST_F(ServiceProject, GrpcByPathGivesTheCliPosesAfterQueuedStagesAndPairs) {
  const ProjectCall call = register_project(*server_, by_path(kScans));
  ASSERT_TRUE(call.status.ok()) << call.status.error_message();
  ASSERT_FALSE(call.events.empty());
  EXPECT_TRUE(call.events.front().has_queued());
  ASSERT_TRUE(call.events.back().has_result());
  std::vector<std::string> stages;
  int pairs = 0;
  for (const auto& event : call.events) {
    if (event.has_stage() && event.stage().phase() == v1::StageEvent::PHASE_STARTED) stages.push_back(event.stage().stage());
    if (event.has_pair()) {
      EXPECT_EQ(event.pair().index(), static_cast<std::uint32_t>(pairs));
      EXPECT_EQ(event.pair().pairs(), 3u);
      EXPECT_TRUE(event.pair().error().empty());
      ++pairs;
    }
  }
  EXPECT_EQ(pairs, 3);
  EXPECT_EQ(stages, (std::vector<std::string>{"load", "pairs", "selection", "refinement"}));
  const v1::RegisterProjectResponse& response = call.events.back().result();
  expect_cli_poses(response.result());
  EXPECT_EQ(response.result().scans(1).file(), "bun045.ply");
  EXPECT_EQ(response.result().links_size(), 3);
  EXPECT_EQ(response.server().server_id(), "project-test");
  EXPECT_GT(response.timings().registration_s(), 0.0);
}

TEST_F(ServiceProject, HttpJsonGivesTheCliPoses) {
  auto http = server_->http();
  const HttpReply reply = reply_of(http.Post("/v1/register-project", service::to_json(by_path(kScans)), "application/json"));
  ASSERT_EQ(reply.status, 200) << reply.body;
  v1::RegisterProjectResponse response;
  service::from_json(reply.body, response);
  expect_cli_poses(response.result());
}

// `k4reg register-project` sends the files inline (or names them with --ref) and prints align-project's JSON.
TEST_F(ServiceProject, RegisterProjectCommandUploadOrReferenceGivesTheCliPoses) {
  for (bool by_reference : {false, true}) {
    std::vector<std::string> args{K4REG_BIN_DIR "/k4reg", "register-project", "--server", server_->address()};
    for (const std::string& scan : kScans) args.push_back(by_reference ? scan : (bunny_dir() / scan).string());
    for (const char* flag : {"--min-scale", "0.002", "--overlap", "0.5", "--seed", "1", "--json"}) args.push_back(flag);
    if (by_reference) args.push_back("--ref");
    const CommandRun run = run_command(args);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const nlohmann::json j = nlohmann::json::parse(run.out);
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(j["scans"][i]["pose"], (*local_)["scans"][i]["pose"]) << i;
      EXPECT_EQ(j["scans"][i]["file"], args[4 + i]) << i;  // as given
    }
    EXPECT_EQ(j["server"]["server_id"], "project-test");
  }
  const CommandRun missing = run_command({K4REG_BIN_DIR "/k4reg", "register-project", "--server", server_->address(), "--ref",
                                          "bun000.ply", "nothing-here.ply"});
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("NOT_FOUND"), std::string::npos) << missing.err;
}

TEST_F(ServiceProject, ScanThatOverlapsNothingIsNotRegisteredAndTheRestAre) {
  // A mirrored bunny, sent inline: shaped like the others, but no rigid motion puts it on them.
  const PointCloud original = read_cloud((bunny_dir() / "bun045.ply").string());
  std::vector<Eigen::Vector3d> mirrored;
  for (const Eigen::Vector3f& p : original.points) mirrored.push_back(Eigen::Vector3d(-p.x(), p.y(), p.z()) + original.origin_m);
  TempDir dir;
  write_cloud((dir.path() / "mirrored.ply").string(), make_local_cloud(mirrored, {}));
  v1::RegisterProjectRequest request = by_path(kScans);
  v1::InlineCloud& inline_scan = *request.add_scans()->mutable_inline_cloud();
  inline_scan.set_data(read_file(dir.path() / "mirrored.ply"));
  inline_scan.set_file_name("mirrored.ply");
  const ProjectCall call = register_project(*server_, request);
  ASSERT_TRUE(call.status.ok()) << call.status.error_message();
  const v1::ProjectResult& result = call.events.back().result().result();
  EXPECT_FALSE(result.scans(3).registered());
  EXPECT_TRUE(result.scans(3).pose().empty());
  EXPECT_FALSE(result.scans(3).reason().empty());
  EXPECT_EQ(result.scans(3).file(), "mirrored.ply");
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(result.scans(i).registered()) << i;
}

TEST_F(ServiceProject, MalformedProjectsAreRefusedWithAReason) {
  struct Case {
    v1::RegisterProjectRequest request;
    grpc::StatusCode code;
    std::string message;
    int http_status;
  };
  v1::RegisterProjectRequest broken = by_path({"bun000.ply"});
  broken.add_scans()->mutable_inline_cloud()->set_data("ply\nthis is no header\n");
  broken.mutable_scans(1)->mutable_inline_cloud()->set_file_name("broken.ply");
  v1::RegisterProjectRequest far_reference = by_path(kScans);
  far_reference.mutable_params()->set_reference(3);
  const std::vector<Case> cases{
      {by_path({}), grpc::StatusCode::INVALID_ARGUMENT, "at least 2 scans, got 0", 400},
      {by_path({"bun000.ply"}), grpc::StatusCode::INVALID_ARGUMENT, "at least 2 scans, got 1", 400},
      {by_path({"bun000.ply", "bun045.ply", "bun000.ply"}), grpc::StatusCode::INVALID_ARGUMENT, "given twice", 400},
      {by_path({"bun000.ply", "missing.ply"}), grpc::StatusCode::NOT_FOUND, "missing.ply", 404},
      {by_path({"bun000.ply", "../bunny/../../etc/passwd"}), grpc::StatusCode::PERMISSION_DENIED, "", 403},
      {broken, grpc::StatusCode::INVALID_ARGUMENT, "broken.ply", 400},
      {far_reference, grpc::StatusCode::INVALID_ARGUMENT, "reference 3 is out of range", 400},
  };
  auto http = server_->http();
  for (const Case& c : cases) {
    const ProjectCall call = register_project(*server_, c.request);
    EXPECT_EQ(call.status.error_code(), c.code) << c.message << ": " << call.status.error_message();
    EXPECT_NE(call.status.error_message().find(c.message), std::string::npos) << call.status.error_message();
    const HttpReply reply = reply_of(http.Post("/v1/register-project", service::to_json(c.request), "application/json"));
    EXPECT_EQ(reply.status, c.http_status) << c.message << ": " << reply.body;
  }
}

// RegisterProjectStream (what `k4reg register-project` uploads with, above) checks every chunk against the
// header: a chunk for a scan the header does not upload, or bytes whose CRC-32C differs, end the call.
TEST_F(ServiceProject, StreamedUploadRefusesChunksItCannotPlace) {
  const std::string bytes = read_file(bunny_dir() / "bun045.ply");
  auto call = [&](std::uint32_t chunk_scan, std::uint32_t declared_crc) {
    auto stub = server_->stub();
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::minutes(1));
    auto stream = stub->RegisterProjectStream(&context);
    v1::RegisterProjectStreamRequest header;
    header.mutable_header()->add_scans()->set_path("bun000.ply");
    v1::UploadedFile& upload = *header.mutable_header()->add_scans()->mutable_upload();
    upload.set_file_name("bun045.ply");
    upload.set_size_bytes(bytes.size());
    upload.set_crc32c(declared_crc);
    *header.mutable_header()->mutable_params() = project_params();
    bool open = stream->Write(header);
    for (std::size_t at = 0; open && at < bytes.size(); at += 1 << 20) {
      v1::RegisterProjectStreamRequest chunk;
      chunk.mutable_chunk()->set_scan(chunk_scan);
      chunk.mutable_chunk()->set_data(bytes.substr(at, 1 << 20));
      open = stream->Write(chunk);
    }
    if (open) stream->WritesDone();
    for (v1::RegisterProjectEvent event; stream->Read(&event);) {
    }
    return stream->Finish();
  };
  const grpc::Status path_chunk = call(0, crc32c(bytes));
  EXPECT_EQ(path_chunk.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << path_chunk.error_message();
  EXPECT_NE(path_chunk.error_message().find("scan 0, which is not an upload"), std::string::npos) << path_chunk.error_message();
  const grpc::Status beyond = call(2, crc32c(bytes));
  EXPECT_EQ(beyond.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << beyond.error_message();
  const grpc::Status corrupted = call(1, crc32c(bytes) ^ 1u);
  EXPECT_EQ(corrupted.error_code(), grpc::StatusCode::DATA_LOSS) << corrupted.error_message();
  EXPECT_NE(corrupted.error_message().find("scan 1 upload bun045.ply"), std::string::npos) << corrupted.error_message();
}

}  // namespace
}  // namespace k4reg::test
