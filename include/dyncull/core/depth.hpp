/// @file depth.hpp
/// Non-owning view of a depth image: uint16 raw units with a scale (TUM: 5000 per metre) or float
/// metres. "No measurement" is raw 0, a non-finite value, or a depth outside [min_m, max_m];
/// depth_m() returns 0 for all of them, so callers test one thing.
#pragma once

#include "dyncull/core/status.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>

namespace dyncull {

template <class Raw>
struct DepthView {
  static_assert(std::is_same<Raw, std::uint16_t>::value || std::is_same<Raw, float>::value ||
                    std::is_same<Raw, double>::value,
                "DepthView holds uint16 raw depth or float/double metres");
  const Raw* data = nullptr;
  int width = 0;
  int height = 0;
  std::ptrdiff_t stride = 0;    ///< elements (not bytes) between rows; 0 means width
  float units_per_metre = 1.f;  ///< raw units per metre: 5000 for TUM PNGs, 1000 for mm, 1 for metres
  float min_m = 0.f;            ///< valid range; TUM's sensor is reliable in about [0.4, 10] m
  float max_m = 1e30f;

  bool empty() const { return data == nullptr || width <= 0 || height <= 0; }
  /// Raw units per metre a depth sensor can have: from kilometres (1e-3) to micrometres (1e6).
  static constexpr float kMinUnitsPerMetre = 1e-3f, kMaxUnitsPerMetre = 1e6f;

  /// InvalidInput with the field in `reason` when the view cannot be read as documented: negative size,
  /// a stride shorter than a row, units_per_metre not in [1e-3, 1e6], min_m not finite and >= 0, max_m
  /// NaN, not positive or below min_m (no depth could be valid). An empty view (no data) is valid: it
  /// means "no depth image".
  Status validate(std::string* reason = nullptr) const {
    auto bad = [&](const char* why) {
      if (reason) *reason = why;
      return Status::InvalidInput;
    };
    if (width < 0 || height < 0) return bad("depth width and height must be >= 0");
    if (stride < 0 || (stride > 0 && stride < width)) return bad("depth stride must be 0 or at least the width");
    if (!(units_per_metre >= kMinUnitsPerMetre) || !(units_per_metre <= kMaxUnitsPerMetre))
      return bad("depth units_per_metre must be in [1e-3, 1e6] (metres: 1, millimetres: 1000, TUM: 5000)");
    if (!(min_m >= 0.f) || !std::isfinite(min_m)) return bad("depth min_m must be >= 0 and finite");
    if (!(max_m > 0.f)) return bad("depth max_m must be positive (not NaN)");
    if (!(max_m >= min_m)) return bad("depth max_m must be >= min_m");
    if (reason) reason->clear();
    return Status::Ok;
  }
  std::ptrdiff_t row_stride() const { return stride > 0 ? stride : width; }
  const Raw* row(int v) const { return data + static_cast<std::ptrdiff_t>(v) * row_stride(); }
  Raw raw(int u, int v) const { return row(v)[u]; }
  bool in_bounds(int u, int v) const { return u >= 0 && v >= 0 && u < width && v < height; }

  /// Metres at integer pixel (u, v), or 0 for no measurement (also outside the image).
  float depth_m(int u, int v) const {
    if (!in_bounds(u, v)) return 0.f;
    return to_metres(raw(u, v));
  }
  /// Converts a raw value with this view's scale and validity rules.
  float to_metres(Raw r) const {
    const float d = static_cast<float>(r) / units_per_metre;
    return (std::isfinite(d) && d > 0.f && d >= min_m && d <= max_m) ? d : 0.f;
  }
  /// Raw value of a depth in metres (for comparing in raw units inside hot loops).
  double to_raw(double metres) const { return metres * static_cast<double>(units_per_metre); }
};

/// Axial (along the ray) depth noise of a structured-light sensor at z metres, sigma(z) = base +
/// quadratic (z - reference)^2 (Nguyen, Izadi & Lovell 2012, Kinect v1: 0.0012, 0.0019, 0.4 m). Used by
/// the sim to degrade depth and by the reprojection check to judge a depth residual.
template <class T>
T axial_depth_sigma_m(T z, T base = T(0.0012), T quadratic = T(0.0019), T reference = T(0.4)) {
  const T dz = z - reference;
  return base + quadratic * dz * dz;
}

/// True when a pixel within `radius` of (u, v) (sampled every 2 px beyond radius 2; pixels outside the
/// image are not looked at) has no depth or differs from the depth at (u, v) by more than `ratio` of it:
/// (u, v) lies near an occlusion edge or a hole. A centre without depth is not near an edge (nothing to
/// compare with). Used to distrust features whose tracking window straddles an edge.
template <class Raw>
bool depth_step_near(const DepthView<Raw>& depth, int u, int v, int radius, double ratio) {
  const float z = depth.depth_m(u, v);
  if (!(z > 0.f) || radius <= 0) return false;
  const long long step = radius > 2 ? 2 : 1;
  const float tol = static_cast<float>(ratio) * z;
  // The sampled offsets are -radius, -radius + step, ... ; only those inside the image are visited, in
  // 64 bits, so a radius far beyond the image costs one pass over the image at most.
  auto first_inside = [&](long long centre) {
    const long long lo = centre - radius;
    return lo >= 0 ? lo : lo + ((-lo + step - 1) / step) * step;
  };
  const long long y_end = std::min<long long>(static_cast<long long>(v) + radius, depth.height - 1);
  const long long x_end = std::min<long long>(static_cast<long long>(u) + radius, depth.width - 1);
  // Every visited pixel is inside the image: its row is read directly, without depth_m's bounds test (the
  // per-pixel call was not inlined in the culler's library).
  for (long long y = first_inside(v); y <= y_end; y += step) {
    const Raw* row = depth.row(static_cast<int>(y));
    for (long long x = first_inside(u); x <= x_end; x += step) {
      const float zz = depth.to_metres(row[x]);
      if (!(zz > 0.f) || std::abs(zz - z) > tol) return true;
    }
  }
  return false;
}

/// TUM convention: uint16, 5000 units per metre, 0 = no measurement.
inline DepthView<std::uint16_t> tum_depth_view(const std::uint16_t* data, int width, int height,
                                               float min_m = 0.f, float max_m = 1e30f) {
  DepthView<std::uint16_t> v;  // member by member: with its initialisers it is no aggregate in C++11
  v.data = data;
  v.width = width;
  v.height = height;
  v.units_per_metre = 5000.f;
  v.min_m = min_m;
  v.max_m = max_m;
  return v;
}

}  // namespace dyncull
