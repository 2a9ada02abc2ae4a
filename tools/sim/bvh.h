// Closest-hit queries over a few hundred primitives: a bounding volume hierarchy (median split on the
// longest axis) so that a ray tests a handful of boxes and primitives instead of all of them.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <vector>

#include "sim/primitives.h"

namespace k4reg::sim {

struct SurfaceHit {
  double distance_m = 0.0;
  Eigen::Vector3d normal;  // unit, facing the ray
  double reflectivity = 0.0;
  Material material = Material::kOpaque;
};

class SceneIndex {
 public:
  explicit SceneIndex(std::vector<Primitive> primitives);

  // The nearest surface along the ray with distance in [t_min, t_max]. Thread-safe.
  std::optional<SurfaceHit> closest_hit(const Ray& ray, double t_min, double t_max) const;

 private:
  struct Node {
    Eigen::AlignedBox3d box;
    int first = 0;  // leaf: first primitive; inner node: index of the second child (the first is next)
    int count = 0;  // > 0 for leaves
  };
  int build(int first, int count);

  std::vector<Primitive> primitives_;
  std::vector<Eigen::AlignedBox3d> primitive_bounds_;
  std::vector<Node> nodes_;
};

}  // namespace k4reg::sim
