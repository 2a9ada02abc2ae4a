// The heap bytes a vector holds: its capacity, not its size, since that is what stays allocated. Caches that keep
// what they computed (prepared_scan.h) charge their budget with it.
#pragma once

#include <cstddef>
#include <vector>

namespace k4reg {

template <typename T>
std::size_t held_bytes(const std::vector<T>& values) {
  return values.capacity() * sizeof(T);
}

inline std::size_t held_bytes(const std::vector<bool>& values) { return values.capacity() / 8; }  // bits

}  // namespace k4reg
