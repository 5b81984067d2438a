/// @file declarations.hpp
/// The stages of the culling pipeline in front-end order, each declared once with its name, its report, its
/// switch and the frame inputs it reads. The frame's reason ("stage: why"), every missing-input reason and
/// the culler's list of inputs (CullerCore::inputs_of) are derived from this list. Pipeline plumbing, no
/// paper equation.
#pragma once

#include "dyncull/culling/pipeline_types.hpp"

#include <cstddef>
#include <cstdint>

namespace dyncull {

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

/// One stage: `name` as its option in PipelineOptions (and in reasons), its report in PipelineResult, its
/// switch, the frame inputs it cannot run without (`needs`) and those it reads when given (`uses`: a
/// refinement that is left out without them).
template <class T>
struct StageDeclaration {
  const char* name;
  StageReport PipelineResult<T>::*report;
  bool (*enabled)(const PipelineOptions<T>&);
  FrameInputs (*needs)(const PipelineOptions<T>&);
  FrameInputs (*uses)(const PipelineOptions<T>&);
};

namespace detail {
template <class T>
using Opt = const PipelineOptions<T>&;
template <class T>
constexpr FrameInputs reads_nothing(Opt<T>) {
  return 0;
}
}  // namespace detail

/// The stages in front-end order (pipeline.hpp runs them so).
template <class T>
constexpr StageDeclaration<T> kStages[] = {
    {"detections", &PipelineResult<T>::detections, [](detail::Opt<T> o) { return o.detections.enabled; },
     [](detail::Opt<T>) { return FrameInputs(FrameInput::Detections); }, detail::reads_nothing<T>},
    {"tracker", &PipelineResult<T>::tracker, [](detail::Opt<T> o) { return o.tracker.enabled; },
     detail::reads_nothing<T>, detail::reads_nothing<T>},
    // Without the detection filter, the box rule is the stage that reads the detections.
    {"box_rule", &PipelineResult<T>::box_rule, [](detail::Opt<T> o) { return o.box_rule.enabled; },
     [](detail::Opt<T> o) { return FrameInputs(o.detections.enabled ? 0 : FrameInputs(FrameInput::Detections)); },
     detail::reads_nothing<T>},
    {"depth_mask", &PipelineResult<T>::depth_mask, [](detail::Opt<T> o) { return o.depth_mask.enabled; },
     [](detail::Opt<T>) { return FrameInputs(FrameInput::Depth); }, detail::reads_nothing<T>},
    {"probability", &PipelineResult<T>::probability, [](detail::Opt<T> o) { return o.probability.enabled; },
     [](detail::Opt<T>) { return FrameInputs(FrameInput::PrevKeypoints); }, detail::reads_nothing<T>},
    // Depth: occlusion edges discount the flags on them (edge_evidence).
    {"moving_consistency", &PipelineResult<T>::moving_consistency,
     [](detail::Opt<T> o) { return o.moving_consistency.enabled; },
     [](detail::Opt<T>) { return FrameInputs(FrameInput::PrevKeypoints); },
     [](detail::Opt<T> o) { return FrameInputs(o.edge_evidence.enabled ? FrameInputs(FrameInput::Depth) : 0); }},
    // Depth: the depth residual (max_depth_residual_sigmas) and occlusion edges.
    {"reprojection", &PipelineResult<T>::reprojection, [](detail::Opt<T> o) { return o.reprojection.enabled; },
     [](detail::Opt<T>) { return FrameInputs(FrameInput::Points3d); },
     [](detail::Opt<T> o) {
       return FrameInputs(o.reprojection.max_depth_residual_sigmas > T(0) || o.edge_evidence.enabled
                              ? FrameInputs(FrameInput::Depth)
                              : 0);
     }},
    {"coherent_motion", &PipelineResult<T>::coherent_motion, [](detail::Opt<T> o) { return o.coherent_motion.enabled; },
     detail::reads_nothing<T>, detail::reads_nothing<T>},
    {"subbox", &PipelineResult<T>::subbox, [](detail::Opt<T> o) { return o.subbox.enabled; }, detail::reads_nothing<T>,
     detail::reads_nothing<T>},
    {"multiview", &PipelineResult<T>::multiview, [](detail::Opt<T> o) { return o.multiview.enabled; },
     [](detail::Opt<T>) {
       return FrameInput::CamFromWorld | FrameInput::Depth | FrameInput::ReferenceKeyframe;
     },
     detail::reads_nothing<T>},
    {"static_history", &PipelineResult<T>::static_history, [](detail::Opt<T> o) { return o.static_history.enabled; },
     [](detail::Opt<T>) { return FrameInputs(FrameInput::TrackIds); }, detail::reads_nothing<T>},
};

/// The declaration of the stage that reports into `report`.
template <class T>
constexpr const StageDeclaration<T>& stage_of(StageReport PipelineResult<T>::*report) {
  for (const StageDeclaration<T>& s : kStages<T>)
    if (s.report == report) return s;
  return kStages<T>[0];  // unreachable for the reports of PipelineResult
}

/// The frame inputs the enabled stages need (`optional` false) or read when given as well (true).
template <class T>
FrameInputs inputs_read(const PipelineOptions<T>& options, bool optional = false) {
  FrameInputs in = 0;
  for (const StageDeclaration<T>& s : kStages<T>) {
    if (!s.enabled(options)) continue;
    in = static_cast<FrameInputs>(in | s.needs(options) | (optional ? s.uses(options) : 0));
  }
  return in;
}

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

/// False, with the stage's report MissingInput and the first input it needs and the frame lacks named,
/// when the stage cannot run; true when it has what it needs. (Given inputs have the keypoints' length:
/// accept_inputs checked.)
template <class T, class Frame>
bool stage_has_inputs(const Frame& frame, const PipelineOptions<T>& options, StageReport PipelineResult<T>::*report,
                      PipelineResult<T>* r, bool keyframe_stored = true) {
  const FrameInputs lacking = static_cast<FrameInputs>(stage_of<T>(report).needs(options) &
                                                       frame_lacks(frame, keyframe_stored));
  if (lacking == 0) return true;
  for (FrameInput input : kFrameInputs) {
    if (!reads(lacking, input)) continue;
    StageReport& st = r->*report;
    st.status = Status::MissingInput;
    st.reason.assign(missing_reason(input, frame.cam_from_world != nullptr));
    break;
  }
  return false;
}

}  // namespace detail
}  // namespace dyncull
