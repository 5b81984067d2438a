/// @file camera.hpp
/// Pinhole camera without distortion (TUM RGB-D images are given undistorted or nearly so):
/// u = fx x/z + cx, v = fy y/z + cy, and its inverse for a known depth (Zhu et al. 2024, eq. 5-6, with fy
/// for y where the paper's eq. 6 has a typo dividing by fx).
/// validate() refuses intrinsics that no camera has (bounds relative to the image size).
#pragma once

#include "dyncull/core/camera_bounds.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/core/types.hpp"

#include <cmath>
#include <string>

namespace dyncull {

template <class T>
struct PinholeCamera {
  T fx = T(525);
  T fy = T(525);
  T cx = T(319.5);
  T cy = T(239.5);
  int width = 640;   ///< image width in pixels (used for bounds checks only)
  int height = 480;  ///< image height in pixels

  /// Pixel of a camera-frame point. z <= 0 gives non-finite or mirrored pixels: check z first.
  Vec2<T> project(const Vec3<T>& p_cam) const {
    const T inv_z = T(1) / p_cam.z();
    return Vec2<T>(fx * p_cam.x() * inv_z + cx, fy * p_cam.y() * inv_z + cy);
  }
  /// Camera-frame point of pixel (u, v) at depth z (metres along the optical axis).
  Vec3<T> backproject(const Vec2<T>& uv, T z) const {
    return Vec3<T>((uv.x() - cx) * z / fx, (uv.y() - cy) * z / fy, z);
  }
  /// Unit-depth ray (x/z, y/z, 1) of a pixel.
  Vec3<T> ray(const Vec2<T>& uv) const { return Vec3<T>((uv.x() - cx) / fx, (uv.y() - cy) / fy, T(1)); }
  /// True when (u, v) lies inside the image, at least `border` pixels from every edge.
  bool in_image(T u, T v, T border = T(0)) const {
    // T(width) - 1, not T(width - 1): no int overflow for a bogus width of INT_MIN.
    return u >= border && v >= border && u <= T(width) - T(1) - border && v <= T(height) - T(1) - border;
  }
  Mat3<T> K() const {
    Mat3<T> k;
    k << fx, T(0), cx, T(0), fy, cy, T(0), T(0), T(1);
    return k;
  }
  /// Bounds of a camera that exists (CameraBounds in core/camera_bounds.hpp).
  static constexpr double kMinFocalPerSide = CameraBounds::kMinFocalPerSide;
  static constexpr double kMaxFocalPerSide = CameraBounds::kMaxFocalPerSide;

  /// Ok, or InvalidInput naming the first intrinsic no camera has (check_intrinsics): an image size
  /// outside [1, 100000], a non-finite or non-positive focal length, a focal length or principal point
  /// outside CameraBounds.
  Status validate(std::string* reason = nullptr) const {
    return check_intrinsics(static_cast<double>(fx), static_cast<double>(fy), static_cast<double>(cx),
                            static_cast<double>(cy), width, height, reason);
  }
  /// validate() == Ok.
  bool valid() const { return validate() == Status::Ok; }
  template <class U> PinholeCamera<U> cast() const {
    return PinholeCamera<U>{U(fx), U(fy), U(cx), U(cy), width, height};
  }

  /// TUM RGB-D freiburg3 intrinsics (the walking / sitting sequences).
  static PinholeCamera tum_fr3() { return PinholeCamera{T(535.4), T(539.2), T(320.1), T(247.6), 640, 480}; }
};

}  // namespace dyncull
