// geometry/symmetric_eigen.hpp: the Jacobi decomposition recovers known eigenvalues (ascending) and their
// vectors, keeps the vectors orthonormal through repeated and zero eigenvalues, finds the null vector of a
// rank-deficient normal matrix to rounding, and refuses non-finite input.
#include "dyncull/geometry/symmetric_eigen.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <random>

namespace {

template <int N>
using Mat = Eigen::Matrix<double, N, N>;
template <int N>
using Vec = Eigen::Matrix<double, N, 1>;

/// A random orthogonal matrix: Gram-Schmidt on Gaussian columns.
template <int N>
Mat<N> random_orthogonal(std::mt19937* rng) {
  std::normal_distribution<double> gauss;
  Mat<N> q;
  for (int j = 0; j < N; ++j) {
    Vec<N> c;
    for (int i = 0; i < N; ++i) c[i] = gauss(*rng);
    for (int k = 0; k < j; ++k) c -= q.col(k).dot(c) * q.col(k);
    q.col(j) = c.normalized();
  }
  return q;
}

template <int N>
void expect_decomposes(const Mat<N>& a, const dyncull::SymmetricEigen<N>& e) {
  const double scale = a.norm();
  EXPECT_LT((a * e.vectors - e.vectors * e.values.asDiagonal()).norm(), 1e-13 * scale);
  EXPECT_LT((e.vectors.transpose() * e.vectors - Mat<N>::Identity()).norm(), 1e-13);
  for (int i = 0; i + 1 < N; ++i) EXPECT_LE(e.values[i], e.values[i + 1]);
}

template <int N>
void check_known_spectrum(unsigned seed) {
  std::mt19937 rng(seed);
  const Mat<N> q = random_orthogonal<N>(&rng);
  Vec<N> values;
  for (int i = 0; i < N; ++i) values[i] = std::pow(10.0, i - N / 2) * (i % 2 ? 1 : -1);
  const Mat<N> a = q * values.asDiagonal() * q.transpose();
  dyncull::SymmetricEigen<N> e;
  ASSERT_TRUE(dyncull::symmetric_eigen(a, &e));
  expect_decomposes(a, e);
  Vec<N> sorted = values;
  std::sort(sorted.data(), sorted.data() + N);
  for (int i = 0; i < N; ++i) EXPECT_NEAR(e.values[i], sorted[i], 1e-13 * values.cwiseAbs().maxCoeff()) << i;
  // Distinct eigenvalues: each vector is q's column of that value, up to sign.
  for (int i = 0; i < N; ++i) {
    int col = 0;
    while (values[col] != sorted[i]) ++col;
    EXPECT_NEAR(std::abs(e.vectors.col(i).dot(q.col(col))), 1.0, 1e-9) << i;
  }
}

TEST(SymmetricEigen, RecoversAKnownSpectrumAndItsVectors) {
  check_known_spectrum<3>(1);
  check_known_spectrum<9>(2);
  check_known_spectrum<12>(3);
}

TEST(SymmetricEigen, NullVectorOfARankDeficientNormalMatrix) {
  // Eight rows of 9: the 8-point normal matrix of exact data, one zero eigenvalue.
  std::mt19937 rng(4);
  std::normal_distribution<double> gauss;
  Eigen::Matrix<double, 8, 9> rows;
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 9; ++j) rows(i, j) = gauss(rng) * (j < 3 ? 100 : 1);
  const Mat<9> ata = rows.transpose() * rows;
  dyncull::SymmetricEigen<9> e;
  ASSERT_TRUE(dyncull::symmetric_eigen(ata, &e));
  expect_decomposes(ata, e);
  EXPECT_LT(std::abs(e.values[0]), 1e-14 * e.values[8]);
  EXPECT_LT((rows * e.vectors.col(0)).norm(), 1e-12 * rows.norm());
  EXPECT_GT(e.values[1], 1e-6 * e.values[8]);
}

TEST(SymmetricEigen, RepeatedAndZeroEigenvaluesKeepOrthonormalVectors) {
  std::mt19937 rng(5);
  const Mat<9> q = random_orthogonal<9>(&rng);
  Vec<9> values;
  values << 0, 0, 0, 2, 2, 2, 2, 7, 7;
  const Mat<9> a = q * values.asDiagonal() * q.transpose();
  dyncull::SymmetricEigen<9> e;
  ASSERT_TRUE(dyncull::symmetric_eigen(a, &e));
  expect_decomposes(a, e);
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(e.values[i], values[i], 1e-13 * 7) << i;

  dyncull::SymmetricEigen<12> z;
  ASSERT_TRUE(dyncull::symmetric_eigen(Mat<12>::Zero().eval(), &z));
  EXPECT_EQ(z.values, Vec<12>::Zero());
  EXPECT_EQ(z.vectors, Mat<12>::Identity());
}

TEST(SymmetricEigen, ReadsBothTrianglesAsTheirMean) {
  Mat<3> a;
  a << 2, 1, 0, 3, 2, 0, 0, 0, 5;  // (1 + 3) / 2 = 2 off the diagonal: eigenvalues 0, 4, 5
  dyncull::SymmetricEigen<3> e;
  ASSERT_TRUE(dyncull::symmetric_eigen(a, &e));
  EXPECT_NEAR(e.values[0], 0.0, 1e-14);
  EXPECT_NEAR(e.values[1], 4.0, 1e-14);
  EXPECT_NEAR(e.values[2], 5.0, 1e-14);
}

TEST(SymmetricEigen, NonFiniteInputIsRefused) {
  for (const double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    Mat<9> a = Mat<9>::Identity();
    a(3, 5) = a(5, 3) = bad;
    dyncull::SymmetricEigen<9> e;
    EXPECT_FALSE(dyncull::symmetric_eigen(a, &e));
  }
}

}  // namespace
