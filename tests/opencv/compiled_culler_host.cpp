// A C++11 / C++14 host of the compiled public culler (dyncull::Culler, culling/culler.hpp) and its OpenCV
// overloads (opencv/culler.hpp), as ORB-SLAM2/3 compile: built twice (CXX_STANDARD 11 and 14, -Wall
// -Wextra -Wpedantic -Werror) against dyncull::culler, then run. It culls a few frames of grid keypoints
// through the cv::KeyPoint and cv::Point2f overloads and through plain views, checks the statuses and
// compacts; exit code 0 when all is as the headers say. (The host harness, dyncull::host, has its own
// C++11 program: tests/host/orb_slam_host.cpp.)
#include <dyncull/culling/culler.hpp>
#include <dyncull/opencv/culler.hpp>

#include <opencv2/core.hpp>

#include <cmath>
#include <cstdio>
#include <vector>

namespace {

int failures = 0;

void expect(bool condition, const char* what) {
  if (!condition) {
    std::printf("compiled_culler_host: FAILED: %s\n", what);
    ++failures;
  }
}

}  // namespace

int main() {
  namespace cva = dyncull::cv_adapter;
  const cv::Mat K = (cv::Mat_<double>(3, 3) << 525, 0, 319.5, 0, 525, 239.5, 0, 0, 1);
  dyncull::CullerOptions options("zhu_2024");  // box rule: a person box culls without motion evidence
  expect(options.validate() == dyncull::Status::Ok, "the zhu_2024 preset's settings are valid");
  dyncull::Culler culler(cva::culler_camera(K, cv::Size(640, 480)), options);
  expect(culler.ok(), "a valid K and preset give an ok culler");
  expect(culler.inputs().keypoints && culler.inputs().detections, "the preset reads keypoints and detections");

  std::vector<cv::KeyPoint> keys;
  for (int y = 40; y < 440; y += 20)
    for (int x = 40; x < 600; x += 20) keys.push_back(cv::KeyPoint(cv::Point2f(float(x), float(y)), 7.f));
  cv::Mat descriptors(static_cast<int>(keys.size()), 32, CV_8UC1);
  cv::randu(descriptors, 0, 256);
  const cv::Mat depth(480, 640, CV_32FC1, cv::Scalar(2.f));
  const cv::Mat Tcw = cv::Mat::eye(4, 4, CV_64F);
  std::vector<dyncull::DetectedBox> boxes;
  boxes.push_back(cva::detected_box(cv::Rect2f(100.f, 100.f, 120.f, 200.f), 0, 0.9f));

  for (int frame = 0; frame < 3; ++frame) {
    const dyncull::CullerResult& r = cva::cull(culler, keys, descriptors, depth, boxes, &Tcw);
    expect(r.keep.size() == keys.size(), "the keep mask is parallel to the keypoints");
    expect(r.status != dyncull::Status::InvalidInput && !r.refused, "valid input is not refused");
    expect(r.labels.size() == keys.size(), "labels are parallel to the keypoints");
  }
  std::size_t culled = 0;
  for (std::size_t i = 0; i < culler.result().keep.size(); ++i) culled += culler.result().keep[i] == 0;
  expect(culled > 0, "keypoints inside the person box are culled");

  std::vector<cv::Point2f> points;
  cv::KeyPoint::convert(keys, points);
  cva::cull(culler, points, descriptors, depth, boxes, &Tcw);
  expect(culler.result().keep.size() == points.size(), "the cv::Point2f overload culls");

  // The plain views: float pairs with a stride, descriptor rows, metres, the pose as 12 doubles.
  dyncull::CullerFrame f;
  f.keypoints = dyncull::PointsView::of(&points[0].x, points.size(), sizeof(cv::Point2f));
  f.descriptors = dyncull::DescriptorRows(descriptors.ptr<std::uint8_t>(0), static_cast<std::size_t>(descriptors.rows),
                                          descriptors.step[0], static_cast<std::size_t>(descriptors.cols));
  f.depth_m.data = depth.ptr<float>(0);
  f.depth_m.width = depth.cols;
  f.depth_m.height = depth.rows;
  f.detections = &boxes;
  const double Rt[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
  f.cam_from_world = Rt;
  culler.cull(f);
  expect(culler.result().keep.size() == points.size() && !culler.result().refused, "the plain views cull");

  cva::cull(culler, keys, descriptors.rowRange(0, 10), depth, boxes, &Tcw);
  expect(culler.result().status == dyncull::Status::InvalidInput, "mismatched descriptor rows are refused");
  std::printf("compiled_culler_host (C++ %ld): %s: %s\n", static_cast<long>(__cplusplus),
              dyncull::to_string(culler.result().status), culler.result().reason.c_str());

  const std::vector<std::uint8_t> keep = cva::cull(culler, keys, descriptors, depth, boxes, &Tcw).keep;
  std::vector<cv::Point2f> host_points = points;
  const long n = cva::compact(keep, descriptors, keys);
  expect(n == static_cast<long>(keys.size()) && descriptors.rows == n, "compact shrinks keys and descriptors");
  expect(dyncull::compact(keep, host_points) == n && host_points.size() == keys.size(),
         "dyncull::compact shrinks a plain vector alike");

  culler.reset();
  expect(culler.keyframe_size() == 0, "reset forgets the keyframe");

  std::printf("compiled_culler_host: %zu culled, %ld kept, %d failures\n", culled, n, failures);
  return failures == 0 ? 0 : 1;
}
