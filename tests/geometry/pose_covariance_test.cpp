// geometry/pose_covariance.hpp: the projection Jacobian matches finite differences of a left
// perturbation, the covariance shrinks as points are added and is refused on too few points, and the
// projected spread grows with the pixel noise.
#include "dyncull/geometry/pose_covariance.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cstdint>
#include <vector>

namespace {

using dyncull::PinholeCamera;
using dyncull::PoseCovariance;
using dyncull::Rigid3;
using dyncull::Vec2;
using dyncull::Vec3;

const PinholeCamera<double> kCamera{525.0, 520.0, 319.5, 239.5, 640, 480};

Vec2<double> project(const Vec3<double>& pc) {
  return Vec2<double>(kCamera.fx * pc.x() / pc.z() + kCamera.cx, kCamera.fy * pc.y() / pc.z() + kCamera.cy);
}

TEST(PoseCovariance, JacobianMatchesFiniteDifferencesOfALeftPerturbation) {
  const Vec3<double> pc(0.3, -0.2, 2.5);
  const dyncull::ProjectionJacobian J = dyncull::projection_jacobian(kCamera, pc);
  const double h = 1e-6;
  for (int k = 0; k < 6; ++k) {
    Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
    d(k) = h;
    // exp([w, v]) applied on the left: R(w) pc + v.
    const Eigen::AngleAxisd rotation(d.head<3>().norm(), d.head<3>().norm() > 0 ? Vec3<double>(d.head<3>().normalized())
                                                                                 : Vec3<double>::UnitX());
    const Vec3<double> moved = rotation * pc + d.tail<3>();
    const Vec2<double> numeric = (project(moved) - project(pc)) / h;
    EXPECT_NEAR(J(0, k), numeric.x(), 1e-3 * (1 + std::abs(numeric.x()))) << "column " << k;
    EXPECT_NEAR(J(1, k), numeric.y(), 1e-3 * (1 + std::abs(numeric.y()))) << "column " << k;
  }
}

std::vector<Vec3<double>> grid_points(int per_side) {
  std::vector<Vec3<double>> points;
  for (int i = 0; i < per_side; ++i)
    for (int j = 0; j < per_side; ++j)
      points.emplace_back(-1.0 + 2.0 * i / (per_side - 1), -0.8 + 1.6 * j / (per_side - 1), 2.0 + 0.5 * ((i + j) % 3));
  return points;
}

TEST(PoseCovariance, ShrinksWithMorePointsAndGrowsWithTheNoise) {
  const Rigid3<double> pose = Rigid3<double>::identity();
  const std::vector<Vec3<double>> few = grid_points(4), many = grid_points(12);
  PoseCovariance cov_few, cov_many, cov_noisy;
  ASSERT_TRUE(dyncull::pose_covariance(few, std::vector<std::uint8_t>(few.size(), 1), pose, kCamera, 1.0, &cov_few));
  ASSERT_TRUE(dyncull::pose_covariance(many, std::vector<std::uint8_t>(many.size(), 1), pose, kCamera, 1.0, &cov_many));
  ASSERT_TRUE(dyncull::pose_covariance(many, std::vector<std::uint8_t>(many.size(), 1), pose, kCamera, 2.0, &cov_noisy));
  EXPECT_LT(cov_many.trace(), cov_few.trace());
  EXPECT_NEAR(cov_noisy.trace(), 4.0 * cov_many.trace(), 1e-9 * cov_noisy.trace());
  const Vec3<double> pc(0.5, 0.1, 3.0);
  EXPECT_GT(dyncull::projected_spread_px(kCamera, pc, cov_few), dyncull::projected_spread_px(kCamera, pc, cov_many));
}

TEST(PoseCovariance, TooFewPointsOrOnlyOutliersOrPointsBehindTheCameraAreRefused) {
  const Rigid3<double> pose = Rigid3<double>::identity();
  const std::vector<Vec3<double>> two = {Vec3<double>(0, 0, 2), Vec3<double>(1, 0, 2)};
  PoseCovariance cov;
  EXPECT_FALSE(dyncull::pose_covariance(two, std::vector<std::uint8_t>(2, 1), pose, kCamera, 1.0, &cov));
  const std::vector<Vec3<double>> many = grid_points(6);
  EXPECT_FALSE(dyncull::pose_covariance(many, std::vector<std::uint8_t>(many.size(), 0), pose, kCamera, 1.0, &cov));
  std::vector<Vec3<double>> behind = many;
  for (auto& p : behind) p.z() = -p.z();
  EXPECT_FALSE(dyncull::pose_covariance(behind, std::vector<std::uint8_t>(behind.size(), 1), pose, kCamera, 1.0, &cov));
}

}  // namespace
