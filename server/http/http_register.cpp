#include "http/http_register.h"

#include <fmt/format.h>

#include <algorithm>
#include <future>
#include <memory>

#include "http/http_event_stream.h"
#include "http/http_json.h"
#include "http/http_upload.h"
#include "k4reg/util/error.h"
#include "api/proto_convert.h"
#include "api/status_mapping.h"

namespace k4reg::service {
namespace {

// Part headers and parameter fields around the two files of a multipart body.
constexpr std::uint64_t kFormOverheadBytes = 1 << 20;
// The JSON around base64-encoded inline clouds.
constexpr std::uint64_t kJsonOverheadBytes = 64 << 10;

enum class BodyKind { kJson, kMultipart };

BodyKind body_kind(const httplib::Request& request) {
  if (request.is_multipart_form_data()) return BodyKind::kMultipart;
  const std::string type = request.get_header_value("Content-Type");
  if (type.rfind(kJsonContentType, 0) == 0) return BodyKind::kJson;
  fail(ErrorCode::kInvalidArgument,
       "unsupported Content-Type '" + type + "': send application/json or multipart/form-data");
}


// Pairs: two files; projects: at most kMaxProjectUploads files' worth of --max-upload-mb in one body.
constexpr std::uint64_t kMaxProjectUploads = 64;
std::uint64_t multipart_limit(const ServiceContext& service, std::uint64_t files) {
  return files * service.max_upload_bytes + kFormOverheadBytes;
}
std::uint64_t multipart_limit(const ServiceContext& service, const httplib::Request& request) {
  return multipart_limit(service, request.path == "/v1/register-project" ? kMaxProjectUploads : 2);
}

}  // namespace

std::uint64_t json_body_limit(const ServiceContext& service) {
  return (service.max_inline_bytes + 2) / 3 * 4 + kJsonOverheadBytes;
}

std::uint64_t largest_body_limit(const ServiceContext& service) {
  return std::max(json_body_limit(service), multipart_limit(service, kMaxProjectUploads));
}

grpc::Status run_and_wait(const ServiceContext& service, CallClock& clock, const std::function<grpc::Status(Job&)>& work,
                          bool& queue_full) {
  // Owned by the job as well: the worker may still be inside set_value when this thread wakes up.
  auto done = std::make_shared<std::promise<grpc::Status>>();
  std::future<grpc::Status> finished = done->get_future();
  auto job = std::make_shared<Job>([&work, done](Job& self) { done->set_value(work(self)); });
  clock.enqueued = CallClock::Clock::now();
  std::size_t position = 0;
  if (const grpc::Status status = service.submit(job, position); !status.ok()) {
    queue_full = status.error_code() == grpc::StatusCode::RESOURCE_EXHAUSTED;
    return status;
  }
  // A queued job always runs, if only to notice its cancellation (JobQueue::stop), so this wait ends.
  return finished.get();
}

grpc::Status check_register_headers(const ServiceContext& service, const httplib::Request& request) {
  if (grpc::Status status = service.admit(authorization_header(request)); !status.ok()) return status;
  try {
    const bool multipart = body_kind(request) == BodyKind::kMultipart;
    const std::uint64_t limit = multipart ? multipart_limit(service, request) : json_body_limit(service);
    const std::uint64_t declared = request.get_header_value<std::uint64_t>("Content-Length");
    if (declared > limit)
      fail(ErrorCode::kResourceExhausted,
           fmt::format("request body of {} bytes, more than the {} limit of {} bytes ({})", declared,
                       multipart ? "multipart" : "JSON", limit,
                       multipart ? "the files' --max-upload-mb" : "--max-inline-mb of base64 clouds"));
  } catch (...) {
    return status_from_current_exception();
  }
  return grpc::Status::OK;
}

void handle_register(const ServiceContext& service, HttpExchange& exchange) {
  if (const grpc::Status status = check_register_headers(service, exchange.request); !status.ok()) {
    exchange.fail(status);
    return;
  }
  // What the job reads, owned by the job when the answer streams (the handler returns before it runs).
  struct Call {
    v1::RegisterRequest request;  // owns inline cloud bytes
    UploadForm form;              // owns spool files
    PairJob pair;
  };
  auto call = std::make_shared<Call>();
  CallClock clock;
  try {
    if (body_kind(exchange.request) == BodyKind::kJson) {
      from_json(exchange.body.read_all(json_body_limit(service)), call->request);
      call->pair.params = params_from_proto(call->request.params());
      call->pair.preview_points = preview_points_from_proto(call->request.preview_points());
      call->pair.source = service.cloud_source(call->request.source(), "source");
      call->pair.target = service.cloud_source(call->request.target(), "target");
    } else {
      clock.upload_start = CallClock::Clock::now();
      call->form = read_upload_form(exchange.body, service, FormKind::kPair);
      clock.upload_end = CallClock::Clock::now();
      call->pair.params = params_from_proto(call->form.params.pairwise());
      call->pair.preview_points = preview_points_from_proto(call->form.preview_points);
      call->pair.source = call->form.clouds[0];
      call->pair.target = call->form.clouds[1];
    }
  } catch (...) {
    exchange.fail(status_from_current_exception());
    return;
  }
  if (wants_events(exchange.request)) {
    stream_job(service, exchange, clock, [call, &service](Job& job, StreamedCall& events) {
      const StageListener listener = [&events](const std::string& stage, v1::StageEvent::Phase phase, double fraction) {
        events.post_stage<v1::RegisterStreamResponse>(stage, phase, fraction);
      };
      v1::RegisterStreamResponse reply;
      const grpc::Status status =
          run_job(service, job, call->pair, listener, events.clock, events.record, *reply.mutable_result());
      if (status.ok()) events.post(reply);
      return status;
    });
    return;
  }
  v1::RegisterResponse reply;
  bool queue_full = false;
  const grpc::Status status = run_and_wait(
      service, clock, [&](Job& job) { return run_job(service, job, call->pair, {}, clock, exchange.record, reply); },
      queue_full);
  if (!status.ok()) {
    exchange.fail(status, queue_full);
    return;
  }
  exchange.reply(reply);
}

}  // namespace k4reg::service
