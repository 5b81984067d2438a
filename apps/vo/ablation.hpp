/// @file ablation.hpp
/// Ablation strategies of the dynamic_vo demo: the recommended preset (culling/presets.hpp) with one of
/// its stages, or one of its options that differ from PipelineOptions' defaults, switched back off, so
/// scripts/ablation.sh can show what each earns over the scene families. No paper equation.
#pragma once

#include "culling.hpp"

#include <algorithm>
#include <functional>
#include <string>
#include <vector>

namespace dyncull {
namespace vo {

/// One switch: its name (the strategy is "recommended-no_<name>"), what it undoes, and how.
struct AblationSwitch {
  std::string name;
  std::string what;
  std::function<void(StrategySpec&)> undo;
};

/// The recommended preset's stages, then its non-default options, each undone alone. Options that act
/// only through a stage the preset leaves off (the multi-view check's) are not listed: undoing them
/// changes nothing.
inline std::vector<AblationSwitch> ablation_switches() {
  using P = PipelineOptions<float>;
  // The library's defaults, which "off" returns an option to (copied out as scalars: the lambdas keep
  // no PipelineOptions of their own).
  P defaults;
  const auto missing_depth = defaults.depth_mask.missing_depth;
  const double eps_m = defaults.depth_mask.eps_m;
  const float epipolar_in_boxes_px = defaults.moving_consistency.max_epipolar_distance_in_boxes_px;
  const float depth_sigmas = defaults.reprojection.max_depth_residual_sigmas;
  const bool overlaps = defaults.depth_mask.assign_overlaps_by_depth;
  const double margin = defaults.depth_mask.overlap_high_level_margin_m;
  const bool low_override = defaults.depth_mask.low_override_by_depth;
  const double head_band = defaults.depth_mask.head_band_fraction;
  const bool mask_votes = defaults.subbox.object_mask_votes_only;
  const bool static_evidence = defaults.subbox.static_needs_evidence;
  const bool verifies_candidates = defaults.subbox.verifies_candidates;
  const int min_evidence = defaults.subbox.min_evidence_frames;
  const bool last_vote = defaults.subbox.short_baseline_keeps_last_vote;
  std::vector<AblationSwitch> s;
  auto add = [&](const char* name, const char* what, std::function<void(P&)> f) {
    s.push_back(AblationSwitch{name, what, [f](StrategySpec& spec) { f(spec.pipeline); }});
  };
  // Stages: each one's `enabled` off.
  add("detection_filter", "stage: detections.enabled (padding, class confidences)",
      [](P& o) { o.detections.enabled = false; });
  add("box_tracker", "stage: tracker.enabled (boxes carried through detector misses)",
      [](P& o) { o.tracker.enabled = false; });
  add("box_rule", "stage: box_rule.enabled (motion levels of the boxes)", [](P& o) { o.box_rule.enabled = false; });
  add("depth_mask", "stage: depth_mask.enabled (box culls limited to the object's depth band)",
      [](P& o) { o.depth_mask.enabled = false; });
  add("moving_consistency", "stage: moving_consistency.enabled (epipolar check)",
      [](P& o) { o.moving_consistency.enabled = false; });
  add("reprojection", "stage: reprojection.enabled (RGB-D reprojection check)",
      [](P& o) { o.reprojection.enabled = false; });
  add("edge_evidence", "stage: edge_evidence.enabled (flags on occlusion edges discounted)",
      [](P& o) { o.edge_evidence.enabled = false; });
  add("coherent_motion", "stage: coherent_motion.enabled (coherent motion of a cell)",
      [](P& o) { o.coherent_motion.enabled = false; });
  add("subbox", "stage: subbox.enabled (3x3 sub-box refinement)", [](P& o) { o.subbox.enabled = false; });
  add("static_history", "stage: static_history.enabled (static history of a track)",
      [](P& o) { o.static_history.enabled = false; });
  add("survivor_guard", "stage: guard.enabled (minimum-survivor guard)", [](P& o) { o.guard.enabled = false; });
  s.push_back(AblationSwitch{"keyframe_tracks",
                             "evidence against the previous frame instead of the keyframe (no 3-D points)",
                             [](StrategySpec& spec) { spec.tracks_from_keyframe = false; }});
  // Options that differ from PipelineOptions' defaults, each back to its default.
  add("missing_depth_in_mask", "depth_mask.missing_depth back to its default",
      [=](P& o) { o.depth_mask.missing_depth = missing_depth; });
  add("depth_band_0.5m", "depth_mask.eps_m back to its default",
      [=](P& o) { o.depth_mask.eps_m = eps_m; });
  add("epipolar_in_boxes_1px", "moving_consistency.max_epipolar_distance_in_boxes_px back to its default",
      [=](P& o) { o.moving_consistency.max_epipolar_distance_in_boxes_px = epipolar_in_boxes_px; });
  add("depth_residual", "reprojection.max_depth_residual_sigmas back to its default (no depth comparison)",
      [=](P& o) { o.reprojection.max_depth_residual_sigmas = depth_sigmas; });
  add("overlaps_by_depth", "depth_mask.assign_overlaps_by_depth back to its default",
      [=](P& o) { o.depth_mask.assign_overlaps_by_depth = overlaps; });
  add("overlap_margin", "depth_mask.overlap_high_level_margin_m back to its default",
      [=](P& o) { o.depth_mask.overlap_high_level_margin_m = margin; });
  add("low_override_by_depth", "depth_mask.low_override_by_depth back to its default",
      [=](P& o) { o.depth_mask.low_override_by_depth = low_override; });
  add("head_band", "depth_mask.head_band_fraction back to its default (no head band)",
      [=](P& o) { o.depth_mask.head_band_fraction = head_band; });
  add("subbox_mask_votes", "subbox.object_mask_votes_only back to its default",
      [=](P& o) { o.subbox.object_mask_votes_only = mask_votes; });
  add("subbox_static_evidence", "subbox.static_needs_evidence back to its default",
      [=](P& o) { o.subbox.static_needs_evidence = static_evidence; });
  add("candidates_own_evidence", "subbox.verifies_candidates back to its default",
      [=](P& o) { o.subbox.verifies_candidates = verifies_candidates; });
  add("min_evidence_frames", "subbox.min_evidence_frames back to its default",
      [=](P& o) { o.subbox.min_evidence_frames = min_evidence; });
  add("short_baseline_vote", "subbox.short_baseline_keeps_last_vote back to its default",
      [=](P& o) { o.subbox.short_baseline_keeps_last_vote = last_vote; });
  return s;
}

/// "recommended-no_<switch>" for every switch: never in the default run, named in --strategies.
inline std::vector<StrategySpec> ablation_strategies() {
  std::vector<StrategySpec> out;
  const std::vector<StrategySpec> all = all_strategies();
  const auto rec = std::find_if(all.begin(), all.end(), [](const StrategySpec& s) { return s.recommended; });
  if (rec == all.end()) return out;
  for (const AblationSwitch& sw : ablation_switches()) {
    StrategySpec spec = *rec;
    sw.undo(spec);
    spec.name = "recommended-no_" + sw.name;
    spec.description = "recommended without " + sw.what + " (ablation)";
    spec.recommended = false;
    spec.in_default = false;
    out.push_back(spec);
  }
  return out;
}

}  // namespace vo
}  // namespace dyncull
