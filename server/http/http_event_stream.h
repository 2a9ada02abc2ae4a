// Progress for HTTP clients: with "Accept: application/x-ndjson" a registration is answered 200 with a chunked
// body of newline-delimited JSON events as they happen, the same messages as the gRPC streams
// (RegisterStreamResponse / RegisterProjectEvent): {"queued": {...}}, {"stage": {...}}, {"pair": {...}}, then
// {"result": {...}} or {"error": {"code", "message", "request_id"}}. What is refused before the job queues
// (headers, body, a full queue) gets the usual error answer instead. A client that goes away cancels its job.
#pragma once

#include <google/protobuf/message.h>
#include <grpcpp/support/status.h>

#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>

#include "http/http_exchange.h"
#include "k4reg/v1/registration.pb.h"
#include "observability/request_log.h"
#include "service_context.h"

namespace k4reg::service {

inline constexpr const char* kEventsContentType = "application/x-ndjson";

// True when the request asks for the event stream.
bool wants_events(const httplib::Request& request);

// One streamed call: the job posts events from its worker; the connection's thread writes them.
class StreamedCall {
 public:
  explicit StreamedCall(RequestRecord record) : record(std::move(record)) {}
  void post(const google::protobuf::Message& event);  // any thread
  // Ahead of every event posted so far (the queued event: the job may have begun before it is known).
  void post_first(const google::protobuf::Message& event);
  // The job's last word: its status (an error event unless OK; the result event is the job's to post).
  void finish(const grpc::Status& status);
  // A stage event (Event: RegisterStreamResponse or RegisterProjectEvent), timed from the job's start;
  // progress at most every 100 ms, as the gRPC streams.
  template <typename Event>
  void post_stage(const std::string& stage, v1::StageEvent::Phase phase, double fraction) {
    const auto now = CallClock::Clock::now();
    if (phase == v1::StageEvent::PHASE_PROGRESS) {
      if (now - last_progress_ < std::chrono::milliseconds(100)) return;
      last_progress_ = now;  // only the job's worker posts stages
    }
    post(make_stage_event<Event>(stage, phase, fraction, clock, now));
  }
  // Waits for the next line; false once finished and every line was taken.
  bool next(std::string& line);
  // Writes the access-log line, once: when the last line is out, or when the client went away.
  void log_end(const ServiceContext& service);

  RequestRecord record;  // the job fills in points and times; logged when the answer ends
  CallClock clock;
  grpc::Status status;

 private:
  void push(std::string line);
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::string> lines_;
  bool finished_ = false, logged_ = false;
  CallClock::Clock::time_point last_progress_{};
};

// Queues `work` as the call's job and makes the answer its event stream (queued first). Refusals before the
// job runs (a full queue, draining) are the exchange's usual error answers.
// `clock` has the call's start and upload times.
void stream_job(const ServiceContext& service, HttpExchange& exchange, const CallClock& clock,
                const std::function<grpc::Status(Job& job, StreamedCall& call)>& work);

}  // namespace k4reg::service
