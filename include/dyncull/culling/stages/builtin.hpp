/// @file builtin.hpp
/// The pipeline's built-in stages, each declared in the form of stages/stage.hpp: its options with its
/// switch, its report and the frame inputs it reads. Their work is cull_frame's own steps (boxes,
/// semantic evidence, geometric evidence, probability, region votes, static history). The papers'
/// options are documented where their equations are (Zhu et al. 2024, Zhang et al. 2023, DLD-SLAM 2024,
/// DFD-SLAM 2024, RTD-SLAM 2024).
#pragma once

#include "dyncull/core/status.hpp"
#include "dyncull/culling/box_rule.hpp"
#include "dyncull/culling/box_tracker.hpp"
#include "dyncull/culling/coherent_motion.hpp"
#include "dyncull/culling/depth_mask.hpp"
#include "dyncull/culling/detections.hpp"
#include "dyncull/culling/dynamic_probability.hpp"
#include "dyncull/culling/moving_consistency.hpp"
#include "dyncull/culling/reprojection_check.hpp"
#include "dyncull/culling/stages/stage.hpp"
#include "dyncull/culling/static_history.hpp"
#include "dyncull/culling/subbox_refine.hpp"
#include "dyncull/culling/validation.hpp"

#include <string>

namespace dyncull {

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

/// The detection filter: padding and class-dependent confidence on the detector's boxes.
template <class T>
struct DetectionFilterStage {
  static constexpr const char* kName = "detections";
  static constexpr StageKind kKind = StageKind::Builtin;
  using Options = DetectionStageOptions<T>;
  struct OptionsSlot {
    Options detections{};
  };
  struct ReportSlot {
    StageReport detections;
  };
  static constexpr Options OptionsSlot::*kOptions = &OptionsSlot::detections;
  static constexpr StageReport ReportSlot::*kReport = &ReportSlot::detections;
  static constexpr FrameInputs needs(const Options&) { return FrameInputs(FrameInput::Detections); }
  static constexpr FrameInputs uses(const Options&) { return 0; }
};

/// The box tracker: missed dynamic-class boxes carried forward (Dynamic-VINS).
template <class T>
struct BoxTrackerStage {
  static constexpr const char* kName = "tracker";
  static constexpr StageKind kKind = StageKind::Builtin;
  using Options = TrackerStageOptions<T>;
  struct OptionsSlot {
    Options tracker{};
  };
  struct ReportSlot {
    StageReport tracker;
  };
  static constexpr Options OptionsSlot::*kOptions = &OptionsSlot::tracker;
  static constexpr StageReport ReportSlot::*kReport = &ReportSlot::tracker;
  static constexpr FrameInputs needs(const Options&) { return 0; }
  static constexpr FrameInputs uses(const Options&) { return 0; }
};

/// The box rule (Zhu et al. 2024 Table 2). Without the detection filter it is the stage that reads the detections.
template <class T>
struct BoxRuleStage {
  static constexpr const char* kName = "box_rule";
  static constexpr StageKind kKind = StageKind::Builtin;
  using Options = BoxRuleStageOptions<T>;
  struct OptionsSlot {
    Options box_rule{};
  };
  struct ReportSlot {
    StageReport box_rule;
  };
  static constexpr Options OptionsSlot::*kOptions = &OptionsSlot::box_rule;
  static constexpr StageReport ReportSlot::*kReport = &ReportSlot::box_rule;
  template <class Pipeline>
  static constexpr FrameInputs needs(const Options&, const Pipeline& p) {
    return FrameInputs(p.detections.enabled ? 0 : FrameInputs(FrameInput::Detections));
  }
  template <class Pipeline>
  static constexpr FrameInputs uses(const Options&, const Pipeline&) { return 0; }
};

/// The depth masks (DLD-SLAM eq. 1-2): box culls limited to the object's depth band.
template <class T>
struct DepthMaskStage {
  static constexpr const char* kName = "depth_mask";
  static constexpr StageKind kKind = StageKind::Builtin;
  using Options = DepthMaskStageOptions;
  struct OptionsSlot {
    Options depth_mask{};
  };
  struct ReportSlot {
    StageReport depth_mask;
  };
  static constexpr Options OptionsSlot::*kOptions = &OptionsSlot::depth_mask;
  static constexpr StageReport ReportSlot::*kReport = &ReportSlot::depth_mask;
  static constexpr FrameInputs needs(const Options&) { return FrameInputs(FrameInput::Depth); }
  static constexpr FrameInputs uses(const Options&) { return 0; }
};

/// The dynamic probability (DLD-SLAM eq. 3-5) of the features in the object masks.
template <class T>
struct ProbabilityStage {
  static constexpr const char* kName = "probability";
  static constexpr StageKind kKind = StageKind::Builtin;
  using Options = ProbabilityStageOptions<T>;
  struct OptionsSlot {
    Options probability{};
  };
  struct ReportSlot {
    StageReport probability;
  };
  static constexpr Options OptionsSlot::*kOptions = &OptionsSlot::probability;
  static constexpr StageReport ReportSlot::*kReport = &ReportSlot::probability;
  static constexpr FrameInputs needs(const Options&) { return FrameInputs(FrameInput::PrevKeypoints); }
  static constexpr FrameInputs uses(const Options&) { return 0; }
};

/// The epipolar moving-consistency check (DFD-SLAM eq. 1-3). It reads depth for the occlusion-edge discount
/// (edge_evidence) when given.
template <class T>
struct MovingConsistencyStage {
  static constexpr const char* kName = "moving_consistency";
  static constexpr StageKind kKind = StageKind::Builtin;
  using Options = MovingConsistencyStageOptions<T>;
  struct OptionsSlot {
    Options moving_consistency{};
  };
  struct ReportSlot {
    StageReport moving_consistency;
  };
  static constexpr Options OptionsSlot::*kOptions = &OptionsSlot::moving_consistency;
  static constexpr StageReport ReportSlot::*kReport = &ReportSlot::moving_consistency;
  template <class Pipeline>
  static constexpr FrameInputs needs(const Options&, const Pipeline&) { return FrameInputs(FrameInput::PrevKeypoints); }
  template <class Pipeline>
  static constexpr FrameInputs uses(const Options&, const Pipeline& p) {
    return FrameInputs(p.edge_evidence.enabled ? FrameInputs(FrameInput::Depth) : 0);
  }
};

/// The RGB-D reprojection check. It reads depth for its depth residual (max_depth_residual_sigmas) and the
/// occlusion-edge discount when given.
template <class T>
struct ReprojectionStage {
  static constexpr const char* kName = "reprojection";
  static constexpr StageKind kKind = StageKind::Builtin;
  using Options = ReprojectionStageOptions<T>;
  struct OptionsSlot {
    Options reprojection{};
  };
  struct ReportSlot {
    StageReport reprojection;
  };
  static constexpr Options OptionsSlot::*kOptions = &OptionsSlot::reprojection;
  static constexpr StageReport ReportSlot::*kReport = &ReportSlot::reprojection;
  template <class Pipeline>
  static constexpr FrameInputs needs(const Options&, const Pipeline&) { return FrameInputs(FrameInput::Points3d); }
  template <class Pipeline>
  static constexpr FrameInputs uses(const Options& o, const Pipeline& p) {
    const bool reads_depth = o.max_depth_residual_sigmas > T(0) || p.edge_evidence.enabled;
    return FrameInputs(reads_depth ? FrameInputs(FrameInput::Depth) : 0);
  }
};

/// Cell-level coherent motion before the sub-box vote (coherent_motion.hpp).
template <class T>
struct CoherentMotionStage {
  static constexpr const char* kName = "coherent_motion";
  static constexpr StageKind kKind = StageKind::Builtin;
  using Options = CoherentMotionStageOptions<T>;
  struct OptionsSlot {
    Options coherent_motion{};
  };
  struct ReportSlot {
    StageReport coherent_motion;
  };
  static constexpr Options OptionsSlot::*kOptions = &OptionsSlot::coherent_motion;
  static constexpr StageReport ReportSlot::*kReport = &ReportSlot::coherent_motion;
  static constexpr FrameInputs needs(const Options&) { return 0; }
  static constexpr FrameInputs uses(const Options&) { return 0; }
};

/// The sub-box refinement (DFD-SLAM Algorithm 1).
template <class T>
struct SubBoxStage {
  static constexpr const char* kName = "subbox";
  static constexpr StageKind kKind = StageKind::Builtin;
  using Options = SubBoxStageOptions<T>;
  struct OptionsSlot {
    Options subbox{};
  };
  struct ReportSlot {
    StageReport subbox;
  };
  static constexpr Options OptionsSlot::*kOptions = &OptionsSlot::subbox;
  static constexpr StageReport ReportSlot::*kReport = &ReportSlot::subbox;
  static constexpr FrameInputs needs(const Options&) { return 0; }
  static constexpr FrameInputs uses(const Options&) { return 0; }
};

/// A track's static history (static_history.hpp).
template <class T>
struct StaticHistoryStage {
  static constexpr const char* kName = "static_history";
  static constexpr StageKind kKind = StageKind::Builtin;
  using Options = StaticHistoryStageOptions<T>;
  struct OptionsSlot {
    Options static_history{};
  };
  struct ReportSlot {
    StageReport static_history;
  };
  static constexpr Options OptionsSlot::*kOptions = &OptionsSlot::static_history;
  static constexpr StageReport ReportSlot::*kReport = &ReportSlot::static_history;
  static constexpr FrameInputs needs(const Options&) { return FrameInputs(FrameInput::TrackIds); }
  static constexpr FrameInputs uses(const Options&) { return 0; }
};

}  // namespace dyncull
