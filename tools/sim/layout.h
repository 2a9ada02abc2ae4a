// Deterministic variants of a scene for the benchmark's tune / hold-out split: layout 0 is the canonical
// scene (every draw returns the neutral value), layout N > 0 draws its variations from a stream keyed
// by (scene, N), so a variant is the same on every machine and run.
#pragma once

#include <cstdint>
#include <string>

#include "sim/random.h"

namespace k4reg::sim {

class LayoutDice {
 public:
  LayoutDice(const std::string& scene_name, int layout) : varied_(layout > 0), rng_(key(scene_name, layout)) {}

  bool varied() const { return varied_; }
  // 1 for layout 0, else uniform in [1 - max_fraction, 1 + max_fraction]: scales a dimension.
  double scale(double max_fraction) { return varied_ ? 1.0 + max_fraction * (2.0 * rng_.uniform() - 1.0) : 1.0; }
  // 0 for layout 0, else uniform in [-max_m, max_m]: moves an object or a station.
  double shift(double max_m) { return varied_ ? max_m * (2.0 * rng_.uniform() - 1.0) : 0.0; }
  // false for layout 0, else a fair coin: swaps sides, mirrors a detail.
  bool flip() { return varied_ && rng_.uniform() < 0.5; }

 private:
  static std::uint64_t key(const std::string& scene_name, int layout) {
    std::uint64_t k = 0x6c61'796f'7574ULL;
    for (const char c : scene_name) k = derive_key(k, static_cast<unsigned char>(c));
    return derive_key(k, static_cast<std::uint64_t>(layout));
  }

  bool varied_;
  RandomStream rng_;
};

}  // namespace k4reg::sim
