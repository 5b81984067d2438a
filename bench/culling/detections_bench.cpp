// Per-frame detection ingest before any culling: YOLO text parsing (with file:line errors) against a
// plain std::istringstream parse, YOLO box conversion with padding / class thresholds / clipping
// (RTD-SLAM eq. 1-2, Zhang et al. 2023 eq. 1), motion-level lookup (COCO-80 table), and the box tracker that carries boxes
// over missed detections (Dynamic-VINS). 20 detections per frame, 640x480. There is no library peer;
// the point is the scale: all of it together should stay far below one LK call (~10 ms).
#include "dyncull/culling/box_tracker.hpp"
#include "dyncull/culling/detections.hpp"
#include "dyncull/culling/labels.hpp"
#include "dyncull/culling/motion_levels.hpp"

#include <benchmark/benchmark.h>

#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

namespace {
using namespace dyncull;

constexpr int kW = 640, kH = 480, kBoxes = 20;

std::string yolo_text() {
  std::string text = "# class cx cy w h conf\n";
  char line[128];
  for (int i = 0; i < kBoxes; ++i) {
    std::snprintf(line, sizeof line, "%d %.6f %.6f %.6f %.6f %.4f\n", (i * 7) % 80, 0.05 + 0.045 * i, 0.5 - 0.01 * i,
                  0.08 + 0.01 * (i % 5), 0.2 + 0.02 * (i % 7), 0.3 + 0.03 * (i % 20));
    text += line;
  }
  return text;
}

void BM_ParseYolo_Dyncull(benchmark::State& state) {
  const std::string text = yolo_text();
  std::size_t boxes = 0;
  for (auto _ : state) {
    const auto r = parse_yolo_lines<float>(text);
    boxes = r.boxes.size();
    benchmark::DoNotOptimize(r.boxes.data());
  }
  state.counters["boxes"] = double(boxes);
}
BENCHMARK(BM_ParseYolo_Dyncull)->Unit(benchmark::kMicrosecond);

// Reference: what most forks do (istringstream >> per field, no line numbers, no error report).
void BM_ParseYolo_Istringstream(benchmark::State& state) {
  const std::string text = yolo_text();
  std::size_t boxes = 0;
  for (auto _ : state) {
    std::istringstream in(text);
    std::string line;
    std::vector<YoloBox<float>> out;
    while (std::getline(in, line)) {
      if (line.empty() || line[0] == '#') continue;
      std::istringstream fields(line);
      YoloBox<float> b;
      if (fields >> b.class_id >> b.cx >> b.cy >> b.w >> b.h >> b.confidence) out.push_back(b);
    }
    boxes = out.size();
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["boxes"] = double(boxes);
}
BENCHMARK(BM_ParseYolo_Istringstream)->Unit(benchmark::kMicrosecond);

void BM_ConvertYolo_AndLevels(benchmark::State& state) {
  const auto parsed = parse_yolo_lines<float>(yolo_text());
  const MotionLevelTable levels = MotionLevelTable::coco80();
  DetectionOptions<float> options;
  std::size_t kept = 0, high = 0;
  for (auto _ : state) {
    const auto r = convert_yolo_detections(parsed.boxes, kW, kH, options);
    high = 0;
    for (const Detection<float>& d : r.detections) high += levels.level(d.class_id) == MotionLevel::High;
    kept = r.detections.size();
    benchmark::DoNotOptimize(r.detections.data());
  }
  state.counters["kept"] = double(kept);
  state.counters["high_level"] = double(high);
}
BENCHMARK(BM_ConvertYolo_AndLevels)->Unit(benchmark::kMicrosecond);

// Five people walking sideways for 100 frames; every 4th frame the detector misses two of them.
void BM_BoxTracker_Update(benchmark::State& state) {
  BoxTracker<float> tracker;
  std::vector<Detection<float>> frame;
  int t = 0;
  std::size_t carried = 0, frames = 0;
  for (auto _ : state) {
    frame.clear();
    for (int p = 0; p < 5; ++p) {
      if (t % 4 == 3 && p < 2) continue;
      const float x = 40.f + 110.f * p + 2.f * static_cast<float>(t % 100);
      frame.push_back(Detection<float>{Box<float>{x, 100.f, x + 80.f, 400.f}, 0, 0.8f});
    }
    const auto r = tracker.update(frame, kW, kH);
    carried += r.num_carried;
    ++frames;
    benchmark::DoNotOptimize(r.boxes.data());
    ++t;
  }
  state.counters["carried_per_frame"] = frames ? double(carried) / double(frames) : 0.0;  // 0.5 when every miss is bridged
}
BENCHMARK(BM_BoxTracker_Update)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
