#include "sim/scene.h"

#include "k4reg/util/error.h"
#include "sim/scene_builder.h"

namespace k4reg::sim {

std::vector<Primitive> Scene::primitives_seen_from(int station) const {
  if (station < 0 || station >= static_cast<int>(stations.size()))
    fail(ErrorCode::kInvalidArgument, "scene '" + name + "' has stations 0.." + std::to_string(static_cast<int>(stations.size()) - 1) +
                                          ", not " + std::to_string(station));
  std::vector<Primitive> all = primitives;
  const auto& movers = stations[station].movers;
  all.insert(all.end(), movers.begin(), movers.end());
  return all;
}

Scene make_scene(const std::string& name, int layout) {
  if (layout < 0) fail(ErrorCode::kInvalidArgument, "layout must be >= 0, not " + std::to_string(layout));
  const bool fixed_layout = name == "lab" || name == "arch";
  if (fixed_layout && layout > 0)
    fail(ErrorCode::kInvalidArgument, "scene '" + name + "' has only layout 0 (its benchmark results depend on it)");
  if (name == "lab") return make_lab_scene();
  if (name == "arch") return make_arch_scene();
  if (name == "hall") return make_hall_scene(layout);
  if (name == "corridor") return make_corridor_scene(layout);
  if (name == "monument") return make_monument_scene(layout);
  if (name == "courtyard") return make_courtyard_scene(layout);
  if (name == "object") return make_object_scene(layout, 10);
  if (name == "object15") return make_object_scene(layout, 15);
  std::string known;
  for (const auto& n : scene_names()) known += (known.empty() ? "" : ", ") + n;
  fail(ErrorCode::kInvalidArgument, "unknown scene '" + name + "' (known: " + known + ")");
}

std::vector<std::string> scene_names() { return {"lab", "arch", "hall", "corridor", "monument", "courtyard", "object", "object15"}; }

}  // namespace k4reg::sim
