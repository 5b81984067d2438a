/// @file epipolar.hpp
/// Epipolar lines and distances for a fundamental matrix F (x2^T F x1 = 0): the point-to-line distance of
/// DFD-SLAM (Qian et al. 2024) eq. 3, D = |p2^T F p1| / sqrt(X^2 + Y^2), (X, Y, Z) = F p1; symmetric
/// (Hartley & Zisserman eq. 11.10) and Sampson (HZ eq. 11.9).
#pragma once

#include "dyncull/core/status.hpp"
#include "dyncull/core/traits.hpp"
#include "dyncull/core/types.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <utility>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace dyncull {

// ---------------------------------------------------------------------------------------------------------
// Single correspondence. p1 in image 1, p2 in image 2, pixels; any point type with PointTraits.
// ---------------------------------------------------------------------------------------------------------

/// Epipolar line l2 = F p1 in image 2 as (a, b, c) with a x + b y + c = 0 (not normalised).
template <class T, class P1>
Vec3<T> epipolar_line(const Mat3<T>& F, const P1& p1) {
  return F * Vec3<T>(point_x<T>(p1), point_y<T>(p1), T(1));
}

/// Epipolar line l1 = F^T p2 in image 1.
template <class T, class P2>
Vec3<T> epipolar_line_in_first(const Mat3<T>& F, const P2& p2) {
  return F.transpose() * Vec3<T>(point_x<T>(p2), point_y<T>(p2), T(1));
}

/// DFD-SLAM eq. 3: distance in pixels of p2 to the line F p1. NaN when the line is undefined
/// (p1 at the epipole, X = Y = 0) or the input is not finite.
template <class T, class P1, class P2>
T epipolar_distance(const Mat3<T>& F, const P1& p1, const P2& p2) {
  using std::abs;
  using std::sqrt;
  const Vec3<T> l = epipolar_line(F, p1);
  const T num = point_x<T>(p2) * l[0] + point_y<T>(p2) * l[1] + l[2];
  const T norm_sq = l[0] * l[0] + l[1] * l[1];
  if (!(norm_sq > T(0))) return Constants<T>::nan();
  return abs(num) / sqrt(norm_sq);
}

/// Symmetric epipolar distance, squared: d(p2, F p1)^2 + d(p1, F^T p2)^2 (HZ eq. 11.10), px^2.
template <class T, class P1, class P2>
T symmetric_epipolar_distance_sq(const Mat3<T>& F, const P1& p1, const P2& p2) {
  const Vec3<T> l2 = epipolar_line(F, p1);
  const Vec3<T> l1 = epipolar_line_in_first(F, p2);
  const T num = point_x<T>(p2) * l2[0] + point_y<T>(p2) * l2[1] + l2[2];
  const T n2 = l2[0] * l2[0] + l2[1] * l2[1];
  const T n1 = l1[0] * l1[0] + l1[1] * l1[1];
  if (!(n1 > T(0)) || !(n2 > T(0))) return Constants<T>::nan();
  return num * num * (T(1) / n1 + T(1) / n2);
}

/// Sampson distance, squared: (p2^T F p1)^2 / ((F p1)_1^2 + (F p1)_2^2 + (F^T p2)_1^2 + (F^T p2)_2^2)
/// (HZ eq. 11.9), px^2: the first-order geometric reprojection error of the correspondence.
template <class T, class P1, class P2>
T sampson_distance_sq(const Mat3<T>& F, const P1& p1, const P2& p2) {
  const Vec3<T> l2 = epipolar_line(F, p1);
  const Vec3<T> l1 = epipolar_line_in_first(F, p2);
  const T num = point_x<T>(p2) * l2[0] + point_y<T>(p2) * l2[1] + l2[2];
  const T den = l2[0] * l2[0] + l2[1] * l2[1] + l1[0] * l1[0] + l1[1] * l1[1];
  if (!(den > T(0))) return Constants<T>::nan();
  return num * num / den;
}

// ---------------------------------------------------------------------------------------------------------
// Structure-of-arrays kernels (contiguous x1, y1, x2, y2). Eigen array expressions so that they vectorise
// at -O2 too (g++ 12 auto-vectorises nothing at -O2). Used by the batch API and the F-RANSAC estimator.
// ---------------------------------------------------------------------------------------------------------
namespace detail {
template <class T> using ArrayMap = Eigen::Map<Eigen::Array<T, Eigen::Dynamic, 1>>;
template <class T> using ConstArrayMap = Eigen::Map<const Eigen::Array<T, Eigen::Dynamic, 1>>;
}  // namespace detail

/// Which distance a batch call writes.
enum class EpipolarDistance : std::uint8_t {
  PointToLine,       ///< DFD-SLAM eq. 3, px (one-sided, in image 2)
  PointToLineSq,     ///< its square, px^2
  SymmetricSq,       ///< HZ eq. 11.10, px^2
  SampsonSq,         ///< HZ eq. 11.9, px^2
};

/// Distances for n correspondences stored as contiguous arrays; `out` holds n values.
/// Where the relevant line norm is zero the value is NaN or +inf (undefined line).
template <class T>
void epipolar_distances_soa(const Mat3<T>& F, const T* x1, const T* y1, const T* x2, const T* y2, std::size_t n,
                            T* out, EpipolarDistance kind = EpipolarDistance::PointToLine) {
  if (n == 0) return;
  const auto N = static_cast<Eigen::Index>(n);
  const detail::ConstArrayMap<T> u1(x1, N), v1(y1, N), u2(x2, N), v2(y2, N);
  detail::ArrayMap<T> o(out, N);
  // l2 = F p1 (X, Y, Z); the residual p2^T F p1 = x2 X + y2 Y + Z.
  const auto X = F(0, 0) * u1 + F(0, 1) * v1 + F(0, 2);
  const auto Y = F(1, 0) * u1 + F(1, 1) * v1 + F(1, 2);
  const auto Z = F(2, 0) * u1 + F(2, 1) * v1 + F(2, 2);
  const auto num = u2 * X + v2 * Y + Z;
  switch (kind) {
    case EpipolarDistance::PointToLine:
      o = num.abs() / (X.square() + Y.square()).sqrt();
      break;
    case EpipolarDistance::PointToLineSq:
      o = num.square() / (X.square() + Y.square());
      break;
    case EpipolarDistance::SymmetricSq: {
      const auto A = F(0, 0) * u2 + F(1, 0) * v2 + F(2, 0);  // (F^T p2)_1
      const auto B = F(0, 1) * u2 + F(1, 1) * v2 + F(2, 1);  // (F^T p2)_2
      o = num.square() * ((X.square() + Y.square()).inverse() + (A.square() + B.square()).inverse());
      break;
    }
    case EpipolarDistance::SampsonSq: {
      const auto A = F(0, 0) * u2 + F(1, 0) * v2 + F(2, 0);
      const auto B = F(0, 1) * u2 + F(1, 1) * v2 + F(2, 1);
      o = num.square() / (X.square() + Y.square() + A.square() + B.square());
      break;
    }
  }
}

/// Labels without sqrt or division: out[i] = 1 when the DFD-SLAM eq. 3 distance exceeds `threshold_px`,
/// i.e. (p2^T F p1)^2 > t^2 (X^2 + Y^2). Non-finite values give 0 (no evidence of motion). Returns the count of 1s.
template <class T>
std::size_t label_epipolar_soa(const Mat3<T>& F, const T* x1, const T* y1, const T* x2, const T* y2, std::size_t n,
                               T threshold_px, std::uint8_t* out) {
  constexpr std::size_t kBlock = 256;
  alignas(32) T lhs[kBlock];
  alignas(32) T rhs[kBlock];
  const T t2 = threshold_px * threshold_px;
  std::size_t count = 0;
  for (std::size_t begin = 0; begin < n; begin += kBlock) {
    const std::size_t len = n - begin < kBlock ? n - begin : kBlock;
    const auto N = static_cast<Eigen::Index>(len);
    const detail::ConstArrayMap<T> u1(x1 + begin, N), v1(y1 + begin, N), u2(x2 + begin, N), v2(y2 + begin, N);
    const auto X = F(0, 0) * u1 + F(0, 1) * v1 + F(0, 2);
    const auto Y = F(1, 0) * u1 + F(1, 1) * v1 + F(1, 2);
    const auto Z = F(2, 0) * u1 + F(2, 1) * v1 + F(2, 2);
    detail::ArrayMap<T>(lhs, N) = (u2 * X + v2 * Y + Z).square();
    detail::ArrayMap<T>(rhs, N) = t2 * (X.square() + Y.square());
    // Local pointer copies: the uint8 store must not alias the bound, or g++ reloads it every iteration.
    std::uint8_t* dst = out + begin;
    for (std::size_t i = 0; i < len; ++i) {
      const std::uint8_t v = static_cast<std::uint8_t>(lhs[i] > rhs[i]);
      dst[i] = v;
      count += v;
    }
  }
  return count;
}

// ---------------------------------------------------------------------------------------------------------
// Batch over the caller's point containers (std::vector<cv::Point2f>, std::vector<Vec2<T>>, keypoints ...).
// eq. 3 on packed (x, y) containers runs in one pass over them; otherwise points are copied in blocks
// of 256 into stack arrays and the SoA kernels run. No heap allocation either way.
// ---------------------------------------------------------------------------------------------------------
namespace detail {
template <class C, class = void> struct has_data_member : std::false_type {};
template <class C>
struct has_data_member<C, void_t<decltype(std::declval<const C&>().data())>> : std::true_type {};

/// True when C stores its points contiguously as (x, y) pairs of T: std::vector / std::array of Eigen
/// 2-vectors of T, or of standard-layout {T x; T y;} structs such as cv::Point_<T>.
template <class T, class C>
constexpr bool is_packed_xy() {
  using P = container_point_t<C>;
  if constexpr (!has_data_member<C>::value) {
    return false;
  } else if constexpr (!std::is_same<std::remove_cv_t<std::remove_pointer_t<decltype(std::declval<const C&>().data())>>,
                                     P>::value ||
                       sizeof(P) != 2 * sizeof(T)) {
    return false;
  } else if constexpr (is_eigen_vec2<P>::value) {
    return std::is_same<typename P::Scalar, T>::value;
  } else if constexpr (has_xy_members<P>::value && std::is_standard_layout<P>::value) {
    return std::is_same<std::decay_t<decltype(std::declval<const P&>().x)>, T>::value &&
           std::is_same<std::decay_t<decltype(std::declval<const P&>().y)>, T>::value && offsetof(P, x) == 0 &&
           offsetof(P, y) == sizeof(T);
  } else {
    return false;
  }
}

/// Packed (x, y) pairs to two arrays. With SSE2 (every x86-64) two loads and two shuffles per 4 floats /
/// 2 doubles: g++ 12 does not vectorise the plain loop at -O2, where it cost as much as the arithmetic.
template <class T>
void deinterleave(const T* xy, std::size_t len, T* x, T* y) {
  std::size_t i = 0;
#if defined(__SSE2__)
  if constexpr (std::is_same<T, float>::value) {
    for (; i + 4 <= len; i += 4) {
      const __m128 a = _mm_loadu_ps(xy + 2 * i);      // x0 y0 x1 y1
      const __m128 b = _mm_loadu_ps(xy + 2 * i + 4);  // x2 y2 x3 y3
      _mm_storeu_ps(x + i, _mm_shuffle_ps(a, b, _MM_SHUFFLE(2, 0, 2, 0)));
      _mm_storeu_ps(y + i, _mm_shuffle_ps(a, b, _MM_SHUFFLE(3, 1, 3, 1)));
    }
  } else if constexpr (std::is_same<T, double>::value) {
    for (; i + 2 <= len; i += 2) {
      const __m128d a = _mm_loadu_pd(xy + 2 * i);      // x0 y0
      const __m128d b = _mm_loadu_pd(xy + 2 * i + 2);  // x1 y1
      _mm_storeu_pd(x + i, _mm_unpacklo_pd(a, b));
      _mm_storeu_pd(y + i, _mm_unpackhi_pd(a, b));
    }
  }
#endif
  for (; i < len; ++i) {
    x[i] = xy[2 * i];
    y[i] = xy[2 * i + 1];
  }
}

template <class T, class C>
void load_block(const C& points, std::size_t begin, std::size_t len, T* x, T* y) {
  if constexpr (is_packed_xy<T, C>()) {
    deinterleave(reinterpret_cast<const T*>(points.data() + begin), len, x, y);
  } else {
    for (std::size_t i = 0; i < len; ++i) {
      const auto& p = points[begin + i];
      x[i] = point_x<T>(p);
      y[i] = point_y<T>(p);
    }
  }
}

/// DFD-SLAM eq. 3 straight from packed (x, y) pairs, in one pass: the block copy of for_each_soa_block
/// cost as much as the arithmetic (double, 1000 points: 0.62x -> 0.40x of OpenCV's epilines + distance
/// at -O3, docs/benchmarks.md). Same operations in the same order as epipolar_distances_soa (tested equal).
template <class T>
void point_to_line_packed(const Mat3<T>& F, const T* xy1, const T* xy2, std::size_t n, T* out) {
  std::size_t i = 0;
#if defined(__SSE2__)
  if constexpr (std::is_same<T, double>::value) {
    const __m128d f00 = _mm_set1_pd(F(0, 0)), f01 = _mm_set1_pd(F(0, 1)), f02 = _mm_set1_pd(F(0, 2));
    const __m128d f10 = _mm_set1_pd(F(1, 0)), f11 = _mm_set1_pd(F(1, 1)), f12 = _mm_set1_pd(F(1, 2));
    const __m128d f20 = _mm_set1_pd(F(2, 0)), f21 = _mm_set1_pd(F(2, 1)), f22 = _mm_set1_pd(F(2, 2));
    const __m128d abs_mask = _mm_castsi128_pd(_mm_set1_epi64x(0x7fffffffffffffffLL));
    for (; i + 2 <= n; i += 2) {
      const __m128d a = _mm_loadu_pd(xy1 + 2 * i), b = _mm_loadu_pd(xy1 + 2 * i + 2);
      const __m128d c = _mm_loadu_pd(xy2 + 2 * i), d = _mm_loadu_pd(xy2 + 2 * i + 2);
      const __m128d u1 = _mm_unpacklo_pd(a, b), v1 = _mm_unpackhi_pd(a, b);
      const __m128d u2 = _mm_unpacklo_pd(c, d), v2 = _mm_unpackhi_pd(c, d);
      const __m128d X = _mm_add_pd(_mm_add_pd(_mm_mul_pd(f00, u1), _mm_mul_pd(f01, v1)), f02);
      const __m128d Y = _mm_add_pd(_mm_add_pd(_mm_mul_pd(f10, u1), _mm_mul_pd(f11, v1)), f12);
      const __m128d Z = _mm_add_pd(_mm_add_pd(_mm_mul_pd(f20, u1), _mm_mul_pd(f21, v1)), f22);
      const __m128d num = _mm_add_pd(_mm_add_pd(_mm_mul_pd(u2, X), _mm_mul_pd(v2, Y)), Z);
      const __m128d q = _mm_add_pd(_mm_mul_pd(X, X), _mm_mul_pd(Y, Y));
      _mm_storeu_pd(out + i, _mm_div_pd(_mm_and_pd(num, abs_mask), _mm_sqrt_pd(q)));
    }
  } else if constexpr (std::is_same<T, float>::value) {
    const __m128 f00 = _mm_set1_ps(F(0, 0)), f01 = _mm_set1_ps(F(0, 1)), f02 = _mm_set1_ps(F(0, 2));
    const __m128 f10 = _mm_set1_ps(F(1, 0)), f11 = _mm_set1_ps(F(1, 1)), f12 = _mm_set1_ps(F(1, 2));
    const __m128 f20 = _mm_set1_ps(F(2, 0)), f21 = _mm_set1_ps(F(2, 1)), f22 = _mm_set1_ps(F(2, 2));
    const __m128 abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
    for (; i + 4 <= n; i += 4) {
      const __m128 a = _mm_loadu_ps(xy1 + 2 * i), b = _mm_loadu_ps(xy1 + 2 * i + 4);
      const __m128 c = _mm_loadu_ps(xy2 + 2 * i), d = _mm_loadu_ps(xy2 + 2 * i + 4);
      const __m128 u1 = _mm_shuffle_ps(a, b, _MM_SHUFFLE(2, 0, 2, 0));
      const __m128 v1 = _mm_shuffle_ps(a, b, _MM_SHUFFLE(3, 1, 3, 1));
      const __m128 u2 = _mm_shuffle_ps(c, d, _MM_SHUFFLE(2, 0, 2, 0));
      const __m128 v2 = _mm_shuffle_ps(c, d, _MM_SHUFFLE(3, 1, 3, 1));
      const __m128 X = _mm_add_ps(_mm_add_ps(_mm_mul_ps(f00, u1), _mm_mul_ps(f01, v1)), f02);
      const __m128 Y = _mm_add_ps(_mm_add_ps(_mm_mul_ps(f10, u1), _mm_mul_ps(f11, v1)), f12);
      const __m128 Z = _mm_add_ps(_mm_add_ps(_mm_mul_ps(f20, u1), _mm_mul_ps(f21, v1)), f22);
      const __m128 num = _mm_add_ps(_mm_add_ps(_mm_mul_ps(u2, X), _mm_mul_ps(v2, Y)), Z);
      const __m128 q = _mm_add_ps(_mm_mul_ps(X, X), _mm_mul_ps(Y, Y));
      _mm_storeu_ps(out + i, _mm_div_ps(_mm_and_ps(num, abs_mask), _mm_sqrt_ps(q)));
    }
  }
#endif
  for (; i < n; ++i) {
    const T u1 = xy1[2 * i], v1 = xy1[2 * i + 1], u2 = xy2[2 * i], v2 = xy2[2 * i + 1];
    const T X = F(0, 0) * u1 + F(0, 1) * v1 + F(0, 2);
    const T Y = F(1, 0) * u1 + F(1, 1) * v1 + F(1, 2);
    const T Z = F(2, 0) * u1 + F(2, 1) * v1 + F(2, 2);
    out[i] = std::abs(u2 * X + v2 * Y + Z) / std::sqrt(X * X + Y * Y);
  }
}

template <class T, class C1, class C2, class Fn>
Status for_each_soa_block(const C1& points1, const C2& points2, Fn&& fn) {
  static_assert(is_point_container_v<C1> && is_point_container_v<C2>,
                "dyncull: point containers need size(), operator[] and points with PointTraits");
  const std::size_t n = points1.size();
  if (points2.size() != n) return Status::InvalidInput;
  constexpr std::size_t kBlock = 256;
  alignas(32) T x1[kBlock];
  alignas(32) T y1[kBlock];
  alignas(32) T x2[kBlock];
  alignas(32) T y2[kBlock];
  for (std::size_t begin = 0; begin < n; begin += kBlock) {
    const std::size_t len = n - begin < kBlock ? n - begin : kBlock;
    load_block(points1, begin, len, x1, y1);
    load_block(points2, begin, len, x2, y2);
    fn(begin, len, x1, y1, x2, y2);
  }
  return Status::Ok;
}

/// F divided by a power of two near its largest magnitude (exact: every distance is invariant to the
/// scale of F, and power-of-two scaling rounds nothing), so that X^2 + Y^2 neither overflows for a
/// huge F nor underflows for a tiny one. NonFinite for NaN / Inf entries, Degenerate for F = 0 (no
/// epipolar geometry: every line is undefined).
template <class T>
Status normalised_fundamental(const Mat3<T>& F, Mat3<T>* out) {
  if (!F.allFinite()) return Status::NonFinite;
  const T m = F.cwiseAbs().maxCoeff();
  if (!(m > T(0))) return Status::Degenerate;
  int exponent = 0;
  std::frexp(m, &exponent);
  // Element-wise ldexp: 2^-exponent itself is not representable for the largest and smallest m.
  *out = F.unaryExpr([exponent](T x) { return std::ldexp(x, -exponent); });
  return Status::Ok;
}
}  // namespace detail

/// Batch distances of `kind` for corresponding containers; `out` must hold points1.size() values.
/// Returns InvalidInput (writing nothing) when the sizes differ, NonFinite when F has a NaN / Inf
/// entry and Degenerate when F = 0 (every value NaN then: no line is defined). The distances do not depend on the scale
/// of F, which is normalised first. A value is NaN (or +inf) only where its line is undefined: a
/// non-finite point or p1 at the epipole. Finite coordinates so large that X^2 + Y^2 overflows (beyond
/// ~1e19 px in float, ~1e154 in double; no image has them) give an unspecified NaN, +inf or 0.
template <class T, class C1, class C2>
Status epipolar_distances(const Mat3<T>& F_in, const C1& points1, const C2& points2, T* out,
                          EpipolarDistance kind = EpipolarDistance::PointToLine) {
  if (points1.size() != points2.size()) return Status::InvalidInput;
  Mat3<T> F;
  const Status fs = detail::normalised_fundamental(F_in, &F);
  if (fs != Status::Ok) {
    std::fill(out, out + points1.size(), Constants<T>::nan());
    return fs;
  }
  if constexpr (detail::is_packed_xy<T, C1>() && detail::is_packed_xy<T, C2>()) {
    if (kind == EpipolarDistance::PointToLine) {
      if (points1.size() == 0) return Status::Ok;
      detail::point_to_line_packed(F, reinterpret_cast<const T*>(points1.data()),
                                   reinterpret_cast<const T*>(points2.data()), points1.size(), out);
      return Status::Ok;
    }
  }
  return detail::for_each_soa_block<T>(
      points1, points2,
      [&](std::size_t begin, std::size_t len, const T* x1, const T* y1, const T* x2, const T* y2) {
        epipolar_distances_soa(F, x1, y1, x2, y2, len, out + begin, kind);
      });
}

/// As above, resizing `out` to points1.size().
template <class T, class C1, class C2>
Status epipolar_distances(const Mat3<T>& F, const C1& points1, const C2& points2, std::vector<T>* out,
                          EpipolarDistance kind = EpipolarDistance::PointToLine) {
  if (points1.size() != points2.size()) return Status::InvalidInput;
  out->resize(points1.size());
  return epipolar_distances(F, points1, points2, out->data(), kind);
}

/// Sampson distances squared (px^2) for corresponding containers.
template <class T, class C1, class C2>
Status sampson_distances_sq(const Mat3<T>& F, const C1& points1, const C2& points2, std::vector<T>* out) {
  return epipolar_distances(F, points1, points2, out, EpipolarDistance::SampsonSq);
}

/// Symmetric epipolar distances squared (px^2) for corresponding containers.
template <class T, class C1, class C2>
Status symmetric_epipolar_distances_sq(const Mat3<T>& F, const C1& points1, const C2& points2,
                                       std::vector<T>* out) {
  return epipolar_distances(F, points1, points2, out, EpipolarDistance::SymmetricSq);
}

/// Thresholded labels (1 = DFD-SLAM eq. 3 distance above `threshold_px`) for corresponding containers,
/// without sqrt or division. `labels` holds points1.size() bytes; `count` (optional) receives the number of 1s.
/// Statuses as epipolar_distances (F normalised first), and InvalidInput for a threshold that is negative
/// or not finite (labels all 0 on any failure but a size mismatch). Non-finite points get 0.
template <class T, class C1, class C2>
Status label_epipolar(const Mat3<T>& F_in, const C1& points1, const C2& points2, T threshold_px,
                      std::uint8_t* labels, std::size_t* count = nullptr) {
  if (count) *count = 0;
  if (points1.size() != points2.size()) return Status::InvalidInput;
  Mat3<T> F;
  Status fs = detail::normalised_fundamental(F_in, &F);
  if (!(threshold_px >= T(0)) || !std::isfinite(threshold_px)) fs = Status::InvalidInput;
  if (fs != Status::Ok) {
    std::fill(labels, labels + points1.size(), std::uint8_t{0});
    return fs;
  }
  std::size_t total = 0;
  const Status s = detail::for_each_soa_block<T>(
      points1, points2,
      [&](std::size_t begin, std::size_t len, const T* x1, const T* y1, const T* x2, const T* y2) {
        total += label_epipolar_soa(F, x1, y1, x2, y2, len, threshold_px, labels + begin);
      });
  if (count) *count = total;
  return s;
}

}  // namespace dyncull
