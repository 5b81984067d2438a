/// @file pipeline_types.hpp
/// Options, per-frame input and result of the culling pipeline (pipeline.hpp), which composes the
/// semantic (Zhu et al. 2024, Zhang et al. 2023; DLD-SLAM 2024 depth mask and probability) and geometric
/// (DFD-SLAM 2024 epipolar + sub-box, RTD-SLAM 2024 multi-view) strategies in front-end order.
#pragma once

#include "dyncull/core/box.hpp"
#include "dyncull/core/camera.hpp"
#include "dyncull/core/depth.hpp"
#include "dyncull/core/flags.hpp"
#include "dyncull/core/mask.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/core/traits.hpp"
#include "dyncull/core/types.hpp"
#include "dyncull/culling/box_rule.hpp"
#include "dyncull/culling/box_tracker.hpp"
#include "dyncull/culling/coherent_motion.hpp"
#include "dyncull/culling/depth_mask.hpp"
#include "dyncull/culling/detections.hpp"
#include "dyncull/culling/dynamic_probability.hpp"
#include "dyncull/culling/labels.hpp"
#include "dyncull/culling/motion_levels.hpp"
#include "dyncull/culling/moving_consistency.hpp"
#include "dyncull/culling/reprojection_check.hpp"
#include "dyncull/culling/multiview_check.hpp"
#include "dyncull/culling/static_history.hpp"
#include "dyncull/culling/subbox_memory.hpp"
#include "dyncull/culling/subbox_refine.hpp"
#include "dyncull/culling/validation.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace dyncull {

/// What happens to features still labelled Candidate (medium-level boxes, 001 §III.D) at the end.
enum class CandidatePolicy : std::uint8_t {
  Keep = 0,  ///< static: only proven motion culls them
  Cull,      ///< dynamic: treat medium-level objects as moving (004 Algorithm 1)
  Verify,    ///< dynamic only when a geometric stage flags the feature, else static (001)
};

/// What the minimum-survivor guard did.
enum class GuardAction : std::uint8_t { None = 0, Softened, Undone };

constexpr const char* to_string(GuardAction a) noexcept {
  switch (a) {
    case GuardAction::None: return "none";
    case GuardAction::Softened: return "softened";
    case GuardAction::Undone: return "undone";
  }
  return "unknown";
}

/// Which strategies run and their options. presets.hpp builds the papers' configurations.
template <class T>
struct PipelineOptions {
  bool use_detection_filter = true;   ///< padding and class-dependent confidence (detections.hpp)
  bool use_box_tracker = false;       ///< carry missed boxes forward (Dynamic-VINS)
  bool use_box_rule = true;           ///< 002 Table 2 / 004 Algorithm 1
  bool use_depth_mask = false;        ///< 000 eq. 1-2: box culls limited to the object's depth band
  bool use_probability = false;       ///< 000 eq. 3-5 for features in object masks (needs tracks)
  bool use_moving_consistency = true; ///< 003 eq. 1-3 (needs tracks)
  /// RGB-D reprojection check (reprojection_check.hpp; needs CullingFrame::points_3d): its labels join
  /// the epipolar ones as the geometric evidence (see reprojection_evidence).
  bool use_reprojection = false;
  bool use_subbox = true;             ///< 003 Algorithm 1 (needs the moving-consistency labels)
  bool use_multiview = false;         ///< 001 §III.A (needs the current pose and a keyframe)

  DetectionOptions<T> detections{};
  BoxTrackerOptions<T> tracker{};
  MotionLevelTable levels = MotionLevelTable::coco80();
  BoxRuleOptions<T> box_rule{};
  DepthMaskOptions depth_mask{};
  DynamicProbabilityOptions<T> probability{};
  /// Flow model of the probability's M term: Fundamental reuses the moving-consistency F when it ran.
  FlowModel probability_flow_model = FlowModel::Fundamental;
  MovingConsistencyOptions<T> moving{};
  ReprojectionCheckOptions<T> reprojection{};
  /// How the reprojection labels combine with the epipolar ones when both ran: Replace (the residual
  /// sees the motion along the epipolar line too, so it alone decides) or Either (dynamic when either
  /// check flags the track, static when one says static and the other does not flag it).
  enum class Evidence { Replace, Either } reprojection_evidence = Evidence::Replace;
  SubBoxOptions<T> subbox{};
  MultiViewOptions<T> multiview{};
  std::size_t max_reference_keyframes = 2;  ///< keyframes checked per frame (DynaSLAM: 5)

  CandidatePolicy candidates = CandidatePolicy::Verify;
  /// Epipolar-dynamic features outside every dynamic-class box are culled (DS-SLAM) or only used as
  /// evidence inside boxes (false: an unexplained flow outlier outside boxes is more often LK error).
  bool cull_geometric_outside_boxes = true;
  /// Multi-view-dynamic features are culled wherever they are (DynaSLAM); false: only candidates.
  bool multiview_overrides_static = true;
  /// Run the sub-box refinement only when F was fitted on tracks outside the dynamic-class boxes
  /// (or no track lay inside one). An F fitted through a large mover absorbs its motion (measured in
  /// docs/algorithms.md), and the refinement would then clear the whole box.
  bool subbox_requires_fit_outside_boxes = true;
  /// Medium-level candidates (a chair) are culled by a dynamic sub-box of their region (true), or only
  /// on their own evidence, their epipolar distance or the multi-view check (false): a chair under a
  /// seated person or behind a walker otherwise inherits the person's sub-box vote.
  bool subbox_verifies_candidates = true;

  /// A feature held by the depth masks of several dynamic-class boxes (a chair in front of a walker,
  /// a walker passing a chair) belongs to the one whose object depth d_c is nearest its own depth, and
  /// takes that box's level: a static chair's features are then candidates verified on their own
  /// evidence instead of inheriting the walker's label and sub-box vote. The same applies to a
  /// feature in a person's box but only in a chair's mask. false: the box rule's label (highest level
  /// of the rectangles holding it) stands.
  bool assign_overlaps_by_depth = false;
  /// With assign_overlaps_by_depth: a high-level object (a person) takes the feature unless another
  /// object's d_c is nearer its depth by more than this: a seated person's torso and its chair lie at
  /// nearly the same depth, and the torso's features would go to the chair. 0 = nearest d_c only.
  double overlap_high_level_margin_m = 0;
  /// A low-level box (a TV) shelters a feature that a dynamic-class object's depth mask holds only when
  /// the feature's depth is at least as near the low-level object's depth as that object's d_c: a walker
  /// passing in front of a TV is not on it, and 002/004's rule would keep its features. The low-level
  /// object's depth is its box's d_c (000's centre sample, re-estimated from the pixels outside a nearer
  /// box that covers its centre: DepthMaskOptions::occluded_centre_search); without a depth there the
  /// shelter stands. Needs the depth mask.
  bool low_override_by_depth = false;
  /// Sub-box memory (subbox_memory.hpp): a sub-box its own features voted dynamic stays dynamic for this
  /// many frames in the same tracked box, for the tracks flagged in that time or younger than it. 0 = off.
  /// Needs the box tracker (use_box_tracker) and CullingFrame::track_ids; without them the stage report
  /// says so and the vote is this frame's only.
  int subbox_memory_frames = 0;
  /// An epipolar flag of a feature with a depth step above edge_depth_step_ratio within this many
  /// pixels (sampled every 2 px) is not evidence (its moving-consistency label becomes Candidate): an LK
  /// window straddling an occlusion edge follows the contour, not a 3-D point, and is flagged although
  /// its surface is static. 0 = off. Needs the depth image.
  int edge_evidence_radius_px = 0;
  double edge_depth_step_ratio = 0.05;

  /// Shortest baseline, in frames (CullingFrame::evidence_frames), at which the geometric labels may make
  /// part of a dynamic-class box static through the sub-box vote. Over fewer frames a slow mover has not
  /// moved past the thresholds (a walker at 0.4 m/s covers 13 mm a frame, at 2.5 m about 2.8 px sideways
  /// and nothing along the ray), so "not flagged" says nothing: the sub-box refinement is skipped and the
  /// box rule decides (high-level objects culled, candidates on their own flags). A front end that
  /// measures against its keyframe has such frames right after each keyframe, when its corners on the
  /// movers are new. 0 = off; frames with evidence_frames 0 (unknown) are never affected.
  int min_evidence_frames = 0;
  /// With min_evidence_frames: in a frame whose baseline is too short, the cells of a tracked box (box
  /// tracker) keep the states of its last vote within min_evidence_frames frames, where there was one:
  /// static where none of that cell's features was flagged (a seated person's still legs), dynamic where
  /// it voted dynamic; the box rule decides elsewhere and in boxes without such a vote (a walker just
  /// come into view). Needs the box tracker; without it the box rule decides.
  bool short_baseline_keeps_last_vote = false;
  /// Cell-level evidence before the sub-box vote (coherent_motion.hpp): in a cell of a high-level object
  /// (features the box rule labelled Dynamic; candidates such as chairs stay on their own evidence) whose
  /// features' reprojection residuals share a significant median, every feature counts as flagged, so the
  /// vote culls a seated person's sway that no single residual shows. Needs the reprojection check; runs
  /// with the sub-box refinement, on its grid.
  bool use_coherent_motion = false;
  CoherentMotionOptions<T> coherent_motion{};
  /// Track history (static_history.hpp; off while min_frames is 0): a feature culled only for the region it
  /// lies in (its box, its medium-level box, a tracked box or its sub-box) stays static when the reprojection
  /// check said Static with a residual below max_residual_px in each of its last min_frames evaluated frames
  /// (baseline of at least min_evidence_frames, or unknown) and does not flag it now. Needs
  /// CullingFrame::track_ids and the reprojection check.
  StaticHistoryOptions<T> static_history{};

  /// Minimum-survivor guard: if fewer than max(min_survivor_fraction * n, min_survivors) features stay
  /// static, first soften (restore the culls of single geometric stages and of candidates), then undo
  /// all culling. ORB-SLAM2 loses tracking below ~30 local-map inliers; SG-SLAM guards at 10 %.
  bool survivor_guard = true;
  double min_survivor_fraction = 0.10;
  std::size_t min_survivors = 30;

  static constexpr std::size_t kMaxReferenceKeyframes = 64;  ///< upper bound of max_reference_keyframes
  static constexpr int kMaxEdgeEvidenceRadiusPx = 64;        ///< upper bound of edge_evidence_radius_px

  /// InvalidInput naming the first field out of its range, nested fields as "depth_mask.histogram_bin_m":
  /// every nested options struct that has a validate() passes it (whether its stage is on or not);
  /// enums in range; max_reference_keyframes <= kMaxReferenceKeyframes; edge_evidence_radius_px in
  /// [0, kMaxEdgeEvidenceRadiusPx]; edge_depth_step_ratio and overlap_high_level_margin_m finite and >= 0;
  /// subbox_memory_frames and min_evidence_frames in [0, 65535]; min_survivor_fraction in [0, 1].
  Status validate(std::string* reason = nullptr) const {
    using detail::finite_in;
    using detail::invalid_option;
    using detail::validate_nested;
    // Nested structs first, in stage order; the first failure's reason stands.
    if (validate_nested(detections, "detections", reason) != Status::Ok ||
        validate_nested(tracker, "tracker", reason) != Status::Ok ||
        validate_nested(levels, "levels", reason) != Status::Ok ||
        validate_nested(box_rule, "box_rule", reason) != Status::Ok ||
        validate_nested(depth_mask, "depth_mask", reason) != Status::Ok ||
        validate_nested(probability, "probability", reason) != Status::Ok ||
        validate_nested(moving, "moving", reason) != Status::Ok ||
        validate_nested(reprojection, "reprojection", reason) != Status::Ok ||
        validate_nested(subbox, "subbox", reason) != Status::Ok ||
        validate_nested(multiview, "multiview", reason) != Status::Ok ||
        validate_nested(coherent_motion, "coherent_motion", reason) != Status::Ok ||
        validate_nested(static_history, "static_history", reason) != Status::Ok)
      return Status::InvalidInput;
    if (static_cast<int>(probability_flow_model) > 2)
      return invalid_option(reason, "probability_flow_model", "must be MeanFlow, Fundamental or Homography");
    if (static_cast<int>(reprojection_evidence) > 1)
      return invalid_option(reason, "reprojection_evidence", "must be Replace or Either");
    if (static_cast<int>(candidates) > 2) return invalid_option(reason, "candidates", "must be Keep, Cull or Verify");
    if (max_reference_keyframes > kMaxReferenceKeyframes)
      return invalid_option(reason, "max_reference_keyframes", "must be at most 64");
    if (!finite_in(overlap_high_level_margin_m, 0, 1e4))
      return invalid_option(reason, "overlap_high_level_margin_m", "must be finite and in [0, 1e4] m");
    if (subbox_memory_frames < 0 || subbox_memory_frames > 0xFFFF)
      return invalid_option(reason, "subbox_memory_frames", "must be in [0, 65535]");
    if (edge_evidence_radius_px < 0 || edge_evidence_radius_px > kMaxEdgeEvidenceRadiusPx)
      return invalid_option(reason, "edge_evidence_radius_px", "must be in [0, 64]");
    if (!finite_in(edge_depth_step_ratio, 0, 1e30))
      return invalid_option(reason, "edge_depth_step_ratio", "must be finite and >= 0");
    if (min_evidence_frames < 0 || min_evidence_frames > 0xFFFF)
      return invalid_option(reason, "min_evidence_frames", "must be in [0, 65535]");
    if (!finite_in(min_survivor_fraction, 0, 1))
      return invalid_option(reason, "min_survivor_fraction", "must be in [0, 1]");
    if (reason) reason->clear();
    return Status::Ok;
  }
};

/// Outcome of one stage in one frame. status: Ok (ran), Skipped (disabled, nothing to do this frame, or an
/// earlier stage it builds on did not run), MissingInput (enabled, but an input of the frame it needs was
/// not given: the reason names it), or the stage's own failure.
struct StageReport {
  bool enabled = false;
  Status status = Status::Skipped;
  std::string reason;
  std::size_t num_dynamic = 0;  ///< features this stage labelled Dynamic (before combination)
  bool ran() const { return enabled && status == Status::Ok; }
};

/// What the stages saw of one feature this frame (diagnostics: which stage left a kept feature static).
struct FeatureTrace {
  FeatureLabel semantic = FeatureLabel::Static;     ///< after the box rule, depth masks and probability
  FeatureLabel geometric = FeatureLabel::Candidate; ///< geometric evidence with the cell flags (Candidate: none)
  std::uint8_t in_dynamic_box = 0;  ///< in a dynamic-class box (after the depth-mask assignment)
  std::uint8_t in_object = 1;       ///< in its box's depth-mask object (1 when the mask did not run)
  std::uint8_t history_kept = 0;    ///< kept static by its track's static history
};

/// Per-frame result: labels for the caller's keypoint vector (same order), why, and per-stage counts.
/// status: Ok; MissingInput when an enabled stage could not run for lack of an input of the frame (reason:
/// "stage: input" for each, as the stage's option is named, joined with "; "), the labels and keep mask then
/// being those of the stages that ran; InvalidInput when the frame could not be culled at all (nothing
/// culled). labelled(): the labels are usable (Ok or MissingInput).
template <class T>
struct PipelineResult {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }
  bool labelled() const { return status == Status::Ok || status == Status::MissingInput; }

  std::vector<FeatureLabel> labels;  ///< Static or Dynamic (Candidates are resolved by CandidatePolicy)
  std::vector<CullReason> reasons;   ///< deciding strategy (None for untouched statics)
  std::vector<std::uint8_t> keep;    ///< 1 = static: apply to every parallel per-keypoint array
  std::size_t num_features = 0, num_static = 0, num_dynamic = 0;
  StageReport detections, tracker, box_rule, depth_mask, probability, moving_consistency, reprojection,
      coherent_motion, subbox, multiview;
  StageReport static_history;       ///< PipelineOptions::static_history
  std::size_t history_kept = 0;     ///< features the static history kept against a region's cull
  std::size_t unsheltered = 0;      ///< features low_override_by_depth took out of a low-level box's shelter
  GuardAction guard = GuardAction::None;
  std::size_t guard_restored = 0;   ///< features the guard turned back to static
  std::vector<FeatureTrace> trace;  ///< per feature, parallel to labels
};


/// One frame as the front end has it. Keypoints: the caller's container (cv::KeyPoint, Eigen, ...);
/// prev_keypoints: previous-frame positions parallel to keypoints (any point container), with
/// track_valid (not given = all valid; else one flag per keypoint, checked); nothing is copied out of them
/// except into scratch buffers.
/// points_3d: optional 3-D point of each track in one fixed frame (the map point, or the reference
/// keyframe's back-projection in world or keyframe coordinates), parallel to keypoints, non-finite where
/// there is none; used by the reprojection check.
template <class T, class Keypoints, class Prev = Keypoints, class Raw = float, class Points3 = std::vector<Vec3<T>>>
struct CullingFrame {
  const Keypoints* keypoints = nullptr;
  const Prev* prev_keypoints = nullptr;
  FlagView track_valid{};
  const std::vector<std::int64_t>* track_ids = nullptr;  ///< for the probability's K term (optional)
  const Points3* points_3d = nullptr;                     ///< for the reprojection check (optional)
  const std::vector<Detection<T>>* detections = nullptr;  ///< pixel boxes after NMS
  DepthView<Raw> depth{};
  PinholeCamera<T> camera{};
  const Rigid3<T>* cam_from_world = nullptr;  ///< current pose (a motion-model prediction is enough)
  bool is_keyframe = false;  ///< store this frame's static features with depth as a multi-view reference
  /// Frames between the reference of prev_keypoints / points_3d and this frame (1: the previous frame;
  /// a keyframe-based front end: frames since its keyframe); 0 = unknown. See min_evidence_frames.
  int evidence_frames = 0;
};

namespace detail {
inline bool is_soft_cull(CullReason r) {
  return r == CullReason::Epipolar || r == CullReason::Reprojection || r == CullReason::MultiView ||
         r == CullReason::SubBox || r == CullReason::CoherentMotion || r == CullReason::MediumLevelBox ||
         r == CullReason::TrackedBox;
}

/// Culls for the region a feature lies in (its box, tracked box or sub-box), not for its own evidence: the
/// ones a track's static history may overrule (PipelineOptions::static_history).
inline bool is_regional_cull(CullReason r) {
  return r == CullReason::SubBox || r == CullReason::CoherentMotion || r == CullReason::HighLevelBox ||
         r == CullReason::TrackedBox || r == CullReason::MediumLevelBox;
}

template <class T, class Keypoints>
bool keypoint_in_image(const Keypoints& kp, std::size_t i, int w, int h, int* u, int* v) {
  return pixel_of(point_x<T>(kp[i]), point_y<T>(kp[i]), w, h, u, v);
}
}  // namespace detail

}  // namespace dyncull
