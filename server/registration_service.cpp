#include "registration_service.h"

#include "register_reactor.h"
#include "stream_reactor.h"

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

}  // namespace k4reg::service
