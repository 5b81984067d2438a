// The Jacobi eigen-decomposition of geometry/symmetric_eigen.hpp against its peer, Eigen's fixed-size
// SelfAdjointEigenSolver, on the 9x9 normal matrix of an 8-point fit (200 noisy correspondences): the solve
// behind every F refit and homography DLT. Eigen's is faster at run time; ours costs a unit that compiles it
// well under a second instead of about 15 s.
#include "dyncull/geometry/symmetric_eigen.hpp"

#include <Eigen/Eigenvalues>
#include <benchmark/benchmark.h>

#include <random>

namespace {

using Mat9 = Eigen::Matrix<double, 9, 9>;

/// Normal matrix of 200 rows (x2 x1, x2 y1, x2, y2 x1, ..., 1) of random normalised correspondences.
Mat9 eight_point_normal_matrix() {
  std::mt19937 rng(3);
  std::normal_distribution<double> g;
  Mat9 ata = Mat9::Zero();
  for (int i = 0; i < 200; ++i) {
    const double x1 = g(rng), y1 = g(rng), x2 = x1 + 0.01 * g(rng), y2 = y1 + 0.01 * g(rng);
    Eigen::Matrix<double, 9, 1> r;
    r << x2 * x1, x2 * y1, x2, y2 * x1, y2 * y1, y2, x1, y1, 1;
    ata.noalias() += r * r.transpose();
  }
  return ata;
}

void BM_SymmetricEigen9_Dyncull(benchmark::State& state) {
  const Mat9 ata = eight_point_normal_matrix();
  dyncull::SymmetricEigen<9> e;
  for (auto _ : state) {
    benchmark::DoNotOptimize(dyncull::symmetric_eigen(ata, &e));
    benchmark::DoNotOptimize(e.vectors.data());
  }
}
BENCHMARK(BM_SymmetricEigen9_Dyncull);

void BM_SymmetricEigen9_EigenSelfAdjoint(benchmark::State& state) {
  const Mat9 ata = eight_point_normal_matrix();
  Eigen::SelfAdjointEigenSolver<Mat9> es;
  for (auto _ : state) {
    es.compute(ata);
    benchmark::DoNotOptimize(es.eigenvectors().data());
  }
}
BENCHMARK(BM_SymmetricEigen9_EigenSelfAdjoint);

}  // namespace
