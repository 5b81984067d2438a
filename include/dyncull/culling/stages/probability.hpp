/// @file probability.hpp
/// Stage 5 of the culling pipeline: the dynamic probability P = a1 S + a2 M + a3 K (DLD-SLAM 2024
/// eq. 3-5) of the features in the object masks; its decisions replace their semantic labels.
#pragma once

#include "dyncull/culling/stages/geometric.hpp"

#include <cstddef>

namespace dyncull {
namespace detail {

/// What the probability reads: its options, the class levels, and the inputs it needs (its declaration in stages/builtin.hpp).
template <class T>
struct ProbabilitySlice {
  const ProbabilityStageOptions<T>& probability;
  const MotionLevelTable& levels;
  FrameInputs needs;
  ProbabilitySlice(const PipelineOptions<T>& o)  // implicit: the pipeline passes its options
      : probability(o.probability), levels(o.levels), needs(stage_needs<ProbabilityStage<T>>(o)) {}
};

/// out->labels / reasons: the semantic labels with the probability's decisions (valid when out->ok).
template <class T, class Frame>
void score_probability(const Frame& frame, const NonDeduced<ProbabilitySlice<T>>& options, const BoxRegions<T>& regions,
                       const SemanticEvidence<T>& semantic, const GeometricEvidence<T>& geometric,
                       TrackStateStore* track_states, ProbabilityEvidence<T>* out, PipelineResult<T>* r) {
  ProbabilityEvidence<T>& p = *out;
  p.ok = false;
  if (!options.probability.enabled) return;
  const auto& kp = *frame.keypoints;
  const std::size_t n = r->num_features;
  if (!has_needed_inputs(frame, options.needs, &r->probability)) return;
  const FlagView track_valid = frame.track_valid;  // accept_inputs checked its size
  p.levels.assign(n, MotionLevel::Ignore);
  p.prev.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const bool valid = !track_valid.given || track_valid[i] != 0;
    p.prev[i] = valid ? Vec2<T>(point_x<T>((*frame.prev_keypoints)[i]), point_y<T>((*frame.prev_keypoints)[i]))
                      : Vec2<T>(Constants<T>::nan(), Constants<T>::nan());
    if (semantic.in_dyn_box[i] && semantic.in_object[i] && semantic.rule_ok && i < semantic.rule.box_index.size() &&
        semantic.rule.box_index[i] >= 0)
      p.levels[i] = options.levels.level(regions.boxes[static_cast<std::size_t>(semantic.rule.box_index[i])].class_id);
  }
  EgoMotion<T> ego;
  if (options.probability.flow_model == FlowModel::Fundamental && r->moving_consistency.ran()) {
    ego.model = FlowModel::Fundamental;
    ego.matrix = geometric.moving.F;
  }
  if (frame.track_ids) track_states->begin_frame();
  DynamicProbabilityResult<T>& pr = p.result;
  dynamic_probability(p.prev, kp, p.levels, options.probability, ego, frame.track_ids ? track_states : nullptr,
                      frame.track_ids, &pr, &p.scratch);
  r->probability.status = pr.status;
  r->probability.reason = pr.reason;
  if (!pr.ok()) return;
  p.ok = true;
  r->probability.num_dynamic = pr.num_dynamic;
  p.labels.assign(semantic.labels.begin(), semantic.labels.end());
  p.reasons.assign(semantic.reasons.begin(), semantic.reasons.end());
  for (std::size_t i = 0; i < n; ++i) {
    if (p.levels[i] == MotionLevel::Ignore || p.reasons[i] == CullReason::InvalidInput) continue;
    p.labels[i] = pr.labels[i];
    p.reasons[i] = pr.labels[i] == FeatureLabel::Dynamic ? CullReason::Probability : CullReason::None;
  }
}

}  // namespace detail
}  // namespace dyncull
