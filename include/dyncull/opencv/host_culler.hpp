/// @file host_culler.hpp
/// What a SLAM host's tracking thread calls once per frame (ORB-SLAM2/3's Tracking): the variant chosen at
/// run time (stock, box_only, culler), the detector boxes looked up by image timestamp in a folder of
/// per-frame JSON files, a per-frame status log, and the keep mask applied to an ORB-SLAM-style Frame.
/// C++11 header (standard library and opencv2/core.hpp); compiled into dyncull::culler.
///
/// API:
///   static dyncull::cv_adapter::HostCuller culler(dyncull::cv_adapter::HostCuller::environment_settings());
///   dyncull::cv_adapter::cull_orb_slam_frame(culler, frame, image_size, depth, K, dist, predicted_Tcw);
///   // or, for any host: const std::vector<std::uint8_t>* keep = culler.cull(stamp, frame_id, ...);
#pragma once

#include "dyncull/opencv/culler.hpp"

#include <opencv2/core.hpp>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

namespace dyncull {
namespace cv_adapter {

/// One camera stream's culling as a host runs it: the variant, the detections by timestamp, the log.
/// Not thread-safe (one tracking thread); not copyable.
class HostCuller {
 public:
  /// stock: nothing removed (the host runs as without dyncull); box_only: every feature inside a box of
  /// Settings::box_only_classes removed (the YOLO forks' way); culler: the compiled culler's decision.
  enum class Mode { Stock, BoxOnly, Culler };

  struct Settings {
    Mode mode;
    std::string preset;              ///< the culler's preset (CullerOptions)
    std::string detections_dir;      ///< NNNNNN.json per frame with `timestamp` = the image stamp
    double stamp_tolerance_s;        ///< a detections file matches an image within this many seconds
    std::string log_path;            ///< per-frame CSV log; empty: none
    std::vector<int> box_only_classes;  ///< classes box_only removes (COCO-80: 0 = person)

    Settings() : mode(Mode::Stock), preset("recommended"), stamp_tolerance_s(0.005), box_only_classes(1, 0) {}
  };

  /// Settings from the environment: DYNCULL_MODE (stock, box_only or culler; unset: culler when
  /// DYNCULL_DETECTIONS is set, else stock), DYNCULL_DETECTIONS, DYNCULL_PRESET, DYNCULL_STAMP_TOLERANCE
  /// (seconds), DYNCULL_LOG, DYNCULL_BOX_CLASSES (comma-separated class ids). Throws std::invalid_argument
  /// naming the variable and its value when one cannot be read.
  static Settings environment_settings();

  /// Reads the whole detections folder for box_only and culler. Throws std::invalid_argument when the
  /// folder is missing or a file in it cannot be read (the file, byte and reason named), or when the log
  /// cannot be opened; the message is also written to standard error.
  explicit HostCuller(const Settings& settings);
  ~HostCuller();  ///< writes summary() to standard error when any frame was seen
  HostCuller(const HostCuller&) = delete;
  HostCuller& operator=(const HostCuller&) = delete;

  /// The keep mask for one frame (1 = keep), parallel to `keys`, or null in stock mode (nothing to
  /// remove). `keys`: as detected (raw pixels, where the detector's boxes are); `keys_un`: the host's
  /// undistorted copy or empty; `depth`: CV_32F metres, CV_16U raw or empty (monocular);
  /// `predicted_Tcw`: 4x4 cam_from_world or empty. The culler is made on the first call from `K`,
  /// `distortion` and `image_size`. A `frame_id` not above the last one means the host restarted its map:
  /// the culler forgets its keyframe first.
  const std::vector<std::uint8_t>* cull(double stamp, unsigned long frame_id, const cv::Mat& K,
                                        const cv::Mat& distortion, cv::Size image_size,
                                        const std::vector<cv::KeyPoint>& keys,
                                        const std::vector<cv::KeyPoint>& keys_un, const cv::Mat& descriptors,
                                        const cv::Mat& depth, const cv::Mat& predicted_Tcw);

  /// The boxes of the frame at `stamp`, or false when no detections file is within the tolerance.
  bool detections_for(double stamp, std::vector<DetectedBox>* boxes) const;

  const Settings& settings() const;
  static const char* to_string(Mode mode);
  /// Frames seen, frames without a detections file, features before and after, milliseconds culling.
  struct Stats {
    std::size_t frames, frames_without_detections, frames_not_ok, restarts;
    double features_in, features_kept, cull_ms;
    Stats() : frames(0), frames_without_detections(0), frames_not_ok(0), restarts(0), features_in(0), features_kept(0), cull_ms(0) {}
  };
  const Stats& stats() const;
  /// One line: mode, frames, frames without detections, mean features in and kept, mean milliseconds.
  std::string summary() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

namespace detail {
template <class Vector>
void assign_default(Vector& v, std::size_t n) {
  v.assign(n, typename Vector::value_type());
}
}  // namespace detail

/// Culls an ORB-SLAM2/3-style Frame after its constructor and before tracking uses it: applies the keep
/// mask to mvKeys, mvKeysUn, mDescriptors, mvuRight and mvDepth, sets N, and rebuilds what is sized by N
/// (mvpMapPoints, mvbOutlier, the feature grid through the Frame's public PosInGrid). Returns the new N
/// (the old one in stock mode, or when the arrays disagree with the mask: nothing is touched then).
template <class Frame>
int cull_orb_slam_frame(HostCuller& culler, Frame& frame, cv::Size image_size, const cv::Mat& depth, const cv::Mat& K,
                        const cv::Mat& distortion, const cv::Mat& predicted_Tcw) {
  const std::vector<std::uint8_t>* keep =
      culler.cull(frame.mTimeStamp, static_cast<unsigned long>(frame.mnId), K, distortion, image_size, frame.mvKeys,
                  frame.mvKeysUn, frame.mDescriptors, depth, predicted_Tcw);
  if (!keep) return frame.N;
  const long n = compact(*keep, frame.mDescriptors, frame.mvKeys, frame.mvKeysUn, frame.mvuRight,
                                         frame.mvDepth);
  if (n < 0) return frame.N;
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
}

}  // namespace cv_adapter
}  // namespace dyncull
