/// @file pipeline.hpp
/// The culling pipeline: the semantic (Zhu et al. 2024 / Zhang et al. 2023 box rule, DLD-SLAM 2024 depth
/// mask and probability) and geometric (DFD-SLAM 2024 epipolar + sub-box, RTD-SLAM 2024 multi-view)
/// strategies run as named stages in front-end order (culling/stages/), with a survivor guard.
#pragma once

#include "dyncull/culling/pipeline_types.hpp"
#include "dyncull/culling/stages/boxes.hpp"
#include "dyncull/culling/stages/combine.hpp"
#include "dyncull/culling/stages/context.hpp"
#include "dyncull/culling/stages/listed.hpp"
#include "dyncull/culling/stages/geometric.hpp"
#include "dyncull/culling/stages/inputs.hpp"
#include "dyncull/culling/stages/probability.hpp"
#include "dyncull/culling/stages/region_votes.hpp"
#include "dyncull/culling/stages/semantic.hpp"

namespace dyncull {

/// Runs the enabled strategies on one frame and returns the labels (a reference into `state`, valid
/// until the next call). Never throws. An enabled stage whose input the frame lacks (no prev_keypoints,
/// depth, points_3d, cam_from_world, detections, track_ids, or no reference keyframe yet) does not run:
/// its report says MissingInput, and so does the frame's status, with "stage: input" in the reason; the
/// labels and keep mask are those of the stages that ran (labelled() is true). A stage with nothing to
/// do (a frame without boxes, detections given as an empty vector) is not missing input. An enabled stage
/// that ran but could not do its job (its own InvalidInput, TooFewPoints, Degenerate, NonFinite, ...)
/// gives the frame that status, outranking MissingInput, with "stage: why" in the reason; the labels are
/// still those of the other stages. Ok means every enabled stage did its job. Options that fail
/// PipelineOptions::validate, an invalid depth view (DepthView::validate) or a given per-keypoint
/// input (prev_keypoints, track_valid, track_ids, points_3d) whose size is not the keypoints' give status
/// InvalidInput with the reason and cull nothing (refused, labelled() false): every keypoint is labelled
/// Static and kept.
///
/// Each stage reads the earlier stages' outputs and writes only its own (stages/context.hpp); the stages
/// are those of stages/list.hpp, in its order:
///   boxes -> semantic evidence (box rule, depth masks) -> box classification and depth stages
///   -> geometric evidence (tracks, 3-D points) -> probability (semantic labels in the masks)
///   -> region votes (coherent cells, sub-boxes) -> evidence stages (the multi-view check)
///   -> combination -> static history -> survivor guard -> keyframe store.
template <class T, class Keypoints, class Prev, class Raw, class Points3>
const PipelineResult<T>& cull_frame(const CullingFrame<T, Keypoints, Prev, Raw, Points3>& frame,
                                    const PipelineOptions<T>& options, PipelineState<T>* state) {
  static_assert(is_point_container_v<Keypoints>, "dyncull::cull_frame: keypoints must hold points (see PointTraits)");
  static_assert(is_point_container_v<Prev>, "dyncull::cull_frame: prev_keypoints must hold points");
  PipelineState<T>& s = *state;
  PipelineResult<T>& r = s.result;
  detail::PipelineWork<T>& w = detail::work_of(state);
  ++s.frame_index;
  detail::begin_frame(options, &r);
  if (!detail::accept_inputs(frame, options, &r)) return r;

  detail::collect_boxes(frame, options, &s.tracker, &w.regions, &r);
  detail::classify_by_boxes(frame, options, w.regions, &w.semantic, &r);
  detail::run_listed_stages<StageKind::BoxClassification>(frame, options, s.keyframes, &w, &r);
  detail::add_box_classifications(&w);
  detail::run_listed_stages<StageKind::Depth>(frame, options, s.keyframes, &w, &r);
  detail::limit_by_depth_stages(&w);
  detail::gather_geometric_evidence(frame, options, w.regions, w.semantic, &w.geometric, &r);
  detail::score_probability(frame, options, w.regions, w.semantic, w.geometric, &s.track_states, &w.probability, &r);
  detail::vote_regions(frame, options, s.frame_index, w.regions, w.semantic, w.semantic_labels(), w.geometric,
                       &s.subbox_memory, &w.votes, &r);
  detail::run_listed_stages<StageKind::Evidence>(frame, options, s.keyframes, &w, &r);
  detail::combine_evidence(options, w, &r);
  detail::apply_static_history(frame, options, w.geometric, &s.static_history, &w.still_frames, &w.history_kept, &r);
  detail::guard_survivors(options, &r);
  detail::report_stage_outcomes(&r);
  detail::trace_features(w, &r);
  detail::store_keyframe(frame, r, &w.keypoint_depth, &s.keyframes);
  return r;
}

}  // namespace dyncull

#include "dyncull/culling/pipeline_extern.hpp"  // instantiations precompiled in dyncull::pipeline
