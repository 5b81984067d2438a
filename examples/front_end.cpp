// The README's integration, compiled and run so it cannot rot: an ORB-SLAM-like front end (a
// cv::KeyPoint vector, a descriptor cv::Mat, depth and detector boxes per frame) culls its features on
// moving objects with one stateful culler, then compacts its parallel arrays with the keep mask. The
// culler keeps the keyframe, its matches, 3-D points and track ids itself (culling/culler.hpp, compiled
// into dyncull::culler behind a C++11 header, as a C++11 / C++14 SLAM system links it).
// Input: the synthetic walking scene (any RGB-D source works the same way).
#include <dyncull/opencv/culler.hpp>
#include <dyncull/sim/scene.hpp>

#include <opencv2/core/eigen.hpp>
#include <opencv2/features2d.hpp>

#include <cstdio>
#include <vector>

int main() {
  dyncull::sim::SceneOptions scene_options;
  scene_options.num_frames = 20;
  const dyncull::sim::Scene scene(scene_options);
  cv::Mat K;
  cv::eigen2cv(scene.camera().K(), K);
  std::size_t detected = 0, kept = 0;

  // --- README snippet begins ---
  dyncull::Culler culler(dyncull::cv_adapter::culler_camera(K, cv::Size(640, 480)));  // + distortion, if any
  const cv::Ptr<cv::ORB> orb = cv::ORB::create(1000);
  dyncull::sim::FrameData frame;
  for (int i = 0; i < scene_options.num_frames; ++i) {
    scene.render(i, &frame);  // your grey image, depth (CV_32F metres or CV_16U) and detector boxes
    const cv::Mat gray(frame.height, frame.width, CV_8UC1, frame.gray.data());
    const cv::Mat depth(frame.height, frame.width, CV_32FC1, frame.depth_m.data());
    std::vector<cv::KeyPoint> keys;
    cv::Mat descriptors;
    orb->detectAndCompute(gray, cv::noArray(), keys, descriptors);
    cv::Mat Tcw;  // predicted cam_from_world, 4x4 (here the true pose stands in for a motion model)
    cv::eigen2cv(frame.world_from_cam.inverse().matrix(), Tcw);
    std::vector<dyncull::DetectedBox> boxes;  // your detector's: corners, class, score
    for (const auto& d : frame.detections)
      boxes.emplace_back(d.box.x0, d.box.y0, d.box.x1, d.box.y1, d.class_id, d.confidence);
    const dyncull::CullerResult& r = dyncull::cv_adapter::cull(culler, keys, descriptors, depth, boxes, &Tcw);
    detected += keys.size();
    dyncull::cv_adapter::compact(r.keep, descriptors, keys);  // descriptors shrink with keys (and any parallel vector)
    kept += keys.size();
    // r: labels, reasons, track ids, and a status naming any input that was missing.
  }
  // --- README snippet ends ---

  std::printf("front_end: %zu ORB features in %d frames, %zu kept; last status %s%s%s\n", detected,
              scene_options.num_frames, kept, dyncull::to_string(culler.result().status),
              culler.result().reason.empty() ? "" : ": ", culler.result().reason.c_str());
  return culler.ok() && culler.result().ok() && kept < detected ? 0 : 1;
}
