// A simulated scene: analytic primitives in the scene frame (metres, z up) plus the scanner stations.
// Objects that move between scans (people) belong to the station whose scan they appear in.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "sim/primitives.h"

namespace k4reg::sim {

struct Station {
  Eigen::Vector3d position_m;           // scanner centre in the scene frame
  std::string description;
  std::vector<Primitive> movers;        // present only during this station's scan
  // Set: an object range scanner aimed at this point, seeing a square frustum field_of_view_deg across
  // (a camera-like grid of rays). Unset: the terrestrial scanner's 360 x 150 deg.
  std::optional<Eigen::Vector3d> look_at_m = std::nullopt;
  double field_of_view_deg = 35.0;      // full angle across, used only with look_at_m
};

struct Scene {
  std::string name;
  std::string description;
  int layout = 0;                       // 0 = canonical; > 0 a deterministic variant (see make_scene)
  double default_max_range_m = 120.0;
  std::size_t default_points = 700000;  // what ScanParams::points = 0 asks for
  double default_noise_m = 0.002;       // range noise when ScanParams::noise_m is unset
  bool intensity = true;                // false: the scanner records no intensity (the cloud has none)
  std::vector<Primitive> primitives;    // static for all stations
  std::vector<Station> stations;

  // Everything a scan from `station` can see; throws kInvalidArgument for a station out of range.
  std::vector<Primitive> primitives_seen_from(int station) const;
};

// The built-in scenes (scene_names()). layout 0 is the canonical scene; layout N > 0 a deterministic
// variant of it (dimensions scaled by up to ~15 %, furniture, details and stations moved, sides swapped)
// that keeps what makes the scene hard. lab and arch exist only as layout 0. Throws
// k4reg::Error(kInvalidArgument) for an unknown name, a negative layout, or layout > 0 of lab or arch.
Scene make_scene(const std::string& name, int layout = 0);
std::vector<std::string> scene_names();

}  // namespace k4reg::sim
