/// @file pose_covariance.hpp
/// First-order uncertainty of a camera pose fitted to pixel observations: the Jacobian of a pinhole
/// projection with respect to a left perturbation [w, v] of cam_from_world (d pc = -[pc]x w + v), the
/// Gauss-Newton covariance sigma^2 (J^T J)^-1 over the fit's inliers, and the pixel spread that
/// covariance gives a projected point (Hartley and Zisserman 2004, §5.2: the covariance of an ML estimate).
#pragma once

#include "dyncull/core/camera.hpp"
#include "dyncull/core/types.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace dyncull {

using PoseCovariance = Eigen::Matrix<double, 6, 6>;  ///< over [w, v] (rotation, translation), in double
using ProjectionJacobian = Eigen::Matrix<double, 2, 6>;

/// d pixel / d [w, v] of the projection of pc (a point in the camera frame, z > 0), in double.
template <class T>
ProjectionJacobian projection_jacobian(const PinholeCamera<T>& camera, const Vec3<T>& pc) {
  ProjectionJacobian J;
  const double x = double(pc.x()), y = double(pc.y()), z = double(pc.z()), iz = 1.0 / z;
  const double fx = double(camera.fx), fy = double(camera.fy);
  Eigen::Matrix<double, 2, 3> P;
  P << fx * iz, 0, -fx * x * iz * iz, 0, fy * iz, -fy * y * iz * iz;
  Mat3<double> S;
  S << 0, -z, y, z, 0, -x, -y, x, 0;  // [pc]x
  J.template leftCols<3>() = -P * S;
  J.template rightCols<3>() = P;
  return J;
}

/// sigma_px^2 (J^T J)^-1 over the world points whose inlier flag is set and that lie in front of the
/// camera at `cam_from_world`; false when J^T J is singular or nearly so (too few or degenerate points:
/// a pivot below 1e-12 of the largest) or the result is not finite.
template <class T>
bool pose_covariance(const std::vector<Vec3<T>>& world, const std::vector<std::uint8_t>& inlier,
                     const Rigid3<T>& cam_from_world, const PinholeCamera<T>& camera, double sigma_px,
                     PoseCovariance* covariance) {
  PoseCovariance H = PoseCovariance::Zero();
  for (std::size_t k = 0; k < inlier.size() && k < world.size(); ++k) {
    if (!inlier[k]) continue;
    const Vec3<T> pc = cam_from_world.R * world[k] + cam_from_world.t;
    if (!(pc.z() > T(0))) continue;
    const ProjectionJacobian J = projection_jacobian(camera, pc);
    H.noalias() += J.transpose() * J;
  }
  const Eigen::LDLT<PoseCovariance> ldlt(H);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return false;
  // A zero pivot is a direction the points do not observe: LDLT's solve would give it zero variance.
  const auto pivots = ldlt.vectorD();
  if (!(pivots.minCoeff() > 1e-12 * pivots.maxCoeff())) return false;
  *covariance = ldlt.solve(PoseCovariance::Identity()) * (sigma_px * sigma_px);
  return covariance->allFinite();
}

/// The spread in pixels (sqrt of the trace of J cov J^T) the pose covariance gives the projection of pc.
template <class T>
T projected_spread_px(const PinholeCamera<T>& camera, const Vec3<T>& pc, const PoseCovariance& covariance) {
  const ProjectionJacobian J = projection_jacobian(camera, pc);
  return static_cast<T>(std::sqrt(std::max(0.0, (J * covariance * J.transpose()).trace())));
}

}  // namespace dyncull
