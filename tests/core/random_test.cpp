// Tests of core/random.hpp: determinism per seed, ranges, and rough uniformity / normality.
#include "dyncull/core/random.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

namespace {

TEST(Random, SameSeedSameSequenceDifferentSeedDifferent) {
  dyncull::Random a(42), b(42), c(43);
  int equal_ac = 0;
  for (int i = 0; i < 1000; ++i) {
    const auto x = a.next();
    EXPECT_EQ(x, b.next());
    equal_ac += x == c.next();
  }
  EXPECT_EQ(equal_ac, 0);
  a.reseed(42);
  dyncull::Random fresh(42);
  EXPECT_EQ(a.next(), fresh.next());
  // Seed 0 is a valid seed (splitmix64 never leaves the state all zero).
  dyncull::Random zero(0);
  EXPECT_NE(zero.next(), zero.next());
}

TEST(Random, RangesHold) {
  dyncull::Random r(7);
  for (int i = 0; i < 100000; ++i) {
    const double u = r.uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    const double w = r.uniform(-3.0, 5.0);
    ASSERT_GE(w, -3.0);
    ASSERT_LT(w, 5.0);
    ASSERT_LT(r.index(7), 7u);
    ASSERT_EQ(r.index(1), 0u);
  }
}

TEST(Random, RoughlyUniform) {
  dyncull::Random r(11);
  constexpr int kBins = 10, kDraws = 100000;
  std::array<int, kBins> counts{};
  double sum = 0, sum_sq = 0;
  for (int i = 0; i < kDraws; ++i) {
    ++counts[r.index(kBins)];
    const double u = r.uniform();
    sum += u;
    sum_sq += u * u;
  }
  // Chi-square with 9 degrees of freedom: 27.9 is the 0.1 % critical value.
  double chi2 = 0;
  for (int c : counts) chi2 += (c - kDraws / kBins) * (c - kDraws / kBins) / double(kDraws / kBins);
  EXPECT_LT(chi2, 27.9);
  const double mean = sum / kDraws, var = sum_sq / kDraws - mean * mean;
  EXPECT_NEAR(mean, 0.5, 0.005);         // standard error 0.0009
  EXPECT_NEAR(var, 1.0 / 12.0, 0.002);
}

TEST(Random, NormalMoments) {
  dyncull::Random r(13);
  constexpr int kDraws = 100000;
  double sum = 0, sum_sq = 0;
  int beyond_3sigma = 0;
  for (int i = 0; i < kDraws; ++i) {
    const double x = r.normal();
    ASSERT_TRUE(std::isfinite(x));
    sum += x;
    sum_sq += x * x;
    beyond_3sigma += std::abs(x) > 3;
  }
  EXPECT_NEAR(sum / kDraws, 0.0, 0.015);
  EXPECT_NEAR(sum_sq / kDraws, 1.0, 0.02);
  EXPECT_NEAR(beyond_3sigma, 270, 80);  // 0.27 % of draws
}

}  // namespace
