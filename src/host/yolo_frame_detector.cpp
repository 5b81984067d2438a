// The host's YOLO detector (host/live_detection.hpp, open_yolo_detector): opencv/yolo_detector.hpp behind
// the FrameDetector interface, its boxes as the culler's DetectedBox. Built without OpenCV's dnn module,
// opening says so.
#include "dyncull/host/live_detection.hpp"

#if defined(DYNCULL_HAS_OPENCV_DNN)
#include "dyncull/opencv/yolo_detector.hpp"
#endif

#include <cstdint>
#include <exception>
#include <filesystem>
#include <utility>

namespace dyncull {
namespace host {

#if defined(DYNCULL_HAS_OPENCV_DNN)
namespace {

// A Darknet cfg's own input size ([net] width and height, what the network was trained at) in place of
// the adapter's default: Yolo-Fastest's 320 x 320 takes 0.6x the time of 416 x 416, so live boxes are
// younger when they reach the tracker. Left at the default when the cfg gives none or cannot be read
// (opening the detector then names the problem).
void use_trained_input_size(cv_adapter::YoloDetectorOptions* o) {
  std::string text, why;
  cv_adapter::DarknetLayout layout;
  if (o->model.size() < 4 || o->model.compare(o->model.size() - 4, 4, ".cfg") != 0) return;
  if (!text::read_small_file(o->model, cv_adapter::kMaxYoloCfgBytes, &text, &why)) return;
  if (!cv_adapter::darknet_layout(text, &layout, &why)) return;
  const bool usable = layout.input_width > 0 && layout.input_height > 0 && layout.input_width % 32 == 0 &&
                      layout.input_height % 32 == 0;  // YOLO's strides
  if (!usable) return;
  o->input_width = layout.input_width;
  o->input_height = layout.input_height;
}

class YoloFrameDetector : public FrameDetector {
 public:
  bool open(const cv_adapter::YoloDetectorOptions& options, std::string* reason) {
    const cv_adapter::YoloOpenResult r = detector_.open(options);
    if (!r.ok()) *reason = r.reason;
    return r.ok();
  }
  bool detect(const cv::Mat& frame, std::vector<DetectedBox>* boxes, std::string* reason) override {
    const cv_adapter::YoloDetectorResult& r = detector_.detect(frame);
    boxes->clear();
    if (!r.ok()) {
      *reason = r.reason;
      return false;
    }
    for (const Detection<float>& d : r.detections)
      boxes->push_back(DetectedBox(d.box.x0, d.box.y0, d.box.x1, d.box.y1, d.class_id, d.confidence));
    return true;
  }

 private:
  cv_adapter::YoloDetector detector_;
};

}  // namespace
#endif

namespace {

// A model file the detector may open: a regular, non-empty file (checked by its status, without opening
// it: a FIFO would block the open, a device never ends). The detector checks what the file holds.
bool usable_file(const std::string& path, std::string* reason) {
  std::error_code ec;
  const std::filesystem::file_status st = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(st)) {
    *reason = path + ": no such file";
    return false;
  }
  if (!std::filesystem::is_regular_file(st)) {
    *reason = path + ": not a regular file";
    return false;
  }
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec || size == 0) {
    *reason = path + ": empty file";
    return false;
  }
  return true;
}

}  // namespace

std::unique_ptr<FrameDetector> open_yolo_detector(const std::string& spec, std::string* reason) {
  const std::size_t comma = spec.find(',');
  const std::string model = spec.substr(0, comma);
  const std::string weights = comma == std::string::npos ? std::string() : spec.substr(comma + 1);
  if (model.empty() || (comma != std::string::npos && weights.empty())) {
    *reason = "expected CFG,WEIGHTS (Darknet) or MODEL.onnx";
    return nullptr;
  }
  if (!usable_file(model, reason) || (!weights.empty() && !usable_file(weights, reason))) return nullptr;
#if defined(DYNCULL_HAS_OPENCV_DNN)
  try {
    std::unique_ptr<YoloFrameDetector> d(new YoloFrameDetector);
    cv_adapter::YoloDetectorOptions o;
    o.model = model;
    o.weights = weights;
    use_trained_input_size(&o);
    if (!d->open(o, reason)) return nullptr;
    return std::unique_ptr<FrameDetector>(std::move(d));
  } catch (const std::exception& e) {
    *reason = model + ": " + e.what();
    return nullptr;
  }
#else
  *reason = "dyncull was built without OpenCV's dnn module: no live detector";
  return nullptr;
#endif
}

}  // namespace host
}  // namespace dyncull
