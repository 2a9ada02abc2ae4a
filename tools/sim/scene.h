// A simulated scene: analytic primitives in the scene frame (metres, z up) plus the scanner stations.
// Objects that move between scans (people) belong to the station whose scan they appear in.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "sim/primitives.h"

namespace k4reg::sim {

struct Station {
  Eigen::Vector3d position_m;           // scanner centre in the scene frame
  std::string description;
  std::vector<Primitive> movers;        // present only during this station's scan
};

struct Scene {
  std::string name;
  std::string description;
  double default_max_range_m = 120.0;
  std::vector<Primitive> primitives;    // static for all stations
  std::vector<Station> stations;

  // Everything a scan from `station` can see; throws kInvalidArgument for a station out of range.
  std::vector<Primitive> primitives_seen_from(int station) const;
};

// The built-in scenes ("lab", "arch"); throws k4reg::Error(kInvalidArgument) for an unknown name.
Scene make_scene(const std::string& name);
std::vector<std::string> scene_names();

}  // namespace k4reg::sim
