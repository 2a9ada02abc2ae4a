#include "test_support.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "k4reg/util/crc32c.h"
#include "grpc/health/v1/health.grpc.pb.h"
#include "k4reg/io/cloud_io.h"
#include "k4reg/io/gt_pairs.h"
#include "sim/scene.h"

extern char** environ;

namespace k4reg::test {

fs::path bunny_dir() { return fs::path(K4REG_TEST_DATA_DIR) / "bunny"; }

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path.string());
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

void write_file(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

CommandRun run_command(std::vector<std::string> arguments, const std::map<std::string, std::string>& env) {
  TempDir dir;
  const fs::path out = dir.path() / "out", err = dir.path() / "err";
  ExecVectors exec = exec_vectors(std::move(arguments), env);
  const pid_t pid = fork();
  if (pid == 0) {
    const int out_fd = ::open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err_fd = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(out_fd, STDOUT_FILENO);
    dup2(err_fd, STDERR_FILENO);
    execve(exec.argv[0], exec.argv.data(), exec.envp.data());
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  CommandRun run;
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  run.out = read_file(out);
  run.err = read_file(err);
  return run;
}

TempDir::TempDir() {
  std::string pattern = (fs::temp_directory_path() / "k4reg-test-XXXXXX").string();
  if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
  path_ = pattern;
}

TempDir::~TempDir() {
  std::error_code ec;
  fs::remove_all(path_, ec);
}

ExecVectors exec_vectors(std::vector<std::string> arguments, const std::map<std::string, std::string>& env) {
  ExecVectors exec;
  exec.arguments = std::move(arguments);
  for (char** e = environ; *e; ++e)
    if (std::string_view(*e).rfind("K4REG_", 0) != 0) exec.environment.emplace_back(*e);
  for (const auto& [name, value] : env) exec.environment.push_back(name + "=" + value);
  for (std::string& a : exec.arguments) exec.argv.push_back(a.data());
  exec.argv.push_back(nullptr);
  for (std::string& e : exec.environment) exec.envp.push_back(e.data());
  exec.envp.push_back(nullptr);
  return exec;
}

ServerProcess::ServerProcess(const std::vector<std::string>& args, const std::map<std::string, std::string>& env) {
  const fs::path port_file = work_.path() / "port", http_port_file = work_.path() / "http_port",
                 log_file = work_.path() / "server.log";
  std::vector<std::string> arguments{K4REG_BIN_DIR "/k4reg-server", "--port-file", port_file.string(), "--spool-dir",
                                     (work_.path() / "spool").string()};
  if (std::find(args.begin(), args.end(), "--grpc-listen") == args.end())
    arguments.insert(arguments.end(), {"--grpc-listen", "127.0.0.1:0"});
  const bool own_http = std::find(args.begin(), args.end(), "--http-listen") != args.end();
  if (!own_http)
    arguments.insert(arguments.end(), {"--http-listen", "127.0.0.1:0", "--http-port-file", http_port_file.string()});
  arguments.insert(arguments.end(), args.begin(), args.end());
  ExecVectors exec = exec_vectors(std::move(arguments), env);
  const int log_fd = ::open(log_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  pid_ = fork();
  if (pid_ == 0) {
    dup2(log_fd, STDERR_FILENO);
    execve(exec.argv[0], exec.argv.data(), exec.envp.data());
    _exit(127);
  }
  ::close(log_fd);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (!fs::exists(port_file)) {
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      exited_ = true;
      throw std::runtime_error("k4reg-server exited at start-up: " + log());
    }
    if (std::chrono::steady_clock::now() > deadline) throw std::runtime_error("k4reg-server did not start: " + log());
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  port_ = std::stoi(read_file(port_file));
  if (!own_http) http_port_ = std::stoi(read_file(http_port_file));  // written before the gRPC port file
}

ServerProcess::~ServerProcess() {
  if (exited_ || pid_ <= 0) return;
  kill(pid_, SIGKILL);
  waitpid(pid_, nullptr, 0);
}

std::shared_ptr<grpc::Channel> ServerProcess::channel() const {
  return grpc::CreateChannel(address(), grpc::InsecureChannelCredentials());
}

std::unique_ptr<v1::Registration::Stub> ServerProcess::stub() const { return v1::Registration::NewStub(channel()); }

httplib::Client ServerProcess::http() const {
  httplib::Client client("127.0.0.1", http_port_);
  client.set_read_timeout(std::chrono::minutes(2));
  return client;
}

std::size_t ServerProcess::spooled_files() const {
  std::size_t count = 0;
  std::error_code ec;
  for (const auto& entry : fs::recursive_directory_iterator(work_.path() / "spool", ec))
    count += entry.is_regular_file();
  return count;
}

std::string ServerProcess::log() const { return read_file(work_.path() / "server.log"); }

std::vector<nlohmann::json> ServerProcess::log_lines(const std::string& msg) const {
  std::vector<nlohmann::json> lines;
  std::istringstream text(log());
  for (std::string line; std::getline(text, line);) {
    nlohmann::json json = nlohmann::json::parse(line, nullptr, false);
    if (!json.is_discarded() && json.value("msg", "") == msg) lines.push_back(std::move(json));
  }
  return lines;
}

void ServerProcess::signal(int number) const { kill(pid_, number); }

int ServerProcess::wait(std::chrono::seconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      exited_ = true;
      return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    }
    if (std::chrono::steady_clock::now() > deadline) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
      exited_ = true;
      throw std::runtime_error("k4reg-server did not exit in time");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

v1::RegistrationParams bunny_params() {
  v1::RegistrationParams params;
  params.set_min_scale_m(0.001);
  params.set_overlap(0.9);
  return params;
}

v1::RegistrationParams slow_params(double seconds) {
  // Measured on this project's 2-core machine: ~1 s of keypoints/ICP plus ~0.16 ms per 4PCS base.
  v1::RegistrationParams params = bunny_params();
  params.set_max_bases(static_cast<int>(std::clamp((seconds - 1.0) / 0.16e-3, 1000.0, 1e6)));
  return params;
}

v1::RegistrationParams quick_params() {
  v1::RegistrationParams params;
  params.set_min_scale_m(0.004);
  params.set_overlap(0.9);
  return params;
}

v1::RegisterRequest bunny_request(const v1::RegistrationParams& params) {
  v1::RegisterRequest request;
  request.mutable_source()->set_path("bun045.ply");
  request.mutable_target()->set_path("bun000.ply");
  *request.mutable_params() = params;
  return request;
}

v1::UploadHeader bunny_reference_header(const v1::RegistrationParams& params) {
  v1::UploadHeader header;
  header.mutable_source()->set_path("bun045.ply");
  header.mutable_target()->set_path("bun000.ply");
  *header.mutable_params() = params;
  return header;
}

v1::RegisterRequest sphere_request() {
  v1::RegisterRequest request;
  request.mutable_source()->mutable_inline_cloud()->set_data(sphere_xyz());
  request.mutable_source()->mutable_inline_cloud()->set_file_name("sphere.xyz");
  request.mutable_target()->mutable_inline_cloud()->set_data(sphere_xyz());
  request.mutable_params()->set_min_scale_m(0.2);
  return request;
}

LabPair simulate_lab_pair(const fs::path& dir, std::size_t points) {
  const sim::Scene lab = sim::make_scene("lab");
  sim::ScanParams scan;
  scan.points = points;
  scan.seed = 11;
  LabPair pair{sim::simulate_scan(lab, 0, scan), {}, dir / "lab0.ply", dir / "lab2.ply"};
  scan.seed = 12;
  pair.target = sim::simulate_scan(lab, 2, scan);
  write_cloud(pair.source_file.string(), pair.source.cloud);
  write_cloud(pair.target_file.string(), pair.target.cloud);
  return pair;
}

std::string sphere_xyz() {
  std::ostringstream text;
  constexpr int kPoints = 4000;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < kPoints; ++i) {
    const double y = 1.0 - 2.0 * (i + 0.5) / kPoints, r = std::sqrt(1.0 - y * y), t = golden * i;
    text << r * std::cos(t) << ' ' << y << ' ' << r * std::sin(t) << '\n';
  }
  return text.str();
}

Eigen::Matrix4d to_matrix(const google::protobuf::RepeatedField<double>& values) {
  if (values.size() != 16) throw std::runtime_error("a transform needs 16 values");
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = values.Get(4 * r + c);
  return m;
}

Eigen::Matrix4d bunny_truth(const std::string& source, const std::string& target) {
  for (const GtPair& pair : read_gt_pairs((bunny_dir() / "gt_pairs.log").string()))
    if (pair.source == source && pair.target == target) return pair.T_target_source;
  throw std::runtime_error("no ground truth for " + source + " -> " + target);
}

v1::UploadHeader upload_header(const std::string& source_name, const std::string& source_bytes,
                               const std::string& target_name, const std::string& target_bytes,
                               const v1::RegistrationParams& params) {
  v1::UploadHeader header;
  auto describe = [](v1::UploadedFile* file, const std::string& name, const std::string& bytes) {
    file->set_file_name(name);
    file->set_size_bytes(bytes.size());
    file->set_crc32c(crc32c(bytes));
  };
  describe(header.mutable_source()->mutable_upload(), source_name, source_bytes);
  describe(header.mutable_target()->mutable_upload(), target_name, target_bytes);
  *header.mutable_params() = params;
  return header;
}

StreamCall::StreamCall(v1::Registration::Stub& stub, grpc::ClientContext& context, const v1::UploadHeader& header,
                       const StreamUpload& upload)
    : stream_(stub.RegisterStream(&context)) {
  v1::RegisterStreamRequest message;
  *message.mutable_header() = header;
  bool open = stream_->Write(message);
  auto send = [&](v1::CloudRole role, const std::string& bytes) {
    for (std::size_t offset = 0; open && offset < bytes.size(); offset += upload.chunk_bytes) {
      v1::RegisterStreamRequest chunk;
      chunk.mutable_chunk()->set_role(role);
      chunk.mutable_chunk()->set_data(bytes.substr(offset, upload.chunk_bytes));
      open = stream_->Write(chunk);
    }
  };
  if (header.source().has_upload()) send(v1::CLOUD_ROLE_SOURCE, upload.source_bytes);
  if (header.target().has_upload()) send(v1::CLOUD_ROLE_TARGET, upload.target_bytes);
  stream_->WritesDone();
}

bool StreamCall::next() {
  v1::RegisterStreamResponse event;
  if (!stream_->Read(&event)) return false;
  events_.push_back(std::move(event));
  return true;
}

bool StreamCall::wait_for_queued() {
  while (next())
    if (events_.back().has_queued()) return true;
  return false;
}

bool StreamCall::wait_for_stage(const std::string& stage, v1::StageEvent::Phase phase) {
  while (next())
    if (events_.back().has_stage() && events_.back().stage().stage() == stage && events_.back().stage().phase() == phase)
      return true;
  return false;
}

grpc::Status StreamCall::finish() {
  while (next()) {
  }
  return stream_->Finish();
}

const v1::RegisterResponse* StreamCall::result() const {
  return !events_.empty() && events_.back().has_result() ? &events_.back().result() : nullptr;
}

std::string health_status(const ServerProcess& server, const std::string& service) {
  auto stub = grpc::health::v1::Health::NewStub(server.channel());
  grpc::ClientContext context;
  set_timeout(context, std::chrono::seconds(10));
  grpc::health::v1::HealthCheckRequest request;
  request.set_service(service);
  grpc::health::v1::HealthCheckResponse reply;
  const grpc::Status status = stub->Check(&context, request, &reply);
  if (!status.ok()) return std::to_string(status.error_code());
  return grpc::health::v1::HealthCheckResponse::ServingStatus_Name(reply.status());
}

::testing::AssertionResult has_status(const grpc::Status& status, grpc::StatusCode code, const std::string& text) {
  if (status.error_code() == code && status.error_message().find(text) != std::string::npos)
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "status " << status.error_code() << " \"" << status.error_message()
                                       << "\", expected " << code << " with \"" << text << "\"";
}

void set_timeout(grpc::ClientContext& context, std::chrono::milliseconds timeout) {
  context.set_deadline(std::chrono::system_clock::now() + timeout);
}

std::unique_ptr<grpc::ClientContext> context_with_deadline(std::chrono::seconds timeout) {
  auto context = std::make_unique<grpc::ClientContext>();
  set_timeout(*context, timeout);
  return context;
}

FullQueue::FullQueue(const ServerProcess& server, const std::string& running_stage) : stub_(server.stub()) {
  running_ = std::make_unique<StreamCall>(*stub_, *running_context_, bunny_reference_header(slow_params(3)), StreamUpload{});
  if (!running_->wait_for_stage(running_stage, v1::StageEvent::PHASE_STARTED))
    throw std::runtime_error("the slow job did not reach " + running_stage);
  queued_ = std::make_unique<StreamCall>(*stub_, *queued_context_, bunny_reference_header(quick_params()), StreamUpload{});
  if (!queued_->wait_for_queued()) throw std::runtime_error("the quick job was not queued");
}

std::string HttpReply::header(const std::string& name) const {
  const auto it = headers.find(name);
  return it == headers.end() ? std::string() : it->second;
}

nlohmann::json HttpReply::json() const { return nlohmann::json::parse(body, nullptr, false); }

namespace {

std::string shell_quoted(const std::string& text) {
  std::string quoted = "'";
  for (const char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

std::string lower_case(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return std::tolower(c); });
  return text;
}

}  // namespace

HttpReply reply_of(const httplib::Result& result) {
  if (!result) throw std::runtime_error("no HTTP answer: " + httplib::to_string(result.error()));
  HttpReply reply;
  reply.status = result->status;
  reply.body = result->body;
  for (const auto& [name, value] : result->headers) reply.headers[lower_case(name)] = value;
  return reply;
}

bool http_status_becomes(const ServerProcess& server, const std::string& path, int status) {
  httplib::Client client = server.http();
  for (auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10); std::chrono::steady_clock::now() < end;
       std::this_thread::sleep_for(std::chrono::milliseconds(20)))
    if (reply_of(client.Get(path)).status == status) return true;
  return false;
}

HttpReply curl(const std::vector<std::string>& args, const std::string& stdin_command) {
  TempDir dir;
  const fs::path headers = dir.path() / "headers", body = dir.path() / "body";
  std::vector<std::string> command{"curl", "-sS", "-D", headers.string(), "-o", body.string(), "-w", "%{http_code}"};
  command.insert(command.end(), args.begin(), args.end());
  std::string line = stdin_command.empty() ? "exec" : stdin_command + " |";
  for (const std::string& word : command) line.append(" ").append(shell_quoted(word));
  const CommandRun run = run_command({"/bin/sh", "-c", line});
  HttpReply reply;
  reply.status = std::atoi(run.out.c_str());
  if (run.exit_code != 0) throw std::runtime_error("curl failed (" + std::to_string(run.exit_code) + "): " + run.err);
  reply.body = read_file(body);
  // The last header block is the final answer (a "100 Continue" block may come first).
  std::istringstream text(read_file(headers));
  for (std::string header; std::getline(text, header);) {
    if (!header.empty() && header.back() == '\r') header.pop_back();
    if (header.rfind("HTTP/", 0) == 0) reply.headers.clear();
    const auto colon = header.find(':');
    if (colon == std::string::npos) continue;
    const std::string name = lower_case(header.substr(0, colon));
    const auto value = header.find_first_not_of(' ', colon + 1);
    reply.headers[name] = value == std::string::npos ? std::string() : header.substr(value);
  }
  return reply;
}

namespace {

// A "Field:   N kB" line of /proc/<pid>/status, KiB.
std::size_t status_kib(pid_t pid, const std::string& field) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind(field + ":", 0) == 0) return std::stoul(line.substr(field.size() + 1));
  throw std::runtime_error("no " + field + " for pid " + std::to_string(pid));
}

}  // namespace

std::size_t resident_kib(pid_t pid) { return status_kib(pid, "VmRSS"); }

std::size_t peak_resident_kib(pid_t pid) { return status_kib(pid, "VmHWM"); }

}  // namespace k4reg::test
