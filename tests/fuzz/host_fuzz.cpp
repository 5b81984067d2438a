// libFuzzer target: the host harness's ORB-SLAM helper (host/host_culler.hpp, cull_orb_slam_frame) as an
// ORB-SLAM tracking thread calls it, with everything decoded from the input: the camera matrix (absurd
// values and wrong types too), the distortion (empty, 4 or 5 values, a column view, wrong types), depth
// of random type and size, the motion-model pose, the image, and a Frame whose keypoints hold NaN, Inf and
// huge coordinates and whose parallel arrays sometimes disagree; the culler and box-only hosts run with a
// stand-in detector that returns decoded boxes. Checks the helper's contract: it never throws; a Frame
// whose arrays disagree is untouched; otherwise every parallel array keeps N entries and N never grows.
#include "dyncull/host/host_culler.hpp"

#include "fuzz_input.hpp"

#include <opencv2/core.hpp>

#include <cstdint>
#include <memory>
#include <vector>

namespace {

using namespace dyncull;

// The members of ORB-SLAM2's Frame that cull_orb_slam_frame touches.
struct Frame {
  double mTimeStamp = 0;
  unsigned long mnId = 0;
  int N = 0;
  std::vector<cv::KeyPoint> mvKeys, mvKeysUn;
  cv::Mat mDescriptors;
  std::vector<float> mvuRight, mvDepth;
  std::vector<int*> mvpMapPoints;
  std::vector<bool> mvbOutlier;
  std::vector<std::size_t> mGrid[8][6];
  bool PosInGrid(const cv::KeyPoint& k, int& x, int& y) const {
    if (!(k.pt.x >= 0.f && k.pt.x < 640.f && k.pt.y >= 0.f && k.pt.y < 480.f)) return false;
    x = static_cast<int>(k.pt.x / 80.f);  // checked: in [0, 640) just above
    y = static_cast<int>(k.pt.y / 80.f);  // checked: in [0, 480) just above
    return true;
  }
};

// Boxes of the current input, handed out by the stand-in detector (synchronous: read after they are set).
std::vector<DetectedBox> g_boxes;

class DecodedBoxes : public host::FrameDetector {
 public:
  bool detect(const cv::Mat&, std::vector<DetectedBox>* boxes, std::string*) {
    *boxes = g_boxes;
    return true;
  }
};

host::HostSettings settings(host::Mode mode) {
  host::HostSettings s;
  s.mode = mode;
  s.detector_sync = true;
  return s;
}

/// One host per mode for the whole run, as a tracking thread keeps one.
host::HostCuller& host_of(int kind) {
  static host::HostCuller culler(settings(host::Mode::Culler), std::unique_ptr<host::FrameDetector>(new DecodedBoxes));
  static host::HostCuller box_only(settings(host::Mode::BoxOnly),
                                   std::unique_ptr<host::FrameDetector>(new DecodedBoxes));
  return kind == 0 ? culler : box_only;
}

cv::Mat decode_matrix(fuzz::Input& in, int rows, int cols) {
  const int type = in.u8() % 4 == 0 ? CV_32F : CV_64F;
  cv::Mat m(rows, cols, type);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const double v = in.value(-2000.0, 2000.0);
      if (type == CV_32F) m.at<float>(r, c) = static_cast<float>(v);
      else m.at<double>(r, c) = v;
    }
  return m;
}

cv::Mat decode_K(fuzz::Input& in) {
  switch (in.u8() % 6) {
    case 0: return cv::Mat();
    case 1: return decode_matrix(in, 3, 3);
    case 2: return cv::Mat(3, 3, CV_8U, cv::Scalar(1));
    default: {
      cv::Mat K = (cv::Mat_<float>(3, 3) << 525.f, 0.f, 319.5f, 0.f, 525.f, 239.5f, 0.f, 0.f, 1.f);
      if (in.u8() % 2) K.at<float>(0, 0) = static_cast<float>(in.value(-1e3, 1e4));
      return K;
    }
  }
}

cv::Mat decode_distortion(fuzz::Input& in) {
  switch (in.u8() % 6) {
    case 0: return cv::Mat();
    case 1: return decode_matrix(in, 1, 4);
    case 2: return decode_matrix(in, 5, 1);
    case 3: return decode_matrix(in, 5, 3).col(1);  // a column view: not continuous
    case 4: return cv::Mat(1, 5, CV_32S, cv::Scalar(0));
    default: return cv::Mat(5, 1, CV_32F, cv::Scalar(0));
  }
}

cv::Mat decode_depth(fuzz::Input& in) {
  const int kind = in.u8() % 5;
  if (kind == 0) return cv::Mat();
  const bool full = in.u8() % 4 != 0;
  const int w = full ? 640 : 1 + in.u8(), h = full ? 480 : 1 + in.u8();
  if (kind == 1) return cv::Mat(h, w, CV_16U, cv::Scalar(in.u16()));
  if (kind == 2) return cv::Mat(h, w, CV_8U, cv::Scalar(3));
  cv::Mat d(h, w, CV_32F, cv::Scalar(static_cast<float>(in.value(0.0, 8.0))));
  return d;
}

Frame decode_frame(fuzz::Input& in) {
  Frame f;
  f.mTimeStamp = in.value(0.0, 1e9);
  const std::size_t n = in.u8() % 160;
  for (std::size_t i = 0; i < n; ++i)
    f.mvKeys.push_back(cv::KeyPoint(cv::Point2f(in.scalar<float>(0.0, 640.0), in.scalar<float>(0.0, 480.0)), 7.f));
  f.mvKeysUn = f.mvKeys;
  f.N = static_cast<int>(n);
  f.mDescriptors = cv::Mat(static_cast<int>(n), 32, CV_8U, cv::Scalar(in.u8()));
  f.mvuRight.assign(n, -1.f);
  f.mvDepth.assign(n, -1.f);
  switch (in.u8() % 8) {  // sometimes the arrays disagree
    case 0: f.mvKeysUn.resize(n / 2); break;
    case 1: f.mDescriptors = cv::Mat(static_cast<int>(n) + 1, 32, CV_8U, cv::Scalar(0)); break;
    case 2: f.N = static_cast<int>(n) + 3; break;
    case 3: f.mvDepth.resize(n + 1); break;
    default: break;
  }
  f.mvpMapPoints.assign(static_cast<std::size_t>(f.N < 0 ? 0 : f.N), nullptr);
  f.mvbOutlier.assign(f.mvpMapPoints.size(), false);
  return f;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::Input in(data, size);
  host::HostCuller& culler = host_of(in.u8() % 2);
  const cv::Mat K = decode_K(in), distortion = decode_distortion(in), depth = decode_depth(in);
  const cv::Mat pose = in.u8() % 3 == 0 ? cv::Mat() : decode_matrix(in, 4, 4);
  const cv::Mat image(in.u8() % 4 == 0 ? 0 : 480, 640, CV_8UC3, cv::Scalar(90, 90, 90));
  g_boxes.clear();
  for (int b = in.u8() % 4; b > 0; --b)
    g_boxes.push_back(DetectedBox(in.scalar<float>(0.0, 640.0), in.scalar<float>(0.0, 480.0),
                                  in.scalar<float>(0.0, 640.0), in.scalar<float>(0.0, 480.0), in.u8() % 3, 0.9f));
  Frame f = decode_frame(in);
  const Frame before = f;
  const bool agreed = host::detail::orb_slam_frame_disagreement(f).empty();
  const int n = host::cull_orb_slam_frame(culler, f, image, depth, K, distortion, pose);
  DYNCULL_FUZZ_CHECK(n == f.N);
  if (!agreed) {
    DYNCULL_FUZZ_CHECK(f.N == before.N && f.mvKeys.size() == before.mvKeys.size() &&
                       f.mvKeysUn.size() == before.mvKeysUn.size() && f.mvDepth.size() == before.mvDepth.size() &&
                       f.mDescriptors.rows == before.mDescriptors.rows);
    return 0;
  }
  const std::size_t kept = static_cast<std::size_t>(f.N);
  DYNCULL_FUZZ_CHECK(f.N <= before.N);
  DYNCULL_FUZZ_CHECK(f.mvKeys.size() == kept && f.mvKeysUn.size() == kept && f.mvuRight.size() == kept &&
                     f.mvDepth.size() == kept && static_cast<std::size_t>(f.mDescriptors.rows) == kept &&
                     f.mvpMapPoints.size() == kept && f.mvbOutlier.size() == kept);
  return 0;
}
