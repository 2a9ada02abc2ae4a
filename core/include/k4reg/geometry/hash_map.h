// A minimal open-addressing hash map from 64-bit voxel keys to 32-bit slots. std::unordered_map
// allocates per node and is ~5x slower on the 10 M-point voxel grid; this is all we need.
#pragma once

#include <cstdint>
#include <vector>

#include "k4reg/util/held_bytes.h"

namespace k4reg {

class VoxelKeyMap {
 public:
  static constexpr std::uint32_t kAbsent = 0xffffffffu;

  explicit VoxelKeyMap(std::size_t expected = 1024) { rehash(expected * 2); }

  // Returns the value for key, inserting next_value if absent (inserted = true then).
  std::uint32_t find_or_insert(std::uint64_t key, std::uint32_t next_value, bool& inserted) {
    if ((size_ + 1) * 2 > keys_.size()) rehash(keys_.size() * 2);
    std::size_t i = slot(key);
    while (values_[i] != kAbsent) {
      if (keys_[i] == key) {
        inserted = false;
        return values_[i];
      }
      i = (i + 1) & mask_;
    }
    keys_[i] = key;
    values_[i] = next_value;
    ++size_;
    inserted = true;
    return next_value;
  }

  std::uint32_t find(std::uint64_t key) const {
    for (std::size_t i = slot(key);; i = (i + 1) & mask_) {
      if (values_[i] == kAbsent) return kAbsent;
      if (keys_[i] == key) return values_[i];
    }
  }

  std::size_t size() const { return size_; }
  std::size_t bytes() const { return held_bytes(keys_) + held_bytes(values_); }  // heap bytes held

 private:
  std::size_t slot(std::uint64_t key) const {
    key ^= key >> 33;  // murmur3 finaliser: voxel keys are highly regular
    key *= 0xff51afd7ed558ccdULL;
    key ^= key >> 33;
    return static_cast<std::size_t>(key) & mask_;
  }

  void rehash(std::size_t capacity) {
    std::size_t n = 16;
    while (n < capacity) n *= 2;
    std::vector<std::uint64_t> old_keys(n);
    std::vector<std::uint32_t> old_values(n, kAbsent);
    old_keys.swap(keys_);
    old_values.swap(values_);
    mask_ = n - 1;
    size_ = 0;
    for (std::size_t i = 0; i < old_keys.size(); ++i) {
      if (old_values[i] == kAbsent) continue;
      std::size_t j = slot(old_keys[i]);
      while (values_[j] != kAbsent) j = (j + 1) & mask_;
      keys_[j] = old_keys[i];
      values_[j] = old_values[i];
      ++size_;
    }
  }

  std::vector<std::uint64_t> keys_;
  std::vector<std::uint32_t> values_;
  std::size_t mask_ = 0;
  std::size_t size_ = 0;
};

// One bit per hashed key, about 16 bits per expected key: says "absent" for most keys never added, from an array small
// enough to stay in cache, where a hash map's probe for an absent key costs a cache miss. Searches whose look-ups
// mostly miss (the congruent-set search's cells, a pass over a whole cloud for the cells around a few queries) test
// it first.
class KeyBits {
 public:
  explicit KeyBits(std::size_t expected_keys) {
    int bits = 6;
    while ((std::size_t{1} << bits) < 16 * expected_keys) ++bits;
    words_.assign((std::size_t{1} << bits) / 64, 0);
    shift_ = 64 - bits;
  }
  void add(std::uint64_t key) {
    const std::uint64_t bit = position(key);
    words_[bit >> 6] |= std::uint64_t{1} << (bit & 63);
  }
  bool may_hold(std::uint64_t key) const {
    const std::uint64_t bit = position(key);
    return (words_[bit >> 6] >> (bit & 63)) & 1;
  }
  std::size_t bytes() const { return held_bytes(words_); }

 private:
  std::uint64_t position(std::uint64_t key) const {
    return (key * 0x9e3779b97f4a7c15ULL) >> shift_;
  }  // Fibonacci hashing

  std::vector<std::uint64_t> words_;
  int shift_ = 58;
};

}  // namespace k4reg
