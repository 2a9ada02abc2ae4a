// Every status code the service promises, for both RPCs: bad files and parameters, missing files, paths
// outside the data roots, clouds that cannot align, budgets, checksums, authentication.
#include <gtest/gtest.h>

#include "k4reg/util/crc32c.h"
#include "k4reg/v1/registration.grpc.pb.h"
#include "test_support.h"

namespace k4reg::test {
namespace {

// A data root with two good scans, a malformed file, a subfolder, and a symlink leading out of the root.
class DataRoot {
 public:
  DataRoot() {
    fs::copy_file(bunny_dir() / "bun045.ply", root() / "bun045.ply");
    fs::copy_file(bunny_dir() / "bun000.ply", root() / "bun000.ply");
    write_file(root() / "malformed.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 1000\nproperty float x\n");
    fs::create_directory(root() / "nested");
    fs::create_symlink(bunny_dir() / "bun000.ply", root() / "escape.ply");
  }
  fs::path root() const { return dir_.path() / "root"; }

 private:
  TempDir dir_;
  bool created_ = fs::create_directory(dir_.path() / "root");
};

class Errors : public ::testing::Test {
 protected:
  explicit Errors(std::vector<std::string> extra_args = {}) {
    std::vector<std::string> args{"--data-root", data_.root().string(), "--workers", "1"};
    args.insert(args.end(), extra_args.begin(), extra_args.end());
    server_ = std::make_unique<ServerProcess>(args);
    stub_ = server_->stub();
  }

  grpc::Status call(const std::string& source, const std::string& target,
                    const v1::RegistrationParams& params = quick_params()) {
    v1::RegisterRequest request;
    request.mutable_source()->set_path(source);
    request.mutable_target()->set_path(target);
    *request.mutable_params() = params;
    return call(request);
  }
  grpc::Status call(const v1::RegisterRequest& request) {
    grpc::ClientContext context;
    set_timeout(context, std::chrono::seconds(60));
    v1::RegisterResponse reply;
    return stub_->Register(&context, request, &reply);
  }
  grpc::Status stream(const v1::UploadHeader& header, const StreamUpload& upload) {
    grpc::ClientContext context;
    set_timeout(context, std::chrono::seconds(60));
    StreamCall call(*stub_, context, header, upload);
    return call.finish();
  }

  DataRoot data_;
  std::unique_ptr<ServerProcess> server_;
  std::unique_ptr<v1::Registration::Stub> stub_;
};

TEST_F(Errors, MalformedFileIsInvalidArgumentNamingTheFile) {
  EXPECT_TRUE(has_status(call("malformed.ply", "bun000.ply"), grpc::StatusCode::INVALID_ARGUMENT, "malformed.ply"));
  v1::RegisterRequest request;
  request.mutable_source()->mutable_inline_cloud()->set_data("ply\nformat ascii 1.0\nelement vertex 3\nend_header\n1 2\n");
  request.mutable_source()->mutable_inline_cloud()->set_file_name("broken.ply");
  request.mutable_target()->set_path("bun000.ply");
  EXPECT_TRUE(has_status(call(request), grpc::StatusCode::INVALID_ARGUMENT, "broken.ply"));
  // The server's own paths stay private.
  EXPECT_EQ(call("malformed.ply", "bun000.ply").error_message().find(data_.root().string()), std::string::npos);
}

TEST_F(Errors, BadParametersAreInvalidArgumentNamingTheField) {
  v1::RegistrationParams params = quick_params();
  params.set_overlap(2.0);
  EXPECT_TRUE(has_status(call("bun045.ply", "bun000.ply", params), grpc::StatusCode::INVALID_ARGUMENT, "overlap"));
  params = quick_params();
  params.set_min_scale_m(-1);
  EXPECT_TRUE(has_status(call("bun045.ply", "bun000.ply", params), grpc::StatusCode::INVALID_ARGUMENT, "min_scale_m"));
  params = quick_params();
  params.set_signal(static_cast<v1::KeypointSignal>(99));
  EXPECT_TRUE(has_status(call("bun045.ply", "bun000.ply", params), grpc::StatusCode::INVALID_ARGUMENT, "params.signal"));
  EXPECT_TRUE(has_status(call(v1::RegisterRequest{}), grpc::StatusCode::INVALID_ARGUMENT, "source"));
  // Streams refuse bad parameters before any upload.
  const std::string bytes = read_file(data_.root() / "bun045.ply");
  params = quick_params();
  params.set_hypotheses_kept(0);
  EXPECT_TRUE(has_status(stream(upload_header("a.ply", bytes, "b.ply", bytes, params), {bytes, bytes}), grpc::StatusCode::INVALID_ARGUMENT, "hypotheses_kept"));
}

TEST_F(Errors, MissingFileIsNotFound) {
  EXPECT_TRUE(has_status(call("missing.ply", "bun000.ply"), grpc::StatusCode::NOT_FOUND, "missing.ply"));
  EXPECT_TRUE(has_status(call("bun045.ply", "nested/missing.ply"), grpc::StatusCode::NOT_FOUND, "nested/missing.ply"));
}

TEST_F(Errors, PathsOutsideTheDataRootsArePermissionDenied) {
  for (const std::string& path : {std::string("../x.ply"), std::string("/etc/passwd"), std::string("escape.ply"),
                                  std::string("nested/../../root/../x"), std::string("../root2/bun045.ply"),
                                  (bunny_dir() / "bun000.ply").string()})
    EXPECT_TRUE(has_status(call(path, "bun000.ply"), grpc::StatusCode::PERMISSION_DENIED, "outside")) << path;
  // Inside the root, absolute and "..": fine.
  EXPECT_TRUE(call((data_.root() / "bun045.ply").string(), "nested/../bun000.ply").ok());
  v1::UploadHeader header;
  header.mutable_source()->set_path("/etc/passwd");
  header.mutable_target()->set_path("bun000.ply");
  EXPECT_TRUE(has_status(stream(header, {}), grpc::StatusCode::PERMISSION_DENIED, "outside"));
}

TEST_F(Errors, DirectoryIsInvalidArgument) { EXPECT_TRUE(has_status(call("nested", "bun000.ply"), grpc::StatusCode::INVALID_ARGUMENT, "nested")); }

TEST_F(Errors, CloudsWithoutAlignmentAreFailedPrecondition) {
  v1::RegisterRequest request;
  request.mutable_source()->mutable_inline_cloud()->set_data(sphere_xyz());
  request.mutable_source()->mutable_inline_cloud()->set_file_name("sphere.xyz");
  request.mutable_target()->mutable_inline_cloud()->set_data(sphere_xyz());
  request.mutable_params()->set_min_scale_m(0.2);
  EXPECT_TRUE(has_status(call(request), grpc::StatusCode::FAILED_PRECONDITION, "too few keypoints"));
}

TEST_F(Errors, ChecksumMismatchIsDataLossAndLeavesNoSpoolFile) {
  const std::string source = read_file(data_.root() / "bun045.ply"), target = read_file(data_.root() / "bun000.ply");
  v1::UploadHeader header = upload_header("bun045.ply", source, "bun000.ply", target, quick_params());
  header.mutable_target()->mutable_upload()->set_crc32c(crc32c(target) ^ 1u);
  EXPECT_TRUE(has_status(stream(header, {source, target}), grpc::StatusCode::DATA_LOSS, "CRC-32C"));
  EXPECT_EQ(server_->spooled_files(), 0u);
}

TEST_F(Errors, UploadProtocolViolationsAreInvalidArgument) {
  const std::string bytes = read_file(data_.root() / "bun045.ply");
  const v1::UploadHeader header = upload_header("a.ply", bytes, "b.ply", bytes, quick_params());
  // More bytes than declared.
  v1::UploadHeader short_header = header;
  short_header.mutable_source()->mutable_upload()->set_size_bytes(bytes.size() - 10);
  EXPECT_TRUE(has_status(stream(short_header, {bytes, bytes}), grpc::StatusCode::INVALID_ARGUMENT, "more bytes"));
  // Fewer bytes than declared, then the client closes.
  EXPECT_TRUE(has_status(stream(header, {bytes.substr(0, 1000), bytes}), grpc::StatusCode::INVALID_ARGUMENT, "ended before"));
  EXPECT_TRUE(has_status(stream(header, {bytes, bytes.substr(0, 1000)}), grpc::StatusCode::INVALID_ARGUMENT, "ended before"));
  // Chunks over 1 MiB.
  const std::string big(1 << 21, 'x');
  EXPECT_TRUE(has_status(stream(upload_header("a.ply", big, "b.ply", bytes, quick_params()), {big, bytes, big.size()}), grpc::StatusCode::INVALID_ARGUMENT, "at most"));
  // No header.
  {
    grpc::ClientContext context;
    auto call = stub_->RegisterStream(&context);
    v1::RegisterStreamRequest chunk;
    chunk.mutable_chunk()->set_role(v1::CLOUD_ROLE_SOURCE);
    call->Write(chunk);
    call->WritesDone();
    EXPECT_TRUE(has_status(call->Finish(), grpc::StatusCode::INVALID_ARGUMENT, "header"));
  }
  EXPECT_EQ(server_->spooled_files(), 0u);
}

class Budgets : public Errors {
 protected:
  // bun045 has 40097 points, bun000 40256; two clouds of 40097 need 4.8 MB at 60 bytes per point.
  Budgets()
      : Errors({"--max-points", "40100", "--memory-budget-mb", "4", "--max-upload-mb", "1", "--max-inline-mb", "1"}) {}
};

TEST_F(Budgets, OverTheLimitsIsResourceExhaustedNamingTheLimit) {
  EXPECT_TRUE(has_status(call("bun000.ply", "bun045.ply"), grpc::StatusCode::RESOURCE_EXHAUSTED, "--max-points"));
  EXPECT_TRUE(has_status(call("bun045.ply", "bun045.ply"), grpc::StatusCode::RESOURCE_EXHAUSTED, "--memory-budget-mb"));
  const std::string big((3 << 20) / 2, 'x');  // refused by its declared size, before any byte is spooled
  EXPECT_TRUE(has_status(stream(upload_header("a.ply", big, "b.ply", big, quick_params()), {big, big}),
                         grpc::StatusCode::RESOURCE_EXHAUSTED, "--max-upload-mb"));
  // Inline requests over --max-inline-mb (gRPC's own limit is the larger --max-pair-mb, for peers' pair jobs).
  {
    v1::RegisterRequest request = bunny_request(quick_params());
    request.mutable_source()->mutable_inline_cloud()->set_data(big);
    request.mutable_source()->mutable_inline_cloud()->set_file_name("big.xyz");
    grpc::ClientContext context;
    v1::RegisterResponse reply;
    EXPECT_TRUE(has_status(stub_->Register(&context, request, &reply), grpc::StatusCode::RESOURCE_EXHAUSTED,
                           "--max-inline-mb"));
  }
  {
    v1::RegisterProjectRequest request;
    for (int i = 0; i < 2; ++i) {
      request.add_scans()->mutable_inline_cloud()->set_data(big);
      request.mutable_scans(i)->mutable_inline_cloud()->set_file_name("big.xyz");
    }
    grpc::ClientContext context;
    auto reader = stub_->RegisterProject(&context, request);
    for (v1::RegisterProjectEvent event; reader->Read(&event);) {
    }
    EXPECT_TRUE(has_status(reader->Finish(), grpc::StatusCode::RESOURCE_EXHAUSTED, "--max-inline-mb"));
  }
}

class Auth : public Errors {
 protected:
  Auth() : Errors({"--auth-token", "s3cret"}) {}
};

TEST_F(Auth, CallsNeedTheBearerTokenButHealthDoesNot) {
  EXPECT_TRUE(has_status(call("bun045.ply", "bun000.ply"), grpc::StatusCode::UNAUTHENTICATED, "authorization"));
  {
    grpc::ClientContext context;
    context.AddMetadata("authorization", "Bearer wrong");
    v1::RegisterResponse reply;
    EXPECT_EQ(stub_->Register(&context, bunny_request(quick_params()), &reply).error_code(),
              grpc::StatusCode::UNAUTHENTICATED);
  }
  {
    grpc::ClientContext context;
    context.AddMetadata("authorization", "Bearer s3cret");
    v1::RegisterResponse reply;
    const grpc::Status status = stub_->Register(&context, bunny_request(quick_params()), &reply);
    EXPECT_TRUE(status.ok()) << status.error_message();
  }
  EXPECT_TRUE(has_status(stream(v1::UploadHeader{}, {}), grpc::StatusCode::UNAUTHENTICATED, "authorization"));
  EXPECT_EQ(health_status(*server_, "readiness"), "SERVING");
  // The token never appears in the log.
  EXPECT_EQ(server_->log().find("s3cret"), std::string::npos);
}

}  // namespace
}  // namespace k4reg::test
