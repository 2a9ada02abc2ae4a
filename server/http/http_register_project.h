// POST /v1/register-project: the HTTP face of Registration.RegisterProject. The body is a
// RegisterProjectRequest as JSON (scans by path under the data roots, or inline base64, at most
// --max-inline-mb of cloud bytes in all). It runs the same job (run_project_job) on the same queue; the
// HTTP thread waits for it and answers the RegisterProjectResponse as JSON (no progress events: use the
// RPC for those), or an error from the same statuses.
#pragma once

#include "http/http_exchange.h"
#include "service_context.h"

namespace k4reg::service {

void handle_register_project(const ServiceContext& service, HttpExchange& exchange);

}  // namespace k4reg::service
