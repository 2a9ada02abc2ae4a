// Shared by the service integration tests: the real k4reg-server started on an ephemeral loopback port,
// temporary folders, the bunny test data and small request builders.
#pragma once

#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>
#include <sys/types.h>

#include <Eigen/Core>
#include <chrono>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "http/http_lib.h"
#include "k4reg/v1/registration.grpc.pb.h"
#include "sim/scanner.h"

namespace k4reg::test {

namespace fs = std::filesystem;

fs::path bunny_dir();

// argv and envp for execve: `arguments`, and the caller's environment less its K4REG_* variables (they must not
// leak into the program under test) plus `env`. argv/envp point into the strings held alongside them.
struct ExecVectors {
  std::vector<std::string> arguments, environment;
  std::vector<char*> argv, envp;
};
ExecVectors exec_vectors(std::vector<std::string> arguments, const std::map<std::string, std::string>& env);
std::string read_file(const fs::path& path);
void write_file(const fs::path& path, const std::string& bytes);

struct CommandRun {
  int exit_code = -1;
  std::string out, err;
};
// Runs `arguments` (argv[0] a path) with stdout and stderr to files, so neither pipe can fill up, and an
// environment without the caller's K4REG_* variables plus `env`.
CommandRun run_command(std::vector<std::string> arguments, const std::map<std::string, std::string>& env = {});

// A fresh folder under the system temp dir, removed with its contents.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// The real binary, started with `args` plus --grpc-listen and --http-listen on 127.0.0.1:0 (never a fixed
// port, so ctest -j works; each unless `args` has its own), their port files and a private
// --spool-dir; stderr (the JSON log) goes to a file. Killed if still running when destroyed.
class ServerProcess {
 public:
  explicit ServerProcess(const std::vector<std::string>& args, const std::map<std::string, std::string>& env = {});
  ~ServerProcess();
  ServerProcess(const ServerProcess&) = delete;
  ServerProcess& operator=(const ServerProcess&) = delete;

  int port() const { return port_; }
  std::string address() const { return "127.0.0.1:" + std::to_string(port_); }
  int http_port() const { return http_port_; }
  std::string http_url() const { return "http://127.0.0.1:" + std::to_string(http_port_); }
  pid_t pid() const { return pid_; }
  std::shared_ptr<grpc::Channel> channel() const;
  std::unique_ptr<v1::Registration::Stub> stub() const;
  // A cpp-httplib client of the HTTP API that waits up to two minutes for an answer (jobs run meanwhile).
  httplib::Client http() const;
  // The folder given as --spool-dir; the server keeps its uploads in a subfolder of it.
  const fs::path& spool_parent() const { return work_.path(); }
  // Regular files anywhere below the spool parent (uploads in flight or left behind).
  std::size_t spooled_files() const;
  std::string log() const;
  // The JSON log lines whose "msg" is `msg` (e.g. "request").
  std::vector<nlohmann::json> log_lines(const std::string& msg) const;

  void signal(int number) const;
  // Waits for the exit; returns the exit code (or 128 + signal). Kills and fails after `timeout`.
  int wait(std::chrono::seconds timeout = std::chrono::seconds(60));

 private:
  TempDir work_;
  pid_t pid_ = -1;
  int port_ = 0, http_port_ = 0;
  bool exited_ = false;
};

// Parameters under which the bunny pair (bun045 onto bun000) registers in about a second.
v1::RegistrationParams bunny_params();
// A job that takes about `seconds` on one core (many 4PCS bases on the bunny pair).
v1::RegistrationParams slow_params(double seconds);
// A quick job (~0.1 s) whose result is not checked: for load distribution and queue tests.
v1::RegistrationParams quick_params();

v1::RegisterRequest bunny_request(const v1::RegistrationParams& params);
// RegisterStream's header for the bunny pair by reference (nothing to upload).
v1::UploadHeader bunny_reference_header(const v1::RegistrationParams& params);
// Points on a sphere as XYZ text: smooth, so it yields too few keypoints at min_scale_m 0.2.
std::string sphere_xyz();
// Two inline spheres at min_scale_m 0.2: valid clouds that cannot be aligned (FAILED_PRECONDITION).
v1::RegisterRequest sphere_request();

// Stations 0 and 2 of the simulated lab (seeds 11 and 12), written to `dir` as lab0.ply and lab2.ply.
struct LabPair {
  sim::SimulatedScan source, target;
  fs::path source_file, target_file;
};
LabPair simulate_lab_pair(const fs::path& dir, std::size_t points);

Eigen::Matrix4d to_matrix(const google::protobuf::RepeatedField<double>& values);
// Ground truth T_target_source of a pair from tests/data/bunny/gt_pairs.log.
Eigen::Matrix4d bunny_truth(const std::string& source, const std::string& target);

// Client side of RegisterStream: sends the header and the uploads in chunks at once, then reads events.
struct StreamUpload {
  std::string source_bytes, target_bytes;  // sent for each cloud the header declares as an upload
  std::size_t chunk_bytes = 256 << 10;
};
// A header uploading both clouds, with their sizes and CRC-32C.
v1::UploadHeader upload_header(const std::string& source_name, const std::string& source_bytes,
                               const std::string& target_name, const std::string& target_bytes,
                               const v1::RegistrationParams& params);

class StreamCall {
 public:
  StreamCall(v1::Registration::Stub& stub, grpc::ClientContext& context, const v1::UploadHeader& header,
             const StreamUpload& upload);
  // Reads events until one matches; false if the stream ended first.
  bool wait_for_queued();
  bool wait_for_stage(const std::string& stage, v1::StageEvent::Phase phase);
  // Reads the remaining events and returns the call's status.
  grpc::Status finish();
  const std::vector<v1::RegisterStreamResponse>& events() const { return events_; }
  // The final result, or nullptr.
  const v1::RegisterResponse* result() const;

 private:
  bool next();

  std::unique_ptr<grpc::ClientReaderWriter<v1::RegisterStreamRequest, v1::RegisterStreamResponse>> stream_;
  std::vector<v1::RegisterStreamResponse> events_;
};

// grpc.health.v1 Check of `service`: "SERVING", "NOT_SERVING", ... or the status code's number on error.
std::string health_status(const ServerProcess& server, const std::string& service);

// The status has `code` and its message contains `text`.
::testing::AssertionResult has_status(const grpc::Status& status, grpc::StatusCode code, const std::string& text);

// Deadline helper for client contexts.
void set_timeout(grpc::ClientContext& context, std::chrono::milliseconds timeout);
// Every call gets a deadline, so a regression fails the test instead of hanging it.
std::unique_ptr<grpc::ClientContext> context_with_deadline(std::chrono::seconds timeout = std::chrono::seconds(90));

// Fills the queue of a server run with --workers 1 --queue-size 1 with gRPC streams, whose events tell when: a
// slow job (~3 s on one core) that has started `running_stage`, and a quick one waiting behind it.
class FullQueue {
 public:
  explicit FullQueue(const ServerProcess& server, const std::string& running_stage = "load");
  StreamCall& running() { return *running_; }
  StreamCall& queued() { return *queued_; }
  grpc::ClientContext& running_context() { return *running_context_; }
  grpc::ClientContext& queued_context() { return *queued_context_; }

 private:
  std::unique_ptr<v1::Registration::Stub> stub_;
  std::unique_ptr<grpc::ClientContext> running_context_ = context_with_deadline(), queued_context_ = context_with_deadline();
  std::unique_ptr<StreamCall> running_, queued_;
};

// An HTTP answer as either client saw it; header names in lower case.
struct HttpReply {
  int status = 0;
  std::map<std::string, std::string> headers;
  std::string body;
  std::string header(const std::string& name) const;
  nlohmann::json json() const;
};
// What cpp-httplib's client got; throws if it got no answer at all.
HttpReply reply_of(const httplib::Result& result);
// Polls GET `path` until it answers `status` (server-side state that follows a client action asynchronously:
// a signal, a cancellation); false if it does not within 10 s.
bool http_status_becomes(const ServerProcess& server, const std::string& path, int status);
// `curl -sS` with `args` (the URL among them). `stdin_command`, if given, is a shell command whose output is
// curl's stdin (`-T -`, `-d @-`): large bodies come from a generator, never from a file.
HttpReply curl(const std::vector<std::string>& args, const std::string& stdin_command = "");

// Resident memory of a process, from /proc/<pid>/status, KiB: now (VmRSS) and its peak (VmHWM).
std::size_t resident_kib(pid_t pid);
std::size_t peak_resident_kib(pid_t pid);

}  // namespace k4reg::test
