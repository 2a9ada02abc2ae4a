// The service reads the scanner formats by upload and by reference, detected by content: a simulated lab pair at
// UTM coordinates as E57 (scan pose carrying the offset) and LAS (scaled integers), uploaded through
// RegisterStream under names whose extensions say nothing; PTX and E57 by path. Each result equals the core's
// in-process result on the same files and is right against the ground truth. A corrupt E57 page is DATA_LOSS
// naming the client's file, a LAZ file a clear INVALID_ARGUMENT.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include "k4reg/io/cloud_io.h"
#include "k4reg/io/e57_io.h"
#include "k4reg/io/las_io.h"
#include "k4reg/io/ptx_io.h"
#include "k4reg/registration/registration.h"
#include "api/proto_convert.h"
#include "../unit/simulated_lab_pair.h"
#include "test_support.h"

namespace k4reg::test {
namespace {

class ScanFormats : public ::testing::Test {
 protected:
  void SetUp() override {
    placement_ = Eigen::Isometry3d::Identity();
    placement_.linear() = Eigen::AngleAxisd(-0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    placement_.translation() = Eigen::Vector3d(512000, 5240000, 280);
    const fs::path dir = data_.path();
    E57Scan e57;
    e57.name = "station 0";
    e57.cloud = lab_scan(0).cloud;  // scan frame; the pose places it
    e57.pose = placement_;
    write_e57((dir / "source.e57").string(), {e57});
    write_las((dir / "target.las").string(), placed(lab_scan(2).cloud));
    std::vector<PtxScan> ptx(1);
    ptx[0].cloud = lab_scan(0).cloud;
    ptx[0].scanner_to_file = placement_.matrix();
    write_ptx((dir / "source.ptx").string(), ptx);
  }

  PointCloud placed(const PointCloud& scan) const {
    std::vector<Eigen::Vector3d> points;
    for (std::size_t i = 0; i < scan.size(); ++i) points.push_back(placement_ * (scan.origin_m + scan.points[i].cast<double>()));
    return make_local_cloud(points, scan.intensity, "placed");
  }

  static v1::RegistrationParams params() {
    v1::RegistrationParams p;
    p.set_min_scale_m(0.1);
    p.set_overlap(0.8);
    p.set_seed(5);
    return p;
  }

  // Same transform as the core on the same files, and right in the files' (UTM) frame.
  void expect_right(const v1::RegisterResponse& reply, const std::string& source_file, const std::string& target_file) {
    const Eigen::Matrix4d transform = to_matrix(reply.result().transform());
    const RegistrationResult local = register_clouds(read_cloud((data_.path() / source_file).string()),
                                                     read_cloud((data_.path() / target_file).string()),
                                                     service::params_from_proto(params()));
    EXPECT_EQ(transform, local.transform);
    const Eigen::Matrix4d truth =
        placement_.matrix() * lab_scan(2).scan_to_scene.inverse() * lab_scan(0).scan_to_scene * placement_.inverse().matrix();
    const Eigen::Vector4d centre = (placement_ * Eigen::Vector3d(0, 0, 1.5)).homogeneous();  // the source station
    EXPECT_LT((transform * centre - truth * centre).norm(), 0.01);
    const Eigen::AngleAxisd rotation_error(Eigen::Matrix3d(transform.topLeftCorner<3, 3>().transpose() * truth.topLeftCorner<3, 3>()));
    EXPECT_LT(rotation_error.angle() * 180 / M_PI, 0.05);
    EXPECT_GT(std::abs(transform(1, 3)), 1.0);  // a real motion, reported in the files' frame
  }

  TempDir data_;
  Eigen::Isometry3d placement_;
  ServerProcess server_{{"--data-root", data_.path().string(), "--workers", "1"}};
};

TEST_F(ScanFormats, UploadedE57AndLasAreDetectedByContent) {
  const std::string source = read_file(data_.path() / "source.e57"), target = read_file(data_.path() / "target.las");
  auto stub = server_.stub();
  grpc::ClientContext context;
  // Names whose extensions give no hint: the server's spool keeps them, the readers go by the magic bytes.
  StreamCall call(*stub, context, upload_header("station0.dat", source, "station2.bin", target, params()),
                  {source, target, 1 << 20});
  const grpc::Status status = call.finish();
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_NE(call.result(), nullptr);
  expect_right(*call.result(), "source.e57", "target.las");
  EXPECT_EQ(server_.spooled_files(), 0u);
}

TEST_F(ScanFormats, PtxAndE57ByReference) {
  v1::RegisterRequest request;
  request.mutable_source()->set_path("source.ptx");
  request.mutable_target()->set_path("target.las");
  *request.mutable_params() = params();
  grpc::ClientContext context;
  v1::RegisterResponse reply;
  const grpc::Status status = server_.stub()->Register(&context, request, &reply);
  ASSERT_TRUE(status.ok()) << status.error_message();
  expect_right(reply, "source.ptx", "target.las");

  request.mutable_source()->set_path("source.e57");
  grpc::ClientContext context2;
  v1::RegisterResponse reply2;
  const grpc::Status status2 = server_.stub()->Register(&context2, request, &reply2);
  ASSERT_TRUE(status2.ok()) << status2.error_message();
  expect_right(reply2, "source.e57", "target.las");
}

TEST_F(ScanFormats, CorruptE57PageIsDataLossAndLazIsRefused) {
  std::string source = read_file(data_.path() / "source.e57");
  source[source.size() / 2] ^= 0x01;  // one bit in a data page; the upload's own CRC-32C is of these bytes
  const std::string target = read_file(data_.path() / "target.las");
  auto stub = server_.stub();
  grpc::ClientContext context;
  StreamCall call(*stub, context, upload_header("damaged.e57", source, "target.las", target, params()),
                  {source, target, 1 << 20});
  EXPECT_TRUE(has_status(call.finish(), grpc::StatusCode::DATA_LOSS, "damaged.e57: CRC-32C mismatch in page"));

  std::string laz = target;
  laz[104] = static_cast<char>(laz[104] | 0x80);  // the LASzip compression bit of the point format
  grpc::ClientContext context2;
  StreamCall call2(*stub, context2, upload_header("source.e57", read_file(data_.path() / "source.e57"), "target.laz", laz, params()),
                   {read_file(data_.path() / "source.e57"), laz, 1 << 20});
  EXPECT_TRUE(has_status(call2.finish(), grpc::StatusCode::INVALID_ARGUMENT,
                         "target.laz: LAZ is not supported; decompress with laszip or pdal first"));
  EXPECT_EQ(server_.spooled_files(), 0u);
}

}  // namespace
}  // namespace k4reg::test
