// Errors never quote a file's content: a hostile file, or a symlink swapped onto a secret, must not have its bytes
// echoed to a client in an error message. Every field a reader can refuse holds a marker here; the readers must
// refuse each file (by line, position and kind) without the marker in their message. E57's XML: e57_io_test.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "io_test_support.h"
#include "k4reg/io/cloud_io.h"
#include "k4reg/io/gt_pairs.h"
#include "k4reg/io/matrix_file.h"

namespace k4reg::test {
namespace {

constexpr const char* kMarker = "SECRET-7f3a";

std::string with_marker(std::string text) {
  for (std::size_t at; (at = text.find('@')) != std::string::npos;) text.replace(at, 1, kMarker);
  return text;
}

// Expects `read` to throw a k4reg::Error whose message lacks the marker.
void expect_refused_without_marker(const std::string& what, const std::function<void()>& read) {
  SCOPED_TRACE(what);
  try {
    read();
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).find(kMarker), std::string::npos) << e.what();
  }
}

void expect_cloud_refused(const std::string& file_name, const std::string& text) {
  expect_refused_without_marker(file_name + ": " + text, [&] { read_cloud_bytes(with_marker(text), file_name); });
}

const std::string kPlyXyz = "property float x\nproperty float y\nproperty float z\n";

TEST(FileTextInErrors, PlyHeaderAndBody) {
  for (const std::string& text : std::vector<std::string>{
           "@\nformat ascii 1.0\nend_header\n",
           "ply\nformat @ 1.0\nelement vertex 1\n" + kPlyXyz + "end_header\n0 0 0\n",
           "ply\nformat ascii @\nelement vertex 1\n" + kPlyXyz + "end_header\n0 0 0\n",
           "ply\nformat ascii 1.0\nelement vertex @\n" + kPlyXyz + "end_header\n0 0 0\n",
           "ply\nformat ascii 1.0\nelement vertex 1\nproperty @ x\nend_header\n0\n",
           "ply\nformat ascii 1.0\nelement vertex 1\nproperty list @ int x\nend_header\n0\n",
           "ply\nformat ascii 1.0\n@ 1\nend_header\n",
           "ply\nformat ascii 1.0\nelement vertex 1\nproperty float @\nend_header\n0\n",  // no x
           // A bad value of a property the file names; a bad list count of an element the file names.
           "ply\nformat ascii 1.0\nelement vertex 1\n" + kPlyXyz + "property float @\nend_header\n0 0 0 @\n",
           "ply\nformat ascii 1.0\nelement @ 1\nproperty list uchar int @\nelement vertex 1\n" + kPlyXyz +
               "end_header\n@\n0 0 0\n",
           "ply\nformat ascii 1.0\nelement vertex 1\nproperty list uchar int @\n" + kPlyXyz + "end_header\n@ 0 0 0\n",
           // Truncated: the element and list the file names run past its end.
           "ply\nformat ascii 1.0\nelement @ 3\nproperty float @\nelement vertex 1\n" + kPlyXyz + "end_header\n1\n",
           "ply\nformat binary_little_endian 1.0\nelement @ 3\nproperty float @\nelement vertex 1\n" + kPlyXyz +
               "end_header\n1234",
           "ply\nformat binary_little_endian 1.0\nelement @ 1\nproperty list uchar float @\nelement vertex 1\n" +
               kPlyXyz + "end_header\n\x09" + "1234",
       })
    expect_cloud_refused("cloud.ply", text);
}

TEST(FileTextInErrors, PcdHeaderAndBody) {
  const std::string fields = "FIELDS x y z @\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n";
  for (const std::string& text : std::vector<std::string>{
           "@\nFIELDS x y z\n",
           "VERSION 0.7\n@ 1\n",
           "VERSION 0.7\n" + fields + "WIDTH @\nPOINTS 1\nDATA ascii\n0 0 0 0\n",
           "VERSION 0.7\n" + fields + "POINTS 1\nDATA @\n0 0 0 0\n",
           "VERSION 0.7\nFIELDS x y z @\nSIZE 4 4 4 @\nTYPE F F F F\nPOINTS 1\nDATA ascii\n0 0 0 0\n",
           "VERSION 0.7\nFIELDS x y z @\nSIZE 4 4 4 4\nTYPE F F F @\nPOINTS 1\nDATA ascii\n0 0 0 0\n",
           "VERSION 0.7\nFIELDS x y z @\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 @\nPOINTS 1\nDATA ascii\n0 0 0 0\n",
           "VERSION 0.7\nFIELDS x y z @\nSIZE 4 4 4 2\nTYPE F F F F\nPOINTS 1\nDATA ascii\n0 0 0 0\n",
           "VERSION 0.7\n" + fields + "POINTS 1\nDATA ascii\n0 0 0 @\n",
           "VERSION 0.7\n" + fields + "POINTS 1\nDATA ascii\n0 @ 0 0\n",
       })
    expect_cloud_refused("cloud.pcd", text);
}

TEST(FileTextInErrors, XyzAndPtxLines) {
  expect_cloud_refused("cloud.xyz", "1 2 3\n4 @ 6\n");
  expect_cloud_refused("cloud.xyz", "1 2 3\n4 5 6 @\n");
  const std::string pose = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n";
  for (const std::string& text : std::vector<std::string>{
           "@\n1\n" + pose + "1 2 3 0.5\n",
           "1\n@\n" + pose + "1 2 3 0.5\n",
           "1\n1\n@ 0 0\n" + pose.substr(6) + "1 2 3 0.5\n",
           "1\n1\n" + pose.substr(0, 24) + "@ 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n1 2 3 0.5\n",
           "1\n1\n" + pose + "1 @ 3 0.5\n",
       })
    expect_cloud_refused("cloud.ptx", text);
}

class FileTextInErrorsFiles : public TempDirTest {};

TEST_F(FileTextInErrorsFiles, GroundTruthPairsAndMatrices) {
  const std::string rows = "1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n";
  for (const std::string& text : std::vector<std::string>{
           "a.ply b.ply @ 0.01\n" + rows,
           "a.ply b.ply 0.5 0.01 @\n" + rows,
           "@ @ 0.5 0.01\n1 0 0 0\n",
           "a.ply b.ply 0.5 0.01\n1 0 0 @\n0 1 0 0\n0 0 1 0\n0 0 0 1\n",
       }) {
    const std::string file = write_file("gt_pairs.log", with_marker(text));
    expect_refused_without_marker(text, [&] { read_gt_pairs(file); });
  }
  const std::string matrix = write_file("pose.txt", with_marker("1 0 0 @\n0 1 0 0\n0 0 1 0\n0 0 0 1\n"));
  expect_refused_without_marker("matrix", [&] { read_matrix4(matrix); });
}

}  // namespace
}  // namespace k4reg::test
