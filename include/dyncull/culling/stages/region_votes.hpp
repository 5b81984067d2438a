/// @file region_votes.hpp
/// Stage 6 of the culling pipeline: region votes over the dynamic-class boxes, the sub-box refinement
/// (DFD-SLAM 2024 Algorithm 1) on the geometric evidence, with cell-level coherent motion before the
/// vote, features of a box's head band following its top row, and on too short a baseline the box rule or
/// a tracked box's last vote deciding.
#pragma once

#include "dyncull/culling/stages/context.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>

namespace dyncull {
namespace detail {

/// What the region votes read: the sub-box refinement's and the coherent cells' options, whether the
/// box tracker runs (a tracked box's cells keep its last vote on too short a baseline), and the class levels.
template <class T>
struct RegionVotesSlice {
  const SubBoxStageOptions<T>& subbox;
  const CoherentMotionStageOptions<T>& coherent_motion;
  bool boxes_tracked;
  const MotionLevelTable& levels;
  RegionVotesSlice(const PipelineOptions<T>& o)  // implicit: the pipeline passes its options
      : subbox(o.subbox), coherent_motion(o.coherent_motion), boxes_tracked(o.tracker.enabled), levels(o.levels) {}
};

/// Per dynamic-class box: 1 for an object that moves by itself (high level), where the sub-box vote puts
/// the burden of proof on "static"; a chair's cell is dynamic only on its own vote, since on a real camera
/// the flags on a still chair are noise, not a mover's.
template <class T>
void flag_self_moving_boxes(const std::vector<Detection<T>>& boxes, const MotionLevelTable& levels,
                            std::vector<std::uint8_t>* out) {
  out->resize(boxes.size());
  for (std::size_t b = 0; b < boxes.size(); ++b) (*out)[b] = levels.level(boxes[b].class_id) == MotionLevel::High;
}

/// A feature in a box's head band (SemanticEvidence::head_band_box) follows the cell of the box's top row
/// in its column: dynamic there, it is culled with the person; a static top row keeps it.
template <class T, class Keypoints>
void subbox_follow_head_bands(const Keypoints& kp, const std::vector<Detection<T>>& boxes,
                              const std::vector<std::int32_t>& band_box, int grid, SubBoxResult<T>* out) {
  SubBoxResult<T>& r = *out;
  const std::size_t cells_per_box = static_cast<std::size_t>(grid) * static_cast<std::size_t>(grid);
  if (!r.ok() || band_box.size() != r.labels.size() || r.cells.size() < boxes.size() * cells_per_box) return;
  for (std::size_t i = 0; i < band_box.size(); ++i) {
    if (band_box[i] < 0 || r.labels[i] == FeatureLabel::Dynamic) continue;
    const auto b = static_cast<std::size_t>(band_box[i]);
    const Box<T>& box = boxes[b].box;
    const int col = subbox_index(point_x<T>(kp[i]), box.x0, box.x1, grid);
    if (r.cells[b * cells_per_box + static_cast<std::size_t>(col)] == 0) continue;
    r.labels[i] = FeatureLabel::Dynamic;
    r.reasons[i] = CullReason::SubBox;
    ++r.num_dynamic;
    --r.num_static;
  }
}

/// out->subbox: this frame's sub-box labels (valid when out->ok); out->evidence: the geometric labels with
/// the coherent cells' features flagged (when out->coherent_ran). Reports into r.coherent_motion, r.subbox.
template <class T, class Frame>
void vote_regions(const Frame& frame, const NonDeduced<RegionVotesSlice<T>>& options, std::uint64_t frame_index,
                  const BoxRegions<T>& regions, const SemanticEvidence<T>& semantic,
                  const std::vector<FeatureLabel>& semantic_labels, const GeometricEvidence<T>& geometric,
                  SubBoxMemory* last_votes, RegionVotes<T>* out, PipelineResult<T>* r) {
  RegionVotes<T>& v = *out;
  v.ok = false;
  v.coherent_ran = false;
  if (!options.subbox.enabled) return;
  const auto& kp = *frame.keypoints;
  const std::size_t n = r->num_features;
  const bool masks = semantic.masks;
  const FlagView in_object = masks ? FlagView(semantic.in_object) : nullptr;
  const BoxBitsView box_bits = masks ? BoxBitsView(semantic.object_box_bits) : nullptr;
  if (!geometric.ok) {
    r->subbox.reason = "needs geometric labels (moving consistency or reprojection), unavailable this frame";
  } else if (regions.dyn_boxes.empty()) {
    r->subbox.reason = "no dynamic-class boxes";
  } else if (options.subbox.min_evidence_frames > 0 && frame.evidence_frames > 0 &&
             frame.evidence_frames < options.subbox.min_evidence_frames) {
    const std::size_t recalled =
        options.subbox.short_baseline_keeps_last_vote && options.boxes_tracked && r->tracker.ran()
            ? last_votes->recall_states(regions.dyn_box_track_id, options.subbox.grid, frame_index,
                                        options.subbox.min_evidence_frames, &v.remembered_cells)
            : 0;
    if (recalled > 0) {
      apply_subbox_states(kp, geometric.labels, regions.dyn_boxes, v.remembered_cells, options.subbox,
                          &v.subbox, in_object, box_bits);
      subbox_follow_head_bands(kp, regions.dyn_boxes, semantic.head_band_box, options.subbox.grid, &v.subbox);
      r->subbox.status = v.subbox.status;
      r->subbox.num_dynamic = v.subbox.num_dynamic;
    }
    // Appended piece by piece into the kept buffer: numbers' texts fit the small-string buffer.
    std::string& why = r->subbox.reason;
    why.assign("baseline of ").append(std::to_string(frame.evidence_frames));
    why.append(" frame(s) too short for static evidence (subbox.min_evidence_frames): ");
    if (recalled > 0)
      why.append("the last vote of ").append(std::to_string(recalled)).append(" tracked box(es) kept, the box rule elsewhere");
    else
      why.append("the box rule decides");
  } else if (options.subbox.requires_fit_outside_boxes && !geometric.fit_outside_boxes &&
             std::any_of(semantic.in_dyn_box.begin(), semantic.in_dyn_box.end(),
                         [](std::uint8_t f) { return f != 0; })) {
    r->subbox.reason = "F or the pose was fitted through the dynamic-class boxes (too few tracks outside them): "
                       "its evidence inside the boxes is not trusted";
  } else {
    ArrayView<FeatureLabel> evidence = geometric.labels;
    if (options.coherent_motion.enabled) {
      if (!r->reprojection.ran() || geometric.reprojection.residual_vec.size() != n) {
        r->coherent_motion.reason = "needs the reprojection check's residuals (reprojection.enabled, points_3d)";
      } else {
        // High-level objects only: a candidate (a chair) stays verified on its own evidence.
        v.coherent_eligible.resize(n);
        for (std::size_t i = 0; i < n; ++i) v.coherent_eligible[i] = semantic_labels[i] == FeatureLabel::Dynamic;
        v.evidence.assign(geometric.labels.begin(), geometric.labels.end());
        v.coherent_ran = true;
        evidence = v.evidence;
        // The cells the sub-box vote will count.
        flag_coherent_cells(kp, geometric.reprojection.residual_vec, regions.dyn_boxes, options.subbox.grid,
                            geometric.reprojection.inlier_noise_px, options.coherent_motion, v.evidence.data(),
                            &v.coherent, in_object, box_bits, v.coherent_eligible);
        r->coherent_motion.status = v.coherent.status;
        r->coherent_motion.reason = v.coherent.reason;
        r->coherent_motion.num_dynamic = v.coherent.num_flagged;
      }
    }
    flag_self_moving_boxes(regions.dyn_boxes, options.levels, &v.self_moving_boxes);
    refine_subboxes(kp, evidence, regions.dyn_boxes, options.subbox, &v.subbox, in_object, box_bits,
                    FlagView(v.self_moving_boxes));
    subbox_follow_head_bands(kp, regions.dyn_boxes, semantic.head_band_box, options.subbox.grid, &v.subbox);
    if (options.subbox.short_baseline_keeps_last_vote && options.subbox.min_evidence_frames > 0 &&
        options.boxes_tracked && r->tracker.ran() && v.subbox.ok())
      last_votes->remember_states(regions.dyn_box_track_id, v.subbox, options.subbox, frame_index,
                                  options.subbox.min_evidence_frames);
    r->subbox.status = v.subbox.status;
    r->subbox.reason = v.subbox.reason;
    r->subbox.num_dynamic = v.subbox.num_dynamic;
  }
  v.ok = r->subbox.ran();
}

}  // namespace detail
}  // namespace dyncull
