#include "k4reg/registration/dog_keypoints.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "k4reg/util/error.h"
#include "k4reg/geometry/neighbor_grid.h"
#include "k4reg/geometry/voxel_grid.h"

namespace k4reg {
namespace {

// Gaussians are cut at 2.5 sigma (weight 4%): the tail changes the mean by far less than the noise.
constexpr double kKernelRadius = 2.5;

float robust_range(std::vector<float> values) {
  if (values.empty()) return 0.0f;
  const std::size_t lo = values.size() / 200, hi = values.size() - 1 - values.size() / 200;
  std::nth_element(values.begin(), values.begin() + lo, values.end());
  const float low = values[lo];
  std::nth_element(values.begin(), values.begin() + hi, values.end());
  return values[hi] - low;
}

constexpr int kMaxLevels = 16;  // scales_per_octave + 3, scales_per_octave <= 10 (validated)

// Gaussian-weighted sums around one point at every level: weight, signal and offset from the point.
// In float: a few hundred terms of one sign (relative error ~1e-6, far below the 1 % contrast).
struct LevelSums {
  std::array<float, kMaxLevels> w, s, x, y, z;
};

struct SmoothingInput {
  const std::vector<Eigen::Vector3f>& points;
  const std::vector<float>& signal;
  const NeighborGrid& grid;
  float radius;
  const float* table;  // kRow weights per squared-distance bin
  float table_scale;
};

// The inner loop of the DoG (most of its time): fixed-size rows so the compiler vectorises them.
template <int kRow>
void smoothed_sums(const SmoothingInput& in, std::size_t i, LevelSums& out) {
  std::array<float, kRow> w{}, s{}, x{}, y{}, z{};
  const Eigen::Vector3f centre = in.points[i];
  in.grid.for_each_within(centre, in.radius, [&](std::uint32_t k, float d2) {
    const Eigen::Vector3f offset = in.points[k] - centre;
    const float value = in.signal[k];
    std::array<float, kRow> weight;
    std::copy_n(in.table + static_cast<int>(d2 * in.table_scale + 0.5f) * kRow, kRow, weight.begin());
    for (int j = 0; j < kRow; ++j) {
      w[j] += weight[j];
      s[j] += weight[j] * value;
      x[j] += weight[j] * offset.x();
      y[j] += weight[j] * offset.y();
      z[j] += weight[j] * offset.z();
    }
  });
  std::copy(w.begin(), w.end(), out.w.begin());
  std::copy(s.begin(), s.end(), out.s.begin());
  std::copy(x.begin(), x.end(), out.x.begin());
  std::copy(y.begin(), y.end(), out.y.begin());
  std::copy(z.begin(), z.end(), out.z.begin());
}

// One octave: points at spacing h with their signal; appends its keypoints to out.
void detect_octave(const std::vector<Eigen::Vector3f>& points, const std::vector<float>& signal, double h,
                   double contrast, const DogParams& params, const CancellationToken* cancel, DogKeypoints& out) {
  const int levels = params.scales_per_octave + 3;  // Gaussian scales; levels - 1 DoG layers
  const int dogs = levels - 1;
  const std::size_t n = points.size();
  std::vector<double> sigma(levels);
  for (int j = 0; j < levels; ++j) sigma[j] = h * std::pow(2.0, static_cast<double>(j) / params.scales_per_octave);
  const float radius = static_cast<float>(kKernelRadius * sigma.back());
  const NeighborGrid grid(points, radius);

  // Gaussian weights of all levels tabulated over the squared distance: one look-up per neighbour
  // instead of `levels` exponentials (the table's step changes a weight by < 0.1 %). Rows are padded to
  // 8 or 16 levels so the per-neighbour sums vectorise.
  constexpr int kTableSize = 4096;
  const int row = levels <= 8 ? 8 : kMaxLevels;
  const float table_scale = (kTableSize - 1) / (radius * radius);
  std::vector<float> table(kTableSize * row, 0.0f);
  for (int b = 0; b < kTableSize; ++b)
    for (int j = 0; j < levels; ++j)
      table[b * row + j] = static_cast<float>(std::exp(-(b / table_scale) / (2.0 * sigma[j] * sigma[j])));

  std::vector<float> dog(n * dogs, 0.0f);
  std::vector<std::uint8_t> stable(n * dogs, 0);  // DoG layer j is trustworthy at point i
  const SmoothingInput input{points, signal, grid, radius, table.data(), table_scale};
  auto smooth = row <= 8 ? &smoothed_sums<8> : &smoothed_sums<16>;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024), [&](const auto& range) {
    check(cancel);
    LevelSums sums;
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      smooth(input, i, sums);
      // A fully sampled plane at spacing h gives sum(w) = 2 pi sigma^2 / h^2.
      auto ok = [&](int j) {
        const double coverage = sums.w[j] * h * h / (2.0 * M_PI * sigma[j] * sigma[j]);
        const double border = Eigen::Vector3d(sums.x[j], sums.y[j], sums.z[j]).norm() / sums.w[j] / sigma[j];
        return coverage >= params.min_coverage && border <= params.max_border_offset;
      };
      bool previous_ok = ok(0);
      for (int j = 0; j < dogs; ++j) {
        const bool next_ok = ok(j + 1);
        dog[i * dogs + j] = sums.s[j + 1] / sums.w[j + 1] - sums.s[j] / sums.w[j];
        stable[i * dogs + j] = previous_ok && next_ok;
        previous_ok = next_ok;
      }
    }
  });

  // Extrema over the neighbours within the scale (at least the 26-neighbourhood) and the adjacent layers.
  std::vector<std::vector<int>> found(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024), [&](const auto& range) {
    check(cancel);
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      for (int j = 1; j + 1 < dogs; ++j) {
        const float v = dog[i * dogs + j];
        if (!stable[i * dogs + j] || std::abs(v) < contrast) continue;
        const float r = static_cast<float>(std::max(1.75 * h, sigma[j]));
        bool is_max = v > dog[i * dogs + j - 1] && v > dog[i * dogs + j + 1];
        bool is_min = v < dog[i * dogs + j - 1] && v < dog[i * dogs + j + 1];
        if (!is_max && !is_min) continue;
        grid.for_each_within(points[i], r, [&](std::uint32_t k, float) {
          if (k == i) return;
          for (int dj = -1; dj <= 1; ++dj) {
            const float u = dog[k * dogs + j + dj];
            is_max = is_max && v > u;
            is_min = is_min && v < u;
          }
        });
        if (is_max || is_min) found[i].push_back(j);
      }
    }
  });
  // A keypoint sits at the response-weighted centre of its blob rather than on a voxel centroid: voxel
  // grids of two scans are not aligned, and the coarse octaves' voxels are large.
  for (std::size_t i = 0; i < n; ++i)
    for (int j : found[i]) {
      const float v = dog[i * dogs + j];
      const float r = static_cast<float>(std::max(1.75 * h, sigma[j]));
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      double weight = 0;
      grid.for_each_within(points[i], r, [&](std::uint32_t k, float) {
        const double w = std::max(0.0f, v > 0 ? dog[k * dogs + j] : -dog[k * dogs + j]);
        sum += w * (points[k] - points[i]).cast<double>();
        weight += w;
      });
      const Eigen::Vector3d mean = weight > 0 ? Eigen::Vector3d(sum / weight) : Eigen::Vector3d::Zero();
      out.points.push_back(points[i] + mean.cast<float>());
      out.scale_m.push_back(static_cast<float>(sigma[j]));
      out.response.push_back(v);
    }
}

}  // namespace

DogKeypoints detect_dog_keypoints(const std::vector<Eigen::Vector3f>& points, const std::vector<float>& signal,
                                  const DogParams& params, const CancellationToken* cancel) {
  if (signal.size() != points.size()) fail(ErrorCode::kInternal, "DoG: signal and points differ in size");
  if (params.octaves < 1 || params.scales_per_octave < 1 || params.scales_per_octave + 3 > kMaxLevels)
    fail(ErrorCode::kInvalidArgument, "DoG: octaves must be at least 1 and scales_per_octave in [1, " +
                                          std::to_string(kMaxLevels - 3) + "]");
  const double range = robust_range(signal);
  const double contrast = params.min_contrast * range;

  DogKeypoints out;
  // A flat signal (e.g. a constant intensity field) has no extrema; float rounding would invent some.
  if (!(range > 0.0)) return out;
  PointCloud octave;
  octave.points = points;
  octave.intensity = signal;
  double h = params.min_scale_m;
  for (int o = 0; o < params.octaves; ++o) {
    if (o > 0) {
      h *= 2.0;
      octave = voxel_grid(octave, h, cancel).cloud;  // averages positions and signal per coarser voxel
    }
    if (octave.size() < 27) break;  // nothing left to find extrema in
    detect_octave(octave.points, octave.intensity, h, contrast, params, cancel, out);
  }
  return out;
}

}  // namespace k4reg
