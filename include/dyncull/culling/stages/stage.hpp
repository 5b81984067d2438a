/// @file stage.hpp
/// What a culling stage is: the frame inputs it reads (FrameInput), its report (StageReport), and the form
/// of an evidence stage, the form a new check takes (one header, one line in stages/list.hpp; see
/// docs/design.md, "Adding a stage"). Pipeline plumbing, no paper equation.
#pragma once

#include "dyncull/core/pixel.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/core/traits.hpp"
#include "dyncull/core/types.hpp"

#include <cstddef>
#include <cstdint>
#include <string>

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

/// The evidence stages the pipeline runs after the region votes, in order (stages/list.hpp). An evidence
/// stage is a struct template on the scalar T with
///   - `kName`: its option in PipelineOptions, its report in PipelineResult and its name in reasons;
///   - `kReason`: the CullReason of its culls (CullReason::EvidenceStage unless it has its own);
///   - `Options`: its options slice, with `bool enabled` and `Status validate(std::string*) const`;
///   - `OptionsSlot` and `ReportSlot`: one member each, named kName, of types Options and StageReport
///     (PipelineOptions and PipelineResult derive from the slots of the listed stages), and `kOptions`,
///     `kReport`: pointers to those members;
///   - `Work`: its buffers, kept between frames so it allocates nothing after warm-up;
///   - `needs(options)` and `uses(options)`: the FrameInputs it cannot run without and those it reads
///     when given;
///   - `run(frame, options, context, work, dynamic, report)`: called when it is enabled and has what it
///     needs, with `dynamic` one zeroed flag per keypoint; it sets dynamic[i] = 1 for each feature it finds
///     moving and report->status (Ok, or its failure with report->reason). The context (EvidenceContext,
///     stages/context.hpp) holds the earlier stages' outputs and the stored keyframes, read-only.
/// Its flags cull wherever they are, as the multi-view check's do (DynaSLAM); the survivor guard may
/// restore them, as it restores every single geometric stage's culls.
template <class... Stages>
struct StageList {};

namespace detail {

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
