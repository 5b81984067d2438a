// Applying a keep-mask to 1000 ORB features (keypoint, 32-byte descriptor row, depth), the region
// predicate at 1000 points x 5 boxes, and a 640x480 raster, each beside the OpenCV way.
#include "dyncull/culling/keep_mask.hpp"
#include "dyncull/core/random.hpp"

#include <benchmark/benchmark.h>

#include <vector>

#ifdef DYNCULL_HAS_OPENCV
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#endif

namespace {
using namespace dyncull;

struct Key {
  float x, y, size, angle, response;
  int octave, class_id;
};

std::vector<std::uint8_t> make_keep(std::size_t n) {
  Random rng(9);
  std::vector<std::uint8_t> keep(n);
  for (auto& k : keep) k = rng.uniform() > 0.3;  // 30 % culled
  return keep;
}

std::vector<Box<float>> make_boxes() {
  return {{50, 50, 150, 400}, {200, 100, 260, 300}, {300, 200, 420, 470}, {450, 20, 600, 120}, {500, 300, 630, 470}};
}

void BM_Keep_Compact(benchmark::State& state) {
  const std::vector<std::uint8_t> keep = make_keep(1000);
  std::vector<Key> keys0(1000);
  std::vector<float> depth0(1000, 1.f);
  std::vector<std::uint8_t> desc0(1000 * 32, 7);
  std::size_t count = 0;
  for (auto _ : state) {
    state.PauseTiming();
    std::vector<Key> keys = keys0;
    std::vector<float> depth = depth0;
    std::vector<std::uint8_t> desc = desc0;
    state.ResumeTiming();
    count = static_cast<std::size_t>(compact(keep, keys, RowsView(desc.data(), 32, 32, 1000), depth));
    benchmark::DoNotOptimize(keys.data());
    benchmark::DoNotOptimize(desc.data());
  }
  state.counters["kept"] = double(count);
}
BENCHMARK(BM_Keep_Compact)->Unit(benchmark::kMicrosecond);

#ifdef DYNCULL_HAS_OPENCV
// What ORB-SLAM forks do: new vectors with push_back and a new descriptor Mat row by row.
void BM_Keep_OpenCVRebuild(benchmark::State& state) {
  const std::vector<std::uint8_t> keep = make_keep(1000);
  const std::vector<cv::KeyPoint> keys(1000);
  const std::vector<float> depth(1000, 1.f);
  const cv::Mat desc(1000, 32, CV_8UC1, cv::Scalar(7));
  std::size_t count = 0;
  for (auto _ : state) {
    std::vector<cv::KeyPoint> k2;
    std::vector<float> d2;
    cv::Mat desc2;
    for (std::size_t i = 0; i < keep.size(); ++i) {
      if (!keep[i]) continue;
      k2.push_back(keys[i]);
      d2.push_back(depth[i]);
      desc2.push_back(desc.row(int(i)));
    }
    count = k2.size();
    benchmark::DoNotOptimize(desc2.data);
    benchmark::DoNotOptimize(k2.data());
  }
  state.counters["kept"] = double(count);
}
BENCHMARK(BM_Keep_OpenCVRebuild)->Unit(benchmark::kMicrosecond);
#endif

void BM_Keep_RegionPredicatePerLevel(benchmark::State& state) {
  Random rng(3);
  std::vector<Vec2<float>> pts(1000);
  std::vector<int> level(1000);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    level[i] = int(rng.index(8));
    const float s = std::pow(1.2f, float(level[i]));
    pts[i] = Vec2<float>(float(rng.uniform(0, 640)) / s, float(rng.uniform(0, 480)) / s);
  }
  const DynamicRegionPredicate<float> inside(make_boxes(), ConstMaskView{}, 1.2f, 8);
  std::size_t n_in = 0;
  for (auto _ : state) {
    n_in = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) n_in += inside(pts[i].x(), pts[i].y(), level[i]);
    benchmark::DoNotOptimize(n_in);
  }
  state.counters["inside"] = double(n_in);
}
BENCHMARK(BM_Keep_RegionPredicatePerLevel)->Unit(benchmark::kMicrosecond);

void BM_Keep_Rasterise(benchmark::State& state) {
  Mask out(640, 480);
  const std::vector<Box<float>> boxes = make_boxes();
  for (auto _ : state) {
    rasterise_dynamic_regions(boxes, ConstMaskView{}, out.view(), MaskConvention::StaticIs255);
    benchmark::DoNotOptimize(out.pixels.data());
  }
  state.counters["static_px"] = double(out.count());
}
BENCHMARK(BM_Keep_Rasterise)->Unit(benchmark::kMicrosecond);

#ifdef DYNCULL_HAS_OPENCV
void BM_Keep_OpenCVRectangles(benchmark::State& state) {
  cv::Mat out(480, 640, CV_8UC1);
  const std::vector<Box<float>> boxes = make_boxes();
  for (auto _ : state) {
    out.setTo(255);
    for (const auto& b : boxes)
      cv::rectangle(out, cv::Point(int(std::ceil(b.x0)), int(std::ceil(b.y0))),
                    cv::Point(int(std::floor(b.x1)), int(std::floor(b.y1))), cv::Scalar(0), cv::FILLED);
    benchmark::DoNotOptimize(out.data);
  }
  state.counters["static_px"] = double(cv::countNonZero(out));
}
BENCHMARK(BM_Keep_OpenCVRectangles)->Unit(benchmark::kMicrosecond);
#endif
}  // namespace
