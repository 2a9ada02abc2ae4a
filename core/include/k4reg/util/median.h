// The median of a sample, by selection rather than sorting.
// Cost: O(n) (std::nth_element on the copy it takes).
#pragma once

#include <algorithm>
#include <vector>

namespace k4reg {

// The middle value (the upper of the two middle ones for an even count); values must not be empty.
inline double median(std::vector<double> values) {
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace k4reg
