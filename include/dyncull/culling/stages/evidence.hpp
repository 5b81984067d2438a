/// @file evidence.hpp
/// The evidence stages of stages/list.hpp run in order over one frame, each on its options slice, and the
/// flag the combination reads from them. Pipeline plumbing, no paper equation (the multi-view check of
/// RTD-SLAM 2024 §III.A is one such stage: stages/multiview.hpp).
#pragma once

#include "dyncull/culling/stages/context.hpp"

#include <cstddef>
#include <cstdint>
#include <tuple>
#include <type_traits>

namespace dyncull {
namespace detail {

/// Runs Stage when it is enabled and the frame has what it needs: out->dynamic one flag per feature (all 0
/// otherwise), out->ok when it ran; reports into its StageReport (MissingInput naming the input it lacks).
template <class Stage, class T, class Frame>
void run_evidence_stage(const Frame& frame, const PipelineOptions<T>& options, const EvidenceContext<T>& context,
                        StageFlags<Stage>* out, PipelineResult<T>* r) {
  const typename Stage::Options& stage_options = options.*Stage::kOptions;
  StageReport& report = r->*Stage::kReport;
  out->dynamic.assign(r->num_features, 0);
  out->ok = false;
  if (!stage_options.enabled) return;
  if (!has_needed_inputs(frame, Stage::needs(stage_options), &report, !context.keyframes.empty())) return;
  Stage::run(frame, stage_options, context, &out->work, out->dynamic.data(), &report);
  if (!report.ran()) return;
  for (std::uint8_t d : out->dynamic) report.num_dynamic += d != 0;
  out->ok = true;
}

/// Every evidence stage of the list, in order.
template <class T, class Frame>
void run_evidence_stages(const Frame& frame, const PipelineOptions<T>& options, const KeyframeRing<T>& keyframes,
                         PipelineWork<T>* w, PipelineResult<T>* r) {
  const EvidenceContext<T> context{*w, keyframes};
  std::apply([&](auto&... flags) { (run_evidence_stage(frame, options, context, &flags, r), ...); },
             w->evidence_flags);
}

/// True when an evidence stage that ran flags feature i, with *why its CullReason (the first in list order).
template <class T>
bool evidence_flagged(const PipelineWork<T>& w, std::size_t i, CullReason* why) {
  return std::apply(
      [&](const auto&... flags) {
        return ((flags.ok && flags.dynamic[i] &&
                 (*why = std::decay_t<decltype(flags)>::StageType::kReason, true)) ||
                ...);
      },
      w.evidence_flags);
}

}  // namespace detail
}  // namespace dyncull
