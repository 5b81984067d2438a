/// @file boxes.hpp
/// Stage 1 of the culling pipeline: detection boxes filtered (padding, class-dependent confidence) and
/// missed dynamic-class boxes carried forward by the box tracker (Dynamic-VINS, Liu et al. 2022).
#pragma once

#include "dyncull/culling/stages/context.hpp"

namespace dyncull {
namespace detail {

/// What the box stages read: the detection filter's and the box tracker's options, the class levels, and
/// the inputs the filter needs (its declaration in stages/builtin.hpp).
template <class T>
struct BoxesSlice {
  const DetectionStageOptions<T>& detections;
  const TrackerStageOptions<T>& tracker;
  const MotionLevelTable& levels;
  FrameInputs detections_needs;
  BoxesSlice(const PipelineOptions<T>& o)  // implicit: the pipeline passes its options
      : detections(o.detections),
        tracker(o.tracker),
        levels(o.levels),
        detections_needs(stage_needs<DetectionFilterStage<T>>(o)) {}
};

/// Fills `out` with this frame's boxes; reports into r.detections and r.tracker.
template <class T, class Frame>
void collect_boxes(const Frame& frame, const NonDeduced<BoxesSlice<T>>& options, BoxTracker<T>* tracker,
                   BoxRegions<T>* out, PipelineResult<T>* r) {
  const int W = frame.camera.width, H = frame.camera.height;
  BoxRegions<T>& s = *out;
  s.boxes.clear();
  if (frame.detections) {
    if (options.detections.enabled) {
      DetectionsResult<T>& d = s.filtered;
      filter_detections(*frame.detections, W, H, options.detections, &d);
      r->detections.status = d.status;
      r->detections.reason = d.reason;
      if (d.ok()) s.boxes = d.detections;
    } else {
      s.boxes = *frame.detections;
    }
  } else if (options.detections.enabled) {
    has_needed_inputs(frame, options.detections_needs, &r->detections);
  }
  if (options.tracker.enabled) {
    // Only dynamic-class boxes are tracked: carrying a missed (or one-frame false positive) low-level box
    // would only stretch its shelter over whatever moves in front of it.
    s.untracked_boxes.clear();
    std::size_t kept = 0;
    for (std::size_t b = 0; b < s.boxes.size(); ++b) {
      const MotionLevel lv = options.levels.level(s.boxes[b].class_id);
      if (lv == MotionLevel::High || lv == MotionLevel::Medium)
        s.boxes[kept++] = s.boxes[b];
      else
        s.untracked_boxes.push_back(s.boxes[b]);
    }
    s.boxes.resize(kept);
    tracker->set_options(options.tracker);
    BoxTrackerResult<T>& t = s.tracked;
    tracker->update(s.boxes, W, H, &t);
    r->tracker.status = t.status;
    r->tracker.reason = t.reason;
    s.box_track_id.assign(s.boxes.size(), -1);
    if (t.ok()) {
      s.boxes = t.boxes;
      s.box_track_id = t.track_id;
    }
    s.boxes.insert(s.boxes.end(), s.untracked_boxes.begin(), s.untracked_boxes.end());
    s.box_track_id.resize(s.boxes.size(), -1);
  } else {
    s.box_track_id.assign(s.boxes.size(), -1);
  }
  // Dynamic-class boxes (high and medium level): the ones sub-box refinement and the depth mask act on.
  s.dyn_boxes.clear();
  s.dyn_box_source.clear();
  s.dyn_box_track_id.clear();
  for (std::size_t b = 0; b < s.boxes.size(); ++b) {
    const MotionLevel lv = options.levels.level(s.boxes[b].class_id);
    if (lv == MotionLevel::High || lv == MotionLevel::Medium) {
      s.dyn_boxes.push_back(s.boxes[b]);
      s.dyn_box_source.push_back(static_cast<std::int32_t>(b));
      s.dyn_box_track_id.push_back(b < s.box_track_id.size() ? s.box_track_id[b] : -1);
    }
  }
}

}  // namespace detail
}  // namespace dyncull
