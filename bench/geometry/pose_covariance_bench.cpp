// The Gauss-Newton pose covariance of geometry/pose_covariance.hpp (J^T J over the inliers, LDLT
// inverse) against its peer, the same J^T J inverted by Eigen's FullPivLU, and the projected spread of
// one point, on 300 inliers of a camera 2-4 m from the points (the reprojection check's case).
#include "dyncull/geometry/pose_covariance.hpp"

#include <benchmark/benchmark.h>

#include <Eigen/LU>

#include <cstdint>
#include <random>
#include <vector>

namespace {

const dyncull::PinholeCamera<double> kCamera{525.0, 525.0, 319.5, 239.5, 640, 480};

std::vector<dyncull::Vec3<double>> points(std::size_t n) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> x(-1.5, 1.5), y(-1.0, 1.0), z(2.0, 4.0);
  std::vector<dyncull::Vec3<double>> p(n);
  for (auto& q : p) q = dyncull::Vec3<double>(x(rng), y(rng), z(rng));
  return p;
}

void BM_PoseCovariance_Dyncull(benchmark::State& state) {
  const auto world = points(300);
  const std::vector<std::uint8_t> inlier(world.size(), 1);
  const dyncull::Rigid3<double> pose = dyncull::Rigid3<double>::identity();
  dyncull::PoseCovariance cov;
  for (auto _ : state) {
    benchmark::DoNotOptimize(dyncull::pose_covariance(world, inlier, pose, kCamera, 1.0, &cov));
    benchmark::DoNotOptimize(cov.data());
  }
}
BENCHMARK(BM_PoseCovariance_Dyncull);

// Peer: the same normal matrix from the same Jacobians, inverted by a full-pivoting LU.
void BM_PoseCovariance_EigenFullPivLu(benchmark::State& state) {
  const auto world = points(300);
  const dyncull::Rigid3<double> pose = dyncull::Rigid3<double>::identity();
  dyncull::PoseCovariance cov;
  for (auto _ : state) {
    dyncull::PoseCovariance H = dyncull::PoseCovariance::Zero();
    for (const auto& X : world) {
      const dyncull::Vec3<double> pc = pose.R * X + pose.t;
      if (!(pc.z() > 0)) continue;
      const dyncull::ProjectionJacobian J = dyncull::projection_jacobian(kCamera, pc);
      H.noalias() += J.transpose() * J;
    }
    cov = H.fullPivLu().inverse();
    benchmark::DoNotOptimize(cov.data());
  }
}
BENCHMARK(BM_PoseCovariance_EigenFullPivLu);

void BM_ProjectedSpread(benchmark::State& state) {
  const auto world = points(300);
  dyncull::PoseCovariance cov;
  dyncull::pose_covariance(world, std::vector<std::uint8_t>(world.size(), 1), dyncull::Rigid3<double>::identity(),
                           kCamera, 1.0, &cov);
  const dyncull::Vec3<double> pc(0.4, -0.2, 3.0);
  for (auto _ : state) benchmark::DoNotOptimize(dyncull::projected_spread_px(kCamera, pc, cov));
}
BENCHMARK(BM_ProjectedSpread);

}  // namespace
