#include "sim/scene.h"

#include "k4reg/error.h"
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

Scene make_scene(const std::string& name) {
  if (name == "lab") return make_lab_scene();
  if (name == "arch") return make_arch_scene();
  std::string known;
  for (const auto& n : scene_names()) known += (known.empty() ? "" : ", ") + n;
  fail(ErrorCode::kInvalidArgument, "unknown scene '" + name + "' (known: " + known + ")");
}

std::vector<std::string> scene_names() { return {"lab", "arch"}; }

}  // namespace k4reg::sim
