// `k4reg align-project` as a user runs it: the JSON layout, the --out-dir files, and the ways a project can
// be malformed (each one line on stderr and exit code 1).
#include <gtest/gtest.h>

#include <fstream>

#include <Eigen/Geometry>

#include "k4reg/io/cloud_io.h"
#include "k4reg/io/e57_io.h"
#include "test_support.h"

namespace k4reg::test {
namespace {

CommandRun k4reg(std::vector<std::string> args) {
  args.insert(args.begin(), K4REG_BIN_DIR "/k4reg");
  return run_command(std::move(args));
}

std::string bunny(const std::string& name) { return (bunny_dir() / name).string(); }

const std::vector<std::string> kFlags{"--min-scale", "0.002", "--overlap", "0.5", "--seed", "1"};

std::vector<std::string> with_flags(std::vector<std::string> args) {
  args.insert(args.end(), kFlags.begin(), kFlags.end());
  return args;
}

TEST(AlignProjectCommand, JsonHasEveryScanAsGivenAndTheOutDirItsPoses) {
  TempDir dir;
  const CommandRun run = k4reg(with_flags({"align-project", bunny("bun000.ply"), bunny("bun045.ply"), bunny("bun315.ply"),
                                           "--json", "--out-dir", (dir.path() / "out").string()}));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  ASSERT_EQ(j["scans"].size(), 3u);
  EXPECT_EQ(j["scans"][1]["file"], bunny("bun045.ply"));
  for (const auto& scan : j["scans"]) {
    EXPECT_TRUE(scan["registered"].get<bool>());
    EXPECT_EQ(scan["pose"].size(), 16u);
  }
  EXPECT_EQ(j["scans"][0]["pose"][0], 1.0);  // the reference
  ASSERT_EQ(j["links"].size(), 3u);
  for (const char* key : {"source", "target", "transform", "rmse_m", "overlap", "cloud_score", "ambiguity_margin", "accepted",
                          "verdict", "reason", "loops", "loops_closed", "loop_residual_m", "residual_m"})
    EXPECT_TRUE(j["links"][0].contains(key)) << key;
  EXPECT_EQ(j["loops_checked"], 1);
  // Each scan says where its scanner stood: the bunny's range camera looked from outside the object, so none of
  // these could be a terrestrial scanner's origin.
  for (const auto& scan : j["scans"]) {
    ASSERT_TRUE(scan.contains("scanner_position"));
    for (const char* key : {"point_m", "source", "fit", "angular_step_rad", "reason"})
      EXPECT_TRUE(scan["scanner_position"].contains(key)) << key;
    EXPECT_NE(scan["scanner_position"]["source"], "origin");
  }
  // Long work shows itself on stderr even when stderr is no terminal (a script keeping stdout's JSON).
  EXPECT_NE(run.err.find("pair 3/3"), std::string::npos) << run.err;
  for (const char* file : {"bun000.pose.txt", "bun045.pose.txt", "bun315.pose.txt", "project.json"})
    EXPECT_TRUE(fs::exists(dir.path() / "out" / file)) << file;
  std::ifstream saved(dir.path() / "out" / "project.json");
  EXPECT_EQ(nlohmann::json::parse(saved)["scans"], j["scans"]);
}

// A multi-scan E57 counts as its scans, each registered in its own frame; --write-e57 gives them their poses.
TEST(AlignProjectCommand, QuietPrintsNoPairLines) {
  const CommandRun run =
      k4reg(with_flags({"align-project", bunny("bun000.ply"), bunny("bun045.ply"), "--json", "--quiet"}));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.err.find("pair "), std::string::npos) << run.err;
}

TEST(AlignProjectCommand, MultiScanE57InAndRegisteredE57Out) {
  TempDir dir;
  std::vector<E57Scan> scans;
  for (const char* name : {"bun000.ply", "bun045.ply", "bun315.ply"}) {
    E57Scan scan;
    scan.name = name;
    scan.cloud = read_cloud(bunny(name));
    // An instrument pose the project must not apply: each scan in its own frame.
    scan.pose = Eigen::Translation3d(10.0 * scans.size(), 0, 0) * Eigen::AngleAxisd(0.5 * scans.size(), Eigen::Vector3d::UnitZ());
    scans.push_back(std::move(scan));
  }
  const std::string site = (dir.path() / "site.e57").string(), out = (dir.path() / "registered.e57").string();
  write_e57(site, scans);
  const CommandRun run = k4reg(with_flags({"align-project", site, "--json", "--write-e57", out}));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  ASSERT_EQ(j["scans"].size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(j["scans"][k]["file"], site);
    EXPECT_EQ(j["scans"][k]["scan_in_file"], k);
    ASSERT_TRUE(j["scans"][k]["registered"].get<bool>());
  }
  // The written file: every scan's points as read, placed by the pose the JSON gives.
  ASSERT_EQ(count_scans(out), 3u);
  for (std::size_t k = 0; k < 3; ++k) {
    Eigen::Matrix4d pose;
    for (int i = 0; i < 16; ++i) pose(i / 4, i % 4) = j["scans"][k]["pose"][i].get<double>();
    ReadOptions one;
    one.scan_index = k;
    const PointCloud placed = read_cloud(out, one);
    const Eigen::Vector3d local = scans[k].cloud.points[0].cast<double>() + scans[k].cloud.origin_m;
    const Eigen::Vector3d expected = (pose * local.homogeneous()).head<3>();
    EXPECT_LT((placed.points[0].cast<double>() + placed.origin_m - expected).norm(), 1e-5) << k;
  }
}

TEST(AlignProjectCommand, SequencePairsAndTableOutput) {
  const CommandRun run = k4reg(
      with_flags({"align-project", bunny("bun000.ply"), bunny("bun045.ply"), bunny("bun315.ply"), "--pairs", "sequence"}));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("3 of 3 scans registered"), std::string::npos) << run.out;
}

TEST(AlignProjectCommand, ScreenedPairsSayWhatRanInTheJson) {
  const CommandRun run = k4reg(with_flags({"align-project", bunny("bun000.ply"), bunny("bun045.ply"), bunny("bun315.ply"),
                                           "--pairs", "screened", "--partners", "1", "--json"}));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["pairs_used"], "screened");
  EXPECT_EQ(j["pairs_screened"], 3);
  EXPECT_EQ(j["params"]["partners"], 1);
  const CommandRun zero = k4reg(with_flags({"align-project", bunny("bun000.ply"), bunny("bun045.ply"), "--partners", "0"}));
  EXPECT_NE(zero.exit_code, 0);
}

TEST(AlignProjectCommand, MalformedProjectsAreOneLineAndExitOne) {
  TempDir dir;
  const std::string garbage = (dir.path() / "garbage.ply").string();
  std::ofstream(garbage) << "ply\nthis is not a header\n";
  const std::string pairs = (dir.path() / "pairs.txt").string();
  std::ofstream(pairs) << "0 1\n0 7\n";
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const std::vector<Case> cases{
      {{"align-project", bunny("bun000.ply"), bunny("bun000.ply")}, "given twice"},
      {{"align-project", bunny("bun000.ply")}, "at least 2 scans"},
      {{"align-project", bunny("bun000.ply"), garbage}, "garbage.ply"},
      {{"align-project", bunny("bun000.ply"), bunny("bun045.ply"), "--pairs", pairs}, "names a scan beyond"},
      {{"align-project", bunny("bun000.ply"), bunny("bun045.ply"), "--reference", "2"}, "reference scan 2 is out of range"},
  };
  for (const Case& c : cases) {
    const CommandRun run = k4reg(with_flags(c.args));
    EXPECT_EQ(run.exit_code, 1) << c.message;
    EXPECT_NE(run.err.find(c.message), std::string::npos) << run.err;
    EXPECT_TRUE(run.out.empty()) << run.out;
  }
}

}  // namespace
}  // namespace k4reg::test
