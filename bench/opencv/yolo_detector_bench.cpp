// One detection of the YOLO detector (opencv/yolo_detector.hpp) on a real 640x480 RGB frame of the Bonn
// crowd sequence: Yolo-Fastest-1.1-XL at 416 x 416 on OpenCV DNN (CPU), preprocessing, network and
// decoding with per-class NMS. Reads DYNCULL_DATA_DIR and skips with the reason when the frame or the
// model is absent. Counter `boxes` = detections per frame.
#include "dyncull/opencv/yolo_detector.hpp"

#include <benchmark/benchmark.h>

#include <opencv2/imgcodecs.hpp>

#include <cstdlib>
#include <string>

namespace {

using dyncull::cv_adapter::YoloDetector;
using dyncull::cv_adapter::YoloDetectorOptions;

void BM_YoloFastestDetect416(benchmark::State& state) {
  const char* root = std::getenv("DYNCULL_DATA_DIR");
  if (root == nullptr || *root == '\0') {
    state.SkipWithError("DYNCULL_DATA_DIR is not set: the real-frame detector bench was skipped");
    return;
  }
  const std::string data(root);
  const std::string image = data + "/bonn/crowd_part1/rgb_samples/1548339831.60618.png";
  const cv::Mat frame = cv::imread(image, cv::IMREAD_COLOR);
  if (frame.empty()) {
    state.SkipWithError((image + " is missing: the real-frame detector bench was skipped").c_str());
    return;
  }
  YoloDetectorOptions o;
  o.model = data + "/models/yolo-fastest-1.1-xl/yolo-fastest-1.1-xl.cfg";
  o.weights = data + "/models/yolo-fastest-1.1-xl/yolo-fastest-1.1-xl.weights";
  o.input_width = o.input_height = 416;
  YoloDetector detector;
  const auto opened = detector.open(o);
  if (!opened.ok()) {
    state.SkipWithError(opened.reason.c_str());
    return;
  }
  std::size_t boxes = 0;
  for (auto _ : state) {
    const auto& r = detector.detect(frame);
    boxes = r.detections.size();
    benchmark::DoNotOptimize(r.detections.data());
  }
  state.counters["boxes"] = static_cast<double>(boxes);
}
BENCHMARK(BM_YoloFastestDetect416)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
