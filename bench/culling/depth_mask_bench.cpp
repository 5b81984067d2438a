// Depth mask over a 200x300 box of a 640x480 uint16 depth image: one memory pass is the target.
// Floor: memcpy of the box rows; peer: cv::inRange on the ROI (what an OpenCV port would write).
// MissingDepth::Nearest (the default) adds two exact distance transforms over the box; its peer is the
// same rule with cv::distanceTransform (DIST_L2, DIST_MASK_PRECISE) twice.
#include "dyncull/culling/depth_mask.hpp"
#include "dyncull/core/random.hpp"

#include <benchmark/benchmark.h>

#include <cstring>
#include <vector>

#ifdef DYNCULL_HAS_OPENCV
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#endif

namespace {
using namespace dyncull;

constexpr int W = 640, H = 480;
const Box<float> kBox{200, 100, 499, 299};  // 300 wide x 200 high

// Wall at ~3 m, a person at ~1.5 m in the box centre, 3 % Kinect holes.
std::vector<std::uint16_t> make_depth(bool corners_valid) {
  Random rng(2);
  std::vector<std::uint16_t> d(W * H);
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const bool person = u > 280 && u < 420 && v > 120;
      double m = person ? 1.5 + 0.1 * rng.uniform() : 3.0 + 0.3 * rng.uniform();
      if (rng.uniform() < 0.03) m = 0;
      d[std::size_t(v * W + u)] = std::uint16_t(m * 5000);
    }
  if (!corners_valid) {  // the rule cannot apply: histogram fallback
    for (int v = 100; v < 300; ++v)
      for (int u = 200; u < 500; ++u)
        if (d[std::size_t(v * W + u)] > 10000) d[std::size_t(v * W + u)] = 0;
  }
  return d;
}

void run(benchmark::State& state, DepthMaskMode mode, bool corners_valid,
         MissingDepth missing = MissingDepth::Nearest) {
  const std::vector<std::uint16_t> depth = make_depth(corners_valid);
  Mask mask(W, H);
  DepthMaskOptions o;
  o.mode = mode;
  o.missing_depth = missing;
  std::size_t pixels = 0;
  for (auto _ : state) {
    const DepthMaskBoxInfo info = depth_mask_box(tum_depth_view(depth.data(), W, H), kBox, o, mask.view());
    pixels = info.num_mask_pixels;
    benchmark::DoNotOptimize(mask.pixels.data());
  }
  state.counters["mask_px"] = double(pixels);
  state.SetBytesProcessed(std::int64_t(state.iterations()) * 300 * 200 * 2);
}
void BM_DepthMask_Plain(benchmark::State& s) { run(s, DepthMaskMode::Plain, true); }
void BM_DepthMask_Robust(benchmark::State& s) { run(s, DepthMaskMode::Robust, true); }
void BM_DepthMask_RobustMissingInMask(benchmark::State& s) {
  run(s, DepthMaskMode::Robust, true, MissingDepth::InMask);
}
void BM_DepthMask_RobustHistogramFallback(benchmark::State& s) { run(s, DepthMaskMode::Robust, false); }
BENCHMARK(BM_DepthMask_Plain)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_DepthMask_Robust)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_DepthMask_RobustMissingInMask)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_DepthMask_RobustHistogramFallback)->Unit(benchmark::kMicrosecond);

void BM_DepthMask_MemcpyFloor(benchmark::State& state) {
  const std::vector<std::uint16_t> depth = make_depth(true);
  std::vector<std::uint16_t> out(W * H);
  for (auto _ : state) {
    for (int v = 100; v < 300; ++v)
      std::memcpy(out.data() + v * W + 200, depth.data() + v * W + 200, 300 * sizeof(std::uint16_t));
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(std::int64_t(state.iterations()) * 300 * 200 * 2);
}
BENCHMARK(BM_DepthMask_MemcpyFloor)->Unit(benchmark::kMicrosecond);

#ifdef DYNCULL_HAS_OPENCV
void BM_DepthMask_OpenCVInRange(benchmark::State& state) {
  std::vector<std::uint16_t> depth = make_depth(true);
  const cv::Mat d(H, W, CV_16UC1, depth.data());
  cv::Mat mask(H, W, CV_8UC1, cv::Scalar(0));
  const cv::Rect roi(200, 100, 300, 200);
  // The same band as the plain rule computes here (1 <= d < d_c + eps), thresholds set outside the loop.
  DepthMaskOptions o;
  o.mode = DepthMaskMode::Plain;
  const DepthMaskBoxInfo info = depth_mask_box(tum_depth_view(depth.data(), W, H), kBox, o);
  const double hi = info.threshold_raw - 1;
  int pixels = 0;
  for (auto _ : state) {
    cv::Mat out = mask(roi);
    cv::inRange(d(roi), cv::Scalar(1), cv::Scalar(hi), out);
    benchmark::DoNotOptimize(out.data);
    pixels = cv::countNonZero(out);
  }
  state.counters["mask_px"] = pixels;
  state.SetBytesProcessed(std::int64_t(state.iterations()) * 300 * 200 * 2);
}
BENCHMARK(BM_DepthMask_OpenCVInRange)->Unit(benchmark::kMicrosecond);

// The Nearest rule written with OpenCV: the band with inRange, then the distance to the nearest in-band
// and to the nearest measured out-of-band pixel (exact L2 transforms), and the comparison.
void BM_DepthMask_OpenCVNearestFill(benchmark::State& state) {
  std::vector<std::uint16_t> depth = make_depth(true);
  const cv::Mat d(H, W, CV_16UC1, depth.data());
  const cv::Rect roi(200, 100, 300, 200);
  DepthMaskOptions o;
  const DepthMaskBoxInfo info = depth_mask_box(tum_depth_view(depth.data(), W, H), kBox, o);
  const double hi = info.threshold_raw - 1;
  cv::Mat in_band, out_band, missing, dist_in, dist_out, mask;
  int pixels = 0;
  for (auto _ : state) {
    const cv::Mat box = d(roi);
    cv::inRange(box, cv::Scalar(1), cv::Scalar(hi), in_band);
    cv::compare(box, cv::Scalar(hi), out_band, cv::CMP_GT);
    cv::compare(box, cv::Scalar(0), missing, cv::CMP_EQ);
    cv::distanceTransform(~in_band, dist_in, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    cv::distanceTransform(~out_band, dist_out, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    cv::compare(dist_in, dist_out, mask, cv::CMP_LE);
    mask = in_band | (mask & missing);
    benchmark::DoNotOptimize(mask.data);
    pixels = cv::countNonZero(mask);
  }
  state.counters["mask_px"] = pixels;
  state.SetBytesProcessed(std::int64_t(state.iterations()) * 300 * 200 * 2);
}
BENCHMARK(BM_DepthMask_OpenCVNearestFill)->Unit(benchmark::kMicrosecond);
#endif
}  // namespace
