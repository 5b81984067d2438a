/// @file presets.hpp
/// Pipeline configurations reproducing each seed paper (000 DLD-SLAM, 001 RTD-SLAM, 002 Zhu et al.,
/// 003 DFD-SLAM, 004 Zhang et al.) and the recommended combination (reasons in the comments and docs).
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
/// depth, limited to the object's depth band (000, eps 0.5 m), each feature in overlapping masks given to
/// the object nearest its depth (a person unless the other is nearer by 0.15 m), verified per region by the
/// geometric check fitted outside boxes (003 + SG-SLAM: the RGB-D reprojection check when the caller gives
/// 3-D points, with the depth residual, else the epipolar one; flags within 8 px of a depth edge are not
/// evidence) and the evidence-aware sub-box vote (keeps a seated person's still legs; not on a one-frame
/// baseline; a person's cell whose residuals move together counts as flagged), a track its own residual showed
/// still over its last frames kept against its region's cull (needs CullingFrame::track_ids), medium-level
/// objects culled only when their own features are flagged, each box's sub-boxes voted by and acting on its own
/// depth-mask object only, a tracker for missed (dynamic-class) boxes, and the survivor guard.
/// Tracks: give as prev_keypoints the features' positions in a reference frame a few frames back (the
/// front end's keyframe), not the previous frame: slow movers (a seated person) build up a measurable
/// epipolar distance only over several frames, hence the 1 px in-box threshold (0.5 px suits
/// frame-to-frame tracks). 3-D points (CullingFrame::points_3d): each track's point measured in that
/// reference frame's depth. The reprojection residual then replaces the epipolar distance: it also sees
/// motion along the epipolar line (a walker crossing a sideways-moving camera), and on the sim it flags
/// still chairs far less often. CullingFrame::evidence_frames: frames since that reference frame (the box
/// rule decides in the first one, min_evidence_frames). Measured on the dynamic_vo sim: docs/results.md.
/// Left out: the probability (000; its M term is the epipolar evidence already used, its S term
/// duplicates the box rule) and the multi-view check (001): with static features protected it only
/// verifies candidates, and on the sim it mostly culled static chairs next to walkers.
template <class T>
PipelineOptions<T> recommended() {
  PipelineOptions<T> o;
  o.use_detection_filter = true;
  o.use_box_tracker = true;
  o.use_box_rule = true;
  o.box_rule.medium_as_candidate = true;
  o.use_depth_mask = true;
  o.depth_mask.mode = DepthMaskMode::Robust;
  // A feature on a pixel without depth in a mover's box is culled, although as a segmentation the mask
  // gives such pixels to their nearest measured neighbour (DepthMaskOptions default, better IoU on the
  // real frame): on the silhouette such a track is dragged along the contour. Over six seeds the
  // nearest-pixel labels raised precision by up to 0.02 but median ATE rose on static, xyz and rpy
  // (0.76 / 1.26 / 4.23 -> 0.87 / 2.51 / 5.14 cm; halfsphere 3.59 -> 2.85), docs/results.md.
  o.depth_mask.missing_depth = MissingDepth::InMask;
  // The top of 000's eps range (0.3-0.5 m; DepthMaskOptions keeps 0.3, the best fit on the real TUM frame's
  // mask): a walker within a metre of the camera, seen obliquely, reaches more than 0.3 m behind its centre
  // depth, and its far side was left out of the band (rpy seed 9: up to 97 of the walkers' features a frame,
  // the pose pulled 20 cm). With the session 10 front end, twelve seeds, four sequences: summed ATE static / xyz /
  // rpy / halfsphere 10.0 / 17.2 / 29.1 / 30.2 -> 7.8 / 18.1 / 21.8 / 26.2 cm, median cut rpy 84.2 -> 88.7 %,
  // recall +0.01 to +0.04, precision within 0.01, static in boxes kept 0.97-0.99 (docs/results.md).
  o.depth_mask.eps_m = 0.5;
  o.use_probability = false;
  o.use_moving_consistency = true;
  o.moving.fit_outside_boxes = true;
  o.moving.max_epipolar_distance_in_boxes_px = T(1);
  o.use_reprojection = true;  // acts only when the frame carries points_3d
  o.reprojection_evidence = PipelineOptions<T>::Evidence::Replace;
  // ... and with the depth image it also compares depths: a walker heading for the camera barely moves in
  // the image. Over six seeds median halfsphere ATE 3.59 -> 2.12 cm (better on 5 of 6), the other
  // sequences within the noise, labels within 0.01 (docs/results.md).
  o.reprojection.max_depth_residual_sigmas = T(5);
  o.assign_overlaps_by_depth = true;
  // ... a person's mask keeps a feature unless the chair's d_c is nearer by more than 0.15 m: features on a
  // seated person's torso went to its chair's box and were verified only on their own flags. Twelve seeds,
  // session 15 (the one value measured): recall 0.847-0.891 -> 0.872-0.914 (rpy 0.901 / 0.914), precision
  // 0.865-0.933 -> 0.841-0.916, static in boxes kept -0.01, summed ATE 59.2 -> 57.7 cm (docs/results.md).
  o.overlap_high_level_margin_m = 0.15;
  // A TV box shelters only what is at the TV's depth: on two seeds 3.9k walker features in front of the TV
  // were kept by 002/004's low-level override. With it and the tracker carrying only dynamic-class boxes
  // (a carried false-positive TV box sheltered a walker at 1.2 m), twelve seeds, session 15: recall +0.015
  // to +0.026 (0.847-0.891 pooled), precision -0.001 to +0.008, summed ATE 59.8 -> 59.2 cm (docs/results.md).
  o.low_override_by_depth = true;
  o.edge_evidence_radius_px = 8;  // flags on occlusion edges are contour tracking, not motion
  o.use_subbox = true;
  o.subbox.object_mask_votes_only = true;
  // A box's sub-box is kept only on a clear static vote (at most 30 % of its features flagged): empty
  // cells and split votes stay with the box rule. Twelve seeds, session 12: summed ATE 65.0 -> 59.9 cm,
  // median cut on the held-out seeds 7-12 xyz / halfsphere 77.3 / 81.2 -> 84.1 / 85.3 %, recall 0.68-0.77
  // -> 0.75-0.83, precision 0.900-0.952 -> 0.881-0.936 (docs/results.md, session 12).
  o.subbox.static_needs_evidence = true;
  o.subbox.static_max_dynamic_ratio = T(0.3);
  // The whole-box rule stays (sigma2 = 4): without it (sigma2 = 9) precision rose by 0.01-0.02 but summed ATE
  // went 59.8 -> 65.6 cm over twelve seeds: it also culls movers their own cell's static vote missed
  // (docs/results.md, session 14). Sparing its clearly static cells (whole_box_spare_min_points 6, ratio 0.1)
  // raised precision by 0.012-0.022 but cost recall up to 0.008 for the same summed ATE (session 16).
  o.subbox.sigma2 = 4;
  // A person's sub-box whose residuals share a significant median (10 standard errors, at least 0.5 px)
  // counts as flagged: a seated person's sway stays under the per-track thresholds. Twelve seeds, session
  // 13: recall 0.75-0.83 -> 0.83-0.87, precision 0.881-0.936 -> 0.861-0.931, summed ATE 59.9 -> 59.8 cm
  // (docs/results.md, session 13).
  o.use_coherent_motion = true;
  // ... and a track the check found still (residual under 0.8 px, not flagged) in each of its last 6 frames of
  // at least 2 frames' baseline stays static whatever its box or cell says: a seated person's legs and chair
  // share the cells its sway votes dynamic. Twelve seeds, session 17: summed ATE 57.8 -> 52.9 cm (xyz, rpy
  // and halfsphere lower, static 4.7 -> 4.8 cm; rpy is the noisiest: 6 frames was the one setting tried that
  // lowered it), held-out median cut xyz 83.9 -> 85.7 %, precision 0.841-0.916 -> 0.854-0.945, recall
  // 0.872-0.914 -> 0.861-0.904 (docs/results.md, session 17).
  o.static_history.min_frames = 6;
  o.static_history.max_residual_px = T(0.8);
  o.subbox_verifies_candidates = false;
  // In the first frame after the keyframe (a one-frame baseline) the box rule decides: the trace of
  // halfsphere seed 1 showed up to 118 features of a walker kept "not flagged" in the two frames after a
  // keyframe made as it came into view, and the pose pulled 2-4 cm. With the session 11 front end, twelve
  // seeds: summed ATE static / xyz / rpy / halfsphere 7.8 / 17.1 / 21.8 / 24.6 -> 6.0 / 17.7 / 20.8 / 22.7 cm,
  // recall 0.62-0.70 -> 0.70-0.79, precision 0.90-0.95 -> 0.88-0.93; 3 frames: recall 0.75-0.82 but summed
  // ATE 73.5 cm (docs/results.md, session 11). Needs CullingFrame::evidence_frames.
  o.min_evidence_frames = 2;
  // ... except where a tracked box voted within those frames: cells whose features were all static (a
  // seated person's still legs) stay static, cells voted dynamic stay culled. Twelve seeds, session 12:
  // precision 0.876-0.930 -> 0.900-0.952 (pooled per six seeds), recall -0.01 to -0.04, summed ATE 67.2
  // -> 65.0 cm; trusting split static votes too gave the same precision but rpy seed 5 3.0 -> 7.0 cm.
  o.short_baseline_keeps_last_vote = true;
  // Sub-box memory off: with 15 frames (half a second) the demo's recall rose from 0.65-0.68 to 0.78-0.82
  // on every sequence, precision fell by 0.01-0.03, and the map-less VO's ATE got worse (summed over six
  // seeds and four sequences 61.8 -> 69.6 cm; 8 frames: 73.1 cm). Set it with CullingFrame::track_ids when
  // missed slow movers cost more than culled static features, e.g. before map insertion (docs/results.md).
  o.subbox_memory_frames = 0;
  o.use_multiview = false;
  // When switched on: outside boxes a depth jump is more often a sensor edge, and a person at 2-3 m
  // covers about 20k pixels at 640x480; a seed on a static occlusion edge would otherwise flood a whole
  // wall (most of the multi-view cost, measured in the pipeline bench).
  o.multiview_overrides_static = false;
  o.multiview.max_region_pixels = 20000;
  o.cull_geometric_outside_boxes = false;
  o.candidates = CandidatePolicy::Verify;
  o.survivor_guard = true;
  return o;
}

}  // namespace presets
}  // namespace dyncull
