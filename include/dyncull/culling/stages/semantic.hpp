/// @file semantic.hpp
/// Stages 2-3 of the culling pipeline: the box rule (Zhu et al. 2024 Table 2; Zhang et al. 2023
/// Algorithm 1; motion levels of RTD-SLAM 2024 §III.D), limited to each object's depth band by the depth
/// mask (DLD-SLAM 2024 eq. 1-2), with overlapping masks, low-level shelters and a person's head cut off
/// its box decided by depth.
#pragma once

#include "dyncull/culling/stages/context.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace dyncull {
namespace detail {
/// DepthMaskStageOptions::low_override_by_depth: features the box rule sheltered (LowLevelOverride) that a
/// dynamic-class object's depth mask holds lose the shelter when their depth is nearer that object's d_c
/// than the d_c of every low-level box holding them. `combined` lists the dynamic-class boxes, then the
/// low-level ones (scratch); their depth is planned again with occluded_centre_search so a TV's depth is
/// not read off the walker in front of its centre (into `planned`, scratch too). Returns how many
/// features lost the shelter.
template <class T, class Keypoints, class Raw>
std::size_t unshelter_by_depth(const Keypoints& kp, const DepthView<Raw>& depth, const DepthMaskResult& dm,
                               const std::vector<Detection<T>>& dyn_boxes, const std::vector<Detection<T>>& boxes,
                               const MotionLevelTable& levels, DepthMaskOptions depth_options,
                               std::vector<Detection<T>>* combined, DepthMaskResult* planned_out,
                               DepthMaskScratch* scratch, std::vector<std::uint32_t>* bits,
                               std::vector<FeatureLabel>* labels, std::vector<CullReason>* reasons,
                               std::vector<std::uint8_t>* in_dyn_box) {
  const std::size_t n = bits->size();
  bool any = false;
  for (std::size_t i = 0; i < n && !any; ++i) any = (*reasons)[i] == CullReason::LowLevelOverride && (*bits)[i] != 0;
  if (!any) return 0;
  const std::size_t nd = std::min<std::size_t>({dyn_boxes.size(), dm.boxes.size(), 32});
  combined->assign(dyn_boxes.begin(), dyn_boxes.begin() + static_cast<std::ptrdiff_t>(nd));
  for (const Detection<T>& b : boxes)
    if (levels.level(b.class_id) == MotionLevel::Low) combined->push_back(b);
  if (combined->size() == nd) return 0;
  depth_options.occluded_centre_search = true;
  // Only the per-box depths are needed: no points.
  const std::vector<Vec2<T>> no_points;
  depth_mask(depth, *combined, no_points, depth_options, planned_out, scratch);
  const DepthMaskResult& planned = *planned_out;
  if (!planned.ok() || planned.boxes.size() != combined->size()) return 0;
  std::size_t changed = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t b = (*bits)[i];
    if ((*reasons)[i] != CullReason::LowLevelOverride || b == 0) continue;
    int u = 0, v = 0;
    if (!keypoint_in_image<T>(kp, i, depth.width, depth.height, &u, &v)) continue;
    const double d = depth.depth_m(u, v);
    if (!(d > 0)) continue;
    // Nearest dynamic-class object among the masks holding the feature.
    std::size_t best = nd;
    double best_gap = 0;
    for (std::size_t k = 0; k < nd; ++k) {
      const double dc = dm.boxes[k].d_c_m;
      if (!(b & (std::uint32_t(1) << k)) || !(dc > 0)) continue;
      const double gap = std::abs(d - dc);
      if (best == nd || gap < best_gap) {
        best = k;
        best_gap = gap;
      }
    }
    if (best == nd) continue;
    // Sheltered by any low-level box holding it whose depth is unknown or at least as near.
    bool sheltered = false;
    const T x = point_x<T>(kp[i]), y = point_y<T>(kp[i]);
    for (std::size_t k = nd; k < combined->size() && !sheltered; ++k) {
      const Box<T>& box = (*combined)[k].box;
      if (!box.contains(x, y)) continue;
      const DepthMaskBoxInfo& info = planned.boxes[k];
      sheltered = !info.ok() || !(info.d_c_m > 0) || std::abs(d - info.d_c_m) <= best_gap;
    }
    if (sheltered) continue;
    (*bits)[i] = std::uint32_t(1) << best;
    (*in_dyn_box)[i] = 1;
    if (levels.level(dyn_boxes[best].class_id) == MotionLevel::High) {
      (*labels)[i] = FeatureLabel::Dynamic;
      (*reasons)[i] = CullReason::HighLevelBox;
    } else {
      (*labels)[i] = FeatureLabel::Candidate;
      (*reasons)[i] = CullReason::MediumLevelBox;
    }
    ++changed;
  }
  return changed;
}

/// DepthMaskStageOptions::assign_overlaps_by_depth: for features inside a dynamic-class box whose depth
/// masks hold them, keeps one mask bit (the box with d_c nearest the feature's depth, a high-level box's
/// gap counted `high_level_margin_m` smaller; ties and missing depth: the highest level, then the first
/// box) and sets the semantic label from that box's level.
template <class T, class Keypoints, class Raw>
void assign_overlaps_by_depth(const Keypoints& kp, const DepthView<Raw>& depth, const DepthMaskResult& dm,
                              const std::vector<Detection<T>>& dyn_boxes, const MotionLevelTable& levels,
                              std::vector<std::uint32_t>* bits, std::vector<FeatureLabel>* labels,
                              std::vector<CullReason>* reasons, double high_level_margin_m = 0) {
  const std::size_t n = bits->size();
  const std::size_t nb = std::min<std::size_t>({dyn_boxes.size(), dm.boxes.size(), 32});
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t b = (*bits)[i];
    const CullReason why = (*reasons)[i];
    // Only the box rule's own labels are re-decided (not a low-level override or invalid input).
    if (b == 0 || !(why == CullReason::HighLevelBox || why == CullReason::MediumLevelBox || why == CullReason::DepthMask))
      continue;
    int u = 0, v = 0;
    float d = 0.f;
    if (keypoint_in_image<T>(kp, i, depth.width, depth.height, &u, &v)) d = depth.depth_m(u, v);
    std::size_t best = nb;
    double best_gap = 0;
    MotionLevel best_level = MotionLevel::Ignore;
    for (std::size_t k = 0; k < nb; ++k) {
      if (!(b & (std::uint32_t(1) << k))) continue;
      const MotionLevel lv = levels.level(dyn_boxes[k].class_id);
      const double dc = dm.boxes[k].d_c_m;
      double gap = d > 0.f && dc > 0 ? std::abs(static_cast<double>(d) - dc) : 0.0;
      if (lv == MotionLevel::High && d > 0.f && dc > 0) gap -= high_level_margin_m;
      const bool better = best == nb || gap < best_gap ||
                          (gap == best_gap && lv == MotionLevel::High && best_level != MotionLevel::High);
      if (better) {
        best = k;
        best_gap = gap;
        best_level = lv;
      }
    }
    if (best == nb) continue;
    (*bits)[i] = std::uint32_t(1) << best;
    if (best_level == MotionLevel::High && (*labels)[i] != FeatureLabel::Dynamic) {
      (*labels)[i] = FeatureLabel::Dynamic;
      (*reasons)[i] = CullReason::HighLevelBox;
    } else if (best_level == MotionLevel::Medium && (*labels)[i] == FeatureLabel::Dynamic) {
      (*labels)[i] = FeatureLabel::Candidate;
      (*reasons)[i] = CullReason::MediumLevelBox;
    }
  }
}

/// DepthMaskStageOptions::head_band_fraction: a feature the boxes left static (outside every dynamic-class
/// box) that lies in the band above a high-level box, within the box's columns, with a depth within the
/// tolerance of the box's object depth d_c, is labelled as that person (nearest d_c among the bands holding
/// it): Dynamic, in the box and its object mask, its index in `band_box`. Returns how many were.
template <class T, class Keypoints, class Raw>
std::size_t claim_head_bands(const Keypoints& kp, const DepthView<Raw>& depth, const DepthMaskResult& dm,
                             const std::vector<Detection<T>>& dyn_boxes, const MotionLevelTable& levels,
                             const DepthMaskStageOptions& options, SemanticEvidence<T>* s) {
  const std::size_t n = s->labels.size();  // head_band_box: all -1 (classify_by_boxes)
  if (!(options.head_band_fraction > 0)) return 0;
  const std::size_t nb = std::min<std::size_t>({dyn_boxes.size(), dm.boxes.size(), 32});
  // A box has a head band when it is a person's (high level) with an object depth.
  bool has_band[32] = {};
  for (std::size_t k = 0; k < nb; ++k)
    has_band[k] = levels.level(dyn_boxes[k].class_id) == MotionLevel::High && dm.boxes[k].ok() && dm.boxes[k].d_c_m > 0;
  std::size_t claimed = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (s->in_dyn_box[i] || s->labels[i] != FeatureLabel::Static || s->reasons[i] != CullReason::None) continue;
    int u = 0, v = 0;
    if (!keypoint_in_image<T>(kp, i, depth.width, depth.height, &u, &v)) continue;
    const double d = depth.depth_m(u, v);
    if (!(d > 0)) continue;  // without depth nothing says it is the person rather than the wall
    const double x = static_cast<double>(point_x<T>(kp[i])), y = static_cast<double>(point_y<T>(kp[i]));
    std::int32_t best = -1;
    double best_gap = options.head_band_depth_tolerance_m;
    for (std::size_t k = 0; k < nb; ++k) {
      if (!has_band[k]) continue;
      const Box<T>& b = dyn_boxes[k].box;
      const double top = static_cast<double>(b.y0), band = options.head_band_fraction * static_cast<double>(b.y1 - b.y0);
      const double dc = dm.boxes[k].d_c_m;
      if (!(y < top && y >= top - band && x >= static_cast<double>(b.x0) && x <= static_cast<double>(b.x1))) continue;
      const double gap = std::abs(d - dc);
      if (gap <= best_gap) {
        best = static_cast<std::int32_t>(k);
        best_gap = gap;
      }
    }
    if (best < 0) continue;
    s->labels[i] = FeatureLabel::Dynamic;
    s->reasons[i] = CullReason::DepthMask;
    s->in_dyn_box[i] = 1;
    s->in_object[i] = 1;
    s->object_box_bits[i] = std::uint32_t(1) << best;
    s->head_band_box[i] = best;
    ++claimed;
  }
  return claimed;
}

/// What the semantic stages read: the box rule's and the depth masks' options, the class levels, and the
/// inputs each needs (their declarations in stages/builtin.hpp).
template <class T>
struct SemanticSlice {
  const BoxRuleStageOptions<T>& box_rule;
  const DepthMaskStageOptions& depth_mask;
  const MotionLevelTable& levels;
  FrameInputs box_rule_needs, depth_mask_needs;
  SemanticSlice(const PipelineOptions<T>& o)  // implicit: the pipeline passes its options
      : box_rule(o.box_rule),
        depth_mask(o.depth_mask),
        levels(o.levels),
        box_rule_needs(stage_needs<BoxRuleStage<T>>(o)),
        depth_mask_needs(stage_needs<DepthMaskStage<T>>(o)) {}
};

/// Semantic evidence of this frame: the box rule's labels, then the depth masks (out->labels etc.).
template <class T, class Frame>
void classify_by_boxes(const Frame& frame, const NonDeduced<SemanticSlice<T>>& options, const BoxRegions<T>& regions,
                       SemanticEvidence<T>* out, PipelineResult<T>* r) {
  const auto& kp = *frame.keypoints;
  const std::size_t n = r->num_features;
  SemanticEvidence<T>& s = *out;
  s.labels.assign(n, FeatureLabel::Static);
  s.reasons.assign(n, CullReason::None);
  s.in_dyn_box.assign(n, 0);
  s.in_object.assign(n, 1);
  s.rule_ok = false;
  s.masks = false;
  s.head_band_box.assign(n, -1);
  if (options.box_rule.enabled) {
    apply_box_rule(kp, regions.boxes, options.levels, options.box_rule, &s.rule, &s.rule_scratch);
    r->box_rule.status = s.rule.status;
    r->box_rule.reason = s.rule.reason;
    if (s.rule.ok()) {
      s.rule_ok = true;
      for (std::size_t i = 0; i < n; ++i) {
        s.labels[i] = s.rule.labels[i];
        s.reasons[i] = s.rule.reasons[i];
        s.in_dyn_box[i] = s.rule.reasons[i] == CullReason::HighLevelBox || s.rule.reasons[i] == CullReason::MediumLevelBox;
      }
      r->box_rule.num_dynamic = s.rule.num_dynamic;
    }
    // Without the detection filter, the box rule is the stage that reads the detections. It still ran on
    // no boxes, so a non-finite keypoint is culled as on any frame.
    has_needed_inputs(frame, options.box_rule_needs, &r->box_rule);
  }

  // Inside dynamic-class boxes only the object's depth band is culled.
  if (!options.depth_mask.enabled) return;
  if (!has_needed_inputs(frame, options.depth_mask_needs, &r->depth_mask)) return;
  DepthMaskResult& dm = s.mask;
  depth_mask(frame.depth, regions.dyn_boxes, kp, options.depth_mask, &dm, &s.mask_scratch);
  r->depth_mask.status = dm.status;
  r->depth_mask.reason = dm.reason;
  if (!dm.ok()) return;
  s.masks = true;
  r->depth_mask.num_dynamic = dm.num_dynamic;
  s.object_box_bits.assign(dm.box_bits.begin(), dm.box_bits.end());
  if (options.depth_mask.low_override_by_depth && options.box_rule.enabled)
    r->unsheltered = unshelter_by_depth(kp, frame.depth, dm, regions.dyn_boxes, regions.boxes, options.levels,
                                        options.depth_mask, &s.shelter_boxes, &s.shelter_mask, &s.mask_scratch,
                                        &s.object_box_bits, &s.labels,
                                        &s.reasons, &s.in_dyn_box);
  if (options.depth_mask.assign_overlaps_by_depth && options.box_rule.enabled)
    assign_overlaps_by_depth(kp, frame.depth, dm, regions.dyn_boxes, options.levels, &s.object_box_bits, &s.labels,
                             &s.reasons, options.depth_mask.overlap_high_level_margin_m);
  for (std::size_t i = 0; i < n; ++i) {
    s.in_object[i] = dm.labels[i] != FeatureLabel::Static;
    if (dm.labels[i] == FeatureLabel::Dynamic && dm.reasons[i] == CullReason::InvalidInput) {
      s.labels[i] = FeatureLabel::Dynamic;
      s.reasons[i] = CullReason::InvalidInput;
    } else if (s.in_dyn_box[i] && dm.labels[i] == FeatureLabel::Static) {
      s.labels[i] = FeatureLabel::Static;  // box background behind or in front of the object
      s.reasons[i] = CullReason::None;
    } else if (s.in_dyn_box[i] && dm.labels[i] == FeatureLabel::Dynamic && s.labels[i] == FeatureLabel::Dynamic) {
      s.reasons[i] = CullReason::DepthMask;
    } else if (!options.box_rule.enabled && dm.labels[i] != FeatureLabel::Static) {
      s.labels[i] = dm.labels[i];
      s.reasons[i] = dm.reasons[i];
      s.in_dyn_box[i] = 1;
    }
  }
  if (options.box_rule.enabled)
    claim_head_bands(kp, frame.depth, dm, regions.dyn_boxes, options.levels, options.depth_mask, &s);
}

}  // namespace detail
}  // namespace dyncull
