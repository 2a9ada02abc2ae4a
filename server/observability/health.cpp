#include "observability/health.h"

namespace k4reg::service {

HealthPublisher::HealthPublisher(std::vector<grpc::HealthCheckServiceInterface*> health, const JobQueue& queue)
    : health_(std::move(health)), queue_(queue) {
  for (const char* name : {"", kLivenessService, kReadinessService, kRegistrationService}) set(name, true);
  update();
}

void HealthPublisher::set(const char* name, bool serving) {
  for (grpc::HealthCheckServiceInterface* health : health_) health->SetServingStatus(name, serving);
}

void HealthPublisher::update() {
  std::lock_guard lock(mutex_);
  const bool ready = !draining_ && !queue_.full();
  if (ready == ready_) return;
  ready_ = ready;
  set(kReadinessService, ready);
}

void HealthPublisher::set_draining() {
  std::lock_guard lock(mutex_);
  draining_ = true;
  ready_ = false;
  for (const char* name : {"", kReadinessService, kRegistrationService}) set(name, false);
}

}  // namespace k4reg::service
