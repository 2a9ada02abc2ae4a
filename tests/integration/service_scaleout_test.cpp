// Scale-out: three replicas behind one client channel with round_robin all receive work; the response
// says which replica answered (server_id), and each replica logs its own calls.
#include <gtest/gtest.h>

#include <set>

#include "test_support.h"

namespace k4reg::test {
namespace {

TEST(ScaleOut, RoundRobinSpreadsCallsOverThreeReplicas) {
  std::vector<std::unique_ptr<ServerProcess>> servers;
  std::string target = "ipv4:";
  for (const char* id : {"replica-a", "replica-b", "replica-c"}) {
    servers.push_back(std::make_unique<ServerProcess>(
        std::vector<std::string>{"--data-root", bunny_dir().string(), "--workers", "1", "--server-id", id}));
    if (servers.size() > 1) target += ',';
    target += servers.back()->address();
  }
  grpc::ChannelArguments args;
  args.SetLoadBalancingPolicyName("round_robin");
  auto stub = v1::Registration::NewStub(grpc::CreateCustomChannel(target, grpc::InsecureChannelCredentials(), args));

  std::multiset<std::string> answered_by;
  for (int i = 0; i < 12; ++i) {
    grpc::ClientContext context;
    set_timeout(context, std::chrono::seconds(60));
    v1::RegisterResponse reply;
    const grpc::Status status = stub->Register(&context, bunny_request(quick_params()), &reply);
    ASSERT_TRUE(status.ok()) << status.error_message();
    answered_by.insert(reply.server().server_id());
  }
  for (const char* id : {"replica-a", "replica-b", "replica-c"}) EXPECT_GE(answered_by.count(id), 1u) << id;
  std::size_t logged = 0;
  for (const auto& server : servers) {
    const std::size_t lines = server->log_lines("request").size();
    EXPECT_GE(lines, 1u);
    logged += lines;
  }
  EXPECT_EQ(logged, 12u);
}

// With a short maximum connection age the server closes connections (GOAWAY) between and during calls;
// clients reconnect, so replicas added later get traffic, and no call fails.
TEST(ScaleOut, MaxConnectionAgeRecyclesConnectionsWithoutFailingCalls) {
  ServerProcess server({"--data-root", bunny_dir().string(), "--workers", "1", "--max-connection-age-s", "0.3",
                        "--max-connection-age-grace-s", "30"});
  auto stub = server.stub();
  for (int i = 0; i < 8; ++i) {
    grpc::ClientContext context;
    set_timeout(context, std::chrono::seconds(60));
    v1::RegisterResponse reply;
    const grpc::Status status = stub->Register(&context, bunny_request(quick_params()), &reply);
    ASSERT_TRUE(status.ok()) << i << ": " << status.error_message();
  }
}

}  // namespace
}  // namespace k4reg::test
