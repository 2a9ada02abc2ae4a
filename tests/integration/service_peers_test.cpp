// Projects fanned out across replicas (k4reg-server --peers): three local replicas on loopback. A project through
// the coordinator has the single-replica poses bit for bit and says where its pairs ran; a peer killed with SIGKILL
// mid-project loses nothing; a peer whose pair queue is full is backpressure, not failure.
#include <gtest/gtest.h>

#include <csignal>

#include "test_support.h"

namespace k4reg::test {
namespace {

const std::vector<std::string> kScans{"bun000.ply", "bun045.ply", "bun090.ply", "bun315.ply"};

v1::RegisterProjectRequest project_request() {
  v1::RegisterProjectRequest request;
  for (const std::string& scan : kScans) request.add_scans()->set_path(scan);
  request.mutable_params()->mutable_pairwise()->set_min_scale_m(0.002);
  request.mutable_params()->mutable_pairwise()->set_overlap(0.5);
  request.mutable_params()->mutable_pairwise()->set_seed(1);
  return request;
}

struct ProjectCall {
  grpc::Status status;
  v1::RegisterProjectResponse response;
  int pairs_seen = 0;
};

// `after_first_pair` runs once the first pair event arrives.
ProjectCall register_project(const ServerProcess& server, const std::function<void()>& after_first_pair = {}) {
  auto stub = server.stub();
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::minutes(3));
  ProjectCall call;
  auto reader = stub->RegisterProject(&context, project_request());
  for (v1::RegisterProjectEvent event; reader->Read(&event);) {
    if (event.has_pair() && call.pairs_seen++ == 0 && after_first_pair) after_first_pair();
    if (event.has_result()) call.response = event.result();
  }
  call.status = reader->Finish();
  return call;
}

std::string peers_of(const std::vector<const ServerProcess*>& peers) {
  std::string target = "ipv4:";
  for (const ServerProcess* peer : peers) target += (target.size() > 5 ? "," : "") + peer->address();
  return target;
}

void expect_same_poses(const v1::ProjectResult& a, const v1::ProjectResult& b) {
  ASSERT_EQ(a.scans_size(), b.scans_size());
  for (int s = 0; s < a.scans_size(); ++s) {
    EXPECT_EQ(a.scans(s).registered(), b.scans(s).registered()) << "scan " << s;
    ASSERT_EQ(a.scans(s).pose_size(), b.scans(s).pose_size());
    for (int i = 0; i < a.scans(s).pose_size(); ++i) EXPECT_EQ(a.scans(s).pose(i), b.scans(s).pose(i)) << "scan " << s;
  }
  for (int l = 0; l < a.links_size(); ++l) EXPECT_EQ(a.links(l).verdict(), b.links(l).verdict()) << "link " << l;
}

class ServicePeers : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    alone_ = new ServerProcess({"--data-root", bunny_dir().string(), "--workers", "1"});
    const ProjectCall call = register_project(*alone_);
    ASSERT_TRUE(call.status.ok()) << call.status.error_message();
    reference_ = new v1::ProjectResult(call.response.result());
  }
  static void TearDownTestSuite() {
    delete alone_;
    delete reference_;
  }
  static ServerProcess* alone_;
  static v1::ProjectResult* reference_;
};

ServerProcess* ServicePeers::alone_ = nullptr;
v1::ProjectResult* ServicePeers::reference_ = nullptr;

TEST_F(ServicePeers, ThreeReplicasGiveTheSingleReplicaPosesAndSayWhereThePairsRan) {
  ServerProcess b({"--workers", "1", "--server-id", "peer-b"}), c({"--workers", "1", "--server-id", "peer-c"});
  ServerProcess a({"--data-root", bunny_dir().string(), "--workers", "1", "--peers", peers_of({&b, &c})});
  const ProjectCall call = register_project(a);
  ASSERT_TRUE(call.status.ok()) << call.status.error_message();
  expect_same_poses(call.response.result(), *reference_);
  EXPECT_EQ(call.response.pairs_on_peers(), 6u);
  EXPECT_EQ(call.response.pairs_local(), 0u);
  // Both peers served pairs, each logged with the project's request id.
  for (const ServerProcess* peer : {&b, &c}) {
    int pairs = 0;
    for (const nlohmann::json& line : peer->log_lines("request"))
      if (line.value("method", "") == "/k4reg.v1.Registration/RegisterPair") {
        ++pairs;
        EXPECT_EQ(line.value("request_id", ""), call.response.request_id());
      }
    EXPECT_GT(pairs, 0);
  }
}

TEST_F(ServicePeers, APeerKilledMidProjectLosesNothing) {
  ServerProcess b({"--workers", "1"}), c({"--workers", "1"});
  ServerProcess a({"--data-root", bunny_dir().string(), "--workers", "1", "--peers", peers_of({&b, &c})});
  const ProjectCall call = register_project(a, [&] { c.signal(SIGKILL); });
  ASSERT_TRUE(call.status.ok()) << call.status.error_message();
  expect_same_poses(call.response.result(), *reference_);
  EXPECT_EQ(call.response.pairs_on_peers() + call.response.pairs_local(), 6u);
}

TEST_F(ServicePeers, AFullPairQueueIsBackpressureNotFailure) {
  ServerProcess b({"--workers", "1", "--pair-workers", "1", "--pair-queue-size", "1"});
  ServerProcess a({"--data-root", bunny_dir().string(), "--workers", "1", "--peers", peers_of({&b}), "--peer-in-flight",
                   "4"});
  const ProjectCall call = register_project(a);
  ASSERT_TRUE(call.status.ok()) << call.status.error_message();
  expect_same_poses(call.response.result(), *reference_);
  EXPECT_EQ(call.response.pairs_on_peers(), 6u) << "every pair waited for the peer rather than running locally";
  EXPECT_GT(call.response.pair_retries(), 0u);
}

TEST_F(ServicePeers, NoPeerAnsweringRunsThePairsLocally) {
  ServerProcess a({"--data-root", bunny_dir().string(), "--workers", "1", "--peers", "ipv4:127.0.0.1:1"});
  const ProjectCall call = register_project(a);
  ASSERT_TRUE(call.status.ok()) << call.status.error_message();
  expect_same_poses(call.response.result(), *reference_);
  EXPECT_EQ(call.response.pairs_local(), 6u);
}

}  // namespace
}  // namespace k4reg::test
