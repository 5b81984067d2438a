// Camera motions of the synthetic scene (modelled on TUM fr3 walking_static / xyz / rpy / halfsphere):
// each motion has the range its name promises and the others stay small, poses are rigid, smooth at
// 30 Hz, and deterministic for a seed.
#include "dyncull/sim/trajectory.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace dyncull::sim {
namespace {

constexpr double kRadToDeg = 57.29577951308232;

struct Range {
  double max_translation_m = 0;   // largest distance from the rest position
  double max_rotation_deg = 0;    // largest rotation away from the rest orientation
  double max_step_m = 0;          // largest translation between consecutive frames
  double max_step_deg = 0;        // largest rotation between consecutive frames
  double max_orthonormality = 0;  // |R^T R - I|
};

Range sweep(CameraMotion motion, std::uint64_t seed, const TrajectoryOptions& o = {}) {
  const Rigid3<double> rest = detail::look_at(o.eye_m, o.target_m);
  Range r;
  Rigid3<double> previous = camera_pose(motion, 0.0, seed, o);
  for (int i = 0; i <= 600; ++i) {  // 20 s at 30 Hz: every period (< 10 s) is swept
    const Rigid3<double> pose = camera_pose(motion, i / 30.0, seed, o);
    r.max_translation_m = std::max(r.max_translation_m, (pose.t - rest.t).norm());
    r.max_rotation_deg = std::max(r.max_rotation_deg, kRadToDeg * rotation_angle(Mat3<double>(rest.R.transpose() * pose.R)));
    r.max_step_m = std::max(r.max_step_m, (pose.t - previous.t).norm());
    r.max_step_deg = std::max(r.max_step_deg, kRadToDeg * rotation_angle(Mat3<double>(previous.R.transpose() * pose.R)));
    r.max_orthonormality =
        std::max(r.max_orthonormality, (pose.R.transpose() * pose.R - Mat3<double>::Identity()).cwiseAbs().maxCoeff());
    previous = pose;
  }
  return r;
}

TEST(SimTrajectory, EachMotionSpansItsRangeAndKeepsTheOthersSmall) {
  const TrajectoryOptions o;
  const Range still = sweep(CameraMotion::Static, 1);
  EXPECT_LE(still.max_translation_m, std::sqrt(3.0) * o.static_jitter_m + 1e-12);
  EXPECT_LE(still.max_rotation_deg, 2.0 * o.static_jitter_deg);

  const Range xyz = sweep(CameraMotion::Xyz, 1);
  EXPECT_GE(xyz.max_translation_m, 0.8 * o.xyz_amplitude_m.maxCoeff());  // metres of translation...
  EXPECT_LE(xyz.max_translation_m, o.xyz_amplitude_m.norm() + 1e-12);
  EXPECT_LE(xyz.max_rotation_deg, 2.0 * o.xyz_rotation_deg);             // ...with little rotation

  const Range rpy = sweep(CameraMotion::Rpy, 1);
  EXPECT_GE(rpy.max_rotation_deg, 0.8 * o.rpy_amplitude_deg.maxCoeff());  // tens of degrees...
  EXPECT_LE(rpy.max_translation_m, std::sqrt(3.0) * o.rpy_translation_m + 1e-12);  // ...in place

  const Range half = sweep(CameraMotion::Halfsphere, 1);
  EXPECT_GE(half.max_translation_m, 0.5 * o.halfsphere_radius_m);  // both move a lot
  EXPECT_LE(half.max_translation_m, 2.0 * o.halfsphere_radius_m + 1e-12);
  EXPECT_GE(half.max_rotation_deg, 10.0);
}

TEST(SimTrajectory, PosesAreRigidAndSmoothAt30Hz) {
  for (CameraMotion m : {CameraMotion::Static, CameraMotion::Xyz, CameraMotion::Rpy, CameraMotion::Halfsphere}) {
    const Range r = sweep(m, 7);
    EXPECT_LT(r.max_orthonormality, 1e-12) << to_string(m);
    // A hand-held Kinect in TUM moves at most a few cm and a few degrees per frame.
    EXPECT_LT(r.max_step_m, 0.05) << to_string(m);
    EXPECT_LT(r.max_step_deg, 3.0) << to_string(m);
    EXPECT_GT(r.max_step_m + r.max_step_deg, 0.0) << to_string(m) << " never moves";
  }
}

TEST(SimTrajectory, HalfsphereKeepsLookingAtTheTarget) {
  const TrajectoryOptions o;
  for (int i = 0; i <= 300; i += 10) {
    const Rigid3<double> pose = camera_pose(CameraMotion::Halfsphere, i / 30.0, 3, o);
    const Vec3<double> to_target = (o.target_m - pose.t).normalized();
    const double off_axis_deg = kRadToDeg * std::acos(std::clamp(to_target.dot(pose.R.col(2)), -1.0, 1.0));
    EXPECT_LT(off_axis_deg, 1e-4) << "frame " << i;
  }
}

TEST(SimTrajectory, DeterministicForASeedAndDifferentAcrossSeeds) {
  for (CameraMotion m : {CameraMotion::Xyz, CameraMotion::Rpy, CameraMotion::Halfsphere}) {
    const Rigid3<double> a = camera_pose(m, 2.5, 11), b = camera_pose(m, 2.5, 11), c = camera_pose(m, 2.5, 12);
    EXPECT_EQ(a.t, b.t) << to_string(m);
    EXPECT_EQ(a.R, b.R) << to_string(m);
    EXPECT_GT((a.t - c.t).norm() + (a.R - c.R).norm(), 1e-6) << to_string(m);
  }
}

}  // namespace
}  // namespace dyncull::sim
