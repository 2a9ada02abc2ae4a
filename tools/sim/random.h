// Counter-based random numbers. Every ray draws from its own stream keyed by (seed, station, ray index),
// so a scan is bit-for-bit the same whichever thread traces which ray, and for any thread count.
#pragma once

#include <cmath>
#include <cstdint>
#include <numbers>

namespace k4reg::sim {

// SplitMix64 finaliser: a bijective 64-bit mix with good avalanche.
inline std::uint64_t mix64(std::uint64_t x) {
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// Derives the key of a sub-stream (e.g. one ray of one station) from a parent key.
inline std::uint64_t derive_key(std::uint64_t parent, std::uint64_t index) {
  return mix64(parent ^ mix64(index + 0x9e3779b97f4a7c15ULL));
}

// SplitMix64 generator: cheap to create per ray, unlike std::mt19937_64's 2.5 kB state.
class RandomStream {
 public:
  explicit RandomStream(std::uint64_t key) : state_(key) {}

  std::uint64_t next() {
    state_ += 0x9e3779b97f4a7c15ULL;
    return mix64(state_);
  }
  // Uniform in [0, 1).
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  // Standard normal (Box-Muller; written out so the values do not depend on the standard library).
  double normal() {
    const double u1 = 1.0 - uniform();  // (0, 1]: keeps log finite
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
  }

 private:
  std::uint64_t state_;
};

}  // namespace k4reg::sim
