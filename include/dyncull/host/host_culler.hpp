/// @file host_culler.hpp
/// The host harness a SLAM system's tracking thread calls once per frame (ORB-SLAM2/3's Tracking): the
/// variant chosen at start (stock, box_only, culler), detector boxes from a folder of per-frame JSON files
/// or from a live YOLO detector on its own thread, a per-frame CSV log and a summary at exit.
/// C++11 header (standard library and opencv2/core.hpp); compiled into dyncull::host, apart from the
/// culler library (dyncull::culler links no JSON reader and no detector).
///
/// API:
///   dyncull::host::HostCuller& culler = dyncull::host::environment_culler();  // at start: a bad setting exits
///   dyncull::host::cull_orb_slam_frame(culler, frame, colour, depth, K, dist, predicted_Tcw);  // per frame
///   culler.reset();  // the host started a new map (ORB-SLAM3's Atlas): from any thread
///   // or, for any host: const std::vector<std::uint8_t>* keep = culler.cull(host_frame);
#pragma once

#include "dyncull/host/live_detection.hpp"
#include "dyncull/opencv/culler.hpp"

#include <opencv2/core.hpp>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace dyncull {
namespace host {

/// stock: nothing removed (the host runs as without dyncull); box_only: every feature inside a box of
/// HostSettings::box_only_classes removed (the YOLO forks' way); culler: the compiled culler's decision.
enum class Mode { Stock, BoxOnly, Culler };
const char* to_string(Mode mode);

/// Everything the host reads at start. from_environment() fills it from DYNCULL_* and says which variable
/// could not be read; HostCuller checks the rest (preset, folder, detector, log) when it is made.
struct HostSettings {
  Mode mode;
  std::string preset;                 ///< the culler's preset (CullerOptions)
  std::string detections_dir;         ///< NNNNNN.json per frame with `timestamp` = the image stamp
  double stamp_tolerance_s;           ///< a detections file matches an image within this many seconds, [0, 1]
  std::string log_path;               ///< per-frame CSV log; empty: none
  std::vector<int> box_only_classes;  ///< classes box_only removes (COCO-80: 0 = person)
  std::string detector;               ///< live detector: "CFG,WEIGHTS" (Darknet) or "MODEL.onnx"; empty: none
  bool detector_sync;                 ///< wait for each frame's own boxes (true) or use the newest finished ones
  bool frames_rgb;                    ///< colour frames arrive in RGB order (false: BGR, as cv::imread gives)
  int opencv_threads;                 ///< > 0: cv::setNumThreads(n) at start, for the whole process; 0: unchanged
  Status status;                      ///< Ok, or InvalidInput with `reason` naming the variable
  std::string reason;

  HostSettings()
      : mode(Mode::Stock), preset("recommended"), stamp_tolerance_s(0.005), box_only_classes(1, 0),
        detector_sync(false), frames_rgb(false), opencv_threads(0), status(Status::Ok) {}
  bool ok() const { return status == Status::Ok; }

  /// DYNCULL_MODE (stock, box_only or culler; unset: culler when DYNCULL_DETECTIONS or DYNCULL_DETECTOR is
  /// set, else stock), DYNCULL_DETECTIONS, DYNCULL_DETECTOR, DYNCULL_DETECTOR_SYNC (0 or 1),
  /// DYNCULL_FRAMES_RGB (0 or 1), DYNCULL_OPENCV_THREADS (1 to 64), DYNCULL_PRESET, DYNCULL_STAMP_TOLERANCE
  /// (seconds), DYNCULL_LOG,
  /// DYNCULL_BOX_CLASSES (comma-separated class ids). The first unreadable one sets status and reason.
  static HostSettings from_environment();
};

/// One frame as the host has it. `image`: the frame as captured, CV_8UC3 colour (the live detector runs on
/// it) or CV_8UC1 grey; its size is the image size. `keys`: as detected (raw pixels, where the boxes are);
/// `keys_un`: the host's undistorted copy or null; `depth`: CV_32F metres, CV_16U raw or empty
/// (monocular); `predicted_Tcw`: 4x4 cam_from_world or empty.
struct HostFrame {
  double stamp;
  unsigned long frame_id;
  const cv::Mat* K;
  const cv::Mat* distortion;
  const cv::Mat* image;
  const std::vector<cv::KeyPoint>* keys;
  const std::vector<cv::KeyPoint>* keys_un;
  const cv::Mat* descriptors;
  const cv::Mat* depth;
  const cv::Mat* predicted_Tcw;
  HostFrame()
      : stamp(0), frame_id(0), K(nullptr), distortion(nullptr), image(nullptr), keys(nullptr), keys_un(nullptr),
        descriptors(nullptr), depth(nullptr), predicted_Tcw(nullptr) {}
};

/// One camera stream's culling as a host runs it. Made once at start: status() says whether every setting,
/// the detections folder, the detector and the log could be opened; a host that is not ok passes every
/// frame uncut. Nothing it does per frame throws: a failure is the frame's status in the log and the
/// frame passes uncut. One tracking thread; not copyable.
class HostCuller {
 public:
  /// Stops at the first setting, folder, detector or log that cannot be used (status and reason).
  explicit HostCuller(const HostSettings& settings);
  /// The same with a detector of the host's own (or a test's) in place of settings.detector.
  HostCuller(const HostSettings& settings, std::unique_ptr<FrameDetector> detector);
  ~HostCuller();  ///< writes summary() to standard error when any frame was seen
  HostCuller(const HostCuller&) = delete;
  HostCuller& operator=(const HostCuller&) = delete;

  Status status() const;
  const std::string& reason() const;  ///< names the variable, the file and why
  bool ok() const { return status() == Status::Ok; }

  /// The keep mask for one frame (1 = keep), parallel to *frame.keys, or null when nothing is removed
  /// (stock mode, a host that is not ok, a frame that could not be culled: the log says why). The culler
  /// is made on the first call from K, the distortion and the image size. A frame_id not above the last
  /// one means the host restarted its map: the culler forgets its keyframe first.
  const std::vector<std::uint8_t>* cull(const HostFrame& frame) noexcept;

  /// The host started a new map (ORB-SLAM3's Atlas creating one): the culler forgets its keyframe before
  /// the next frame it culls, and the summary counts a restart when there was one to forget. Only sets a
  /// flag: safe from any thread, at any time (before the first frame it does nothing).
  void reset() noexcept;

  /// Logs and counts a frame of `features` features that the host passes uncut because `why` (its arrays
  /// disagree, for example): status InvalidInput, every feature kept.
  void pass_uncut(double stamp, std::size_t features, const std::string& why) noexcept;

  /// The boxes of the detections file at `stamp`, or false when none is within the tolerance.
  bool detections_for(double stamp, std::vector<DetectedBox>* boxes) const;

  const HostSettings& settings() const;
  /// Frames seen, frames without boxes (no file, no finished detection yet, detector failed), frames not
  /// Ok, restarts, features before and after, milliseconds culling, live boxes' age and detector time.
  struct Stats {
    std::size_t frames, frames_without_detections, frames_not_ok, restarts, detector_failures, frames_with_age;
    double features_in, features_kept, cull_ms, box_age_frames, detector_ms;
    Stats()
        : frames(0), frames_without_detections(0), frames_not_ok(0), restarts(0), detector_failures(0),
          frames_with_age(0), features_in(0), features_kept(0), cull_ms(0), box_age_frames(0), detector_ms(0) {}
  };
  const Stats& stats() const;
  /// One line: mode, frames, frames without boxes, not Ok, restarts, mean features in and kept, mean
  /// milliseconds; with a live detector, its milliseconds per frame and the boxes' mean age.
  std::string summary() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The process's host culler, made from the environment at the first call and destroyed at exit (its
/// summary written, its detector stopped), for hosts such as ORB-SLAM2 whose Tracking object is never
/// destroyed. When a setting cannot be used, the first call writes "dyncull: <reason>" to standard error
/// and exits with status 1, as ORB-SLAM2 does for a settings file it cannot open: call it once at start.
HostCuller& environment_culler();

namespace detail {
template <class Vector>
void assign_default(Vector& v, std::size_t n) {
  v.assign(n, typename Vector::value_type());
}

/// Empty when the Frame's parallel arrays agree with its keypoints, else the first that does not.
template <class Frame>
std::string orb_slam_frame_disagreement(const Frame& f) {
  const std::size_t n = f.mvKeys.size();
  const auto says = [n](const char* name, std::size_t size) {
    return std::string("frame arrays disagree: ") + name + " has " + std::to_string(size) + " entries, mvKeys " +
           std::to_string(n) + "; the frame passes uncut";
  };
  if (f.N < 0 || static_cast<std::size_t>(f.N) != n) return says("N", static_cast<std::size_t>(f.N < 0 ? 0 : f.N));
  if (f.mvKeysUn.size() != n) return says("mvKeysUn", f.mvKeysUn.size());
  if (f.mvuRight.size() != n) return says("mvuRight", f.mvuRight.size());
  if (f.mvDepth.size() != n) return says("mvDepth", f.mvDepth.size());
  if (f.mDescriptors.dims > 2 || static_cast<std::size_t>(f.mDescriptors.rows) != n)
    return says("mDescriptors", f.mDescriptors.dims > 2 ? 0 : static_cast<std::size_t>(f.mDescriptors.rows));
  return std::string();
}

/// ORB-SLAM3's Frame (it has Nleft, Nright, mvLeftToRightMatch, mvStereo3Dpoints): empty for a one-camera
/// frame (Nleft == -1, no left-right matches), else why it passes uncut. A two-camera frame (fisheye
/// stereo) indexes its keys as left then right, which the culling here does not keep in step.
template <class Frame>
auto two_camera_refusal(const Frame& f, int)
    -> decltype(f.Nleft + f.Nright + f.mvLeftToRightMatch.size() + f.mvStereo3Dpoints.size(), std::string()) {
  if (f.Nleft != -1 || f.Nright != -1)
    return "a two-camera frame (Nleft " + std::to_string(f.Nleft) + ", Nright " + std::to_string(f.Nright) +
           "): its left and right keys are not culled; the frame passes uncut";
  if (!f.mvLeftToRightMatch.empty() || !f.mvStereo3Dpoints.empty())
    return "a one-camera frame with left-right matches (mvLeftToRightMatch " +
           std::to_string(f.mvLeftToRightMatch.size()) + ", mvStereo3Dpoints " +
           std::to_string(f.mvStereo3Dpoints.size()) + " entries): the frame passes uncut";
  return std::string();
}
/// ORB-SLAM2's Frame (no such arrays): always one camera.
template <class Frame>
std::string two_camera_refusal(const Frame&, long) {
  return std::string();
}

/// A pose as a 4x4 cv::Mat: a cv::Mat as it is (empty: none), anything with matrix() (Sophus::SE3f,
/// Sophus::SE3d, an Eigen transform) copied element by element as CV_64F.
inline cv::Mat pose_matrix(const cv::Mat& pose) { return pose; }
template <class Pose>
cv::Mat pose_matrix(const Pose& pose) {
  const auto m = pose.matrix();
  if (m.rows() != 4 || m.cols() != 4) return cv::Mat();
  cv::Mat out(4, 4, CV_64F);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out.at<double>(r, c) = static_cast<double>(m(r, c));
  return out;
}
}  // namespace detail

/// Culls an ORB-SLAM2 or ORB-SLAM3 Frame after its constructor and before tracking uses it: applies the
/// keep mask to mvKeys, mvKeysUn, mDescriptors, mvuRight and mvDepth, sets N, and rebuilds what is sized
/// by N (mvpMapPoints, mvbOutlier, the feature grid through the Frame's public PosInGrid). `image`: the
/// frame as captured (colour for a live detector; ORB-SLAM's imRGB before it is turned grey).
/// `predicted_Tcw`: cam_from_world, a 4x4 cv::Mat (ORB-SLAM2; empty: none) or a Sophus SE3 (ORB-SLAM3),
/// used only when `pose_known`. An ORB-SLAM3 two-camera frame (Nleft != -1) passes uncut, logged.
/// Returns the new N; the old one, with nothing touched, in stock mode, when the frame's arrays disagree
/// (logged as not culled) or when anything fails (logged).
template <class Frame, class Pose>
int cull_orb_slam_frame(HostCuller& culler, Frame& frame, const cv::Mat& image, const cv::Mat& depth,
                        const cv::Mat& K, const cv::Mat& distortion, const Pose& predicted_Tcw,
                        bool pose_known = true) noexcept {
  try {
    std::string disagreement = detail::two_camera_refusal(frame, 0);
    if (disagreement.empty()) disagreement = detail::orb_slam_frame_disagreement(frame);
    if (!disagreement.empty()) {
      culler.pass_uncut(frame.mTimeStamp, frame.mvKeys.size(), disagreement);
      return frame.N;
    }
    HostFrame h;
    h.stamp = frame.mTimeStamp;
    h.frame_id = static_cast<unsigned long>(frame.mnId);
    h.K = &K;
    h.distortion = &distortion;
    h.image = &image;
    h.keys = &frame.mvKeys;
    h.keys_un = &frame.mvKeysUn;
    h.descriptors = &frame.mDescriptors;
    h.depth = &depth;
    const cv::Mat pose = pose_known ? detail::pose_matrix(predicted_Tcw) : cv::Mat();
    h.predicted_Tcw = &pose;
    const std::vector<std::uint8_t>* keep = culler.cull(h);
    if (!keep) return frame.N;
    const long n = cv_adapter::compact(*keep, frame.mDescriptors, frame.mvKeys, frame.mvKeysUn, frame.mvuRight,
                                       frame.mvDepth);
    if (n < 0) return frame.N;  // checked above: the arrays agree
    frame.N = static_cast<int>(n);
    detail::assign_default(frame.mvpMapPoints, frame.mvKeys.size());
    frame.mvbOutlier.assign(frame.mvKeys.size(), false);
    for (auto& column : frame.mGrid)
      for (auto& cell : column) cell.clear();
    for (std::size_t i = 0; i < frame.mvKeysUn.size(); ++i) {
      int x = 0, y = 0;
      if (frame.PosInGrid(frame.mvKeysUn[i], x, y)) frame.mGrid[x][y].push_back(i);
    }
    return frame.N;
  } catch (...) {  // out of memory in the host's own containers: the frame goes on as it is
    return frame.N;
  }
}

}  // namespace host
}  // namespace dyncull
