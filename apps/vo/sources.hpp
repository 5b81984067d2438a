/// @file sources.hpp
/// The frame a dynamic_vo source hands the runner, and the synthetic source: the dynamic scene
/// rendered in memory (dyncull::sim::Scene, with per-pixel "moving" truth). Recorded RGB-D sequences
/// are read by DatasetSource (dataset.hpp).
#pragma once

#include "dyncull/core/box.hpp"
#include "dyncull/core/camera.hpp"
#include "dyncull/core/pixel.hpp"
#include "dyncull/core/types.hpp"
#include "dyncull/culling/detections.hpp"
#include "dyncull/sim/scene.hpp"


#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace dyncull {
namespace vo {

/// One frame as the demo consumes it. Mats may be headers over the source's buffers: valid until
/// the next load() on the same source.
/// SequenceFrame::moving where the truth of a real sequence says neither static nor moving.
constexpr std::uint8_t kTruthUnknown = 2;

/// The motion truth at the pixel nearest p: 1 moving, 0 static, -1 none (no truth, outside, unknown).
inline int truth_at(const cv::Mat& moving, const cv::Point2f& p) {
  int u = 0, v = 0;
  if (moving.empty() || !pixel_of(p.x, p.y, moving.cols, moving.rows, &u, &v)) return -1;
  const std::uint8_t m = moving.at<std::uint8_t>(v, u);
  return m == kTruthUnknown ? -1 : (m != 0 ? 1 : 0);
}

struct SequenceFrame {
  double timestamp = 0;
  cv::Mat gray;     ///< CV_8UC1
  cv::Mat depth_m;  ///< CV_32FC1 metres, 0 = no measurement
  cv::Mat moving;   ///< CV_8UC1, 1 where the surface moves, kTruthUnknown where a real sequence's truth
                    ///< cannot tell (dyncull_motion_truth); empty when there is no truth
  cv::Mat instance; ///< CV_16UC1 sim instance ids (sim::SceneInstance); empty when there is no truth
  cv::Mat motion_m; ///< CV_32FC1 sim: metres the surface moved since the previous frame (sim::FrameData)
  std::vector<Detection<float>> detections;
  bool has_truth_pose = false;
  Rigid3<double> truth_world_from_cam;
  /// BGR image for drawing (only filled by load_colour()).
  cv::Mat bgr;
};

/// Synthetic walking sequence rendered on demand (deterministic for its options).
class SimSource {
 public:
  explicit SimSource(const sim::SceneOptions& options) : scene_(options) {}
  int size() const { return scene_.num_frames(); }
  PinholeCamera<double> camera() const { return scene_.camera(); }
  bool has_detections() const { return true; }
  bool has_truth_labels() const { return true; }

  bool load(int index, SequenceFrame* out, std::string* error) {
    scene_.render(index, &data_);
    if (!data_.ok()) {
      if (error) *error = "sim frame " + std::to_string(index) + ": " + data_.reason;
      return false;
    }
    const int w = data_.width, h = data_.height;
    if (w <= 0 || h <= 0 || data_.gray.size() != static_cast<std::size_t>(w) * h ||
        data_.depth_m.size() != static_cast<std::size_t>(w) * h) {
      if (error) *error = "sim frame " + std::to_string(index) + " has inconsistent buffers";
      return false;
    }
    out->timestamp = data_.timestamp;
    out->gray = cv::Mat(h, w, CV_8UC1, data_.gray.data());
    out->depth_m = cv::Mat(h, w, CV_32FC1, data_.depth_m.data());
    out->moving = data_.moving.size() == data_.gray.size() ? cv::Mat(h, w, CV_8UC1, data_.moving.data()) : cv::Mat();
    out->instance = data_.instance.size() == data_.gray.size() ? cv::Mat(h, w, CV_16UC1, data_.instance.data()) : cv::Mat();
    out->motion_m = data_.motion_m.size() == data_.gray.size() ? cv::Mat(h, w, CV_32FC1, data_.motion_m.data()) : cv::Mat();
    out->detections = data_.detections;
    out->has_truth_pose = true;
    out->truth_world_from_cam = data_.world_from_cam;
    out->bgr.release();
    return true;
  }
  void load_colour(SequenceFrame* out) const {
    if (data_.rgb.size() != static_cast<std::size_t>(data_.width) * data_.height * 3) {
      cv::cvtColor(out->gray, out->bgr, cv::COLOR_GRAY2BGR);
      return;
    }
    cv::Mat rgb(data_.height, data_.width, CV_8UC3, const_cast<std::uint8_t*>(data_.rgb.data()));
    cv::cvtColor(rgb, out->bgr, cv::COLOR_RGB2BGR);
  }

 private:
  sim::Scene scene_;
  sim::FrameData data_;
};

}  // namespace vo
}  // namespace dyncull
