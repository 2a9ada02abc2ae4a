// Round trips on real scans with ground truth: by reference, inline bytes and streamed upload, each
// bit-identical to calling the core in-process with the same parameters (what `k4reg align` does).
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "k4reg/io/cloud_io.h"
#include "k4reg/registration/registration.h"
#include "api/proto_convert.h"
#include "test_support.h"

namespace k4reg::test {
namespace {

class RoundTrip : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const v1::RegistrationParams params = bunny_params();
    expected_ = new RegistrationResult(register_clouds(read_cloud((bunny_dir() / "bun045.ply").string()),
                                                       read_cloud((bunny_dir() / "bun000.ply").string()),
                                                       service::params_from_proto(params)));
  }
  static void TearDownTestSuite() { delete expected_; }

  // Same transform to the last bit, same counts, and close to the ground truth.
  static void expect_same_as_in_process(const v1::RegisterResponse& reply) {
    const v1::RegistrationResult& r = reply.result();
    const Eigen::Matrix4d transform = to_matrix(r.transform());
    for (int i = 0; i < 16; ++i) EXPECT_EQ(transform(i / 4, i % 4), expected_->transform(i / 4, i % 4)) << i;
    EXPECT_EQ(r.rmse_m(), expected_->rmse_m);
    EXPECT_EQ(r.inliers(), expected_->inliers);
    EXPECT_EQ(r.source_points(), expected_->source_points);
    EXPECT_EQ(r.target_keypoints(), expected_->target_keypoints);
    EXPECT_EQ(r.signal(), expected_->signal);
    EXPECT_EQ(r.seed(), 42u);
    ASSERT_EQ(r.hypotheses_size(), static_cast<int>(expected_->hypotheses.size()));
    EXPECT_EQ(r.ambiguity_margin(), expected_->ambiguity_margin);
    EXPECT_EQ(r.timings_size(), static_cast<int>(expected_->timings.size()));

    const Eigen::Matrix4d truth = bunny_truth("bun045.ply", "bun000.ply");
    EXPECT_LT((transform.topRightCorner<3, 1>() - truth.topRightCorner<3, 1>()).norm(), 0.002);
    const Eigen::AngleAxisd rotation_error(Eigen::Matrix3d(transform.topLeftCorner<3, 3>().transpose() *
                                                           truth.topLeftCorner<3, 3>()));
    EXPECT_LT(rotation_error.angle(), 0.5 * M_PI / 180.0);

    EXPECT_EQ(reply.server().version(), "0.1.0");
    EXPECT_FALSE(reply.server().server_id().empty());
    EXPECT_GT(reply.timings().registration_s(), 0.0);
    EXPECT_GE(reply.timings().request_to_job_start_s(), reply.timings().queue_wait_s());
  }

  static RegistrationResult* expected_;
  ServerProcess server_{{"--data-root", bunny_dir().string(), "--workers", "1"}};
};

RegistrationResult* RoundTrip::expected_ = nullptr;

TEST_F(RoundTrip, ByReference) {
  grpc::ClientContext context;
  context.AddMetadata("x-request-id", "roundtrip-ref-1");
  v1::RegisterResponse reply;
  const grpc::Status status = server_.stub()->Register(&context, bunny_request(bunny_params()), &reply);
  ASSERT_TRUE(status.ok()) << status.error_message();
  expect_same_as_in_process(reply);
  EXPECT_EQ(reply.request_id(), "roundtrip-ref-1");
  const auto echoed = context.GetServerInitialMetadata().find("x-request-id");
  ASSERT_NE(echoed, context.GetServerInitialMetadata().end());
  EXPECT_EQ(std::string(echoed->second.data(), echoed->second.size()), "roundtrip-ref-1");

  const auto lines = server_.log_lines("request");
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0]["request_id"], "roundtrip-ref-1");
  EXPECT_EQ(lines[0]["method"], "/k4reg.v1.Registration/Register");
  EXPECT_EQ(lines[0]["code"], "OK");
  EXPECT_EQ(lines[0]["source_points"], 40097);
  EXPECT_TRUE(lines[0].contains("queue_wait_ms"));
  EXPECT_TRUE(lines[0].contains("duration_ms"));
}

TEST_F(RoundTrip, InlineBytes) {
  v1::RegisterRequest request;
  request.mutable_source()->mutable_inline_cloud()->set_data(read_file(bunny_dir() / "bun045.ply"));
  request.mutable_source()->mutable_inline_cloud()->set_file_name("bun045.ply");
  request.mutable_target()->mutable_inline_cloud()->set_data(read_file(bunny_dir() / "bun000.ply"));
  *request.mutable_params() = bunny_params();
  grpc::ClientContext context;
  v1::RegisterResponse reply;
  const grpc::Status status = server_.stub()->Register(&context, request, &reply);
  ASSERT_TRUE(status.ok()) << status.error_message();
  expect_same_as_in_process(reply);
  EXPECT_EQ(reply.request_id().size(), 36u);  // generated UUID
}

TEST_F(RoundTrip, StreamedUploadWithProgress) {
  const std::string source = read_file(bunny_dir() / "bun045.ply"), target = read_file(bunny_dir() / "bun000.ply");
  auto stub = server_.stub();
  grpc::ClientContext context;
  StreamCall call(*stub, context, upload_header("bun045.ply", source, "bun000.ply", target, bunny_params()),
                  {source, target, 1 << 20});
  const grpc::Status status = call.finish();
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_NE(call.result(), nullptr);
  expect_same_as_in_process(*call.result());
  EXPECT_GT(call.result()->timings().upload_s(), 0.0);

  // queued first, then every stage started and finished in order, then the result.
  const auto& events = call.events();
  ASSERT_TRUE(events.front().has_queued());
  EXPECT_EQ(events.front().queued().position(), 0u);
  std::vector<std::string> finished;
  for (const auto& e : events)
    if (e.has_stage() && e.stage().phase() == v1::StageEvent::PHASE_FINISHED) finished.push_back(e.stage().stage());
  EXPECT_EQ(finished, (std::vector<std::string>{"load", "voxel_grid", "scanner_position", "keypoints", "matching", "icp_setup",
                                               "symmetry_guard", "icp", "verdict", "polish"}));
  EXPECT_EQ(server_.spooled_files(), 0u);
}

TEST_F(RoundTrip, StreamMixingReferenceAndUpload) {
  const std::string source = read_file(bunny_dir() / "bun045.ply");
  v1::UploadHeader header = upload_header("scan.ply", source, "unused", "", bunny_params());
  header.mutable_target()->set_path("bun000.ply");
  auto stub = server_.stub();
  grpc::ClientContext context;
  StreamCall call(*stub, context, header, {source, {}, 100000});
  const grpc::Status status = call.finish();
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_NE(call.result(), nullptr);
  expect_same_as_in_process(*call.result());
}

}  // namespace
}  // namespace k4reg::test
