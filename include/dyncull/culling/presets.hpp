/// @file presets.hpp
/// Pipeline configurations reproducing each source paper (000 DLD-SLAM, Yu et al. 2024; 001 RTD-SLAM, Gao
/// et al. 2024; 002 Zhu et al. 2024; 003 DFD-SLAM, Qian et al. 2024; 004 Zhang et al. 2023; numbered as in
/// docs/algorithms.md) and the recommended combination (reasons in the comments, figures in docs/results.md).
#pragma once

#include "dyncull/culling/pipeline.hpp"

namespace dyncull {
namespace presets {

/// Everything off; each preset switches on what its paper runs.
template <class T>
PipelineOptions<T> none() {
  PipelineOptions<T> o;
  o.use_detection_filter = true;
  o.use_box_tracker = false;
  o.use_box_rule = false;
  o.use_depth_mask = false;
  o.use_probability = false;
  o.use_moving_consistency = false;
  o.use_subbox = false;
  o.use_multiview = false;
  o.candidates = CandidatePolicy::Keep;
  return o;
}

/// 000 DLD-SLAM: depth-threshold object mask inside detection boxes (eq. 1-2, plain rule), then the
/// dynamic probability P = a1 S + a2 M + a3 K (eq. 3-5) of the features in the masks with the
/// paper's mean-flow M. Features in a box but outside its mask stay static.
template <class T>
PipelineOptions<T> dld_slam() {
  PipelineOptions<T> o = none<T>();
  o.use_box_rule = true;  // provides the motion level (S) of each box
  o.box_rule.medium_as_candidate = true;
  o.use_depth_mask = true;
  o.depth_mask.mode = DepthMaskMode::Plain;
  o.use_probability = true;
  o.probability_flow_model = FlowModel::MeanFlow;
  o.candidates = CandidatePolicy::Keep;  // medium-level features the probability could not decide
  return o;
}

/// 001 RTD-SLAM: motion levels and box culling (high-level boxes culled, medium-level ones sent to
/// verification), and the multi-view geometry check (30 deg, 0.4 m) on every feature.
template <class T>
PipelineOptions<T> rtd_slam() {
  PipelineOptions<T> o = none<T>();
  o.use_box_rule = true;
  o.box_rule.medium_as_candidate = true;
  o.use_multiview = true;
  o.multiview.depth_threshold_m = T(0.4);
  o.multiview.max_parallax_deg = T(30);
  o.multiview_overrides_static = true;
  o.candidates = CandidatePolicy::Verify;
  return o;
}

/// 002 Zhu et al.: the static/dynamic box rule of Table 2 only (dynamic in a dynamic box and in no
/// static box); no medium level.
template <class T>
PipelineOptions<T> zhu_2024() {
  PipelineOptions<T> o = none<T>();
  o.use_box_rule = true;
  o.box_rule.medium_as_candidate = false;
  o.candidates = CandidatePolicy::Keep;
  return o;
}

/// 003 DFD-SLAM: LK tracks, F-RANSAC and the epipolar distance (eq. 1-3, 1 px), refined by the 3x3
/// sub-box vote (Algorithm 1) with the paper's literal merge (every static neighbour of a dynamic
/// sub-box) and sigma2 = 4. Boxes are only used by the refinement (no semantic culling of their own).
template <class T>
PipelineOptions<T> dfd_slam() {
  PipelineOptions<T> o = none<T>();
  o.use_box_rule = true;  // marks which features lie in dynamic-class boxes
  o.box_rule.medium_as_candidate = true;
  o.use_moving_consistency = true;
  o.moving.fit_outside_boxes = false;
  o.moving.max_epipolar_distance_in_boxes_px = o.moving.max_epipolar_distance_px;
  o.use_subbox = true;
  o.subbox.merge_ratio = T(0);
  o.subbox_requires_fit_outside_boxes = false;
  o.cull_geometric_outside_boxes = false;
  o.candidates = CandidatePolicy::Verify;
  return o;
}

/// 004 Zhang et al.: the logical discrimination of Algorithm 1: high- and medium-level boxes are
/// dynamic unless the feature is also in a low-level box.
template <class T>
PipelineOptions<T> zhang_2023() {
  PipelineOptions<T> o = none<T>();
  o.use_box_rule = true;
  o.box_rule.medium_as_candidate = true;
  o.candidates = CandidatePolicy::Cull;
  return o;
}

/// Recommended: the box rule with the low-level override (002/004) for features at the low-level object's
/// depth, limited to the object's depth band (000), verified per region by the geometric check fitted
/// outside the boxes (003 + SG-SLAM: the RGB-D reprojection check where the caller gives 3-D points, else
/// the epipolar one) and the evidence-aware sub-box vote, with a tracker for missed dynamic-class boxes,
/// each track's static history and the survivor guard. Its per-option evidence is the ablation table of
/// docs/results.md (scripts/ablation.sh); how each value was chosen is in the git log.
/// Inputs: prev_keypoints and points_3d measured in the front end's keyframe (slow movers build up a
/// measurable displacement only over several frames), evidence_frames = frames since that keyframe, and
/// track_ids for the static history.
/// Left out: the probability (000; its M term is the geometric evidence already used, its S term the box
/// rule) and the multi-view check (001; with static features protected it only verifies candidates).
template <class T>
PipelineOptions<T> recommended() {
  PipelineOptions<T> o;
  o.use_detection_filter = true;
  o.use_box_tracker = true;
  o.use_box_rule = true;
  o.box_rule.medium_as_candidate = true;
  o.use_depth_mask = true;
  o.depth_mask.mode = DepthMaskMode::Robust;
  // A feature on a pixel without depth in a mover's box is culled: on a silhouette such a track is
  // dragged along the contour.
  o.depth_mask.missing_depth = MissingDepth::InMask;
  // The top of 000's eps range (0.3-0.5 m): a walker within a metre of the camera, seen obliquely, reaches
  // more than 0.3 m behind its centre depth.
  o.depth_mask.eps_m = 0.5;
  o.use_probability = false;
  o.use_moving_consistency = true;
  o.moving.fit_outside_boxes = true;
  // Tracks from the keyframe: 1 px in boxes (0.5 px suits frame-to-frame tracks).
  o.moving.max_epipolar_distance_in_boxes_px = T(1);
  // Acts only when the frame carries points_3d; the residual also sees motion along the epipolar line.
  o.use_reprojection = true;
  o.reprojection_evidence = PipelineOptions<T>::Evidence::Replace;
  // With the depth image it also compares depths: a walker heading for the camera barely moves in the image.
  o.reprojection.max_depth_residual_sigmas = T(5);
  // A feature in overlapping masks belongs to the object nearest its depth, a person unless the other is
  // nearer by 0.15 m (a seated person's torso and its chair lie at nearly the same depth).
  o.assign_overlaps_by_depth = true;
  o.overlap_high_level_margin_m = 0.15;
  // A TV box shelters only what is at the TV's depth, not a walker passing in front of it.
  o.low_override_by_depth = true;
  o.edge_evidence_radius_px = 8;  // flags on occlusion edges are contour tracking, not motion
  o.use_subbox = true;
  o.subbox.object_mask_votes_only = true;
  // A sub-box is kept only on a clear static vote (at most 30 % of its features flagged): empty cells and
  // split votes stay with the box rule.
  o.subbox.static_needs_evidence = true;
  o.subbox.static_max_dynamic_ratio = T(0.3);
  // The paper's whole-box rule (sigma2 = 4) also culls movers their own cell's static vote missed.
  o.subbox.sigma2 = 4;
  // A person's cell whose residuals share a significant median counts as flagged: a seated person's sway
  // stays under the per-track thresholds.
  o.use_coherent_motion = true;
  // A track found still (residual under 0.8 px, not flagged) in each of its last 6 evaluated frames stays
  // static whatever its region says: a seated person's legs and chair share the cells its sway votes dynamic.
  o.static_history.min_frames = 6;
  o.static_history.max_residual_px = T(0.8);
  // Candidates (a chair) are culled on their own flags, not by a person's sub-box vote.
  o.subbox_verifies_candidates = false;
  // On a one-frame baseline "not flagged" says nothing about a slow mover: the box rule decides, except in
  // the cells of a tracked box that voted within those frames (its still legs stay static).
  o.min_evidence_frames = 2;
  o.short_baseline_keeps_last_vote = true;
  o.subbox_memory_frames = 0;  // a remembered vote culls more static features than it finds movers
  o.use_multiview = false;
  // When switched on: outside boxes a depth jump is more often a sensor edge; a region is capped at about a
  // person at 2-3 m (20k pixels at 640x480).
  o.multiview_overrides_static = false;
  o.multiview.max_region_pixels = 20000;
  o.cull_geometric_outside_boxes = false;
  o.candidates = CandidatePolicy::Verify;
  o.survivor_guard = true;
  return o;
}

}  // namespace presets
}  // namespace dyncull
