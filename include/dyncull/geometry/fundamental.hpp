/// @file fundamental.hpp
/// Fundamental matrix x2^T F x1 = 0 (DFD-SLAM, Qian et al. 2024, eq. 1-2): Hartley-normalised 8-point with
/// rank 2 enforced,
/// the 7-point minimal solver (cubic det constraint, up to 3 solutions) and LO-RANSAC on Sampson error (px).
#pragma once

#include "dyncull/core/pixel.hpp"
#include "dyncull/core/precompiled.hpp"
#include "dyncull/core/random.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/core/traits.hpp"
#include "dyncull/core/types.hpp"
#include "dyncull/geometry/epipolar.hpp"
#include "dyncull/geometry/ransac.hpp"
#include "dyncull/geometry/symmetric_eigen.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/LU>
#include <Eigen/SVD>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

namespace dyncull {

/// Options of estimate_fundamental_ransac().
template <class T>
struct FundamentalOptions {
  /// ransac.max_residual is the Sampson distance threshold in pixels (not squared). Sampson is the
  /// first-order reprojection error of the correspondence in both images; for an error in image 2 only it is
  /// about the DFD-SLAM eq. 3 distance / sqrt(2).
  RansacOptions ransac{};
  /// LO refit weights each 8-point row by 1 / (Sampson denominator) of the current model, so the algebraic
  /// least squares approximates least squares on Sampson error (Torr's reweighting). false: plain 8-point.
  bool sampson_weighted_refit = true;
  /// After RANSAC, test whether one homography explains the inliers (planar scene, pure rotation, no
  /// motion): F is then not determined by the data and status becomes Degenerate (F and mask still filled).
  bool check_homography_degeneracy = true;
  /// Degenerate when at least this fraction of the F inliers lies within the transfer threshold of H.
  double degenerate_homography_fraction = 0.95;
  /// Homography transfer threshold (px) as a multiple of ransac.max_residual: the one-sided transfer error
  /// of a correct H is about sqrt(2) times the Sampson error of the same correspondence, plus noise.
  double homography_threshold_factor = 2.0;

  /// Ok, or InvalidInput with a reason naming the field.
  Status validate(std::string* reason = nullptr) const {
    std::string why;
    if (ransac.validate(&why) != Status::Ok) {
      if (reason) *reason = detail::nested_reason("FundamentalOptions", "ransac", why);
      return Status::InvalidInput;
    }
    auto bad = [&](const char* text) {
      if (reason) *reason = text;
      return Status::InvalidInput;
    };
    if (!(degenerate_homography_fraction > 0.0 && degenerate_homography_fraction <= 1.0))
      return bad("FundamentalOptions: degenerate_homography_fraction must be in (0, 1]");
    if (!(homography_threshold_factor > 0.0) || !std::isfinite(homography_threshold_factor) ||
        !std::isfinite(homography_threshold_factor * ransac.max_residual))
      return bad("FundamentalOptions: homography_threshold_factor must be finite and > 0");
    if (reason) reason->clear();
    return Status::Ok;
  }
};

/// Result of an F estimation. F has unit Frobenius norm and rank 2; inlier_mask has one entry per input
/// correspondence (non-finite correspondences are never inliers).
template <class T>
struct FundamentalResult {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }

  Mat3<T> F = Mat3<T>::Zero();
  std::vector<std::uint8_t> inlier_mask;
  std::size_t num_inliers = 0;
  std::size_t iterations = 0;              ///< RANSAC samples drawn (0 for the direct solvers)
  double score = 0;                        ///< MSAC cost in px^2 (RANSAC only)
  double homography_inlier_fraction = 0;   ///< fraction of F inliers explained by one homography (diagnostic)
};

/// Up to three F from seven correspondences (fundamental_7point).
template <class T>
struct FundamentalSolutions {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }
  int count = 0;
  std::array<Mat3<T>, 3> F{};
};

namespace detail {

/// Isotropic Hartley normalisation: centroid to the origin, mean distance sqrt(2). Returns false when all
/// points coincide.
struct Normaliser {
  double s = 1, cx = 0, cy = 0;
  Mat3<double> matrix() const {
    Mat3<double> m;
    m << s, 0, -s * cx, 0, s, -s * cy, 0, 0, 1;
    return m;
  }
};

inline bool make_normaliser(const double* x, const double* y, std::size_t n, Normaliser* out) {
  if (n == 0) return false;
  double cx = 0, cy = 0;
  for (std::size_t i = 0; i < n; ++i) cx += x[i], cy += y[i];
  cx /= double(n), cy /= double(n);
  double dist = 0;
  for (std::size_t i = 0; i < n; ++i) dist += std::sqrt((x[i] - cx) * (x[i] - cx) + (y[i] - cy) * (y[i] - cy));
  dist /= double(n);
  if (!(dist > 0) || !std::isfinite(dist)) return false;
  out->s = std::sqrt(2.0) / dist;
  out->cx = cx;
  out->cy = cy;
  return true;
}

/// Row of the epipolar constraint for (x1, y1) <-> (x2, y2): a . vec(F) with F row-major.
inline void epipolar_row(double x1, double y1, double x2, double y2, double* a) {
  a[0] = x2 * x1, a[1] = x2 * y1, a[2] = x2;
  a[3] = y2 * x1, a[4] = y2 * y1, a[5] = y2;
  a[6] = x1, a[7] = y1, a[8] = 1;
}

// The solvers below have no template parameter: with DYNCULL_PRECOMPILED they are compiled once into
// dyncull::pipeline (src/geometry/fundamental.cpp) and only declared here; header-only, they are inline.
using RowsMatrix = Eigen::Matrix<double, 9, Eigen::Dynamic>;
DYNCULL_SOLVER Mat3<double> enforce_rank2(const Mat3<double>& F);
DYNCULL_SOLVER Status solve_normal_equations(const Eigen::Matrix<double, 9, 9>& ata, Mat3<double>* F,
                                             std::string* reason);
DYNCULL_SOLVER bool nullspace_7x9(double A[7][9], double n1[9], double n2[9]);
DYNCULL_SOLVER int solve_cubic(double c3, double c2, double c1, double c0, double roots[3]);
DYNCULL_SOLVER int seven_point_normalised(const double* x1, const double* y1, const double* x2, const double* y2,
                                          const std::uint32_t* idx, Mat3<double>* out);
DYNCULL_SOLVER Mat3<double> denormalise(const Mat3<double>& Fn, const Normaliser& n1, const Normaliser& n2);
DYNCULL_SOLVER Status eight_point_normalised(const double* x1, const double* y1, const double* x2, const double* y2,
                                             const std::uint32_t* idx, std::size_t n, const double* weights,
                                             RowsMatrix* rows, Mat3<double>* Fn, std::string* reason,
                                             const Mat3<double>* warm = nullptr);
DYNCULL_SOLVER bool homography_dlt(const double* x1, const double* y1, const double* x2, const double* y2,
                                   const std::uint32_t* idx, std::size_t n, Mat3<double>* H);
DYNCULL_SOLVER bool homography_4point(const double* x1, const double* y1, const double* x2, const double* y2,
                                      const std::uint32_t* idx, Mat3<double>* H);

#if !defined(DYNCULL_PRECOMPILED) || defined(DYNCULL_FUNDAMENTAL_SOURCE)

/// Closest rank-2 matrix (Frobenius), via SVD with the smallest singular value zeroed.
DYNCULL_SOLVER Mat3<double> enforce_rank2(const Mat3<double>& F) {
  Eigen::JacobiSVD<Mat3<double>> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Vec3<double> s = svd.singularValues();
  s[2] = 0;
  return svd.matrixU() * s.asDiagonal() * svd.matrixV().transpose();
}

/// Smallest-eigenvalue eigenvector of the 9x9 normal matrix, as a 3x3 F (row-major). Fails (Degenerate)
/// when the null space is at least two-dimensional: the correspondences do not determine F.
DYNCULL_SOLVER Status solve_normal_equations(const Eigen::Matrix<double, 9, 9>& ata, Mat3<double>* F,
                                             std::string* reason) {
  SymmetricEigen<9> es;
  if (!symmetric_eigen(ata, &es)) {
    if (reason) *reason = "eigen-decomposition of the 8-point normal matrix failed";
    return Status::NotConverged;
  }
  const auto& ev = es.values;  // ascending
  // Relative rank test: a second (near) zero eigenvalue means a family of solutions. The bound is loose
  // on purpose (exact degeneracy in double gives ~1e-16); noisy near-degenerate data is caught later by the
  // homography test of the RANSAC.
  constexpr double kRankTolerance = 1e-12;
  if (!(ev[8] > 0) || ev[1] <= kRankTolerance * ev[8]) {
    if (reason) *reason = "correspondences do not determine F (null space of dimension >= 2: too few distinct "
                          "points, collinear points, or a planar scene / pure rotation without noise)";
    return Status::Degenerate;
  }
  const Eigen::Matrix<double, 9, 1> f = es.vectors.col(0);
  *F << f[0], f[1], f[2], f[3], f[4], f[5], f[6], f[7], f[8];
  return Status::Ok;
}

/// Null space of a 7x9 matrix by Gauss-Jordan elimination with full pivoting (no allocation, ~1 us).
/// Returns false when the rank is below 7.
DYNCULL_SOLVER bool nullspace_7x9(double A[7][9], double n1[9], double n2[9]) {
  int perm[9] = {0, 1, 2, 3, 4, 5, 6, 7, 8};
  double scale = 0;
  for (int i = 0; i < 7; ++i)
    for (int j = 0; j < 9; ++j) scale = std::max(scale, std::abs(A[i][j]));
  if (!(scale > 0) || !std::isfinite(scale)) return false;
  constexpr double kPivotTolerance = 1e-10;  // relative to the largest entry; normalised data are O(1)
  for (int k = 0; k < 7; ++k) {
    int pr = k, pc = k;
    double best = 0;
    for (int i = k; i < 7; ++i)
      for (int j = k; j < 9; ++j)
        if (std::abs(A[i][j]) > best) best = std::abs(A[i][j]), pr = i, pc = j;
    if (!(best > kPivotTolerance * scale)) return false;
    if (pr != k)
      for (int j = 0; j < 9; ++j) std::swap(A[k][j], A[pr][j]);
    if (pc != k) {
      for (int i = 0; i < 7; ++i) std::swap(A[i][k], A[i][pc]);
      std::swap(perm[k], perm[pc]);
    }
    const double inv = 1.0 / A[k][k];
    for (int j = k; j < 9; ++j) A[k][j] *= inv;
    for (int i = 0; i < 7; ++i) {
      if (i == k) continue;
      const double f = A[i][k];
      if (f == 0) continue;
      for (int j = k; j < 9; ++j) A[i][j] -= f * A[k][j];
    }
  }
  // A = [I | B] in permuted columns: free columns 7 and 8.
  for (int j = 0; j < 9; ++j) n1[j] = n2[j] = 0;
  n1[perm[7]] = 1;
  n2[perm[8]] = 1;
  for (int k = 0; k < 7; ++k) {
    n1[perm[k]] = -A[k][7];
    n2[perm[k]] = -A[k][8];
  }
  return true;
}

/// Real roots of c3 x^3 + c2 x^2 + c1 x + c0 (degrades to quadratic / linear); Newton-polished.
DYNCULL_SOLVER int solve_cubic(double c3, double c2, double c1, double c0, double roots[3]) {
  const double cmax = std::max(std::max(std::abs(c3), std::abs(c2)), std::max(std::abs(c1), std::abs(c0)));
  if (!(cmax > 0) || !std::isfinite(cmax)) return 0;
  int count = 0;
  if (std::abs(c3) <= 1e-12 * cmax) {
    if (std::abs(c2) <= 1e-12 * cmax) {
      if (std::abs(c1) <= 1e-12 * cmax) return 0;
      roots[0] = -c0 / c1;
      return 1;
    }
    const double disc = c1 * c1 - 4 * c2 * c0;
    if (disc < 0) return 0;
    const double q = -0.5 * (c1 + std::copysign(std::sqrt(disc), c1));
    roots[count++] = q / c2;
    if (q != 0) roots[count++] = c0 / q;
    return count;
  }
  const double b = c2 / c3, c = c1 / c3, d = c0 / c3;
  const double p = c - b * b / 3.0;
  const double q = 2.0 * b * b * b / 27.0 - b * c / 3.0 + d;
  const double disc = q * q / 4.0 + p * p * p / 27.0;
  if (disc > 0) {
    const double sq = std::sqrt(disc);
    roots[count++] = std::cbrt(-q / 2.0 + sq) + std::cbrt(-q / 2.0 - sq) - b / 3.0;
  } else {
    const double r = std::sqrt(std::max(0.0, -p / 3.0));
    if (r == 0) {
      roots[count++] = -b / 3.0;
    } else {
      double arg = -q / (2.0 * r * r * r);
      arg = std::min(1.0, std::max(-1.0, arg));
      const double phi = std::acos(arg);
      for (int k = 0; k < 3; ++k)
        roots[count++] = 2.0 * r * std::cos((phi + 2.0 * Constants<double>::pi() * k) / 3.0) - b / 3.0;
    }
  }
  for (int i = 0; i < count; ++i) {
    double x = roots[i];
    for (int it = 0; it < 2; ++it) {
      const double f = ((x + b) * x + c) * x + d;
      const double df = (3.0 * x + 2.0 * b) * x + c;
      if (df == 0) break;
      x -= f / df;
    }
    if (std::isfinite(x)) roots[i] = x;
  }
  return count;
}

/// 7-point solver on normalised coordinates: writes up to 3 normalised F (unit norm), returns the count.
DYNCULL_SOLVER int seven_point_normalised(const double* x1, const double* y1, const double* x2, const double* y2,
                                          const std::uint32_t* idx, Mat3<double>* out) {
  double A[7][9];
  for (int i = 0; i < 7; ++i) {
    const std::uint32_t k = idx[i];
    epipolar_row(x1[k], y1[k], x2[k], y2[k], A[i]);
  }
  double n1[9], n2[9];
  if (!nullspace_7x9(A, n1, n2)) return 0;
  Mat3<double> F1, F2;
  F1 << n1[0], n1[1], n1[2], n1[3], n1[4], n1[5], n1[6], n1[7], n1[8];
  F2 << n2[0], n2[1], n2[2], n2[3], n2[4], n2[5], n2[6], n2[7], n2[8];
  // det(F2 + l (F1 - F2)) is a cubic in l: recover it from four samples (exact up to rounding).
  const Mat3<double> D = F1 - F2;
  const double p0 = F2.determinant();
  const double p1 = (F2 + D).determinant();
  const double pm1 = (F2 - D).determinant();
  const double p2 = (F2 + 2.0 * D).determinant();
  const double c0 = p0;
  const double c2 = 0.5 * (p1 + pm1) - p0;
  const double c3 = (p2 - 4.0 * c2 - p0 - (p1 - pm1)) / 6.0;
  const double c1 = 0.5 * (p1 - pm1) - c3;
  double roots[3];
  const int nr = solve_cubic(c3, c2, c1, c0, roots);
  int count = 0;
  for (int i = 0; i < nr; ++i) {
    Mat3<double> F = F2 + roots[i] * D;
    const double norm = F.norm();
    if (!(norm > 0) || !std::isfinite(norm)) continue;
    out[count++] = F / norm;
  }
  return count;
}

/// Back to pixels: F_px = T2^T F_n T1, unit Frobenius norm, sign fixed so the largest entry is positive
/// (makes results comparable and deterministic up to numerics).
DYNCULL_SOLVER Mat3<double> denormalise(const Mat3<double>& Fn, const Normaliser& n1, const Normaliser& n2) {
  Mat3<double> F = n2.matrix().transpose() * Fn * n1.matrix();
  const double norm = F.norm();
  if (norm > 0) F /= norm;
  Eigen::Index r, c;
  F.cwiseAbs().maxCoeff(&r, &c);
  if (F(r, c) < 0) F = -F;
  return F;
}

/// Weighted 8-point on normalised coordinates of the selected points (idx == nullptr: all n). `rows` is
/// scratch (9 x n, grown if needed): the normal matrix is one vectorised product A A^T, 5-10x faster
/// than n rank-one updates.
/// `warm` (optional): a nearby solution in normalised coordinates (LO refits). The null vector is then found
/// by three steps of inverse iteration on an LDLT of A^T A (~1 us) instead of a full 9x9 eigen-decomposition
/// (~10 us, the largest LO cost); the eigen-decomposition remains the fallback and the only path that runs
/// the rank (degeneracy) test.
DYNCULL_SOLVER Status eight_point_normalised(const double* x1, const double* y1, const double* x2, const double* y2,
                                             const std::uint32_t* idx, std::size_t n, const double* weights,
                                             RowsMatrix* rows, Mat3<double>* Fn, std::string* reason,
                                             const Mat3<double>* warm) {
  if (n < 8) {
    if (reason) *reason = std::to_string(n) + " correspondences, the 8-point algorithm needs 8";
    return Status::TooFewPoints;
  }
  const auto N = static_cast<Eigen::Index>(n);
  if (rows->cols() < N) rows->resize(9, N);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t k = idx ? idx[i] : i;
    double* a = rows->col(static_cast<Eigen::Index>(i)).data();
    epipolar_row(x1[k], y1[k], x2[k], y2[k], a);
    if (weights) {
      const double sw = std::sqrt(weights[i]);
      for (int j = 0; j < 9; ++j) a[j] *= sw;
    }
  }
  Eigen::Matrix<double, 9, 9> ata;
  ata.noalias() = rows->leftCols(N) * rows->leftCols(N).transpose();
  if (warm) {
    const Eigen::LDLT<Eigen::Matrix<double, 9, 9>> ldlt(ata);
    if (ldlt.info() == Eigen::Success) {
      Eigen::Matrix<double, 9, 1> v;
      v << (*warm)(0, 0), (*warm)(0, 1), (*warm)(0, 2), (*warm)(1, 0), (*warm)(1, 1), (*warm)(1, 2), (*warm)(2, 0),
          (*warm)(2, 1), (*warm)(2, 2);
      for (int it = 0; it < 3 && v.allFinite(); ++it) v = ldlt.solve(v).normalized();
      if (v.allFinite()) {
        Mat3<double> F;
        F << v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8];
        *Fn = enforce_rank2(F);
        return Status::Ok;
      }
    }
  }
  Mat3<double> F;
  const Status s = solve_normal_equations(ata, &F, reason);
  if (s != Status::Ok) return s;
  *Fn = enforce_rank2(F);
  return Status::Ok;
}

/// Homography by normalised DLT on selected correspondences (normalised coordinates); false if degenerate.
DYNCULL_SOLVER bool homography_dlt(const double* x1, const double* y1, const double* x2, const double* y2,
                                   const std::uint32_t* idx, std::size_t n, Mat3<double>* H) {
  if (n < 4) return false;
  Eigen::Matrix<double, 9, 9> ata = Eigen::Matrix<double, 9, 9>::Zero();
  Eigen::Matrix<double, 9, 1> a, b;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t k = idx[i];
    const double u = x1[k], v = y1[k], X = x2[k], Y = y2[k];
    a << -u, -v, -1, 0, 0, 0, X * u, X * v, X;
    b << 0, 0, 0, -u, -v, -1, Y * u, Y * v, Y;
    ata.selfadjointView<Eigen::Upper>().rankUpdate(a);
    ata.selfadjointView<Eigen::Upper>().rankUpdate(b);
  }
  ata.triangularView<Eigen::StrictlyLower>() = ata.transpose();
  SymmetricEigen<9> es;
  if (!symmetric_eigen(ata, &es)) return false;
  const Eigen::Matrix<double, 9, 1> h = es.vectors.col(0);
  *H << h[0], h[1], h[2], h[3], h[4], h[5], h[6], h[7], h[8];
  return H->allFinite() && std::abs(H->determinant()) > 1e-12 * std::pow(H->norm(), 3);
}

/// Homography through four correspondences (normalised coordinates), h33 = 1; false if singular.
DYNCULL_SOLVER bool homography_4point(const double* x1, const double* y1, const double* x2, const double* y2,
                                      const std::uint32_t* idx, Mat3<double>* H) {
  Eigen::Matrix<double, 8, 8> A;
  Eigen::Matrix<double, 8, 1> b;
  for (int i = 0; i < 4; ++i) {
    const std::uint32_t k = idx[i];
    const double u = x1[k], v = y1[k], X = x2[k], Y = y2[k];
    A.row(2 * i) << u, v, 1, 0, 0, 0, -X * u, -X * v;
    A.row(2 * i + 1) << 0, 0, 0, u, v, 1, -Y * u, -Y * v;
    b[2 * i] = X;
    b[2 * i + 1] = Y;
  }
  const Eigen::PartialPivLU<Eigen::Matrix<double, 8, 8>> lu(A);
  const double det = lu.determinant();
  if (!(std::abs(det) > 1e-12) || !std::isfinite(det)) return false;
  const Eigen::Matrix<double, 8, 1> h = lu.solve(b);
  *H << h[0], h[1], h[2], h[3], h[4], h[5], h[6], h[7], 1.0;
  return H->allFinite();
}

#endif  // solver definitions

}  // namespace detail

/// RANSAC estimator for F (see ransac.hpp for the concept): 7-point minimal solver on Hartley-normalised
/// coordinates, residual = squared Sampson distance in pixels, refit = (Sampson-weighted) 8-point.
/// Only finite correspondences are kept; index(i) maps estimator data back to the caller's index.
template <class T>
class FundamentalEstimator {
 public:
  using Model = Mat3<T>;
  using Scalar = T;
  static constexpr int kSampleSize = 7;
  static constexpr int kMaxModels = 3;

  FundamentalEstimator() = default;
  template <class C1, class C2>
  FundamentalEstimator(const C1& points1, const C2& points2, bool sampson_weighted_refit = true) {
    load(points1, points2, sampson_weighted_refit);
  }

  /// Takes the finite correspondences of points1 / points2, reusing this estimator's buffers (they only
  /// grow), so an estimator kept across calls allocates nothing once it has held the largest input.
  template <class C1, class C2>
  void load(const C1& points1, const C2& points2, bool sampson_weighted_refit = true) {
    weighted_ = sampson_weighted_refit;
    const std::size_t n = std::min<std::size_t>(points1.size(), points2.size());
    for (auto* v : {&px1_, &py1_, &px2_, &py2_}) v->clear(), v->reserve(n);
    for (auto* v : {&ux1_, &uy1_, &ux2_, &uy2_}) v->clear(), v->reserve(n);
    index_.clear(), index_.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
      const double a = point_x<double>(points1[i]), b = point_y<double>(points1[i]);
      const double c = point_x<double>(points2[i]), d = point_y<double>(points2[i]);
      if (!std::isfinite(a) || !std::isfinite(b) || !std::isfinite(c) || !std::isfinite(d)) continue;
      ux1_.push_back(a), uy1_.push_back(b), ux2_.push_back(c), uy2_.push_back(d);
      px1_.push_back(float(a)), py1_.push_back(float(b)), px2_.push_back(float(c)), py2_.push_back(float(d));
      index_.push_back(static_cast<std::uint32_t>(i));
    }
    normalise();
  }

  std::size_t num_data() const { return normalisable_ ? index_.size() : 0; }
  std::size_t num_input_finite() const { return index_.size(); }
  /// False when every correspondence is at the same pixel in both images (a camera that did not move, and
  /// nothing else did): every skew-symmetric F = [e]x fits them, so each 7-point sample has a null space of
  /// dimension 3 and no sample can produce a model.
  bool has_baseline() const {
    for (std::size_t i = 0; i < ux1_.size(); ++i)
      if (ux1_[i] != ux2_[i] || uy1_[i] != uy2_[i]) return true;
    return false;
  }
  std::uint32_t index(std::size_t i) const { return index_[i]; }

  int minimal_solve(const std::uint32_t* sample, Model* models) const {
    Mat3<double> Fn[3];
    const int count = detail::seven_point_normalised(nx1_.data(), ny1_.data(), nx2_.data(), ny2_.data(), sample, Fn);
    int written = 0;
    for (int i = 0; i < count; ++i) {
      const Mat3<double> F = detail::denormalise(Fn[i], n1_, n2_);
      if (!F.allFinite()) continue;
      models[written++] = F.cast<T>();
    }
    return written;
  }

  void residuals_sq(const Model& F, T* out) const { residuals_sq(F, std::size_t{0}, px1_.size(), out); }
  /// Hypotheses are scored with float Sampson distances whatever T is: pixel coordinates of a few
  /// thousand px keep ~1e-4 px resolution in float, far below any inlier threshold, and float runs
  /// twice as many lanes. Minimal solves and refits are in double (normalised coordinates) for every T.
  void residuals_sq(const Model& F, std::size_t begin, std::size_t end, T* out) const {
    const Mat3<float> Ff = F.template cast<float>();
    if constexpr (std::is_same<T, float>::value) {
      epipolar_distances_soa(Ff, px1_.data() + begin, py1_.data() + begin, px2_.data() + begin, py2_.data() + begin,
                             end - begin, out, EpipolarDistance::SampsonSq);
    } else {
      if (scratch_.size() < end - begin) scratch_.resize(end - begin);  // grows once; reused afterwards
      epipolar_distances_soa(Ff, px1_.data() + begin, py1_.data() + begin, px2_.data() + begin, py2_.data() + begin,
                             end - begin, scratch_.data(), EpipolarDistance::SampsonSq);
      for (std::size_t i = 0; i < end - begin; ++i) out[i] = static_cast<T>(scratch_[i]);
    }
  }

  /// Residuals at given indices (RANSAC's probe pre-test): a scalar loop, n is small.
  void residuals_sq(const Model& F, const std::uint32_t* idx, std::size_t n, T* out) const {
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t k = idx[i];
      const T x1 = px1_[k], y1 = py1_[k], x2 = px2_[k], y2 = py2_[k];
      const T X = F(0, 0) * x1 + F(0, 1) * y1 + F(0, 2);
      const T Y = F(1, 0) * x1 + F(1, 1) * y1 + F(1, 2);
      const T Z = F(2, 0) * x1 + F(2, 1) * y1 + F(2, 2);
      const T A = F(0, 0) * x2 + F(1, 0) * y2 + F(2, 0);
      const T B = F(0, 1) * x2 + F(1, 1) * y2 + F(2, 1);
      const T e = x2 * X + y2 * Y + Z;
      out[i] = e * e / (X * X + Y * Y + A * A + B * B);
    }
  }

  bool refit(const std::uint32_t* inliers, std::size_t n, Model* model) const {
    const double* w = nullptr;
    // The current model in normalised coordinates, Fn = T2^-T F T1^-1: warm start and Sampson weights.
    const Mat3<double> Fn_current =
        n2_.matrix().transpose().inverse() * model->template cast<double>() * n1_.matrix().inverse();
    if (weighted_) {
      const Mat3<double>& Fn = Fn_current;
      for (std::size_t i = 0; i < n; ++i) {
        const std::uint32_t k = inliers[i];
        const Vec3<double> p1(nx1_[k], ny1_[k], 1.0), p2(nx2_[k], ny2_[k], 1.0);
        const Vec3<double> l2 = Fn * p1, l1 = Fn.transpose() * p2;
        const double den = l2[0] * l2[0] + l2[1] * l2[1] + l1[0] * l1[0] + l1[1] * l1[1];
        weights_[i] = den > 1e-12 ? 1.0 / den : 1e12;
      }
      w = weights_.data();
    }
    Mat3<double> Fn;
    const bool warm = model->allFinite() && !model->isZero();
    if (detail::eight_point_normalised(nx1_.data(), ny1_.data(), nx2_.data(), ny2_.data(), inliers, n, w, &rows_,
                                       &Fn, nullptr, warm ? &Fn_current : nullptr) != Status::Ok)
      return false;
    const Mat3<double> F = detail::denormalise(Fn, n1_, n2_);
    if (!F.allFinite()) return false;
    *model = F.cast<T>();
    return true;
  }

  /// Fraction of the given inliers within `threshold_px` (transfer error in image 2) of one homography:
  /// a few 4-point samples scored on at most 256 of the inliers (enough to find an H that explains >= 90 %
  /// of them with probability > 0.999), then two DLT refits on the best sample's inliers. A plain DLT on all
  /// inliers is not enough: the few outliers that a degenerate F admits pull it far off.
  double homography_fraction(const std::uint32_t* inliers, std::size_t n, double threshold_px,
                             std::uint64_t seed) const {
    if (n < 8) return 0;
    const double t2 = threshold_px * threshold_px;
    std::vector<std::uint32_t> probe;
    const std::size_t step = std::max<std::size_t>(1, n / 256);
    for (std::size_t i = 0; i < n; i += step) probe.push_back(inliers[i]);
    auto count_within = [&](const Mat3<double>& H, const std::uint32_t* idx, std::size_t m,
                            std::vector<std::uint32_t>* keep) {
      std::size_t good = 0;
      for (std::size_t i = 0; i < m; ++i) {
        const std::uint32_t k = idx[i];
        const Vec3<double> q = H * Vec3<double>(double(px1_[k]), double(py1_[k]), 1.0);
        if (!(std::abs(q[2]) > 0)) continue;
        const double dx = q[0] / q[2] - double(px2_[k]), dy = q[1] / q[2] - double(py2_[k]);
        const bool in = dx * dx + dy * dy < t2;
        good += in;
        if (in && keep) keep->push_back(k);
      }
      return good;
    };
    const Mat3<double> T2inv = n2_.matrix().inverse();
    const Mat3<double> T1 = n1_.matrix();
    Random rng(seed ^ 0x5DEECE66Dull);
    constexpr int kSamples = 8;  // (1 - 0.9^4)^8 < 1e-3
    Mat3<double> best_H = Mat3<double>::Identity();
    std::size_t best = 0;
    for (int s = 0; s < kSamples; ++s) {
      std::uint32_t sample[4];
      for (int i = 0; i < 4; ++i) {
        bool again = true;
        while (again) {
          sample[i] = probe[rng.index(static_cast<std::uint32_t>(probe.size()))];
          again = false;
          for (int j = 0; j < i; ++j) again = again || sample[j] == sample[i];
        }
      }
      Mat3<double> Hn;
      if (!detail::homography_4point(nx1_.data(), ny1_.data(), nx2_.data(), ny2_.data(), sample, &Hn)) continue;
      const Mat3<double> H = T2inv * Hn * T1;
      const std::size_t c = count_within(H, probe.data(), probe.size(), nullptr);
      if (c > best) best = c, best_H = H;
    }
    if (best < 4) return 0;
    std::vector<std::uint32_t> fit;
    count_within(best_H, probe.data(), probe.size(), &fit);
    Mat3<double> H = best_H;
    for (int round = 0; round < 2 && fit.size() >= 8; ++round) {
      Mat3<double> Hn;
      if (!detail::homography_dlt(nx1_.data(), ny1_.data(), nx2_.data(), ny2_.data(), fit.data(), fit.size(), &Hn))
        break;
      const Mat3<double> refined = T2inv * Hn * T1;
      std::vector<std::uint32_t> next;
      const std::size_t c = count_within(refined, probe.data(), probe.size(), &next);
      if (c < fit.size()) break;
      H = refined;
      fit.swap(next);
    }
    return double(count_within(H, inliers, n, nullptr)) / double(n);
  }

 private:
  bool weighted_ = true;
  bool normalisable_ = false;
  detail::Normaliser n1_, n2_;
  std::vector<float> px1_, py1_, px2_, py2_;     // pixels, for residuals (float: see residuals_sq)
  mutable std::vector<float> scratch_;           // float residuals before widening to T (T = double)
  std::vector<double> nx1_, ny1_, nx2_, ny2_;    // Hartley-normalised, for the solvers
  std::vector<std::uint32_t> index_;
  mutable std::vector<double> weights_;          // refit scratch, sized once
  mutable detail::RowsMatrix rows_;              // refit scratch (9 x n or wider), grown only
  std::vector<double> ux1_, uy1_, ux2_, uy2_;    // pixels in double, the normaliser's input

  void normalise() {
    const std::size_t m = index_.size();
    n1_ = n2_ = detail::Normaliser{};
    normalisable_ = detail::make_normaliser(ux1_.data(), uy1_.data(), m, &n1_) &&
                    detail::make_normaliser(ux2_.data(), uy2_.data(), m, &n2_);
    nx1_.resize(m), ny1_.resize(m), nx2_.resize(m), ny2_.resize(m);
    for (std::size_t i = 0; i < m; ++i) {
      nx1_[i] = n1_.s * (ux1_[i] - n1_.cx), ny1_[i] = n1_.s * (uy1_[i] - n1_.cy);
      nx2_[i] = n2_.s * (ux2_[i] - n2_.cx), ny2_[i] = n2_.s * (uy2_[i] - n2_.cy);
    }
    weights_.resize(m);
    // Eigen reallocates on any change of size: grow only (the 8-point uses the leading columns).
    if (rows_.cols() < static_cast<Eigen::Index>(m)) rows_.resize(9, static_cast<Eigen::Index>(m));
  }
};

/// Buffers F estimation reuses from call to call: a caller that keeps one across frames (with the result it
/// writes into) allocates nothing once they have held the largest input, failures' reasons aside.
template <class T>
struct FundamentalWorkspace {
  FundamentalEstimator<T> estimator;
  RansacWorkspace<T> ransac;
  RansacResult<Mat3<T>> ransac_result;
  std::vector<std::uint32_t> indices;  // the estimator's data taken by a fit (all, or the inliers)
};

namespace detail {
/// Clears every field of `r` (keeping its buffers) and sizes its mask to n zeros.
template <class T>
void reset_fundamental_result(std::size_t n, FundamentalResult<T>* r) {
  r->status = Status::Ok;
  r->reason.clear();
  r->F.setZero();
  r->inlier_mask.assign(n, 0);
  r->num_inliers = r->iterations = 0;
  r->score = r->homography_inlier_fraction = 0;
}
}  // namespace detail

/// Normalised 8-point algorithm on all correspondences (least squares, rank 2 enforced). Non-finite
/// correspondences are skipped; fewer than 8 usable ones give TooFewPoints, a non-unique solution Degenerate.
/// Writes into `out`, reusing its buffers and the workspace's.
template <class T, class C1, class C2>
void fundamental_8point(const C1& points1, const C2& points2, FundamentalWorkspace<T>* workspace,
                        FundamentalResult<T>* out) {
  FundamentalResult<T>& r = *out;
  detail::reset_fundamental_result(points1.size(), &r);
  if (points1.size() != points2.size()) {
    r.status = Status::InvalidInput;
    r.reason = "points1 and points2 differ in size";
    return;
  }
  FundamentalEstimator<T>& est = workspace->estimator;
  est.load(points1, points2, false);
  if (est.num_input_finite() < 8) {
    r.status = Status::TooFewPoints;
    r.reason = std::to_string(est.num_input_finite()) + " finite correspondences, the 8-point algorithm needs 8";
    return;
  }
  if (est.num_data() == 0) {
    r.status = Status::Degenerate;
    r.reason = "all points coincide in one image";
    return;
  }
  std::vector<std::uint32_t>& all = workspace->indices;
  all.resize(est.num_data());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<std::uint32_t>(i);
  // Reuse the estimator's normalised arrays through an unweighted refit.
  Mat3<T> F = Mat3<T>::Zero();
  if (!est.refit(all.data(), all.size(), &F)) {
    r.status = Status::Degenerate;
    r.reason = "correspondences do not determine F (null space of dimension >= 2: duplicate or collinear "
               "points, or a planar scene / pure rotation without noise)";
    return;
  }
  if (!F.allFinite()) {  // wild but finite coordinates can still defeat the solver
    r.status = Status::Degenerate;
    r.reason = "the 8-point solve produced a non-finite F (coordinates too large or too small)";
    return;
  }
  r.F = F;
  for (std::size_t i = 0; i < est.num_data(); ++i) r.inlier_mask[est.index(i)] = 1;
  r.num_inliers = est.num_data();
}

/// Convenience overload with its own workspace and a fresh result.
template <class C1, class C2, class T = typename PointTraits<container_point_t<C1>>::Scalar>
FundamentalResult<T> fundamental_8point(const C1& points1, const C2& points2) {
  FundamentalWorkspace<T> workspace;
  FundamentalResult<T> r;
  fundamental_8point(points1, points2, &workspace, &r);
  return r;
}

/// Seven-point algorithm on exactly the first seven correspondences: up to three F (rank 2 by construction).
template <class C1, class C2, class T = typename PointTraits<container_point_t<C1>>::Scalar>
FundamentalSolutions<T> fundamental_7point(const C1& points1, const C2& points2) {
  FundamentalSolutions<T> r;
  if (points1.size() < 7 || points2.size() < 7) {
    r.status = Status::TooFewPoints;
    r.reason = "the 7-point algorithm needs 7 correspondences";
    return r;
  }
  std::array<Vec2<double>, 7> a, b;
  for (std::size_t i = 0; i < 7; ++i) {
    a[i] = to_vec2<double>(points1[i]);
    b[i] = to_vec2<double>(points2[i]);
    if (!a[i].allFinite() || !b[i].allFinite()) {
      r.status = Status::NonFinite;
      r.reason = "non-finite coordinate in correspondence " + std::to_string(i);
      return r;
    }
  }
  FundamentalEstimator<T> est(a, b, false);
  if (est.num_data() < 7) {
    r.status = Status::Degenerate;
    r.reason = "all points coincide in one image";
    return r;
  }
  const std::uint32_t sample[7] = {0, 1, 2, 3, 4, 5, 6};
  r.count = est.minimal_solve(sample, r.F.data());
  if (r.count == 0) {
    r.status = Status::Degenerate;
    r.reason = "the seven correspondences do not determine a two-dimensional family of F (rank < 7), or the "
               "cubic has no real root";
  }
  return r;
}

/// LO-RANSAC estimate of F from corresponding containers (any point type with PointTraits).
/// Status: Ok; TooFewPoints (< 7 finite correspondences); InvalidInput (size mismatch, bad options);
/// Degenerate (no baseline: every correspondence at the same pixel in both images, found before any
/// sample; no model; or one homography explains the inliers: F, mask and counts are still filled).
/// Writes into `out`, reusing its buffers and the workspace's (the homography test, off in the culling
/// stages, still allocates its own).
template <class T, class C1, class C2>
void estimate_fundamental_ransac(const C1& points1, const C2& points2, const FundamentalOptions<T>& options,
                                 FundamentalWorkspace<T>* workspace, FundamentalResult<T>* out) {
  static_assert(is_point_container_v<C1> && is_point_container_v<C2>,
                "dyncull: point containers need size(), operator[] and points with PointTraits");
  FundamentalResult<T>& r = *out;
  detail::reset_fundamental_result(points1.size(), &r);
  if (points1.size() != points2.size()) {
    r.status = Status::InvalidInput;
    r.reason = "points1 and points2 differ in size";
    return;
  }
  if (options.validate(&r.reason) != Status::Ok) {
    r.status = Status::InvalidInput;
    return;
  }
  FundamentalEstimator<T>& est = workspace->estimator;
  est.load(points1, points2, options.sampson_weighted_refit);
  if (est.num_input_finite() < 7) {
    r.status = Status::TooFewPoints;
    r.reason = std::to_string(est.num_input_finite()) + " finite correspondences, F-RANSAC needs at least 7";
    return;
  }
  if (est.num_data() == 0) {
    r.status = Status::Degenerate;
    r.reason = "all points coincide in one image";
    return;
  }
  if (!est.has_baseline()) {  // every sample would fail in the solver: max_iterations of them, for nothing
    r.status = Status::Degenerate;
    r.reason = "no correspondence moved between the images (no baseline): F is not determined by the data";
    return;
  }
  RansacResult<Mat3<T>>& rr = workspace->ransac_result;
  ransac(est, options.ransac, &workspace->ransac, &rr);
  r.status = rr.status;
  r.reason = rr.reason;
  r.iterations = rr.iterations;
  r.score = rr.score;
  if (rr.inlier_mask.size() != est.num_data()) return;  // failed before any model
  if (r.ok() && !rr.model.allFinite()) {  // wild but finite coordinates can still defeat the solver
    r.status = Status::Degenerate;
    r.reason = "RANSAC produced a non-finite F (coordinates too large or too small)";
    return;
  }
  r.F = rr.model;
  std::vector<std::uint32_t>& inliers = workspace->indices;
  inliers.clear();
  for (std::size_t i = 0; i < est.num_data(); ++i) {
    if (!rr.inlier_mask[i]) continue;
    r.inlier_mask[est.index(i)] = 1;
    inliers.push_back(static_cast<std::uint32_t>(i));
  }
  r.num_inliers = rr.num_inliers;
  if (r.ok() && options.check_homography_degeneracy) {
    r.homography_inlier_fraction = est.homography_fraction(
        inliers.data(), inliers.size(), options.homography_threshold_factor * options.ransac.max_residual,
        options.ransac.seed);
    if (r.homography_inlier_fraction >= options.degenerate_homography_fraction) {
      r.status = Status::Degenerate;
      r.reason = "one homography explains " + std::to_string(clamped_int(100 * r.homography_inlier_fraction + 0.5, 0, 100)) +
                 "% of the inliers (planar scene, pure rotation or no motion): F is not determined by the data";
    }
  }
}

/// Convenience overload with its own workspace and a fresh result.
template <class T, class C1, class C2>
FundamentalResult<T> estimate_fundamental_ransac(const C1& points1, const C2& points2,
                                                 const FundamentalOptions<T>& options) {
  FundamentalWorkspace<T> workspace;
  FundamentalResult<T> r;
  estimate_fundamental_ransac(points1, points2, options, &workspace, &r);
  return r;
}

#if defined(DYNCULL_PRECOMPILED)
// Compiled once into dyncull::pipeline (src/geometry/fundamental.cpp) for the pipeline's point containers.
extern template FundamentalResult<float> estimate_fundamental_ransac(const std::vector<Vec2<float>>&,
                                                                     const std::vector<Vec2<float>>&,
                                                                     const FundamentalOptions<float>&);
extern template FundamentalResult<double> estimate_fundamental_ransac(const std::vector<Vec2<double>>&,
                                                                      const std::vector<Vec2<double>>&,
                                                                      const FundamentalOptions<double>&);
extern template FundamentalResult<float> fundamental_8point(const std::vector<Vec2<float>>&,
                                                            const std::vector<Vec2<float>>&);
extern template FundamentalResult<double> fundamental_8point(const std::vector<Vec2<double>>&,
                                                             const std::vector<Vec2<double>>&);
extern template void estimate_fundamental_ransac(const std::vector<Vec2<float>>&, const std::vector<Vec2<float>>&,
                                                 const FundamentalOptions<float>&, FundamentalWorkspace<float>*,
                                                 FundamentalResult<float>*);
extern template void estimate_fundamental_ransac(const std::vector<Vec2<double>>&, const std::vector<Vec2<double>>&,
                                                 const FundamentalOptions<double>&, FundamentalWorkspace<double>*,
                                                 FundamentalResult<double>*);
extern template void fundamental_8point(const std::vector<Vec2<float>>&, const std::vector<Vec2<float>>&,
                                        FundamentalWorkspace<float>*, FundamentalResult<float>*);
extern template void fundamental_8point(const std::vector<Vec2<double>>&, const std::vector<Vec2<double>>&,
                                        FundamentalWorkspace<double>*, FundamentalResult<double>*);
#endif

}  // namespace dyncull
