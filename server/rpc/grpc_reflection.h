// gRPC server reflection, on request only (--reflection): it lists every method to anyone who connects.
#pragma once

#include <grpcpp/impl/server_builder_option.h>

#include <memory>

namespace k4reg::service {

// libgrpc++_reflection registers its plugin for every ServerBuilder as soon as it is loaded (a static
// initializer), whether or not InitProtoReflectionServerBuilderPlugin() is called: this option takes it out of
// the API's builder again
// (the health listener's keeps it: it lists that server's health service only).
std::unique_ptr<grpc::ServerBuilderOption> without_reflection();

}  // namespace k4reg::service
