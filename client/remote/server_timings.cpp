#include "remote/server_timings.h"

namespace k4reg::cli {

double server_overhead_s(const v1::ServerTimings& t) {
  return t.request_to_job_start_s() - t.queue_wait_s() - t.upload_s() + t.job_end_to_reply_s();
}

nlohmann::json server_timings_to_json(const v1::ServerTimings& t) {
  return {{"queue_wait_s", t.queue_wait_s()},
          {"request_to_job_start_s", t.request_to_job_start_s()},
          {"upload_s", t.upload_s()},
          {"load_s", t.load_s()},
          {"registration_s", t.registration_s()},
          {"job_end_to_reply_s", t.job_end_to_reply_s()},
          {"overhead_s", server_overhead_s(t)}};
}

}  // namespace k4reg::cli
