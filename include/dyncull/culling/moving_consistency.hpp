/// @file moving_consistency.hpp
/// Moving-consistency check (DFD-SLAM, Qian et al. 2024, §3.2 eq. 1-3; DS-SLAM, Yu et al. 2018): F by RANSAC on
/// the tracks (outside dynamic-class boxes: SG-SLAM, Cheng et al. 2023), then each track's distance
/// D = |p2^T F p1| / sqrt(X^2 + Y^2) to its epipolar line; D above a threshold = dynamic (model_check.hpp).
#pragma once

#include "dyncull/core/flags.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/core/traits.hpp"
#include "dyncull/core/types.hpp"
#include "dyncull/culling/labels.hpp"
#include "dyncull/culling/model_check.hpp"
#include "dyncull/culling/validation.hpp"
#include "dyncull/geometry/epipolar.hpp"
#include "dyncull/geometry/fundamental.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace dyncull {

/// Options. Defaults: SG-SLAM's F-RANSAC (1 px, 0.99) and DS-SLAM's 1 px epipolar threshold; the
/// SG-SLAM variants (fit outside boxes, tighter threshold inside boxes) act only when box flags are given.
template <class T>
struct MovingConsistencyOptions {
  /// F-RANSAC's inlier threshold, a Sampson distance in px (about eq. 3 / sqrt(2)): SG-SLAM's 1 px.
  static constexpr double kRansacSampsonPx = 1.0;
  /// F-RANSAC's confidence of having drawn one all-inlier sample (SG-SLAM's 0.99).
  static constexpr double kRansacConfidence = 0.99;

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
  /// F-RANSAC's sample cap. Why you would change it: to bound the worst frame's time on a slow CPU (a
  /// frame with few static tracks, or random ones, runs to the cap; a usual frame stops far earlier).
  std::size_t max_ransac_iterations = 10000;

  /// The F fit's solver settings: the constants above, and no homography test: it fires at small
  /// baselines, where F on the static tracks is still well determined; and under pure rotation any
  /// F = [e]x H keeps static tracks at distance 0, so the labels stay meaningful.
  FundamentalOptions<T> fundamental_fit() const {
    FundamentalOptions<T> f;
    f.ransac.max_residual = kRansacSampsonPx;
    f.ransac.confidence = kRansacConfidence;
    f.ransac.max_iterations = max_ransac_iterations;
    f.check_homography_degeneracy = false;
    return f;
  }

  /// InvalidInput naming the first field out of its range: both epipolar thresholds positive and finite,
  /// refit_iterations in [0, kMaxRefitIterations], max_ransac_iterations in [1, RansacOptions::kMaxIterations].
  Status validate(std::string* reason = nullptr) const {
    using detail::invalid_option;
    if (!(max_epipolar_distance_px > T(0)) || !std::isfinite(max_epipolar_distance_px))
      return invalid_option(reason, "max_epipolar_distance_px", "must be positive and finite");
    if (!(max_epipolar_distance_in_boxes_px > T(0)) || !std::isfinite(max_epipolar_distance_in_boxes_px))
      return invalid_option(reason, "max_epipolar_distance_in_boxes_px", "must be positive and finite");
    if (refit_iterations < 0 || refit_iterations > kMaxRefitIterations)
      return invalid_option(reason, "refit_iterations", "must be in [0, 100]");
    if (max_ransac_iterations < 1 || max_ransac_iterations > RansacOptions::kMaxIterations)
      return invalid_option(reason, "max_ransac_iterations", "must be in [1, 1e7]");
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

/// The epipolar estimator of check_against_model (model_check.hpp): F by RANSAC on the fit tracks,
/// polished by the 8-point algorithm, and each track's eq. 3 distance to its epipolar line.
template <class T, class C1, class C2>
struct EpipolarEstimator {
  static constexpr std::size_t kMinimalTracks = 8;
  // With every usable track outside the boxes the subset is the whole set: not reported as the subset.
  static constexpr bool kSubsetLeavesSomeOut = true;
  static constexpr const char* kSizeMismatch = "prev and cur differ in size";
  static constexpr const char* kTooFew = " valid tracks, the moving-consistency check needs at least ";

  const C1& prev;
  const C2& cur;
  const MovingConsistencyOptions<T>& options;
  MovingConsistencyResult<T>* r;
  bool subset = false;  ///< F is fitted on the tracks outside the boxes, copied apart

  std::size_t size() const { return static_cast<std::size_t>(cur.size()); }
  bool sizes_agree() const { return static_cast<std::size_t>(prev.size()) == size(); }
  bool inputs_valid(std::string*) const { return true; }

  void reset() {
    r->ransac_iterations = 0;
    r->F.setZero();
    r->distance_px.assign(size(), Constants<T>::nan());
    r->scratch_prev.clear();
    r->scratch_cur.clear();
    r->scratch_index.clear();
    r->scratch_fit_prev.clear();
    r->scratch_fit_cur.clear();
    r->scratch_fit_index.clear();
  }

  bool usable(std::size_t i) const {
    using std::isfinite;
    return isfinite(point_x<T>(prev[i])) && isfinite(point_y<T>(prev[i])) && isfinite(point_x<T>(cur[i])) &&
           isfinite(point_y<T>(cur[i]));
  }
  /// Every usable track, compacted: the distances are one batch pass over them.
  void keep(std::size_t i) {
    r->scratch_prev.emplace_back(point_x<T>(prev[i]), point_y<T>(prev[i]));
    r->scratch_cur.emplace_back(point_x<T>(cur[i]), point_y<T>(cur[i]));
    r->scratch_index.push_back(static_cast<std::uint32_t>(i));
  }
  /// The subset is copied apart; without it F is fitted on the kept tracks as they are.
  bool begin_fit(bool fit_subset) {
    subset = fit_subset;
    return subset;
  }
  void add_to_fit(std::size_t k, std::size_t i) {
    r->scratch_fit_prev.push_back(r->scratch_prev[k]);
    r->scratch_fit_cur.push_back(r->scratch_cur[k]);
    r->scratch_fit_index.push_back(static_cast<std::uint32_t>(i));
  }
  const std::vector<Vec2<T>>& fit_prev() const { return subset ? r->scratch_fit_prev : r->scratch_prev; }
  const std::vector<Vec2<T>>& fit_cur() const { return subset ? r->scratch_fit_cur : r->scratch_cur; }

  /// F-RANSAC on the fit tracks; false when F is not usable: Degenerate means one homography explains the
  /// tracks (static camera, pure rotation, planar scene), so F's epipolar lines carry no evidence of motion.
  bool fit() {
    FundamentalResult<T>& fr = r->scratch_ransac_fit;
    estimate_fundamental_ransac(fit_prev(), fit_cur(), options.fundamental_fit(), &r->scratch_fundamental, &fr);
    const std::vector<std::uint32_t>& fit_index = subset ? r->scratch_fit_index : r->scratch_index;
    for (std::size_t k = 0; k < fr.inlier_mask.size(); ++k) r->inlier_mask[fit_index[k]] = fr.inlier_mask[k];
    r->num_inliers = fr.num_inliers;
    r->ransac_iterations = fr.iterations;
    r->F = fr.F;
    if (fr.ok()) return true;
    r->status = fr.status;
    r->reason.assign("fundamental matrix not usable: ").append(fr.reason);  // into the kept buffer
    for (auto& m8 : r->inlier_mask) m8 = 0;
    r->num_inliers = 0;
    return false;
  }

  /// Refits F by the 8-point algorithm on the fit tracks within max_epipolar_distance_px of it,
  /// refit_iterations times (stops early below 16 tracks or on a failed fit): at small baselines the
  /// RANSAC model is noticeably worse than a least-squares fit on its own inliers.
  void polish() {
    const std::vector<Vec2<T>>& fp = fit_prev();
    const std::vector<Vec2<T>>& fc = fit_cur();
    r->scratch_distance.resize(r->scratch_index.size());
    for (int it = 0; it < options.refit_iterations; ++it) {
      if (epipolar_distances(r->F, fp, fc, r->scratch_distance.data(), EpipolarDistance::PointToLine) != Status::Ok)
        break;  // residuals_ready reports it
      r->scratch_refit_prev.clear();
      r->scratch_refit_cur.clear();
      for (std::size_t k = 0; k < fp.size(); ++k) {
        if (!(r->scratch_distance[k] <= options.max_epipolar_distance_px)) continue;
        r->scratch_refit_prev.push_back(fp[k]);
        r->scratch_refit_cur.push_back(fc[k]);
      }
      if (r->scratch_refit_prev.size() < 16) break;
      FundamentalResult<T>& polished = r->scratch_polished_fit;
      fundamental_8point(r->scratch_refit_prev, r->scratch_refit_cur, &r->scratch_fundamental, &polished);
      if (!polished.ok()) break;
      r->F = polished.F;
    }
  }

  /// The eq. 3 distance of every usable track; false when F = 0 (Degenerate) or is not finite
  /// (NonFinite): no epipolar line, so no track has evidence.
  bool residuals_ready() {
    r->scratch_distance.resize(r->scratch_index.size());
    const Status ds = epipolar_distances(r->F, r->scratch_prev, r->scratch_cur, r->scratch_distance.data(),
                                         EpipolarDistance::PointToLine);
    if (ds == Status::Ok) return true;
    r->status = ds;
    r->reason = std::string("epipolar distances not usable (") + to_string(ds) + "): F is zero or not finite";
    return false;
  }

  FeatureLabel label(std::size_t k, std::size_t i, T limit) {
    const T d = r->scratch_distance[k];
    r->distance_px[i] = d;
    if (!std::isfinite(d)) return FeatureLabel::Candidate;  // at the epipole: the line is undefined
    return d > limit ? FeatureLabel::Dynamic : FeatureLabel::Static;
  }
  void finish() {}
};

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
  detail::EpipolarEstimator<T, C1, C2> epipolar{prev, cur, options, out};
  const detail::ModelCheckRule<T> rule{options.max_epipolar_distance_px, options.max_epipolar_distance_in_boxes_px,
                                       options.min_tracks, options.fit_outside_boxes,
                                       options.min_tracks_outside_boxes};
  detail::check_against_model(epipolar, valid, in_box, rule);
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
