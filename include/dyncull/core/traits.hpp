/// @file traits.hpp
/// Point traits: how dyncull reads coordinates out of the caller's own point and keypoint types
/// (Eigen vectors, structs with x/y members such as cv::Point2f, structs with a .pt member such as
/// cv::KeyPoint) without copying them. Specialise PointTraits for anything else.
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <type_traits>
#include <utility>

namespace dyncull {

namespace detail {
template <class...> using void_t = void;

template <class P, class = void> struct has_xy_members : std::false_type {};
template <class P>
struct has_xy_members<P, void_t<decltype(std::declval<const P&>().x), decltype(std::declval<const P&>().y)>>
    : std::true_type {};

template <class P, class = void> struct has_z_member : std::false_type {};
template <class P>
struct has_z_member<P, void_t<decltype(std::declval<const P&>().z)>> : std::true_type {};

template <class P, class = void> struct has_pt_member : std::false_type {};
template <class P>
struct has_pt_member<P, void_t<decltype(std::declval<const P&>().pt.x), decltype(std::declval<const P&>().pt.y)>>
    : std::true_type {};

template <class P> struct is_eigen_vec2 : std::false_type {};
template <class S, int O, int R, int C>
struct is_eigen_vec2<Eigen::Matrix<S, 2, 1, O, R, C>> : std::true_type {};
template <class P> struct is_eigen_vec3 : std::false_type {};
template <class S, int O, int R, int C>
struct is_eigen_vec3<Eigen::Matrix<S, 3, 1, O, R, C>> : std::true_type {};
}  // namespace detail

/// Primary template: intentionally undefined members. A specialisation provides
///   using Scalar = ...; static Scalar x(const P&); static Scalar y(const P&);
/// and for 3-D points also static Scalar z(const P&).
template <class P, class Enable = void>
struct PointTraits {
  static constexpr bool specialised = false;
};

/// Eigen 2-vectors.
template <class P>
struct PointTraits<P, std::enable_if_t<detail::is_eigen_vec2<P>::value>> {
  static constexpr bool specialised = true;
  static constexpr int dim = 2;
  using Scalar = typename P::Scalar;
  static Scalar x(const P& p) { return p[0]; }
  static Scalar y(const P& p) { return p[1]; }
};

/// Eigen 3-vectors.
template <class P>
struct PointTraits<P, std::enable_if_t<detail::is_eigen_vec3<P>::value>> {
  static constexpr bool specialised = true;
  static constexpr int dim = 3;
  using Scalar = typename P::Scalar;
  static Scalar x(const P& p) { return p[0]; }
  static Scalar y(const P& p) { return p[1]; }
  static Scalar z(const P& p) { return p[2]; }
};

/// Structs with public x, y (and optionally z) members: cv::Point2f, cv::Point3d, pcl points, POD.
template <class P>
struct PointTraits<P, std::enable_if_t<detail::has_xy_members<P>::value && !detail::is_eigen_vec2<P>::value &&
                                      !detail::is_eigen_vec3<P>::value>> {
  static constexpr bool specialised = true;
  static constexpr int dim = detail::has_z_member<P>::value ? 3 : 2;
  using Scalar = std::decay_t<decltype(std::declval<const P&>().x)>;
  static Scalar x(const P& p) { return p.x; }
  static Scalar y(const P& p) { return p.y; }
  template <class Q = P, std::enable_if_t<detail::has_z_member<Q>::value, int> = 0>
  static Scalar z(const Q& p) {
    return p.z;
  }
};

/// Keypoints with a .pt member (cv::KeyPoint and look-alikes): the keypoint's image position.
template <class P>
struct PointTraits<P, std::enable_if_t<detail::has_pt_member<P>::value && !detail::has_xy_members<P>::value>> {
  static constexpr bool specialised = true;
  static constexpr int dim = 2;
  using Scalar = std::decay_t<decltype(std::declval<const P&>().pt.x)>;
  static Scalar x(const P& p) { return p.pt.x; }
  static Scalar y(const P& p) { return p.pt.y; }
};

/// True when P can be read as a point.
template <class P>
constexpr bool is_point_v = PointTraits<std::decay_t<P>>::specialised;

/// Checked accessors: a readable compile error instead of a template storm.
template <class T = void, class P>
auto point_x(const P& p) {
  static_assert(is_point_v<P>, "dyncull: no PointTraits for this type; give it x/y members, a .pt member, "
                               "or specialise dyncull::PointTraits");
  using S = typename PointTraits<P>::Scalar;
  using Out = std::conditional_t<std::is_void<T>::value, S, T>;
  return static_cast<Out>(PointTraits<P>::x(p));
}
template <class T = void, class P>
auto point_y(const P& p) {
  static_assert(is_point_v<P>, "dyncull: no PointTraits for this type; give it x/y members, a .pt member, "
                               "or specialise dyncull::PointTraits");
  using S = typename PointTraits<P>::Scalar;
  using Out = std::conditional_t<std::is_void<T>::value, S, T>;
  return static_cast<Out>(PointTraits<P>::y(p));
}
template <class T = void, class P>
auto point_z(const P& p) {
  static_assert(is_point_v<P> && PointTraits<P>::dim == 3, "dyncull: point type has no z coordinate");
  using S = typename PointTraits<P>::Scalar;
  using Out = std::conditional_t<std::is_void<T>::value, S, T>;
  return static_cast<Out>(PointTraits<P>::z(p));
}

/// Point as an Eigen 2-vector of scalar T.
template <class T, class P>
Eigen::Matrix<T, 2, 1> to_vec2(const P& p) {
  return Eigen::Matrix<T, 2, 1>(point_x<T>(p), point_y<T>(p));
}
/// Point as an Eigen 3-vector of scalar T.
template <class T, class P>
Eigen::Matrix<T, 3, 1> to_vec3(const P& p) {
  return Eigen::Matrix<T, 3, 1>(point_x<T>(p), point_y<T>(p), point_z<T>(p));
}

/// Containers of points: anything with size() and operator[] (std::vector, std::array, spans).
template <class C>
using container_point_t = std::decay_t<decltype(std::declval<const C&>()[std::size_t{0}])>;

template <class C>
constexpr bool is_point_container_v = is_point_v<container_point_t<C>>;

}  // namespace dyncull
