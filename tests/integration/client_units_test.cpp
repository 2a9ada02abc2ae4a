// Parts of the k4reg command line that need no server: latency statistics, --server parsing, the mapping of
// registration flags to the request, and a project result as the service sends it back.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "remote/channel.h"
#include "reports/latency_stats.h"
#include "reports/progress_bar.h"
#include "api/project_convert.h"
#include "remote/project_mapping.h"
#include "reports/project_report.h"
#include "remote/proto_mapping.h"

namespace k4reg::cli {
namespace {

std::vector<double> one_to(int n) {
  std::vector<double> values(n);
  std::iota(values.begin(), values.end(), 1.0);
  return values;
}

TEST(LatencyStats, NearestRankPercentilesOfOneToHundred) {
  std::vector<double> shuffled = one_to(100);
  std::reverse(shuffled.begin(), shuffled.end());
  const LatencySummary s = summarize(shuffled);
  EXPECT_EQ(s.count, 100u);
  EXPECT_EQ(s.min, 1);
  EXPECT_EQ(s.max, 100);
  EXPECT_DOUBLE_EQ(s.mean, 50.5);
  EXPECT_EQ(s.p50, 50);
  EXPECT_EQ(s.p90, 90);
  EXPECT_EQ(s.p95, 95);
  EXPECT_EQ(s.p99, 99);
}

TEST(LatencyStats, PercentilesAreMeasuredValues) {
  // Ten samples: p99 is the largest (rank ceil(9.9) = 10), p50 the fifth, p90 the ninth.
  const LatencySummary s = summarize({0.010, 0.020, 0.030, 0.040, 0.050, 0.060, 0.070, 0.080, 0.090, 1.0});
  EXPECT_EQ(s.p50, 0.050);
  EXPECT_EQ(s.p90, 0.090);
  EXPECT_EQ(s.p95, 1.0);
  EXPECT_EQ(s.p99, 1.0);
  const std::vector<double> sorted{3.0};
  EXPECT_EQ(percentile(sorted, 0), 3.0);
  EXPECT_EQ(percentile(sorted, 100), 3.0);
}

TEST(LatencyStats, EmptyIsAllZero) {
  const LatencySummary s = summarize({});
  EXPECT_EQ(s.count, 0u);
  EXPECT_EQ(s.p99, 0.0);
  EXPECT_TRUE(histogram({}, 10).empty());
}

TEST(LatencyStats, HistogramSpansMinToMaxInEqualBuckets) {
  const std::vector<HistogramBucket> buckets = histogram(one_to(100), 10);
  ASSERT_EQ(buckets.size(), 10u);
  EXPECT_EQ(buckets.front().lower, 1.0);
  EXPECT_EQ(buckets.back().upper, 100.0);
  std::size_t total = 0;
  for (const HistogramBucket& b : buckets) {
    EXPECT_NEAR(b.upper - b.lower, 9.9, 1e-9);
    total += b.count;
  }
  EXPECT_EQ(total, 100u);
  EXPECT_EQ(buckets.front().count, 10u);  // 1..10 < 10.9
  EXPECT_EQ(buckets.back().count, 10u);   // 91..100, the maximum included

  const std::vector<HistogramBucket> same = histogram({2.0, 2.0, 2.0}, 10);
  ASSERT_EQ(same.size(), 1u);
  EXPECT_EQ(same[0].count, 3u);
}

TEST(ChannelTarget, AddressesAndTargets) {
  EXPECT_EQ(channel_target("127.0.0.1:50051"), "127.0.0.1:50051");
  EXPECT_EQ(channel_target("scanner-office:50051"), "scanner-office:50051");
  EXPECT_EQ(channel_target("127.0.0.1:1,127.0.0.1:2"), "ipv4:127.0.0.1:1,127.0.0.1:2");
  EXPECT_EQ(channel_target("[::1]:1,[::1]:2"), "ipv6:[::1]:1,[::1]:2");
  EXPECT_EQ(channel_target("dns:///k4reg.example:50051"), "dns:///k4reg.example:50051");
  EXPECT_EQ(channel_target("ipv4:10.0.0.1:1"), "ipv4:10.0.0.1:1");
  for (const char* bad : {"", "localhost", "host:", ":50051", "host:0", "host:70000", "host:http", "::1:50051",
                          "a:1,b:2", "127.0.0.1:1,[::1]:2", "127.0.0.1:1,"})
    EXPECT_THROW(channel_target(bad), std::invalid_argument) << bad;
}

TEST(RequestId, IsAVersionFourUuid) {
  const std::string id = new_request_id();
  ASSERT_EQ(id.size(), 36u);
  EXPECT_EQ(id[14], '4');
  EXPECT_NE(std::string("89ab").find(id[19]), std::string::npos);
  EXPECT_NE(id, new_request_id());
}

TEST(HumanBytes, DecimalUnits) {
  EXPECT_EQ(human_bytes(999), "999 B");
  EXPECT_EQ(human_bytes(964'600), "964.6 kB");
  EXPECT_EQ(human_bytes(2.5e9), "2.5 GB");
}

// A remote request carries exactly the flags the user gave, so the server's defaults apply to the rest.
TEST(RegistrationFlagsToProto, OnlyTheGivenFlagsAreSent) {
  const auto parse = [](std::vector<std::string> args) {
    CLI::App app;
    RegistrationParams params;
    const RegistrationFlags flags = add_registration_flags(app, params);
    std::reverse(args.begin(), args.end());  // CLI11 parses a vector given last argument first
    app.parse(args);
    return params_to_proto(params, flags);
  };
  const v1::RegistrationParams none = parse({});
  EXPECT_FALSE(none.has_min_scale_m());
  EXPECT_EQ(none.free_space(), v1::FREE_SPACE_CHECK_UNSPECIFIED);
  EXPECT_EQ(none.signal(), v1::KEYPOINT_SIGNAL_UNSPECIFIED);
  EXPECT_FALSE(none.has_search_other_side());
  const v1::RegistrationParams one_sided = parse({"--one-sided"});
  EXPECT_TRUE(one_sided.has_search_other_side());
  EXPECT_FALSE(one_sided.search_other_side());

  EXPECT_EQ(parse({"--free-space", "off"}).free_space(), v1::FREE_SPACE_CHECK_OFF);
  EXPECT_EQ(parse({"--free-space", "ON"}).free_space(), v1::FREE_SPACE_CHECK_ON);
  const v1::RegistrationParams given = parse({"--free-space", "auto", "--min-scale", "0.05", "--signal", "geometric"});
  EXPECT_EQ(given.free_space(), v1::FREE_SPACE_CHECK_AUTO);
  EXPECT_DOUBLE_EQ(given.min_scale_m(), 0.05);
  EXPECT_EQ(given.signal(), v1::KEYPOINT_SIGNAL_GEOMETRIC);
  EXPECT_THROW(parse({"--free-space", "sometimes"}), CLI::ValidationError);
}

// An ambiguous scan's two placements reach `register-project` as they left the core, and its --json, table and
// --out-dir say it as `align-project`'s do: no pose, no pose file, both candidates.
TEST(ProjectResultFromProto, AnAmbiguousScanKeepsItsTwoCandidatePlacements) {
  ProjectResult core;
  core.scans.resize(2);
  core.scans[0].registered = true;
  Eigen::Matrix4d preferred = Eigen::Matrix4d::Identity(), twin = Eigen::Matrix4d::Identity();
  preferred(0, 3) = 5.0;
  twin.topLeftCorner<2, 2>() << -1, 0, 0, -1;
  twin(0, 3) = 15.0;
  core.scans[1].ambiguous = true;
  core.scans[1].candidate_poses = {preferred, twin};
  core.scans[1].strength = 0.049;
  core.scans[1].reason = "held too weakly";
  v1::ProjectResult message;
  service::project_result_to_proto(core, {"a.ply", "b.ply"}, &message);
  ASSERT_EQ(message.scans(1).candidate_poses_size(), 2);
  EXPECT_EQ(message.scans(1).pose_size(), 0);  // not registered: no pose
  EXPECT_EQ(message.scans(0).candidate_poses_size(), 0);
  const ProjectResult back = project_result_from_proto(message);
  EXPECT_FALSE(back.scans[1].registered);
  EXPECT_TRUE(back.scans[1].ambiguous);
  ASSERT_EQ(back.scans[1].candidate_poses.size(), 2u);
  EXPECT_EQ(back.scans[1].candidate_poses[0], preferred);
  EXPECT_EQ(back.scans[1].candidate_poses[1], twin);
  EXPECT_FALSE(back.scans[0].ambiguous);

  const std::vector<ScanOrigin> origins{{"a.ply", -1}, {"b.ply", -1}};
  const nlohmann::json json = project_to_json(back, origins, ProjectParams{});
  EXPECT_TRUE(json["scans"][1]["pose"].is_null());
  EXPECT_TRUE(json["scans"][1]["ambiguous"].get<bool>());
  ASSERT_EQ(json["scans"][1]["candidate_poses"].size(), 2u);
  EXPECT_EQ(json["scans"][1]["candidate_poses"][1]["pose"][3].get<double>(), 15.0);  // as the proto's JSON: {"pose": [...]}
  EXPECT_TRUE(json["scans"][0]["candidate_poses"].empty());
  std::ostringstream table;
  print_project_table(table, back, origins);
  EXPECT_NE(table.str().find("candidate placement 2 (the twin)"), std::string::npos) << table.str();
}

}  // namespace
}  // namespace k4reg::cli
