/// @file depth_noise.hpp
/// Kinect-like depth degradation for the synthetic scene: axial Gaussian noise with
/// sigma(z) = 0.0012 + 0.0019 (z - 0.4)^2 (Nguyen et al. 2012), quantisation to the TUM PNG unit
/// (1/5000 m), holes at depth discontinuities, a border band and the sensor's range limits.
#pragma once

#include "dyncull/core/depth.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>

namespace dyncull::sim {

struct DepthNoiseOptions {
  double sigma_base_m = 0.0012;       ///< sigma at the reference distance
  double sigma_quadratic = 0.0019;    ///< growth of sigma with (z - sigma_reference_m)^2, 1/m
  double sigma_reference_m = 0.4;     ///< distance of minimal noise
  double units_per_metre = 5000.0;    ///< quantisation step 1/units_per_metre (TUM PNG scale)
  double min_range_m = 0.4;           ///< closer surfaces give no measurement
  double max_range_m = 8.0;           ///< farther surfaces give no measurement
  double edge_threshold_rel = 0.05;   ///< neighbours differing by more than this fraction of depth make holes
  int border_px = 8;                  ///< band along every image edge without measurements
};

/// Axial standard deviation of the depth at z metres.
inline double kinect_depth_sigma_m(double z, const DepthNoiseOptions& options = {}) {
  return axial_depth_sigma_m(z, options.sigma_base_m, options.sigma_quadratic, options.sigma_reference_m);
}

namespace detail {

inline std::uint64_t splitmix(std::uint64_t& x) {
  std::uint64_t z = (x += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

/// Approximately standard normal from one 64-bit word: the sum of four 16-bit uniforms
/// (Irwin-Hall, variance 4/12), rescaled. Cheaper than Box-Muller per pixel; tails end at 3.46.
inline double approx_normal(std::uint64_t bits) {
  const std::uint64_t sum = (bits & 0xFFFF) + ((bits >> 16) & 0xFFFF) + ((bits >> 32) & 0xFFFF) + (bits >> 48);
  constexpr double kScale = 1.7320508075688772 / 65536.0;  // sqrt(3) / 2^16: unit variance
  return (static_cast<double>(sum) - 2.0 * 65535.0) * kScale;
}

}  // namespace detail

/// Degrades a noiseless depth image (metres, 0 = no surface) in place. Deterministic for a seed.
/// Holes are decided on the noiseless depth first, then noise and quantisation are applied.
inline void apply_depth_noise(float* depth, int width, int height, const DepthNoiseOptions& options,
                              std::uint64_t seed) {
  if (depth == nullptr || width <= 0 || height <= 0) return;
  const auto at = [&](int u, int v) -> float& { return depth[static_cast<std::ptrdiff_t>(v) * width + u]; };
  // Pass 1: mark both sides of every discontinuity by negating (magnitudes stay comparable).
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      float& a = at(u, v);
      const float za = std::abs(a);
      if (u + 1 < width) {
        float& b = at(u + 1, v);
        const float zb = std::abs(b);
        if (std::abs(za - zb) > options.edge_threshold_rel * std::fmin(za, zb)) {
          a = -za;
          b = -zb;
        }
      }
      if (v + 1 < height) {
        float& b = at(u, v + 1);
        const float zb = std::abs(b);
        if (std::abs(za - zb) > options.edge_threshold_rel * std::fmin(za, zb)) {
          a = -za;
          b = -zb;
        }
      }
    }
  }
  // Pass 2: holes, border, range, noise, quantisation.
  std::uint64_t state = seed ^ 0xD1B54A32D192ED03ull;
  const int border = options.border_px;
  const double metres_per_unit = 1.0 / options.units_per_metre;
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      float& d = at(u, v);
      const std::uint64_t bits = detail::splitmix(state);  // drawn for every pixel: stable streams
      const bool in_band = u < border || v < border || u >= width - border || v >= height - border;
      const double z = d;
      if (in_band || !(z > 0.0) || z < options.min_range_m || z > options.max_range_m) {
        d = 0.f;
        continue;
      }
      const double noisy = z + kinect_depth_sigma_m(z, options) * detail::approx_normal(bits);
      // Round half up by truncation (noisy > 0 here): std::round is a library call without SSE4.1.
      const double units = noisy * options.units_per_metre + 0.5;
      // checked: units in [1, 2^63): a depth of a ray-cast scene times at most 1e6 units per metre.
      d = units >= 1.0 ? static_cast<float>(static_cast<double>(static_cast<std::int64_t>(units)) * metres_per_unit)  // checked: above
                       : 0.f;
    }
  }
}

}  // namespace dyncull::sim
