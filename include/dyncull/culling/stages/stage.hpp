/// @file stage.hpp
/// What a culling stage is: the frame inputs it reads (FrameInput), its report (StageReport), where it
/// runs (StageKind) and the one form every stage is declared in (one header, one line in
/// stages/list.hpp; see docs/design.md, "Adding a stage"). Pipeline plumbing, no paper equation.
#pragma once

#include "dyncull/core/pixel.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/core/traits.hpp"
#include "dyncull/core/types.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>
#include <utility>

namespace dyncull {

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

/// An input of a CullingFrame that a stage reads, as a bit of FrameInputs; in the order a stage that
/// lacks several reports them (the first one missing is named).
enum class FrameInput : std::uint8_t {
  Detections = 1u << 0,
  CamFromWorld = 1u << 1,  ///< given and finite: a lost track's pose is no pose
  Depth = 1u << 2,
  PrevKeypoints = 1u << 3,
  Points3d = 1u << 4,
  TrackIds = 1u << 5,
  ReferenceKeyframe = 1u << 6,  ///< a keyframe stored in PipelineState (is_keyframe, or pushed by hand)
};
using FrameInputs = std::uint8_t;
constexpr FrameInputs operator|(FrameInput a, FrameInput b) noexcept {
  return static_cast<FrameInputs>(static_cast<FrameInputs>(a) | static_cast<FrameInputs>(b));
}
constexpr FrameInputs operator|(FrameInputs a, FrameInput b) noexcept {
  return static_cast<FrameInputs>(a | static_cast<FrameInputs>(b));
}
constexpr bool reads(FrameInputs set, FrameInput input) noexcept { return (set & static_cast<FrameInputs>(input)) != 0; }
constexpr FrameInput kFrameInputs[] = {FrameInput::Detections, FrameInput::CamFromWorld,  FrameInput::Depth,
                                       FrameInput::PrevKeypoints, FrameInput::Points3d, FrameInput::TrackIds,
                                       FrameInput::ReferenceKeyframe};

/// Why a stage cannot run without the input: the stage's missing-input reason.
constexpr const char* missing_reason(FrameInput input, bool pose_given = false) noexcept {
  switch (input) {
    case FrameInput::Detections: return "no detections given";
    case FrameInput::CamFromWorld: return pose_given ? "cam_from_world not finite (tracking lost)" : "no cam_from_world given";
    case FrameInput::Depth: return "no depth given";
    case FrameInput::PrevKeypoints: return "no prev_keypoints given";
    case FrameInput::Points3d: return "no points_3d given";
    case FrameInput::TrackIds: return "no track_ids given";
    case FrameInput::ReferenceKeyframe: return "no reference keyframe stored yet";
  }
  return "an input is missing";
}

/// Where the pipeline runs a stage of stages/list.hpp, and what it writes.
///   - Builtin: the stages of the papers (stages/builtin.hpp), run by cull_frame's own steps.
///   - BoxClassification: after the box rule and the depth masks; it labels features from the boxes
///     (`marks[i]`: Candidate or Dynamic; Static for no opinion). A label it raises stands, with its
///     kReason, unless a depth stage clears it; a candidate is verified as the box rule's are.
///   - Depth: after the box classification; it clears box labels off the object (`marks[i]` = 1: the
///     feature's depth says it is not on the object its box label gave it, so it becomes static).
///   - Evidence: after the region votes; it flags moving features (`marks[i]` = 1), which cull wherever
///     they are, as the multi-view check's do (DynaSLAM); the survivor guard may restore them, as it
///     restores every single geometric stage's culls.
enum class StageKind : std::uint8_t { Builtin, BoxClassification, Depth, Evidence };

/// The stages of the pipeline, in front-end order (stages/list.hpp). A stage is a struct template on the
/// scalar T with
///   - `kName`: its option in PipelineOptions, its report in PipelineResult and its name in reasons;
///   - `kKind`: where it runs (StageKind);
///   - `Options`: its options slice, with `bool enabled` and `Status validate(std::string*) const`;
///   - `OptionsSlot` and `ReportSlot`: one member each, named kName, of types Options and StageReport
///     (PipelineOptions and PipelineResult derive from the slots of the listed stages), and `kOptions`,
///     `kReport`: pointers to those members;
///   - `needs(options)` and `uses(options)`: the FrameInputs it cannot run without and those it reads
///     when given (a built-in stage whose inputs depend on another stage's options takes the
///     PipelineOptions as a second argument).
/// A stage of another kind than Builtin also has
///   - `kReason`: the CullReason of its culls (CullReason::ListedStage unless it has its own);
///   - `Work`: its buffers, kept between frames so it allocates nothing after warm-up;
///   - `run(frame, options, context, work, marks, report)`: called when it is enabled and has what it
///     needs, with `marks` one zeroed entry per keypoint (FeatureLabel for a box classification, else a
///     flag) that it sets as its kind says, and report->status (Ok, or its failure with report->reason).
///     The context (StageContext, stages/context.hpp) holds the earlier stages' outputs and the stored
///     keyframes, read-only.
template <class... Stages>
struct StageList {};

namespace detail {

/// True when Stage's needs and uses take the PipelineOptions as well (a built-in stage that reads another
/// stage's switch).
template <class Stage, class Pipeline, class = void>
struct ReadsOtherStages : std::false_type {};
template <class Stage, class Pipeline>
struct ReadsOtherStages<Stage, Pipeline,
                        std::void_t<decltype(Stage::needs(std::declval<const typename Stage::Options&>(),
                                                          std::declval<const Pipeline&>()))>> : std::true_type {};

/// The frame inputs Stage cannot run without under the pipeline's options.
template <class Stage, class Pipeline>
constexpr FrameInputs stage_needs(const Pipeline& pipeline) {
  if constexpr (ReadsOtherStages<Stage, Pipeline>::value)
    return Stage::needs(pipeline.*Stage::kOptions, pipeline);
  else
    return Stage::needs(pipeline.*Stage::kOptions);
}

/// The frame inputs Stage reads when given under the pipeline's options.
template <class Stage, class Pipeline>
constexpr FrameInputs stage_uses(const Pipeline& pipeline) {
  if constexpr (ReadsOtherStages<Stage, Pipeline>::value)
    return Stage::uses(pipeline.*Stage::kOptions, pipeline);
  else
    return Stage::uses(pipeline.*Stage::kOptions);
}

/// The frame inputs this frame lacks.
template <class Frame>
FrameInputs frame_lacks(const Frame& frame, bool keyframe_stored) {
  FrameInputs lacking = 0;
  if (!frame.detections) lacking = lacking | FrameInput::Detections;
  if (!frame.cam_from_world || !frame.cam_from_world->all_finite()) lacking = lacking | FrameInput::CamFromWorld;
  if (frame.depth.empty()) lacking = lacking | FrameInput::Depth;
  if (!frame.prev_keypoints) lacking = lacking | FrameInput::PrevKeypoints;
  if (!frame.points_3d) lacking = lacking | FrameInput::Points3d;
  if (!frame.track_ids) lacking = lacking | FrameInput::TrackIds;
  if (!keyframe_stored) lacking = lacking | FrameInput::ReferenceKeyframe;
  return lacking;
}

/// False, with the report MissingInput and the first input it needs and the frame lacks named, when the
/// stage cannot run; true when it has what it needs.
template <class Frame>
bool has_needed_inputs(const Frame& frame, FrameInputs needs, StageReport* report, bool keyframe_stored = true) {
  const FrameInputs lacking = static_cast<FrameInputs>(needs & frame_lacks(frame, keyframe_stored));
  if (lacking == 0) return true;
  for (FrameInput input : kFrameInputs) {
    if (!reads(lacking, input)) continue;
    report->status = Status::MissingInput;
    report->reason.assign(missing_reason(input, frame.cam_from_world != nullptr));
    break;
  }
  return false;
}

/// Keypoint i's pixel in a w x h image: false when it lies outside or is not finite.
template <class T, class Keypoints>
bool keypoint_in_image(const Keypoints& kp, std::size_t i, int w, int h, int* u, int* v) {
  return pixel_of(point_x<T>(kp[i]), point_y<T>(kp[i]), w, h, u, v);
}

}  // namespace detail
}  // namespace dyncull
