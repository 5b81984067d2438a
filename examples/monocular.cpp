// A monocular front end: the same compiled culler as front_end.cpp, without depth. The depth mask and
// the reprojection check cannot run, so the culler decides on epipolar evidence against its own keyframe
// and on the detector's boxes, and its status says which inputs were missing (MissingInput, the frame
// still culled by the stages that ran). Input: the synthetic walking scene's grey frames and boxes.
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
  dyncull::Culler culler(dyncull::cv_adapter::culler_camera(K, cv::Size(640, 480)));
  const cv::Ptr<cv::ORB> orb = cv::ORB::create(1000);
  dyncull::sim::FrameData frame;
  std::size_t detected = 0, kept = 0;
  for (int i = 0; i < scene_options.num_frames; ++i) {
    scene.render(i, &frame);
    const cv::Mat gray(frame.height, frame.width, CV_8UC1, frame.gray.data());
    std::vector<cv::KeyPoint> keys;
    cv::Mat descriptors;
    orb->detectAndCompute(gray, cv::noArray(), keys, descriptors);
    cv::Mat Tcw;  // a monocular system's pose is up to scale; the culler uses it only to guide matching
    cv::eigen2cv(frame.world_from_cam.inverse().matrix(), Tcw);
    std::vector<dyncull::DetectedBox> boxes;
    for (const auto& d : frame.detections)
      boxes.emplace_back(d.box.x0, d.box.y0, d.box.x1, d.box.y1, d.class_id, d.confidence);
    const dyncull::CullerResult& r = dyncull::cv_adapter::cull(culler, keys, descriptors, cv::Mat(), boxes, &Tcw);  // no depth
    detected += keys.size();
    dyncull::cv_adapter::compact(r.keep, descriptors, keys);
    kept += keys.size();
  }
  const auto& result = culler.result();
  std::printf("monocular: %zu ORB features in %d frames, %zu kept; last status %s%s%s\n", detected,
              scene_options.num_frames, kept, dyncull::to_string(result.status), result.reason.empty() ? "" : ": ",
              result.reason.c_str());
  // Without depth the status names what is missing; the frame is still culled.
  const bool says_missing = result.status == dyncull::Status::MissingInput;
  return culler.ok() && says_missing && kept < detected ? 0 : 1;
}
