/// @file declarations.hpp
/// The stages of the culling pipeline in front-end order, each declared once with its name, its report, its
/// switch and the frame inputs it reads. The frame's reason ("stage: why"), every missing-input reason and
/// the culler's list of inputs (CullerCore::inputs_of) are derived from this list. Pipeline plumbing, no
/// paper equation.
#pragma once

#include "dyncull/culling/pipeline_types.hpp"
#include "dyncull/culling/stages/stage.hpp"

#include <array>
#include <cstddef>
#include <cstdint>

namespace dyncull {

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
/// A report as a member of PipelineResult<T>, T not deduced from it: an evidence stage's report is a
/// member of its slot and converts.
template <class T>
using ReportMember = NonDeduced<StageReport PipelineResult<T>::*>;
template <class T>
constexpr FrameInputs reads_nothing(Opt<T>) {
  return 0;
}
}  // namespace detail

/// An evidence stage's declaration, from its struct (stages/stage.hpp).
template <class T, class Stage>
constexpr StageDeclaration<T> declare_evidence_stage() {
  return {Stage::kName, Stage::kReport, [](detail::Opt<T> o) { return (o.*Stage::kOptions).enabled; },
          [](detail::Opt<T> o) { return Stage::needs(o.*Stage::kOptions); },
          [](detail::Opt<T> o) { return Stage::uses(o.*Stage::kOptions); }};
}

/// The stages in front-end order (pipeline.hpp runs them so), the evidence stages (stages/list.hpp)
/// between the region votes and the static history.
template <class T, class... Evidence>
constexpr std::array<StageDeclaration<T>, 10 + sizeof...(Evidence)> declare_stages(StageList<Evidence...>) {
  return {{
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
    declare_evidence_stage<T, Evidence>()...,
    {"static_history", &PipelineResult<T>::static_history, [](detail::Opt<T> o) { return o.static_history.enabled; },
     [](detail::Opt<T>) { return FrameInputs(FrameInput::TrackIds); }, detail::reads_nothing<T>},
  }};
}

template <class T>
constexpr auto kStages = declare_stages<T>(EvidenceStages<T>{});

namespace detail {
/// Every entry of kStages filled: declare_stages's count of core stages matches its list (an entry left
/// out would be value-initialised, with no name and no report).
template <class T>
constexpr bool every_stage_declared() {
  for (const StageDeclaration<T>& s : kStages<T>)
    if (s.name == nullptr || s.report == nullptr) return false;
  return true;
}
static_assert(every_stage_declared<double>(), "declare_stages: the count of core stages and the list disagree");
}  // namespace detail

/// The declaration of the stage that reports into `report`.
template <class T>
constexpr const StageDeclaration<T>& stage_of(detail::ReportMember<T> report) {
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

/// The frame inputs the stage reporting into `report` needs under `options` (its declaration above): a
/// stage's options slice carries them to detail::has_needed_inputs (stages/stage.hpp).
template <class T>
FrameInputs needs_of(const PipelineOptions<T>& options, ReportMember<T> report) {
  return stage_of<T>(report).needs(options);
}

}  // namespace detail
}  // namespace dyncull
