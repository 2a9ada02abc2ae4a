#include "random_motion.h"

#include <Eigen/Geometry>
#include <random>
#include <vector>

namespace k4reg::bench {

Eigen::Matrix4d random_motion(std::uint64_t seed, double reach) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  q.normalize();
  std::uniform_real_distribution<double> shift(-reach, reach);
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = q.toRotationMatrix();
  m.topRightCorner<3, 1>() = Eigen::Vector3d(shift(rng), shift(rng), shift(rng));
  return m;
}

PointCloud moved(const PointCloud& cloud, const Eigen::Matrix4d& m) {
  std::vector<Eigen::Vector3d> world;
  world.reserve(cloud.size());
  for (const auto& p : cloud.points) {
    const Eigen::Vector3d q = cloud.origin_m + p.cast<double>();
    world.push_back(m.topLeftCorner<3, 3>() * q + m.topRightCorner<3, 1>());
  }
  return make_local_cloud(world, cloud.intensity, "moved cloud");
}

}  // namespace k4reg::bench
