// The k4reg.v1.Registration service on gRPC's callback API: each RPC gets a reactor; no handler blocks
// a gRPC thread.
#pragma once

#include "k4reg/v1/registration.grpc.pb.h"
#include "service_context.h"

namespace k4reg::service {

class RegistrationService final : public v1::Registration::CallbackService {
 public:
  explicit RegistrationService(ServiceContext context) : context_(std::move(context)) {}

  grpc::ServerUnaryReactor* Register(grpc::CallbackServerContext* context, const v1::RegisterRequest* request,
                                     v1::RegisterResponse* reply) override;
  grpc::ServerBidiReactor<v1::RegisterStreamRequest, v1::RegisterStreamResponse>* RegisterStream(
      grpc::CallbackServerContext* context) override;
  grpc::ServerWriteReactor<v1::RegisterProjectEvent>* RegisterProject(grpc::CallbackServerContext* context,
                                                                     const v1::RegisterProjectRequest* request) override;
  grpc::ServerBidiReactor<v1::RegisterProjectStreamRequest, v1::RegisterProjectEvent>* RegisterProjectStream(
      grpc::CallbackServerContext* context) override;
  grpc::ServerUnaryReactor* RegisterPair(grpc::CallbackServerContext* context, const v1::RegisterPairRequest* request,
                                         v1::RegisterPairResponse* reply) override;

 private:
  ServiceContext context_;
};

}  // namespace k4reg::service
