// The README's "use it from your front end" example, compiled and run so it cannot rot: an ORB +
// LK front end calls dyncull::cull_frame once per frame on its own cv::KeyPoint / cv::Point2f
// vectors, then compacts keypoints and descriptor rows together with the keep mask.
// Input: two frames of the synthetic walking scene (any RGB-D source works the same way).
#include <dyncull/culling/keep_mask.hpp>
#include <dyncull/culling/pipeline.hpp>
#include <dyncull/culling/presets.hpp>
#include <dyncull/sim/scene.hpp>

#include <opencv2/features2d.hpp>
#include <opencv2/video/tracking.hpp>

#include <cstdio>
#include <vector>

int main() {
  dyncull::sim::SceneOptions scene_options;
  scene_options.num_frames = 2;
  const dyncull::sim::Scene scene(scene_options);
  dyncull::sim::FrameData previous, current;
  scene.render(0, &previous);
  scene.render(1, &current);
  const cv::Mat prev_gray(previous.height, previous.width, CV_8UC1, previous.gray.data());
  const cv::Mat gray(current.height, current.width, CV_8UC1, current.gray.data());

  // The front end's own data: ORB keypoints + descriptors, and where LK finds them in the last frame.
  std::vector<cv::KeyPoint> keys;
  cv::Mat descriptors;
  cv::ORB::create(1000)->detectAndCompute(gray, cv::noArray(), keys, descriptors);
  std::vector<cv::Point2f> points, prev_pts;
  cv::KeyPoint::convert(keys, points);
  std::vector<std::uint8_t> lk_status;
  std::vector<float> lk_error;
  cv::calcOpticalFlowPyrLK(gray, prev_gray, points, prev_pts, lk_status, lk_error);
  const dyncull::Rigid3<float> predicted_pose = current.world_from_cam.inverse().cast<float>();
  const std::size_t detected = keys.size();

  // --- README snippet begins ---
  dyncull::PipelineState<float> state;  // lives as long as the tracker: carries boxes and track flags
  const auto options = dyncull::presets::recommended<float>();
  dyncull::CullingFrame<float, std::vector<cv::KeyPoint>, std::vector<cv::Point2f>, float> frame;
  frame.keypoints = &keys;  frame.prev_keypoints = &prev_pts;  frame.track_valid = lk_status;
  frame.detections = &current.detections;  // pixel boxes from your detector (see detections.hpp for YOLO)
  frame.depth = dyncull::DepthView<float>{current.depth_m.data(), current.width, current.height};
  frame.camera = scene.camera().cast<float>();
  frame.cam_from_world = &predicted_pose;  // a motion-model prediction is enough
  const auto& result = dyncull::cull_frame(frame, options, &state);
  const auto kept = dyncull::compact_parallel(result.keep, keys,
      dyncull::RowsView{descriptors.data, descriptors.cols * descriptors.elemSize(), descriptors.step, std::size_t(descriptors.rows)});
  descriptors = descriptors.rowRange(0, static_cast<int>(kept.count));
  // --- README snippet ends ---

  std::size_t truly_moving = 0, caught = 0;
  for (std::size_t i = 0; i < result.labels.size(); ++i) {
    const cv::Point2f p = points[i];
    const auto idx = static_cast<std::size_t>(cvRound(p.y)) * static_cast<std::size_t>(current.width) +
                     static_cast<std::size_t>(cvRound(p.x));
    if (idx >= current.moving.size() || !current.moving[idx]) continue;
    ++truly_moving;
    caught += result.keep[i] == 0;
  }
  std::printf("front_end: %zu ORB features, %zu kept, %zu culled (%zu of %zu on moving surfaces); status %s%s%s\n",
              detected, kept.count, kept.removed, caught, truly_moving, result.ok() ? "ok" : "error",
              result.reason.empty() ? "" : ": ", result.reason.c_str());
  return result.ok() && kept.ok() && keys.size() == kept.count ? 0 : 1;
}
