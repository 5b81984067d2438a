/// @file trajectory.hpp
/// Camera trajectories of the synthetic scene, shaped like TUM RGB-D fr3 walking_{static,xyz,rpy,
/// halfsphere}: smooth sums of sines (no paper equation; amplitudes from the TUM sequence descriptions),
/// or a recorded TUM ground truth (Sturm et al. 2012) re-anchored at the rest pose and resampled.
#pragma once

#include "dyncull/core/types.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace dyncull::sim {

/// Recorded: the camera follows TrajectoryOptions::recorded_* (a real hand-held trajectory).
enum class CameraMotion { Static, Xyz, Rpy, Halfsphere, Recorded };

/// Stable lower-case name ("static", "xyz", "rpy", "halfsphere", "recorded").
constexpr const char* to_string(CameraMotion motion) noexcept {
  switch (motion) {
    case CameraMotion::Static: return "static";
    case CameraMotion::Xyz: return "xyz";
    case CameraMotion::Rpy: return "rpy";
    case CameraMotion::Halfsphere: return "halfsphere";
    case CameraMotion::Recorded: return "recorded";
  }
  return "unknown";
}

/// Amplitudes of each motion; the defaults mimic the TUM fr3 walking sequences.
struct TrajectoryOptions {
  Vec3<double> eye_m{0.0, -0.3, 1.35};        ///< rest position of the camera centre (world, z up)
  Vec3<double> target_m{0.0, 2.5, 1.0};       ///< point the rest pose (and halfsphere) looks at
  double static_jitter_m = 0.004;             ///< Static: translation amplitude per axis
  double static_jitter_deg = 0.4;             ///< Static: rotation amplitude per axis
  Vec3<double> xyz_amplitude_m{0.30, 0.15, 0.25};  ///< Xyz: camera right, down, forward
  double xyz_rotation_deg = 1.5;              ///< Xyz: small hand-held rotation
  Vec3<double> rpy_amplitude_deg{16.0, 12.0, 25.0};  ///< Rpy: yaw (about down), pitch (right), roll (forward)
  double rpy_translation_m = 0.015;           ///< Rpy: small translation
  double halfsphere_radius_m = 0.5;           ///< Halfsphere: ~1 m diameter
  double halfsphere_azimuth_deg = 70.0;       ///< Halfsphere: azimuth swing (< 90 keeps one hemisphere)
  double halfsphere_elevation_deg = 35.0;     ///< Halfsphere: elevation swing
  /// Recorded: stamps (seconds, non-decreasing) and world_from_cam poses of a real trajectory,
  /// e.g. a TUM groundtruth.txt read by the caller with eval::read_tum_trajectory. The pose at
  /// recorded_start_s becomes the rest pose (eye_m looking at target_m); later frames move relative
  /// to it exactly as the recording does, interpolated at the frame times (slerp / linear). Past the
  /// recording's end the camera holds its last pose.
  std::vector<double> recorded_stamps_s;
  std::vector<Rigid3<double>> recorded_poses;
  double recorded_start_s = 0.0;              ///< Recorded: seconds after the first stamp where frame 0 starts

  /// Ok-ness of the recorded trajectory: true when it is usable (or empty and not needed); otherwise
  /// false with a reason naming the field and index. `required` = the motion is Recorded.
  bool validate_recorded(bool required, std::string* reason = nullptr) const {
    auto bad = [&](const std::string& why) {
      if (reason) *reason = why;
      return false;
    };
    const std::size_t n = recorded_stamps_s.size();
    if (n != recorded_poses.size())
      return bad("trajectory.recorded_stamps_s has " + std::to_string(n) + " stamps but trajectory.recorded_poses has " +
                 std::to_string(recorded_poses.size()) + " poses");
    if (n == 0) return required ? bad("trajectory.recorded_poses is empty but the motion is recorded") : true;
    for (std::size_t k = 0; k < n; ++k) {
      if (!std::isfinite(recorded_stamps_s[k]))
        return bad("trajectory.recorded_stamps_s[" + std::to_string(k) + "] is not finite");
      // Equal stamps are allowed: TUM files round to 0.1 ms and repeat one now and then (the later wins).
      if (k > 0 && recorded_stamps_s[k] < recorded_stamps_s[k - 1])
        return bad("trajectory.recorded_stamps_s[" + std::to_string(k) + "] is before the previous stamp");
      const Rigid3<double>& p = recorded_poses[k];
      if (!p.R.allFinite() || !p.t.allFinite())
        return bad("trajectory.recorded_poses[" + std::to_string(k) + "] is not finite");
      // 1e-6: a quaternion read from 4-decimal text and normalised is orthonormal to ~1e-15.
      if ((p.R.transpose() * p.R - Mat3<double>::Identity()).cwiseAbs().maxCoeff() > 1e-6 || p.R.determinant() < 0)
        return bad("trajectory.recorded_poses[" + std::to_string(k) + "] has a rotation that is not orthonormal");
    }
    if (!std::isfinite(recorded_start_s) || recorded_start_s < 0 ||
        recorded_start_s > recorded_stamps_s.back() - recorded_stamps_s.front())
      return bad("trajectory.recorded_start_s must lie within the recording (0 to its duration)");
    return true;
  }
};

namespace detail {

/// Phase in [0, 2 pi) derived from the seed, so seeds vary the trajectory without changing its range.
inline double seeded_phase(std::uint64_t seed, int k) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ull * static_cast<std::uint64_t>(k + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return 6.283185307179586 * static_cast<double>(z >> 11) * 0x1.0p-53;
}

/// world_from_cam of a camera at `eye` looking at `target`, x right, y down, z forward (world z up).
inline Rigid3<double> look_at(const Vec3<double>& eye, const Vec3<double>& target) {
  const Vec3<double> forward = (target - eye).normalized();
  Vec3<double> right = forward.cross(Vec3<double>::UnitZ());
  if (right.norm() < 1e-9) right = Vec3<double>::UnitX();  // looking straight up or down
  right.normalize();
  const Vec3<double> down = forward.cross(right);
  Rigid3<double> world_from_cam;
  world_from_cam.R.col(0) = right;
  world_from_cam.R.col(1) = down;
  world_from_cam.R.col(2) = forward;
  world_from_cam.t = eye;
  return world_from_cam;
}

/// Rotation about the camera's down (yaw), right (pitch) and forward (roll) axes, angles in radians.
inline Mat3<double> camera_rotation(double yaw, double pitch, double roll) {
  return (Eigen::AngleAxisd(yaw, Vec3<double>::UnitY()) * Eigen::AngleAxisd(pitch, Vec3<double>::UnitX()) *
          Eigen::AngleAxisd(roll, Vec3<double>::UnitZ()))
      .toRotationMatrix();
}

/// Recorded world_from_cam at `stamp` (recording's clock): slerp of rotation and linear translation
/// between the bracketing samples, clamped to the first/last pose outside. Assumes a valid recording.
inline Rigid3<double> recorded_pose_at(const std::vector<double>& stamps, const std::vector<Rigid3<double>>& poses,
                                       double stamp) {
  if (stamp <= stamps.front()) return poses.front();
  if (stamp >= stamps.back()) return poses.back();
  const auto hi = static_cast<std::size_t>(std::upper_bound(stamps.begin(), stamps.end(), stamp) - stamps.begin());
  const std::size_t lo = hi - 1;
  const double s = (stamp - stamps[lo]) / (stamps[hi] - stamps[lo]);
  const Eigen::Quaterniond q0(poses[lo].R), q1(poses[hi].R);
  Rigid3<double> out;
  out.R = q0.slerp(s, q1).normalized().toRotationMatrix();
  out.t = (1.0 - s) * poses[lo].t + s * poses[hi].t;
  return out;
}

}  // namespace detail

/// Ground-truth world_from_cam at time t seconds from the start (TUM convention: camera x right,
/// y down, z forward). Periods are below 10 s so a 300-frame sequence sweeps the full range.
/// Recorded with an unusable recording (see TrajectoryOptions::validate_recorded) gives the rest pose.
inline Rigid3<double> camera_pose(CameraMotion motion, double t, std::uint64_t seed,
                                  const TrajectoryOptions& options = {}) {
  constexpr double kTwoPi = 6.283185307179586;
  constexpr double kDeg = 0.017453292519943295;
  const Rigid3<double> world_from_rest = detail::look_at(options.eye_m, options.target_m);
  auto wave = [&](int k, double period_s) { return std::sin(kTwoPi * t / period_s + detail::seeded_phase(seed, k)); };
  Rigid3<double> rest_from_cam;
  switch (motion) {
    case CameraMotion::Static:
      rest_from_cam.t = options.static_jitter_m * Vec3<double>(wave(0, 1.7), wave(1, 2.3), wave(2, 3.1));
      rest_from_cam.R = detail::camera_rotation(options.static_jitter_deg * kDeg * wave(3, 2.9),
                                                options.static_jitter_deg * kDeg * wave(4, 1.9),
                                                options.static_jitter_deg * kDeg * wave(5, 3.7));
      break;
    case CameraMotion::Xyz:
      rest_from_cam.t = Vec3<double>(options.xyz_amplitude_m.x() * wave(0, 6.1), options.xyz_amplitude_m.y() * wave(1, 4.3),
                                     options.xyz_amplitude_m.z() * wave(2, 7.7));
      rest_from_cam.R = detail::camera_rotation(options.xyz_rotation_deg * kDeg * wave(3, 3.3),
                                                options.xyz_rotation_deg * kDeg * wave(4, 2.7),
                                                options.xyz_rotation_deg * kDeg * wave(5, 4.1));
      break;
    case CameraMotion::Rpy:
      rest_from_cam.t = options.rpy_translation_m * Vec3<double>(wave(0, 3.9), wave(1, 4.7), wave(2, 5.3));
      rest_from_cam.R = detail::camera_rotation(options.rpy_amplitude_deg.x() * kDeg * wave(3, 5.0),
                                                options.rpy_amplitude_deg.y() * kDeg * wave(4, 3.7),
                                                options.rpy_amplitude_deg.z() * kDeg * wave(5, 6.3));
      break;
    case CameraMotion::Halfsphere: {
      // Centre of the sphere one radius in front of the rest pose, so the rest pose lies on it;
      // azimuth |a| < 90 deg keeps the camera on the half facing the room.
      const Vec3<double> forward = world_from_rest.R.col(2);
      const Vec3<double> right = world_from_rest.R.col(0);
      const Vec3<double> up = -world_from_rest.R.col(1);
      const double r = options.halfsphere_radius_m;
      const Vec3<double> centre = options.eye_m + r * forward;
      const double a = options.halfsphere_azimuth_deg * kDeg * wave(0, 8.3);
      const double e = options.halfsphere_elevation_deg * kDeg * wave(1, 5.9);
      const Vec3<double> dir = std::cos(e) * (std::sin(a) * right - std::cos(a) * forward) + std::sin(e) * up;
      return detail::look_at(centre + r * dir, options.target_m);
    }
    case CameraMotion::Recorded: {
      if (!options.validate_recorded(true)) return world_from_rest;
      const std::vector<double>& stamps = options.recorded_stamps_s;
      const double t0 = stamps.front() + options.recorded_start_s;
      const Rigid3<double> rec_start = detail::recorded_pose_at(stamps, options.recorded_poses, t0);
      const Rigid3<double> rec_now = detail::recorded_pose_at(stamps, options.recorded_poses, t0 + t);
      rest_from_cam = rec_start.inverse() * rec_now;
      break;
    }
  }
  return world_from_rest * rest_from_cam;
}

}  // namespace dyncull::sim
