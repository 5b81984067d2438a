// F-RANSAC and 8-point benchmarks: ours (float, double) vs cv::findFundamentalMat (FM_RANSAC, USAC_FAST,
// FM_8POINT) on 1000 synthetic correspondences, 0.5 px noise, 30 % outliers; five data sets (Arg = seed).
// Counters: recall / precision of the true inliers and RMS Sampson error (px) of the clean true inliers.
#include "dyncull/geometry/fundamental.hpp"

#include "support/two_view.hpp"

#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#ifdef DYNCULL_HAS_OPENCV
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#endif

namespace {

using dyncull::Mat3;

#ifdef DYNCULL_HAS_OPENCV
// One thread for every peer: OpenCV's parallel_for would otherwise hide wall time
// behind other cores, and the machine is shared.
[[maybe_unused]] const int kSingleThread = [] {
  cv::setNumThreads(1);
  return 1;
}();
#endif
using dyncull::test::TwoViewData;
using dyncull::test::TwoViewOptions;

constexpr int kNumPoints = 1000;

struct Scene {
  TwoViewData<double> truth;
  std::vector<Eigen::Vector2f> p1f, p2f;
  std::vector<Eigen::Vector2d> p1d, p2d;
#ifdef DYNCULL_HAS_OPENCV
  std::vector<cv::Point2f> cv1, cv2;
#endif
};

const Scene& scene(int seed) {
  static std::vector<Scene> cache(16);
  static std::vector<bool> built(16, false);
  if (!built[std::size_t(seed)]) {
    TwoViewOptions o;
    o.num_points = kNumPoints;
    o.seed = std::uint64_t(seed);
    Scene& s = cache[std::size_t(seed)];
    s.truth = dyncull::test::make_two_view<double>(o);
    for (std::size_t i = 0; i < s.truth.points1.size(); ++i) {
      s.p1d.push_back(s.truth.points1[i]);
      s.p2d.push_back(s.truth.points2[i]);
      s.p1f.push_back(s.truth.points1[i].cast<float>());
      s.p2f.push_back(s.truth.points2[i].cast<float>());
#ifdef DYNCULL_HAS_OPENCV
      s.cv1.emplace_back(float(s.truth.points1[i].x()), float(s.truth.points1[i].y()));
      s.cv2.emplace_back(float(s.truth.points2[i].x()), float(s.truth.points2[i].y()));
#endif
    }
    built[std::size_t(seed)] = true;
  }
  return cache[std::size_t(seed)];
}

/// Accuracy counters from a mask (any byte type) and an F in double.
template <class Mask>
void accuracy(benchmark::State& state, const Scene& s, const Mat3<double>& F, const Mask& mask) {
  std::size_t tp = 0, fp = 0;
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < s.truth.is_inlier.size(); ++i) {
    const bool in = mask[i] != 0;
    tp += in && s.truth.is_inlier[i];
    fp += in && !s.truth.is_inlier[i];
    if (s.truth.is_inlier[i]) {
      sum += dyncull::sampson_distance_sq(F, s.truth.clean1[i], s.truth.clean2[i]);
      ++n;
    }
  }
  state.counters["recall"] = double(tp) / double(s.truth.num_inliers);
  state.counters["precision"] = tp + fp ? double(tp) / double(tp + fp) : 0.0;
  state.counters["sampson_rms_px"] = std::sqrt(sum / double(n));
}

template <class T>
void BM_Ours_FRansac(benchmark::State& state) {
  const Scene& s = scene(int(state.range(0)));
  const auto& p1 = [&]() -> const auto& {
    if constexpr (std::is_same<T, float>::value) return s.p1f; else return s.p1d;
  }();
  const auto& p2 = [&]() -> const auto& {
    if constexpr (std::is_same<T, float>::value) return s.p2f; else return s.p2d;
  }();
  dyncull::FundamentalOptions<T> options;
  options.ransac.max_residual = 1.0;
  options.ransac.confidence = 0.99;
  dyncull::FundamentalResult<T> r;
  for (auto _ : state) {
    r = dyncull::estimate_fundamental_ransac(p1, p2, options);
    benchmark::DoNotOptimize(r.F.data());
  }
  if (!r.ok()) state.SkipWithError(r.reason.c_str());
  accuracy(state, s, r.F.template cast<double>(), r.inlier_mask);
  state.counters["iterations"] = double(r.iterations);
}
BENCHMARK_TEMPLATE(BM_Ours_FRansac, float)->DenseRange(1, 5)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(BM_Ours_FRansac, double)->DenseRange(1, 5)->Unit(benchmark::kMicrosecond);

#ifdef DYNCULL_HAS_OPENCV
/// cv::Point2f input, float F: the configuration an ORB-SLAM front end uses.
void BM_Ours_FRansac_CvPoints(benchmark::State& state) {
  const Scene& s = scene(int(state.range(0)));
  dyncull::FundamentalOptions<float> options;
  dyncull::FundamentalResult<float> r;
  for (auto _ : state) {
    r = dyncull::estimate_fundamental_ransac(s.cv1, s.cv2, options);
    benchmark::DoNotOptimize(r.F.data());
  }
  accuracy(state, s, r.F.cast<double>(), r.inlier_mask);
}
BENCHMARK(BM_Ours_FRansac_CvPoints)->DenseRange(1, 5)->Unit(benchmark::kMicrosecond);

void run_cv(benchmark::State& state, int method) {
  const Scene& s = scene(int(state.range(0)));
  cv::Mat F, mask;
  for (auto _ : state) {
    F = cv::findFundamentalMat(s.cv1, s.cv2, method, 1.0, 0.99, 10000, mask);
    benchmark::DoNotOptimize(F.data);
  }
  if (F.rows != 3) {
    state.SkipWithError("findFundamentalMat returned no F");
    return;
  }
  Mat3<double> Fe;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) Fe(r, c) = F.at<double>(r, c);
  accuracy(state, s, Fe, mask.ptr<uchar>());
}
void BM_OpenCV_FM_RANSAC(benchmark::State& state) { run_cv(state, cv::FM_RANSAC); }
void BM_OpenCV_USAC_FAST(benchmark::State& state) { run_cv(state, cv::USAC_FAST); }
void BM_OpenCV_USAC_DEFAULT(benchmark::State& state) { run_cv(state, cv::USAC_DEFAULT); }
BENCHMARK(BM_OpenCV_FM_RANSAC)->DenseRange(1, 5)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_OpenCV_USAC_FAST)->DenseRange(1, 5)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_OpenCV_USAC_DEFAULT)->DenseRange(1, 5)->Unit(benchmark::kMicrosecond);
#endif

/// 8-point on the true inliers (the LO refit's cost).
void BM_Ours_8Point_Inliers(benchmark::State& state) {
  const Scene& s = scene(1);
  std::vector<Eigen::Vector2d> a, b;
  for (std::size_t i = 0; i < s.p1d.size(); ++i)
    if (s.truth.is_inlier[i]) a.push_back(s.p1d[i]), b.push_back(s.p2d[i]);
  for (auto _ : state) {
    auto r = dyncull::fundamental_8point(a, b);
    benchmark::DoNotOptimize(r.F.data());
  }
}
BENCHMARK(BM_Ours_8Point_Inliers)->Unit(benchmark::kMicrosecond);

#ifdef DYNCULL_HAS_OPENCV
void BM_OpenCV_FM_8POINT_Inliers(benchmark::State& state) {
  const Scene& s = scene(1);
  std::vector<cv::Point2f> a, b;
  for (std::size_t i = 0; i < s.cv1.size(); ++i)
    if (s.truth.is_inlier[i]) a.push_back(s.cv1[i]), b.push_back(s.cv2[i]);
  for (auto _ : state) {
    cv::Mat F = cv::findFundamentalMat(a, b, cv::FM_8POINT);
    benchmark::DoNotOptimize(F.data);
  }
}
BENCHMARK(BM_OpenCV_FM_8POINT_Inliers)->Unit(benchmark::kMicrosecond);
#endif

}  // namespace
