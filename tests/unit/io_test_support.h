// Shared by the scan-format reader tests (las_io, ptx_io, e57_io, survey_coordinates): a fresh temporary folder
// per test, error expectations, world coordinates of a cloud.
#pragma once

#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "k4reg/util/error.h"
#include "k4reg/geometry/point_cloud.h"

namespace k4reg::test {

namespace fs = std::filesystem;

class TempDirTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string tmpl = (fs::temp_directory_path() / "k4reg_io_XXXXXX").string();
    ASSERT_NE(::mkdtemp(tmpl.data()), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string path(const std::string& name) const { return (fs::path(dir_) / name).string(); }
  std::string write_file(const std::string& name, const std::string& bytes) const {
    std::ofstream(path(name), std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return path(name);
  }
  static std::string read_bytes(const std::string& file) {
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }

  std::string dir_;
};

// Runs fn and expects a k4reg::Error with `code` whose message names the file and contains `needle`.
inline void expect_error(const std::function<void()>& fn, ErrorCode code, const std::string& file,
                         const std::string& needle) {
  try {
    fn();
    ADD_FAILURE() << "no error for " << file;
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_EQ(e.code(), code) << message;
    EXPECT_NE(message.find(fs::path(file).filename().string()), std::string::npos) << "lacks the file name: " << message;
    EXPECT_NE(message.find(needle), std::string::npos) << "lacks '" << needle << "': " << message;
  }
}

inline Eigen::Vector3d world(const PointCloud& cloud, std::size_t i) {
  return cloud.origin_m + cloud.points[i].cast<double>();
}

}  // namespace k4reg::test
