#include "health.h"

namespace k4reg::service {

HealthPublisher::HealthPublisher(grpc::HealthCheckServiceInterface& health, const JobQueue& queue)
    : health_(health), queue_(queue) {
  for (const char* name : {"", kLivenessService, kReadinessService, kRegistrationService})
    health_.SetServingStatus(name, true);
  update();
}

void HealthPublisher::update() {
  std::lock_guard lock(mutex_);
  const bool ready = !draining_ && !queue_.full();
  if (ready == ready_) return;
  ready_ = ready;
  health_.SetServingStatus(kReadinessService, ready);
}

void HealthPublisher::set_draining() {
  std::lock_guard lock(mutex_);
  draining_ = true;
  ready_ = false;
  for (const char* name : {"", kReadinessService, kRegistrationService}) health_.SetServingStatus(name, false);
}

}  // namespace k4reg::service
