// Synthetic ground-truth trajectories for the eval tests: a non-planar loop with rotation, so
// alignment is well determined, at a given rate.
#pragma once

#include "dyncull/core/types.hpp"
#include "dyncull/eval/trajectory.hpp"

#include <Eigen/Geometry>

#include <cmath>

namespace dyncull::eval::synthetic {

/// n poses at `rate_hz` from `t0`: positions on a tilted loop (x, y radius 1 m, z = 0.3 cos 2a),
/// camera yawing with the loop angle and pitching slowly. Alignment of these positions is
/// non-degenerate (full-rank covariance).
template <class T>
Trajectory<T> make_loop(int n, double rate_hz = 30.0, double t0 = 1000.0) {
  Trajectory<T> out;
  out.reserve(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    const double a = 2.0 * Constants<double>::pi() * k / n;
    Rigid3<double> pose;
    pose.t = Vec3<double>(std::cos(a), std::sin(a), 0.3 * std::cos(2.0 * a));
    pose.R = (Eigen::AngleAxisd(a, Vec3<double>::UnitZ()) * Eigen::AngleAxisd(0.2 * std::sin(a), Vec3<double>::UnitX()))
                 .toRotationMatrix();
    out.push_back(t0 + k / rate_hz, pose.template cast<T>());
  }
  return out;
}

/// A rigid transform that is far from the identity, for "estimate in another world frame" tests.
inline Rigid3<double> some_transform() {
  Rigid3<double> g;
  g.R = (Eigen::AngleAxisd(0.7, Vec3<double>(1, 2, 3).normalized())).toRotationMatrix();
  g.t = Vec3<double>(2.0, -1.0, 0.5);
  return g;
}

}  // namespace dyncull::eval::synthetic
