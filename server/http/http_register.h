// POST /v1/register: the HTTP face of Registration.Register. The body is a RegisterRequest as JSON
// (application/json: file references or inline base64 clouds, at most --max-inline-mb of cloud bytes, as the
// unary RPC) or a multipart/form-data upload (http_upload.h). Either way the request becomes the same
// CloudSource/RegistrationParams as over gRPC and runs the same job (run_job) on the same queue; the HTTP
// thread waits for it and answers the RegisterResponse as JSON, or an error from the same statuses.
#pragma once

#include <grpcpp/support/status.h>

#include <functional>

#include "http/http_lib.h"

#include "http/http_exchange.h"
#include "service_context.h"

namespace k4reg::service {

// What can be refused from the headers alone, before any body byte is read (also the answer to
// "Expect: 100-continue"): the bearer token, draining, the content type and the declared Content-Length.
grpc::Status check_register_headers(const ServiceContext& service, const httplib::Request& request);

void handle_register(const ServiceContext& service, HttpExchange& exchange);

// The largest JSON body: --max-inline-mb of clouds, base64-encoded (4 characters per 3 bytes), and the JSON
// around them.
std::uint64_t json_body_limit(const ServiceContext& service);

// The largest body any route takes (a project's multipart upload): the HTTP listener's payload limit.
std::uint64_t largest_body_limit(const ServiceContext& service);

// Queues `work` like the RPCs queue their jobs and waits for it on this (cpp-httplib) thread. `queue_full`
// tells a full queue (429) from the other RESOURCE_EXHAUSTED refusals (413).
grpc::Status run_and_wait(const ServiceContext& service, CallClock& clock, const std::function<grpc::Status(Job&)>& work,
                          bool& queue_full);

}  // namespace k4reg::service
