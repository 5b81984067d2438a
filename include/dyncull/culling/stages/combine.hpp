/// @file combine.hpp
/// Stages 8-10 of the culling pipeline: the per-feature combination in the order of evidence strength
/// (semantics, then the geometric refinements; candidates resolved as in RTD-SLAM 2024 §III.D), the
/// static history of each track, the minimum-survivor guard (SG-SLAM 2023's 10 %) and the keyframe store.
#pragma once

#include "dyncull/culling/stages/context.hpp"
#include "dyncull/culling/stages/listed.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>

namespace dyncull {
namespace detail {

/// What the combination reads: the policy for candidates, and whether a dynamic sub-box culls them.
struct CombineSlice {
  CandidatePolicy candidates;
  bool subbox_verifies_candidates;
  template <class T>
  CombineSlice(const PipelineOptions<T>& o)  // implicit: the pipeline passes its options
      : candidates(o.candidates), subbox_verifies_candidates(o.subbox.verifies_candidates) {}
};

/// r.labels / r.reasons from the stages' evidence.
template <class T>
void combine_evidence(const CombineSlice& options, const PipelineWork<T>& w, PipelineResult<T>* r) {
  const std::size_t n = r->num_features;
  const std::vector<FeatureLabel>& sem_labels = w.semantic_labels();
  const std::vector<CullReason>& sem_reasons = w.semantic_reasons();
  const bool geo_ok = w.geometric.ok;
  const FeatureLabel* const evidence = w.evidence();
  const bool subbox_ok = w.votes.ok;
  for (std::size_t i = 0; i < n; ++i) {
    FeatureLabel lab = sem_labels[i];
    CullReason why = sem_reasons[i];
    if (why == CullReason::InvalidInput) {
      r->labels[i] = FeatureLabel::Dynamic;
      r->reasons[i] = why;
      continue;
    }
    const bool sheltered = why == CullReason::LowLevelOverride;
    const bool geo_dyn = geo_ok && evidence[i] == FeatureLabel::Dynamic;
    bool geo_flagged = geo_dyn;
    if (subbox_ok) {
      const CullReason vote = w.votes.subbox.reasons[i];
      if (lab == FeatureLabel::Candidate && !options.subbox_verifies_candidates) {
        // Stays a candidate, verified below on its own evidence: flagged itself inside a dynamic sub-box,
        // or by the multi-view check.
        geo_flagged = geo_dyn && vote == CullReason::SubBox;
        if (geo_flagged) why = CullReason::SubBox;
      } else if (vote == CullReason::SubBox && (!sheltered || geo_dyn)) {
        lab = FeatureLabel::Dynamic;
        why = geo_dyn && w.evidence_source(i) == CullReason::CoherentMotion ? CullReason::CoherentMotion
                                                                             : CullReason::SubBox;
        geo_flagged = true;
      } else if (w.semantic.in_dyn_box[i] && sem_reasons[i] != CullReason::Probability) {
        lab = FeatureLabel::Static;  // refined: in a static sub-box of its box
        why = CullReason::None;
      }
      // Outside the boxes a geometric flag alone culls nothing: an unexplained flow outlier there is more
      // often tracking error than a mover the detector missed.
    } else if (geo_dyn && lab == FeatureLabel::Candidate) {
      lab = FeatureLabel::Dynamic;
      why = w.evidence_source(i);
    }
    CullReason flag_reason = CullReason::None;
    if (evidence_flagged(w, i, &flag_reason)) {
      geo_flagged = true;
      if (lab != FeatureLabel::Dynamic) {  // a flag culls wherever it is (DynaSLAM's multi-view rule)
        lab = FeatureLabel::Dynamic;
        why = flag_reason;
      }
    }
    if (lab == FeatureLabel::Candidate) {
      const bool cull = options.candidates == CandidatePolicy::Cull ||
                        (options.candidates == CandidatePolicy::Verify && geo_flagged);
      lab = cull ? FeatureLabel::Dynamic : FeatureLabel::Static;
      if (!cull) why = CullReason::None;
    }
    r->labels[i] = lab;
    r->reasons[i] = lab == FeatureLabel::Static ? CullReason::None : why;
  }
}

/// What the static history reads: its options, the shortest baseline that may vote (a slow mover is not
/// proven still over fewer frames), and the inputs it needs (its declaration in stages/builtin.hpp).
template <class T>
struct StaticHistorySlice {
  const StaticHistoryStageOptions<T>& static_history;
  int min_evidence_frames;
  FrameInputs needs;
  StaticHistorySlice(const PipelineOptions<T>& o)  // implicit: the pipeline passes its options
      : static_history(o.static_history),
        min_evidence_frames(o.subbox.min_evidence_frames),
        needs(stage_needs<StaticHistoryStage<T>>(o)) {}
};

/// A track proven still over its last frames outweighs its region's cull (PipelineOptions::static_history).
template <class T, class Frame>
void apply_static_history(const Frame& frame, const NonDeduced<StaticHistorySlice<T>>& options,
                          const GeometricEvidence<T>& geometric, StaticHistory* history,
                          std::vector<std::uint16_t>* still_frames, std::vector<std::uint8_t>* kept,
                          PipelineResult<T>* r) {
  const std::size_t n = r->num_features;
  kept->assign(n, 0);
  if (!r->static_history.enabled) return;
  if (!has_needed_inputs(frame, options.needs, &r->static_history)) return;
  const ReprojectionCheckResult<T>& rp = geometric.reprojection;
  const bool checked = r->reprojection.ran() && rp.labels.size() == n && rp.residual_px.size() == n;
  // A baseline too short to vote (subbox.min_evidence_frames) is too short to prove a slow mover still.
  const bool evaluated = checked && (frame.evidence_frames <= 0 ||
                                     frame.evidence_frames >= std::max(1, options.min_evidence_frames));
  history->update(*frame.track_ids, checked ? ArrayView<FeatureLabel>(rp.labels) : nullptr,
                  checked ? ArrayView<T>(rp.residual_px) : nullptr, evaluated, options.static_history.max_residual_px,
                  still_frames);
  if (!checked) {
    r->static_history.reason =
        "needs the reprojection check (reprojection.enabled, points_3d), which did not run: counts carried over";
    return;
  }
  const auto min_frames = static_cast<std::uint16_t>(std::min(options.static_history.min_frames, 0xFFFF));
  for (std::size_t i = 0; i < n; ++i) {
    if (r->labels[i] != FeatureLabel::Dynamic || !is_regional_cull(r->reasons[i]) || (*still_frames)[i] < min_frames ||
        rp.labels[i] == FeatureLabel::Dynamic)
      continue;
    r->labels[i] = FeatureLabel::Static;
    r->reasons[i] = CullReason::None;
    (*kept)[i] = 1;
    ++r->history_kept;
  }
  r->static_history.status = Status::Ok;
  // Built in place: the report's string keeps its capacity from frame to frame.
  r->static_history.reason.assign(std::to_string(r->history_kept));
  r->static_history.reason += " feature(s) kept static by their history";
}

/// What the survivor guard reads: its options.
struct SurvivorGuardSlice {
  const SurvivorGuardOptions& guard;
  template <class T>
  SurvivorGuardSlice(const PipelineOptions<T>& o) : guard(o.guard) {}  // implicit: the pipeline passes its options
};

/// Minimum-survivor guard: below max(guard.min_fraction * n, guard.min_survivors) static features, first
/// soften (restore the culls of single geometric stages and of candidates), then undo all culling.
template <class T>
void guard_survivors(const SurvivorGuardSlice& options, PipelineResult<T>* r) {
  const std::size_t n = r->num_features;
  auto count_static = [&]() {
    std::size_t c = 0;
    for (std::size_t i = 0; i < n; ++i) c += r->labels[i] == FeatureLabel::Static;
    return c;
  };
  std::size_t survivors = count_static();
  // The fraction is clamped to [0, 1] before the conversion (validate() rejects others; NaN counts as 0).
  const double survivor_fraction =
      options.guard.min_fraction >= 0 ? std::min(options.guard.min_fraction, 1.0) : 0.0;
  const std::size_t need =
      std::max(options.guard.min_survivors,
               static_cast<std::size_t>(std::ceil(survivor_fraction * double(n))));  // checked: fraction in [0, 1]
  if (options.guard.enabled && survivors < need && n > 0) {
    std::size_t soft = 0;
    for (std::size_t i = 0; i < n; ++i) soft += r->labels[i] == FeatureLabel::Dynamic && is_soft_cull(r->reasons[i]);
    const bool soften_enough = survivors + soft >= need;
    for (std::size_t i = 0; i < n; ++i) {
      if (r->labels[i] != FeatureLabel::Dynamic || r->reasons[i] == CullReason::InvalidInput) continue;
      if (soften_enough && !is_soft_cull(r->reasons[i])) continue;
      r->labels[i] = FeatureLabel::Static;
      r->reasons[i] = CullReason::SurvivorGuardUndo;
      ++r->guard_restored;
    }
    r->guard = soften_enough ? GuardAction::Softened : GuardAction::Undone;
    std::string& why = r->reason;
    why.assign("survivor guard ");
    why += to_string(r->guard);
    why += ": ";
    why += std::to_string(survivors);
    why += " static features of ";
    why += std::to_string(n);
    why += " were below ";
    why += std::to_string(need);
    why += ", ";
    why += std::to_string(r->guard_restored);
    why += " restored";
    survivors = count_static();
  }
  r->num_static = survivors;
  r->num_dynamic = n - survivors;
  r->keep.resize(n);
  for (std::size_t i = 0; i < n; ++i) r->keep[i] = r->labels[i] == FeatureLabel::Static;
}

/// The frame's status, the worst of its enabled stages': the first stage (front-end order) that failed
/// (a status other than Ok, Skipped and MissingInput), else MissingInput when a stage lacked an input of
/// the frame, else Ok. The reason (after the guard's, if any) says "stage: why" for each of them; the
/// labels stay those of the stages that did their job.
template <class T>
void report_stage_outcomes(PipelineResult<T>* r) {
  Status failed = Status::Ok;
  for (const StageDeclaration<T>& stage : kStages<T>) {
    const StageReport& st = r->*stage.report;
    const Status s = st.status;
    if (!st.enabled || s == Status::Ok || s == Status::Skipped) continue;
    if (s != Status::MissingInput && failed == Status::Ok) failed = s;
    if (r->status == Status::Ok) r->status = Status::MissingInput;
    if (!r->reason.empty()) r->reason += "; ";
    r->reason += stage.name;
    r->reason += ": ";
    if (st.reason.empty())
      r->reason += to_string(s);
    else
      r->reason += st.reason;
  }
  if (failed != Status::Ok) r->status = failed;
}

/// r.trace: what the stages saw of each feature.
template <class T>
void trace_features(const PipelineWork<T>& w, PipelineResult<T>* r) {
  const std::size_t n = r->num_features;
  const std::vector<FeatureLabel>& sem = w.semantic_labels();
  const FeatureLabel* const geo = w.geometric.ok ? w.evidence() : nullptr;
  r->trace.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    FeatureTrace& t = r->trace[i];
    t.semantic = sem[i];
    t.geometric = geo ? geo[i] : FeatureLabel::Candidate;
    t.in_dynamic_box = w.semantic.in_dyn_box[i];
    t.in_object = w.semantic.in_object[i];
    t.history_kept = w.history_kept[i];
  }
}

/// A keyframe for later multi-view checks: this frame's static features with their depth.
template <class T, class Frame>
void store_keyframe(const Frame& frame, const PipelineResult<T>& r, std::vector<T>* keypoint_depth,
                    KeyframeRing<T>* keyframes) {
  if (!frame.is_keyframe || !frame.cam_from_world || !frame.cam_from_world->all_finite() || frame.depth.empty()) return;
  const auto& kp = *frame.keypoints;
  const std::size_t n = r.num_features;
  keypoint_depth->assign(n, T(0));
  for (std::size_t i = 0; i < n; ++i) {
    int u = 0, v = 0;
    if (keypoint_in_image<T>(kp, i, frame.depth.width, frame.depth.height, &u, &v))
      (*keypoint_depth)[i] = T(frame.depth.depth_m(u, v));
  }
  keyframes->push(*frame.cam_from_world, kp, *keypoint_depth, r.keep);
}

}  // namespace detail
}  // namespace dyncull
