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
#include "dyncull/culling/static_history.hpp"
#include "dyncull/culling/stages/list.hpp"
#include "dyncull/culling/stages/stage.hpp"
#include "dyncull/culling/subbox_refine.hpp"
#include "dyncull/culling/validation.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace dyncull {

/// What happens to features still labelled Candidate (medium-level boxes, RTD-SLAM §III.D) at the end.
enum class CandidatePolicy : std::uint8_t {
  Keep = 0,  ///< static: only proven motion culls them
  Cull,      ///< dynamic: treat medium-level objects as moving (Zhang et al. 2023 Algorithm 1)
  Verify,    ///< dynamic only when a geometric stage flags the feature, else static (RTD-SLAM)
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

/// The detection filter's options (detections.hpp) with its switch.
template <class T>
struct DetectionStageOptions : DetectionOptions<T> {
  bool enabled = true;  ///< padding and class-dependent confidence
};

/// The box tracker's options (box_tracker.hpp) with its switch: missed dynamic-class boxes carried
/// forward (Dynamic-VINS).
template <class T>
struct TrackerStageOptions : BoxTrackerOptions<T> {
  bool enabled = false;
};

/// The box rule's options (Zhu et al. 2024 Table 2 / Zhang et al. 2023 Algorithm 1) with its switch.
template <class T>
struct BoxRuleStageOptions : BoxRuleOptions<T> {
  bool enabled = true;
};

/// The depth mask (DLD-SLAM eq. 1-2: box culls limited to the object's depth band) with its switch and the
/// decisions that need the objects' depths.
struct DepthMaskStageOptions : DepthMaskOptions {
  bool enabled = false;
  /// A feature held by the depth masks of several dynamic-class boxes (a chair in front of a walker)
  /// belongs to the one whose object depth d_c is nearest its own depth, and takes that box's level: a
  /// static chair's features are then candidates verified on their own evidence instead of inheriting
  /// the walker's label. false: the box rule's label (highest level of the rectangles holding it) stands.
  bool assign_overlaps_by_depth = false;
  /// With assign_overlaps_by_depth: a high-level object (a person) takes the feature unless another
  /// object's d_c is nearer its depth by more than this (a seated person's torso and its chair lie at
  /// nearly the same depth). 0 = nearest d_c only.
  double overlap_high_level_margin_m = 0;
  /// A low-level box (a TV) shelters a feature that a dynamic-class object's depth mask holds only when
  /// the feature's depth is at least as near the low-level object's d_c (re-estimated outside a nearer box
  /// covering its centre: occluded_centre_search) as the object's: a walker passing in front of a TV is
  /// not on it. Without a depth there the shelter stands.
  bool low_override_by_depth = false;
  /// Head band: detectors often cut a walker's head off the top of its box. A feature in the band of this
  /// fraction of the box's height above a high-level box (its columns) belongs to that person when its
  /// depth lies within head_band_depth_tolerance_m of the box's object depth d_c (the background above a
  /// box is usually farther); it then follows the top row of the box's sub-box vote. 0 = no band.
  double head_band_fraction = 0;
  double head_band_depth_tolerance_m = 0.3;

  /// DepthMaskOptions::validate, then overlap_high_level_margin_m finite and in [0, 1e4] m, the head band's
  /// fraction in [0, 1] and its tolerance in [0, 1e4] m.
  Status validate(std::string* reason = nullptr) const {
    if (DepthMaskOptions::validate(reason) != Status::Ok) return Status::InvalidInput;
    if (!detail::finite_in(overlap_high_level_margin_m, 0, 1e4))
      return detail::invalid_option(reason, "overlap_high_level_margin_m", "must be finite and in [0, 1e4] m");
    if (!detail::finite_in(head_band_fraction, 0, 1))
      return detail::invalid_option(reason, "head_band_fraction", "must be finite and in [0, 1]");
    if (!detail::finite_in(head_band_depth_tolerance_m, 0, 1e4))
      return detail::invalid_option(reason, "head_band_depth_tolerance_m", "must be finite and in [0, 1e4] m");
    if (reason) reason->clear();
    return Status::Ok;
  }
};

/// The dynamic probability (DLD-SLAM eq. 3-5, features in object masks; needs tracks) with its switch.
template <class T>
struct ProbabilityStageOptions : DynamicProbabilityOptions<T> {
  bool enabled = false;
  /// Flow model of the M term: Fundamental reuses the moving-consistency F when it ran (DLD-SLAM: MeanFlow).
  FlowModel flow_model = FlowModel::Fundamental;

  /// DynamicProbabilityOptions::validate, then flow_model in range.
  Status validate(std::string* reason = nullptr) const {
    if (DynamicProbabilityOptions<T>::validate(reason) != Status::Ok) return Status::InvalidInput;
    if (static_cast<int>(flow_model) > 2)
      return detail::invalid_option(reason, "flow_model", "must be MeanFlow, Fundamental or Homography");
    if (reason) reason->clear();
    return Status::Ok;
  }
};

/// The epipolar moving-consistency check (DFD-SLAM eq. 1-3; needs tracks) with its switch.
template <class T>
struct MovingConsistencyStageOptions : MovingConsistencyOptions<T> {
  bool enabled = true;
};

/// The RGB-D reprojection check (reprojection_check.hpp; needs CullingFrame::points_3d) with its switch.
/// Where it runs its labels replace the epipolar ones: the residual also sees the motion along the
/// epipolar line.
template <class T>
struct ReprojectionStageOptions : ReprojectionCheckOptions<T> {
  bool enabled = false;
};

/// Geometric flags on occlusion edges discounted (needs the depth image): an LK window straddling an
/// occlusion edge follows the contour, not a 3-D point, and is flagged although its surface is static.
/// A flag with a depth step above kDepthStepRatio within radius_px (sampled every 2 px) becomes Candidate.
struct EdgeEvidenceOptions {
  bool enabled = false;
  /// How far from an occlusion edge a flag is discounted. Why you would change it: the LK window of your
  /// front end (the demo's is 21 x 21 px, so a flag 8 px from an edge may straddle it).
  int radius_px = 8;
  /// A depth step: neighbouring depths differing by more than this share (5 %, several Kinect sigmas).
  static constexpr double kDepthStepRatio = 0.05;

  static constexpr int kMaxRadiusPx = 64;

  /// InvalidInput naming the first field out of its range: radius_px in [1, 64].
  Status validate(std::string* reason = nullptr) const {
    if (radius_px < 1 || radius_px > kMaxRadiusPx)
      return detail::invalid_option(reason, "radius_px", "must be in [1, 64]");
    if (reason) reason->clear();
    return Status::Ok;
  }
};

/// The sub-box refinement (DFD-SLAM Algorithm 1; needs the geometric labels) with its switch and when its
/// vote is trusted.
template <class T>
struct SubBoxStageOptions : SubBoxOptions<T> {
  bool enabled = true;
  /// Vote only when F (or the pose) was fitted on tracks outside the dynamic-class boxes, or no track lay
  /// inside one: a model fitted through a large mover absorbs its motion, and the vote would clear the box.
  bool requires_fit_outside_boxes = true;
  /// Medium-level candidates (a chair) are culled by a dynamic sub-box of their region (true), or only on
  /// their own evidence (false): a chair under a seated person otherwise inherits the person's vote.
  bool verifies_candidates = true;
  /// Shortest baseline, in frames (CullingFrame::evidence_frames), at which "not flagged" may make part of
  /// a dynamic-class box static: over fewer frames a slow mover has not moved past the thresholds, so the
  /// vote is skipped and the box rule decides. 0 = no minimum; evidence_frames 0 (unknown) always votes.
  int min_evidence_frames = 0;
  /// With min_evidence_frames: on too short a baseline, the cells of a tracked box keep the states of its
  /// last vote within min_evidence_frames frames (a seated person's still legs stay static); the box rule
  /// decides elsewhere. Needs the box tracker.
  bool short_baseline_keeps_last_vote = false;

  /// SubBoxOptions::validate, then min_evidence_frames in [0, 65535].
  Status validate(std::string* reason = nullptr) const {
    if (SubBoxOptions<T>::validate(reason) != Status::Ok) return Status::InvalidInput;
    if (min_evidence_frames < 0 || min_evidence_frames > 0xFFFF)
      return detail::invalid_option(reason, "min_evidence_frames", "must be in [0, 65535]");
    if (reason) reason->clear();
    return Status::Ok;
  }
};

/// Cell-level coherent motion before the sub-box vote (coherent_motion.hpp; needs the reprojection
/// check, runs with the sub-box refinement on its grid) with its switch: in a cell of a high-level object
/// whose residuals share a significant median every feature counts as flagged (a seated person's sway).
template <class T>
struct CoherentMotionStageOptions : CoherentMotionOptions<T> {
  bool enabled = false;
};

/// A track's static history (static_history.hpp; needs CullingFrame::track_ids and the reprojection
/// check) with its switch: a feature culled only for its region stays static when its own check said
/// still in each of its last min_frames evaluated frames and does not flag it now.
template <class T>
struct StaticHistoryStageOptions : StaticHistoryOptions<T> {
  bool enabled = false;
};

/// Minimum-survivor guard: if fewer than max(min_fraction * n, min_survivors) features stay static, first
/// soften (restore the culls of single geometric stages and of candidates), then undo all culling.
/// ORB-SLAM2 loses tracking below ~30 local-map inliers; SG-SLAM guards at 10 %.
struct SurvivorGuardOptions {
  bool enabled = true;
  double min_fraction = 0.10;
  std::size_t min_survivors = 30;

  /// InvalidInput unless min_fraction is in [0, 1].
  Status validate(std::string* reason = nullptr) const {
    if (!detail::finite_in(min_fraction, 0, 1))
      return detail::invalid_option(reason, "min_fraction", "must be in [0, 1]");
    if (reason) reason->clear();
    return Status::Ok;
  }
};

namespace detail {
/// PipelineOptions and PipelineResult hold the options and the report of each listed evidence stage as a
/// member named as the stage, from the stage's slots (stages/stage.hpp).
template <class List>
struct OptionSlots;
template <class... Stages>
struct OptionSlots<StageList<Stages...>> : Stages::OptionsSlot... {};
template <class List>
struct ReportSlots;
template <class... Stages>
struct ReportSlots<StageList<Stages...>> : Stages::ReportSlot... {};

/// Each listed stage's options pass their validate(), in list order; the first failure's reason stands.
template <class Options, class... Stages>
bool slots_valid(const Options& options, StageList<Stages...>, std::string* reason) {
  return ((validate_nested(options.*Stages::kOptions, Stages::kName, reason) == Status::Ok) && ...);
}
}  // namespace detail

/// Which stages run and their options, in front-end order; each stage's `enabled` is its one switch.
/// The evidence stages' options (stages/list.hpp: `multiview`) come from detail::OptionSlots.
/// presets.hpp builds the papers' configurations.
template <class T>
struct PipelineOptions : detail::OptionSlots<EvidenceStages<T>> {
  DetectionStageOptions<T> detections{};
  TrackerStageOptions<T> tracker{};
  MotionLevelTable levels = MotionLevelTable::coco80();
  BoxRuleStageOptions<T> box_rule{};
  DepthMaskStageOptions depth_mask{};
  ProbabilityStageOptions<T> probability{};
  MovingConsistencyStageOptions<T> moving_consistency{};
  ReprojectionStageOptions<T> reprojection{};
  EdgeEvidenceOptions edge_evidence{};
  CoherentMotionStageOptions<T> coherent_motion{};
  SubBoxStageOptions<T> subbox{};
  StaticHistoryStageOptions<T> static_history{};
  /// What happens to the features still labelled Candidate (medium-level boxes) at the end.
  CandidatePolicy candidates = CandidatePolicy::Verify;
  SurvivorGuardOptions guard{};

  /// InvalidInput naming the first field out of its range, nested fields as "subbox.min_evidence_frames":
  /// every stage's options pass their validate() whether the stage is on or not; candidates in range.
  Status validate(std::string* reason = nullptr) const {
    using detail::validate_nested;
    // Stages in order; the first failure's reason stands.
    if (validate_nested(detections, "detections", reason) != Status::Ok ||
        validate_nested(tracker, "tracker", reason) != Status::Ok ||
        validate_nested(levels, "levels", reason) != Status::Ok ||
        validate_nested(box_rule, "box_rule", reason) != Status::Ok ||
        validate_nested(depth_mask, "depth_mask", reason) != Status::Ok ||
        validate_nested(probability, "probability", reason) != Status::Ok ||
        validate_nested(moving_consistency, "moving_consistency", reason) != Status::Ok ||
        validate_nested(reprojection, "reprojection", reason) != Status::Ok ||
        validate_nested(edge_evidence, "edge_evidence", reason) != Status::Ok ||
        validate_nested(coherent_motion, "coherent_motion", reason) != Status::Ok ||
        validate_nested(subbox, "subbox", reason) != Status::Ok ||
        validate_nested(static_history, "static_history", reason) != Status::Ok ||
        !detail::slots_valid(*this, EvidenceStages<T>{}, reason) ||
        validate_nested(guard, "guard", reason) != Status::Ok)
      return Status::InvalidInput;
    if (static_cast<int>(candidates) > 2)
      return detail::invalid_option(reason, "candidates", "must be Keep, Cull or Verify");
    if (reason) reason->clear();
    return Status::Ok;
  }
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
/// status is the worst of the enabled stages': Ok only when every enabled stage did its job (ran, or had
/// nothing to do); else the status of the first enabled stage, in front-end order, that failed
/// (InvalidInput, TooFewPoints, Degenerate, NonFinite, ...), or MissingInput when stages only lacked an
/// input of the frame. The reason then says "stage: why" for each such stage, as the stage's option is
/// named, joined with "; ", and the labels and keep mask are those of the stages that did their job
/// (labelled() is true). A frame refused at entry (invalid options, depth view or sizes: refused is true)
/// is InvalidInput with nothing culled and labelled() false. The evidence stages' reports (`multiview`)
/// come from detail::ReportSlots.
template <class T>
struct PipelineResult : detail::ReportSlots<EvidenceStages<T>> {
  Status status = Status::Ok;
  std::string reason;
  bool refused = false;  ///< the frame could not be culled at all: every keypoint Static and kept
  bool ok() const { return status == Status::Ok; }
  bool labelled() const { return !refused; }

  std::vector<FeatureLabel> labels;  ///< Static or Dynamic (Candidates are resolved by CandidatePolicy)
  std::vector<CullReason> reasons;   ///< deciding strategy (None for untouched statics)
  std::vector<std::uint8_t> keep;    ///< 1 = static: apply to every parallel per-keypoint array
  std::size_t num_features = 0, num_static = 0, num_dynamic = 0;
  StageReport detections, tracker, box_rule, depth_mask, probability, moving_consistency, reprojection,
      coherent_motion, subbox;
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
  /// a keyframe-based front end: frames since its keyframe); 0 = unknown. See SubBoxStageOptions::min_evidence_frames.
  int evidence_frames = 0;
};

namespace detail {
inline bool is_soft_cull(CullReason r) {
  return r == CullReason::Epipolar || r == CullReason::Reprojection || r == CullReason::MultiView ||
         r == CullReason::EvidenceStage ||
         r == CullReason::SubBox || r == CullReason::CoherentMotion || r == CullReason::MediumLevelBox ||
         r == CullReason::TrackedBox;
}

/// Culls for the region a feature lies in (its box, tracked box or sub-box), not for its own evidence: the
/// ones a track's static history may overrule (PipelineOptions::static_history).
inline bool is_regional_cull(CullReason r) {
  return r == CullReason::SubBox || r == CullReason::CoherentMotion || r == CullReason::HighLevelBox ||
         r == CullReason::TrackedBox || r == CullReason::MediumLevelBox;
}

}  // namespace detail

}  // namespace dyncull
