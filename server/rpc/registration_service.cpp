#include "rpc/registration_service.h"

#include "rpc/pair_reactor.h"
#include "rpc/project_reactor.h"
#include "rpc/project_stream_reactor.h"
#include "rpc/register_reactor.h"
#include "rpc/stream_reactor.h"

namespace k4reg::service {

// Reactors delete themselves in OnDone.
grpc::ServerUnaryReactor* RegistrationService::Register(grpc::CallbackServerContext* context,
                                                        const v1::RegisterRequest* request,
                                                        v1::RegisterResponse* reply) {
  return new RegisterReactor(context_, context, request, reply);
}

grpc::ServerBidiReactor<v1::RegisterStreamRequest, v1::RegisterStreamResponse>* RegistrationService::RegisterStream(
    grpc::CallbackServerContext* context) {
  return new StreamReactor(context_, context);
}

grpc::ServerWriteReactor<v1::RegisterProjectEvent>* RegistrationService::RegisterProject(
    grpc::CallbackServerContext* context, const v1::RegisterProjectRequest* request) {
  return new ProjectReactor(context_, context, request);
}

grpc::ServerBidiReactor<v1::RegisterProjectStreamRequest, v1::RegisterProjectEvent>*
RegistrationService::RegisterProjectStream(grpc::CallbackServerContext* context) {
  return new ProjectStreamReactor(context_, context);
}

grpc::ServerUnaryReactor* RegistrationService::RegisterPair(grpc::CallbackServerContext* context,
                                                            const v1::RegisterPairRequest* request,
                                                            v1::RegisterPairResponse* reply) {
  return new PairReactor(context_, context, request, reply);
}

}  // namespace k4reg::service
