/// @file reprojection_check.hpp
/// RGB-D form of the moving-consistency check (DFD-SLAM, Qian et al. 2024, eq. 3): the pose by PnP-RANSAC on the
/// tracks outside dynamic boxes (SG-SLAM, Cheng et al. 2023), then each track's reprojection residual, and
/// optionally its depth residual, against a threshold (model_check.hpp).
#pragma once

#include "dyncull/core/camera.hpp"
#include "dyncull/core/depth.hpp"
#include "dyncull/core/flags.hpp"
#include "dyncull/core/pixel.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/core/traits.hpp"
#include "dyncull/core/types.hpp"
#include "dyncull/culling/labels.hpp"
#include "dyncull/culling/model_check.hpp"
#include "dyncull/culling/validation.hpp"
#include "dyncull/geometry/pnp.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace dyncull {

/// Options. The thresholds are pixel reprojection errors at the fitted pose.
template <class T>
struct ReprojectionCheckOptions {
  /// PnP-RANSAC's inlier threshold in px on the fit subset (P3P + MSAC + LM, geometry/pnp.hpp), as the
  /// demo front end; its confidence of having drawn one all-inlier sample.
  static constexpr double kRansacThresholdPx = 2.0;
  static constexpr double kRansacConfidence = 0.999;
  /// PnP-RANSAC's sample cap: 300 samples reach 0.999 confidence down to about 20 % outliers (outside
  /// boxes). Why you would change it: more outliers among the fit tracks, or a tighter time budget.
  std::size_t max_ransac_iterations = 300;
  T max_residual_px = T(3);           ///< residual above this: dynamic (tracks outside dynamic boxes)
  /// Threshold inside dynamic-class boxes. Measured on the dynamic_vo sim at the front end's own pose: 2 px
  /// is exceeded by 4-7 % of the tracks on still chairs and a seated person's legs, against 77 % of the
  /// walkers' and 40 % of the swaying upper body's; 1.5 px (the default) trades a little of the first for
  /// more of the second (docs/algorithms.md).
  T max_residual_in_boxes_px = T(1.5);
  /// Both pixel limits rise to this many times the frame's static-track noise (inlier_noise_px) where that
  /// is larger: a fixed limit suits one camera's noise. On the Bonn crowd sequence the noise is 0.40 px
  /// (median over frames; the simulator's 0.12 px) and 1.5 px flagged 13 % of the tracks on still chairs;
  /// 5 sigma keeps a still track's flags rare on any camera (docs/algorithms.md).
  static constexpr double kNoiseMultiple = 5.0;
  /// The pose is fitted only on tracks outside dynamic boxes when at least this many remain.
  std::size_t min_tracks_outside_boxes = 20;
  /// Depth residual (needs the current depth image): when > 0, a track is also dynamic when the depth
  /// measured at its pixel differs from its point's depth at the fitted pose by more than this many
  /// standard deviations of that difference, sqrt(2) sigma(z) (two measurements) with the Kinect axial
  /// noise model sigma(z) = base + quadratic (z - reference)^2 (Nguyen et al. 2012; 3.5 mm at 1.5 m, 1.4 cm
  /// at 3 m). The pixel residual is blind to motion along the viewing ray: a walker heading for the camera
  /// at 0.4 m/s moves 1.3 cm a frame in depth and a fraction of a pixel in the image. 0 = off.
  T max_depth_residual_sigmas = T(0);
  /// The Kinect axial noise model's base, quadratic term and reference depth (Nguyen et al. 2012).
  static constexpr double kDepthSigmaBaseM = 0.0012;
  static constexpr double kDepthSigmaQuadratic = 0.0019;
  static constexpr double kDepthSigmaReferenceM = 0.4;
  std::size_t min_tracks = 15;  ///< fewer usable tracks: Skipped

  /// InvalidInput naming the first field out of its range: the pixel thresholds positive and finite;
  /// max_depth_residual_sigmas finite and >= 0; max_ransac_iterations in [1, RansacOptions::kMaxIterations].
  Status validate(std::string* reason = nullptr) const {
    using detail::finite_in;
    using detail::invalid_option;
    constexpr double kBig = 1e30;
    if (!(max_residual_px > T(0)) || !std::isfinite(max_residual_px))
      return invalid_option(reason, "max_residual_px", "must be positive and finite");
    if (!(max_residual_in_boxes_px > T(0)) || !std::isfinite(max_residual_in_boxes_px))
      return invalid_option(reason, "max_residual_in_boxes_px", "must be positive and finite");
    if (!finite_in(max_depth_residual_sigmas, 0, kBig))
      return invalid_option(reason, "max_depth_residual_sigmas", "must be finite and >= 0");
    if (max_ransac_iterations < 1 || max_ransac_iterations > RansacOptions::kMaxIterations)
      return invalid_option(reason, "max_ransac_iterations", "must be in [1, 1e7]");
    if (reason) reason->clear();
    return Status::Ok;
  }

  /// The pose fit's solver settings: the constants above, then Levenberg-Marquardt with a Huber loss
  /// (geometry/pnp.hpp's defaults otherwise) on the inliers.
  PnpOptions<T> pose_fit() const {
    PnpOptions<T> o;
    o.ransac.max_residual = kRansacThresholdPx;
    o.ransac.max_iterations = max_ransac_iterations;
    o.ransac.confidence = kRansacConfidence;
    o.refinement.huber = true;
    return o;
  }
};

/// Per-track result. labels: Dynamic (residual above threshold), Static, or Candidate (no usable
/// 3-D point or track: no evidence either way). residual_px is NaN where not evaluated.
template <class T>
struct ReprojectionCheckResult {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }

  std::vector<FeatureLabel> labels;
  std::vector<T> residual_px;
  /// Measured minus predicted pixel position (the residual as a vector); NaN where not evaluated. Features
  /// of one object moving together share its direction (coherent_motion.hpp).
  std::vector<Vec2<T>> residual_vec;
  /// Robust standard deviation of one residual component over the fit's PnP inliers (1.4826 times the
  /// median absolute component): the tracking and map noise of static tracks this frame, measured before
  /// the tracks are labelled (the limits rise to kNoiseMultiple times it). NaN when no fit.
  T inlier_noise_px = Constants<T>::nan();
  /// Measured minus predicted depth (m); NaN where not evaluated (depth residual off, no depth there).
  std::vector<T> depth_residual_m;
  std::vector<std::uint8_t> inlier_mask;  ///< PnP-RANSAC inliers (0 for tracks not used in the fit)
  Rigid3<T> cam_from_world;               ///< fitted pose of the current frame (points' frame -> camera)
  std::size_t num_tracks = 0, num_valid = 0, num_fit = 0, num_inliers = 0;
  std::size_t num_dynamic = 0, num_static = 0;
  std::size_t num_depth_dynamic = 0;  ///< dynamic by the depth residual while the pixel residual was within its limit
  bool fitted_outside_boxes = false;

  // Scratch reused across frames (compacted tracks, the pose fit); not part of the result's meaning.
  std::vector<Vec3<T>> scratch_points;
  std::vector<Vec2<T>> scratch_pixels;
  std::vector<std::uint32_t> scratch_index;
  std::vector<T> scratch_values;
  PnpWorkspace<T> scratch_pnp;
  PnpResult<T> scratch_pose_fit;
};

namespace detail {

/// Measured minus predicted pixel of a point pc in front of the camera (camera coordinates).
template <class T>
Vec2<T> reprojection_residual_vec(const Vec3<T>& pc, T u, T v, const PinholeCamera<T>& camera) {
  return Vec2<T>(u - (camera.fx * pc.x() / pc.z() + camera.cx), v - (camera.fy * pc.y() / pc.z() + camera.cy));
}

/// Track i's residuals at the fitted pose and its label: dynamic when the pixel residual exceeds its
/// limit (tighter in a box), or
/// when the depth residual exceeds max_depth_residual_sigmas of the sensor's axial noise; a point behind
/// the camera is dynamic.
template <class T, class Raw>
bool reprojection_label(std::size_t i, const Vec3<T>& X, T u, T v, T limit, const PinholeCamera<T>& camera,
                        const DepthView<Raw>* depth,
                        const ReprojectionCheckOptions<T>& options, ReprojectionCheckResult<T>* r) {
  const Vec3<T> pc = r->cam_from_world.R * X + r->cam_from_world.t;
  T res = std::numeric_limits<T>::infinity();
  if (pc.z() > T(0)) {
    r->residual_vec[i] = reprojection_residual_vec(pc, u, v, camera);
    res = r->residual_vec[i].norm();
  }
  r->residual_px[i] = res;
  bool dyn = !(res <= limit);
  if (depth && pc.z() > T(0)) {
    int pu = 0, pv = 0;
    const float measured = pixel_of(u, v, depth->width, depth->height, &pu, &pv) ? depth->depth_m(pu, pv) : 0.f;
    if (measured > 0.f) {
      const T dz = static_cast<T>(measured) - pc.z();
      r->depth_residual_m[i] = dz;
      using Options = ReprojectionCheckOptions<T>;
      const T sigma = axial_depth_sigma_m(pc.z(), T(Options::kDepthSigmaBaseM), T(Options::kDepthSigmaQuadratic),
                                          T(Options::kDepthSigmaReferenceM));
      const bool depth_dyn = std::abs(dz) > options.max_depth_residual_sigmas * T(1.4142135623730951) * sigma;
      r->num_depth_dynamic += depth_dyn && !dyn;
      dyn = dyn || depth_dyn;
    }
  }
  return dyn;
}

/// Noise of the static tracks: the robust spread (1.4826 MAD about zero) of the fit inliers' residual
/// components, which are zero-mean at the fit. The fit's points and pixels are in scratch order.
template <class T>
void reprojection_inlier_noise(const PinholeCamera<T>& camera, ReprojectionCheckResult<T>* r) {
  const PnpResult<T>& pr = r->scratch_pose_fit;
  r->scratch_values.clear();
  for (std::size_t k = 0; k < pr.inlier_mask.size() && k < r->scratch_points.size(); ++k) {
    const Vec3<T> pc = r->cam_from_world.R * r->scratch_points[k] + r->cam_from_world.t;
    if (!pr.inlier_mask[k] || !(pc.z() > T(0))) continue;
    const Vec2<T> e = reprojection_residual_vec(pc, r->scratch_pixels[k].x(), r->scratch_pixels[k].y(), camera);
    if (!e.allFinite()) continue;
    r->scratch_values.push_back(std::abs(e.x()));
    r->scratch_values.push_back(std::abs(e.y()));
  }
  if (!r->scratch_values.empty()) {
    auto mid = r->scratch_values.begin() + static_cast<std::ptrdiff_t>(r->scratch_values.size() / 2);
    std::nth_element(r->scratch_values.begin(), mid, r->scratch_values.end());
    r->inlier_noise_px = T(1.4826) * *mid;
  }
}

/// The pose estimator of check_against_model (model_check.hpp): the pose by PnP-RANSAC (refined by LM
/// inside solve_pnp_ransac) on the fit tracks, and each track's reprojection (and depth) residual. The
/// epipolar distance sees only the motion across the epipolar line, the reprojection residual all of it in
/// the image, and the depth residual the motion along the viewing ray (docs/algorithms.md).
template <class T, class Points3, class Pixels, class Raw>
struct ReprojectionEstimator {
  static constexpr std::size_t kMinimalTracks = 4;
  static constexpr bool kSubsetLeavesSomeOut = false;  // the subset flag reports the rule as met
  static constexpr const char* kSizeMismatch = "points and pixels differ in size";
  static constexpr const char* kTooFew = " tracks with a 3-D point, the reprojection check needs at least ";

  const Points3& points;
  const Pixels& pixels;
  const PinholeCamera<T>& camera;
  const ReprojectionCheckOptions<T>& options;
  const DepthView<Raw>& depth;
  ReprojectionCheckResult<T>* r;
  bool use_depth = false;

  std::size_t size() const { return static_cast<std::size_t>(pixels.size()); }
  bool sizes_agree() const { return static_cast<std::size_t>(points.size()) == size(); }
  bool inputs_valid(std::string* why) const {
    if (depth.validate(why) != Status::Ok) return false;
    if (camera.valid()) return true;
    *why = "invalid camera intrinsics";
    return false;
  }

  void reset() {
    const std::size_t n = size();
    const T nan = Constants<T>::nan();
    r->num_depth_dynamic = 0;
    r->cam_from_world = Rigid3<T>();
    r->residual_px.assign(n, nan);
    r->residual_vec.assign(n, Vec2<T>(nan, nan));
    r->inlier_noise_px = nan;
    r->depth_residual_m.assign(n, nan);
    r->scratch_points.clear();
    r->scratch_pixels.clear();
    r->scratch_index.clear();
  }

  Vec3<T> point(std::size_t i) const {
    return Vec3<T>(point_x<T>(points[i]), point_y<T>(points[i]), point_z<T>(points[i]));
  }
  Vec2<T> pixel(std::size_t i) const { return Vec2<T>(point_x<T>(pixels[i]), point_y<T>(pixels[i])); }
  bool usable(std::size_t i) const { return point(i).allFinite() && pixel(i).allFinite(); }  // no depth: no point
  void keep(std::size_t) {}  // the residuals are read from the inputs
  bool begin_fit(bool) { return true; }
  void add_to_fit(std::size_t, std::size_t i) {
    r->scratch_points.push_back(point(i));
    r->scratch_pixels.push_back(pixel(i));
    r->scratch_index.push_back(static_cast<std::uint32_t>(i));
  }

  bool fit() {
    PnpResult<T>& pr = r->scratch_pose_fit;
    solve_pnp_ransac(r->scratch_points, r->scratch_pixels, camera, options.pose_fit(), &r->scratch_pnp, &pr);
    if (!pr.ok() || !pr.cam_from_world.all_finite()) {
      r->status = pr.ok() ? Status::NonFinite : pr.status;
      r->reason.assign("pose not found: ").append(pr.ok() ? "non-finite pose" : pr.reason);  // into the kept buffer
      return false;
    }
    r->cam_from_world = pr.cam_from_world;
    r->num_inliers = pr.num_inliers;
    for (std::size_t k = 0; k < pr.inlier_mask.size() && k < r->scratch_index.size(); ++k)
      r->inlier_mask[r->scratch_index[k]] = pr.inlier_mask[k];
    return true;
  }
  void polish() {}  // PnP-RANSAC's LM refinement is the polish

  T noise_limit = T(0);  // kNoiseMultiple times this frame's inlier noise (0 without it)
  bool residuals_ready() {
    use_depth = options.max_depth_residual_sigmas > T(0) && !depth.empty();
    reprojection_inlier_noise(camera, r);
    const T floor = T(ReprojectionCheckOptions<T>::kNoiseMultiple) * r->inlier_noise_px;
    noise_limit = std::isfinite(floor) ? floor : T(0);
    return true;
  }

  FeatureLabel label(std::size_t, std::size_t i, T limit) {
    const Vec2<T> x = pixel(i);
    const bool dyn = reprojection_label(i, point(i), x.x(), x.y(), std::max(limit, noise_limit), camera,
                                        use_depth ? &depth : nullptr, options, r);
    return dyn ? FeatureLabel::Dynamic : FeatureLabel::Static;  // behind the camera: dynamic
  }
  void finish() {}
};

}  // namespace detail

/// Runs the check on n tracks: points[i] is the 3-D point of track i in any fixed frame (world, or the
/// reference keyframe's camera), pixels[i] its position in the current image; camera: the current
/// image's intrinsics. Non-finite points (no depth) are not evaluated. valid: optional per-track flag;
/// in_box: optional per-track flag (1 = inside a dynamic-class box: excluded from the fit when possible,
/// tighter threshold). depth: the current depth image, used by the depth residual when enabled.
/// InvalidInput (nothing read) when points and pixels differ in size, a given flag view does not hold
/// pixels.size() flags, or the options (ReprojectionCheckOptions::validate), the depth view or the camera
/// are invalid.
/// Writes into `out` (buffers reused).
template <class T, class Points3, class Pixels, class Raw = float>
void check_reprojection(const Points3& points, const Pixels& pixels, const PinholeCamera<T>& camera,
                        const ReprojectionCheckOptions<T>& options, ReprojectionCheckResult<T>* out,
                        FlagView valid = nullptr, FlagView in_box = nullptr,
                        const DepthView<Raw>& depth = DepthView<Raw>{}) {
  static_assert(is_point_container_v<Points3> && is_point_container_v<Pixels>,
                "dyncull::check_reprojection: points and pixels must hold points (see PointTraits)");
  detail::ReprojectionEstimator<T, Points3, Pixels, Raw> reprojection{points, pixels, camera, options, depth, out};
  const detail::ModelCheckRule<T> rule{options.max_residual_px, options.max_residual_in_boxes_px, options.min_tracks,
                                       true, options.min_tracks_outside_boxes};
  detail::check_against_model(reprojection, valid, in_box, rule);
}

/// Convenience overload returning a fresh result.
template <class T, class Points3, class Pixels, class Raw = float>
ReprojectionCheckResult<T> check_reprojection(const Points3& points, const Pixels& pixels, const PinholeCamera<T>& camera,
                                              const ReprojectionCheckOptions<T>& options = {},
                                              FlagView valid = nullptr, FlagView in_box = nullptr,
                                              const DepthView<Raw>& depth = DepthView<Raw>{}) {
  ReprojectionCheckResult<T> r;
  check_reprojection(points, pixels, camera, options, &r, valid, in_box, depth);
  return r;
}

}  // namespace dyncull
