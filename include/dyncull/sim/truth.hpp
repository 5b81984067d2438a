/// @file truth.hpp
/// Ground truth of a rendered synthetic frame at arbitrary sub-pixel keypoints (nearest pixel):
/// whether the surface moves in the world and which instance it belongs to, for scoring culling.
#pragma once

#include "dyncull/core/pixel.hpp"
#include "dyncull/core/traits.hpp"
#include "dyncull/sim/scene.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace dyncull::sim {

/// Truth at one keypoint. Outside the image (or a non-finite position): inside = false, the rest zero.
struct PointTruth {
  bool inside = false;
  std::uint8_t moving = 0;     ///< 1 when the surface under the nearest pixel moves in the world
  std::uint16_t instance = 0;  ///< instance id (0 = static background/furniture)
  float depth_m = 0.f;         ///< the frame's depth at the pixel (0 = no measurement)
};

/// Truth at sub-pixel (x, y): the pixel whose centre is nearest, i.e. (round(x), round(y)) as pixel_of.
inline PointTruth truth_at(const FrameData& frame, double x, double y) {
  PointTruth t;
  int u = 0, v = 0;
  // Range-checked in floating point before any conversion: a coordinate beyond the integer range
  // never wraps back into the image.
  if (!pixel_of(x, y, frame.width, frame.height, &u, &v)) return t;
  const auto i = static_cast<std::size_t>(v) * static_cast<std::size_t>(frame.width) + static_cast<std::size_t>(u);
  if (i >= frame.instance.size() || i >= frame.moving.size() || i >= frame.depth_m.size()) return t;
  t.inside = true;
  t.moving = frame.moving[i];
  t.instance = frame.instance[i];
  t.depth_m = frame.depth_m[i];
  return t;
}

/// Batch truth for any point container (Eigen vectors, cv::Point2f, cv::KeyPoint, ...): fills
/// `moving` and `instance` (resized to points.size(); optional, pass nullptr to skip). Points
/// outside the image get moving = 0 and instance = 0. Returns how many points were inside.
template <class Points>
std::size_t truth_at_points(const FrameData& frame, const Points& points, std::vector<std::uint8_t>* moving,
                            std::vector<std::uint16_t>* instance = nullptr) {
  const std::size_t n = points.size();
  if (moving) moving->assign(n, 0);
  if (instance) instance->assign(n, 0);
  std::size_t inside = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const PointTruth t = truth_at(frame, point_x<double>(points[k]), point_y<double>(points[k]));
    if (!t.inside) continue;
    ++inside;
    if (moving) (*moving)[k] = t.moving;
    if (instance) (*instance)[k] = t.instance;
  }
  return inside;
}

}  // namespace dyncull::sim
