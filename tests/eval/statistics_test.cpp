#include "dyncull/core/random.hpp"
#include "dyncull/core/types.hpp"
#include "dyncull/eval/statistics.hpp"

#include <gtest/gtest.h>

#include "support/adversarial.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace {

using namespace dyncull;
using namespace dyncull::eval;

template <class T>
class StatisticsTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(StatisticsTest, Scalars, );

TYPED_TEST(StatisticsTest, KnownValuesEvenCount) {
  using T = TypeParam;
  const std::vector<T> v{T(4), T(1), T(3), T(2)};
  const ErrorStatistics<T> s = compute_statistics(v);
  ASSERT_TRUE(s.ok()) << s.reason;
  const T tol = Constants<T>::small();
  EXPECT_EQ(s.count, 4u);
  EXPECT_NEAR(s.rmse, std::sqrt(T(30) / T(4)), tol);
  EXPECT_NEAR(s.mean, T(2.5), tol);
  EXPECT_NEAR(s.median, T(2.5), tol);       // numpy: mean of the two middle values
  EXPECT_NEAR(s.std, std::sqrt(T(1.25)), tol);  // population std (ddof 0), not sqrt(5/3)
  EXPECT_EQ(s.min, T(1));
  EXPECT_EQ(s.max, T(4));
}

TYPED_TEST(StatisticsTest, KnownValuesOddCountAndSingle) {
  using T = TypeParam;
  const std::vector<T> v{T(5), T(1), T(3)};
  const ErrorStatistics<T> s = compute_statistics(v);
  ASSERT_TRUE(s.ok());
  EXPECT_EQ(s.median, T(3));
  const std::vector<T> one{T(0.25)};
  const ErrorStatistics<T> s1 = compute_statistics(one);
  ASSERT_TRUE(s1.ok());
  EXPECT_EQ(s1.median, T(0.25));
  EXPECT_EQ(s1.std, T(0));
  EXPECT_EQ(s1.rmse, T(0.25));
}

TYPED_TEST(StatisticsTest, MedianMatchesFullSortOnRandomData) {
  using T = TypeParam;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int n : {2, 5, 10, 101, 1000}) {
    std::vector<T> v(static_cast<std::size_t>(n));
    for (T& x : v) x = static_cast<T>(u(rng));
    std::vector<T> sorted = v;
    std::sort(sorted.begin(), sorted.end());
    const std::size_t h = sorted.size() / 2;
    const double expect = n % 2 ? double(sorted[h]) : 0.5 * (double(sorted[h - 1]) + double(sorted[h]));
    std::vector<T> scratch;
    const ErrorStatistics<T> s = compute_statistics(v.data(), v.size(), &scratch);
    ASSERT_TRUE(s.ok());
    EXPECT_EQ(s.median, static_cast<T>(expect)) << n;
    EXPECT_EQ(s.min, sorted.front());
    EXPECT_EQ(s.max, sorted.back());
  }
}

TYPED_TEST(StatisticsTest, EmptyAndNonFiniteAreReportedNotSummarised) {
  using T = TypeParam;
  const std::vector<T> empty;
  const ErrorStatistics<T> s0 = compute_statistics(empty);
  EXPECT_EQ(s0.status, Status::TooFewPoints);
  EXPECT_FALSE(s0.reason.empty());
  EXPECT_TRUE(std::isnan(s0.rmse));
  const std::vector<T> bad{T(1), Constants<T>::nan(), T(2)};
  const ErrorStatistics<T> s1 = compute_statistics(bad);
  EXPECT_EQ(s1.status, Status::NonFinite);
  EXPECT_NE(s1.reason.find("value 1"), std::string::npos) << s1.reason;
}

TYPED_TEST(StatisticsTest, HugeFiniteValuesGiveFiniteStatistics) {
  using T = TypeParam;
  // Squares (and, for double, sums) overflow; the statistics themselves are representable.
  const T big = std::numeric_limits<T>::max() / T(2);
  const std::vector<T> v{big, big, T(0), big};
  const ErrorStatistics<T> s = compute_statistics(v);
  ASSERT_TRUE(s.ok()) << s.reason;
  for (T x : {s.rmse, s.mean, s.median, s.std, s.min, s.max}) EXPECT_TRUE(std::isfinite(x)) << x;
  EXPECT_EQ(s.max, big);
  EXPECT_EQ(s.median, big);
  EXPECT_NEAR(double(s.mean) / double(big), 0.75, 1e-6);
  EXPECT_NEAR(double(s.rmse) / double(big), std::sqrt(0.75), 1e-6);
  EXPECT_NEAR(double(s.std) / double(big), std::sqrt(0.75 * 0.25), 1e-6);
  // Values of both signs near the limit: the median of the two middle values does not overflow either.
  const std::vector<T> w{-big, big};
  const ErrorStatistics<T> t = compute_statistics(w);
  ASSERT_TRUE(t.ok()) << t.reason;
  EXPECT_EQ(t.median, T(0));
  EXPECT_TRUE(std::isfinite(t.std));
}

TEST(ImprovementRate, ReproducesPaperTable) {
  // Zhu et al. 2024 Table 4, walking_xyz ATE RMSE: ORB-SLAM3 0.6459 m, theirs 0.1290 m -> "80.02 %". The paper
  // truncates to two decimals (the exact rate is 80.0279 %), so compare the truncated percentage.
  auto truncated_percent = [](double rate) { return std::floor(rate * 1e4) / 100.0; };
  EXPECT_NEAR(truncated_percent(improvement_rate(0.6459, 0.1290)), 80.02, 1e-9);
  EXPECT_NEAR(truncated_percent(improvement_rate(0.4256, 0.1204)), 71.71, 1e-9);  // Table 5 RPE RMSE
  EXPECT_NEAR(improvement_rate(0.5f, 0.125f), 0.75f, 1e-7f);
  EXPECT_LT(improvement_rate(0.1, 0.2), 0.0);  // worse than the baseline: negative
  EXPECT_TRUE(std::isnan(improvement_rate(0.0, 0.1)));
  EXPECT_TRUE(std::isnan(improvement_rate(1.0, std::nan(""))));
}

// A value for property tests: mostly ordinary, sometimes NaN, Inf, huge or tiny (tests/support/adversarial.hpp).
template <class T>
T wild_value(dyncull::Random& rng, double lo, double hi) {
  return dyncull::test::adversarial_value<T>(rng, lo, hi, dyncull::test::kStatisticsMix);
}

TYPED_TEST(StatisticsTest, PropertyStatisticsAreFiniteOrTheCallFails) {
  using T = TypeParam;
  dyncull::Random rng(31);
  for (int trial = 0; trial < 400; ++trial) {
    const std::size_t n = rng.index(20);
    const bool clean = rng.uniform() < 0.3;
    std::vector<T> v(n);
    for (auto& x : v) x = clean ? T(rng.uniform(0, 10)) : wild_value<T>(rng, 0, 10);
    const ErrorStatistics<T> s = compute_statistics(v);
    if (!s.ok()) {
      EXPECT_FALSE(s.reason.empty());
      EXPECT_TRUE(n == 0 || std::any_of(v.begin(), v.end(), [](T x) { return !std::isfinite(x); })) << trial;
      continue;
    }
    for (T x : {s.rmse, s.mean, s.median, s.std, s.min, s.max}) EXPECT_TRUE(std::isfinite(x)) << trial;
    EXPECT_LE(s.min, s.median);
    EXPECT_LE(s.median, s.max);
  }
}

}  // namespace
