/// @file multiview_check.hpp
/// Multi-view depth check (RTD-SLAM, Gao et al. 2024, §III.A, after DynaSLAM): keyframe keypoints are
/// back-projected with their depth, moved by the relative pose and projected; d_proj - d' > tau_d marks a
/// moving surface at x'.
#pragma once

#include "dyncull/core/box.hpp"
#include "dyncull/core/camera.hpp"
#include "dyncull/core/depth.hpp"
#include "dyncull/core/flags.hpp"
#include "dyncull/core/mask.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/core/traits.hpp"
#include "dyncull/core/types.hpp"
#include "dyncull/culling/labels.hpp"
#include "dyncull/culling/validation.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace dyncull {

/// Options of the multi-view check. Defaults follow RTD-SLAM (30 deg, 0.4 m) and DynaSLAM's code
/// for what the paper leaves out (depth gates 6 m / 7 m, region growing 0.2 m).
template <class T>
struct MultiViewOptions {
  T max_parallax_deg = T(30);        ///< skip points whose viewing rays differ more (occlusion, not motion)
  T depth_threshold_m = T(0.4);      ///< tau_d of RTD-SLAM (DynaSLAM's code uses 0.6)
  int search_radius_px = 2;          ///< d' is the valid depth closest to d_proj in a (2r+1)^2 window (DynaSLAM: 20)
  T max_reference_depth_m = T(6);    ///< keyframe keypoints deeper than this are not used (DynaSLAM)
  static constexpr double kMaxProjectedDepthM = 7;  ///< projections deeper than this are not used (DynaSLAM)
  T border_px = T(0);                ///< projections closer than this to the image edge are not used
  /// Region growing: |d - d_seed| below this joins the region (DynaSLAM's code).
  static constexpr double kRegionDepthToleranceM = 0.2;

  /// InvalidInput naming the first field out of its range: max_parallax_deg in (0, 180];
  /// depth_threshold_m > 0; search_radius_px in [0, 256]; max_reference_depth_m > 0 (not NaN; +Inf = no
  /// gate); border_px finite and >= 0.
  Status validate(std::string* reason = nullptr) const {
    using detail::finite_in;
    using detail::invalid_option;
    if (!(max_parallax_deg > T(0)) || !finite_in(max_parallax_deg, 0, 180))
      return invalid_option(reason, "max_parallax_deg", "must be in (0, 180]");
    if (!(depth_threshold_m > T(0)) || !std::isfinite(depth_threshold_m))
      return invalid_option(reason, "depth_threshold_m", "must be positive and finite");
    if (search_radius_px < 0 || search_radius_px > 256)
      return invalid_option(reason, "search_radius_px", "must be in [0, 256]");
    if (!(max_reference_depth_m > T(0))) return invalid_option(reason, "max_reference_depth_m", "must be positive");
    if (!finite_in(border_px, 0, 1e9)) return invalid_option(reason, "border_px", "must be finite and >= 0");
    if (reason) reason->clear();
    return Status::Ok;
  }
};

/// What happened to one keyframe point.
enum class MultiViewOutcome : std::uint8_t {
  Checked = 0,         ///< compared; label is Static or Dynamic
  NoReferenceDepth,    ///< keyframe depth missing, non-positive or above max_reference_depth_m
  BehindCamera,        ///< projects behind the current camera or beyond kMaxProjectedDepthM
  OutsideImage,        ///< projects outside the current image (or inside the border)
  LargeParallax,       ///< viewing rays differ by more than max_parallax_deg: skipped
  NoMeasuredDepth,     ///< no valid current depth around x'
  NonFinite,           ///< NaN / Inf coordinates
};

constexpr const char* to_string(MultiViewOutcome o) noexcept {
  switch (o) {
    case MultiViewOutcome::Checked: return "checked";
    case MultiViewOutcome::NoReferenceDepth: return "no reference depth";
    case MultiViewOutcome::BehindCamera: return "behind camera or too deep";
    case MultiViewOutcome::OutsideImage: return "outside image";
    case MultiViewOutcome::LargeParallax: return "large parallax";
    case MultiViewOutcome::NoMeasuredDepth: return "no measured depth";
    case MultiViewOutcome::NonFinite: return "non-finite";
  }
  return "unknown";
}

/// Per keyframe point results (parallel to the keyframe's points) and counts.
/// labels: Dynamic when d_proj - d' > tau_d, Static when checked and not, Candidate when not checked.
template <class T>
struct MultiViewResult {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }

  std::vector<FeatureLabel> labels;
  std::vector<MultiViewOutcome> outcome;
  std::vector<Vec2<T>> projected;     ///< x' in the current image (undefined unless projected)
  std::vector<T> projected_depth_m;   ///< d_proj
  std::vector<T> measured_depth_m;    ///< d' (0 when none)
  std::size_t num_points = 0, num_checked = 0, num_dynamic = 0;
  std::size_t num_large_parallax = 0, num_no_depth = 0, num_outside = 0;
};

namespace detail {

template <class Raw, class T>
T closest_depth_in_window(const DepthView<Raw>& depth, int u, int v, int radius, T target) {
  T best = T(0), best_diff = std::numeric_limits<T>::infinity();
  const int v0 = std::max(0, v - radius), v1 = std::min(depth.height - 1, v + radius);
  const int u0 = std::max(0, u - radius), u1 = std::min(depth.width - 1, u + radius);
  for (int y = v0; y <= v1; ++y) {
    const Raw* row = depth.row(y);
    for (int x = u0; x <= u1; ++x) {
      const T d = T(depth.to_metres(row[x]));
      if (d <= T(0)) continue;
      const T diff = std::abs(d - target);
      if (diff < best_diff) {
        best_diff = diff;
        best = d;
      }
    }
  }
  return best;
}

/// [lo, hi] in raw depth units. For integer depth (TUM uint16) the bounds are rounded inwards once, so
/// the per-pixel test is two integer compares; float depth compares in double as given (NaN fails).
template <class Raw, bool Integral = std::is_integral<Raw>::value>
struct RawDepthRange {
  double lo, hi;
  RawDepthRange(double l, double h) : lo(l), hi(h) {}
  bool contains(Raw r) const { return static_cast<double>(r) >= lo && static_cast<double>(r) <= hi; }
};
template <class Raw>
struct RawDepthRange<Raw, true> {
  long long lo, hi;
  RawDepthRange(double l, double h) {
    const double top = static_cast<double>(std::numeric_limits<Raw>::max());
    lo = static_cast<long long>(std::ceil(std::min(std::max(l, 0.0), top + 1)));    // checked: clamped first
    hi = static_cast<long long>(std::floor(std::min(std::max(h, -1.0), top)));      // checked: clamped first
  }
  // checked: Raw is an integer type in this specialisation.
  bool contains(Raw r) const { return static_cast<long long>(r) >= lo && static_cast<long long>(r) <= hi; }
};

}  // namespace detail

namespace detail {

/// Every point a candidate with no outcome yet; false (status and reason set) when the check cannot run
/// (Skipped: no keyframe points, pose or depth image) or its inputs break the contract (InvalidInput).
template <class T, class Raw>
bool multiview_start(std::size_t n, std::size_t n_depths, const Rigid3<T>& cam_from_world_ref,
                     const Rigid3<T>& cam_from_world_cur, const DepthView<Raw>& depth, const PinholeCamera<T>& camera,
                     const MultiViewOptions<T>& options, MultiViewResult<T>* out) {
  MultiViewResult<T>& r = *out;
  r.status = Status::Ok;
  r.reason.clear();
  r.num_points = n;
  r.num_checked = r.num_dynamic = r.num_large_parallax = r.num_no_depth = r.num_outside = 0;
  r.labels.assign(n, FeatureLabel::Candidate);
  r.outcome.assign(n, MultiViewOutcome::NonFinite);
  r.projected.resize(n);
  r.projected_depth_m.assign(n, T(0));
  r.measured_depth_m.assign(n, T(0));
  auto stop = [&](Status s, std::string why) {
    r.status = s;
    r.reason = std::move(why);
    return false;
  };
  if (n_depths != n)
    return stop(Status::InvalidInput, "ref_depths_m has " + std::to_string(n_depths) + " depths for " +
                                          std::to_string(n) + " ref_points");
  if (n == 0) return stop(Status::Skipped, "no keyframe points yet: the multi-view check needs a keyframe with depth");
  if (!cam_from_world_ref.all_finite() || !cam_from_world_cur.all_finite())
    return stop(Status::Skipped, "no valid pose for the keyframe or the current frame (tracking not initialised?)");
  if (depth.empty()) return stop(Status::Skipped, "no current depth image");
  std::string why;
  if (options.validate(&why) != Status::Ok) return stop(Status::InvalidInput, "invalid options: " + why);
  if (depth.validate(&why) != Status::Ok) return stop(Status::InvalidInput, why);
  if (!camera.valid()) return stop(Status::InvalidInput, "invalid camera");
  return true;
}

/// What the current frame can say about one keyframe point (pixel u, v at depth d): projected into the
/// current view (x, z), seen there at a small enough parallax, and its depth measured near x. Checked
/// when a measurement exists; the other outcomes say why not.
template <class T, class Raw>
MultiViewOutcome multiview_observe(T u, T v, T d, const Rigid3<T>& cur_from_ref, const Vec3<T>& c_cur_in_ref,
                                   T cos_max, const DepthView<Raw>& depth, const PinholeCamera<T>& camera,
                                   const MultiViewOptions<T>& options, Vec2<T>* x, T* z, T* measured) {
  if (!std::isfinite(u) || !std::isfinite(v) || !std::isfinite(d)) return MultiViewOutcome::NonFinite;
  if (!(d > T(0)) || d > options.max_reference_depth_m) return MultiViewOutcome::NoReferenceDepth;
  const Vec3<T> X_ref = camera.backproject(Vec2<T>(u, v), d);
  const Vec3<T> X_cur = cur_from_ref.apply(X_ref);
  if (!(X_cur.z() > T(0)) || X_cur.z() > T(MultiViewOptions<T>::kMaxProjectedDepthM)) return MultiViewOutcome::BehindCamera;
  *x = camera.project(X_cur);
  *z = X_cur.z();
  if (!camera.in_image(x->x(), x->y(), options.border_px)) return MultiViewOutcome::OutsideImage;
  const Vec3<T> ray_cur = X_ref - c_cur_in_ref;
  const T cosang = X_ref.dot(ray_cur) / (X_ref.norm() * ray_cur.norm());
  if (!(cosang >= cos_max)) return MultiViewOutcome::LargeParallax;
  int pu = 0, pv = 0;
  *measured = pixel_of(x->x(), x->y(), depth.width, depth.height, &pu, &pv)
                  ? closest_depth_in_window<Raw, T>(depth, pu, pv, options.search_radius_px, X_cur.z())
                  : T(0);
  return *measured > T(0) ? MultiViewOutcome::Checked : MultiViewOutcome::NoMeasuredDepth;
}

}  // namespace detail

/// Checks keyframe points against the current depth image, writing into `out` (its buffers are reused).
/// ref_points: any point container (keyframe pixels); ref_depths_m: container of depths (metres) with
/// operator[] and size(), one per point (else InvalidInput); poses are cam_from_world. Status Skipped
/// when there are no keyframe points, no pose or no depth image; InvalidInput for an invalid camera,
/// depth view or options (MultiViewOptions::validate).
template <class C, class D, class Raw, class T>
void check_multiview(const C& ref_points, const D& ref_depths_m, const Rigid3<T>& cam_from_world_ref,
                     const Rigid3<T>& cam_from_world_cur, const DepthView<Raw>& depth, const PinholeCamera<T>& camera,
                     const MultiViewOptions<T>& options, MultiViewResult<T>* out) {
  static_assert(is_point_container_v<C>, "dyncull::check_multiview: ref_points must hold points (see PointTraits)");
  MultiViewResult<T>& r = *out;
  const std::size_t n = static_cast<std::size_t>(ref_points.size());
  if (!detail::multiview_start(n, static_cast<std::size_t>(ref_depths_m.size()), cam_from_world_ref,
                               cam_from_world_cur, depth, camera, options, out))
    return;
  const Rigid3<T> cur_from_ref = cam_from_world_cur * cam_from_world_ref.inverse();
  // Parallax from camera centres (DynaSLAM used the translation column of Tcw, right only without rotation).
  // In the reference frame: the ray from the reference centre is X, the current centre is c_cur.
  const Vec3<T> c_cur_in_ref = cur_from_ref.inverse().t;
  const T cos_max = std::cos(options.max_parallax_deg * Constants<T>::deg_to_rad());
  for (std::size_t i = 0; i < n; ++i) {
    T z = T(0), measured = T(0);
    const MultiViewOutcome o = detail::multiview_observe(
        point_x<T>(ref_points[i]), point_y<T>(ref_points[i]), static_cast<T>(ref_depths_m[i]), cur_from_ref,
        c_cur_in_ref, cos_max, depth, camera, options, &r.projected[i], &z, &measured);
    r.outcome[i] = o;
    r.projected_depth_m[i] = z;
    r.measured_depth_m[i] = measured;
    r.num_no_depth += o == MultiViewOutcome::NoReferenceDepth || o == MultiViewOutcome::NoMeasuredDepth;
    r.num_outside += o == MultiViewOutcome::BehindCamera || o == MultiViewOutcome::OutsideImage;
    r.num_large_parallax += o == MultiViewOutcome::LargeParallax;
    if (o != MultiViewOutcome::Checked) continue;
    ++r.num_checked;
    // Something now in front of the remembered surface: the thing at x' moved there (RTD-SLAM).
    const bool moved = z - measured > options.depth_threshold_m;
    r.labels[i] = moved ? FeatureLabel::Dynamic : FeatureLabel::Static;
    r.num_dynamic += moved;
  }
  if (r.num_checked == 0) {
    r.status = Status::TooFewPoints;
    r.reason = "no keyframe point could be compared (all without depth, outside the image or at large parallax)";
  }
}

/// Convenience overload returning a fresh result.
template <class C, class D, class Raw, class T>
MultiViewResult<T> check_multiview(const C& ref_points, const D& ref_depths_m, const Rigid3<T>& cam_from_world_ref,
                                   const Rigid3<T>& cam_from_world_cur, const DepthView<Raw>& depth,
                                   const PinholeCamera<T>& camera, const MultiViewOptions<T>& options = {}) {
  MultiViewResult<T> r;
  check_multiview(ref_points, ref_depths_m, cam_from_world_ref, cam_from_world_cur, depth, camera, options, &r);
  return r;
}

/// Grows the dynamic seeds x' of `result` over the current depth image (4-neighbour flood fill, pixels
/// within kRegionDepthToleranceM of the seed's measured depth d'), OR-ing into `mask` (same size as the
/// depth image; resized and cleared when its size differs). DynaSLAM does the same before dilating.
/// `stack` is caller-owned scratch, reused across frames. `roi` (optional) limits seeds and growth to
/// a pixel rectangle (the pipeline passes the region of the features it still has to decide).
/// Returns the number of pixels set.
template <class Raw, class T>
std::size_t grow_multiview_regions(const MultiViewResult<T>& result, const DepthView<Raw>& depth, Mask* mask,
                                   std::vector<std::uint32_t>* stack, const PixelRect* roi = nullptr) {
  const std::size_t nr = result.labels.size();
  if (depth.empty() || depth.validate() != Status::Ok || result.projected.size() != nr ||
      result.measured_depth_m.size() != nr)
    return 0;
  const int w = depth.width, h = depth.height;
  const int rc0 = roi ? std::max(0, roi->c0) : 0, rr0 = roi ? std::max(0, roi->r0) : 0;
  const int rc1 = roi ? std::min(w, roi->c1) : w, rr1 = roi ? std::min(h, roi->r1) : h;
  if (mask->width != w || mask->height != h) mask->reset(w, h, 0);
  std::uint8_t* m = mask->pixels.data();
  std::size_t set = 0;
  const T tol = T(MultiViewOptions<T>::kRegionDepthToleranceM);
  const double units = static_cast<double>(depth.units_per_metre);
  for (std::size_t i = 0; i < result.labels.size(); ++i) {
    if (result.labels[i] != FeatureLabel::Dynamic) continue;
    int su = 0, sv = 0;
    if (!pixel_of(result.projected[i].x(), result.projected[i].y(), w, h, &su, &sv)) continue;
    if (su < rc0 || sv < rr0 || su >= rc1 || sv >= rr1) continue;
    const std::size_t seed_idx = static_cast<std::size_t>(sv) * static_cast<std::size_t>(w) + static_cast<std::size_t>(su);
    if (m[seed_idx]) continue;  // already inside a grown region
    // The joining test in raw units, with the view's valid range folded in: no division per pixel.
    const double seed_d = static_cast<double>(result.measured_depth_m[i]);
    const double lo_m = std::max({seed_d - static_cast<double>(tol), static_cast<double>(depth.min_m), 1e-9});
    const double hi_m = std::min(seed_d + static_cast<double>(tol), static_cast<double>(depth.max_m));
    const detail::RawDepthRange<Raw> range(lo_m * units, hi_m * units);
    // Scanline fill (4-connected): each stack entry is a seed pixel of a run; runs are filled left and
    // right, and the rows above and below are scanned once per run. Same region as a pixel-wise fill.
    auto inside = [&](int x, int y) {
      return !m[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)] &&
             range.contains(depth.row(y)[x]);
    };
    // Row form for the scans of the rows above and below a run (the bulk of the tests).
    auto scan_row = [&](int ny, int x0, int x1) {
      const Raw* drow = depth.row(ny);
      const std::uint8_t* mrow = m + static_cast<std::size_t>(ny) * static_cast<std::size_t>(w);
      const std::uint32_t base = static_cast<std::uint32_t>(static_cast<std::size_t>(ny) * static_cast<std::size_t>(w));
      bool in_run = false;
      for (int xx = x0; xx <= x1; ++xx) {
        const bool ok = !mrow[xx] && range.contains(drow[xx]);
        if (ok && !in_run) stack->push_back(base + static_cast<std::uint32_t>(xx));
        in_run = ok;
      }
    };
    stack->clear();
    stack->push_back(static_cast<std::uint32_t>(seed_idx));
    bool first = true;
    while (!stack->empty()) {
      const std::uint32_t idx = stack->back();
      stack->pop_back();
      const int y = static_cast<int>(idx / static_cast<std::uint32_t>(w));
      const int x = static_cast<int>(idx - static_cast<std::uint32_t>(y) * static_cast<std::uint32_t>(w));
      if (!first && !inside(x, y)) continue;  // the seed itself is taken whatever its raw value
      first = false;
      int x0 = x, x1 = x;
      while (x0 > rc0 && inside(x0 - 1, y)) --x0;
      while (x1 + 1 < rc1 && inside(x1 + 1, y)) ++x1;
      std::uint8_t* mrow = m + static_cast<std::size_t>(y) * static_cast<std::size_t>(w);
      for (int xx = x0; xx <= x1; ++xx) mrow[xx] = 1;
      const std::size_t run = static_cast<std::size_t>(x1 - x0 + 1);
      set += run;
      if (y - 1 >= rr0) scan_row(y - 1, x0, x1);
      if (y + 1 < rr1) scan_row(y + 1, x0, x1);
    }
  }
  return set;
}

/// One stored keyframe: pose, pixels and depths of (static) keypoints.
template <class T>
struct MultiViewKeyframe {
  Rigid3<T> cam_from_world;
  std::vector<Vec2<T>> points;
  std::vector<T> depth_m;
};

/// Caller-owned ring of recent keyframes (DynaSLAM keeps 20 and compares against 5). Slots are
/// reused, so after the ring is full pushing allocates nothing once point counts have been seen.
template <class T>
class KeyframeRing {
 public:
  explicit KeyframeRing(std::size_t capacity = 20) : slots_(capacity > 0 ? capacity : 1) {}

  std::size_t capacity() const { return slots_.size(); }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  void clear() { size_ = 0; }

  /// Keyframe i, 0 = newest.
  const MultiViewKeyframe<T>& operator[](std::size_t i) const {
    return slots_[(head_ + slots_.size() - 1 - i) % slots_.size()];
  }

  /// Stores a keyframe: points with valid depth (and keep[i] != 0 when keep is given, one flag per
  /// point) are copied. InvalidInput, and nothing stored, when depths_m does not hold one depth per point
  /// or a given keep does not hold one flag per point.
  template <class C, class D>
  Status push(const Rigid3<T>& cam_from_world, const C& points, const D& depths_m, FlagView keep = nullptr) {
    if (static_cast<std::size_t>(depths_m.size()) != static_cast<std::size_t>(points.size())) return Status::InvalidInput;
    if (keep.given && !keep.holds(static_cast<std::size_t>(points.size()))) return Status::InvalidInput;
    MultiViewKeyframe<T>& slot = slots_[head_];
    head_ = (head_ + 1) % slots_.size();
    size_ = std::min(size_ + 1, slots_.size());
    slot.cam_from_world = cam_from_world;
    slot.points.clear();
    slot.depth_m.clear();
    const std::size_t n = static_cast<std::size_t>(points.size());
    for (std::size_t i = 0; i < n; ++i) {
      if (keep.given && !keep[i]) continue;
      const T d = static_cast<T>(depths_m[i]);
      const T u = point_x<T>(points[i]), v = point_y<T>(points[i]);
      if (!(d > T(0)) || !std::isfinite(d) || !std::isfinite(u) || !std::isfinite(v)) continue;
      slot.points.emplace_back(u, v);
      slot.depth_m.push_back(d);
    }
    return Status::Ok;
  }

  /// Up to max_refs keyframe indices, largest pose difference first (DynaSLAM: 0.7 normalised
  /// translation + 0.3 normalised rotation), so the check sees the most motion. Returns the count.
  std::size_t select_references(const Rigid3<T>& cam_from_world_cur, std::size_t max_refs, std::size_t* out) const {
    const std::size_t n = size_;
    if (n == 0 || max_refs == 0) return 0;
    T max_t = T(0), max_r = T(0);
    score_.resize(n);
    order_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const Rigid3<T> rel = cam_from_world_cur * (*this)[i].cam_from_world.inverse();
      const T dt = rel.t.norm(), dr = rotation_angle(rel.R);
      score_[i] = {dt, dr};
      max_t = std::max(max_t, dt);
      max_r = std::max(max_r, dr);
      order_[i] = i;
    }
    auto value = [&](std::size_t i) {
      return T(0.7) * (max_t > T(0) ? score_[i].first / max_t : T(0)) +
             T(0.3) * (max_r > T(0) ? score_[i].second / max_r : T(0));
    };
    std::stable_sort(order_.begin(), order_.end(), [&](std::size_t a, std::size_t b) { return value(a) > value(b); });
    const std::size_t k = std::min(n, max_refs);
    for (std::size_t i = 0; i < k; ++i) out[i] = order_[i];
    return k;
  }

 private:
  std::vector<MultiViewKeyframe<T>> slots_;
  std::size_t head_ = 0, size_ = 0;
  mutable std::vector<std::pair<T, T>> score_;
  mutable std::vector<std::size_t> order_;
};

}  // namespace dyncull
