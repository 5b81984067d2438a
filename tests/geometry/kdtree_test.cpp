// Tests of geometry/kdtree.hpp: exact nearest neighbours against a brute-force oracle (float and
// double, clustered and duplicate points), the distance bound, hints, and empty/non-finite input.
#include "dyncull/geometry/kdtree.hpp"

#include "support/adversarial.hpp"
#include "support/pose_data.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

using dyncull::test::solver_value;

namespace {

using dyncull::KdTree3;
using dyncull::Random;
using dyncull::Status;
using dyncull::Vec3;

template <class T>
class KdTreeTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(KdTreeTest, Scalars, dyncull::test::ScalarNames);

template <class T>
std::uint32_t brute_force(const std::vector<Vec3<T>>& pts, const Vec3<T>& q, T* best) {
  std::uint32_t idx = KdTree3<T>::kNone;
  *best = std::numeric_limits<T>::infinity();
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (!pts[i].allFinite()) continue;
    const T d = (pts[i] - q).squaredNorm();
    if (d < *best) *best = d, idx = static_cast<std::uint32_t>(i);
  }
  return idx;
}

TYPED_TEST(KdTreeTest, MatchesBruteForce) {
  using T = TypeParam;
  Random rng(71);
  for (int leaf : {1, 4, 12, 64}) {
    std::vector<Vec3<T>> pts;
    for (int i = 0; i < 3000; ++i) {
      // Half uniform, half in a tight cluster: unbalanced cells stress the pruning.
      const double s = i % 2 ? 1.0 : 0.01;
      pts.push_back(Vec3<T>(T(rng.uniform(-s, s)), T(rng.uniform(-s, s) * 3), T(rng.uniform(-s, s))));
    }
    KdTree3<T> tree;
    ASSERT_EQ(tree.build(pts, leaf), Status::Ok);
    ASSERT_EQ(tree.size(), pts.size());
    for (int k = 0; k < 2000; ++k) {
      const Vec3<T> q(T(rng.uniform(-1.2, 1.2)), T(rng.uniform(-3.5, 3.5)), T(rng.uniform(-1.2, 1.2)));
      T d_tree = T(-1), d_brute = T(0);
      const auto i_tree = tree.nearest(q, &d_tree);
      const auto i_brute = brute_force(pts, q, &d_brute);
      // Same point, or a tie; the distance formula differs from Eigen's squaredNorm by rounding only.
      const T tol = T(8) * std::numeric_limits<T>::epsilon() * d_brute;
      ASSERT_NEAR(d_tree, d_brute, tol) << "leaf " << leaf << " query " << k;
      if (i_tree != i_brute) {
        EXPECT_NEAR((pts[i_tree] - q).squaredNorm(), d_brute, tol);
      }
    }
  }
}

TYPED_TEST(KdTreeTest, DistanceBoundAndHint) {
  using T = TypeParam;
  Random rng(72);
  std::vector<Vec3<T>> pts;
  for (int i = 0; i < 500; ++i) pts.push_back(dyncull::test::random_points<T>(rng, 1).col(0));
  const KdTree3<T> tree(pts);
  int none = 0;
  for (int k = 0; k < 500; ++k) {
    const Vec3<T> q = dyncull::test::random_points<T>(rng, 1, Vec3<T>::Zero(), 1.5).col(0);
    T d_brute = T(0);
    const auto i_brute = brute_force(pts, q, &d_brute);
    const T bound = T(0.01);
    T d = T(-1);
    const auto i = tree.nearest(q, &d, bound);
    const T tol = T(8) * std::numeric_limits<T>::epsilon() * d_brute;
    if (d_brute < bound) {
      EXPECT_NEAR(d, d_brute, tol);
    } else {
      EXPECT_EQ(i, KdTree3<T>::kNone);
      EXPECT_EQ(d, T(-1));  // untouched
      ++none;
    }
    // Any hint slot (here a random one) must not change the answer.
    T dh = T(0);
    const auto slot = tree.nearest_slot(q, &dh, std::numeric_limits<T>::infinity(),
                                        static_cast<std::uint32_t>(rng.index(500)));
    ASSERT_NE(slot, KdTree3<T>::kNone);
    EXPECT_NEAR(dh, d_brute, tol);
    EXPECT_NEAR((pts[tree.id_of_slot(slot)] - q).squaredNorm(), d_brute, tol);
    (void)i_brute;
  }
  EXPECT_GT(none, 0);  // the bound really excluded far queries
}

TYPED_TEST(KdTreeTest, DuplicatesNonFiniteAndEmpty) {
  using T = TypeParam;
  std::vector<Vec3<T>> dup(100, Vec3<T>(1, 2, 3));
  dup[50] = Vec3<T>(T(1), std::numeric_limits<T>::quiet_NaN(), T(3));
  dup.push_back(Vec3<T>(5, 5, 5));
  const KdTree3<T> tree(dup, 4);
  EXPECT_EQ(tree.size(), 100u);  // the NaN point is left out
  T d = 0;
  EXPECT_EQ(tree.nearest(Vec3<T>(5, 5, 4), &d), 100u);
  EXPECT_EQ(d, T(1));
  const auto i = tree.nearest(Vec3<T>(1, 2, 3.5), &d);
  EXPECT_NE(i, 50u);
  EXPECT_LT(i, 100u);

  KdTree3<T> empty;
  EXPECT_EQ(empty.build(std::vector<Vec3<T>>{}), Status::TooFewPoints);
  EXPECT_TRUE(empty.empty());
  EXPECT_EQ(empty.nearest(Vec3<T>(0, 0, 0), &d), KdTree3<T>::kNone);
  EXPECT_EQ(empty.build(dup, 0), Status::InvalidInput);
}

// A container claiming 2^32 + 5 points (indices would wrap): refused before any point is read.
struct HugeCloud {
  std::size_t size() const { return (std::size_t{1} << 32) + 5; }
  Vec3<double> operator[](std::size_t) const { return Vec3<double>::Constant(std::nan("")); }
};

TEST(KdTree, RefusesMorePointsThanThirtyTwoBitIndices) {
  KdTree3<double> tree;
  EXPECT_EQ(tree.build(HugeCloud{}), Status::InvalidInput);
  EXPECT_TRUE(tree.empty());
}

// For any points and queries: a returned neighbour is a finite point at the reported finite distance,
// and no finite point is strictly nearer (checked by brute force).
TYPED_TEST(KdTreeTest, PropertyNearestIsExactAndFinite) {
  using T = TypeParam;
  Random rng(87);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<Vec3<T>> pts(rng.index(80));
    for (auto& p : pts) p = Vec3<T>(solver_value<T>(rng, -5, 5), solver_value<T>(rng, -5, 5), solver_value<T>(rng, -5, 5));
    KdTree3<T> tree;
    const int leaf = rng.uniform() < 0.05 ? 0 : 1 + static_cast<int>(rng.index(16));
    const Status s = tree.build(pts, leaf);
    if (s != Status::Ok) {
      EXPECT_TRUE(tree.empty());
      continue;
    }
    for (int q = 0; q < 10; ++q) {
      const Vec3<T> query(solver_value<T>(rng, -6, 6), solver_value<T>(rng, -6, 6), solver_value<T>(rng, -6, 6));
      T d2 = T(-1);
      const std::uint32_t i = tree.nearest(query, &d2);
      if (i == KdTree3<T>::kNone) continue;
      ASSERT_LT(i, pts.size());
      EXPECT_TRUE(pts[i].allFinite());
      EXPECT_TRUE(std::isfinite(d2)) << trial;
      for (const auto& p : pts) {
        if (!p.allFinite()) continue;
        const T d = (p - query).squaredNorm();
        // The tree sums dx^2 + dy^2 + dz^2 in its own order: equal distances may differ by an ulp.
        EXPECT_FALSE(d < d2 * (T(1) - T(8) * std::numeric_limits<T>::epsilon())) << "trial " << trial;
      }
    }
  }
}

}  // namespace
