/// @file live_detector.hpp
/// dynamic_vo's live detector (--detector CFG,WEIGHTS or --detector MODEL.onnx): the library's YOLO
/// detector on OpenCV DNN (opencv/yolo_detector.hpp) run on each frame a sequence source loads, its boxes
/// passed through the same detection filter (padding, per-class thresholds) as boxes read from files.
/// A source calls detect() once per frame, in place of reading that frame's boxes.
#pragma once

#include "dyncull/core/box.hpp"
#include "dyncull/culling/detections.hpp"

#if defined(DYNCULL_HAS_OPENCV_DNN)
#include "dyncull/opencv/yolo_detector.hpp"
#endif

#include <opencv2/core.hpp>

#include <chrono>
#include <cstddef>
#include <cstdio>
#include <string>
#include <vector>

namespace dyncull {
namespace vo {

/// Help text of the flag.
inline const char* live_detector_help() {
  return "  --detector CFG,WEIGHTS  run a YOLO detector live on every frame (OpenCV DNN) instead of reading\n"
         "                      boxes: a Darknet cfg and weights pair, or one YOLOv5 / YOLOv8 .onnx export.\n"
         "                      416 x 416 plain resize, confidence >= 0.25, NMS per class at IoU 0.45.\n"
         "                      Detection degrades on grey frames (e.g. the Bonn sequence's rgb/): the\n"
         "                      detector was trained on colour, and on the Bonn crowd frames finds in grey\n"
         "                      about 9 in 10 of the person boxes it finds in colour\n";
}

/// One detector for a whole run; frames in, filtered pixel boxes out.
class LiveDetector {
 public:
  /// `spec`: "CFG,WEIGHTS" (Darknet) or "MODEL.onnx". False with a reason naming the file for a bad
  /// spec, a missing or unreadable model, or a network that is not a YOLO head.
  bool open(const std::string& spec, const DetectionOptions<float>& filter, std::string* error) {
    filter_ = filter;
    frames_ = grey_frames_ = boxes_ = 0;
    seconds_ = 0;
#if defined(DYNCULL_HAS_OPENCV_DNN)
    cv_adapter::YoloDetectorOptions o;
    const std::size_t comma = spec.find(',');
    o.model = spec.substr(0, comma);
    if (comma != std::string::npos) o.weights = spec.substr(comma + 1);
    if (o.model.empty()) {
      *error = "--detector needs CFG,WEIGHTS or MODEL.onnx, got '" + spec + "'";
      return false;
    }
    const cv_adapter::YoloOpenResult r = detector_.open(o);
    if (!r.ok()) {
      *error = "--detector: " + r.reason;
      return false;
    }
    open_ = true;
    return true;
#else
    *error = "--detector '" + spec + "': dynamic_vo was built without OpenCV's dnn module";
    return false;
#endif
  }

  bool enabled() const { return open_; }

  /// Replaces `*out` with the boxes found on `image` (CV_8UC3 BGR, or CV_8UC1 grey) after the filter.
  /// False with a reason when the detector refuses the frame.
  bool detect(const cv::Mat& image, std::vector<Detection<float>>* out, std::string* error) {
    out->clear();
#if defined(DYNCULL_HAS_OPENCV_DNN)
    if (!open_) {
      *error = "live detector: not open";
      return false;
    }
    const auto t0 = std::chrono::steady_clock::now();
    const cv_adapter::YoloDetectorResult& r = detector_.detect(image);
    seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!r.ok()) {
      *error = "live detector: " + r.reason;
      return false;
    }
    ++frames_;
    if (r.converted_from_grey || looks_grey(image)) ++grey_frames_;
    filter_detections(r.detections, image.cols, image.rows, filter_, &filtered_);
    *out = filtered_.detections;
    boxes_ += out->size();
    return true;
#else
    (void)image;
    (void)filtered_;
    *error = "live detector: built without OpenCV's dnn module";
    return false;
#endif
  }

  /// "live detector: N frames, X ms per frame, B boxes (G grey frames)" for the run's log.
  std::string summary() const {
    char line[200];
    std::snprintf(line, sizeof line, "live detector: %zu frames, %.1f ms per frame, %zu boxes after the filter%s", frames_,
                  frames_ ? 1000.0 * seconds_ / static_cast<double>(frames_) : 0.0, boxes_,
                  grey_frames_ ? (", " + std::to_string(grey_frames_) + " grey frames (trained on colour: grey loses boxes)").c_str()
                               : "");
    return line;
  }
  double mean_ms() const { return frames_ ? 1000.0 * seconds_ / static_cast<double>(frames_) : 0.0; }
  std::size_t grey_frames() const { return grey_frames_; }

 private:
  /// A colour image whose three channels agree on a sparse grid: a grey frame read as colour.
  static bool looks_grey(const cv::Mat& image) {
    if (image.type() != CV_8UC3) return false;
    for (int r = 0; r < image.rows; r += 16) {
      const cv::Vec3b* row = image.ptr<cv::Vec3b>(r);
      for (int c = 0; c < image.cols; c += 16)
        if (row[c][0] != row[c][1] || row[c][1] != row[c][2]) return false;
    }
    return true;
  }

#if defined(DYNCULL_HAS_OPENCV_DNN)
  cv_adapter::YoloDetector detector_;
#endif
  DetectionOptions<float> filter_;
  DetectionsResult<float> filtered_;
  bool open_ = false;
  std::size_t frames_ = 0, grey_frames_ = 0, boxes_ = 0;
  double seconds_ = 0;
};

}  // namespace vo
}  // namespace dyncull
