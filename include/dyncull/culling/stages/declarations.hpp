/// @file declarations.hpp
/// The table of the culling pipeline's stages, derived from stages/list.hpp: each stage's name, report,
/// switch and the frame inputs it reads. The frame's reason ("stage: why"), every missing-input reason and
/// the culler's list of inputs (CullerCore::inputs_of) are derived from it. Pipeline plumbing, no paper
/// equation.
#pragma once

#include "dyncull/culling/pipeline_types.hpp"
#include "dyncull/culling/stages/stage.hpp"

#include <array>
#include <cstddef>
#include <string>

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

/// A listed stage's declaration, from its struct (stages/stage.hpp).
template <class T, class Stage>
constexpr StageDeclaration<T> declare_stage() {
  return {Stage::kName, Stage::kReport,
          [](const PipelineOptions<T>& o) { return (o.*Stage::kOptions).enabled; },
          [](const PipelineOptions<T>& o) { return detail::stage_needs<Stage>(o); },
          [](const PipelineOptions<T>& o) { return detail::stage_uses<Stage>(o); }};
}

/// The stages of stages/list.hpp in its order (front-end order: pipeline.hpp runs them so).
template <class T, class... Stages>
constexpr std::array<StageDeclaration<T>, sizeof...(Stages)> declare_stages(StageList<Stages...>) {
  return {{declare_stage<T, Stages>()...}};
}

template <class T>
constexpr auto kStages = declare_stages<T>(PipelineStages<T>{});

namespace detail {
constexpr bool same_name(const char* a, const char* b) {
  while (*a != '\0' && *a == *b) ++a, ++b;
  return *a == *b;
}

/// The built-in stage that stages of `kind` follow in the list: where cull_frame runs them.
constexpr const char* runs_after(StageKind kind) {
  return kind == StageKind::Evidence ? "subbox" : kind == StageKind::Builtin ? "" : "depth_mask";
}

/// Every stage of a kind listed where cull_frame runs it: after the built-in stage its kind follows, with
/// nothing but stages of its kind or of a kind that runs before it in between (box classification, then
/// depth). The order of the frame's reason is then the order the stages ran.
template <class... Stages>
constexpr bool listed_where_they_run(StageList<Stages...>) {
  constexpr StageKind kinds[] = {Stages::kKind...};
  constexpr const char* names[] = {Stages::kName...};
  const char* last_builtin = "";
  StageKind last = StageKind::Builtin;
  for (std::size_t i = 0; i < sizeof...(Stages); ++i) {
    if (kinds[i] == StageKind::Builtin) {
      last_builtin = names[i];
    } else if (!same_name(last_builtin, runs_after(kinds[i])) ||
               (last != StageKind::Builtin && static_cast<int>(last) > static_cast<int>(kinds[i]))) {
      return false;
    }
    last = kinds[i];
  }
  return true;
}
static_assert(listed_where_they_run(PipelineStages<double>{}),
              "stages/list.hpp: a box classification or depth stage goes after DepthMaskStage, an evidence "
              "stage after SubBoxStage (stages/stage.hpp, StageKind)");
}  // namespace detail

/// The place of the stage named `name` in front-end order (its index in kStages); kStages<T>.size() when
/// no stage has that name.
template <class T>
std::size_t stage_index(const std::string& name) {
  std::size_t i = 0;
  while (i < kStages<T>.size() && name != kStages<T>[i].name) ++i;
  return i;
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

}  // namespace dyncull
