// Projects fanned out across replicas (k4reg-server --peers): three local replicas on loopback. A project through
// the coordinator has the single-replica poses bit for bit and says where its pairs ran (response, metrics, the
// peers' access logs); a peer killed with SIGKILL or drained mid-project loses nothing; a peer whose pair queue is
// full is backpressure, not failure; replicas coordinating at once serve each other's pairs.
// RegisterPair itself refuses bad clouds with the upload status codes and needs the bearer token, or the peer token
// where one is set. A coordinator uses no peer reply that is malformed or late.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <limits>
#include <sstream>
#include <thread>

#include "k4reg/io/cloud_io.h"
#include "peers/peer_reply.h"
#include "api/proto_convert.h"
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

// `after_first_pair` runs once the first pair event arrives; `token`, if any, is sent as the bearer token.
ProjectCall register_project(const ServerProcess& server, const std::function<void()>& after_first_pair = {},
                             const std::string& token = "", const v1::RegisterProjectRequest& request = project_request()) {
  auto stub = server.stub();
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::minutes(3));
  if (!token.empty()) context.AddMetadata("authorization", "Bearer " + token);
  ProjectCall call;
  auto reader = stub->RegisterProject(&context, request);
  for (v1::RegisterProjectEvent event; reader->Read(&event);) {
    if (event.has_pair() && call.pairs_seen++ == 0 && after_first_pair) after_first_pair();
    if (event.has_result()) call.response = event.result();
  }
  call.status = reader->Finish();
  return call;
}

std::string peers_of(const std::vector<const ServerProcess*>& peers) {
  std::string target = "ipv4:";
  for (std::size_t i = 0; i < peers.size(); ++i) {
    if (i > 0) target += ',';
    target += peers[i]->address();
  }
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

// The metric `name`{labels...} summed over its samples whose label text contains `label` (e.g. `code="OK"`).
double metric_sum(const ServerProcess& server, const std::string& name, const std::string& label = "") {
  const auto reply = server.http().Get("/metrics");
  EXPECT_TRUE(reply && reply->status == 200);
  double sum = 0;
  std::istringstream lines(reply ? reply->body : "");
  for (std::string line; std::getline(lines, line);)
    if ((line.rfind(name + "{", 0) == 0 || line.rfind(name + " ", 0) == 0) && line.find(label) != std::string::npos)
      sum += std::stod(line.substr(line.rfind(' ') + 1));
  return sum;
}

TEST_F(ServicePeers, PeersKeepTheScansSoTheNextPairsTravelAsDigests) {
  ServerProcess b({"--workers", "1"});
  ServerProcess a({"--data-root", bunny_dir().string(), "--workers", "1", "--peers", peers_of({&b})});
  const std::string to_b = "peer=\"ipv4:" + b.address() + "\"";
  const ProjectCall first = register_project(a);
  ASSERT_TRUE(first.status.ok()) << first.status.error_message();
  EXPECT_EQ(metric_sum(b, "k4reg_pair_jobs_received_total", "code=\"OK\""), 6);
  EXPECT_GT(metric_sum(b, "k4reg_pair_cache_bytes"), 0);
  EXPECT_EQ(metric_sum(a, "k4reg_peer_pairs_failed_total"), 0);
  EXPECT_EQ(metric_sum(b, "k4reg_peer_pairs_sent_total"), 0) << "b coordinated nothing";
  // Each of the 4 scans travelled once at most, in one of the calls NOT_FOUND sent back for its points.
  const double calls = metric_sum(a, "k4reg_peer_pairs_sent_total", to_b);
  const double bytes = metric_sum(a, "k4reg_peer_pair_bytes_sent_total", to_b);
  EXPECT_GE(calls, 6);
  EXPECT_LE(metric_sum(b, "k4reg_pair_jobs_received_total", "code=\"NOT_FOUND\""), 6);

  // The same project again: b holds every scan, so each pair is one call of digests, and the poses are the same.
  const ProjectCall second = register_project(a);
  ASSERT_TRUE(second.status.ok()) << second.status.error_message();
  expect_same_poses(second.response.result(), *reference_);
  EXPECT_EQ(metric_sum(a, "k4reg_peer_pairs_sent_total", to_b) - calls, 6);
  EXPECT_LT(metric_sum(a, "k4reg_peer_pair_bytes_sent_total", to_b) - bytes, 6 * 1000) << "digests, not points";
  EXPECT_EQ(metric_sum(b, "k4reg_pair_jobs_received_total", "code=\"OK\""), 12);
}

// A port no one listens on now (the kernel's pick, released): for a replica that must name itself as its peer.
int unused_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t length = sizeof address;
  EXPECT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&address), length), 0);
  EXPECT_EQ(::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length), 0);
  ::close(fd);
  return ntohs(address.sin_port);
}

TEST_F(ServicePeers, ProjectsCoordinatedAtOnceDoNotWaitOnEachOther) {
  // One replica that is its own peer, both workers holding a project: the pairs run on the pair pool. Were they
  // jobs of the main pool, each project would wait for pairs no worker is free to run.
  const std::string address = "127.0.0.1:" + std::to_string(unused_port());
  ServerProcess a({"--grpc-listen", address, "--data-root", bunny_dir().string(), "--workers", "2", "--pair-workers",
                   "1", "--peers", "ipv4:" + address});
  ProjectCall first, second;
  std::thread other([&] { second = register_project(a); });
  first = register_project(a);
  other.join();
  for (const ProjectCall* call : {&first, &second}) {
    ASSERT_TRUE(call->status.ok()) << call->status.error_message();
    expect_same_poses(call->response.result(), *reference_);
    EXPECT_EQ(call->response.pairs_on_peers(), 6u);
  }
}

TEST_F(ServicePeers, APeerDrainedMidProjectLosesNothing) {
  ServerProcess b({"--workers", "1", "--drain-grace-s", "30"}), c({"--workers", "1"});
  ServerProcess a({"--data-root", bunny_dir().string(), "--workers", "1", "--peers", peers_of({&b, &c})});
  const ProjectCall call = register_project(a, [&] { b.signal(SIGTERM); });
  ASSERT_TRUE(call.status.ok()) << call.status.error_message();
  expect_same_poses(call.response.result(), *reference_);
  EXPECT_EQ(call.response.pairs_on_peers() + call.response.pairs_local(), 6u);
  EXPECT_EQ(b.wait(), 0) << "the drained peer finished its pairs and exited cleanly";
}

TEST_F(ServicePeers, TheProjectsDeadlineCancelsItsOutstandingPairCalls) {
  ServerProcess b({"--workers", "1", "--pair-workers", "1"});
  ServerProcess a({"--data-root", bunny_dir().string(), "--workers", "1", "--peers", peers_of({&b})});
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::milliseconds(1500));
  auto reader = a.stub()->RegisterProject(&context, project_request());
  for (v1::RegisterProjectEvent event; reader->Read(&event);) {
  }
  EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  // Four pairs were out (--peer-in-flight 4) and b runs one at a time: the rest end cancelled, none runs on.
  int cancelled = 0;
  double pending = -1;
  for (int wait = 0; wait < 100 && (cancelled == 0 || pending != 0); ++wait) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    cancelled = 0;
    for (const nlohmann::json& line : b.log_lines("request"))
      if (line.value("method", "") == "/k4reg.v1.Registration/RegisterPair" && line.value("code", "") == "CANCELLED")
        ++cancelled;
    pending = metric_sum(b, "k4reg_pair_queue_depth") + metric_sum(b, "k4reg_pair_workers_busy");
  }
  EXPECT_GT(cancelled, 0);
  EXPECT_EQ(pending, 0) << "pair jobs still queued or running on the peer";
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

TEST_F(ServicePeers, PairsLargerThanAPeerAcceptsRunOnTheCoordinator) {
  ServerProcess b({"--workers", "1", "--max-pair-mb", "0.5"});
  ServerProcess a({"--data-root", bunny_dir().string(), "--workers", "1", "--peers", peers_of({&b}), "--max-pair-mb",
                   "0.5"});
  const ProjectCall call = register_project(a);
  ASSERT_TRUE(call.status.ok()) << call.status.error_message();
  expect_same_poses(call.response.result(), *reference_);
  EXPECT_EQ(call.response.pairs_local(), 6u) << "a pair of bunny scans is about 0.9 MiB";
  EXPECT_EQ(metric_sum(a, "k4reg_peer_pairs_failed_total", "reason=\"too_large\""), 6);
}

TEST_F(ServicePeers, NoPeerAnsweringRunsThePairsLocally) {
  ServerProcess a({"--data-root", bunny_dir().string(), "--workers", "1", "--peers", "ipv4:127.0.0.1:1"});
  const ProjectCall call = register_project(a);
  ASSERT_TRUE(call.status.ok()) << call.status.error_message();
  expect_same_poses(call.response.result(), *reference_);
  EXPECT_EQ(call.response.pairs_local(), 6u);
}

// RegisterPair answers a peer, but it is a public RPC like any other: bad clouds get the status codes of bad
// uploads, and the bearer token guards it.
class PairJobs : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    for (const char* scan : {"bun045.ply", "bun000.ply"}) {
      const PointCloud cloud = read_cloud((bunny_dir() / scan).string());
      service::cloud_to_proto(cloud, scan, &clouds_.emplace_back());
    }
  }
  static v1::RegisterPairRequest request() {
    v1::RegisterPairRequest request;
    *request.mutable_source() = clouds_[0];
    *request.mutable_target() = clouds_[1];
    *request.mutable_params() = quick_params();
    return request;
  }
  static grpc::Status call(const ServerProcess& server, const v1::RegisterPairRequest& request,
                           const std::string& token = "") {
    grpc::ClientContext context;
    set_timeout(context, std::chrono::seconds(60));
    if (!token.empty()) context.AddMetadata("authorization", "Bearer " + token);
    v1::RegisterPairResponse reply;
    return server.stub()->RegisterPair(&context, request, &reply);
  }
  static std::vector<v1::PairCloud> clouds_;
};

std::vector<v1::PairCloud> PairJobs::clouds_;

TEST_F(PairJobs, BadCloudsAreRefusedWithTheUploadsStatusCodes) {
  ServerProcess server({"--workers", "1", "--max-points", "45000"});  // the bunny scans have 40-41 k points
  ASSERT_TRUE(call(server, request()).ok());

  v1::RegisterPairRequest torn = request();
  torn.mutable_source()->mutable_points_xyz()->pop_back();
  torn.mutable_source()->clear_digest();
  EXPECT_TRUE(has_status(call(server, torn), grpc::StatusCode::INVALID_ARGUMENT, "bun045.ply points_xyz"));

  v1::RegisterPairRequest nan = request();
  const float not_a_number = std::numeric_limits<float>::quiet_NaN();
  nan.mutable_target()->mutable_points_xyz()->replace(4, sizeof not_a_number,
                                                      reinterpret_cast<const char*>(&not_a_number), sizeof not_a_number);
  EXPECT_TRUE(has_status(call(server, nan), grpc::StatusCode::INVALID_ARGUMENT, "NaN"));

  v1::RegisterPairRequest mismatched = request();
  mismatched.mutable_source()->set_digest(service::cloud_digest(clouds_[1]));
  EXPECT_TRUE(has_status(call(server, mismatched), grpc::StatusCode::INVALID_ARGUMENT, "digest does not match"));

  v1::RegisterPairRequest no_origin = request();
  no_origin.mutable_target()->clear_origin_m();
  EXPECT_TRUE(has_status(call(server, no_origin), grpc::StatusCode::INVALID_ARGUMENT, "origin_m"));

  v1::RegisterPairRequest short_intensity = request();
  short_intensity.mutable_source()->set_intensity(std::string(8, '\0'));
  EXPECT_TRUE(has_status(call(server, short_intensity), grpc::StatusCode::INVALID_ARGUMENT, "intensity"));

  v1::RegisterPairRequest unknown = request();
  unknown.mutable_source()->clear_points_xyz();
  unknown.mutable_source()->set_digest(std::string(32, 'x'));
  EXPECT_TRUE(has_status(call(server, unknown), grpc::StatusCode::NOT_FOUND, "send its points"));

  v1::RegisterPairRequest empty = request();
  empty.mutable_target()->clear_points_xyz();
  EXPECT_TRUE(has_status(call(server, empty), grpc::StatusCode::INVALID_ARGUMENT, "empty"));

  v1::RegisterPairRequest degenerate = request();  // every point in one place
  const std::string first_point = degenerate.target().points_xyz().substr(0, 12);
  std::string same;
  for (int i = 0; i < 1000; ++i) same += first_point;
  degenerate.mutable_target()->set_points_xyz(same);
  degenerate.mutable_target()->clear_intensity();
  EXPECT_TRUE(has_status(call(server, degenerate), grpc::StatusCode::INVALID_ARGUMENT, "occupied voxels"));

  v1::RegisterPairRequest huge = request();
  const std::string& points = huge.source().points_xyz();
  huge.mutable_source()->set_points_xyz(points + points);
  EXPECT_TRUE(has_status(call(server, huge), grpc::StatusCode::RESOURCE_EXHAUSTED, "--max-points"));

  // The refusals left the server serving, and none of the bad clouds was kept.
  ASSERT_TRUE(call(server, request()).ok());
  unknown.mutable_source()->set_digest(service::cloud_digest(nan.target()));
  EXPECT_EQ(call(server, unknown).error_code(), grpc::StatusCode::NOT_FOUND);
}

TEST_F(PairJobs, NeedTheBearerTokenAndCoordinatorsSendIt) {
  ServerProcess b({"--workers", "1", "--auth-token", "s3cret"});
  EXPECT_TRUE(has_status(call(b, request()), grpc::StatusCode::UNAUTHENTICATED, "authorization"));
  EXPECT_EQ(call(b, request(), "wrong").error_code(), grpc::StatusCode::UNAUTHENTICATED);
  ServerProcess a({"--data-root", bunny_dir().string(), "--workers", "1", "--auth-token", "s3cret", "--peers",
                   peers_of({&b})});
  const ProjectCall project = register_project(a, {}, "s3cret");
  ASSERT_TRUE(project.status.ok()) << project.status.error_message();
  EXPECT_EQ(project.response.pairs_on_peers(), 6u);
}

TEST_F(PairJobs, WithAPeerTokenTheClientTokenCannotSubmitThemAndCoordinatorsSendThePeerToken) {
  ServerProcess b({"--workers", "1", "--auth-token", "client", "--peer-token", "peer"});
  EXPECT_TRUE(has_status(call(b, request(), "client"), grpc::StatusCode::UNAUTHENTICATED, "invalid bearer token"));
  EXPECT_TRUE(call(b, request(), "peer").ok());
  {
    grpc::ClientContext context;  // and the peer token is no client token
    context.AddMetadata("authorization", "Bearer peer");
    v1::RegisterResponse reply;
    EXPECT_EQ(b.stub()->Register(&context, bunny_request(quick_params()), &reply).error_code(),
              grpc::StatusCode::UNAUTHENTICATED);
  }
  ServerProcess a({"--data-root", bunny_dir().string(), "--workers", "1", "--auth-token", "client", "--peer-token",
                   "peer", "--peers", peers_of({&b})});
  const ProjectCall project = register_project(a, {}, "client");
  ASSERT_TRUE(project.status.ok()) << project.status.error_message();
  EXPECT_EQ(project.response.pairs_on_peers(), 6u);
}

// A peer that answers every pair it gets the points of with a result of the right shape for those clouds, but not
// a number in its transform; or that never answers.
class FakePeer final : public v1::Registration::Service {
 public:
  explicit FakePeer(bool stall) : stall_(stall) {
    grpc::ServerBuilder builder;
    builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), &port_);
    builder.RegisterService(this);
    server_ = builder.BuildAndStart();
  }
  ~FakePeer() override { server_->Shutdown(std::chrono::system_clock::now()); }
  std::string target() const { return "ipv4:127.0.0.1:" + std::to_string(port_); }
  int calls() const { return calls_; }

  grpc::Status RegisterPair(grpc::ServerContext* context, const v1::RegisterPairRequest* request,
                            v1::RegisterPairResponse* reply) override {
    ++calls_;
    while (stall_ && !context->IsCancelled()) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    if (request->source().points_xyz().empty()) return {grpc::StatusCode::NOT_FOUND, "send the points"};
    v1::RegistrationResult& result = *reply->mutable_result();
    result.set_source_points(request->source().points_xyz().size() / 12);
    result.set_target_points(request->target().points_xyz().size() / 12);
    for (int i = 0; i < 16; ++i) result.add_transform(std::numeric_limits<double>::quiet_NaN());
    return grpc::Status::OK;
  }

 private:
  const bool stall_;
  std::atomic<int> calls_{0};
  int port_ = 0;
  std::unique_ptr<grpc::Server> server_;
};

TEST(PeerReplies, AreUsedOnlyWhenTheyAnswerThePairAskedWithARigidFiniteTransform) {
  v1::RegisterPairResponse reply;
  EXPECT_EQ(service::reply_problem(reply, 10, 20), "no result");
  v1::RegistrationResult& result = *reply.mutable_result();
  result.set_source_points(10);
  result.set_target_points(20);
  for (const double value : {1, 0, 0, 5, 0, 0, -1, 2, 0, 1, 0, 3, 0, 0, 0, 1}) result.add_transform(value);
  EXPECT_EQ(service::reply_problem(reply, 10, 20), "");
  EXPECT_NE(service::reply_problem(reply, 20, 10).find("not the 20 and 10 sent"), std::string::npos);
  result.set_transform(0, 2);  // a scale
  EXPECT_EQ(service::reply_problem(reply, 10, 20), "a transform that is not rigid");
  result.set_transform(0, std::numeric_limits<double>::infinity());
  EXPECT_EQ(service::reply_problem(reply, 10, 20), "a NaN or infinite number");
  result.mutable_transform()->RemoveLast();
  EXPECT_EQ(service::reply_problem(reply, 10, 20), "a transform of 15 numbers, not 16");
}

TEST(PeerReplies, ACoordinatorRegistersThePairsItselfWhenAPeerAnswersNonsenseOrNothing) {
  for (const bool stall : {false, true}) {
    FakePeer peer(stall);
    std::vector<std::string> args{"--data-root", bunny_dir().string(), "--workers", "1", "--peers", peer.target()};
    if (stall) args.insert(args.end(), {"--peer-timeout-s", "0.5"});
    ServerProcess a(args);
    v1::RegisterProjectRequest two_scans = project_request();
    two_scans.mutable_scans()->DeleteSubrange(2, 2);
    const ProjectCall project = register_project(a, {}, "", two_scans);
    ASSERT_TRUE(project.status.ok()) << project.status.error_message();
    EXPECT_EQ(project.response.pairs_on_peers(), 0u) << (stall ? "stalled" : "malformed");
    EXPECT_EQ(project.response.pairs_local(), 1u);
    EXPECT_GT(peer.calls(), 0);
  }
}

}  // namespace
}  // namespace k4reg::test
