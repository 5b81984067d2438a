// A C++11 / C++14 host of the compiled culler, as ORB-SLAM2/3 compile: built twice (CXX_STANDARD 11 and
// 14, -Wall -Wextra -Wpedantic -Werror) against dyncull::culler, then run. It culls a few frames of
// grid keypoints through each overload, checks the statuses and compacts; then the ORB-SLAM glue
// (host_culler.hpp) on a Frame-like struct in stock mode; exit code 0 when all is as the headers say.
#include <dyncull/opencv/compiled_culler.hpp>
#include <dyncull/opencv/host_culler.hpp>

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

// The members of ORB-SLAM2's Frame that cull_orb_slam_frame touches.
struct Frame {
  double mTimeStamp;
  unsigned long mnId;
  int N;
  std::vector<cv::KeyPoint> mvKeys, mvKeysUn;
  cv::Mat mDescriptors;
  std::vector<float> mvuRight, mvDepth;
  std::vector<int*> mvpMapPoints;
  std::vector<bool> mvbOutlier;
  std::vector<std::size_t> mGrid[4][3];
  bool PosInGrid(const cv::KeyPoint&, int& x, int& y) const {
    x = 0;
    y = 0;
    return true;
  }
};

}  // namespace

int main() {
  typedef dyncull::cv_adapter::CompiledCuller Culler;
  const cv::Mat K = (cv::Mat_<double>(3, 3) << 525, 0, 319.5, 0, 525, 239.5, 0, 0, 1);
  Culler::Options options;
  options.preset = "zhu_2024";  // box rule: a person box culls without motion evidence
  Culler culler(K, cv::Size(640, 480), cv::Mat(), options);
  expect(culler.ok(), "a valid K and preset give an ok culler");

  std::vector<cv::KeyPoint> keys;
  for (int y = 40; y < 440; y += 20)
    for (int x = 40; x < 600; x += 20) keys.push_back(cv::KeyPoint(cv::Point2f(float(x), float(y)), 7.f));
  cv::Mat descriptors(static_cast<int>(keys.size()), 32, CV_8UC1);
  cv::randu(descriptors, 0, 256);
  const cv::Mat depth(480, 640, CV_32FC1, cv::Scalar(2.f));
  const cv::Mat Tcw = cv::Mat::eye(4, 4, CV_64F);
  std::vector<dyncull::cv_adapter::DetectedBox> boxes;
  boxes.push_back(dyncull::cv_adapter::DetectedBox(cv::Rect2f(100.f, 100.f, 120.f, 200.f), 0, 0.9f));

  for (int frame = 0; frame < 3; ++frame) {
    const std::vector<std::uint8_t>& keep = culler.cull(keys, descriptors, depth, boxes, &Tcw);
    expect(keep.size() == keys.size(), "the keep mask is parallel to the keypoints");
    expect(culler.result().status != Culler::Status::InvalidInput, "valid input is not refused");
    expect(culler.result().labels.size() == keys.size(), "labels are parallel to the keypoints");
  }
  std::size_t culled = 0;
  for (std::size_t i = 0; i < culler.result().keep.size(); ++i) culled += culler.result().keep[i] == 0;
  expect(culled > 0, "keypoints inside the person box are culled");

  std::vector<cv::Point2f> points;
  cv::KeyPoint::convert(keys, points);
  culler.cull(points, descriptors, depth, boxes, &Tcw);
  expect(culler.result().keep.size() == points.size(), "the cv::Point2f overload culls");
  culler.cull(&points[0].x, points.size(), sizeof(cv::Point2f), descriptors, depth, boxes, &Tcw);
  expect(culler.result().keep.size() == points.size(), "the float-pair overload culls");

  culler.cull(keys, descriptors.rowRange(0, 10), depth, boxes, &Tcw);
  expect(culler.result().status == Culler::Status::InvalidInput, "mismatched descriptor rows are refused");
  std::printf("compiled_culler_host (C++ %ld): %s: %s\n", static_cast<long>(__cplusplus),
              Culler::to_string(culler.result().status), culler.result().reason.c_str());

  const std::vector<std::uint8_t> keep = culler.cull(keys, descriptors, depth, boxes, &Tcw);
  const long n = Culler::compact(keep, descriptors, keys);
  expect(n == static_cast<long>(keys.size()) && descriptors.rows == n, "compact shrinks keys and descriptors");

  dyncull::cv_adapter::HostCuller stock((dyncull::cv_adapter::HostCuller::Settings()));
  Frame frame;
  frame.mTimeStamp = 1.0;
  frame.mnId = 0;
  frame.mvKeys = frame.mvKeysUn = keys;
  frame.mDescriptors = descriptors;
  frame.N = static_cast<int>(keys.size());
  expect(dyncull::cv_adapter::cull_orb_slam_frame(stock, frame, cv::Size(640, 480), depth, K, cv::Mat(), cv::Mat()) ==
             frame.N && frame.mvKeys.size() == keys.size(),
         "stock mode leaves an ORB-SLAM frame as it is");
  std::printf("compiled_culler_host: %zu culled, %ld kept, %d failures\n", culled, n, failures);
  return failures == 0 ? 0 : 1;
}
