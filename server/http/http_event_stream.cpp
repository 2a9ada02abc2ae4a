#include "http/http_event_stream.h"

#include "http/http_json.h"

namespace k4reg::service {

bool wants_events(const httplib::Request& request) {
  return request.get_header_value("Accept").find(kEventsContentType) != std::string::npos;
}

void StreamedCall::push(std::string line) {
  {
    const std::lock_guard lock(mutex_);
    lines_.push_back(std::move(line) + "\n");
  }
  changed_.notify_all();
}

void StreamedCall::post(const google::protobuf::Message& event) { push(to_json(event)); }

void StreamedCall::post_first(const google::protobuf::Message& event) {
  {
    const std::lock_guard lock(mutex_);
    lines_.push_front(to_json(event) + "\n");
  }
  changed_.notify_all();
}

void StreamedCall::log_end(const ServiceContext& service) {
  {
    const std::lock_guard lock(mutex_);
    if (logged_ || !finished_) return;
    logged_ = true;
    record.code = status.error_code();
    record.error = status.error_message();
    record.http_status = 200;
  }
  service.end_request(record);
}

void StreamedCall::finish(const grpc::Status& final_status) {
  if (!final_status.ok()) push("{\"error\":" + error_json(final_status, record.request_id) + "}");
  const std::lock_guard lock(mutex_);
  status = final_status;
  finished_ = true;
  changed_.notify_all();
}

bool StreamedCall::next(std::string& line) {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return finished_ || !lines_.empty(); });
  if (lines_.empty()) return false;
  line = std::move(lines_.front());
  lines_.pop_front();
  return true;
}

void stream_job(const ServiceContext& service, HttpExchange& exchange, const CallClock& clock,
                const std::function<grpc::Status(Job& job, StreamedCall& call)>& work) {
  if (exchange.body.is_multipart()) exchange.record.upload_bytes = exchange.body.bytes_received();
  auto call = std::make_shared<StreamedCall>(exchange.record);
  call->clock = clock;
  auto job = std::make_shared<Job>([call, work](Job& self) { call->finish(work(self, *call)); });
  call->clock.enqueued = CallClock::Clock::now();
  std::size_t position = 0;
  if (const grpc::Status status = service.submit(job, position); !status.ok()) {
    exchange.fail(status, status.error_code() == grpc::StatusCode::RESOURCE_EXHAUSTED);
    return;
  }
  v1::RegisterStreamResponse queued;  // {"queued": {"position": n}}: the same JSON in both streams
  queued.mutable_queued()->set_position(static_cast<std::uint32_t>(position));
  call->post_first(queued);  // nothing has been taken yet: the answer starts after this handler returns
  exchange.stream(
      kEventsContentType,
      [call, &service](std::string& line) {
        if (call->next(line)) return true;
        call->log_end(service);  // before the last byte: a client that has the answer finds the line
        return false;
      },
      [call, job, &service](bool delivered) {
        if (!delivered) job->token().cancel();  // the client went away: nobody waits for the result
        if (service.withdraw(job.get())) call->finish({grpc::StatusCode::CANCELLED, "the client went away while queued"});
        // The job may still be running if the client left: log once it ends.
        std::string ignored;
        while (call->next(ignored)) {
        }
        call->log_end(service);
      });
}

}  // namespace k4reg::service
