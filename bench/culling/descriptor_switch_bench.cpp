// Descriptor matching for the DFD-SLAM (Qian et al. 2024) §3.3 switch: our brute-force Hamming (256-bit ORB) and L2
// (256-float learned) matchers against cv::BFMatcher, and the eq. 18 keyframe search (4096 floats)
// against a cv::norm loop. Counter `agree` = fraction of queries whose match equals OpenCV's.
#include "dyncull/culling/descriptor_switch.hpp"

#include "dyncull/core/random.hpp"

#include <benchmark/benchmark.h>

#ifdef DYNCULL_HAS_OPENCV
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#endif

#include <algorithm>
#include <vector>

namespace {

std::vector<std::uint8_t> random_bytes(std::size_t n, std::uint64_t seed) {
  dyncull::Random rng(seed);
  std::vector<std::uint8_t> v(n);
  for (auto& b : v) b = static_cast<std::uint8_t>(rng.next() >> 56);
  return v;
}

std::vector<float> random_floats(std::size_t n, std::uint64_t seed) {
  dyncull::Random rng(seed);
  std::vector<float> v(n);
  for (auto& x : v) x = static_cast<float>(rng.normal());
  return v;
}

/// n x n binary descriptors; train row i is query row i with 8 bits flipped (a planted match each).
struct BinaryData {
  std::vector<std::uint8_t> q, t;
  explicit BinaryData(std::size_t n) : q(random_bytes(32 * n, 1)), t(q) {
    dyncull::Random rng(3);
    for (std::size_t i = 0; i < n; ++i)
      for (int f = 0; f < 8; ++f) t[32 * i + rng.index(32)] ^= static_cast<std::uint8_t>(1u << rng.index(8));
  }
};

struct FloatData {
  std::vector<float> q, t;
  FloatData(std::size_t n, int dim) : q(random_floats(n * dim, 4)), t(q) {
    dyncull::Random rng(5);
    for (auto& x : t) x += 0.1f * static_cast<float>(rng.normal());
  }
};

void BM_Hamming256Single(benchmark::State& state) {
  const auto a = random_bytes(32 * 1024, 7), b = random_bytes(32 * 1024, 8);
  int sum = 0;
  for (auto _ : state) {
    for (std::size_t i = 0; i < 1024; ++i) sum += dyncull::hamming256(&a[32 * i], &b[32 * i]);
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * 1024);
}
BENCHMARK(BM_Hamming256Single);

void BM_MatchHamming(benchmark::State& state) {
  const std::size_t n = static_cast<std::size_t>(state.range(0));
  const BinaryData d(n);
  dyncull::MatchOptions o;
  o.cross_check = state.range(1) != 0;
  dyncull::MatchResult r;
  for (auto _ : state) {
    r = dyncull::match_hamming256({d.q.data(), n, 32}, {d.t.data(), n, 32}, o);
    benchmark::DoNotOptimize(r.matches.data());
  }
  std::size_t correct = 0;
  for (const auto& m : r.matches) correct += m.query == m.train;
  state.counters["recall"] = double(correct) / double(n);
#ifdef DYNCULL_HAS_OPENCV
  std::vector<cv::DMatch> cvm;
  cv::BFMatcher(cv::NORM_HAMMING, o.cross_check)
      .match(cv::Mat(int(n), 32, CV_8UC1, const_cast<std::uint8_t*>(d.q.data())),
             cv::Mat(int(n), 32, CV_8UC1, const_cast<std::uint8_t*>(d.t.data())), cvm);
  std::size_t agree = 0;
  for (std::size_t k = 0; k < std::min(cvm.size(), r.matches.size()); ++k)
    agree += int(r.matches[k].train) == cvm[k].trainIdx && int(r.matches[k].query) == cvm[k].queryIdx;
  state.counters["agree"] = double(agree) / double(std::max<std::size_t>(1, cvm.size()));
#endif
}
BENCHMARK(BM_MatchHamming)->Args({1000, 0})->Args({1000, 1})->Args({300, 0});

void BM_MatchL2(benchmark::State& state) {
  const std::size_t n = static_cast<std::size_t>(state.range(0));
  const int dim = static_cast<int>(state.range(1));
  const FloatData d(n, dim);
  dyncull::MatchResult r;
  for (auto _ : state) {
    r = dyncull::match_l2<float>({d.q.data(), n, dim, 0}, {d.t.data(), n, dim, 0});
    benchmark::DoNotOptimize(r.matches.data());
  }
  std::size_t correct = 0;
  for (const auto& m : r.matches) correct += m.query == m.train;
  state.counters["recall"] = double(correct) / double(n);
#ifdef DYNCULL_HAS_OPENCV
  std::vector<cv::DMatch> cvm;
  cv::BFMatcher(cv::NORM_L2).match(cv::Mat(int(n), dim, CV_32FC1, const_cast<float*>(d.q.data())),
                                   cv::Mat(int(n), dim, CV_32FC1, const_cast<float*>(d.t.data())), cvm);
  std::size_t agree = 0;
  for (std::size_t k = 0; k < std::min(cvm.size(), r.matches.size()); ++k) agree += int(r.matches[k].train) == cvm[k].trainIdx;
  state.counters["agree"] = double(agree) / double(std::max<std::size_t>(1, cvm.size()));
#endif
}
BENCHMARK(BM_MatchL2)->Args({1000, 256})->Args({300, 256});

void BM_NearestKeyframes(benchmark::State& state) {
  const std::size_t n = static_cast<std::size_t>(state.range(0));
  const int dim = 4096;
  const auto lib = random_floats(n * dim, 9);
  std::vector<float> query(lib.begin() + 7 * dim, lib.begin() + 8 * dim);
  for (auto& x : query) x += 0.01f;
  dyncull::KeyframeSearchResult r;
  for (auto _ : state) {
    r = dyncull::nearest_keyframes(query.data(), dyncull::FloatDescriptors<float>{lib.data(), n, dim, 0}, 5);
    benchmark::DoNotOptimize(r.candidates.data());
  }
  state.counters["top1_correct"] = r.ok() && r.candidates[0].index == 7 ? 1 : 0;
}
BENCHMARK(BM_NearestKeyframes)->Arg(200)->Arg(1000);

#ifdef DYNCULL_HAS_OPENCV
void BM_OpenCvBfMatcherHamming(benchmark::State& state) {
  cv::setNumThreads(1);  // one thread like ours (Google Benchmark's CPU time misses worker threads)
  const std::size_t n = static_cast<std::size_t>(state.range(0));
  const BinaryData d(n);
  const cv::Mat Q(int(n), 32, CV_8UC1, const_cast<std::uint8_t*>(d.q.data()));
  const cv::Mat T(int(n), 32, CV_8UC1, const_cast<std::uint8_t*>(d.t.data()));
  cv::BFMatcher matcher(cv::NORM_HAMMING, state.range(1) != 0);
  std::vector<cv::DMatch> m;
  for (auto _ : state) {
    matcher.match(Q, T, m);
    benchmark::DoNotOptimize(m.data());
  }
}
BENCHMARK(BM_OpenCvBfMatcherHamming)->Args({1000, 0})->Args({1000, 1})->Args({300, 0});

void BM_OpenCvBfMatcherL2(benchmark::State& state) {
  cv::setNumThreads(1);
  const std::size_t n = static_cast<std::size_t>(state.range(0));
  const int dim = static_cast<int>(state.range(1));
  const FloatData d(n, dim);
  const cv::Mat Q(int(n), dim, CV_32FC1, const_cast<float*>(d.q.data()));
  const cv::Mat T(int(n), dim, CV_32FC1, const_cast<float*>(d.t.data()));
  cv::BFMatcher matcher(cv::NORM_L2);
  std::vector<cv::DMatch> m;
  for (auto _ : state) {
    matcher.match(Q, T, m);
    benchmark::DoNotOptimize(m.data());
  }
}
BENCHMARK(BM_OpenCvBfMatcherL2)->Args({1000, 256})->Args({300, 256});

void BM_OpenCvNormKeyframes(benchmark::State& state) {
  cv::setNumThreads(1);
  const std::size_t n = static_cast<std::size_t>(state.range(0));
  const int dim = 4096;
  const auto lib = random_floats(n * dim, 9);
  std::vector<float> query(lib.begin() + 7 * dim, lib.begin() + 8 * dim);
  for (auto& x : query) x += 0.01f;
  const cv::Mat L(int(n), dim, CV_32FC1, const_cast<float*>(lib.data()));
  const cv::Mat q(1, dim, CV_32FC1, query.data());
  std::vector<std::pair<double, int>> dist(n);
  for (auto _ : state) {
    for (int i = 0; i < int(n); ++i) dist[std::size_t(i)] = {cv::norm(q, L.row(i), cv::NORM_L2), i};
    std::partial_sort(dist.begin(), dist.begin() + 5, dist.end());
    benchmark::DoNotOptimize(dist.data());
  }
  state.counters["top1_correct"] = dist[0].second == 7 ? 1 : 0;
}
BENCHMARK(BM_OpenCvNormKeyframes)->Arg(200)->Arg(1000);
#endif

}  // namespace
