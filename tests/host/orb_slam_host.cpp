// A C++11 host of the host harness (host/host_culler.hpp), built as ORB-SLAM2/3 compile (CXX_STANDARD 11,
// -Wall -Wextra -Wpedantic -Werror) against dyncull::host and run: an ORB-SLAM-like Frame culled in
// stock mode (untouched) and in box_only mode with a stand-in detector waited for (the person box's
// features removed, every parallel array in step), and an ORB-SLAM3-like Frame with a Sophus-like pose and
// a reset from another thread (box_only: nothing to restart); exit code 0 when all is as the header says.
#include <dyncull/host/host_culler.hpp>

#include <opencv2/core.hpp>

#include <cstdio>
#include <thread>
#include <vector>

namespace {

int failures = 0;

void expect(bool condition, const char* what) {
  if (!condition) {
    std::printf("orb_slam_host: FAILED: %s\n", what);
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

// ORB-SLAM3's Frame: ORB-SLAM2's members and the two-camera ones (one camera: Nleft = Nright = -1).
struct Frame3 : Frame {
  int Nleft, Nright;
  std::vector<int> mvLeftToRightMatch;
  std::vector<cv::Vec3f> mvStereo3Dpoints;
  Frame3() : Nleft(-1), Nright(-1) {}
};

// Sophus::SE3f's shape: matrix() gives a 4x4 with rows(), cols() and (r, c).
struct Pose {
  struct Matrix {
    int rows() const { return 4; }
    int cols() const { return 4; }
    float operator()(int r, int c) const { return r == c ? 1.f : 0.f; }
  };
  Matrix matrix() const { return Matrix(); }
};

// One person box over the left half, whatever the frame.
class HalfPerson : public dyncull::host::FrameDetector {
 public:
  bool detect(const cv::Mat&, std::vector<dyncull::DetectedBox>* boxes, std::string*) {
    boxes->assign(1, dyncull::DetectedBox(0.f, 0.f, 319.f, 479.f, 0, 0.9f));
    return true;
  }
};

Frame grid_frame() {
  Frame f;
  f.mTimeStamp = 1.0;
  f.mnId = 0;
  for (int y = 40; y < 440; y += 40)
    for (int x = 40; x < 600; x += 40) f.mvKeys.push_back(cv::KeyPoint(cv::Point2f(float(x), float(y)), 7.f));
  f.mvKeysUn = f.mvKeys;
  f.N = static_cast<int>(f.mvKeys.size());
  f.mDescriptors = cv::Mat(f.N, 32, CV_8UC1, cv::Scalar(7));
  f.mvuRight.assign(f.mvKeys.size(), -1.f);
  f.mvDepth.assign(f.mvKeys.size(), -1.f);
  return f;
}

}  // namespace

int main() {
  namespace host = dyncull::host;
  const cv::Mat K = (cv::Mat_<double>(3, 3) << 525, 0, 319.5, 0, 525, 239.5, 0, 0, 1);
  const cv::Mat colour(480, 640, CV_8UC3, cv::Scalar(90, 120, 150));

  host::HostCuller stock((host::HostSettings()));
  expect(stock.ok(), "stock starts with no setting");
  Frame f = grid_frame();
  const int n = f.N;
  expect(host::cull_orb_slam_frame(stock, f, colour, cv::Mat(), K, cv::Mat(), cv::Mat()) == n &&
             f.mvKeys.size() == static_cast<std::size_t>(n),
         "stock mode leaves an ORB-SLAM frame as it is");

  host::HostSettings s;
  s.mode = host::Mode::BoxOnly;
  s.detector_sync = true;
  host::HostCuller box_only(s, std::unique_ptr<host::FrameDetector>(new HalfPerson));
  expect(box_only.ok(), "box_only starts with a detector of the host's own");
  Frame g = grid_frame();
  const int kept = host::cull_orb_slam_frame(box_only, g, colour, cv::Mat(), K, cv::Mat(), cv::Mat());
  expect(kept > 0 && kept < n, "box_only removes the features in the person box");
  expect(g.mvKeysUn.size() == static_cast<std::size_t>(kept) && g.mDescriptors.rows == kept &&
             g.mvDepth.size() == static_cast<std::size_t>(kept) && g.mvpMapPoints.size() == static_cast<std::size_t>(kept),
         "every parallel array keeps step with N");

  Frame3 h;
  static_cast<Frame&>(h) = grid_frame();
  h.mnId = 1;
  std::thread atlas([&box_only] { box_only.reset(); });  // ORB-SLAM3's Atlas starting a map
  atlas.join();
  const int kept3 = host::cull_orb_slam_frame(box_only, h, colour, cv::Mat(), K, cv::Mat(), Pose(), true);
  expect(kept3 == kept && h.mvDepth.size() == static_cast<std::size_t>(kept3) && h.Nleft == -1,
         "an ORB-SLAM3 one-camera frame with a Sophus-like pose is culled as ORB-SLAM2's");
  expect(box_only.stats().restarts == 0, "a reset from another thread in box_only: no keyframe to forget");
  Frame3 two = Frame3();
  static_cast<Frame&>(two) = grid_frame();
  two.Nleft = 100;
  two.Nright = two.N - 100;
  expect(host::cull_orb_slam_frame(box_only, two, colour, cv::Mat(), K, cv::Mat(), Pose(), false) == n &&
             two.mvKeys.size() == static_cast<std::size_t>(n),
         "an ORB-SLAM3 two-camera frame passes uncut");
  std::printf("orb_slam_host: %d of %d kept, %d failures\n", kept, n, failures);
  return failures == 0 ? 0 : 1;
}
