// write_scan_seeds CORPUS_DIR: the LAS, PTX and E57 seeds of the fuzz corpus, written by the project's own
// writers (no sample files of these formats can be shipped) from 40 points of the Stanford bunny, with every
// writer option that changes the file's layout. Run by tests/fuzz/make_corpus.py.
#include <Eigen/Geometry>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "k4reg/io/cloud_io.h"
#include "k4reg/io/e57_io.h"
#include "k4reg/io/las_io.h"
#include "k4reg/io/ptx_io.h"

namespace k4reg {
namespace {

namespace fs = std::filesystem;

// The first `count` points of a real scan, with a synthetic intensity, optionally moved to survey coordinates.
PointCloud seed_cloud(std::size_t count, bool survey) {
  const PointCloud bunny = read_cloud(std::string(K4REG_TEST_DATA_DIR) + "/bunny/bun000.ply");
  std::vector<Eigen::Vector3d> points;
  std::vector<float> intensity;
  const Eigen::Vector3d shift = survey ? Eigen::Vector3d(512000.0, 5240000.0, 300.0) : Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < count; ++i) {
    points.push_back(bunny.origin_m + bunny.points[i].cast<double>() + shift);
    intensity.push_back(static_cast<float>(i % 13) / 13.0f);
  }
  return make_local_cloud(points, std::move(intensity));
}

void write_seeds(const fs::path& corpus) {
  const PointCloud plain = seed_cloud(40, false), survey = seed_cloud(40, true);
  PointCloud no_intensity = plain;
  no_intensity.intensity.clear();

  const fs::path las = corpus / "fuzz_read_las";
  fs::create_directories(las);
  for (int format : {0, 1, 2, 3, 6, 7, 8, 10}) {
    LasWriteOptions options;
    options.point_format = format;
    options.version_minor = format >= 6 ? 4 : 2;
    write_las((las / ("format" + std::to_string(format) + ".las")).string(), plain, options);
  }
  LasWriteOptions extra;
  extra.extra_bytes = 7;
  write_las((las / "extra_bytes_survey.las").string(), survey, extra);
  LasWriteOptions v13;
  v13.version_minor = 3;
  v13.point_format = 4;
  write_las((las / "v13_format4.las").string(), no_intensity, v13);

  const fs::path ptx = corpus / "fuzz_read_ptx";
  fs::create_directories(ptx);
  Eigen::Matrix4d moved = Eigen::Matrix4d::Identity();
  moved.topLeftCorner<3, 3>() = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  moved.topRightCorner<3, 1>() = Eigen::Vector3d(10.0, -2.0, 0.5);
  write_ptx((ptx / "one_scan.ptx").string(), {PtxScan{plain, Eigen::Matrix4d::Identity(), 8}});
  write_ptx((ptx / "two_scans.ptx").string(), {PtxScan{no_intensity, moved, 0}, PtxScan{survey, moved, 5}});

  const fs::path e57 = corpus / "fuzz_read_e57";
  fs::create_directories(e57);
  E57Scan first{"station 1", plain, Eigen::Isometry3d::Identity(), {}};
  E57Scan second{"station 2", survey, Eigen::Isometry3d(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitX())), {}};
  second.invalid_state.assign(survey.size(), 0);
  second.invalid_state[3] = 2;
  second.invalid_state[7] = 1;
  const struct {
    const char* file;
    E57Coordinates coordinates;
    int intensity_bits;
  } kinds[] = {{"cartesian_double.e57", E57Coordinates::kCartesianDouble, 0},
               {"cartesian_single.e57", E57Coordinates::kCartesianSingle, 12},
               {"scaled_integer.e57", E57Coordinates::kCartesianScaledInteger, 1},
               {"spherical.e57", E57Coordinates::kSphericalDouble, 32}};
  for (const auto& kind : kinds) {
    E57WriteOptions options;
    options.coordinates = kind.coordinates;
    options.intensity_bits = kind.intensity_bits;
    write_e57((e57 / kind.file).string(), {first, second}, options);
  }
}

}  // namespace
}  // namespace k4reg

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: write_scan_seeds CORPUS_DIR\n");
    return 2;
  }
  try {
    k4reg::write_seeds(argv[1]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "write_scan_seeds: %s\n", e.what());
    return 1;
  }
  return 0;
}
