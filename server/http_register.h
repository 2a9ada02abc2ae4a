// POST /v1/register: the HTTP face of Registration.Register. The body is a RegisterRequest as JSON
// (application/json: file references or inline base64 clouds, at most --max-inline-mb of cloud bytes, as the
// unary RPC) or a multipart/form-data upload (http_upload.h). Either way the request becomes the same
// CloudSource/RegistrationParams as over gRPC and runs the same job (run_job) on the same queue; the HTTP
// thread waits for it and answers the RegisterResponse as JSON, or an error from the same statuses.
#pragma once

#include <grpcpp/support/status.h>
#include "http_lib.h"

#include "http_exchange.h"
#include "service_context.h"

namespace k4reg::service {

// What can be refused from the headers alone, before any body byte is read (also the answer to
// "Expect: 100-continue"): the bearer token, draining, the content type and the declared Content-Length.
grpc::Status check_register_headers(const ServiceContext& service, const httplib::Request& request);

void handle_register(const ServiceContext& service, HttpExchange& exchange);

}  // namespace k4reg::service
