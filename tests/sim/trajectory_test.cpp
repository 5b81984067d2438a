// Camera motions of the synthetic scene (modelled on TUM fr3 walking_static / xyz / rpy / halfsphere):
// each motion has the range its name promises and the others stay small, poses are rigid, smooth at
// 30 Hz, and deterministic for a seed.
#include "dyncull/sim/trajectory.hpp"

#include "dyncull/eval/trajectory.hpp"
#include "dyncull/sim/scene.hpp"

#include <gtest/gtest.h>

#include "support/real_data.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

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


// A recording whose rotation turns at a constant rate about a fixed axis and whose translation is
// linear in time: slerp and linear interpolation reproduce it exactly between any two samples.
Rigid3<double> analytic_recorded_pose(double stamp) {
  const double s = stamp - 1000.0;
  Rigid3<double> p;
  p.R = Eigen::AngleAxisd(0.4 * s + 0.2, Vec3<double>(1, 2, -0.5).normalized()).toRotationMatrix();
  p.t = Vec3<double>(3.0 - 0.2 * s, -1.0 + 0.1 * s, 1.5 + 0.05 * s);
  return p;
}

TrajectoryOptions analytic_recording() {
  TrajectoryOptions o;
  for (int k = 0; k <= 200; ++k) {
    if (k > 60 && k < 66) continue;  // a 60 ms gap, as motion capture drops samples
    const double stamp = 1000.0 + 0.01 * k;
    o.recorded_stamps_s.push_back(stamp);
    o.recorded_poses.push_back(analytic_recorded_pose(stamp));
  }
  return o;
}

TEST(SimTrajectory, RecordedMotionStartsAtTheRestPoseAndMovesAsTheRecording) {
  TrajectoryOptions o = analytic_recording();
  o.recorded_start_s = 0.25;
  std::string why;
  ASSERT_TRUE(o.validate_recorded(true, &why)) << why;
  const Rigid3<double> rest = detail::look_at(o.eye_m, o.target_m);
  const Rigid3<double> first = camera_pose(CameraMotion::Recorded, 0.0, 1, o);
  EXPECT_LT((first.t - rest.t).norm(), 1e-12);
  EXPECT_LT((first.R - rest.R).norm(), 1e-12);
  const Rigid3<double> rec_start_inv = analytic_recorded_pose(1000.25).inverse();
  for (int i = 0; i <= 52; ++i) {  // 30 Hz frames up to 1.73 s, across the gap (0.61-0.65 s)
    const double t = i / 30.0;
    const Rigid3<double> expected = rest * (rec_start_inv * analytic_recorded_pose(1000.25 + t));
    const Rigid3<double> pose = camera_pose(CameraMotion::Recorded, t, 1, o);
    EXPECT_LT((pose.t - expected.t).norm(), 1e-9) << "frame " << i;
    EXPECT_LT((pose.R - expected.R).norm(), 1e-9) << "frame " << i;
    EXPECT_LT((pose.R.transpose() * pose.R - Mat3<double>::Identity()).norm(), 1e-12);
  }
  // Past the recording's end the camera holds its last pose; the seed plays no part.
  const Rigid3<double> end = camera_pose(CameraMotion::Recorded, 1.75, 1, o);
  const Rigid3<double> later = camera_pose(CameraMotion::Recorded, 9.0, 2, o);
  EXPECT_LT((end.t - later.t).norm(), 1e-12);
  EXPECT_LT((end.R - later.R).norm(), 1e-12);
  EXPECT_STREQ(to_string(CameraMotion::Recorded), "recorded");
}

TEST(SimTrajectory, UnusableRecordingsAreNamedAndGiveTheRestPose) {
  const TrajectoryOptions good = analytic_recording();
  const Rigid3<double> rest = detail::look_at(good.eye_m, good.target_m);
  std::string why;
  EXPECT_TRUE(TrajectoryOptions{}.validate_recorded(false, &why)) << "empty and unused is fine";
  struct Case {
    TrajectoryOptions o;
    const char* field;
  };
  std::vector<Case> cases;
  cases.push_back({TrajectoryOptions{}, "trajectory.recorded_poses is empty"});
  cases.push_back({good, "trajectory.recorded_stamps_s has 196 stamps but trajectory.recorded_poses has 195"});
  cases.back().o.recorded_poses.pop_back();
  cases.push_back({good, "trajectory.recorded_stamps_s[7] is not finite"});
  cases.back().o.recorded_stamps_s[7] = std::nan("");
  cases.push_back({good, "trajectory.recorded_stamps_s[9] is before the previous stamp"});
  cases.back().o.recorded_stamps_s[9] = cases.back().o.recorded_stamps_s[8] - 1e-4;
  cases.push_back({good, "trajectory.recorded_poses[3] is not finite"});
  cases.back().o.recorded_poses[3].t.x() = INFINITY;
  cases.push_back({good, "trajectory.recorded_poses[4] has a rotation that is not orthonormal"});
  cases.back().o.recorded_poses[4].R *= 1.01;
  cases.push_back({good, "trajectory.recorded_start_s must lie within the recording"});
  cases.back().o.recorded_start_s = 2.5;
  cases.push_back({good, "trajectory.recorded_start_s must lie within the recording"});
  cases.back().o.recorded_start_s = -0.1;
  for (const Case& c : cases) {
    EXPECT_FALSE(c.o.validate_recorded(true, &why)) << c.field;
    EXPECT_NE(why.find(c.field), std::string::npos) << why;
    const Rigid3<double> pose = camera_pose(CameraMotion::Recorded, 0.5, 1, c.o);
    EXPECT_EQ(pose.t, rest.t) << c.field;
    EXPECT_EQ(pose.R, rest.R) << c.field;
    SceneOptions so;
    so.motion = CameraMotion::Recorded;
    so.trajectory = c.o;
    const Scene scene(so);
    EXPECT_EQ(scene.status(), Status::InvalidInput) << c.field;
    EXPECT_NE(scene.reason().find(c.field), std::string::npos) << scene.reason();
  }
  // A repeated stamp (as fr3_walking_static's ground truth has) is usable: the later pose wins.
  TrajectoryOptions repeated = good;
  repeated.recorded_stamps_s[9] = repeated.recorded_stamps_s[8];
  EXPECT_TRUE(repeated.validate_recorded(true, &why)) << why;
  const Rigid3<double> at = camera_pose(CameraMotion::Recorded, repeated.recorded_stamps_s[8] - 1000.0, 1, repeated);
  const Rigid3<double> want = rest * (repeated.recorded_poses[0].inverse() * repeated.recorded_poses[9]);
  EXPECT_LT((at.t - want.t).norm(), 1e-12);
  EXPECT_LT((at.R - want.R).norm(), 1e-12);
  // A broken recording is refused even when another motion is chosen (it was given for a reason).
  SceneOptions xyz;
  xyz.trajectory = cases[1].o;
  EXPECT_EQ(Scene(xyz).status(), Status::InvalidInput);
}

// Independent interpolation of a recording for the real-data test: linear search, Eigen slerp.
Rigid3<double> interpolate(const eval::Trajectory<double>& rec, double stamp) {
  std::size_t k = 0;
  while (k + 2 < rec.size() && rec.stamps[k + 1] <= stamp) ++k;
  const double s = std::clamp((stamp - rec.stamps[k]) / (rec.stamps[k + 1] - rec.stamps[k]), 0.0, 1.0);
  Rigid3<double> p;
  p.R = Eigen::Quaterniond(rec.poses[k].R).slerp(s, Eigen::Quaterniond(rec.poses[k + 1].R)).toRotationMatrix();
  p.t = (1 - s) * rec.poses[k].t + s * rec.poses[k + 1].t;
  return p;
}

TEST(SimTrajectory, RecordedMotionFollowsTheRealTumGroundTruth) {
  std::string why_not;
  const std::string root = dyncull::test::real_data_dir(&why_not);
  if (root.empty()) GTEST_SKIP() << why_not;
  for (const char* name : {"fr3_walking_xyz", "fr3_walking_static", "fr3_walking_rpy", "fr3_walking_halfsphere",
                           "fr3_sitting_static", "fr3_sitting_xyz"}) {
    const auto read = eval::read_tum_trajectory<double>(std::string(root) + "/tum/" + name + "/groundtruth.txt");
    ASSERT_TRUE(read.ok()) << read.reason;
    SceneOptions o;
    o.width = 64;
    o.height = 48;
    o.motion = CameraMotion::Recorded;
    o.trajectory.recorded_stamps_s = read.trajectory.stamps;
    o.trajectory.recorded_poses = read.trajectory.poses;
    o.trajectory.recorded_start_s = 3.0;
    const Scene scene(o);
    ASSERT_TRUE(scene.ok()) << scene.reason();
    const Rigid3<double> rest = detail::look_at(o.trajectory.eye_m, o.trajectory.target_m);
    EXPECT_LT((scene.world_from_cam(0).t - rest.t).norm(), 1e-12) << name;
    EXPECT_LT((scene.world_from_cam(0).R - rest.R).norm(), 1e-12) << name;
    const double t0 = read.trajectory.stamps.front() + 3.0;
    double sim_path = 0, real_path = 0, worst_t = 0, worst_r = 0;
    for (int i = 0; i + 1 < scene.num_frames(); ++i) {
      // Frame-to-frame motion in the camera frame does not depend on the re-anchoring.
      const Rigid3<double> sim = scene.world_from_cam(i).inverse() * scene.world_from_cam(i + 1);
      const Rigid3<double> real = interpolate(read.trajectory, t0 + i / o.fps).inverse() *
                                  interpolate(read.trajectory, t0 + (i + 1) / o.fps);
      worst_t = std::max(worst_t, (sim.t - real.t).norm());
      worst_r = std::max(worst_r, (sim.R - real.R).norm());  // not acos: it loses 1e-8 near 0
      sim_path += sim.t.norm();
      real_path += real.t.norm();
    }
    EXPECT_LT(worst_t, 1e-9) << name;
    EXPECT_LT(worst_r, 1e-9) << name;
    EXPECT_NEAR(sim_path, real_path, 1e-8) << name;
    std::printf("%s: %.3f m of camera path in 10 s\n", name, real_path);
    EXPECT_GT(real_path, 0.01) << name << " moved";  // even the *_static cameras drift by centimetres
    FrameData f;
    scene.render(150, &f);
    EXPECT_TRUE(f.ok()) << f.reason;
  }
}

}  // namespace
}  // namespace dyncull::sim
