// Association + ATE (and RPE) on a 2000-pose estimate against a 100 Hz ground truth, as a SLAM user
// runs after each sequence. Reference point in the same binary: associate.py's O(n m) candidate
// enumeration ported literally to C++ (the TUM script itself is Python).
#include "dyncull/eval/ate.hpp"
#include "dyncull/eval/rpe.hpp"
#include "dyncull/eval/trajectory.hpp"

#include "eval/synthetic_trajectory.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <tuple>
#include <vector>

namespace {

using namespace dyncull;
using namespace dyncull::eval;

struct Data {
  Trajectory<double> gt;
  Trajectory<double> est;
};

// n estimate poses at 30 Hz with 3 mm / 0.2 deg noise and stamp jitter; ground truth at 100 Hz.
const Data& data(int n) {
  static std::vector<std::pair<int, Data>> cache;
  for (const auto& entry : cache) {
    if (entry.first == n) return entry.second;
  }
  Data d;
  const int n_gt = static_cast<int>(std::ceil(n * 100.0 / 30.0)) + 10;
  d.gt = synthetic::make_loop<double>(n_gt, 100.0);
  std::mt19937 rng(42);
  std::normal_distribution<double> noise(0.0, 0.003);
  std::uniform_real_distribution<double> jitter(-0.003, 0.003);
  for (int k = 0; k < n; ++k) {
    const std::size_t g = static_cast<std::size_t>(std::lround(k * 100.0 / 30.0));
    Rigid3<double> p = d.gt.poses[g];
    p.t += Vec3<double>(noise(rng), noise(rng), noise(rng));
    p.R = p.R * Eigen::AngleAxisd(noise(rng), Vec3<double>::UnitY()).toRotationMatrix();
    d.est.push_back(d.gt.stamps[g] + jitter(rng), synthetic::some_transform() * p);
  }
  cache.emplace_back(n, std::move(d));
  return cache.back().second;
}

// associate.py's algorithm: every (a, b) pair tested, candidates sorted, greedy with removal.
std::size_t associate_naive(const std::vector<double>& first, const std::vector<double>& second, double max_diff) {
  std::vector<std::tuple<double, double, double>> potential;
  for (double a : first) {
    for (double b : second) {
      const double diff = std::abs(a - b);
      if (diff < max_diff) potential.emplace_back(diff, a, b);
    }
  }
  std::sort(potential.begin(), potential.end());
  std::vector<double> fa = first;
  std::vector<double> sb = second;
  std::sort(fa.begin(), fa.end());
  std::sort(sb.begin(), sb.end());
  std::vector<char> used_a(fa.size(), 0), used_b(sb.size(), 0);
  std::size_t matches = 0;
  for (const auto& [d, a, b] : potential) {
    (void)d;
    const std::size_t ia = static_cast<std::size_t>(std::lower_bound(fa.begin(), fa.end(), a) - fa.begin());
    const std::size_t ib = static_cast<std::size_t>(std::lower_bound(sb.begin(), sb.end(), b) - sb.begin());
    if (used_a[ia] || used_b[ib]) continue;
    used_a[ia] = used_b[ib] = 1;
    ++matches;
  }
  return matches;
}

void BM_Associate(benchmark::State& state) {
  const Data& d = data(static_cast<int>(state.range(0)));
  std::size_t pairs = 0;
  for (auto _ : state) {
    AssociationResult r = associate(d.gt.stamps, d.est.stamps);
    pairs = r.size();
    benchmark::DoNotOptimize(r.first.data());
  }
  state.counters["pairs"] = static_cast<double>(pairs);
}
BENCHMARK(BM_Associate)->Arg(2000)->Unit(benchmark::kMicrosecond);

void BM_AssociateNaiveAssociatePy(benchmark::State& state) {
  const Data& d = data(static_cast<int>(state.range(0)));
  std::size_t pairs = 0;
  for (auto _ : state) {
    pairs = associate_naive(d.gt.stamps, d.est.stamps, 0.02);
    benchmark::DoNotOptimize(pairs);
  }
  state.counters["pairs"] = static_cast<double>(pairs);
}
BENCHMARK(BM_AssociateNaiveAssociatePy)->Arg(2000)->Unit(benchmark::kMicrosecond);

void BM_EvaluateAte(benchmark::State& state) {
  const Data& d = data(static_cast<int>(state.range(0)));
  AteResult<double> ate;
  for (auto _ : state) {
    ate = evaluate_ate(d.gt, d.est);
    benchmark::DoNotOptimize(ate.errors_m.data());  // a pointer: GCC may route a double through "+m,r" wrongly
  }
  state.counters["pairs"] = static_cast<double>(ate.num_pairs);
  state.counters["rmse_mm"] = 1000.0 * ate.error_m.rmse;  // ~sqrt(3) x 3 mm noise expected
}
BENCHMARK(BM_EvaluateAte)->Arg(2000)->Unit(benchmark::kMicrosecond);

void BM_EvaluateAteFloat(benchmark::State& state) {
  const Data& d = data(static_cast<int>(state.range(0)));
  Trajectory<float> gt, est;
  for (std::size_t i = 0; i < d.gt.size(); ++i) gt.push_back(d.gt.stamps[i], d.gt.poses[i].cast<float>());
  for (std::size_t i = 0; i < d.est.size(); ++i) est.push_back(d.est.stamps[i], d.est.poses[i].cast<float>());
  AteResult<float> ate;
  for (auto _ : state) {
    ate = evaluate_ate(gt, est);
    benchmark::DoNotOptimize(ate.errors_m.data());  // a pointer: GCC may route a double through "+m,r" wrongly
  }
  state.counters["pairs"] = static_cast<double>(ate.num_pairs);
  state.counters["rmse_mm"] = 1000.0 * static_cast<double>(ate.error_m.rmse);
}
BENCHMARK(BM_EvaluateAteFloat)->Arg(2000)->Unit(benchmark::kMicrosecond);

void BM_EvaluateRpe1s(benchmark::State& state) {
  const Data& d = data(static_cast<int>(state.range(0)));
  RpeResult<double> rpe;
  for (auto _ : state) {
    rpe = evaluate_rpe(d.gt, d.est);
    benchmark::DoNotOptimize(rpe.pairs.data());
  }
  state.counters["pairs"] = static_cast<double>(rpe.num_pairs);
  state.counters["trans_rmse_mm"] = 1000.0 * rpe.translation_m.rmse;
}
BENCHMARK(BM_EvaluateRpe1s)->Arg(2000)->Unit(benchmark::kMicrosecond);

}  // namespace
