/// @file box_rule.hpp
/// Semantic box rule (002 Table 2, 004 Algorithm 1): a feature is dynamic only if it lies in a
/// high-level box and in no low-level box; medium-level boxes give candidates (001 §III.D).
///
/// API (for the pipeline):
///   BoxRuleResult r = apply_box_rule(points, detections, MotionLevelTable::coco80(), BoxRuleOptions<T>{});
///   r.labels[i] (Static / Candidate / Dynamic), r.reasons[i], r.box_index[i] (deciding box or -1), counts.
/// Points: any container with size() and operator[] of PointTraits points (level-0 pixels).
#pragma once

#include "dyncull/core/box.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/core/traits.hpp"
#include "dyncull/culling/labels.hpp"
#include "dyncull/culling/motion_levels.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace dyncull {

template <class T>
struct BoxRuleOptions {
  /// Extra growth of high-level boxes in pixels (padding usually already applied by detections.hpp).
  T high_padding_px = T(0);
  /// Shrink of low-level boxes in pixels before the override test: a tv box drawn a little too
  /// large must not shelter a person's edge (CDS-SLAM's abandoned rule used 5 px).
  T low_shrink_px = T(0);
  /// Features in a medium-level box (and no low/high box) become Candidate; false: Static.
  bool medium_as_candidate = true;
  /// 001 §III.D sends every boxed feature to geometric verification: when true, features in a
  /// high-level box become Candidate instead of Dynamic.
  bool high_as_candidate = false;
  /// Whether a low-level box also shelters medium-level features (consistent with 002 Table 2).
  bool low_overrides_medium = true;
};

template <class T>
struct BoxRuleResult {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }
  std::vector<FeatureLabel> labels;   ///< one per point
  std::vector<CullReason> reasons;    ///< one per point
  std::vector<std::int32_t> box_index;///< first high (else medium) box containing the point, -1 if none
  std::size_t num_static = 0, num_candidate = 0, num_dynamic = 0;
  std::size_t num_low_override = 0;   ///< in a high/medium box but sheltered by a low box
  std::size_t num_non_finite = 0;     ///< points with NaN/Inf coordinates (labelled Dynamic, never trusted)
  std::size_t num_high_boxes = 0, num_medium_boxes = 0, num_low_boxes = 0;
};

namespace detail {
/// Scalar of a container of Detection<T>.
template <class Dets>
using detection_scalar_t = std::decay_t<decltype(std::declval<const Dets&>()[std::size_t{0}].box.x0)>;

/// Boxes of one level as structure-of-arrays, so the point loop is branch-free and vectorises.
template <class T>
struct BoxSoA {
  std::vector<T> x0, y0, x1, y1;
  std::vector<std::int32_t> index;
  void push(const Box<T>& b, std::int32_t i) {
    x0.push_back(b.x0);
    y0.push_back(b.y0);
    x1.push_back(b.x1);
    y1.push_back(b.y1);
    index.push_back(i);
  }
  std::size_t size() const { return x0.size(); }
};

/// in[i] |= point i lies in any box; first[i] = index of the first containing box (kept if none).
template <class T>
void points_in_boxes(const T* xs, const T* ys, std::size_t n, const BoxSoA<T>& boxes, std::uint8_t* in,
                     std::int32_t* first) {
  // Reverse order so the lowest-index box wins the select without a branch.
  for (std::size_t b = boxes.size(); b-- > 0;) {
    const T bx0 = boxes.x0[b], by0 = boxes.y0[b], bx1 = boxes.x1[b], by1 = boxes.y1[b];
    const std::int32_t id = boxes.index[b];
    for (std::size_t i = 0; i < n; ++i) {
      const unsigned inside =
          unsigned(xs[i] >= bx0) & unsigned(xs[i] <= bx1) & unsigned(ys[i] >= by0) & unsigned(ys[i] <= by1);
      in[i] = static_cast<std::uint8_t>(in[i] | static_cast<std::uint8_t>(inside));
      if (first) first[i] = inside != 0 ? id : first[i];
    }
  }
}
}  // namespace detail

/// Applies the box rule to every point. Boxes of Ignore-level classes take no part; invalid
/// (non-finite or inverted) boxes are skipped and counted in `reason`.
template <class Points, class Dets, class T = detail::detection_scalar_t<Dets>>
BoxRuleResult<T> apply_box_rule(const Points& points, const Dets& detections, const MotionLevelTable& levels,
                                const BoxRuleOptions<T>& options = {}) {
  static_assert(is_point_container_v<Points>, "apply_box_rule: points must be a container of points");
  BoxRuleResult<T> r;
  const std::size_t n = points.size();
  r.labels.assign(n, FeatureLabel::Static);
  r.reasons.assign(n, CullReason::None);
  r.box_index.assign(n, -1);

  detail::BoxSoA<T> high, medium, low;
  std::size_t skipped = 0;
  for (std::size_t b = 0; b < detections.size(); ++b) {
    const Detection<T>& d = detections[b];
    const MotionLevel level = levels.level(d.class_id);
    if (level == MotionLevel::Ignore) continue;
    if (!d.box.valid()) {
      ++skipped;
      continue;
    }
    const auto id = static_cast<std::int32_t>(b);
    if (level == MotionLevel::High) high.push(d.box.padded(options.high_padding_px), id);
    else if (level == MotionLevel::Medium) medium.push(d.box, id);
    else {
      const Box<T> s = d.box.padded(-options.low_shrink_px);
      if (s.valid()) low.push(s, id);
    }
  }
  r.num_high_boxes = high.size();
  r.num_medium_boxes = medium.size();
  r.num_low_boxes = low.size();
  if (skipped) r.reason = std::to_string(skipped) + " invalid box(es) skipped";

  std::vector<T> xs(n), ys(n);
  std::vector<std::uint8_t> in_high(n, 0), in_medium(n, 0), in_low(n, 0), bad(n, 0);
  std::vector<std::int32_t> medium_index(n, -1);
  for (std::size_t i = 0; i < n; ++i) {
    const T x = point_x<T>(points[i]), y = point_y<T>(points[i]);
    const bool finite = std::isfinite(x) && std::isfinite(y);
    bad[i] = static_cast<std::uint8_t>(!finite);
    // Non-finite points are parked far outside every box; their label is set below.
    xs[i] = finite ? x : T(-1e30);
    ys[i] = finite ? y : T(-1e30);
  }
  detail::points_in_boxes(xs.data(), ys.data(), n, high, in_high.data(), r.box_index.data());
  detail::points_in_boxes(xs.data(), ys.data(), n, medium, in_medium.data(), medium_index.data());
  detail::points_in_boxes<T>(xs.data(), ys.data(), n, low, in_low.data(), nullptr);

  const FeatureLabel high_label = options.high_as_candidate ? FeatureLabel::Candidate : FeatureLabel::Dynamic;
  for (std::size_t i = 0; i < n; ++i) {
    if (bad[i]) {
      r.labels[i] = FeatureLabel::Dynamic;
      r.reasons[i] = CullReason::InvalidInput;
      ++r.num_non_finite;
    } else if (in_high[i]) {
      if (in_low[i]) {
        r.reasons[i] = CullReason::LowLevelOverride;
        ++r.num_low_override;
      } else {
        r.labels[i] = high_label;
        r.reasons[i] = CullReason::HighLevelBox;
      }
    } else if (in_medium[i]) {
      r.box_index[i] = medium_index[i];
      if (in_low[i] && options.low_overrides_medium) {
        r.reasons[i] = CullReason::LowLevelOverride;
        ++r.num_low_override;
      } else if (options.medium_as_candidate) {
        r.labels[i] = FeatureLabel::Candidate;
        r.reasons[i] = CullReason::MediumLevelBox;
      }
    }
    r.num_dynamic += r.labels[i] == FeatureLabel::Dynamic;
    r.num_candidate += r.labels[i] == FeatureLabel::Candidate;
  }
  r.num_static = n - r.num_dynamic - r.num_candidate;
  return r;
}

}  // namespace dyncull
