/// @file culling_frames.hpp
/// The culling pipeline's per-frame input (CullingFrame, pipeline_types.hpp) built from a ray-cast test
/// scene (culling_scenes.hpp) as a front end would pass it: the tests and benches of the pipeline share it.
#pragma once

#include "dyncull/culling/pipeline_types.hpp"

#include "support/culling_scenes.hpp"

#include <vector>

namespace dyncull {
namespace test {

/// The scene's detections in the scalar T.
template <class T>
std::vector<Detection<T>> detections_of(const CullingScene<T>& s) {
  std::vector<Detection<T>> out;
  for (const auto& d : s.detections) out.push_back(Detection<T>{d.box.template cast<T>(), d.class_id, T(d.confidence)});
  return out;
}

/// The scene's frame: keypoints with their tracks, the detections `dets`, the depth image, the camera and
/// the current pose; no 3-D points, track ids or keyframe flag (set them on the result where needed).
template <class T>
CullingFrame<T, std::vector<Vec2<T>>> frame_of(const CullingScene<T>& s, const std::vector<Detection<T>>& dets) {
  CullingFrame<T, std::vector<Vec2<T>>> frame;
  frame.keypoints = &s.keypoints;
  frame.prev_keypoints = &s.prev_keypoints;
  frame.track_valid = s.track_valid;
  frame.detections = &dets;
  frame.depth = s.depth_view();
  frame.camera = s.camera;
  frame.cam_from_world = &s.cam_from_world;
  return frame;
}

}  // namespace test
}  // namespace dyncull
