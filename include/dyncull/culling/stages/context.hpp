/// @file context.hpp
/// The per-frame data the culling stages exchange (box regions, per-feature semantic and geometric
/// evidence, region votes, the listed stages' marks) and the caller-owned PipelineState that keeps them between
/// frames so no stage allocates after warm-up. Each stage writes only its own part.
#pragma once

#include "dyncull/culling/pipeline_types.hpp"
#include "dyncull/culling/stages/declarations.hpp"
#include "dyncull/culling/subbox_memory.hpp"

#include <cstddef>
#include <cstdint>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

namespace dyncull {

template <class T>
struct PipelineState;

namespace detail {

/// Boxes of this frame: all of them after the filter and the tracker, and the dynamic-class ones
/// (high and medium level) the depth masks and the sub-box vote act on, with their tracker ids.
template <class T>
struct BoxRegions {
  std::vector<Detection<T>> boxes, dyn_boxes, untracked_boxes;
  std::vector<std::int32_t> dyn_box_source;
  std::vector<std::int64_t> box_track_id, dyn_box_track_id;  ///< box-tracker id per box (-1: none)
  DetectionsResult<T> filtered;  ///< the detection filter's result, reused between frames
  BoxTrackerResult<T> tracked;   ///< the box tracker's result, reused between frames
};

/// Per-feature semantic evidence: the box rule's labels limited to the objects' depth bands (DLD-SLAM eq. 1-2).
template <class T>
struct SemanticEvidence {
  BoxRuleResult<T> rule;  ///< the box rule's own result (box index per feature)
  BoxRuleScratch<T> rule_scratch;
  bool rule_ok = false;
  std::vector<FeatureLabel> labels;
  std::vector<CullReason> reasons;
  std::vector<std::uint8_t> in_dyn_box, in_object;
  std::vector<std::uint32_t> object_box_bits;  ///< per feature: the dynamic boxes whose depth mask holds it
  bool masks = false;                          ///< the depth masks ran (in_object, object_box_bits valid)
  std::vector<std::int32_t> head_band_box;     ///< per feature: the dynamic box whose head band holds it, -1
  std::vector<Detection<T>> shelter_boxes;     ///< scratch of the low-level shelter check
  DepthMaskResult mask, shelter_mask;         ///< the depth masks' results (the shelter check's: scratch)
  DepthMaskScratch mask_scratch;
};

/// DLD-SLAM eq. 3-5 over the features of the object masks: the semantic labels with the probability's decisions.
template <class T>
struct ProbabilityEvidence {
  bool ok = false;
  std::vector<FeatureLabel> labels;
  std::vector<CullReason> reasons;
  std::vector<MotionLevel> levels;
  std::vector<Vec2<T>> prev;
  DynamicProbabilityResult<T> result;  ///< the probability's own result, reused between frames
  DynamicProbabilityScratch<T> scratch;
};

/// Per-feature geometric evidence: the epipolar (DFD-SLAM eq. 3) and/or reprojection labels, combined, with
/// flags on depth edges discounted.
template <class T>
struct GeometricEvidence {
  MovingConsistencyResult<T> moving;
  ReprojectionCheckResult<T> reprojection;
  std::vector<FeatureLabel> labels;
  std::vector<CullReason> source;  ///< per feature, the check whose label stands: Epipolar or Reprojection
  bool ok = false;                 ///< labels valid this frame
  bool fit_outside_boxes = true;   ///< every check in the labels fitted its model outside the boxes
};

/// Region votes: cell-level coherent motion, then the sub-box vote (DFD-SLAM Algorithm 1) over the boxes.
template <class T>
struct RegionVotes {
  CoherentMotionResult<T> coherent;
  std::vector<FeatureLabel> evidence;  ///< the geometric labels with the coherent cells' features flagged
  bool coherent_ran = false;           ///< evidence holds the coherent stage's labels
  std::vector<std::uint8_t> coherent_eligible;
  std::vector<std::uint8_t> remembered_cells;  ///< a tracked box's last vote, on too short a baseline
  std::vector<std::uint8_t> self_moving_boxes;  ///< per dynamic-class box: high level (flag_self_moving_boxes)
  SubBoxResult<T> subbox;
  bool ok = false;
};

/// A listed stage's output (stages/stage.hpp, kinds other than Builtin): its buffers and one mark per
/// feature (a FeatureLabel for a box classification, else a flag), valid when ok.
template <class Stage>
struct StageMarks {
  using StageType = Stage;
  using Mark = std::conditional_t<Stage::kKind == StageKind::BoxClassification, FeatureLabel, std::uint8_t>;
  typename Stage::Work work;
  std::vector<Mark> marks;
  bool ok = false;
};

/// One StageMarks per listed stage that the pipeline runs by its kind (not the built-in ones).
template <class List>
struct StageMarksOf;
template <class... Stages>
struct StageMarksOf<StageList<Stages...>> {
  using type = decltype(std::tuple_cat(
      std::declval<std::conditional_t<Stages::kKind == StageKind::Builtin, std::tuple<>,
                                      std::tuple<StageMarks<Stages>>>>()...));
};

/// Everything the stages of one frame write, reused between frames.
template <class T>
struct PipelineWork {
  BoxRegions<T> regions;
  SemanticEvidence<T> semantic;
  ProbabilityEvidence<T> probability;
  GeometricEvidence<T> geometric;
  RegionVotes<T> votes;
  typename StageMarksOf<PipelineStages<T>>::type listed;  ///< one StageMarks per listed stage run by kind
  std::vector<std::uint16_t> still_frames;  ///< static history count per feature this frame
  std::vector<std::uint8_t> history_kept;   ///< 1: kept static by its history this frame
  std::vector<T> keypoint_depth;

  /// The semantic labels the later stages read: the probability's where it ran, else the depth masks'.
  const std::vector<FeatureLabel>& semantic_labels() const {
    return probability.ok ? probability.labels : semantic.labels;
  }
  const std::vector<CullReason>& semantic_reasons() const {
    return probability.ok ? probability.reasons : semantic.reasons;
  }
  /// The output of the listed stage Stage (stages/list.hpp).
  template <class Stage>
  const StageMarks<Stage>& marks_of() const {
    return std::get<StageMarks<Stage>>(listed);
  }
  template <class Stage>
  StageMarks<Stage>& marks_of() {
    return std::get<StageMarks<Stage>>(listed);
  }
  /// The geometric evidence the vote and the combination read (with the coherent cells' flags).
  const FeatureLabel* evidence() const { return votes.coherent_ran ? votes.evidence.data() : geometric.labels.data(); }
  /// The stage whose flag made feature i geometric-dynamic (evidence()[i] == Dynamic).
  CullReason evidence_source(std::size_t i) const {
    return votes.coherent_ran && geometric.labels[i] != FeatureLabel::Dynamic ? CullReason::CoherentMotion
                                                                             : geometric.source[i];
  }
};

template <class T>
PipelineWork<T>& work_of(PipelineState<T>* state);

/// What a listed stage reads besides the frame and its options: the earlier stages' outputs and the
/// stored keyframes.
template <class T>
struct StageContext {
  const PipelineWork<T>& earlier;
  const KeyframeRing<T>& keyframes;
};

}  // namespace detail

/// Caller-owned state carried between frames. The stages' per-frame buffers are private (reused so the
/// pipeline allocates nothing after warm-up); read a frame's outcome from `result`.
template <class T>
struct PipelineState {
  BoxTracker<T> tracker;             ///< given PipelineOptions::tracker each frame
  TrackStateStore track_states;      ///< K of DLD-SLAM eq. 3, keyed by the caller's track ids
  SubBoxMemory subbox_memory;        ///< last votes: SubBoxStageOptions::short_baseline_keeps_last_vote
  StaticHistory static_history;      ///< PipelineOptions::static_history
  KeyframeRing<T> keyframes;         ///< multi-view references (push with is_keyframe or by hand)
  std::uint64_t frame_index = 0;

  PipelineResult<T> result;

  explicit PipelineState(std::size_t keyframe_capacity = 20) : keyframes(keyframe_capacity) {}
  void reset() {
    tracker = BoxTracker<T>();
    track_states.clear();
    subbox_memory.clear();
    static_history.clear();
    keyframes.clear();
    frame_index = 0;
  }

  /// The stages' buffers of the last frame, read-only: for the stages' own tests, not for callers.
  const detail::PipelineWork<T>& internals() const { return work_; }

 private:
  friend detail::PipelineWork<T>& detail::work_of<T>(PipelineState<T>* state);
  detail::PipelineWork<T> work_;
};

namespace detail {
template <class T>
PipelineWork<T>& work_of(PipelineState<T>* state) {
  return state->work_;
}
}  // namespace detail

}  // namespace dyncull
