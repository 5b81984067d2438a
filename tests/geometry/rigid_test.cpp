// Tests of geometry/rigid.hpp: exact recovery of SE(3)/Sim(3), agreement with Eigen::umeyama,
// weights, the reflection case, and failure statuses on degenerate or non-finite input.
#include "dyncull/geometry/rigid.hpp"

#include "support/adversarial.hpp"
#include "support/pose_data.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <limits>
#include <vector>

namespace {

using dyncull::AlignmentOptions;
using dyncull::Random;
using dyncull::Status;

using dyncull::Vec3;
template <class T> using Points = Eigen::Matrix<T, 3, Eigen::Dynamic>;

template <class T>
class UmeyamaTest : public ::testing::Test {
 protected:
  // Exact data: double recovers to ~1e-12, float to ~1e-5 (7 digits, 100 points summed).
  static T tol() { return std::is_same<T, double>::value ? T(1e-10) : T(2e-4); }
};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(UmeyamaTest, Scalars, dyncull::test::ScalarNames);

TYPED_TEST(UmeyamaTest, RecoversRigidTransformExactly) {
  using T = TypeParam;
  Random rng(7);
  const auto g = dyncull::test::random_rigid<T>(rng, 2.5, 3.0);
  const Points<T> src = dyncull::test::random_points<T>(rng, 100);
  const Points<T> dst = (g.R * src).colwise() + g.t;
  const auto r = dyncull::umeyama(src, dst);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.dst_from_src.scale, T(1));
  EXPECT_LT((r.rigid().R - g.R).norm(), this->tol());
  EXPECT_LT((r.rigid().t - g.t).norm(), this->tol());
  EXPECT_EQ(r.num_points, 100u);
}

TYPED_TEST(UmeyamaTest, RecoversSimilarityFarFromOrigin) {
  using T = TypeParam;
  Random rng(8);
  const auto g = dyncull::test::random_rigid<T>(rng, 3.0, 2.0);
  const T s = T(2.7);
  // Far-from-origin points: a naive one-pass moment sum would lose digits here.
  const Points<T> src = dyncull::test::random_points<T>(rng, 200, Vec3<T>(100, -50, 30), 2.0);
  const Points<T> dst = ((s * g.R) * src).colwise() + g.t;
  AlignmentOptions o;
  o.estimate_scale = true;
  const auto r = dyncull::umeyama(src, dst, o);
  ASSERT_TRUE(r.ok()) << r.reason;
  const T rel = std::is_same<T, double>::value ? T(1e-9) : T(2e-3);
  EXPECT_NEAR(r.dst_from_src.scale, s, rel * s);
  EXPECT_LT((r.dst_from_src.R - g.R).norm(), rel);
  EXPECT_LT((r.dst_from_src.t - g.t).norm(), rel * T(300));
}

TYPED_TEST(UmeyamaTest, ZeroWeightsIgnoreOutliers) {
  using T = TypeParam;
  Random rng(9);
  const auto g = dyncull::test::random_rigid<T>(rng);
  const Points<T> src = dyncull::test::random_points<T>(rng, 50);
  Points<T> dst = (g.R * src).colwise() + g.t;
  std::vector<T> w(50, T(1));
  for (int i = 0; i < 10; ++i) {
    dst.col(i) += Vec3<T>(5, -3, 2);
    w[static_cast<std::size_t>(i)] = T(0);
  }
  const auto r = dyncull::umeyama(src, dst, {}, w.data());
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.num_points, 40u);
  EXPECT_LT((r.rigid().R - g.R).norm(), this->tol());
  EXPECT_LT((r.rigid().t - g.t).norm(), this->tol());
  // Without weights the outliers must pull the estimate away (the weights really were used).
  const auto u = dyncull::umeyama(src, dst);
  EXPECT_GT((u.rigid().t - g.t).norm(), T(0.1));
}

TYPED_TEST(UmeyamaTest, WeightedEqualsRepeatedPoints) {
  using T = TypeParam;
  Random rng(10);
  const Points<T> src = dyncull::test::random_points<T>(rng, 20);
  const Points<T> dst = dyncull::test::random_points<T>(rng, 20);  // unrelated: a genuine least-squares fit
  std::vector<T> w(20, T(1));
  w[3] = T(3);
  Points<T> src_rep(3, 22), dst_rep(3, 22);
  src_rep << src, src.col(3), src.col(3);
  dst_rep << dst, dst.col(3), dst.col(3);
  const auto a = dyncull::umeyama(src, dst, {}, w.data());
  const auto b = dyncull::umeyama(src_rep, dst_rep);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_LT((a.rigid().R - b.rigid().R).norm(), this->tol());
  EXPECT_LT((a.rigid().t - b.rigid().t).norm(), this->tol());
}

TYPED_TEST(UmeyamaTest, ReflectionIsNotReturned) {
  using T = TypeParam;
  Random rng(11);
  const Points<T> src = dyncull::test::random_points<T>(rng, 30);
  Points<T> dst = src;
  dst.row(2) *= T(-1);  // a mirror: the best proper rotation still has det +1
  const auto r = dyncull::umeyama(src, dst);
  ASSERT_TRUE(r.ok());
  EXPECT_NEAR(r.rigid().R.determinant(), T(1), this->tol());
  EXPECT_LT((r.rigid().R * r.rigid().R.transpose() - dyncull::Mat3<T>::Identity()).norm(), this->tol());
}

TYPED_TEST(UmeyamaTest, FailsOnBadInput) {
  using T = TypeParam;
  Points<T> two(3, 2);
  two << 0, 1, 0, 0, 0, 1;
  EXPECT_EQ(dyncull::umeyama(two, two).status, Status::TooFewPoints);

  Points<T> line(3, 10);
  for (int i = 0; i < 10; ++i) line.col(i) = Vec3<T>(1, 2, 3) * T(i) + Vec3<T>(4, 5, 6);
  const auto c = dyncull::umeyama(line, line);
  EXPECT_EQ(c.status, Status::Degenerate);
  EXPECT_FALSE(c.reason.empty());

  Points<T> same(3, 5);
  same.colwise() = Vec3<T>(1, 1, 1);
  EXPECT_EQ(dyncull::umeyama(same, same).status, Status::Degenerate);

  Random rng(12);
  Points<T> p = dyncull::test::random_points<T>(rng, 10);
  Points<T> q = p;
  q(1, 4) = std::numeric_limits<T>::quiet_NaN();
  EXPECT_EQ(dyncull::umeyama(p, q).status, Status::NonFinite);
  q(1, 4) = std::numeric_limits<T>::infinity();
  EXPECT_EQ(dyncull::umeyama(p, q).status, Status::NonFinite);

  Points<T> shorter = p.leftCols(9);
  EXPECT_EQ(dyncull::umeyama(p, shorter).status, Status::InvalidInput);

  std::vector<T> w(10, T(1));
  w[2] = T(-1);
  EXPECT_EQ(dyncull::umeyama(p, p, {}, w.data()).status, Status::InvalidInput);
  std::vector<T> w0(10, T(0));
  w0[0] = w0[1] = T(1);
  EXPECT_EQ(dyncull::umeyama(p, p, {}, w0.data()).status, Status::TooFewPoints);
}

TYPED_TEST(UmeyamaTest, LargeFiniteCoordinatesAreAlignedNotCalledNonFinite) {
  using T = TypeParam;
  // Coordinates whose squares overflow T (double: 1e160^2 = 1e320; float: 1e25^2 = 1e50): the data
  // are finite and well spread, so the fit exists and must be found.
  Random rng(21);
  const dyncull::Rigid3<T> g = dyncull::test::random_rigid<T>(rng, 1.0, 0.0);
  for (const double big : {std::is_same<T, double>::value ? 1e160 : 1e25,
                           std::is_same<T, double>::value ? 1e300 : 1e36}) {
    for (const bool scale : {false, true}) {
      const Points<T> src = dyncull::test::random_points<T>(rng, 40) * T(big);
      Points<T> dst = g.R * src;
      dst.colwise() += Vec3<T>(T(0.5 * big), T(-0.25 * big), T(0.1 * big));
      AlignmentOptions o;
      o.estimate_scale = scale;
      const auto r = dyncull::umeyama(src, dst, o);
      ASSERT_TRUE(r.ok()) << big << ": " << r.reason;
      EXPECT_LT((r.rigid().R - g.R).norm(), T(1e3) * this->tol()) << big;
      EXPECT_NEAR(r.dst_from_src.scale, T(1), T(1e3) * this->tol());
      EXPECT_TRUE(r.dst_from_src.t.allFinite());
      EXPECT_NEAR(r.dst_from_src.t.x() / T(big), T(0.5), T(1e3) * this->tol());
    }
  }
  // Weighted, with weights that overflow their products with the coordinates.
  const Points<T> src = dyncull::test::random_points<T>(rng, 12) * T(1e3);
  const Points<T> dst = g.R * src;
  const std::vector<T> w(12, std::numeric_limits<T>::max() / T(8));
  const auto rw = dyncull::umeyama(src, dst, {}, w.data());
  ASSERT_TRUE(rw.ok()) << rw.reason;
  EXPECT_LT((rw.rigid().R - g.R).norm(), T(1e3) * this->tol());
}

// Cross-check against Eigen's own implementation on noisy data (not just exact data).
TEST(UmeyamaVsEigen, MatchesEigenUmeyamaTo1e12) {
  Random rng(13);
  for (int trial = 0; trial < 20; ++trial) {
    const auto g = dyncull::test::random_rigid<double>(rng, 3.0, 5.0);
    const Points<double> src = dyncull::test::random_points<double>(rng, 1000, Vec3<double>(3, 1, 2), 4.0);
    Points<double> dst = (g.R * src).colwise() + g.t;
    for (int i = 0; i < dst.cols(); ++i) dst.col(i) += 0.05 * Vec3<double>(rng.normal(), rng.normal(), rng.normal());
    for (bool scale : {false, true}) {
      AlignmentOptions o;
      o.estimate_scale = scale;
      const auto r = dyncull::umeyama(src, dst, o);
      ASSERT_TRUE(r.ok());
      const Eigen::Matrix4d e = Eigen::umeyama(src, dst, scale);
      Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
      m.topLeftCorner<3, 3>() = r.dst_from_src.scale * r.dst_from_src.R;
      m.topRightCorner<3, 1>() = r.dst_from_src.t;
      EXPECT_LT((m - e).cwiseAbs().maxCoeff(), 1e-12) << "trial " << trial << " scale " << scale;
    }
  }
}

// A value for property tests: mostly ordinary, sometimes NaN, Inf, huge or tiny (tests/support/adversarial.hpp).
template <class T>
T alignment_value(Random& rng, double lo, double hi) {
  return dyncull::test::adversarial_value<T>(rng, lo, hi, dyncull::test::kAlignmentMix);
}

// For any input: a non-Ok status with a reason, or a finite proper rotation, scale and translation.
TYPED_TEST(UmeyamaTest, PropertyAlignmentIsFiniteOrTheCallFails) {
  using T = TypeParam;
  Random rng(41);
  for (int trial = 0; trial < 400; ++trial) {
    const int n = static_cast<int>(rng.index(12));
    const bool clean = rng.uniform() < 0.2;
    const double magnitude = std::pow(10.0, rng.uniform(-30, 30));
    Points<T> src(3, n), dst(3, n);
    for (int i = 0; i < n; ++i) {
      for (int r = 0; r < 3; ++r) {
        src(r, i) = clean ? T(rng.uniform(-1, 1) * magnitude) : alignment_value<T>(rng, -magnitude, magnitude);
        dst(r, i) = clean ? T(rng.uniform(-1, 1) * magnitude) : alignment_value<T>(rng, -magnitude, magnitude);
      }
    }
    std::vector<T> w(static_cast<std::size_t>(n));
    for (auto& x : w) x = rng.uniform() < 0.1 ? alignment_value<T>(rng, 0, 2) : T(rng.uniform(0, 2));
    AlignmentOptions o;
    o.estimate_scale = rng.uniform() < 0.5;
    const bool weighted = rng.uniform() < 0.4;
    const auto r = dyncull::umeyama(src, dst, o, weighted ? w.data() : nullptr);
    if (!r.ok()) {
      EXPECT_FALSE(r.reason.empty()) << trial;
      continue;
    }
    EXPECT_TRUE(r.dst_from_src.R.allFinite()) << trial;
    EXPECT_TRUE(r.dst_from_src.t.allFinite()) << trial;
    EXPECT_TRUE(std::isfinite(r.dst_from_src.scale)) << trial;
    EXPECT_NEAR(r.dst_from_src.R.determinant(), T(1), T(1e-3)) << trial;
  }
}

}  // namespace
