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
#include "dyncull/culling/detections.hpp"
#include "dyncull/culling/labels.hpp"
#include "dyncull/culling/motion_levels.hpp"
#include "dyncull/culling/stages/list.hpp"
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
/// PipelineOptions and PipelineResult hold the options and the report of each listed stage as a member
/// named as the stage, from the stage's slots (stages/stage.hpp).
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

/// Which stages run and their options. Each stage of stages/list.hpp has its options as a member named
/// as the stage (`detections`, `box_rule`, `subbox`, `multiview`, ...; detail::OptionSlots), with
/// `enabled` as its one switch; the members below are shared by several stages. presets.hpp builds the
/// papers' configurations.
template <class T>
struct PipelineOptions : detail::OptionSlots<PipelineStages<T>> {
  MotionLevelTable levels = MotionLevelTable::coco80();
  EdgeEvidenceOptions edge_evidence{};
  /// What happens to the features still labelled Candidate (medium-level boxes) at the end.
  CandidatePolicy candidates = CandidatePolicy::Verify;
  SurvivorGuardOptions guard{};

  /// InvalidInput naming the first field out of its range, nested fields as "subbox.min_evidence_frames":
  /// every stage's options pass their validate() whether the stage is on or not (in list order), then
  /// the shared members; candidates in range.
  Status validate(std::string* reason = nullptr) const {
    using detail::validate_nested;
    if (!detail::slots_valid(*this, PipelineStages<T>{}, reason) ||
        validate_nested(levels, "levels", reason) != Status::Ok ||
        validate_nested(edge_evidence, "edge_evidence", reason) != Status::Ok ||
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
/// is InvalidInput with nothing culled and labelled() false. Each stage of stages/list.hpp reports into a
/// StageReport named as the stage (`detections`, `box_rule`, `multiview`, ...; detail::ReportSlots).
template <class T>
struct PipelineResult : detail::ReportSlots<PipelineStages<T>> {
  Status status = Status::Ok;
  std::string reason;
  bool refused = false;  ///< the frame could not be culled at all: every keypoint Static and kept
  bool ok() const { return status == Status::Ok; }
  bool labelled() const { return !refused; }

  std::vector<FeatureLabel> labels;  ///< Static or Dynamic (Candidates are resolved by CandidatePolicy)
  std::vector<CullReason> reasons;   ///< deciding strategy (None for untouched statics)
  std::vector<std::uint8_t> keep;    ///< 1 = static: apply to every parallel per-keypoint array
  std::size_t num_features = 0, num_static = 0, num_dynamic = 0;
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
         r == CullReason::ListedStage ||
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
