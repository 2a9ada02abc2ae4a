// What the standard grpc.health.v1 service reports (gRPC's built-in implementation):
//   "liveness"                     SERVING while the process runs (restart only if this fails)
//   "readiness"                    NOT_SERVING while draining or while the job queue is full
//   "" and "k4reg.v1.Registration" SERVING until draining starts
// Kubernetes distinguishes probes by the service name: livenessProbe "liveness", readinessProbe "readiness".
#pragma once

#include <grpcpp/health_check_service_interface.h>

#include <mutex>
#include <vector>

#include "jobs/job_queue.h"

namespace k4reg::service {

inline constexpr const char* kLivenessService = "liveness";
inline constexpr const char* kReadinessService = "readiness";
inline constexpr const char* kRegistrationService = "k4reg.v1.Registration";

class HealthPublisher {
 public:
  // Publishes the same statuses to every server's health service (the API's and the health listener's).
  HealthPublisher(std::vector<grpc::HealthCheckServiceInterface*> health, const JobQueue& queue);

  // Re-reads the queue; call whenever it changes (cheap when nothing changed).
  void update();
  void set_draining();

 private:
  void set(const char* name, bool serving);

  const std::vector<grpc::HealthCheckServiceInterface*> health_;
  const JobQueue& queue_;
  std::mutex mutex_;  // serialises updates so the last published state is the current one
  bool draining_ = false;
  bool ready_ = true;
};

}  // namespace k4reg::service
