// Epipolar distances for 1000 correspondences: ours (batch eq. 3 of DFD-SLAM, Qian et al. 2024; Sampson;
// thresholded labels; float and double) vs cv::computeCorrespondEpilines plus the point-line distance loop.
#include "dyncull/geometry/epipolar.hpp"

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

struct Data {
  dyncull::test::TwoViewData<double> truth;
  std::vector<Eigen::Vector2f> p1f, p2f;
#ifdef DYNCULL_HAS_OPENCV
  std::vector<cv::Point2f> cv1, cv2;
  std::vector<cv::Point2d> cv1d, cv2d;
#endif
};

const Data& data(int n) {
  static Data d;
  static int built = -1;
  if (built != n) {
    dyncull::test::TwoViewOptions o;
    o.num_points = n;
    d = Data{};
    d.truth = dyncull::test::make_two_view<double>(o);
    for (std::size_t i = 0; i < d.truth.points1.size(); ++i) {
      d.p1f.push_back(d.truth.points1[i].cast<float>());
      d.p2f.push_back(d.truth.points2[i].cast<float>());
#ifdef DYNCULL_HAS_OPENCV
      d.cv1.emplace_back(float(d.truth.points1[i].x()), float(d.truth.points1[i].y()));
      d.cv2.emplace_back(float(d.truth.points2[i].x()), float(d.truth.points2[i].y()));
      d.cv1d.emplace_back(d.truth.points1[i].x(), d.truth.points1[i].y());
      d.cv2d.emplace_back(d.truth.points2[i].x(), d.truth.points2[i].y());
#endif
    }
    built = n;
  }
  return d;
}

/// Counter: fraction of true outliers with distance above 1 px, or label above 0 (sanity of the output).
template <class V>
void flagged(benchmark::State& state, const Data& d, const V& dist, double above = 1.0) {
  std::size_t hit = 0, outliers = 0;
  for (std::size_t i = 0; i < d.truth.is_inlier.size(); ++i) {
    if (d.truth.is_inlier[i]) continue;
    ++outliers;
    hit += double(dist[i]) > above;
  }
  state.counters["outliers_flagged"] = outliers ? double(hit) / double(outliers) : 1.0;
}

template <class T>
void BM_Ours_PointToLine(benchmark::State& state) {
  const Data& d = data(int(state.range(0)));
  const Mat3<T> F = d.truth.F.cast<T>();
  std::vector<T> out(d.p1f.size());
  for (auto _ : state) {
    if constexpr (std::is_same<T, float>::value)
      dyncull::epipolar_distances(F, d.p1f, d.p2f, out.data());
    else
      dyncull::epipolar_distances(F, d.truth.points1, d.truth.points2, out.data());
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  flagged(state, d, out);
}
BENCHMARK_TEMPLATE(BM_Ours_PointToLine, float)->Arg(1000)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(BM_Ours_PointToLine, double)->Arg(1000)->Unit(benchmark::kMicrosecond);

template <class T>
void BM_Ours_Sampson(benchmark::State& state) {
  const Data& d = data(int(state.range(0)));
  const Mat3<T> F = d.truth.F.cast<T>();
  std::vector<T> out(d.p1f.size());
  for (auto _ : state) {
    if constexpr (std::is_same<T, float>::value)
      dyncull::epipolar_distances(F, d.p1f, d.p2f, out.data(), dyncull::EpipolarDistance::SampsonSq);
    else
      dyncull::epipolar_distances(F, d.truth.points1, d.truth.points2, out.data(),
                                  dyncull::EpipolarDistance::SampsonSq);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK_TEMPLATE(BM_Ours_Sampson, float)->Arg(1000)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(BM_Ours_Sampson, double)->Arg(1000)->Unit(benchmark::kMicrosecond);

template <class T>
void BM_Ours_Label(benchmark::State& state) {
  const Data& d = data(int(state.range(0)));
  const Mat3<T> F = d.truth.F.cast<T>();
  std::vector<std::uint8_t> labels(d.p1f.size());
  std::size_t count = 0;
  for (auto _ : state) {
    if constexpr (std::is_same<T, float>::value)
      dyncull::label_epipolar(F, d.p1f, d.p2f, T(1), labels.data(), &count);
    else
      dyncull::label_epipolar(F, d.truth.points1, d.truth.points2, T(1), labels.data(), &count);
    benchmark::DoNotOptimize(labels.data());
    benchmark::DoNotOptimize(count);
    benchmark::ClobberMemory();
  }
  flagged(state, d, labels, 0.0);
}
BENCHMARK_TEMPLATE(BM_Ours_Label, float)->Arg(1000)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(BM_Ours_Label, double)->Arg(1000)->Unit(benchmark::kMicrosecond);

#ifdef DYNCULL_HAS_OPENCV
/// The same cv::Point2f containers an ORB-SLAM front end holds, float F.
void BM_Ours_PointToLine_CvPoints(benchmark::State& state) {
  const Data& d = data(int(state.range(0)));
  const Mat3<float> F = d.truth.F.cast<float>();
  std::vector<float> out(d.cv1.size());
  for (auto _ : state) {
    dyncull::epipolar_distances(F, d.cv1, d.cv2, out.data());
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  flagged(state, d, out);
}
BENCHMARK(BM_Ours_PointToLine_CvPoints)->Arg(1000)->Unit(benchmark::kMicrosecond);

void BM_OpenCV_Epilines_Loop(benchmark::State& state) {
  const Data& d = data(int(state.range(0)));
  cv::Mat F(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) F.at<double>(r, c) = d.truth.F(r, c);
  std::vector<cv::Vec3f> lines;
  std::vector<float> out(d.cv1.size());
  for (auto _ : state) {
    cv::computeCorrespondEpilines(d.cv1, 1, F, lines);
    for (std::size_t i = 0; i < out.size(); ++i)
      out[i] = std::abs(lines[i][0] * d.cv2[i].x + lines[i][1] * d.cv2[i].y + lines[i][2]);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  flagged(state, d, out);
}
BENCHMARK(BM_OpenCV_Epilines_Loop)->Arg(1000)->Unit(benchmark::kMicrosecond);
/// The same peer on double points (OpenCV then computes the lines in double): the like-for-like
/// reference for our double kernel.
void BM_OpenCV_Epilines_Loop_Double(benchmark::State& state) {
  const Data& d = data(int(state.range(0)));
  cv::Mat F(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) F.at<double>(r, c) = d.truth.F(r, c);
  std::vector<cv::Vec3d> lines;
  std::vector<double> out(d.cv1d.size());
  for (auto _ : state) {
    cv::computeCorrespondEpilines(d.cv1d, 1, F, lines);
    for (std::size_t i = 0; i < out.size(); ++i)
      out[i] = std::abs(lines[i][0] * d.cv2d[i].x + lines[i][1] * d.cv2d[i].y + lines[i][2]);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  flagged(state, d, out);
}
BENCHMARK(BM_OpenCV_Epilines_Loop_Double)->Arg(1000)->Unit(benchmark::kMicrosecond);
#endif

}  // namespace
