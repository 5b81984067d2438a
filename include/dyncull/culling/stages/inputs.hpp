/// @file inputs.hpp
/// Start of a culling frame: the stage reports reset and enabled from the options, and the frame's inputs
/// checked against the input contract of docs/design.md (nothing is culled on invalid input).
#pragma once

#include "dyncull/culling/stages/context.hpp"

#include <string>

namespace dyncull {
namespace detail {

/// Resets r for a new frame; every stage report enabled as its option says.
template <class T>
void begin_frame(const PipelineOptions<T>& options, PipelineResult<T>* r) {
  r->status = Status::Ok;
  r->reason.clear();
  r->refused = false;
  r->guard = GuardAction::None;
  r->guard_restored = 0;
  r->history_kept = 0;
  r->unsheltered = 0;
  for (const StageDeclaration<T>& stage : kStages<T>) {
    StageReport& st = r->*stage.report;
    st.enabled = stage.enabled(options);
    st.status = Status::Skipped;
    st.reason.clear();
    st.num_dynamic = 0;
  }
  if (options.coherent_motion.enabled)
    r->coherent_motion.reason = "runs with the sub-box refinement, on the reprojection check's residuals";
}

/// False (r filled: InvalidInput, every keypoint Static and kept) when the frame cannot be culled: no
/// keypoints, invalid options, an invalid depth view, or a given per-keypoint input (prev_keypoints,
/// track_valid, track_ids, points_3d) of another length than the keypoints.
template <class T, class Frame>
bool accept_inputs(const Frame& frame, const PipelineOptions<T>& options, PipelineResult<T>* r) {
  if (!frame.keypoints) {
    r->status = Status::InvalidInput;
    r->refused = true;
    r->reason = "no keypoints given";
    r->labels.clear();
    r->reasons.clear();
    r->keep.clear();
    r->trace.clear();
    r->num_features = r->num_static = r->num_dynamic = 0;
    return false;
  }
  const std::size_t n = static_cast<std::size_t>(frame.keypoints->size());
  r->num_features = n;
  r->labels.assign(n, FeatureLabel::Static);
  r->reasons.assign(n, CullReason::None);
  std::string why;
  if (options.validate(&why) != Status::Ok) {
    why = "invalid options: " + why;
  } else if (frame.depth.validate(&why) != Status::Ok) {
  } else if (frame.prev_keypoints && static_cast<std::size_t>(frame.prev_keypoints->size()) != n) {
    why = "prev_keypoints has " + std::to_string(frame.prev_keypoints->size()) + " positions for " +
          std::to_string(n) + " keypoints";
  } else if (!flags_fit(frame.track_valid, n, "track_valid", "keypoints", &why)) {
  } else if (frame.track_ids && frame.track_ids->size() != n) {
    why = "track_ids has " + std::to_string(frame.track_ids->size()) + " ids for " + std::to_string(n) + " keypoints";
  } else if (frame.points_3d && static_cast<std::size_t>(frame.points_3d->size()) != n) {
    why = "points_3d has " + std::to_string(frame.points_3d->size()) + " points for " + std::to_string(n) +
          " keypoints";
  } else {
    return true;
  }
  r->status = Status::InvalidInput;
  r->refused = true;
  r->reason = why;
  r->keep.assign(n, 1);
  r->trace.assign(n, FeatureTrace{});
  r->num_static = n;
  r->num_dynamic = 0;
  return false;
}

}  // namespace detail
}  // namespace dyncull
