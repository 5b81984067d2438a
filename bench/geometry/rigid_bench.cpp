// Umeyama/Kabsch alignment of 1000 (and 100, 10000) pairs: dyncull::umeyama vs Eigen::umeyama,
// SE(3) and Sim(3); the max coefficient difference between the two is reported as a counter.
#include "dyncull/geometry/rigid.hpp"

#include "support/pose_data.hpp"

#include <Eigen/Geometry>
#include <benchmark/benchmark.h>

namespace {

using dyncull::Random;
using Points = Eigen::Matrix<double, 3, Eigen::Dynamic>;

struct Pairs {
  Points src, dst;
};
Pairs make_pairs(int n) {
  Random rng(95);
  const auto g = dyncull::test::random_rigid<double>(rng, 3.0, 5.0);
  Pairs p;
  p.src = dyncull::test::random_points<double>(rng, n, dyncull::Vec3<double>(3, 1, 2), 4.0);
  p.dst = (g.R * p.src).colwise() + g.t;
  for (int i = 0; i < n; ++i) p.dst.col(i) += 0.01 * dyncull::Vec3<double>(rng.normal(), rng.normal(), rng.normal());
  return p;
}

void BM_dyncull_umeyama(benchmark::State& state) {
  const Pairs p = make_pairs(static_cast<int>(state.range(0)));
  dyncull::AlignmentOptions o;
  o.estimate_scale = state.range(1) != 0;
  dyncull::AlignmentResult<double> r;
  for (auto _ : state) {
    r = dyncull::umeyama(p.src, p.dst, o);
    benchmark::DoNotOptimize(r.dst_from_src.t.data());
  }
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = r.dst_from_src.scale * r.dst_from_src.R;
  m.topRightCorner<3, 1>() = r.dst_from_src.t;
  state.counters["max_diff_vs_eigen"] = (m - Eigen::umeyama(p.src, p.dst, o.estimate_scale)).cwiseAbs().maxCoeff();
}
BENCHMARK(BM_dyncull_umeyama)->Args({1000, 0})->Args({1000, 1})->Args({100, 0})->Args({10000, 0})
    ->Unit(benchmark::kMicrosecond);

void BM_eigen_umeyama(benchmark::State& state) {
  const Pairs p = make_pairs(static_cast<int>(state.range(0)));
  const bool scale = state.range(1) != 0;
  for (auto _ : state) {
    const Eigen::Matrix4d m = Eigen::umeyama(p.src, p.dst, scale);
    benchmark::DoNotOptimize(m.data());
  }
}
BENCHMARK(BM_eigen_umeyama)->Args({1000, 0})->Args({1000, 1})->Args({100, 0})->Args({10000, 0})
    ->Unit(benchmark::kMicrosecond);

}  // namespace
