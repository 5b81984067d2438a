/// @file moving_consistency.hpp
/// Moving-consistency check (DFD-SLAM, Qian et al. 2024, §3.2 eq. 1-3; DS-SLAM): F by RANSAC on the tracked features, then
/// each track's distance D = |p2^T F p1| / sqrt(X^2 + Y^2) to its epipolar line; D above a threshold = dynamic.
#pragma once

#include "dyncull/core/flags.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/core/traits.hpp"
#include "dyncull/core/types.hpp"
#include "dyncull/culling/labels.hpp"
#include "dyncull/culling/validation.hpp"
#include "dyncull/geometry/epipolar.hpp"
#include "dyncull/geometry/fundamental.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace dyncull {

/// Options. Defaults: SG-SLAM's F-RANSAC (1 px, 0.99) and DS-SLAM's 1 px epipolar threshold; the
/// SG-SLAM variants (fit outside boxes, tighter threshold inside boxes) act only when box flags are given.
template <class T>
struct MovingConsistencyOptions {
  /// F-RANSAC; fundamental.ransac.max_residual is a Sampson distance in px (about eq. 3 / sqrt(2)).
  FundamentalOptions<T> fundamental{};
  T max_epipolar_distance_px = T(1);  ///< eq. 3 distance above this: dynamic (DS-SLAM limit_dis_epi)
  /// Threshold for tracks flagged as inside a dynamic-class box (SG-SLAM uses 0.2 px inside person boxes).
  /// Default 0.5 px: about 1.5 sigma of LK noise, so a still person is not flagged wholesale.
  T max_epipolar_distance_in_boxes_px = T(0.5);
  /// Fit F only on tracks outside dynamic boxes when at least min_tracks_outside_boxes remain (SG-SLAM).
  bool fit_outside_boxes = true;
  std::size_t min_tracks_outside_boxes = 20;
  /// Fewer valid tracks than this: Skipped (F from a handful of tracks labels noise, not motion).
  std::size_t min_tracks = 15;
  /// Polish: refit F by the normalised 8-point algorithm on the tracks of the fit set whose eq. 3
  /// distance is below max_epipolar_distance_px, this many times (0 = RANSAC's F as is). Measured on
  /// the test scenes: the RANSAC model at small baselines is noticeably worse than a least-squares fit
  /// on its own inliers (docs/algorithms.md).
  int refit_iterations = 2;
  static constexpr int kMaxRefitIterations = 100;  ///< upper bound of refit_iterations (each is one 8-point fit)

  MovingConsistencyOptions() {
    // The homography test of fundamental.hpp fires at small baselines, where F on the static tracks is
    // still well determined; and under pure rotation any F = [e]x H keeps static tracks at distance 0,
    // so the labels stay meaningful. Off by default here.
    fundamental.check_homography_degeneracy = false;
  }

  /// InvalidInput naming the first field out of its range: both epipolar thresholds positive and finite,
  /// refit_iterations in [0, kMaxRefitIterations], fundamental (and fundamental.ransac) passing their own
  /// validate().
  Status validate(std::string* reason = nullptr) const {
    using detail::invalid_option;
    if (!(max_epipolar_distance_px > T(0)) || !std::isfinite(max_epipolar_distance_px))
      return invalid_option(reason, "max_epipolar_distance_px", "must be positive and finite");
    if (!(max_epipolar_distance_in_boxes_px > T(0)) || !std::isfinite(max_epipolar_distance_in_boxes_px))
      return invalid_option(reason, "max_epipolar_distance_in_boxes_px", "must be positive and finite");
    if (refit_iterations < 0 || refit_iterations > kMaxRefitIterations)
      return invalid_option(reason, "refit_iterations", "must be in [0, 100]");
    if (detail::validate_nested(fundamental, "fundamental", reason) != Status::Ok) return Status::InvalidInput;
    if (detail::validate_nested(fundamental.ransac, "fundamental.ransac", reason) != Status::Ok)
      return Status::InvalidInput;
    if (reason) reason->clear();
    return Status::Ok;
  }
};

/// Per-track result. labels: Dynamic (D above threshold), Static, or Candidate (track invalid or not
/// evaluated: no evidence either way). distance_px is NaN where not evaluated.
template <class T>
struct MovingConsistencyResult {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }

  std::vector<FeatureLabel> labels;
  std::vector<T> distance_px;
  std::vector<std::uint8_t> inlier_mask;  ///< F-RANSAC inliers (0 for tracks not used in the fit)
  Mat3<T> F = Mat3<T>::Zero();
  std::size_t num_tracks = 0, num_valid = 0, num_fit = 0, num_inliers = 0;
  std::size_t num_dynamic = 0, num_static = 0;
  std::size_t ransac_iterations = 0;
  bool fitted_outside_boxes = false;  ///< the SG-SLAM subset was used for F

  // Scratch reused across frames (compacted tracks, the F fits); not part of the result's meaning.
  std::vector<Vec2<T>> scratch_prev, scratch_cur, scratch_fit_prev, scratch_fit_cur, scratch_refit_prev,
      scratch_refit_cur;
  std::vector<std::uint32_t> scratch_index, scratch_fit_index;
  std::vector<T> scratch_distance;
  FundamentalWorkspace<T> scratch_fundamental;
  FundamentalResult<T> scratch_ransac_fit, scratch_polished_fit;
};

namespace detail {

/// Every track a candidate with no distance yet; false (status and reason set) when the inputs break
/// the contract.
template <class T>
bool consistency_start(std::size_t n, std::size_t n_prev, FlagView valid, FlagView in_box,
                       const MovingConsistencyOptions<T>& options, MovingConsistencyResult<T>* out) {
  MovingConsistencyResult<T>& r = *out;
  r.status = Status::Ok;
  r.reason.clear();
  r.num_tracks = n;
  r.num_valid = r.num_fit = r.num_inliers = r.num_dynamic = r.num_static = r.ransac_iterations = 0;
  r.fitted_outside_boxes = false;
  r.F.setZero();
  r.labels.assign(n, FeatureLabel::Candidate);
  r.distance_px.assign(n, Constants<T>::nan());
  r.inlier_mask.assign(n, 0);
  auto stop = [&](std::string why) {
    r.status = Status::InvalidInput;
    r.reason = std::move(why);
    return false;
  };
  if (n_prev != n) return stop("prev and cur differ in size");
  std::string why;
  if (!flags_fit(valid, n, "valid", "tracks", &why) || !flags_fit(in_box, n, "in_box", "tracks", &why))
    return stop(why);
  if (options.validate(&why) != Status::Ok) return stop("invalid options: " + why);
  return true;
}

/// The valid, finite tracks compacted into the scratch (their indices in scratch_index); returns those
/// outside the boxes, for SG-SLAM's fit subset.
template <class T, class C1, class C2>
std::size_t consistency_compact(const C1& prev, const C2& cur, FlagView valid, FlagView in_box,
                                MovingConsistencyResult<T>* r) {
  r->scratch_prev.clear();
  r->scratch_cur.clear();
  r->scratch_index.clear();
  std::size_t outside = 0;
  for (std::size_t i = 0; i < static_cast<std::size_t>(cur.size()); ++i) {
    if (valid.given && !valid[i]) continue;
    const T x1 = point_x<T>(prev[i]), y1 = point_y<T>(prev[i]), x2 = point_x<T>(cur[i]), y2 = point_y<T>(cur[i]);
    if (!std::isfinite(x1) || !std::isfinite(y1) || !std::isfinite(x2) || !std::isfinite(y2)) continue;
    r->scratch_prev.emplace_back(x1, y1);
    r->scratch_cur.emplace_back(x2, y2);
    r->scratch_index.push_back(static_cast<std::uint32_t>(i));
    outside += !(in_box.given && in_box[i]);
  }
  return outside;
}

/// F by RANSAC on the compacted tracks, on those outside the boxes alone when `subset`; false (status
/// and reason set) when F is not usable: Degenerate means one homography explains the tracks (static
/// camera, pure rotation, planar scene), so F's epipolar lines carry no evidence of motion.
template <class T>
bool consistency_fit(bool subset, FlagView in_box, const MovingConsistencyOptions<T>& options,
                     MovingConsistencyResult<T>* out) {
  MovingConsistencyResult<T>& r = *out;
  const std::size_t m = r.scratch_index.size();
  FundamentalResult<T>& fr = r.scratch_ransac_fit;
  if (subset) {
    r.scratch_fit_prev.clear();
    r.scratch_fit_cur.clear();
    r.scratch_fit_index.clear();
    for (std::size_t k = 0; k < m; ++k) {
      if (in_box[r.scratch_index[k]]) continue;
      r.scratch_fit_prev.push_back(r.scratch_prev[k]);
      r.scratch_fit_cur.push_back(r.scratch_cur[k]);
      r.scratch_fit_index.push_back(r.scratch_index[k]);
    }
  }
  const std::vector<std::uint32_t>& fit_index = subset ? r.scratch_fit_index : r.scratch_index;
  estimate_fundamental_ransac(subset ? r.scratch_fit_prev : r.scratch_prev, subset ? r.scratch_fit_cur : r.scratch_cur,
                              options.fundamental, &r.scratch_fundamental, &fr);
  r.fitted_outside_boxes = subset;
  r.num_fit = fit_index.size();
  for (std::size_t k = 0; k < fr.inlier_mask.size(); ++k) r.inlier_mask[fit_index[k]] = fr.inlier_mask[k];
  r.num_inliers = fr.num_inliers;
  r.ransac_iterations = fr.iterations;
  r.F = fr.F;
  if (fr.ok()) return true;
  r.status = fr.status;
  r.reason.assign("fundamental matrix not usable: ").append(fr.reason);  // into the kept buffer
  for (auto& m8 : r.inlier_mask) m8 = 0;
  r.num_inliers = 0;
  return false;
}

/// Polishes F by the 8-point algorithm on the fit tracks within max_epipolar_distance_px of it,
/// refit_iterations times (stops early below 16 tracks or on a failed fit).
template <class T>
void consistency_refit(bool subset, const MovingConsistencyOptions<T>& options, MovingConsistencyResult<T>* r) {
  const std::vector<Vec2<T>>& fit_prev = subset ? r->scratch_fit_prev : r->scratch_prev;
  const std::vector<Vec2<T>>& fit_cur = subset ? r->scratch_fit_cur : r->scratch_cur;
  for (int it = 0; it < options.refit_iterations; ++it) {
    if (epipolar_distances(r->F, fit_prev, fit_cur, r->scratch_distance.data(), EpipolarDistance::PointToLine) !=
        Status::Ok)
      break;  // the final pass reports it
    r->scratch_refit_prev.clear();
    r->scratch_refit_cur.clear();
    for (std::size_t k = 0; k < fit_prev.size(); ++k) {
      if (!(r->scratch_distance[k] <= options.max_epipolar_distance_px)) continue;
      r->scratch_refit_prev.push_back(fit_prev[k]);
      r->scratch_refit_cur.push_back(fit_cur[k]);
    }
    if (r->scratch_refit_prev.size() < 16) break;
    FundamentalResult<T>& polished = r->scratch_polished_fit;
    fundamental_8point(r->scratch_refit_prev, r->scratch_refit_cur, &r->scratch_fundamental, &polished);
    if (!polished.ok()) break;
    r->F = polished.F;
  }
}

}  // namespace detail

/// Runs the check on n tracks prev[i] -> cur[i] (any point containers of equal size), writing into `out`
/// (buffers reused). valid: optional per-track flag (0 = no track, e.g. LK failed); in_box: optional
/// per-track flag (1 = inside a dynamic-class box: excluded from the F fit when possible, tighter threshold).
/// InvalidInput (nothing read) when prev and cur differ in size, a given flag view does not hold cur.size()
/// flags, or the options fail MovingConsistencyOptions::validate.
template <class T, class C1, class C2>
void check_moving_consistency(const C1& prev, const C2& cur, const MovingConsistencyOptions<T>& options,
                              MovingConsistencyResult<T>* out, FlagView valid = nullptr, FlagView in_box = nullptr) {
  static_assert(is_point_container_v<C1> && is_point_container_v<C2>,
                "dyncull::check_moving_consistency: prev and cur must hold points (see PointTraits)");
  MovingConsistencyResult<T>& r = *out;
  const std::size_t n = static_cast<std::size_t>(cur.size());
  if (!detail::consistency_start(n, static_cast<std::size_t>(prev.size()), valid, in_box, options, out)) return;
  const std::size_t outside = detail::consistency_compact<T>(prev, cur, valid, in_box, out);
  const std::size_t m = r.scratch_index.size();
  r.num_valid = m;
  if (m < options.min_tracks || m < 8) {
    r.status = Status::Skipped;
    r.reason = std::to_string(m) + " valid tracks, the moving-consistency check needs at least " +
               std::to_string(options.min_tracks < 8 ? 8 : options.min_tracks);
    return;
  }
  const bool subset =
      in_box.given && options.fit_outside_boxes && outside >= options.min_tracks_outside_boxes && outside < m;
  if (!detail::consistency_fit(subset, in_box, options, out)) return;
  r.scratch_distance.resize(m);
  detail::consistency_refit(subset, options, out);
  const Status ds =
      epipolar_distances(r.F, r.scratch_prev, r.scratch_cur, r.scratch_distance.data(), EpipolarDistance::PointToLine);
  if (ds != Status::Ok) {
    // F = 0 (Degenerate) or non-finite (NonFinite): no epipolar line, so no track has evidence.
    r.status = ds;
    r.reason = std::string("epipolar distances not usable (") + to_string(ds) + "): F is zero or not finite";
    return;
  }
  // DFD-SLAM eq. 3: a track further than the threshold from its epipolar line is dynamic.
  const T t_out = options.max_epipolar_distance_px, t_in = options.max_epipolar_distance_in_boxes_px;
  for (std::size_t k = 0; k < m; ++k) {
    const std::uint32_t i = r.scratch_index[k];
    const T d = r.scratch_distance[k];
    r.distance_px[i] = d;
    if (!std::isfinite(d)) continue;  // at the epipole: the line is undefined, no evidence
    const bool dyn = d > ((in_box.given && in_box[i]) ? t_in : t_out);
    r.labels[i] = dyn ? FeatureLabel::Dynamic : FeatureLabel::Static;
    r.num_dynamic += dyn;
    r.num_static += !dyn;
  }
}

/// Convenience overload returning a fresh result.
template <class T, class C1, class C2>
MovingConsistencyResult<T> check_moving_consistency(const C1& prev, const C2& cur,
                                                    const MovingConsistencyOptions<T>& options = {},
                                                    FlagView valid = nullptr, FlagView in_box = nullptr) {
  MovingConsistencyResult<T> r;
  check_moving_consistency(prev, cur, options, &r, valid, in_box);
  return r;
}

}  // namespace dyncull
