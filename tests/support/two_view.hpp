// Synthetic two-view correspondences with ground truth for the fundamental-matrix and epipolar tests and
// benches: random 3-D points seen by two pinhole cameras (fx = fy = 535, 640x480), Gaussian pixel noise,
// a fraction of outliers displaced off their epipolar line, and the true F = K^-T [t]x R K^-1.
#pragma once

#include "dyncull/core/camera.hpp"
#include "dyncull/core/random.hpp"
#include "dyncull/core/types.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

namespace dyncull::test {

enum class TwoViewKind {
  General,       ///< points in a depth range, camera translates and rotates
  Planar,        ///< all points on one plane (F is not determined by the data)
  PureRotation,  ///< zero baseline (F is not determined by the data)
};

struct TwoViewOptions {
  int num_points = 1000;
  double noise_px = 0.5;           ///< Gaussian sigma on both images' pixels
  double outlier_fraction = 0.3;   ///< fraction of correspondences replaced by outliers
  double min_outlier_px = 3.0;     ///< outliers lie at least this far from their true epipolar line (image 2)
  double depth_min_m = 2.0, depth_max_m = 8.0;
  double baseline_m = 0.3;         ///< |t| of cam2_from_cam1
  double max_rotation_deg = 10.0;
  TwoViewKind kind = TwoViewKind::General;
  std::uint64_t seed = 1;
};

template <class T>
struct TwoViewData {
  PinholeCamera<double> camera;
  Rigid3<double> cam2_from_cam1;
  Mat3<T> F = Mat3<T>::Zero();         ///< true F (x2^T F x1 = 0), Frobenius norm 1, computed in double
  std::vector<Vec2<T>> points1, points2;   ///< observed (noisy, with outliers)
  std::vector<Vec2<T>> clean1, clean2;     ///< noise-free projections (outliers: the true projection)
  std::vector<std::uint8_t> is_inlier;     ///< 1 for true correspondences
  std::size_t num_inliers = 0;
};

/// F = K^-T [t]x R K^-1 for x_cam2 = R x_cam1 + t, normalised to unit Frobenius norm.
inline Mat3<double> true_fundamental(const PinholeCamera<double>& cam, const Rigid3<double>& cam2_from_cam1) {
  Mat3<double> tx;
  const Vec3<double>& t = cam2_from_cam1.t;
  tx << 0, -t.z(), t.y(), t.z(), 0, -t.x(), -t.y(), t.x(), 0;
  const Mat3<double> Kinv = cam.K().inverse();
  Mat3<double> F = Kinv.transpose() * tx * cam2_from_cam1.R * Kinv;
  const double n = F.norm();
  if (n > 0) F /= n;
  return F;
}

/// Builds the data set; deterministic for options.seed.
template <class T>
TwoViewData<T> make_two_view(const TwoViewOptions& o) {
  TwoViewData<T> d;
  d.camera = PinholeCamera<double>{535.0, 535.0, 319.5, 239.5, 640, 480};
  Random rng(o.seed);
  Eigen::Vector3d axis(rng.normal(), rng.normal(), rng.normal());
  axis.normalize();
  const double angle = rng.uniform(0.2, 1.0) * o.max_rotation_deg * Constants<double>::deg_to_rad();
  d.cam2_from_cam1.R = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
  if (o.kind != TwoViewKind::PureRotation) {
    Eigen::Vector3d dir(rng.normal(), rng.normal(), 0.3 * rng.normal());
    d.cam2_from_cam1.t = o.baseline_m * dir.normalized();
  }
  const Mat3<double> F = true_fundamental(d.camera, d.cam2_from_cam1);
  d.F = F.cast<T>();
  // Plane for the planar case: normal mostly along the optical axis, through depth (min+max)/2.
  const Eigen::Vector3d plane_n = Eigen::Vector3d(0.2, -0.1, 1.0).normalized();
  const double plane_d = 0.5 * (o.depth_min_m + o.depth_max_m);

  const auto n = static_cast<std::size_t>(o.num_points > 0 ? o.num_points : 0);
  d.points1.reserve(n), d.points2.reserve(n), d.clean1.reserve(n), d.clean2.reserve(n), d.is_inlier.reserve(n);
  const std::size_t num_outliers = static_cast<std::size_t>(std::llround(o.outlier_fraction * double(n)));
  while (d.points1.size() < n) {
    const Vec2<double> u1(rng.uniform(0, d.camera.width - 1), rng.uniform(0, d.camera.height - 1));
    double z = rng.uniform(o.depth_min_m, o.depth_max_m);
    if (o.kind == TwoViewKind::Planar) {
      const Vec3<double> ray = d.camera.ray(u1);
      z = plane_d / plane_n.dot(ray);  // n . (z ray) = plane_d
    }
    const Vec3<double> X1 = d.camera.backproject(u1, z);
    const Vec3<double> X2 = d.cam2_from_cam1.apply(X1);
    if (X2.z() < 0.1) continue;
    const Vec2<double> u2 = d.camera.project(X2);
    if (!d.camera.in_image(u2.x(), u2.y())) continue;
    const std::size_t i = d.points1.size();
    const bool outlier = i < num_outliers;
    Vec2<double> o1 = u1 + o.noise_px * Vec2<double>(rng.normal(), rng.normal());
    Vec2<double> o2 = u2 + o.noise_px * Vec2<double>(rng.normal(), rng.normal());
    if (outlier) {
      // Uniform in image 2, but far enough from the true epipolar line of u1 to be a real outlier.
      const Vec3<double> l = F * Vec3<double>(u1.x(), u1.y(), 1.0);
      for (int tries = 0; tries < 1000; ++tries) {
        o2 = Vec2<double>(rng.uniform(0, d.camera.width - 1), rng.uniform(0, d.camera.height - 1));
        const double dist = std::abs(l.dot(Vec3<double>(o2.x(), o2.y(), 1.0))) / l.head<2>().norm();
        if (dist >= o.min_outlier_px) break;
      }
    }
    d.points1.push_back(o1.cast<T>());
    d.points2.push_back(o2.cast<T>());
    d.clean1.push_back(u1.cast<T>());
    d.clean2.push_back(u2.cast<T>());
    d.is_inlier.push_back(static_cast<std::uint8_t>(!outlier));
    d.num_inliers += !outlier;
  }
  // Shuffle so that outliers are not the first block (Fisher-Yates with the same generator).
  for (std::size_t i = n; i > 1; --i) {
    const std::size_t j = rng.index(static_cast<std::uint32_t>(i));
    std::swap(d.points1[i - 1], d.points1[j]);
    std::swap(d.points2[i - 1], d.points2[j]);
    std::swap(d.clean1[i - 1], d.clean1[j]);
    std::swap(d.clean2[i - 1], d.clean2[j]);
    std::swap(d.is_inlier[i - 1], d.is_inlier[j]);
  }
  return d;
}

/// Frobenius distance between two F up to scale and sign (both normalised first).
template <class T>
double fundamental_difference(const Mat3<T>& a, const Mat3<T>& b) {
  const Mat3<double> x = a.template cast<double>().normalized();
  const Mat3<double> y = b.template cast<double>().normalized();
  return std::min((x - y).norm(), (x + y).norm());
}

}  // namespace dyncull::test
