// Synthetic ground-truth data for the pose tests and benches: random rigid transforms, 3-D point
// pairs, and PnP scenes (world points in front of a pinhole camera, noisy pixels, outliers).
#pragma once

#include "dyncull/core/camera.hpp"
#include "dyncull/core/random.hpp"
#include "dyncull/core/types.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

namespace dyncull::test {

/// Names TYPED_TEST instances "float" / "double". Passing it also keeps clang's -Wpedantic quiet:
/// TYPED_TEST_SUITE(Suite, Types) with no third argument trips -Wgnu-zero-variadic-macro-arguments.
struct ScalarNames {
  template <class T>
  static std::string GetName(int) {
    return std::is_same<T, float>::value ? "float" : "double";
  }
};

/// Random rotation (uniform axis, angle in [0, max_angle]) and translation in a cube of half-size t_range.
template <class T>
Rigid3<T> random_rigid(Random& rng, double max_angle = 1.0, double t_range = 1.0) {
  Eigen::Vector3d axis(rng.normal(), rng.normal(), rng.normal());
  axis.normalize();
  Rigid3<double> g;
  g.R = Eigen::AngleAxisd(rng.uniform(0.0, max_angle), axis).toRotationMatrix();
  g.t = Eigen::Vector3d(rng.uniform(-t_range, t_range), rng.uniform(-t_range, t_range), rng.uniform(-t_range, t_range));
  return g.cast<T>();
}

/// n random points in an axis-aligned box centred at `centre` with half-size `half`.
template <class T>
Eigen::Matrix<T, 3, Eigen::Dynamic> random_points(Random& rng, int n, const Vec3<T>& centre = Vec3<T>::Zero(),
                                                  double half = 1.0) {
  Eigen::Matrix<T, 3, Eigen::Dynamic> P(3, n);
  for (int i = 0; i < n; ++i)
    for (int r = 0; r < 3; ++r) P(r, i) = centre(r) + T(rng.uniform(-half, half));
  return P;
}

/// A PnP scene: world points seen by a camera, their (noisy) pixels and which ones are outliers.
template <class T>
struct PnpScene {
  PinholeCamera<T> camera;
  Rigid3<T> cam_from_world;
  std::vector<Vec3<T>> world;
  std::vector<Vec2<T>> pixels;
  std::vector<std::uint8_t> is_outlier;
};

/// n points at depths [2, 8] m inside the image, projected with Gaussian pixel noise `noise_px`;
/// a fraction `outlier_ratio` of pixels replaced by uniform random pixels in the image.
template <class T>
PnpScene<T> make_pnp_scene(std::uint64_t seed, int n, double noise_px = 0.0, double outlier_ratio = 0.0) {
  Random rng(seed);
  PnpScene<T> s;
  s.camera = PinholeCamera<T>::tum_fr3();
  const PinholeCamera<double> cam = s.camera.template cast<double>();
  const Rigid3<double> cam_from_world = random_rigid<double>(rng, 0.5, 1.0);
  s.cam_from_world = cam_from_world.cast<T>();
  const Rigid3<double> world_from_cam = cam_from_world.inverse();
  s.world.reserve(n);
  s.pixels.reserve(n);
  s.is_outlier.assign(static_cast<std::size_t>(n), 0);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d uv(rng.uniform(0.0, cam.width - 1.0), rng.uniform(0.0, cam.height - 1.0));
    const double z = rng.uniform(2.0, 8.0);
    const Eigen::Vector3d p_cam = cam.backproject(uv, z);
    s.world.push_back(world_from_cam.apply(p_cam).cast<T>());
    Eigen::Vector2d obs = uv + noise_px * Eigen::Vector2d(rng.normal(), rng.normal());
    if (rng.uniform() < outlier_ratio) {
      obs = Eigen::Vector2d(rng.uniform(0.0, cam.width - 1.0), rng.uniform(0.0, cam.height - 1.0));
      s.is_outlier[static_cast<std::size_t>(i)] = 1;
    }
    s.pixels.push_back(obs.cast<T>());
  }
  return s;
}

/// A structured cloud for ICP: three orthogonal 2 m planes and a sphere patch (well constrained in all
/// six degrees of freedom), n points sampled uniformly at random.
template <class T>
std::vector<Vec3<T>> room_cloud(Random& rng, int n) {
  std::vector<Vec3<T>> pts;
  pts.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double a = rng.uniform(0, 2), b = rng.uniform(0, 2);
    switch (i % 4) {
      case 0: pts.push_back(Vec3<T>(T(a), T(b), T(0))); break;
      case 1: pts.push_back(Vec3<T>(T(a), T(0), T(b))); break;
      case 2: pts.push_back(Vec3<T>(T(0), T(a), T(b))); break;
      default: {
        Eigen::Vector3d d(rng.normal(), rng.normal(), rng.normal());
        d = d.normalized() * 0.4 + Eigen::Vector3d(1, 1, 1);
        pts.push_back(d.cast<T>());
      }
    }
  }
  return pts;
}

/// Rotation error in degrees and translation error (same units as t) between two poses.
template <class T>
double rotation_error_deg(const Rigid3<T>& a, const Rigid3<T>& b) {
  const Mat3<double> d = a.R.template cast<double>().transpose() * b.R.template cast<double>();
  // Through the quaternion (atan2), not acos of the trace: acos loses half the digits near 0.
  const Eigen::Quaterniond q(d);
  return 2.0 * std::atan2(q.vec().norm(), std::abs(q.w())) * 180.0 / 3.14159265358979323846;
}
template <class T>
double translation_error(const Rigid3<T>& a, const Rigid3<T>& b) {
  return (a.t.template cast<double>() - b.t.template cast<double>()).norm();
}

}  // namespace dyncull::test
