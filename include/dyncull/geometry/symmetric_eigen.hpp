/// @file symmetric_eigen.hpp
/// Eigen-decomposition of a small symmetric matrix by cyclic Jacobi rotations (Golub & Van Loan 2013,
/// Matrix Computations, sec. 8.5): the null vectors of the 8-point (Hartley 1997), DLT-homography and DLT-PnP
/// normal matrices. It compiles in a fraction of a second where Eigen's fixed-size SelfAdjointEigenSolver
/// costs every header-only unit about 13 s (g++ -O2, 9x9), and it is as accurate (eigenvalues to eps times the
/// matrix's norm); it runs about 2x slower (bench/geometry/symmetric_eigen_bench.cpp), a few times per F-RANSAC.
#pragma once

#include <Eigen/Core>

#include <cmath>
#include <limits>
#include <utility>

namespace dyncull {

/// Eigenvalues (ascending) and unit eigenvectors (the columns, in the same order) of a symmetric matrix.
template <int N>
struct SymmetricEigen {
  Eigen::Matrix<double, N, 1> values;
  Eigen::Matrix<double, N, N> vectors;
};

namespace detail {

/// One Jacobi rotation in the (p, q) plane, a <- J^T a J, that zeroes a(p, q) (both triangles are kept);
/// v <- v J accumulates the rotations.
template <int N>
void jacobi_rotate(Eigen::Matrix<double, N, N>* a, Eigen::Matrix<double, N, N>* v, int p, int q) {
  Eigen::Matrix<double, N, N>& A = *a;
  const double apq = A(p, q);
  // t = tan(angle), the smaller root of t^2 + 2 theta t - 1 = 0 (rotation angle <= pi/4: stable).
  const double theta = (A(q, q) - A(p, p)) / (2 * apq);
  const double t = (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1));
  const double c = 1 / std::sqrt(t * t + 1), s = t * c;
  A(p, p) -= t * apq;
  A(q, q) += t * apq;
  A(p, q) = A(q, p) = 0;
  for (int k = 0; k < N; ++k) {
    if (k == p || k == q) continue;
    const double akp = A(k, p), akq = A(k, q);
    A(k, p) = A(p, k) = c * akp - s * akq;
    A(k, q) = A(q, k) = s * akp + c * akq;
  }
  for (int k = 0; k < N; ++k) {
    const double vkp = (*v)(k, p), vkq = (*v)(k, q);
    (*v)(k, p) = c * vkp - s * vkq;
    (*v)(k, q) = s * vkp + c * vkq;
  }
}

/// Sum of squares of the off-diagonal entries (summed directly: the full norm minus the diagonal's would
/// cancel).
template <int N>
double off_diagonal_norm2(const Eigen::Matrix<double, N, N>& a) {
  double sum = 0;
  for (int p = 0; p < N - 1; ++p)
    for (int q = p + 1; q < N; ++q) sum += a(p, q) * a(p, q);
  return 2 * sum;
}

}  // namespace detail

/// Decomposes the symmetric matrix a (only its values matter, both triangles are read). False when an entry
/// is not finite or the rotations do not converge (then *out is unspecified).
template <int N>
bool symmetric_eigen(const Eigen::Matrix<double, N, N>& a, SymmetricEigen<N>* out) {
  if (!a.allFinite()) return false;
  Eigen::Matrix<double, N, N> A = (a + a.transpose()) / 2;
  Eigen::Matrix<double, N, N> V = Eigen::Matrix<double, N, N>::Identity();
  // Converged when the off-diagonal mass is below rounding of the whole matrix; a rotation of an entry that is
  // negligible beside both its diagonal entries is skipped (it could not change them).
  const double eps = std::numeric_limits<double>::epsilon();
  const double tolerance2 = eps * eps * A.squaredNorm();
  constexpr int kMaxSweeps = 50;  // quadratic convergence: 6-10 sweeps for N <= 12
  for (int sweep = 0; sweep < kMaxSweeps && detail::off_diagonal_norm2(A) > tolerance2; ++sweep)
    for (int p = 0; p < N - 1; ++p)
      for (int q = p + 1; q < N; ++q) {
        if (std::abs(A(p, q)) <= 1e-18 * (std::abs(A(p, p)) + std::abs(A(q, q)))) {
          A(p, q) = A(q, p) = 0;
          continue;
        }
        detail::jacobi_rotate(&A, &V, p, q);
      }
  const bool converged = !(detail::off_diagonal_norm2(A) > tolerance2);
  if (!converged) return false;
  // Ascending order, vectors alongside (selection sort: N is small).
  Eigen::Matrix<double, N, 1> d = A.diagonal();
  for (int i = 0; i < N - 1; ++i) {
    int m = i;
    for (int j = i + 1; j < N; ++j)
      if (d[j] < d[m]) m = j;
    if (m == i) continue;
    std::swap(d[i], d[m]);
    V.col(i).swap(V.col(m));
  }
  out->values = d;
  out->vectors = V;
  return true;
}

}  // namespace dyncull
