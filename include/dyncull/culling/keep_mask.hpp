/// @file keep_mask.hpp
/// Applying a culling decision to a host front end (ORB-SLAM style): keep-masks from labels (the parallel
/// arrays are then compacted by dyncull::compact, core/compact.hpp), an "inside a dynamic region" predicate
/// usable per pyramid level inside an extractor, and a rasterised mask with an explicit convention.
///
/// API:
///   std::vector<std::uint8_t> keep = make_keep_mask(labels, KeepPolicy::DropDynamic);
///   long kept = compact(keep, keypoints, RowsView(desc.data, 32, desc.step, n), depths, right_u);
///   DynamicRegionPredicate<float> inside(boxes, object_mask, /*scale_factor*/ 1.2f, /*levels*/ 8);
///   inside(x_level, y_level, level) -> bool;
///   rasterise_dynamic_regions(boxes, object_masks, out, MaskConvention::DynamicIs255);
#pragma once

#include "dyncull/core/box.hpp"
#include "dyncull/core/compact.hpp"
#include "dyncull/core/mask.hpp"
#include "dyncull/core/pixel.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/culling/labels.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <utility>
#include <vector>

namespace dyncull {

/// Which labels are dropped.
enum class KeepPolicy : std::uint8_t {
  DropDynamic = 0,             ///< keep Static and Candidate (candidates await geometric verification)
  DropDynamicAndCandidate = 1, ///< keep Static only
};

/// keep[i] = 1 when feature i survives.
inline std::vector<std::uint8_t> make_keep_mask(const std::vector<FeatureLabel>& labels,
                                                KeepPolicy policy = KeepPolicy::DropDynamic) {
  std::vector<std::uint8_t> keep(labels.size());
  const auto limit = static_cast<std::uint8_t>(policy == KeepPolicy::DropDynamic ? FeatureLabel::Candidate
                                                                                 : FeatureLabel::Static);
  for (std::size_t i = 0; i < labels.size(); ++i) keep[i] = static_cast<std::uint8_t>(labels[i]) <= limit;
  return keep;
}

/// "Is (x, y) inside a dynamic region?" for use inside a feature extractor, before the keypoints
/// are distributed (the budget then goes to static areas). Coordinates at pyramid level l map to
/// level 0 by multiplying with scale_factor^l (ORB-SLAM's mvScaleFactor). Regions: boxes (level-0
/// pixels) and/or an object mask (non-zero = dynamic, level-0 size). A point is inside when it
/// lies in any box, or on a set mask pixel. When both are given and `mask_refines_boxes` is true,
/// a point must be in a box AND on the mask (the mask refines the boxes).
template <class T>
class DynamicRegionPredicate {
 public:
  static constexpr int kMaxTabulatedLevels = 64;

  DynamicRegionPredicate() = default;
  DynamicRegionPredicate(const std::vector<Box<T>>& boxes, ConstMaskView mask = {}, T scale_factor = T(1),
                         int num_levels = 1, bool mask_refines_boxes = false)
      : mask_(mask), refine_(mask_refines_boxes) {
    for (const Box<T>& b : boxes) {
      if (!b.valid()) continue;
      x0_.push_back(b.x0);
      y0_.push_back(b.y0);
      x1_.push_back(b.x1);
      y1_.push_back(b.y1);
    }
    set_pyramid(scale_factor, num_levels);
  }

  /// A non-finite or non-positive scale factor counts as 1. At most kMaxTabulatedLevels scales are
  /// tabulated (ORB-SLAM uses 8); deeper levels are computed with pow().
  void set_pyramid(T scale_factor, int num_levels) {
    factor_ = scale_factor > T(0) && std::isfinite(scale_factor) ? scale_factor : T(1);
    const int levels = num_levels < 1 ? 1 : (num_levels > kMaxTabulatedLevels ? kMaxTabulatedLevels : num_levels);
    scales_.assign(static_cast<std::size_t>(levels), T(1));
    for (std::size_t l = 1; l < scales_.size(); ++l) scales_[l] = scales_[l - 1] * factor_;
  }

  /// (x, y) at level 0.
  bool operator()(T x, T y) const { return inside_level0(x, y); }
  /// (x, y) in the coordinates of pyramid level `level` (maps to level 0 by scale_factor^level).
  bool operator()(T x, T y, int level) const {
    const T s = level <= 0 ? T(1)
                           : (static_cast<std::size_t>(level) < scales_.size() ? scales_[static_cast<std::size_t>(level)]
                                                                               : std::pow(factor_, T(level)));
    return inside_level0(x * s, y * s);
  }
  bool empty() const { return x0_.empty() && mask_.empty(); }
  std::size_t num_boxes() const { return x0_.size(); }

 private:
  bool in_boxes(T x, T y) const {
    unsigned in = 0;
    const std::size_t n = x0_.size();
    for (std::size_t b = 0; b < n; ++b)
      in |= unsigned(x >= x0_[b]) & unsigned(x <= x1_[b]) & unsigned(y >= y0_[b]) & unsigned(y <= y1_[b]);
    return in != 0;
  }
  bool on_mask(T x, T y) const {
    int u = 0, v = 0;
    return !mask_.empty() && pixel_of(x, y, mask_.width, mask_.height, &u, &v) && mask_.test(u, v);
  }
  bool inside_level0(T x, T y) const {
    if (!std::isfinite(x) || !std::isfinite(y)) return true;  // never trust a NaN position as static
    const bool boxes = in_boxes(x, y);
    if (refine_ && !x0_.empty() && !mask_.empty()) return boxes && on_mask(x, y);
    return boxes || on_mask(x, y);
  }

  std::vector<T> x0_, y0_, x1_, y1_;
  ConstMaskView mask_;
  bool refine_ = false;
  std::vector<T> scales_{T(1)};
  T factor_ = T(1);
};

/// Which value marks the dynamic pixels in a rasterised mask. DynamicIs255 is dyncull's own
/// convention (non-zero = dynamic); StaticIs255 is what OpenCV detectors take as `mask`
/// (non-zero = detect here), e.g. cv::ORB::detect(image, keypoints, mask).
enum class MaskConvention : std::uint8_t { DynamicIs255 = 0, StaticIs255 = 1 };

/// Writes the whole of `out`: dynamic pixels = pixels whose centre lies in a box, or that are set
/// in `object_mask` (same size as out, optional). The mask is first cleared to the static value.
template <class T>
Status rasterise_dynamic_regions(const std::vector<Box<T>>& boxes, ConstMaskView object_mask, MaskView out,
                                 MaskConvention convention = MaskConvention::DynamicIs255) {
  if (out.empty()) return Status::InvalidInput;
  if (!object_mask.empty() && (object_mask.width != out.width || object_mask.height != out.height))
    return Status::InvalidInput;
  const std::uint8_t dyn = convention == MaskConvention::DynamicIs255 ? 255 : 0;
  const std::uint8_t stat = static_cast<std::uint8_t>(255 - dyn);
  const int w = out.width, h = out.height;
  for (int v = 0; v < h; ++v) {
    std::uint8_t* o = out.row(v);
    if (object_mask.empty()) {
      std::memset(o, stat, static_cast<std::size_t>(w));
    } else {
      const std::uint8_t* m = object_mask.row(v);
      for (int u = 0; u < w; ++u) o[u] = m[u] ? dyn : stat;
    }
  }
  for (const Box<T>& b : boxes) {
    const PixelRect r = pixel_rect(b, w, h);
    for (int v = r.r0; v < r.r1; ++v) std::memset(out.row(v) + r.c0, dyn, static_cast<std::size_t>(r.width()));
  }
  return Status::Ok;
}

}  // namespace dyncull
