/// @file keep_mask.hpp
/// Applying a culling decision to a host front end (ORB-SLAM style): keep-masks from labels, in-place
/// compaction of every parallel per-keypoint array together, an "inside a dynamic region" predicate
/// usable per pyramid level inside an extractor, and a rasterised mask with an explicit convention.
///
/// API:
///   std::vector<std::uint8_t> keep = make_keep_mask(labels, KeepPolicy::DropDynamic);
///   CompactResult c = compact_parallel(keep, keypoints, RowsView{desc.data, 32, desc.step, n}, depths, right_u);
///   DynamicRegionPredicate<float> inside(boxes, object_mask, /*scale_factor*/ 1.2f, /*levels*/ 8);
///   inside(x_level, y_level, level) -> bool;
///   rasterise_dynamic_regions(boxes, object_masks, out, MaskConvention::DynamicIs255);
#pragma once

#include "dyncull/core/box.hpp"
#include "dyncull/core/mask.hpp"
#include "dyncull/core/pixel.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/culling/labels.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
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

/// Rows of bytes, `row_bytes` used per row, `stride_bytes` between rows: descriptor matrices
/// (cv::Mat: RowsView{m.data, m.cols * m.elemSize(), m.step, m.rows}). Compaction moves rows up;
/// the host then shrinks its matrix to the returned count (cv::Mat: m = m.rowRange(0, count)).
struct RowsView {
  std::uint8_t* data = nullptr;
  std::size_t row_bytes = 0;
  std::size_t stride_bytes = 0;  ///< 0 means row_bytes
  std::size_t rows = 0;
  std::size_t stride() const { return stride_bytes ? stride_bytes : row_bytes; }
};

struct CompactResult {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }
  std::size_t count = 0;    ///< new number of features
  std::size_t removed = 0;
};

namespace detail {
inline std::size_t array_size(const RowsView& r) { return r.rows; }
template <class V> std::size_t array_size(const std::vector<V>& v) { return v.size(); }

/// Memory an argument of compact_parallel writes, as addresses [begin, end): a vector by its own
/// object (two vector objects never share elements), a RowsView by the bytes its rows span.
struct ByteSpan {
  std::uintptr_t begin = 0, end = 0;
};
template <class V> ByteSpan byte_span(const std::vector<V>& v) {
  const auto p = reinterpret_cast<std::uintptr_t>(&v);
  return ByteSpan{p, p + sizeof(v)};
}
inline ByteSpan byte_span(const RowsView& r) {
  if (r.data == nullptr || r.rows == 0 || r.row_bytes == 0) return ByteSpan{};
  const auto p = reinterpret_cast<std::uintptr_t>(r.data);
  return ByteSpan{p, p + (r.rows - 1) * r.stride() + r.row_bytes};  // bounded by rows_view_ok
}

/// A RowsView compaction can trust: rows reachable (non-null data), not overlapping each other, and
/// the whole span addressable. Vectors always are.
template <class V> bool rows_view_ok(const std::vector<V>&, std::size_t, std::string*) { return true; }
inline bool rows_view_ok(const RowsView& r, std::size_t arg, std::string* reason) {
  const std::string which = "argument " + std::to_string(arg + 1) + " (RowsView): ";
  if (r.rows == 0 || r.row_bytes == 0) return true;  // nothing is moved
  if (r.data == nullptr) {
    *reason = which + "data is null but rows = " + std::to_string(r.rows);
    return false;
  }
  if (r.row_bytes > r.stride()) {
    *reason = which + "row_bytes " + std::to_string(r.row_bytes) + " exceeds stride_bytes " +
              std::to_string(r.stride()) + ": rows would overlap";
    return false;
  }
  const std::uintptr_t room = UINTPTR_MAX - reinterpret_cast<std::uintptr_t>(r.data);
  if (r.row_bytes > room || (r.rows - 1) > (room - r.row_bytes) / r.stride()) {
    *reason = which + "rows * stride_bytes reaches past the address space";
    return false;
  }
  return true;
}

inline void compact_one(const std::vector<std::uint8_t>& keep, RowsView& r, std::size_t count) {
  const std::size_t stride = r.stride();
  std::size_t j = 0;
  for (std::size_t i = 0; i < keep.size(); ++i) {
    if (!keep[i]) continue;
    if (i != j) std::memmove(r.data + j * stride, r.data + i * stride, r.row_bytes);
    ++j;
  }
  r.rows = count;
}
template <class V>
void compact_one(const std::vector<std::uint8_t>& keep, std::vector<V>& v, std::size_t count) {
  std::size_t j = 0;
  for (std::size_t i = 0; i < keep.size(); ++i) {
    if (!keep[i]) continue;
    if (i != j) v[j] = std::move(v[i]);
    ++j;
  }
  v.erase(v.begin() + static_cast<std::ptrdiff_t>(count), v.end());
}
}  // namespace detail

/// Compacts every array (std::vector of anything, or RowsView) in place, stably, keeping element i
/// where keep[i] != 0. All arrays must have keep.size() elements, a RowsView with rows must have
/// non-null data, row_bytes <= stride and a span inside the address space, and no two arguments may
/// share memory (the same vector twice, or overlapping views); otherwise nothing is touched, status is
/// InvalidInput, count = keep.size() and removed = 0. RowsView arguments may be temporaries: their
/// rows field is not needed back.
template <class... Arrays>
CompactResult compact_parallel(const std::vector<std::uint8_t>& keep, Arrays&&... arrays) {
  CompactResult r;
  const std::size_t n = keep.size();
  r.count = n;
  const bool sizes_ok = ((detail::array_size(arrays) == n) && ... && true);
  if (!sizes_ok) {
    r.status = Status::InvalidInput;
    r.reason = "every parallel array must have keep.size() = " + std::to_string(n) + " elements";
    return r;
  }
  constexpr std::size_t kArrays = sizeof...(Arrays);
  if constexpr (kArrays > 0) {
    std::size_t arg = 0;
    const bool views_ok = (detail::rows_view_ok(arrays, arg++, &r.reason) && ...);
    if (!views_ok) {
      r.status = Status::InvalidInput;
      return r;
    }
    const detail::ByteSpan spans[kArrays] = {detail::byte_span(arrays)...};
    for (std::size_t a = 0; a < kArrays; ++a) {
      for (std::size_t b = a + 1; b < kArrays; ++b) {
        if (spans[a].begin < spans[b].end && spans[b].begin < spans[a].end) {
          r.status = Status::InvalidInput;
          r.reason = "arguments " + std::to_string(a + 1) + " and " + std::to_string(b + 1) +
                     " share memory (the same array twice, or overlapping RowsViews)";
          return r;
        }
      }
    }
  }
  std::size_t count = 0;
  for (std::uint8_t k : keep) count += k != 0;
  (detail::compact_one(keep, arrays, count), ...);
  r.count = count;
  r.removed = n - count;
  return r;
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
