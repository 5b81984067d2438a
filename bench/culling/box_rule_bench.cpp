// Box rule at 1000 keypoints x 5 (and 10) boxes: our SoA kernel vs a cv::Rect2f::contains loop.
#include "dyncull/culling/box_rule.hpp"
#include "dyncull/core/random.hpp"

#include <benchmark/benchmark.h>

#include <vector>

#ifdef DYNCULL_HAS_OPENCV
#include <opencv2/core.hpp>
#endif

namespace {
using namespace dyncull;

struct Data {
  std::vector<Vec2<float>> pts;
  std::vector<Detection<float>> dets;
};

// Boxes: half person (high), the rest chair / tv, like a busy office frame.
Data make(int n_points, int n_boxes) {
  Random rng(1);
  Data d;
  for (int i = 0; i < n_points; ++i) d.pts.emplace_back(float(rng.uniform(0, 640)), float(rng.uniform(0, 480)));
  const int classes[] = {0, 56, 62, 0, 0, 73, 0, 56, 62, 0};
  for (int b = 0; b < n_boxes; ++b) {
    const float x = float(rng.uniform(0, 500)), y = float(rng.uniform(0, 300));
    d.dets.push_back({Box<float>{x, y, x + float(rng.uniform(40, 200)), y + float(rng.uniform(60, 250))}, classes[b % 10], 1.f});
  }
  return d;
}

void BM_BoxRule_Dyncull(benchmark::State& state) {
  const Data d = make(1000, int(state.range(0)));
  const MotionLevelTable table = MotionLevelTable::coco80();
  std::size_t dyn = 0;
  for (auto _ : state) {
    const auto r = apply_box_rule(d.pts, d.dets, table, BoxRuleOptions<float>{});
    dyn = r.num_dynamic;
    benchmark::DoNotOptimize(r.labels.data());
  }
  state.counters["dynamic"] = double(dyn);
}
BENCHMARK(BM_BoxRule_Dyncull)->Arg(5)->Arg(10)->Unit(benchmark::kMicrosecond);

// The same three-valued rule written as public code does it: per point, per box, Box::contains.
void BM_BoxRule_ScalarLoop(benchmark::State& state) {
  const Data d = make(1000, int(state.range(0)));
  const MotionLevelTable table = MotionLevelTable::coco80();
  std::vector<FeatureLabel> labels(d.pts.size());
  std::size_t dyn = 0;
  for (auto _ : state) {
    dyn = 0;
    for (std::size_t i = 0; i < d.pts.size(); ++i) {
      bool high = false, medium = false, low = false;
      for (const auto& b : d.dets) {
        if (!b.box.contains(d.pts[i].x(), d.pts[i].y())) continue;
        const MotionLevel l = table.level(b.class_id);
        high |= l == MotionLevel::High;
        medium |= l == MotionLevel::Medium;
        low |= l == MotionLevel::Low;
      }
      labels[i] = low ? FeatureLabel::Static
                      : (high ? FeatureLabel::Dynamic : (medium ? FeatureLabel::Candidate : FeatureLabel::Static));
      dyn += labels[i] == FeatureLabel::Dynamic;
    }
    benchmark::DoNotOptimize(labels.data());
  }
  state.counters["dynamic"] = double(dyn);
}
BENCHMARK(BM_BoxRule_ScalarLoop)->Arg(5)->Arg(10)->Unit(benchmark::kMicrosecond);

#ifdef DYNCULL_HAS_OPENCV
// Peer: cv::Rect2f::contains over cv::Point2f (dynamic = in a high box and in no low box).
void BM_BoxRule_OpenCVRectContains(benchmark::State& state) {
  const Data d = make(1000, int(state.range(0)));
  const MotionLevelTable table = MotionLevelTable::coco80();
  std::vector<cv::Point2f> pts;
  for (const auto& p : d.pts) pts.emplace_back(p.x(), p.y());
  std::vector<cv::Rect2f> high, low;
  for (const auto& b : d.dets) {
    // cv::Rect2f is half-open on the right; +eps makes it inclusive like ours for the count check.
    const cv::Rect2f r(b.box.x0, b.box.y0, b.box.width() + 1e-3f, b.box.height() + 1e-3f);
    if (table.level(b.class_id) == MotionLevel::High) high.push_back(r);
    if (table.level(b.class_id) == MotionLevel::Low) low.push_back(r);
  }
  std::vector<std::uint8_t> dynamic(pts.size());
  std::size_t dyn = 0;
  for (auto _ : state) {
    dyn = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      bool h = false, l = false;
      for (const auto& r : high) h = h || r.contains(pts[i]);
      for (const auto& r : low) l = l || r.contains(pts[i]);
      dynamic[i] = h && !l;
      dyn += dynamic[i];
    }
    benchmark::DoNotOptimize(dynamic.data());
  }
  state.counters["dynamic"] = double(dyn);
}
BENCHMARK(BM_BoxRule_OpenCVRectContains)->Arg(5)->Arg(10)->Unit(benchmark::kMicrosecond);
#endif
}  // namespace
