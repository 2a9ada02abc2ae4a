// Round trip on simulated terrestrial scans with exact ground truth: the server, reading the files by
// reference, returns the same transform as the core in-process, and it is right by the paper's measure.
#include <gtest/gtest.h>

#include <Eigen/LU>

#include "k4reg/io/cloud_io.h"
#include "k4reg/registration/metrics.h"
#include "k4reg/registration/registration.h"
#include "api/proto_convert.h"
#include "sim/scanner.h"
#include "sim/scene.h"
#include "test_support.h"

namespace k4reg::test {
namespace {

TEST(SimulatedScans, LabPairByReferenceMatchesInProcessAndGroundTruth) {
  TempDir data;
  const LabPair lab = simulate_lab_pair(data.path(), 300000);
  const sim::SimulatedScan &source = lab.source, &target = lab.target;

  v1::RegisterRequest request;
  request.mutable_source()->set_path("lab0.ply");
  request.mutable_target()->set_path("lab2.ply");
  request.mutable_params()->set_min_scale_m(0.05);
  request.mutable_params()->set_overlap(0.8);
  request.mutable_params()->set_seed(3);

  ServerProcess server({"--data-root", data.path().string(), "--workers", "1"});
  grpc::ClientContext context;
  v1::RegisterResponse reply;
  const grpc::Status status = server.stub()->Register(&context, request, &reply);
  ASSERT_TRUE(status.ok()) << status.error_message();

  // The files hold what the simulator produced; the server's result equals the in-process one.
  const RegistrationResult local = register_clouds(read_cloud((data.path() / "lab0.ply").string()),
                                                   read_cloud((data.path() / "lab2.ply").string()),
                                                   service::params_from_proto(request.params()));
  const Eigen::Matrix4d transform = to_matrix(reply.result().transform());
  EXPECT_EQ(transform, local.transform);
  EXPECT_EQ(reply.result().signal(), "intensity");

  const Eigen::Matrix4d truth = target.scan_to_scene.inverse() * source.scan_to_scene;
  const TransformError error = transform_error(source.cloud.points, transform, truth);
  EXPECT_TRUE(registration_succeeded(error, kIndoorSuccessRmse_m)) << "RMSE " << error.rmse_m;
  EXPECT_LT(error.rmse_m, 0.02);  // after ICP: under 2 cm against ground truth
}

}  // namespace
}  // namespace k4reg::test
