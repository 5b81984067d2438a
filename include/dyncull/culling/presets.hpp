/// @file presets.hpp
/// Pipeline configurations reproducing each source paper (DLD-SLAM, Yu et al. 2024; RTD-SLAM, Gao et al. 2024;
/// Zhu et al. 2024; DFD-SLAM, Qian et al. 2024; Zhang et al. 2023; cited in full in
/// docs/algorithms.md) and the recommended combination. Each preset says what it runs and why; the figures
/// behind the recommended one are the ablation table of docs/results.md.
#pragma once

#include "dyncull/culling/pipeline.hpp"

namespace dyncull {
namespace presets {

/// Every stage off but the detection filter; each preset switches on what its paper runs.
template <class T>
PipelineOptions<T> none() {
  PipelineOptions<T> o;
  o.detections.enabled = true;
  o.tracker.enabled = false;
  o.box_rule.enabled = false;
  o.depth_mask.enabled = false;
  o.probability.enabled = false;
  o.moving_consistency.enabled = false;
  o.subbox.enabled = false;
  o.multiview.enabled = false;
  o.candidates = CandidatePolicy::Keep;
  return o;
}

/// DLD-SLAM (Yu et al. 2024): the depth-threshold object mask inside the boxes (eq. 1-2, plain rule), then the dynamic
/// probability P = a1 S + a2 M + a3 K (eq. 3-5) of the features in the masks with the paper's mean-flow M.
/// Features in a box but outside its mask stay static.
template <class T>
PipelineOptions<T> dld_slam() {
  PipelineOptions<T> o = none<T>();
  o.box_rule.enabled = true;  // the motion level of each box is the probability's S term
  o.box_rule.medium_as_candidate = true;
  o.depth_mask.enabled = true;
  o.depth_mask.mode = DepthMaskMode::Plain;
  o.probability.enabled = true;
  o.probability.flow_model = FlowModel::MeanFlow;
  o.candidates = CandidatePolicy::Keep;  // the probability decides the medium-level features it scores
  return o;
}

/// RTD-SLAM (Gao et al. 2024): motion levels and box culling (§III.D: high-level boxes culled, medium-level ones sent to
/// verification), and the multi-view depth and parallax check (§III.A: 30 deg, 0.4 m) on every feature.
template <class T>
PipelineOptions<T> rtd_slam() {
  PipelineOptions<T> o = none<T>();
  o.box_rule.enabled = true;
  o.box_rule.medium_as_candidate = true;
  o.multiview.enabled = true;
  o.multiview.depth_threshold_m = T(0.4);
  o.multiview.max_parallax_deg = T(30);
  o.candidates = CandidatePolicy::Verify;
  return o;
}

/// Zhu et al. 2024: the static/dynamic box rule of Table 2 only (dynamic in a dynamic box and in no static
/// box); no medium level.
template <class T>
PipelineOptions<T> zhu_2024() {
  PipelineOptions<T> o = none<T>();
  o.box_rule.enabled = true;
  o.box_rule.medium_as_candidate = false;
  o.candidates = CandidatePolicy::Keep;
  return o;
}

/// DFD-SLAM (Qian et al. 2024): LK tracks, F-RANSAC and the epipolar distance (eq. 1-3, 1 px everywhere), refined by the
/// 3x3 sub-box vote (Algorithm 1) with the paper's literal merge (every static neighbour of a dynamic
/// sub-box) and sigma2 = 4. F is fitted on all tracks and the vote always trusted, as in the paper. Boxes
/// only delimit the vote (no semantic culling of their own).
template <class T>
PipelineOptions<T> dfd_slam() {
  PipelineOptions<T> o = none<T>();
  o.box_rule.enabled = true;  // marks which features lie in dynamic-class boxes
  o.box_rule.medium_as_candidate = true;
  o.moving_consistency.enabled = true;
  o.moving_consistency.fit_outside_boxes = false;
  o.moving_consistency.max_epipolar_distance_in_boxes_px = o.moving_consistency.max_epipolar_distance_px;
  o.subbox.enabled = true;
  o.subbox.merge_ratio = T(0);
  o.subbox.requires_fit_outside_boxes = false;
  o.candidates = CandidatePolicy::Verify;
  return o;
}

/// Zhang et al. 2023: the logical discrimination of Algorithm 1: high- and medium-level boxes are dynamic
/// unless the feature is also in a low-level box.
template <class T>
PipelineOptions<T> zhang_2023() {
  PipelineOptions<T> o = none<T>();
  o.box_rule.enabled = true;
  o.box_rule.medium_as_candidate = true;
  o.candidates = CandidatePolicy::Cull;
  return o;
}

/// Recommended: the box rule with the low-level shelter of Zhu et al. 2024 and Zhang et al. 2023, limited
/// to each object's depth band (DLD-SLAM eq. 1-2) and reaching above a person's box at its depth, verified
/// per region by the geometric check fitted outside the boxes (DFD-SLAM eq. 1-3 with SG-SLAM's RGB-D
/// reprojection where the caller gives 3-D points) and
/// DFD-SLAM's sub-box vote, with a tracker for missed boxes, each track's static history and the survivor guard.
/// Inputs: prev_keypoints and points_3d measured in the front end's keyframe (a slow mover builds up a
/// measurable displacement only over several frames), evidence_frames = frames since that keyframe, and
/// track_ids for the static history.
/// Left out: the probability (DLD-SLAM; its M term is the geometric evidence already used, its S term the box
/// rule) and the multi-view check (RTD-SLAM; grown over the whole image, where a depth jump outside the boxes
/// is more often a sensor edge than a mover).
template <class T>
PipelineOptions<T> recommended() {
  PipelineOptions<T> o;
  o.detections.enabled = true;
  o.tracker.enabled = true;  // a box the detector misses for a frame still culls its mover
  o.box_rule.enabled = true;
  o.box_rule.medium_as_candidate = true;  // a chair is culled only on evidence of its own motion

  o.depth_mask.enabled = true;
  o.depth_mask.mode = DepthMaskMode::Robust;
  // On a silhouette a pixel without depth is dragged along the contour: culled with the object.
  o.depth_mask.missing_depth = MissingDepth::InMask;
  // The top of DLD-SLAM's eps range (0.3-0.5 m): a walker near the camera, seen obliquely, reaches further
  // behind its centre depth than 0.3 m.
  o.depth_mask.eps_m = 0.5;
  // A feature in overlapping masks belongs to the object nearest its depth, a person unless the other is
  // nearer by 0.15 m (a seated person's torso and its chair lie at nearly the same depth).
  o.depth_mask.assign_overlaps_by_depth = true;
  o.depth_mask.overlap_high_level_margin_m = 0.15;
  // A TV box shelters only what is at the TV's depth, not a walker passing in front of it.
  o.depth_mask.low_override_by_depth = true;
  // A detector often cuts a walker's head off its box: features above the box at the person's depth join it.
  o.depth_mask.head_band_fraction = 0.15;

  o.probability.enabled = false;
  o.moving_consistency.enabled = true;
  o.moving_consistency.fit_outside_boxes = true;  // F fitted through a mover absorbs its motion
  // Tracks from the keyframe: 1 px in boxes (0.5 px suits frame-to-frame tracks).
  o.moving_consistency.max_epipolar_distance_in_boxes_px = T(1);
  // Where the frame carries points_3d its residual decides: it also sees motion along the epipolar line,
  // and with the depth image a walker heading for the camera, which barely moves in the image.
  o.reprojection.enabled = true;
  o.reprojection.max_depth_residual_sigmas = T(5);
  o.edge_evidence.enabled = true;  // flags on occlusion edges are contour tracking, not motion

  // A seated person's sway stays under the per-track thresholds: a cell whose residuals share a
  // significant median counts as flagged.
  o.coherent_motion.enabled = true;
  o.subbox.enabled = true;
  o.subbox.object_mask_votes_only = true;  // the background inside a box does not vote for the object
  // A sub-box is kept only on a clear static vote (at most 30 % of its features flagged): empty cells and
  // split votes stay with the box rule.
  o.subbox.static_needs_evidence = true;
  o.subbox.static_max_dynamic_ratio = T(0.3);
  o.subbox.sigma2 = 4;  // DFD-SLAM's whole-box rule also culls movers their own cell's vote missed
  o.subbox.verifies_candidates = false;  // a chair is culled on its own flags, not by a person's vote
  // On a one-frame baseline "not flagged" says nothing about a slow mover: the box rule decides, except in
  // the cells of a tracked box that voted within those frames (its still legs stay static).
  o.subbox.min_evidence_frames = 2;
  o.subbox.short_baseline_keeps_last_vote = true;

  // A track still in each of its last frames stays static whatever its region says: a seated person's
  // legs and chair share the cells its sway votes dynamic.
  o.static_history.enabled = true;
  o.static_history.min_frames = 6;
  o.static_history.max_residual_px = T(0.8);
  o.multiview.enabled = false;
  o.candidates = CandidatePolicy::Verify;
  o.guard.enabled = true;  // ORB-SLAM loses tracking below ~30 inliers
  return o;
}

}  // namespace presets
}  // namespace dyncull
