/// @file listed.hpp
/// The stages of stages/list.hpp that run by their kind (stages/stage.hpp): each run at its place on its
/// options slice, and what the pipeline does with their marks (box classifications raise the semantic
/// labels, depth stages clear them off the object, evidence flags cull). Pipeline plumbing, no paper
/// equation (the multi-view check of RTD-SLAM 2024 §III.A is one such stage: stages/multiview.hpp).
#pragma once

#include "dyncull/culling/stages/context.hpp"

#include <cstddef>
#include <cstdint>
#include <tuple>
#include <type_traits>
#include <vector>

namespace dyncull {
namespace detail {

/// Runs Stage when it is enabled and the frame has what it needs: out->marks one zeroed mark per feature
/// (left so otherwise), out->ok when it ran; reports into its StageReport (MissingInput naming the input
/// it lacks). num_dynamic counts the features it labels Dynamic (box classification) or flags (evidence).
template <class Stage, class T, class Frame>
void run_listed_stage(const Frame& frame, const PipelineOptions<T>& options, const StageContext<T>& context,
                      StageMarks<Stage>* out, PipelineResult<T>* r) {
  using Mark = typename StageMarks<Stage>::Mark;
  const typename Stage::Options& stage_options = options.*Stage::kOptions;
  StageReport& report = r->*Stage::kReport;
  out->marks.assign(r->num_features, Mark{});
  out->ok = false;
  if (!stage_options.enabled) return;
  if (!has_needed_inputs(frame, stage_needs<Stage>(options), &report, !context.keyframes.empty()))
    return;
  Stage::run(frame, stage_options, context, &out->work, out->marks.data(), &report);
  if (!report.ran()) return;
  const Mark counted = Stage::kKind == StageKind::BoxClassification ? Mark(FeatureLabel::Dynamic) : Mark(1);
  if (Stage::kKind != StageKind::Depth)
    for (Mark m : out->marks) report.num_dynamic += m == counted;
  out->ok = true;
}

/// Every listed stage of kind Kind, in list order.
template <StageKind Kind, class T, class Frame>
void run_listed_stages(const Frame& frame, const PipelineOptions<T>& options, const KeyframeRing<T>& keyframes,
                       PipelineWork<T>* w, PipelineResult<T>* r) {
  const StageContext<T> context{*w, keyframes};
  auto run_one = [&](auto& out) {
    using Stage = typename std::decay_t<decltype(out)>::StageType;
    if constexpr (Stage::kKind == Kind) run_listed_stage(frame, options, context, &out, r);
  };
  std::apply([&](auto&... out) { (run_one(out), ...); }, w->listed);
}

/// Calls f(stage's marks, stage's kReason) for each listed stage of kind Kind that ran this frame.
template <StageKind Kind, class T, class F>
void for_each_ran(const PipelineWork<T>& w, F&& f) {
  auto visit = [&](const auto& out) {
    using Stage = typename std::decay_t<decltype(out)>::StageType;
    if constexpr (Stage::kKind == Kind)
      if (out.ok) f(out.marks, Stage::kReason);
  };
  std::apply([&](const auto&... out) { (visit(out), ...); }, w.listed);
}

/// The box classification stages' labels raise the semantic labels: a feature they label higher than the
/// box rule and the depth masks did (Candidate over Static, Dynamic over both) takes their label and
/// kReason, the first stage in list order among equals. A feature with invalid coordinates stays so.
template <class T>
void add_box_classifications(PipelineWork<T>* w) {
  SemanticEvidence<T>& s = w->semantic;
  for_each_ran<StageKind::BoxClassification>(*w, [&](const std::vector<FeatureLabel>& marks, CullReason why) {
    for (std::size_t i = 0; i < marks.size(); ++i) {
      if (s.reasons[i] == CullReason::InvalidInput || marks[i] <= s.labels[i]) continue;
      s.labels[i] = marks[i];
      s.reasons[i] = why;
    }
  });
}

/// The depth stages' flags take features off their box labels: a Candidate or Dynamic feature (not one
/// with invalid coordinates) that a depth stage flags becomes Static, outside its object.
template <class T>
void limit_by_depth_stages(PipelineWork<T>* w) {
  SemanticEvidence<T>& s = w->semantic;
  for_each_ran<StageKind::Depth>(*w, [&](const std::vector<std::uint8_t>& off_object, CullReason) {
    for (std::size_t i = 0; i < off_object.size(); ++i) {
      if (!off_object[i] || s.labels[i] == FeatureLabel::Static || s.reasons[i] == CullReason::InvalidInput) continue;
      s.labels[i] = FeatureLabel::Static;
      s.reasons[i] = CullReason::None;
      s.in_object[i] = 0;
    }
  });
}

/// True when an evidence stage that ran flags feature i, with *why its CullReason (the first in list order).
template <class T>
bool evidence_flagged(const PipelineWork<T>& w, std::size_t i, CullReason* why) {
  bool flagged = false;
  for_each_ran<StageKind::Evidence>(w, [&](const std::vector<std::uint8_t>& flags, CullReason stage_reason) {
    if (flagged || !flags[i]) return;
    flagged = true;
    *why = stage_reason;
  });
  return flagged;
}

}  // namespace detail
}  // namespace dyncull
