/// @file rigid.hpp
/// Closed-form rigid (SE(3)) or similarity (Sim(3)) alignment of corresponding 3-D points:
/// Umeyama 1991 eq. 34-42 / Kabsch with the reflection fix (as TUM evaluate_ate.py `align`), weighted.
#pragma once

#include "dyncull/core/status.hpp"
#include "dyncull/core/types.hpp"

#include <Eigen/Core>
#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <type_traits>
#include <utility>

namespace dyncull {

struct AlignmentOptions {
  /// Estimate a similarity (monocular trajectories); when false the scale is exactly 1.
  bool estimate_scale = false;

  /// Always Ok: the only field is a flag. Present so every options struct has the same shape.
  Status validate(std::string* reason = nullptr) const {
    if (reason) reason->clear();
    return Status::Ok;
  }
};

template <class T>
struct AlignmentResult {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }
  /// dst ~ scale * R * src + t. scale == 1 unless options.estimate_scale.
  Sim3<T> dst_from_src;
  /// Number of columns that entered the fit (weight > 0).
  std::size_t num_points = 0;
  /// The rotation and translation of dst_from_src (the scale is dropped; use with estimate_scale = false).
  Rigid3<T> rigid() const {
    Rigid3<T> out;
    out.R = dst_from_src.R;
    out.t = dst_from_src.t;
    return out;
  }
};

/// One-pass accumulator of the weighted first and second moments of point pairs (src, dst), shifted by
/// a reference pair to avoid cancellation. umeyama() and ICP feed it; solve() is Umeyama's closed form.
template <class T>
struct AlignmentAccumulator {
  Vec3<T> s0 = Vec3<T>::Zero(), d0 = Vec3<T>::Zero();  ///< reference shift (any pair near the data)
  Vec3<T> sum_s = Vec3<T>::Zero(), sum_d = Vec3<T>::Zero();
  Mat3<T> sum_ds = Mat3<T>::Zero();
  T sum_ss = T(0);
  T sum_w = T(0);
  std::size_t used = 0;  ///< pairs with positive weight

  AlignmentAccumulator() = default;
  AlignmentAccumulator(const Vec3<T>& src_ref, const Vec3<T>& dst_ref) : s0(src_ref), d0(dst_ref) {}
  void reset(const Vec3<T>& src_ref, const Vec3<T>& dst_ref) { *this = AlignmentAccumulator(src_ref, dst_ref); }

  template <class A, class B>
  void add(const Eigen::MatrixBase<A>& src, const Eigen::MatrixBase<B>& dst) {
    const Vec3<T> s = src - s0;
    const Vec3<T> d = dst - d0;
    sum_s += s;
    sum_d += d;
    sum_ds.noalias() += d * s.transpose();
    sum_ss += s.squaredNorm();
    sum_w += T(1);
    ++used;
  }
  template <class A, class B>
  void add(const Eigen::MatrixBase<A>& src, const Eigen::MatrixBase<B>& dst, T w) {
    const Vec3<T> s = src - s0;
    const Vec3<T> d = dst - d0;
    const Vec3<T> ws = w * s;
    sum_s += ws;
    sum_d += w * d;
    sum_ds.noalias() += d * ws.transpose();
    sum_ss += ws.dot(s);
    sum_w += w;
    used += (w > T(0));
  }
  /// Least-squares dst_from_src of the accumulated pairs (statuses as umeyama()).
  AlignmentResult<T> solve(const AlignmentOptions& options = {}) const;
};

namespace detail {
/// umeyama()'s second pass, out of line (only reached when the first pass's moments overflowed).
template <class DA, class DB>
__attribute__((noinline, cold)) AlignmentResult<typename DA::Scalar> umeyama_rescaled(
    const Eigen::MatrixBase<DA>& src, const Eigen::MatrixBase<DB>& dst, const AlignmentOptions& options,
    const typename DA::Scalar* weights, AlignmentResult<typename DA::Scalar> result) {
  using T = typename DA::Scalar;
  const Eigen::Index n = src.cols();
  // Overflowing moments of finite data: align src / 2^a and dst / 2^b, each scaled
  // by its own largest magnitude (powers of two, so the scaling is exact). R does not depend on
  // positive factors on src or dst; the scale becomes s' 2^b / 2^a, and t is rebuilt from the means
  // in the original units. Weights are normalised the same way.
  T cs = T(0), cd = T(0), wmax = T(0);
  for (Eigen::Index i = 0; i < n; ++i) {
    cs = std::max(cs, src.col(i).cwiseAbs().maxCoeff());
    cd = std::max(cd, dst.col(i).cwiseAbs().maxCoeff());
    if (weights != nullptr) wmax = std::max(wmax, weights[i]);
  }
  for (Eigen::Index i = 0; i < n; ++i) {  // NaN fails max: test the data itself
    if (!src.col(i).allFinite() || !dst.col(i).allFinite()) {
      result.status = Status::NonFinite;
      result.reason = "umeyama: non-finite coordinates in src or dst";
      return result;
    }
  }
  if (!(cs > T(0)) || !(cd > T(0))) {
    result.status = Status::Degenerate;
    result.reason = "umeyama: every source or every destination point is at the origin";
    return result;
  }
  // Element-wise ldexp: 2^-exponent itself is not representable for the largest and smallest values.
  int es = 0, ed = 0, ew = 0;
  std::frexp(cs, &es);
  std::frexp(cd, &ed);
  if (weights != nullptr && wmax > T(0)) std::frexp(wmax, &ew);
  auto down_s = [es](T x) { return std::ldexp(x, -es); };
  auto down_d = [ed](T x) { return std::ldexp(x, -ed); };
  AlignmentAccumulator<T> scaled(src.col(0).unaryExpr(down_s), dst.col(0).unaryExpr(down_d));
  for (Eigen::Index i = 0; i < n; ++i) {
    const T w = weights != nullptr ? std::ldexp(weights[i], -ew) : T(1);
    scaled.add(src.col(i).unaryExpr(down_s), dst.col(i).unaryExpr(down_d), w);
  }
  AlignmentOptions rotation_only;
  rotation_only.estimate_scale = false;
  AlignmentResult<T> second = scaled.solve(rotation_only);
  if (!second.ok()) return second;
  T scale = T(1);
  if (options.estimate_scale) {
    AlignmentOptions with_scale;
    with_scale.estimate_scale = true;
    const AlignmentResult<T> s = scaled.solve(with_scale);
    if (!s.ok()) return s;
    scale = std::ldexp(s.dst_from_src.scale, ed - es);
  }
  const T inv_w = T(1) / scaled.sum_w;
  const Vec3<T> mean_s = (scaled.s0 + scaled.sum_s * inv_w).unaryExpr([es](T x) { return std::ldexp(x, es); });
  const Vec3<T> mean_d = (scaled.d0 + scaled.sum_d * inv_w).unaryExpr([ed](T x) { return std::ldexp(x, ed); });
  second.dst_from_src.scale = scale;
  second.dst_from_src.t = mean_d - scale * (second.dst_from_src.R * mean_s);
  if (!second.dst_from_src.t.allFinite() || !std::isfinite(scale)) {
    second.status = Status::InvalidInput;
    second.reason = "umeyama: the aligning translation is beyond the largest finite value (coordinates near the "
                    "floating-point limit)";
  }
  return second;
}
}  // namespace detail

/// Least-squares dst_from_src minimising sum_i w_i |dst_i - (s R src_i + t)|^2.
/// src and dst are 3xN (any Eigen expression, column i corresponds); weights (optional) points to N
/// non-negative finite weights. Fails with TooFewPoints below 3 points, Degenerate when the
/// cross-covariance has rank < 2 (collinear or coincident points), NonFinite on NaN/Inf input.
/// Finite coordinates whose squares overflow are aligned after scaling by the largest magnitude
/// (coordinates so small that they underflow give Degenerate); InvalidInput when the fitted
/// transform itself is not representable. Every output of an Ok result is finite.
/// Call it qualified, `dyncull::umeyama(src, dst)`: with two Eigen arguments an unqualified call also
/// finds Eigen::umeyama by argument-dependent lookup and is ambiguous.
/// Cost: one pass over the data (3x3 cross-covariance, centred on the first point so far-from-origin
/// trajectories do not cancel) plus one 3x3 SVD; a second, scaled pass only when the moments overflow.
template <class DA, class DB>
AlignmentResult<typename DA::Scalar> umeyama(const Eigen::MatrixBase<DA>& src, const Eigen::MatrixBase<DB>& dst,
                                             const AlignmentOptions& options = {},
                                             const typename DA::Scalar* weights = nullptr) {
  using T = typename DA::Scalar;
  static_assert(std::is_floating_point<T>::value, "umeyama: scalar must be float or double");
  static_assert(std::is_same<T, typename DB::Scalar>::value, "umeyama: src and dst must have the same scalar type");
  static_assert(DA::RowsAtCompileTime == 3 || DA::RowsAtCompileTime == Eigen::Dynamic,
                "umeyama: src must be 3xN (one point per column)");
  static_assert(DB::RowsAtCompileTime == 3 || DB::RowsAtCompileTime == Eigen::Dynamic,
                "umeyama: dst must be 3xN (one point per column)");
  AlignmentResult<T> result;
  if (src.rows() != 3 || dst.rows() != 3) {
    result.status = Status::InvalidInput;
    result.reason = "umeyama: src and dst must have 3 rows (one point per column)";
    return result;
  }
  if (src.cols() != dst.cols()) {
    result.status = Status::InvalidInput;
    result.reason = "umeyama: src has " + std::to_string(src.cols()) + " columns but dst has " +
                    std::to_string(dst.cols());
    return result;
  }
  const Eigen::Index n = src.cols();
  if (n < 3) {
    result.status = Status::TooFewPoints;
    result.reason = "umeyama: need at least 3 points, got " + std::to_string(n);
    return result;
  }

  // Shift by the first pair: the one-pass moments then stay well conditioned for data far from the origin.
  AlignmentAccumulator<T> acc(src.col(0), dst.col(0));
  if (weights == nullptr) {
    // The 16 moments live in local scalars, not in `acc`: stores into acc's members may alias the
    // input (same scalar type), which made g++ -O2 reload and store all of them for every pair.
    const T sx = acc.s0(0), sy = acc.s0(1), sz = acc.s0(2), dx = acc.d0(0), dy = acc.d0(1), dz = acc.d0(2);
    T s_x = 0, s_y = 0, s_z = 0, d_x = 0, d_y = 0, d_z = 0, ss = 0;
    T m00 = 0, m01 = 0, m02 = 0, m10 = 0, m11 = 0, m12 = 0, m20 = 0, m21 = 0, m22 = 0;
    for (Eigen::Index i = 0; i < n; ++i) {
      const T a0 = src(0, i) - sx, a1 = src(1, i) - sy, a2 = src(2, i) - sz;
      const T b0 = dst(0, i) - dx, b1 = dst(1, i) - dy, b2 = dst(2, i) - dz;
      s_x += a0; s_y += a1; s_z += a2;
      d_x += b0; d_y += b1; d_z += b2;
      ss += a0 * a0 + a1 * a1 + a2 * a2;
      m00 += b0 * a0; m01 += b0 * a1; m02 += b0 * a2;
      m10 += b1 * a0; m11 += b1 * a1; m12 += b1 * a2;
      m20 += b2 * a0; m21 += b2 * a1; m22 += b2 * a2;
    }
    acc.sum_s = Vec3<T>(s_x, s_y, s_z);
    acc.sum_d = Vec3<T>(d_x, d_y, d_z);
    acc.sum_ds << m00, m01, m02, m10, m11, m12, m20, m21, m22;
    acc.sum_ss = ss;
    acc.sum_w = static_cast<T>(n);
    acc.used = static_cast<std::size_t>(n);
  } else {
    for (Eigen::Index i = 0; i < n; ++i) {
      const T w = weights[i];
      if (!(w >= T(0)) || !std::isfinite(w)) {
        result.status = std::isfinite(w) ? Status::InvalidInput : Status::NonFinite;
        result.reason = "umeyama: weight " + std::to_string(i) + " is negative or non-finite";
        return result;
      }
      acc.add(src.col(i), dst.col(i), w);
    }
  }
  // Moments that overflowed (finite data near the floating-point limit, or NaN / Inf: the fallback
  // tells them apart) go to the rescaled pass.
  if (!acc.sum_ds.allFinite() || !acc.sum_s.allFinite() || !acc.sum_d.allFinite() || !std::isfinite(acc.sum_ss) ||
      !std::isfinite(acc.sum_w)) {
    return detail::umeyama_rescaled(src, dst, options, weights, std::move(result));
  }
  return acc.solve(options);
}

template <class T>
AlignmentResult<T> AlignmentAccumulator<T>::solve(const AlignmentOptions& options) const {
  AlignmentResult<T> result;
  result.num_points = used;
  // NaN/Inf anywhere in the input propagates into the sums: one check instead of one per element.
  if (!sum_ds.allFinite() || !sum_s.allFinite() || !sum_d.allFinite() || !std::isfinite(sum_ss) ||
      !s0.allFinite() || !d0.allFinite()) {
    result.status = Status::NonFinite;
    result.reason = "umeyama: non-finite coordinates in src or dst";
    return result;
  }
  if (used < 3 || !(sum_w > T(0))) {
    result.status = Status::TooFewPoints;
    result.reason = "umeyama: need at least 3 points with positive weight, got " + std::to_string(used);
    return result;
  }
  const T inv_w = T(1) / sum_w;
  const Vec3<T> mean_s = sum_s * inv_w;
  const Vec3<T> mean_d = sum_d * inv_w;
  // Umeyama eq. 38: Sigma = 1/n sum (d - mu_d)(s - mu_s)^T, eq. 36: sigma_s^2 = 1/n sum |s - mu_s|^2.
  const Mat3<T> sigma = sum_ds * inv_w - mean_d * mean_s.transpose();
  const T var_s = sum_ss * inv_w - mean_s.squaredNorm();

  Eigen::JacobiSVD<Mat3<T>> svd(sigma, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Vec3<T> sv = svd.singularValues();
  // Rank < 2 leaves the rotation about the points' line (or everything) undetermined (Umeyama's
  // uniqueness condition rank(Sigma) >= m - 1). Relative threshold: 1000 machine epsilons.
  const T rank_tol = T(1000) * Constants<T>::epsilon();
  if (!(sv(0) > T(0)) || sv(1) <= rank_tol * sv(0)) {
    result.status = Status::Degenerate;
    result.reason = "umeyama: points are collinear or coincident (cross-covariance rank < 2)";
    return result;
  }
  const Mat3<T>& U = svd.matrixU();
  const Mat3<T>& V = svd.matrixV();
  // Reflection fix (eq. 39-40): flip the smallest singular direction when det(U V^T) < 0.
  Vec3<T> S(T(1), T(1), T(1));
  if (U.determinant() * V.determinant() < T(0)) S(2) = T(-1);
  const Mat3<T> R = U * S.asDiagonal() * V.transpose();
  // A cross-covariance of subnormal or wildly mixed magnitudes can defeat the SVD: never return a
  // matrix that is not a rotation.
  if (!((R.transpose() * R - Mat3<T>::Identity()).cwiseAbs().maxCoeff() < T(1e-3)) || !(R.determinant() > T(0))) {
    result.status = Status::Degenerate;
    result.reason = "umeyama: the cross-covariance is too ill-conditioned to determine a rotation";
    return result;
  }
  T scale = T(1);
  if (options.estimate_scale) {
    if (!(var_s > T(0))) {
      result.status = Status::Degenerate;
      result.reason = "umeyama: source points have zero spread, scale undefined";
      return result;
    }
    scale = sv.dot(S) / var_s;  // eq. 42
  }
  result.dst_from_src.scale = scale;
  result.dst_from_src.R = R;
  // t maps the shifted frames back: d = s R (x - s0) + d0 + (mu_d - s R mu_s).
  result.dst_from_src.t = d0 + mean_d - scale * (R * (s0 + mean_s));
  if (!result.dst_from_src.t.allFinite() || !std::isfinite(scale)) {
    result.status = Status::InvalidInput;
    result.reason = "umeyama: the aligning transform is beyond the largest finite value (coordinates near the "
                    "floating-point limit)";
  }
  return result;
}

}  // namespace dyncull
