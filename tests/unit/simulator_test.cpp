// The laser-scan simulator: density law, ground truth, rotations, determinism, point counts, errors.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <tuple>
#include <unistd.h>
#include <unordered_set>
#include <vector>

#include "k4reg/util/error.h"
#include "sim/bvh.h"
#include "k4reg/io/matrix_file.h"
#include "sim/scanner.h"
#include "sim/scene.h"
#include "sim/scene_builder.h"
#include "scene_test_support.h"

namespace k4reg::sim {
namespace {

using Eigen::Vector3d;

TEST(Simulator, DensityFallsOffWithTheSquareOfTheRange) {
  // Two walls facing the scanner, 5 m and 10 m away; equal 1.5 x 1.5 m patches straight ahead.
  Scene scene;
  scene.name = "walls";
  scene.default_max_range_m = 50.0;
  const Surface grey = paint(uniform(0.5));
  scene.primitives.push_back(rect(Vector3d(5, -4, -4), Vector3d::UnitY(), Vector3d::UnitZ(), 8, 8, grey));
  scene.primitives.push_back(rect(Vector3d(-10, -4, -4), Vector3d::UnitY(), Vector3d::UnitZ(), 8, 8, grey));
  scene.stations.push_back({Vector3d::Zero(), "between the walls", {}});
  ScanParams params = params_with(200000);
  params.noise_m = 0.0;
  const auto points = in_scene_frame(simulate_scan(scene, 0, params));
  int near = 0, far = 0;
  for (const auto& p : points) {
    if (std::abs(p.y()) > 0.75 || std::abs(p.z()) > 0.75) continue;
    near += std::abs(p.x() - 5.0) < 0.01;
    far += std::abs(p.x() + 10.0) < 0.01;
  }
  ASSERT_GT(far, 1000);
  EXPECT_NEAR(static_cast<double>(near) / far, 4.0, 0.4) << near << " near, " << far << " far";
}

TEST(Simulator, GroundTruthMapsTheScanOntoSceneSurfaces) {
  // Every scene: lab from the raised station, the others from station 0 (layout 0) and a variant.
  for (const auto& name : scene_names())
    for (const int layout : {0, name == "lab" || name == "arch" ? 0 : 2}) {
      const Scene scene = make_scene(name, layout);
      const int station = name == "lab" ? 3 : 0;
      const double sigma = scene.default_noise_m;
      const auto scan = simulate_scan(scene, station, params_with(std::min<std::size_t>(100000, scene.default_points)));
      const auto residuals = range_residuals(scene, station, scan);
      std::size_t within_4_sigma = 0;
      double worst = 0.0;
      for (const double r : residuals) {
        within_4_sigma += std::abs(r) <= 4.0 * sigma;
        worst = std::max(worst, std::abs(r));
      }
      EXPECT_GT(static_cast<double>(within_4_sigma) / residuals.size(), 0.99) << name << " layout " << layout;
      EXPECT_LT(worst, 30.0 * sigma) << name << " layout " << layout
                                     << ": glass returns have 5x the noise, nothing else is off the surfaces";
    }
}

TEST(Simulator, LabPointsLieInsideTheRoomAndMostlyOnItsShell) {
  // Independent of the ray caster: the room is [0, 15] x [0, 10] x [0, 3.5] m with 0.3 m reveals.
  const auto scan = simulate_scan(make_scene("lab"), 0, params_with(100000));
  std::size_t on_shell = 0;
  for (const auto& p : in_scene_frame(scan)) {
    ASSERT_TRUE(p.x() > -0.32 && p.x() < 15.32 && p.y() > -0.32 && p.y() < 10.32 && p.z() > -0.01 && p.z() < 3.51)
        << p.transpose();
    const double shell = std::min({std::abs(p.x()), std::abs(p.x() - 15.0), std::abs(p.y()), std::abs(p.y() - 10.0),
                                   std::abs(p.z()), std::abs(p.z() - 3.5)});
    on_shell += shell < 0.01;
  }
  EXPECT_GT(static_cast<double>(on_shell) / scan.cloud.size(), 0.5);
}

TEST(Simulator, ScansOfTwoStationsOverlapInTheSceneFrame) {
  const Scene lab = make_scene("lab");
  const auto lab0 = in_scene_frame(simulate_scan(lab, 0, params_with(100000)));
  const auto lab1 = in_scene_frame(simulate_scan(lab, 1, params_with(100000)));
  EXPECT_GT(overlap(lab0, lab1, 0.5), 0.5);
  const Scene arch = make_scene("arch");
  const auto arch0 = in_scene_frame(simulate_scan(arch, 0, params_with(150000)));
  const auto arch1 = in_scene_frame(simulate_scan(arch, 1, params_with(150000)));
  EXPECT_GT(overlap(arch0, arch1, 0.5), 0.2);
  EXPECT_LT(overlap(arch0, arch1, 0.5), 0.8);
}

TEST(Simulator, ScanFramesAreProperRotationsThatDifferAndTiltTheVertical) {
  for (const auto& name : scene_names()) {
    const Scene scene = make_scene(name);
    std::vector<Eigen::Matrix3d> rotations;
    for (int s = 0; s < static_cast<int>(scene.stations.size()); ++s) {
      const auto scan = simulate_scan(scene, s, params_with(2000));
      const Eigen::Matrix3d r = scan.scan_to_scene.topLeftCorner<3, 3>();
      EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
      EXPECT_TRUE((r.transpose() * r).isApprox(Eigen::Matrix3d::Identity(), 1e-12));
      EXPECT_TRUE(scan.scan_to_scene.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1)));
      const Vector3d translation = scan.scan_to_scene.topRightCorner<3, 1>();
      EXPECT_EQ(translation, scene.stations[s].position_m);
      // The scene's up axis, seen in the scan frame, is tilted by more than 10 deg.
      EXPECT_LT((r.transpose() * Vector3d::UnitZ()).z(), std::cos(10.0 * M_PI / 180.0)) << name << " " << s;
      for (const auto& other : rotations) EXPECT_GT((r - other).norm(), 0.1) << name << " " << s;
      rotations.push_back(r);
    }
  }
}

bool same_points(const SimulatedScan& a, const SimulatedScan& b) {
  return a.cloud.size() == b.cloud.size() && a.scan_to_scene == b.scan_to_scene &&
         std::memcmp(a.cloud.points.data(), b.cloud.points.data(), a.cloud.size() * sizeof(Eigen::Vector3f)) == 0 &&
         a.cloud.intensity == b.cloud.intensity;
}

TEST(Simulator, ASeedReproducesTheScanForAnyThreadCount) {
  const Scene scene = make_scene("arch");  // glass, foliage, terrain and people: every random path
  SimulatedScan one_thread, two_threads;
  tbb::task_arena(1).execute([&] { one_thread = simulate_scan(scene, 2, params_with(60000, 7)); });
  tbb::task_arena(2).execute([&] { two_threads = simulate_scan(scene, 2, params_with(60000, 7)); });
  EXPECT_TRUE(same_points(one_thread, two_threads));
  EXPECT_TRUE(same_points(one_thread, simulate_scan(scene, 2, params_with(60000, 7))));
  const auto other_seed = simulate_scan(scene, 2, params_with(60000, 8));
  EXPECT_FALSE(same_points(one_thread, other_seed));
  EXPECT_FALSE(one_thread.scan_to_scene.isApprox(other_seed.scan_to_scene));
}

TEST(Simulator, ReachesTheRequestedPointCount) {
  for (const auto& [name, station, points] : std::vector<std::tuple<std::string, int, std::size_t>>{
           {"lab", 0, 100000}, {"lab", 3, 150000}, {"arch", 3, 100000}}) {
    const auto scan = simulate_scan(make_scene(name), station, params_with(points));
    EXPECT_NEAR(static_cast<double>(scan.cloud.size()), static_cast<double>(points), 0.15 * points) << name << " " << station;
    ASSERT_TRUE(scan.cloud.has_intensity());
    double sum = 0.0, sum2 = 0.0;
    for (const float i : scan.cloud.intensity) {
      ASSERT_TRUE(i >= 0.0f && i <= 1.0f);
      sum += i;
      sum2 += static_cast<double>(i) * i;
    }
    const double mean = sum / scan.cloud.size();
    EXPECT_GT(std::sqrt(sum2 / scan.cloud.size() - mean * mean), 0.05) << "intensity carries the patterns";
  }
}

TEST(Simulator, StationsStandInFreeSpaceAndTheRequiredOnesExist) {
  const Scene lab = make_scene("lab");
  EXPECT_GE(lab.stations.size(), 5u);
  EXPECT_GE(make_scene("arch").stations.size(), 4u);
  for (std::size_t a = 0; a < lab.stations.size(); ++a)
    for (std::size_t b = a + 1; b < lab.stations.size(); ++b) {
      const double d = (lab.stations[a].position_m - lab.stations[b].position_m).norm();
      EXPECT_TRUE(d >= 3.0 && d <= 15.0) << a << "-" << b << ": " << d << " m";
    }
  for (const auto& name : scene_names()) {
    const Scene scene = make_scene(name);
    for (int s = 0; s < static_cast<int>(scene.stations.size()); ++s)
      for (const auto& p : scene.primitives_seen_from(s)) {
        if (std::holds_alternative<HeightField>(p.shape)) continue;
        const Eigen::AlignedBox3d box = bounds(p.shape);
        EXPECT_GT(box.exteriorDistance(scene.stations[s].position_m), 0.3) << name << " station " << s;
      }
  }
}

TEST(Simulator, BadArgumentsThrowInvalidArgument) {
  auto code_of = [](auto&& call) {
    try {
      call();
    } catch (const Error& e) {
      return e.code();
    }
    return ErrorCode::kInternal;
  };
  EXPECT_EQ(code_of([] { make_scene("moon"); }), ErrorCode::kInvalidArgument);
  const Scene lab = make_scene("lab");
  EXPECT_EQ(code_of([&] { simulate_scan(lab, -1, ScanParams{}); }), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code_of([&] { simulate_scan(lab, static_cast<int>(lab.stations.size()), ScanParams{}); }),
            ErrorCode::kInvalidArgument);
  EXPECT_EQ(code_of([&] { simulate_scan(lab, 0, params_with(999)); }), ErrorCode::kInvalidArgument);
  ScanParams bad_noise;
  bad_noise.noise_m = -0.001;
  EXPECT_EQ(code_of([&] { simulate_scan(lab, 0, bad_noise); }), ErrorCode::kInvalidArgument);
  ScanParams bad_range;
  bad_range.max_range_m = -1.0;
  EXPECT_EQ(code_of([&] { simulate_scan(lab, 0, bad_range); }), ErrorCode::kInvalidArgument);
}

TEST(MatrixFile, RoundTripsExactlyAndRejectsMalformedFiles) {
  const auto dir = std::filesystem::temp_directory_path() / ("k4reg_gt_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto scan = simulate_scan(make_scene("lab"), 1, params_with(2000));
  const std::string path = (dir / "scan.gt.txt").string();
  write_matrix4(path, scan.scan_to_scene);
  EXPECT_EQ(read_matrix4(path), scan.scan_to_scene);

  auto code_of_reading = [&](const std::string& text) {
    const std::string bad = (dir / "bad.txt").string();
    std::ofstream(bad) << text;
    try {
      read_matrix4(bad);
    } catch (const Error& e) {
      return e.code();
    }
    return ErrorCode::kInternal;
  };
  EXPECT_EQ(code_of_reading("# comment\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n"), ErrorCode::kInternal);  // valid
  EXPECT_EQ(code_of_reading("1 0 0 0\n0 1 0 0\n0 0 1 0\n"), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code_of_reading("1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1 5\n"), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code_of_reading("1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 x 1\n"), ErrorCode::kInvalidArgument);
  EXPECT_EQ(code_of_reading("1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 1 1\n"), ErrorCode::kInvalidArgument);
  try {
    read_matrix4((dir / "missing.txt").string());
    ADD_FAILURE() << "no exception";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kNotFound);
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace k4reg::sim
