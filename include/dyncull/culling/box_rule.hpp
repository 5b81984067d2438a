/// @file box_rule.hpp
/// Semantic box rule (Zhu et al. 2024 Table 2, Zhang et al. 2023 Algorithm 1): a feature is dynamic only if it lies in a
/// high-level box and in no low-level box; medium-level boxes give candidates (RTD-SLAM §III.D).
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
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace dyncull {

template <class T>
struct BoxRuleOptions {
  /// Features in a medium-level box (and no low/high box) become Candidate; false: Static.
  bool medium_as_candidate = true;

  /// Ok: every value is valid (the nested validate() of PipelineOptions).
  Status validate(std::string* reason = nullptr) const {
    if (reason) reason->clear();
    return Status::Ok;
  }
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

constexpr std::uint8_t kInHigh = 1, kInMedium = 2, kInLow = 4, kNonFinite = 8;

/// flags[i] |= bit when point i lies in the box: branch-free over structure-of-arrays points,
/// bounds in locals so the store to flags cannot alias them (g++ would reload them per point).
template <class T>
void mark_points_in_box(const T* xs, const T* ys, std::size_t begin, std::size_t n, const Box<T>& box,
                        std::uint8_t bit, std::uint8_t* flags) {
  const T bx0 = box.x0, by0 = box.y0, bx1 = box.x1, by1 = box.y1;
  for (std::size_t i = begin; i < n; ++i) {
    const unsigned inside =
        unsigned(xs[i] >= bx0) & unsigned(xs[i] <= bx1) & unsigned(ys[i] >= by0) & unsigned(ys[i] <= by1);
    flags[i] = static_cast<std::uint8_t>(flags[i] | (inside * bit));
  }
}

/// All boxes at once. For float, explicit SSE2 over blocks of 16 points with the flags kept in a
/// register (g++ -O2 does not vectorise the plain loop); the rest, and double, use the plain loop.
template <class T>
void mark_points(const T* xs, const T* ys, std::size_t n, const std::vector<Box<T>>& boxes,
                 const std::vector<std::uint8_t>& bits, std::uint8_t* flags) {
  std::size_t done = 0;
#if defined(__SSE2__)
  if constexpr (std::is_same<T, float>::value) {
    for (; done + 16 <= n; done += 16) {
      __m128 x[4], y[4];
      for (int k = 0; k < 4; ++k) {
        x[k] = _mm_loadu_ps(xs + done + 4 * k);
        y[k] = _mm_loadu_ps(ys + done + 4 * k);
      }
      // Start from the flags already set (kNonFinite): the kernel only ORs membership bits in.
      __m128i acc = _mm_loadu_si128(reinterpret_cast<const __m128i*>(flags + done));
      for (std::size_t b = 0; b < boxes.size(); ++b) {
        const __m128 x0 = _mm_set1_ps(boxes[b].x0), x1 = _mm_set1_ps(boxes[b].x1);
        const __m128 y0 = _mm_set1_ps(boxes[b].y0), y1 = _mm_set1_ps(boxes[b].y1);
        __m128i c[4];
        for (int k = 0; k < 4; ++k)
          c[k] = _mm_castps_si128(_mm_and_ps(_mm_and_ps(_mm_cmpge_ps(x[k], x0), _mm_cmple_ps(x[k], x1)),
                                             _mm_and_ps(_mm_cmpge_ps(y[k], y0), _mm_cmple_ps(y[k], y1))));
        const __m128i m = _mm_packs_epi16(_mm_packs_epi32(c[0], c[1]), _mm_packs_epi32(c[2], c[3]));
        acc = _mm_or_si128(acc, _mm_and_si128(m, _mm_set1_epi8(static_cast<char>(bits[b]))));
      }
      _mm_storeu_si128(reinterpret_cast<__m128i*>(flags + done), acc);
    }
  }
#endif
  for (std::size_t b = 0; b < boxes.size(); ++b) mark_points_in_box(xs, ys, done, n, boxes[b], bits[b], flags);
}
}  // namespace detail

/// Scratch of apply_box_rule kept by a caller that runs it every frame (no allocation once warm).
template <class T>
struct BoxRuleScratch {
  std::vector<Box<T>> boxes;          ///< effective boxes (padded / shrunk)
  std::vector<std::uint8_t> bits;     ///< level bit of each effective box
  std::vector<std::int32_t> source;   ///< detection index of each effective box
  std::vector<T> xs, ys;              ///< points as structure of arrays
  std::vector<std::uint8_t> flags;    ///< membership and non-finite bits per point
};

namespace detail {

/// The boxes the rule tests, as detected, with their level bit and detection index; Ignore-level classes
/// left out. Returns the boxes skipped as invalid.
template <class Dets, class T>
std::size_t effective_boxes(const Dets& detections, const MotionLevelTable& levels, BoxRuleScratch<T>* scratch,
                            BoxRuleResult<T>* r) {
  std::vector<Box<T>>& boxes = scratch->boxes;
  boxes.clear();
  scratch->bits.clear();
  scratch->source.clear();
  boxes.reserve(detections.size());
  std::size_t skipped = 0;
  for (std::size_t b = 0; b < detections.size(); ++b) {
    const Detection<T>& d = detections[b];
    const MotionLevel level = levels.level(d.class_id);
    if (level == MotionLevel::Ignore) continue;
    if (!d.box.valid()) {
      ++skipped;
      continue;
    }
    std::uint8_t bit = kInMedium;
    if (level == MotionLevel::High) {
      bit = kInHigh;
      ++r->num_high_boxes;
    } else if (level == MotionLevel::Low) {
      bit = kInLow;
      ++r->num_low_boxes;
    } else {
      ++r->num_medium_boxes;
    }
    boxes.push_back(d.box);
    scratch->bits.push_back(bit);
    scratch->source.push_back(static_cast<std::int32_t>(b));
  }
  return skipped;
}

/// Zhang et al. 2023, Algorithm 1 as a table over the membership bits (high, medium, low) and the
/// non-finite bit: high -> dynamic unless also low; medium -> candidate with medium_as_candidate unless
/// also low (a low-level box shelters both, Zhu et al. 2024 Table 2); a non-finite point is never static.
template <class T>
void box_rule_table(const BoxRuleOptions<T>& options, FeatureLabel label_of[16], CullReason reason_of[16]) {
  for (unsigned f = 0; f < 16; ++f) {
    const bool high = f & kInHigh, medium = f & kInMedium, low = f & kInLow;
    label_of[f] = FeatureLabel::Static;
    reason_of[f] = CullReason::None;
    if (f & kNonFinite) {  // never trusted as static
      label_of[f] = FeatureLabel::Dynamic;
      reason_of[f] = CullReason::InvalidInput;
    } else if (high) {
      if (low) {
        reason_of[f] = CullReason::LowLevelOverride;
      } else {
        label_of[f] = FeatureLabel::Dynamic;
        reason_of[f] = CullReason::HighLevelBox;
      }
    } else if (medium) {
      if (low) {
        reason_of[f] = CullReason::LowLevelOverride;
      } else if (options.medium_as_candidate) {
        label_of[f] = FeatureLabel::Candidate;
        reason_of[f] = CullReason::MediumLevelBox;
      }
    }
  }
}

/// Labels every point by its bits through the table, and names the deciding box (the first high one,
/// else the first medium one) of a boxed point.
template <class T>
void label_by_table(std::size_t n, const FeatureLabel label_of[16], const CullReason reason_of[16],
                    const BoxRuleScratch<T>& scratch, BoxRuleResult<T>* out) {
  BoxRuleResult<T>& r = *out;
  // Counters in locals: stores through `r` would alias the label stores and serialise the loop.
  std::size_t num_dynamic = 0, num_candidate = 0, num_override = 0, num_bad = 0;
  FeatureLabel* labels = r.labels.data();
  CullReason* reasons = r.reasons.data();
  const std::uint8_t* flags = scratch.flags.data();
  const T* xs = scratch.xs.data();
  const T* ys = scratch.ys.data();
  const Box<T>* boxes = scratch.boxes.data();
  const std::uint8_t* bits = scratch.bits.data();
  const std::size_t num_boxes = scratch.boxes.size();
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t f = flags[i];
    const FeatureLabel label = label_of[f];
    const CullReason reason = reason_of[f];
    labels[i] = label;
    reasons[i] = reason;
    num_bad += (f & kNonFinite) != 0;
    num_override += reason == CullReason::LowLevelOverride;
    num_dynamic += label == FeatureLabel::Dynamic;
    num_candidate += label == FeatureLabel::Candidate;
    if (f & (kInHigh | kInMedium)) {
      // Few points are boxed: find the deciding box directly.
      const std::uint8_t want = (f & kInHigh) ? kInHigh : kInMedium;
      for (std::size_t b = 0; b < num_boxes; ++b) {
        if (bits[b] == want && boxes[b].contains(xs[i], ys[i])) {
          r.box_index[i] = scratch.source[b];
          break;
        }
      }
    }
  }
  r.num_dynamic = num_dynamic;
  r.num_candidate = num_candidate;
  r.num_low_override = num_override;
  r.num_non_finite = num_bad;
  r.num_static = n - r.num_dynamic - r.num_candidate;
}

}  // namespace detail

/// Applies the box rule to every point, writing into `*out` and reusing its and `*scratch`'s
/// buffers. Boxes of Ignore-level classes take no part; invalid (non-finite or inverted) boxes are
/// skipped and counted in `reason`. Options
/// failing BoxRuleOptions::validate give InvalidInput with every point Static (None): nothing is decided.
template <class Points, class Dets, class T>
void apply_box_rule(const Points& points, const Dets& detections, const MotionLevelTable& levels,
                    const BoxRuleOptions<T>& options, BoxRuleResult<T>* out, BoxRuleScratch<T>* scratch) {
  static_assert(is_point_container_v<Points>, "apply_box_rule: points must be a container of points");
  BoxRuleResult<T>& r = *out;
  r.status = Status::Ok;
  r.num_static = r.num_candidate = r.num_dynamic = r.num_low_override = r.num_non_finite = 0;
  r.num_high_boxes = r.num_medium_boxes = r.num_low_boxes = 0;
  const std::size_t n = points.size();
  r.labels.assign(n, FeatureLabel::Static);
  r.reasons.assign(n, CullReason::None);
  r.box_index.assign(n, -1);
  if (options.validate(&r.reason) != Status::Ok) {
    r.status = Status::InvalidInput;
    r.num_static = n;
    return;
  }
  const std::size_t skipped = detail::effective_boxes(detections, levels, scratch, &r);
  if (skipped) {
    r.reason.assign(std::to_string(skipped));
    r.reason += " invalid box(es) skipped";
  }
  // NaN / Inf coordinates compare false against every finite bound: never inside a box; they are
  // flagged here (x * 0 is NaN only for non-finite x) and labelled by the decision table.
  // Scratch arrays are left uninitialised: every element is written before it is read.
  scratch->xs.resize(n);
  scratch->ys.resize(n);
  scratch->flags.resize(n);
  T* const xs = scratch->xs.data();  // raw pointers: byte stores through the vectors would alias them
  T* const ys = scratch->ys.data();
  std::uint8_t* const flags = scratch->flags.data();
  for (std::size_t i = 0; i < n; ++i) {
    const T x = point_x<T>(points[i]), y = point_y<T>(points[i]);
    xs[i] = x;
    ys[i] = y;
    flags[i] = (x * T(0) + y * T(0) == T(0)) ? std::uint8_t(0) : detail::kNonFinite;
  }
  detail::mark_points(xs, ys, n, scratch->boxes, scratch->bits, flags);
  FeatureLabel label_of[16];
  CullReason reason_of[16];
  detail::box_rule_table(options, label_of, reason_of);
  detail::label_by_table(n, label_of, reason_of, *scratch, &r);
}

/// The same rule returning a fresh result (allocates; apply_box_rule with an out-parameter reuses buffers).
template <class Points, class Dets, class T = detail::detection_scalar_t<Dets>>
BoxRuleResult<T> apply_box_rule(const Points& points, const Dets& detections, const MotionLevelTable& levels,
                                const BoxRuleOptions<T>& options = {}) {
  BoxRuleResult<T> r;
  BoxRuleScratch<T> scratch;
  apply_box_rule(points, detections, levels, options, &r, &scratch);
  return r;
}

}  // namespace dyncull
