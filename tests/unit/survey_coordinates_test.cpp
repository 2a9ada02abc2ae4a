// Survey coordinates: a simulated scan pair placed at UTM-sized coordinates (+500 000 E, +5 240 000 N, +300 m),
// written as LAS (scaled integers) and E57 (doubles, scaled integers, or local points with the offset in the scan
// pose), read back and registered. Floats near 5 240 000 m are 0.5 m apart, so only reading in double and
// shifting to a local origin keeps millimetres; the result, reported in the files' frame, must be as precise as
// for the same pair at the origin.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "io_test_support.h"
#include "k4reg/io/cloud_io.h"
#include "k4reg/io/e57_io.h"
#include "k4reg/io/las_io.h"
#include "k4reg/registration/registration.h"
#include "simulated_lab_pair.h"

namespace k4reg {
namespace {

using test::lab_scan;
using test::world;

const Eigen::Vector3d kUtmOffset(500000.0, 5240000.0, 300.0);

// How a scan's own frame sits in its file's frame: turned to grid north, and at UTM coordinates when `far`.
// The near placement differs only by the offset, so any difference in the results comes from the coordinates'
// magnitude.
Eigen::Isometry3d placement(bool far) {
  Eigen::Isometry3d a = Eigen::Isometry3d::Identity();
  a.linear() = Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  if (far) a.translation() = kUtmOffset;
  return a;
}

// The scan's points in its file's frame, as a double-precision cloud (what a survey export holds).
PointCloud placed(const PointCloud& scan, const Eigen::Isometry3d& a) {
  std::vector<Eigen::Vector3d> points;
  for (std::size_t i = 0; i < scan.size(); ++i) points.push_back(a * world(scan, i));
  return make_local_cloud(points, scan.intensity, "placed");
}

struct Errors {
  double rotation_deg, translation_m;
};

// Rotation angle of R_est^T R_truth and the displacement error at the source scan's centre (frame-independent).
Errors errors(const Eigen::Matrix4d& estimate, const Eigen::Matrix4d& truth, const Eigen::Vector3d& centre) {
  const Eigen::Matrix3d r = estimate.topLeftCorner<3, 3>().transpose() * truth.topLeftCorner<3, 3>();
  const double angle = std::acos(std::clamp((r.trace() - 1.0) / 2.0, -1.0, 1.0)) * 180.0 / M_PI;
  const Eigen::Vector4d c = centre.homogeneous();
  return {angle, (estimate * c - truth * c).head<3>().norm()};
}

class SurveyCoordinates : public test::TempDirTest {
 protected:
  static RegistrationParams params() {
    RegistrationParams p;
    p.min_scale_m = 0.1;
    p.overlap = 0.8;
    p.seed = 5;
    return p;
  }

  // Writes both scans with `write`, reads them, registers; returns the errors against the truth in the files' frame.
  Errors run(const std::string& label, bool far, const std::function<void(const std::string&, const PointCloud&,
                                                                             const Eigen::Isometry3d&)>& write) {
    const Eigen::Isometry3d a = placement(far);
    const std::string source_file = path(label + "_source"), target_file = path(label + "_target");
    const sim::SimulatedScan &source_scan = lab_scan(0), &target_scan = lab_scan(2);
    write(source_file, source_scan.cloud, a);
    write(target_file, target_scan.cloud, a);
    const PointCloud source = read_cloud(source_file), target = read_cloud(target_file);
    EXPECT_EQ(source.origin_m.isZero(), !far) << label;
    const RegistrationResult r = register_clouds(source, target, params());
    const Eigen::Matrix4d truth_scan = target_scan.scan_to_scene.inverse() * source_scan.scan_to_scene;
    const Eigen::Matrix4d truth = a.matrix() * truth_scan * a.inverse().matrix();
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < source.size(); ++i) centre += world(source, i);
    centre /= static_cast<double>(source.size());
    const Errors e = errors(r.transform, truth, centre);
    std::printf("%-22s origin %14.3f %14.3f %8.3f  rotation error %.5f deg  translation error %.3f mm  rmse %.2f mm\n",
                label.c_str(), source.origin_m.x(), source.origin_m.y(), source.origin_m.z(), e.rotation_deg,
                1000 * e.translation_m, 1000 * r.rmse_m);
    return e;
  }
};

TEST_F(SurveyCoordinates, FarFromTheOriginRegistersAsPreciselyAsAtTheOrigin) {
  auto las = [](const std::string& file, const PointCloud& scan, const Eigen::Isometry3d& a) {
    write_las(file + ".las", placed(scan, a));
    std::rename((file + ".las").c_str(), file.c_str());  // no extension: the content decides
  };
  auto e57 = [](E57Coordinates coordinates, bool pose) {
    return [=](const std::string& file, const PointCloud& scan, const Eigen::Isometry3d& a) {
      E57WriteOptions options;
      options.coordinates = coordinates;
      E57Scan s;
      s.name = "station";
      s.cloud = pose ? scan : placed(scan, a);  // in the scan's frame with the placement as its pose, or placed
      if (pose) s.pose = a;
      write_e57(file, {s}, options);
    };
  };
  const Errors near = run("LAS at the origin", false, las);
  EXPECT_LT(near.rotation_deg, 0.05);
  EXPECT_LT(near.translation_m, 0.005);
  const Errors far[] = {
      run("LAS at UTM", true, las),
      run("E57 double at UTM", true, e57(E57Coordinates::kCartesianDouble, false)),
      run("E57 scaled int at UTM", true, e57(E57Coordinates::kCartesianScaledInteger, false)),
      run("E57 pose at UTM", true, e57(E57Coordinates::kCartesianDouble, true)),
  };
  for (const Errors& e : far) {
    EXPECT_LT(e.rotation_deg, near.rotation_deg + 0.001);
    EXPECT_LT(e.translation_m, near.translation_m + 0.001);
  }
}

}  // namespace
}  // namespace k4reg
