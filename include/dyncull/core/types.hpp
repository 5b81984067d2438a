/// @file types.hpp
/// Scalar-templated Eigen aliases and the rigid transform type used across dyncull.
/// Frames are named target_from_source (COLMAP): `cam_from_world.apply(p_world)` gives p_cam.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>

namespace dyncull {

template <class T> using Vec2 = Eigen::Matrix<T, 2, 1>;
template <class T> using Vec3 = Eigen::Matrix<T, 3, 1>;
template <class T> using Vec4 = Eigen::Matrix<T, 4, 1>;
template <class T> using Mat2 = Eigen::Matrix<T, 2, 2>;
template <class T> using Mat3 = Eigen::Matrix<T, 3, 3>;
template <class T> using Mat4 = Eigen::Matrix<T, 4, 4>;
template <class T> using Mat34 = Eigen::Matrix<T, 3, 4>;
template <class T> using Quat = Eigen::Quaternion<T>;

/// Numeric constants per scalar type (manif/Sophus style): use these, not literals, for tolerances.
template <class T>
struct Constants {
  static_assert(std::is_floating_point<T>::value, "dyncull scalars are float or double");
  static constexpr T epsilon() noexcept { return std::numeric_limits<T>::epsilon(); }
  /// 100 machine epsilons: "zero" for quantities of order one.
  static constexpr T small() noexcept { return T(100) * std::numeric_limits<T>::epsilon(); }
  static constexpr T pi() noexcept { return T(3.14159265358979323846264338327950288); }
  static constexpr T deg_to_rad() noexcept { return pi() / T(180); }
  static constexpr T rad_to_deg() noexcept { return T(180) / pi(); }
  static constexpr T nan() noexcept { return std::numeric_limits<T>::quiet_NaN(); }
};

/// Rigid transform b_from_a: x_b = R x_a + t. Plain data; compose with operator*.
template <class T>
struct Rigid3 {
  Mat3<T> R = Mat3<T>::Identity();
  Vec3<T> t = Vec3<T>::Zero();

  static Rigid3 identity() { return Rigid3{}; }
  Vec3<T> apply(const Vec3<T>& x) const { return R * x + t; }
  Rigid3 inverse() const {
    Rigid3 inv;
    inv.R = R.transpose();
    inv.t = -(inv.R * t);
    return inv;
  }
  /// (c_from_b * b_from_a) = c_from_a.
  Rigid3 operator*(const Rigid3& b_from_a) const {
    Rigid3 out;
    out.R = R * b_from_a.R;
    out.t = R * b_from_a.t + t;
    return out;
  }
  Mat4<T> matrix() const {
    Mat4<T> m = Mat4<T>::Identity();
    m.template topLeftCorner<3, 3>() = R;
    m.template topRightCorner<3, 1>() = t;
    return m;
  }
  /// Camera centre in the source frame when this is cam_from_world: c = -R^T t.
  Vec3<T> centre() const { return -(R.transpose() * t); }
  template <class U> Rigid3<U> cast() const {
    Rigid3<U> out;
    out.R = R.template cast<U>();
    out.t = t.template cast<U>();
    return out;
  }
  bool all_finite() const { return R.allFinite() && t.allFinite(); }
};

/// Similarity b_from_a: x_b = s R x_a + t (monocular alignment).
template <class T>
struct Sim3 {
  T scale = T(1);
  Mat3<T> R = Mat3<T>::Identity();
  Vec3<T> t = Vec3<T>::Zero();
  Vec3<T> apply(const Vec3<T>& x) const { return scale * (R * x) + t; }
};

/// Rotation angle of R in radians, robust near 0 and pi (clamped acos of the trace).
template <class T>
T rotation_angle(const Mat3<T>& R) {
  using std::acos;
  T c = (R.trace() - T(1)) / T(2);
  c = c > T(1) ? T(1) : (c < T(-1) ? T(-1) : c);
  return acos(c);
}

template <class T>
bool is_finite(T v) noexcept {
  return std::isfinite(v);
}

}  // namespace dyncull
