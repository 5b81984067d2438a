/// @file texture.hpp
/// Procedural, deterministic surface texture for the synthetic scene: two octaves of randomly
/// valued cells in the surface's own coordinates (solid texture), so every junction of cells is a
/// corner for FAST / goodFeaturesToTrack and the pattern moves rigidly with its primitive.
#pragma once

#include "dyncull/core/pixel.hpp"
#include "dyncull/core/types.hpp"

#include <cmath>
#include <cstdint>
#include <limits>

namespace dyncull::sim {

/// 32-bit avalanche hash (murmur3 finaliser) of three cell indices and a seed.
inline std::uint32_t hash_cell(std::int32_t x, std::int32_t y, std::int32_t z, std::uint32_t seed) {
  std::uint32_t h = seed * 0x9E3779B1u;
  h ^= static_cast<std::uint32_t>(x) * 0x85EBCA77u;
  h = (h << 13) | (h >> 19);
  h ^= static_cast<std::uint32_t>(y) * 0xC2B2AE3Du;
  h = (h << 17) | (h >> 15);
  h ^= static_cast<std::uint32_t>(z) * 0x27D4EB2Fu;
  h ^= h >> 16;
  h *= 0x85EBCA6Bu;
  h ^= h >> 13;
  h *= 0xC2B2AE35u;
  h ^= h >> 16;
  return h;
}

/// Uniform value in [0, 1) of the cell containing p (cell edge `cell_m`).
inline double cell_value(const Vec3<double>& p, double cell_m, std::uint32_t seed) {
  const double inv = 1.0 / cell_m;
  // Cells beyond the int range (a point far off, or a tiny cell) share the outermost cell's value.
  constexpr int lo = std::numeric_limits<int>::min(), hi = std::numeric_limits<int>::max();
  const std::int32_t ix = clamped_int(std::floor(p.x() * inv), lo, hi);
  const std::int32_t iy = clamped_int(std::floor(p.y() * inv), lo, hi);
  const std::int32_t iz = clamped_int(std::floor(p.z() * inv), lo, hi);
  return static_cast<double>(hash_cell(ix, iy, iz, seed) >> 8) * (1.0 / 16777216.0);
}

/// Texture intensity in [0.08, 1] at a surface point p (metres, in the primitive's local frame).
/// The fine octave is offset and 0.43x the coarse size, so its junctions fall inside coarse cells
/// (T- and X-junctions of varied contrast, not a regular checkerboard).
inline double texture_value(const Vec3<double>& p, double cell_m, std::uint32_t seed) {
  const double coarse = cell_value(p, cell_m, seed);
  const Vec3<double> offset(0.37 * cell_m, 0.71 * cell_m, 0.53 * cell_m);
  const double fine = cell_value(p + offset, 0.43 * cell_m, seed ^ 0xA511E9B3u);
  return 0.08 + 0.92 * (0.65 * coarse + 0.35 * fine);
}

}  // namespace dyncull::sim
