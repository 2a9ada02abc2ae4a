#include "sim/bvh.h"

#include <algorithm>
#include <numeric>
#include <utility>

namespace k4reg::sim {
namespace {

constexpr int kLeafSize = 2;
constexpr double kPad_m = 1e-7;  // flat boxes (walls, posters) must not lose edge hits to rounding

// Entry distance of the ray into the box within [t_min, t_max], or a negative value when it misses.
double box_entry(const Eigen::AlignedBox3d& box, const Eigen::Vector3d& origin, const Eigen::Vector3d& inv_dir,
                 double t_min, double t_max) {
  const Eigen::Array3d t0 = (box.min() - origin).array() * inv_dir.array();
  const Eigen::Array3d t1 = (box.max() - origin).array() * inv_dir.array();
  const double t_in = std::max(t_min, t0.min(t1).maxCoeff());
  const double t_out = std::min(t_max, t0.max(t1).minCoeff());
  return t_in <= t_out ? t_in : -1.0;
}

}  // namespace

SceneIndex::SceneIndex(std::vector<Primitive> primitives) : primitives_(std::move(primitives)) {
  if (primitives_.empty()) return;
  primitive_bounds_.reserve(primitives_.size());
  for (const auto& p : primitives_) {
    Eigen::AlignedBox3d b = bounds(p.shape);
    b.min().array() -= kPad_m;
    b.max().array() += kPad_m;
    primitive_bounds_.push_back(b);
  }
  nodes_.reserve(2 * primitives_.size());
  build(0, static_cast<int>(primitives_.size()));
}

int SceneIndex::build(int first, int count) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.push_back({});
  Eigen::AlignedBox3d box, centroids;
  for (int i = first; i < first + count; ++i) {
    box.extend(primitive_bounds_[i]);
    centroids.extend(primitive_bounds_[i].center());
  }
  nodes_[index].box = box;
  if (count <= kLeafSize) {
    nodes_[index].first = first;
    nodes_[index].count = count;
    return index;
  }
  int axis;
  centroids.sizes().maxCoeff(&axis);
  // Median split; the build reorders primitives (and their bounds) so that every node owns a range.
  std::vector<int> order(count);
  std::iota(order.begin(), order.end(), first);
  const int half = count / 2;
  std::nth_element(order.begin(), order.begin() + half, order.end(), [&](int a, int b) {
    return primitive_bounds_[a].center()[axis] < primitive_bounds_[b].center()[axis];
  });
  std::vector<Primitive> prims;
  std::vector<Eigen::AlignedBox3d> boxes;
  for (const int i : order) {
    prims.push_back(std::move(primitives_[i]));
    boxes.push_back(primitive_bounds_[i]);
  }
  std::move(prims.begin(), prims.end(), primitives_.begin() + first);
  std::copy(boxes.begin(), boxes.end(), primitive_bounds_.begin() + first);
  build(first, half);
  nodes_[index].first = build(first + half, count - half);
  return index;
}

std::optional<SurfaceHit> SceneIndex::closest_hit(const Ray& ray, double t_min, double t_max) const {
  if (nodes_.empty()) return std::nullopt;
  Eigen::Vector3d inv_dir;
  for (int i = 0; i < 3; ++i)  // a huge finite value instead of inf keeps 0 * inv out of NaN
    inv_dir[i] = 1.0 / (ray.direction[i] == 0.0 ? 1e-300 : ray.direction[i]);

  std::optional<ShapeHit> best;
  int best_primitive = -1;
  double t_best = t_max;
  int stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (box_entry(node.box, ray.origin, inv_dir, t_min, t_best) < 0.0) continue;
    if (node.count > 0) {
      for (int i = node.first; i < node.first + node.count; ++i) {
        if (box_entry(primitive_bounds_[i], ray.origin, inv_dir, t_min, t_best) < 0.0) continue;
        if (auto hit = intersect(primitives_[i].shape, ray, t_min, t_best)) {
          t_best = hit->distance_m;
          best = hit;
          best_primitive = i;
        }
      }
      continue;
    }
    // Visit the nearer child first so that t_best shrinks early.
    const int left = static_cast<int>(&node - nodes_.data()) + 1, right = node.first;
    const double t_left = box_entry(nodes_[left].box, ray.origin, inv_dir, t_min, t_best);
    const double t_right = box_entry(nodes_[right].box, ray.origin, inv_dir, t_min, t_best);
    if (t_left >= 0.0 && t_right >= 0.0) {
      const bool left_first = t_left <= t_right;
      stack[top++] = left_first ? right : left;
      stack[top++] = left_first ? left : right;
    } else if (t_left >= 0.0) {
      stack[top++] = left;
    } else if (t_right >= 0.0) {
      stack[top++] = right;
    }
  }
  if (!best) return std::nullopt;
  const Surface& surface = primitives_[best_primitive].surface;
  return SurfaceHit{best->distance_m, best->normal, surface.reflectivity(best->uv_m), surface.material};
}

}  // namespace k4reg::sim
