/// @file culler_core.hpp
/// The culler's implementation, templated on the scalar: it owns the evidence the culling pipeline
/// (pipeline.hpp) reads against a reference keyframe: correspondences of each frame's keypoints to the
/// keyframe's by guided descriptor matching (keyframe_matcher.hpp; Mur-Artal, Montiel & Tardos 2015,
/// ORB-SLAM §V-B), the keyframe's 3-D points back-projected from its depth (pinhole, x = z K^-1 u),
/// stable track ids, frames since the keyframe and a keyframe policy. dyncull::Culler (culling/culler.hpp)
/// is CullerCore<float> compiled behind a C++11 header, its public settings mapped onto the full
/// CullerCoreOptions by bind_settings(); C++17 hosts and tests may use CullerCore<double> directly.
///
/// API:
/// @code
///   CullerCore<double> culler(camera, core_options<double>(CullerOptions("recommended")));
///   CullerCoreFrame<double> f;  f.keypoints = points_view(keys);  f.descriptors = ...;  f.depth_m = ...;
///   f.detections = &boxes;  f.cam_from_world = &predicted;  // each optional, see CullerCore::inputs()
///   const CullerResult& r = culler.cull(f);               // r.keep[i]: 1 = static, parallel to keys
/// @endcode
#pragma once

#include "dyncull/core/camera.hpp"
#include "dyncull/core/depth.hpp"
#include "dyncull/core/pixel.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/core/traits.hpp"
#include "dyncull/core/types.hpp"
#include "dyncull/core/views.hpp"
#include "dyncull/culling/culler.hpp"
#include "dyncull/culling/keyframe_matcher.hpp"
#include "dyncull/culling/pipeline.hpp"
#include "dyncull/culling/presets.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace dyncull {

/// The frame checks of the culler and its adapters (opencv/culler.hpp), so that the same input gets the
/// same status and reason whichever containers the host passes.
namespace culler_checks {

/// Largest magnitude of a predicted pose's entry (metres for t): 1e8 m holds any Earth-fixed map
/// (ECEF, UTM) and keeps every entry and its square inside float's range.
constexpr double kMaxPoseEntry = 1e8;
/// Largest deviation of a predicted rotation from orthonormal: max |(R^T R - I)_ij| and |det R - 1|. A
/// float pose composed over a long motion model stays near 1e-6; a scale, shear or sum of rotations is
/// far above.
constexpr double kRotationTolerance = 1e-3;

/// A value in a reason: three significant digits, the same text for a float and a double input.
inline std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

/// Ok, or InvalidInput naming `name`: a given view with a count needs data, and its stride must hold one
/// (x, y) pair.
inline Status check_points(const PointsView& v, const char* name, std::string* why) {
  if (!v.given) return Status::Ok;
  if (v.count > 0 && v.data == nullptr)
    return (*why = std::string(name) + ": null data with a count of " + std::to_string(v.count), Status::InvalidInput);
  const std::size_t pair = v.is_double ? 2 * sizeof(double) : 2 * sizeof(float);
  if (v.stride_bytes != 0 && v.stride_bytes < pair)
    return (*why = std::string(name) + ": stride_bytes " + std::to_string(v.stride_bytes) + " is below the " +
                   std::to_string(pair) + " bytes of an x, y pair",
            Status::InvalidInput);
  return Status::Ok;
}

/// A predicted pose cam_from_world as R (row-major) and t, read in double before any conversion: NonFinite
/// for a NaN or Inf entry; InvalidInput for an entry beyond kMaxPoseEntry or an R that is not a rotation
/// (orthonormal with det +1 within kRotationTolerance: a zero, scaled, sheared or reflected R). The
/// reason names `name`.
inline Status check_pose(const double R[9], const double t[3], const char* name, std::string* why) {
  const auto n = [name] { return std::string(name); };  // text only on failure: no allocation per frame
  for (int k = 0; k < 12; ++k) {
    const double v = k < 9 ? R[k] : t[k - 9];
    if (!std::isfinite(v)) return (*why = n() + " has a NaN or Inf entry", Status::NonFinite);
  }
  for (int k = 0; k < 12; ++k) {
    const double v = k < 9 ? R[k] : t[k - 9];
    if (std::abs(v) > kMaxPoseEntry)
      return (*why = n() + " has an entry of " + number(v) + ", out of the range [-1e8, 1e8] of a pose",
              Status::InvalidInput);
  }
  double deviation = 0;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      double dot = 0;
      for (int r = 0; r < 3; ++r) dot += R[3 * r + a] * R[3 * r + b];
      const double d = std::abs(dot - (a == b ? 1.0 : 0.0));
      deviation = d > deviation ? d : deviation;
    }
  const double det = R[0] * (R[4] * R[8] - R[5] * R[7]) - R[1] * (R[3] * R[8] - R[5] * R[6]) +
                     R[2] * (R[3] * R[7] - R[4] * R[6]);
  if (deviation > kRotationTolerance || std::abs(det - 1.0) > kRotationTolerance)
    return (*why = n() + "'s rotation is not a rotation (R^T R differs from I by " + number(deviation) +
                   ", det R = " + number(det) + "; a rigid pose has 0 and 1 within 1e-3)",
            Status::InvalidInput);
  return Status::Ok;
}

/// check_pose on a Rigid3.
template <class T>
Status check_pose(const Rigid3<T>& pose, const char* name, std::string* why) {
  double R[9], t[3];
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) R[3 * r + c] = static_cast<double>(pose.R(r, c));
    t[r] = static_cast<double>(pose.t(r));
  }
  return check_pose(R, t, name, why);
}

}  // namespace culler_checks

template <class T>
struct CullerCoreOptions {
  PipelineOptions<T> pipeline = presets::recommended<T>();
  KeyframePolicy keyframe_policy = KeyframePolicy::Own;
  /// Own policy: a new keyframe when the predicted pose is further than this from the keyframe's ...
  /// (the demo front end's 0.1 m: shorter baselines lowered its ATE on translating sequences)
  double keyframe_max_translation_m = 0.1;
  double keyframe_max_rotation_deg = 15.0;   ///< ... or turned more than this ...
  /// ... or fewer than this share of the keypoints matched the keyframe's. Lower than the demo's 0.5 of
  /// its LK tracks: a detector that re-detects every frame matches about half of its keypoints one frame
  /// later (repeatability, and movers the pose-guided search does not find), so at 0.5 nearly every
  /// frame would be a keyframe and the evidence a one-frame baseline, on which the recommended preset
  /// leaves the decision to the box rule (subbox.min_evidence_frames). A host that keeps its tracks
  /// between its own keyframes (new corners only there) matches fewer of them to the culler's keyframe:
  /// about 0.6 suits it (the dynamic_vo demo's culler strategy).
  double keyframe_min_matched_ratio = 0.3;
  KeyframeMatchOptions matching{};
  /// Keyframe depth used for its 3-D points: the TUM sensor's reliable range, and no point within
  /// kDepthEdgeRadiusPx of a depth step above kMaxDepthStepRatio (it back-projects half on the object,
  /// half behind it). Why you would change the range: a sensor with another one.
  float min_depth_m = 0.4f;
  float max_depth_m = 8.f;
  static constexpr int kDepthEdgeRadiusPx = 1;
  static constexpr double kMaxDepthStepRatio = 0.05;
  /// The camera has lens distortion: every frame must carry CullerFrame::undistorted_keypoints, which the
  /// geometry (matching, epipolar and reprojection checks, back-projection) uses.
  bool camera_has_distortion = false;

  /// Ok, or InvalidInput with the reason naming the field ("pipeline." / "matching." for nested ones).
  Status validate(std::string* reason = nullptr) const {
    auto bad = [&](const std::string& why) {
      if (reason) *reason = "CullerOptions: " + why;
      return Status::InvalidInput;
    };
    std::string why;
    if (pipeline.validate(&why) != Status::Ok) return bad("pipeline." + why);
    if (matching.validate(&why) != Status::Ok) return bad("matching: " + why);
    if (static_cast<int>(keyframe_policy) > 1) return bad("keyframe_policy must be Own or Host");
    if (!(keyframe_max_translation_m > 0) || !std::isfinite(keyframe_max_translation_m))
      return bad("keyframe_max_translation_m must be positive and finite");
    if (!(keyframe_max_rotation_deg > 0 && keyframe_max_rotation_deg <= 180))
      return bad("keyframe_max_rotation_deg must be in (0, 180]");
    if (!(keyframe_min_matched_ratio >= 0 && keyframe_min_matched_ratio <= 1))
      return bad("keyframe_min_matched_ratio must be in [0, 1]");
    if (!(min_depth_m >= 0.f) || !std::isfinite(min_depth_m) || !(max_depth_m > min_depth_m))
      return bad("min_depth_m must be finite and >= 0, max_depth_m above it");
    if (reason) reason->clear();
    return Status::Ok;
  }
};

/// One frame as the host has it: views it keeps valid during CullerCore::cull. All per-keypoint inputs are
/// parallel to `keypoints`.
template <class T>
struct CullerCoreFrame {
  PointsView keypoints;              ///< image pixels, as detected
  PointsView undistorted_keypoints;  ///< required when CullerOptions::camera_has_distortion
  DescriptorRows descriptors;        ///< one row per keypoint (data null: not given)
  DepthView<float> depth_m;          ///< depth in metres, or ...
  DepthView<std::uint16_t> depth_raw;  ///< ... raw uint16 with units_per_metre (TUM: 5000); neither: monocular
  const std::vector<Detection<T>>* detections = nullptr;  ///< pixel boxes after NMS (empty: none seen)
  const Rigid3<T>* cam_from_world = nullptr;  ///< predicted pose (a motion model is enough)
  /// Host's correspondences: per keypoint the index of its match among the keypoints of the culler's
  /// keyframe (the frame CullerResult::keyframe last reported), -1 for none. Given: no own matching.
  const int* keyframe_match = nullptr;
  bool is_keyframe = false;  ///< KeyframePolicy::Host: this frame becomes the reference after culling
};

/// Owns the reference keyframe and the pipeline state; one per camera stream. Not thread-safe.
template <class T>
class CullerCore {
 public:
  static_assert(std::is_floating_point<T>::value, "dyncull::CullerCore: T is float or double");
  /// Widest descriptor row the keyframe matcher takes (ORB 32, BRISK 64, BinBoost / LATCH up to 64).
  static constexpr std::size_t kMaxDescriptorBytes = 256;

  /// `camera`: the pinhole model of the (undistorted) keypoints; an invalid camera or options make every
  /// cull() return InvalidInput with the reason (status() says it at once).
  explicit CullerCore(const PinholeCamera<T>& camera, const CullerCoreOptions<T>& options = CullerCoreOptions<T>())
      : camera_(camera), options_(options) {
    std::string why;
    if (camera_.validate(&why) != Status::Ok) {
      status_ = Status::InvalidInput;
      reason_ = "camera: " + why + " (no default intrinsics)";
    } else {
      status_ = options_.validate(&reason_);
    }
  }

  Status status() const { return status_; }
  const std::string& reason() const { return reason_; }
  const CullerCoreOptions<T>& options() const { return options_; }
  const PinholeCamera<T>& camera() const { return camera_; }

  /// The inputs this configuration reads; a frame lacking one gets a non-Ok status naming it.
  CullerInputs inputs() const { return inputs_of(options_); }

  /// From what the enabled stages read (culling/stages/declarations.hpp): the culler makes their tracks
  /// (prev_keypoints, points_3d, track_ids) by matching descriptors to its keyframe, and their 3-D points
  /// from the keyframe's depth and pose.
  static CullerInputs inputs_of(const CullerCoreOptions<T>& o) {
    const FrameInputs read = inputs_read(o.pipeline, /*optional=*/true);
    const bool points = reads(read, FrameInput::Points3d);
    const bool tracks = points || reads(read, FrameInput::PrevKeypoints) || reads(read, FrameInput::TrackIds);
    CullerInputs in;
    in.keypoints = true;
    in.descriptors = tracks;
    in.depth = reads(read, FrameInput::Depth) || points;
    in.detections = reads(read, FrameInput::Detections);
    in.pose = reads(read, FrameInput::CamFromWorld) || points || (tracks && o.keyframe_policy == KeyframePolicy::Own);
    return in;
  }

  /// Culls one frame and, when the policy says so, makes it the reference keyframe. The result is valid
  /// until the next call.
  const CullerResult& cull(const CullerCoreFrame<T>& f) {
    CullerResult& r = begin_result(f.keypoints.given ? f.keypoints.count : 0);
    const std::size_t n = r.num_features;
    std::string why;
    Status s = check_frame(f, n, &why);
    if (s != Status::Ok) return refuse_frame(s, why, n);
    const std::string dropped = drop_keyframe_of_another_width(f, &r);
    NonFinite bad;
    read_positions(f, n, &bad);
    const bool have_depth = !f.depth_m.empty() || !f.depth_raw.empty();
    const bool have_pose = f.cam_from_world != nullptr;
    note_missing(f, n, have_depth, have_pose, &r);
    const Rigid3<T> pose = have_pose ? *f.cam_from_world : (have_keyframe_ ? keyframe_pose_ : Rigid3<T>::identity());
    if (!match_keyframe(f, n, pose, have_pose, &why, &s)) return refuse_frame(s, why, n);
    carry_tracks(f, n, &r);
    const bool new_keyframe = decide_keyframe(f, n, pose, r.matched);
    const PipelineResult<T>& pr = run_pipeline(f, have_pose, pose, new_keyframe, &r);
    take_pipeline_result(pr, n, &r);
    if (bad.count[0] > 0) append_non_finite("keypoints", bad.count[0], bad.first[0], &r.reason);
    if (bad.count[1] > 0) append_non_finite("undistorted_keypoints", bad.count[1], bad.first[1], &r.reason);
    if (!dropped.empty()) append(dropped, &r.reason);
    if (!r.reason.empty()) r.status = Status::MissingInput;
    describe(pr, have_pose, have_depth, dropped.empty(), &r);
    if (new_keyframe && pr.keep.size() == n) {
      if (!f.depth_raw.empty())
        store_keyframe(f, f.depth_raw, pose);
      else
        store_keyframe(f, f.depth_m, pose);
      r.keyframe = true;
    } else if (have_keyframe_) {
      ++frames_since_keyframe_;
    }
    return r;
  }

  /// Forgets the keyframe, the tracks and the pipeline's state, as if newly constructed with the same
  /// camera and options (a new sequence, or a host that lost track). Buffers are kept.
  void reset() {
    forget_keyframe();
    state_.reset();
    next_id_ = 0;
    begin_result(0);
  }

  /// Reports the frame of `n` keypoints as refused with `status` and `why` (every keep 1, nothing
  /// culled, no keyframe), as cull() does for an input it cannot read. For the adapters (opencv/culler.hpp)
  /// that read their own containers first: their refusals then match cull()'s field for field.
  const CullerResult& refuse_frame(Status status, std::string why, std::size_t n) {
    CullerResult& r = begin_result(n);
    r.status = status;
    r.reason = std::move(why);
    r.refused = true;
    r.keep.assign(n, 1);
    r.labels.assign(n, FeatureLabel::Static);
    r.reasons.assign(n, CullReason::None);
    r.track_ids.assign(n, -1);
    r.num_kept = n;
    return r;
  }

  /// The last cull()'s result.
  const CullerResult& result() const { return result_; }
  /// The pipeline's full result of the last cull() (per-stage reports, traces).
  const PipelineResult<T>& pipeline_result() const { return state_.result; }
  /// Keypoints of the reference keyframe (geometry positions), in the order CullerFrame::keyframe_match indexes.
  const std::vector<Vec2<T>>& keyframe_keypoints() const { return keyframe_px_; }
  bool has_keyframe() const { return have_keyframe_; }

 private:
  /// Keypoints with a NaN or Inf coordinate: count and first index, [0] in keypoints, [1] only in the
  /// undistorted ones.
  struct NonFinite {
    std::size_t count[2] = {0, 0}, first[2] = {0, 0};
  };

  /// A descriptor width other than the keyframe's cannot be matched to it: the keyframe is forgotten and
  /// this frame starts anew. Returns the reason, or empty.
  std::string drop_keyframe_of_another_width(const CullerCoreFrame<T>& f, CullerResult* r) {
    if (!have_keyframe_ || f.keyframe_match != nullptr || f.descriptors.data == nullptr || keyframe_desc_rows_ == 0 ||
        f.descriptors.row_bytes == keyframe_row_bytes_)
      return std::string();
    forget_keyframe();
    r->frames_since_keyframe = 0;
    return "descriptors: rows of " + std::to_string(f.descriptors.row_bytes) + " bytes where the keyframe's have " +
           std::to_string(keyframe_row_bytes_) + ": not matched, this frame becomes the keyframe";
  }

  /// The positions the geometry reads (cur_px_): undistorted when given; a point non-finite in either
  /// form is NaN there, flagged in non_finite_ and culled at the end.
  void read_positions(const CullerCoreFrame<T>& f, std::size_t n, NonFinite* bad) {
    const PointsView& geo = f.undistorted_keypoints.given ? f.undistorted_keypoints : f.keypoints;
    const T nan = std::numeric_limits<T>::quiet_NaN();
    cur_px_.resize(n);
    non_finite_.assign(n, 0);
    for (std::size_t i = 0; i < n; ++i) {
      // Read in T: a double beyond float's range is an infinity to CullerCore<float>.
      const Vec2<T> raw(static_cast<T>(f.keypoints.x(i)), static_cast<T>(f.keypoints.y(i)));
      const Vec2<T> p = &geo == &f.keypoints ? raw : Vec2<T>(static_cast<T>(geo.x(i)), static_cast<T>(geo.y(i)));
      const bool raw_ok = std::isfinite(raw.x()) && std::isfinite(raw.y());
      const bool geo_ok = std::isfinite(p.x()) && std::isfinite(p.y());
      cur_px_[i] = raw_ok && geo_ok ? p : Vec2<T>(nan, nan);
      if (raw_ok && geo_ok) continue;
      non_finite_[i] = 1;
      const int which = raw_ok ? 1 : 0;  // named by the argument that holds the NaN or Inf
      if (bad->count[which]++ == 0) bad->first[which] = i;
    }
  }

  /// The inputs the configuration reads that this frame lacks.
  void note_missing(const CullerCoreFrame<T>& f, std::size_t n, bool have_depth, bool have_pose, CullerResult* r) const {
    const CullerInputs need = inputs();
    r->missing.depth = need.depth && !have_depth;
    r->missing.detections = need.detections && f.detections == nullptr;
    // A frame without keypoints has no descriptor rows to give: nothing is missing.
    r->missing.descriptors = need.descriptors && n > 0 && f.descriptors.data == nullptr && f.keyframe_match == nullptr;
    r->missing.pose = need.pose && !have_pose;
  }

  /// The correspondences to the keyframe: the host's (check_frame copied them into match_index_) or the
  /// culler's own matching of the descriptors. False (status and reason set) when the matcher refuses.
  bool match_keyframe(const CullerCoreFrame<T>& f, std::size_t n, const Rigid3<T>& pose, bool have_pose,
                      std::string* why, Status* status) {
    if (!have_keyframe_ || f.keyframe_match) return true;
    if (f.descriptors.data == nullptr || keyframe_desc_rows_ == 0) {
      match_.keyframe_index.assign(n, -1);
      return true;
    }
    const Rigid3<T> cam_from_keyframe = pose * keyframe_pose_.inverse();
    match_to_keyframe(keyframe_px_, keyframe_cam_points_,
                      DescriptorRows(keyframe_desc_.data(), keyframe_desc_rows_, 0, keyframe_row_bytes_), cur_px_,
                      f.descriptors, camera_, have_pose ? &cam_from_keyframe : nullptr, options_.matching, match_ws_,
                      &match_);
    if (match_.status != Status::InvalidInput && match_.status != Status::NonFinite) return true;
    *status = match_.status;
    *why = match_.reason;
    return false;
  }

  /// The evidence arrays from the correspondences: a matched keypoint carries its keyframe point's
  /// pixel, 3-D point and track id; any other gets a new id.
  void carry_tracks(const CullerCoreFrame<T>& f, std::size_t n, CullerResult* r) {
    const T nan = std::numeric_limits<T>::quiet_NaN();
    prev_px_.assign(n, Vec2<T>(nan, nan));
    valid_.assign(n, 0);
    points_world_.assign(n, Vec3<T>(nan, nan, nan));
    r->track_ids.resize(n);
    const std::vector<int>& m = f.keyframe_match || !have_keyframe_ ? match_index_ : match_.keyframe_index;
    for (std::size_t i = 0; i < n; ++i) {
      const int k = have_keyframe_ && !non_finite_[i] ? m[i] : -1;
      if (k >= 0) {
        const std::size_t ku = static_cast<std::size_t>(k);
        prev_px_[i] = keyframe_px_[ku];
        valid_[i] = 1;
        points_world_[i] = keyframe_world_points_[ku];
        r->track_ids[i] = keyframe_ids_[ku];
        ++r->matched;
      } else {
        r->track_ids[i] = next_id_++;
      }
    }
  }

  /// Whether this frame becomes the reference keyframe, decided before the pipeline (its multi-view store
  /// takes this frame's static features): the host's flag, or the own policy's motion and match ratio.
  bool decide_keyframe(const CullerCoreFrame<T>& f, std::size_t n, const Rigid3<T>& pose, std::size_t matched) const {
    if (!have_keyframe_) return true;
    if (options_.keyframe_policy == KeyframePolicy::Host) return f.is_keyframe;
    if (options_.keyframe_policy != KeyframePolicy::Own) return false;
    const Rigid3<T> rel = pose * keyframe_pose_.inverse();
    const double moved = static_cast<double>(rel.t.norm());
    const double turned = static_cast<double>(rotation_angle(rel.R)) * Constants<double>::rad_to_deg();
    const double base = static_cast<double>(keyframe_px_.size() < n ? keyframe_px_.size() : n);
    // A keyframe without keypoints (a front end that detects after its first frame) matches nothing and
    // the ratio rule cannot see it: the first frame with keypoints replaces it.
    const bool empty_keyframe = keyframe_px_.empty() && n > 0;
    return empty_keyframe || moved > options_.keyframe_max_translation_m ||
           turned > options_.keyframe_max_rotation_deg ||
           static_cast<double>(matched) < options_.keyframe_min_matched_ratio * base;
  }

  /// cull_frame on the evidence gathered, with the frame's float or 16-bit depth.
  const PipelineResult<T>& run_pipeline(const CullerCoreFrame<T>& f, bool have_pose, const Rigid3<T>& pose,
                                        bool new_keyframe, CullerResult* r) {
    CullingFrame<T, std::vector<Vec2<T>>, std::vector<Vec2<T>>, float, std::vector<Vec3<T>>> pf;
    pf.keypoints = &cur_px_;
    if (have_keyframe_) {
      pf.prev_keypoints = &prev_px_;
      pf.track_valid = valid_;
      // Without a pose the residuals of the 3-D points would be the camera's own motion.
      if (have_pose && keyframe_has_depth_) pf.points_3d = &points_world_;
      pf.evidence_frames = r->frames_since_keyframe;
    }
    pf.track_ids = &r->track_ids;
    pf.detections = f.detections;
    pf.camera = camera_;
    pf.cam_from_world = have_pose ? &pose : nullptr;
    // Only the multi-view check reads the pipeline's keyframe store; filling it otherwise costs allocations.
    pf.is_keyframe = new_keyframe && options_.pipeline.multiview.enabled;
    if (f.depth_raw.empty()) {
      pf.depth = f.depth_m;
      return cull_frame(pf, options_.pipeline, &state_);
    }
    CullingFrame<T, std::vector<Vec2<T>>, std::vector<Vec2<T>>, std::uint16_t, std::vector<Vec3<T>>> pu;
    copy_frame(pf, &pu);
    pu.depth = f.depth_raw;
    return cull_frame(pu, options_.pipeline, &state_);
  }

  /// The pipeline's keep mask, labels and reasons; a non-finite keypoint is culled whatever the stages
  /// and the survivor guard said.
  void take_pipeline_result(const PipelineResult<T>& pr, std::size_t n, CullerResult* r) const {
    r->keep = pr.keep;
    r->labels = pr.labels;
    r->reasons = pr.reasons;
    if (r->keep.size() == n) {
      for (std::size_t i = 0; i < n; ++i) {
        if (!non_finite_[i]) continue;
        r->keep[i] = 0;
        r->labels[i] = FeatureLabel::Dynamic;
        r->reasons[i] = CullReason::InvalidInput;
      }
    }
    r->num_kept = 0;
    for (std::uint8_t k : r->keep) r->num_kept += k != 0;
  }

  /// Clears the result for a frame of n keypoints; frames_since_keyframe as the frame would see it.
  CullerResult& begin_result(std::size_t n) {
    CullerResult& r = result_;
    r.status = Status::Ok;
    r.reason.clear();
    r.refused = false;
    r.missing = CullerInputs{};
    r.num_features = n;
    r.num_kept = 0;
    r.matched = 0;
    r.keyframe = false;
    r.frames_since_keyframe = have_keyframe_ ? frames_since_keyframe_ + 1 : 0;
    if (n == 0) {
      r.keep.clear();
      r.labels.clear();
      r.reasons.clear();
      r.track_ids.clear();
    }
    return r;
  }

  void forget_keyframe() {
    have_keyframe_ = false;
    keyframe_has_depth_ = false;
    frames_since_keyframe_ = 0;
    keyframe_pose_ = Rigid3<T>::identity();
    keyframe_px_.clear();
    keyframe_cam_points_.clear();
    keyframe_world_points_.clear();
    keyframe_ids_.clear();
    keyframe_desc_rows_ = 0;
  }

  static void append(const std::string& part, std::string* s) {
    if (!s->empty()) *s += "; ";
    *s += part;
  }

  static void append_non_finite(const char* name, std::size_t count, std::size_t first, std::string* s) {
    std::string part = std::string(name) + "[" + std::to_string(first) + "]";
    if (count > 1) part += " and " + std::to_string(count - 1) + (count == 2 ? " other" : " others");
    part += count > 1 ? " have" : " has";
    append(part + " a NaN or Inf coordinate: culled", s);
  }

  /// InvalidInput / NonFinite with the reason naming the input, or Ok.
  Status check_frame(const CullerCoreFrame<T>& f, std::size_t n, std::string* why) {
    if (status_ != Status::Ok) return (*why = reason_, status_);
    if (!f.keypoints.given) return (*why = "missing input: keypoints", Status::InvalidInput);
    Status s = culler_checks::check_points(f.keypoints, "keypoints", why);
    if (s != Status::Ok) return s;
    if (options_.camera_has_distortion && !f.undistorted_keypoints.given)
      return (*why = "missing input: undistorted_keypoints (the camera has distortion; the geometry needs them)",
              Status::InvalidInput);
    if (f.undistorted_keypoints.given && f.undistorted_keypoints.count != n)
      return (*why = "undistorted_keypoints has " + std::to_string(f.undistorted_keypoints.count) + " points for " +
                     std::to_string(n) + " keypoints",
              Status::InvalidInput);
    s = culler_checks::check_points(f.undistorted_keypoints, "undistorted_keypoints", why);
    if (s != Status::Ok) return s;
    if (f.descriptors.data != nullptr && f.descriptors.rows != n)
      return (*why = "descriptors has " + std::to_string(f.descriptors.rows) + " rows for " + std::to_string(n) +
                     " keypoints",
              Status::InvalidInput);
    if (f.descriptors.data != nullptr && (f.descriptors.row_bytes == 0 || f.descriptors.stride() < f.descriptors.row_bytes))
      return (*why = "descriptors: row_bytes must be positive and at most the stride", Status::InvalidInput);
    if (f.descriptors.data != nullptr && f.descriptors.row_bytes > kMaxDescriptorBytes)
      return (*why = "descriptors: rows of " + std::to_string(f.descriptors.row_bytes) +
                     " bytes; the keyframe matcher takes 1 to 256",
              Status::InvalidInput);
    if (f.descriptors.data != nullptr && 8 * f.descriptors.row_bytes < static_cast<std::size_t>(options_.matching.max_hamming))
      return (*why = "descriptors: rows of " + std::to_string(f.descriptors.row_bytes) + " bytes (" +
                     std::to_string(8 * f.descriptors.row_bytes) + " bits) are shorter than matching.max_hamming = " +
                     std::to_string(options_.matching.max_hamming) + " bits",
              Status::InvalidInput);
    if (!f.depth_m.empty() && !f.depth_raw.empty())
      return (*why = "depth: give depth_m (metres) or depth_raw (uint16), not both", Status::InvalidInput);
    std::string d;
    if (f.depth_m.validate(&d) != Status::Ok || f.depth_raw.validate(&d) != Status::Ok)
      return (*why = "depth: " + d, Status::InvalidInput);
    const int dw = !f.depth_m.empty() ? f.depth_m.width : f.depth_raw.width;
    const int dh = !f.depth_m.empty() ? f.depth_m.height : f.depth_raw.height;
    if ((!f.depth_m.empty() || !f.depth_raw.empty()) && (dw != camera_.width || dh != camera_.height))
      return (*why = "depth: " + std::to_string(dw) + "x" + std::to_string(dh) + " for an image of " +
                     std::to_string(camera_.width) + "x" + std::to_string(camera_.height),
              Status::InvalidInput);
    if (f.cam_from_world && (s = culler_checks::check_pose(*f.cam_from_world, "cam_from_world", why)) != Status::Ok)
      return s;
    if (f.keyframe_match) {
      const std::size_t nk = have_keyframe_ ? keyframe_px_.size() : 0;
      for (std::size_t i = 0; i < n; ++i) {
        const int k = f.keyframe_match[i];
        if (k < -1 || (k >= 0 && static_cast<std::size_t>(k) >= nk))
          return (*why = "keyframe_match[" + std::to_string(i) + "] = " + std::to_string(k) +
                         " is not -1 or an index of the keyframe's " + std::to_string(nk) + " keypoints",
                  Status::InvalidInput);
      }
      match_index_.assign(f.keyframe_match, f.keyframe_match + n);
    }
    why->clear();
    return Status::Ok;
  }

  template <class A, class B>
  static void copy_frame(const A& a, B* b) {
    b->keypoints = a.keypoints;
    b->prev_keypoints = a.prev_keypoints;
    b->track_valid = a.track_valid;
    b->track_ids = a.track_ids;
    b->points_3d = a.points_3d;
    b->detections = a.detections;
    b->camera = a.camera;
    b->cam_from_world = a.cam_from_world;
    b->is_keyframe = a.is_keyframe;
    b->evidence_frames = a.evidence_frames;
  }

  /// Status and reason after the frame's own (non-finite keypoints, a new descriptor width): the missing
  /// inputs, then the pipeline's. The status is the first non-Ok one.
  void describe(const PipelineResult<T>& pr, bool have_pose, bool have_depth, bool say_first_frame,
                CullerResult* r) const {
    std::string& s = r->reason;
    if (r->missing.any()) {
      r->status = Status::MissingInput;
      append("missing input: " + r->missing.names(), &s);
      if (r->missing.depth)
        s += "; monocular (no depth): the depth mask and the reprojection check did not run, epipolar evidence only";
      if (r->missing.descriptors) s += "; no descriptors and no keyframe_match: no tracks, box evidence only";
      if (r->missing.pose) s += "; no predicted pose: the keyframe's pose stands in (no motion prior)";
      if (r->missing.detections) s += "; no detections: the box stages did not run";
    } else if (!have_pose && have_depth && options_.pipeline.reprojection.enabled) {
      append("no predicted pose: the reprojection check did not run", &s);
    }
    if (!have_keyframe_ && say_first_frame) append("first frame: no keyframe yet, no track evidence", &s);
    if (!pr.ok()) {
      // The worst wins: a stage that could not do its job outranks a missing input.
      if (r->status == Status::Ok || (r->status == Status::MissingInput && pr.status != Status::MissingInput))
        r->status = pr.status;
      append("pipeline: " + pr.reason, &s);
    }
  }

  template <class Raw>
  void store_keyframe(const CullerCoreFrame<T>& f, const DepthView<Raw>& depth, const Rigid3<T>& pose) {
    const std::size_t n = cur_px_.size();
    keyframe_px_.swap(cur_px_);
    keyframe_ids_.assign(result_.track_ids.begin(), result_.track_ids.end());
    keyframe_pose_ = pose;
    const Rigid3<T> world_from_cam = pose.inverse();
    const T nan = std::numeric_limits<T>::quiet_NaN();
    keyframe_cam_points_.assign(n, Vec3<T>(nan, nan, nan));
    keyframe_world_points_.assign(n, Vec3<T>(nan, nan, nan));
    keyframe_has_depth_ = !depth.empty();
    if (keyframe_has_depth_) {
      constexpr int r = CullerCoreOptions<T>::kDepthEdgeRadiusPx;
      for (std::size_t i = 0; i < n; ++i) {
        // Depth where the keypoint is in the image (as detected), ray through its undistorted position.
        int x = 0, y = 0;
        if (!pixel_of(f.keypoints.x(i), f.keypoints.y(i), depth.width, depth.height, &x, &y)) continue;
        if (x < r || y < r || x >= depth.width - r || y >= depth.height - r) continue;
        const float z = depth.depth_m(x, y);
        if (!(z >= options_.min_depth_m && z <= options_.max_depth_m)) continue;
        if (depth_step_near(depth, x, y, r, CullerCoreOptions<T>::kMaxDepthStepRatio)) continue;
        const Vec2<T>& p = keyframe_px_[i];
        if (!std::isfinite(p.x()) || !std::isfinite(p.y())) continue;
        keyframe_cam_points_[i] = camera_.backproject(p, static_cast<T>(z));
        keyframe_world_points_[i] = world_from_cam.apply(keyframe_cam_points_[i]);
      }
    } else {
      keyframe_cam_points_.clear();  // the matcher's "no depth at all"
    }
    keyframe_desc_rows_ = 0;
    if (f.descriptors.data != nullptr) {
      keyframe_row_bytes_ = f.descriptors.row_bytes;
      keyframe_desc_.resize(n * keyframe_row_bytes_);
      for (std::size_t i = 0; i < n; ++i)
        std::memcpy(keyframe_desc_.data() + i * keyframe_row_bytes_, f.descriptors.row(i), keyframe_row_bytes_);
      keyframe_desc_rows_ = n;
    }
    frames_since_keyframe_ = 0;
    have_keyframe_ = true;
  }

  PinholeCamera<T> camera_;
  CullerCoreOptions<T> options_;
  Status status_ = Status::Ok;
  std::string reason_;
  PipelineState<T> state_;
  CullerResult result_;

  // Reference keyframe.
  bool have_keyframe_ = false;
  bool keyframe_has_depth_ = false;
  int frames_since_keyframe_ = 0;
  Rigid3<T> keyframe_pose_;  // cam_from_world
  std::vector<Vec2<T>> keyframe_px_;
  std::vector<Vec3<T>> keyframe_cam_points_, keyframe_world_points_;
  std::vector<std::int64_t> keyframe_ids_;
  std::vector<std::uint8_t> keyframe_desc_;
  std::size_t keyframe_desc_rows_ = 0, keyframe_row_bytes_ = 32;
  std::int64_t next_id_ = 0;

  // Per-frame buffers, reused.
  std::vector<Vec2<T>> cur_px_, prev_px_;
  std::vector<Vec3<T>> points_world_;
  std::vector<std::uint8_t> valid_, non_finite_;
  std::vector<int> match_index_;  // the host's keyframe_match, checked
  KeyframeMatchWorkspace<T> match_ws_;
  KeyframeMatchResult<T> match_;
};

/// A preset of culling/presets.hpp by name into *out; false (and *out untouched) for an unknown name.
template <class T>
bool preset_by_name(const std::string& name, PipelineOptions<T>* out) {
  if (name == "recommended") *out = presets::recommended<T>();
  else if (name == "none") *out = presets::none<T>();
  else if (name == "dld_slam") *out = presets::dld_slam<T>();
  else if (name == "rtd_slam") *out = presets::rtd_slam<T>();
  else if (name == "zhu_2024") *out = presets::zhu_2024<T>();
  else if (name == "dfd_slam") *out = presets::dfd_slam<T>();
  else if (name == "zhang_2023") *out = presets::zhang_2023<T>();
  else return false;
  return true;
}

/// The public settings (CullerOptions) and where each one lives in CullerCoreOptions, with its range:
/// one list, read one way to fill the options from a preset and the other to lay them onto it, so the
/// two cannot drift. visit(name, public field, core field, low, high, low_open) for every numeric setting.
template <class T, class Options, class Core, class Visit>
void bind_settings(Options& pub, Core& core, Visit&& visit) {
  auto& p = core.pipeline;
  visit("keyframe_max_translation_m", pub.keyframe_max_translation_m, core.keyframe_max_translation_m, 0.0, 1e4, true);
  visit("keyframe_max_rotation_deg", pub.keyframe_max_rotation_deg, core.keyframe_max_rotation_deg, 0.0, 180.0, true);
  visit("keyframe_min_matched_ratio", pub.keyframe_min_matched_ratio, core.keyframe_min_matched_ratio, 0.0, 1.0, false);
  visit("min_depth_m", pub.min_depth_m, core.min_depth_m, 0.0, 1e4, false);
  visit("max_depth_m", pub.max_depth_m, core.max_depth_m, 0.0, 1e4, true);
  visit("match_radius_px", pub.match_radius_px, core.matching.radius_px, 0.0, 4096.0, true);
  visit("match_max_hamming", pub.match_max_hamming, core.matching.max_hamming, 0.0, 2048.0, false);
  visit("box_padding_px", pub.box_padding_px, p.detections.box_padding_px, 0.0, 1e4, false);
  visit("min_box_confidence", pub.min_box_confidence, p.detections.min_confidence, 0.0, 1.0, false);
  visit("min_person_confidence", pub.min_person_confidence, p.detections.min_confidence_person, 0.0, 1.0, false);
  visit("box_memory_frames", pub.box_memory_frames, p.tracker.max_missed_frames, 0.0, 1000.0, false);
  visit("max_epipolar_distance_px", pub.max_epipolar_distance_px, p.moving_consistency.max_epipolar_distance_px, 0.0,
        1e4, true);
  visit("max_epipolar_distance_in_boxes_px", pub.max_epipolar_distance_in_boxes_px,
        p.moving_consistency.max_epipolar_distance_in_boxes_px, 0.0, 1e4, true);
  visit("max_reprojection_px", pub.max_reprojection_px, p.reprojection.max_residual_px, 0.0, 1e4, true);
  visit("max_reprojection_in_boxes_px", pub.max_reprojection_in_boxes_px, p.reprojection.max_residual_in_boxes_px,
        0.0, 1e4, true);
  visit("max_depth_residual_sigmas", pub.max_depth_residual_sigmas, p.reprojection.max_depth_residual_sigmas, 0.0, 1e4,
        false);
  visit("object_depth_band_m", pub.object_depth_band_m, p.depth_mask.eps_m, 0.0, 1e4, false);
  visit("subbox_dynamic_ratio", pub.subbox_dynamic_ratio, p.subbox.sigma1, 0.0, 1.0, false);
  visit("whole_box_min_dynamic_cells", pub.whole_box_min_dynamic_cells, p.subbox.sigma2, 0.0, 64.0, false);
  visit("static_history_min_frames", pub.static_history_min_frames, p.static_history.min_frames, 1.0, 1e6, false);
  visit("static_history_max_residual_px", pub.static_history_max_residual_px, p.static_history.max_residual_px, 0.0,
        1e4, false);
  visit("multiview_depth_threshold_m", pub.multiview_depth_threshold_m, p.multiview.depth_threshold_m, 0.0, 1e4, true);
  visit("multiview_max_parallax_deg", pub.multiview_max_parallax_deg, p.multiview.max_parallax_deg, 0.0, 180.0, true);
  visit("probability_threshold", pub.probability_threshold, p.probability.threshold, 0.0, 1.0, false);
  visit("min_survivors", pub.min_survivors, p.guard.min_survivors, 0.0, 1e9, false);
  visit("min_survivor_fraction", pub.min_survivor_fraction, p.guard.min_fraction, 0.0, 1.0, false);
}

namespace detail {
struct CopyToPublic {
  template <class P, class C>
  void operator()(const char*, P& pub, const C& core, double, double, bool) const { pub = static_cast<P>(core); }
};
struct CopyToCore {
  template <class P, class C>
  void operator()(const char*, const P& pub, C& core, double, double, bool) const { core = static_cast<C>(pub); }
};
}  // namespace detail

/// The public class lists from a level table (ids in order).
inline void class_lists_from(const MotionLevelTable& table, CullerOptions* o) {
  o->high_level_classes.clear();
  o->medium_level_classes.clear();
  o->low_level_classes.clear();
  for (std::size_t id = 0; id < table.size(); ++id) {
    const MotionLevel level = table.level(static_cast<int>(id));
    std::vector<int>* list = level == MotionLevel::High     ? &o->high_level_classes
                             : level == MotionLevel::Medium ? &o->medium_level_classes
                             : level == MotionLevel::Low    ? &o->low_level_classes
                                                            : nullptr;
    if (list) list->push_back(static_cast<int>(id));
  }
}

/// The level table of the public class lists: COCO-80's names, every class not listed ignored.
inline MotionLevelTable class_table_of(const CullerOptions& o) {
  MotionLevelTable table(coco80_names(), MotionLevel::Ignore);
  for (int id : o.low_level_classes) table.set(id, MotionLevel::Low);
  for (int id : o.medium_level_classes) table.set(id, MotionLevel::Medium);
  for (int id : o.high_level_classes) table.set(id, MotionLevel::High);
  return table;
}

/// Fills the public settings with the values of `core` (a preset's).
template <class T>
void settings_from_core(const CullerCoreOptions<T>& core, CullerOptions* o) {
  CullerCoreOptions<T> c = core;
  bind_settings<T>(*o, c, detail::CopyToPublic());
  o->keyframe_policy = core.keyframe_policy;
  class_lists_from(core.pipeline.levels, o);
}

/// The full options of the culler: the preset named by `o` (recommended when the name is unknown) with
/// the public settings laid over it.
template <class T>
CullerCoreOptions<T> core_options(const CullerOptions& o) {
  CullerCoreOptions<T> core;
  preset_by_name(o.preset(), &core.pipeline);
  CullerOptions pub = o;
  bind_settings<T>(pub, core, detail::CopyToCore());
  core.keyframe_policy = o.keyframe_policy;
  core.pipeline.levels = class_table_of(o);
  return core;
}

}  // namespace dyncull
