// Tests of the generic LO-RANSAC (geometry/ransac.hpp) on a 2-D line estimator with known truth.
#include "dyncull/geometry/ransac.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

namespace dyncull {
namespace {

/// Line a x + b y + c = 0 with a^2 + b^2 = 1; residual = point-line distance.
template <class T>
struct LineEstimator {
  using Scalar = T;
  struct Model {
    T a = 0, b = 1, c = 0;
  };
  static constexpr int kSampleSize = 2;
  static constexpr int kMaxModels = 1;

  std::vector<T> x, y;
  mutable std::size_t solves = 0;
  mutable std::size_t refits = 0;

  std::size_t num_data() const { return x.size(); }
  int minimal_solve(const std::uint32_t* s, Model* m) const {
    ++solves;
    const T dx = x[s[1]] - x[s[0]], dy = y[s[1]] - y[s[0]];
    const T len = std::sqrt(dx * dx + dy * dy);
    if (!(len > T(1e-6))) return 0;
    m->a = -dy / len;
    m->b = dx / len;
    m->c = -(m->a * x[s[0]] + m->b * y[s[0]]);
    return 1;
  }
  void residuals_sq(const Model& m, T* out) const {
    for (std::size_t i = 0; i < x.size(); ++i) {
      const T d = m.a * x[i] + m.b * y[i] + m.c;
      out[i] = d * d;
    }
  }
  /// Total least squares on the inliers.
  bool refit(const std::uint32_t* idx, std::size_t n, Model* m) const {
    ++refits;
    if (n < 2) return false;
    double mx = 0, my = 0;
    for (std::size_t i = 0; i < n; ++i) mx += x[idx[i]], my += y[idx[i]];
    mx /= double(n), my /= double(n);
    double sxx = 0, sxy = 0, syy = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double dx = x[idx[i]] - mx, dy = y[idx[i]] - my;
      sxx += dx * dx, sxy += dx * dy, syy += dy * dy;
    }
    // Normal = eigenvector of the scatter matrix with the smaller eigenvalue.
    const double theta = 0.5 * std::atan2(2 * sxy, sxx - syy);
    const double a = -std::sin(theta), b = std::cos(theta);
    m->a = T(a), m->b = T(b), m->c = T(-(a * mx + b * my));
    return true;
  }
};

/// Same estimator with the optional hooks (range residuals, sample check).
template <class T>
struct LineEstimatorHooks : LineEstimator<T> {
  using Model = typename LineEstimator<T>::Model;
  mutable std::size_t rejected = 0;
  void residuals_sq(const Model& m, T* out) const { LineEstimator<T>::residuals_sq(m, out); }
  void residuals_sq(const Model& m, std::size_t begin, std::size_t end, T* out) const {
    for (std::size_t i = begin; i < end; ++i) {
      const T d = m.a * this->x[i] + m.b * this->y[i] + m.c;
      out[i - begin] = d * d;
    }
  }
  bool is_sample_good(const std::uint32_t* s) const {
    const bool good = std::abs(this->x[s[0]] - this->x[s[1]]) > T(1);  // reject close pairs
    rejected += !good;
    return good;
  }
};

/// y = 0.5 x + 2 with noise sigma, the first `outliers` points uniform in the square.
template <class E>
E make_line(std::size_t n, std::size_t outliers, double sigma, std::uint64_t seed) {
  E e;
  Random rng(seed);
  for (std::size_t i = 0; i < n; ++i) {
    const double x = rng.uniform(-100, 100);
    double y = 0.5 * x + 2 + sigma * rng.normal();
    if (i < outliers) y = rng.uniform(-100, 100);
    e.x.push_back(static_cast<typename E::Scalar>(x));
    e.y.push_back(static_cast<typename E::Scalar>(y));
  }
  return e;
}

template <class T>
class RansacTyped : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(RansacTyped, Scalars, );  // trailing comma: clang -Wpedantic rejects an empty variadic

TYPED_TEST(RansacTyped, RecoversLineWith40PercentOutliers) {
  using T = TypeParam;
  auto e = make_line<LineEstimator<T>>(500, 200, 0.2, 7);
  RansacOptions opt;
  opt.max_residual = 1.0;
  opt.seed = 3;
  const auto r = ransac(e, opt);
  ASSERT_TRUE(r.ok()) << r.reason;
  // Slope 0.5: normal direction (-0.5, 1)/|.| up to sign.
  const double slope = -double(r.model.a) / double(r.model.b);
  const double icpt = -double(r.model.c) / double(r.model.b);
  EXPECT_NEAR(slope, 0.5, 0.01);
  EXPECT_NEAR(icpt, 2.0, 0.2);
  // All 300 true inliers have |noise| < 5 sigma = 1.0 px in distance (slope shrinks it), except rare tails.
  std::size_t true_in_found = 0, false_in = 0;
  for (std::size_t i = 0; i < 500; ++i) {
    if (i >= 200) true_in_found += r.inlier_mask[i];
    else false_in += r.inlier_mask[i];
  }
  EXPECT_GE(true_in_found, 297u);
  // Uniform outliers within 1 of the line: ~2*1.12/200 of the 200 (about 2-3); allow 10.
  EXPECT_LE(false_in, 10u);
  EXPECT_EQ(r.num_inliers, true_in_found + false_in);
  EXPECT_EQ(r.inlier_mask.size(), 500u);
  EXPECT_GT(e.refits, 0u);
  // Adaptive stop: with w ~ 0.6 and s = 2, about 11 samples at p = 0.99, far below max_iterations.
  EXPECT_LT(r.iterations, 40u);
}

TYPED_TEST(RansacTyped, HooksGiveTheSameAnswerAndAreCalled) {
  using T = TypeParam;
  auto plain = make_line<LineEstimator<T>>(1000, 300, 0.2, 11);
  LineEstimatorHooks<T> hooks;
  hooks.x = plain.x;
  hooks.y = plain.y;
  RansacOptions opt;
  opt.seed = 5;
  const auto a = ransac(plain, opt);
  const auto b = ransac(hooks, opt);
  ASSERT_TRUE(a.ok()) << a.reason;
  ASSERT_TRUE(b.ok()) << b.reason;
  EXPECT_NEAR(-double(b.model.a) / double(b.model.b), 0.5, 0.01);
  // Both converge to the same least-squares line after LO: inlier sets agree up to a few borderline points.
  EXPECT_NEAR(double(a.num_inliers), double(b.num_inliers), 5.0);
  (void)hooks.rejected;  // may be zero for a lucky seed; the sample-check test below forces it
}

TYPED_TEST(RansacTyped, IsSampleGoodIsConsulted) {
  using T = TypeParam;
  LineEstimatorHooks<T> e;
  // All x within 0.5 of each other: every sample is rejected, so no model can exist.
  for (int i = 0; i < 20; ++i) {
    e.x.push_back(T(0.01) * T(i));
    e.y.push_back(T(i));
  }
  RansacOptions opt;
  opt.max_iterations = 50;
  const auto r = ransac(e, opt);
  EXPECT_EQ(r.status, Status::Degenerate);
  EXPECT_FALSE(r.reason.empty());
  EXPECT_EQ(e.rejected, 50u);
  EXPECT_EQ(e.solves, 0u);
  EXPECT_EQ(r.iterations, 50u);
}

TYPED_TEST(RansacTyped, SameSeedSameResultDifferentSeedDifferentSamples) {
  using T = TypeParam;
  auto e = make_line<LineEstimator<T>>(400, 200, 0.3, 21);
  RansacOptions opt;
  opt.local_optimisation = false;  // keep the minimal-sample model so the seed's effect is visible
  opt.seed = 1;
  const auto a = ransac(e, opt);
  const auto b = ransac(e, opt);
  ASSERT_TRUE(a.ok());
  EXPECT_EQ(a.inlier_mask, b.inlier_mask);
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_EQ(a.model.a, b.model.a);
  EXPECT_EQ(a.model.c, b.model.c);
  // Different seeds pick different minimal samples, hence (without LO) different models; both are good.
  int differing = 0;
  for (std::uint64_t s = 2; s < 7; ++s) {
    opt.seed = s;
    const auto c = ransac(e, opt);
    ASSERT_TRUE(c.ok());
    EXPECT_NEAR(-double(c.model.a) / double(c.model.b), 0.5, 0.05);
    differing += (c.model.c != a.model.c) || (c.iterations != a.iterations);
  }
  EXPECT_GE(differing, 4);
}

TYPED_TEST(RansacTyped, LocalOptimisationDoesNotWorsenTheScore) {
  using T = TypeParam;
  auto e = make_line<LineEstimator<T>>(600, 250, 0.3, 33);
  RansacOptions opt;
  opt.seed = 9;
  opt.local_optimisation = false;
  const auto plain = ransac(e, opt);
  opt.local_optimisation = true;
  const auto lo = ransac(e, opt);
  ASSERT_TRUE(plain.ok() && lo.ok());
  EXPECT_LE(lo.score, plain.score * (1 + 1e-6));
  EXPECT_GE(lo.num_inliers + 3, plain.num_inliers);
}

TYPED_TEST(RansacTyped, BadInputsReturnStatus) {
  using T = TypeParam;
  LineEstimator<T> one;
  one.x = {T(1)};
  one.y = {T(2)};
  auto r = ransac(one, RansacOptions{});
  EXPECT_EQ(r.status, Status::TooFewPoints);
  EXPECT_FALSE(r.reason.empty());

  LineEstimator<T> empty;
  EXPECT_EQ(ransac(empty, RansacOptions{}).status, Status::TooFewPoints);

  auto e = make_line<LineEstimator<T>>(50, 0, 0.1, 1);
  RansacOptions bad;
  bad.max_residual = -1;
  EXPECT_EQ(ransac(e, bad).status, Status::InvalidInput);
  bad = RansacOptions{};
  bad.max_residual = std::nan("");
  EXPECT_EQ(ransac(e, bad).status, Status::InvalidInput);
  bad = RansacOptions{};
  bad.confidence = 1.5;
  EXPECT_EQ(ransac(e, bad).status, Status::InvalidInput);
  bad = RansacOptions{};
  bad.max_iterations = 0;
  EXPECT_EQ(ransac(e, bad).status, Status::InvalidInput);
  bad = RansacOptions{};
  bad.min_iterations = 20;
  bad.max_iterations = 10;
  const auto inv = ransac(e, bad);
  EXPECT_EQ(inv.status, Status::InvalidInput);
  EXPECT_FALSE(inv.reason.empty());

  // All points identical: the solver rejects every sample.
  LineEstimator<T> same;
  same.x.assign(30, T(3));
  same.y.assign(30, T(4));
  RansacOptions few;
  few.max_iterations = 100;
  const auto d = ransac(same, few);
  EXPECT_EQ(d.status, Status::Degenerate);
  EXPECT_EQ(d.iterations, 100u);

  // NaN data: NaN residuals are outliers, the finite points still give the line.
  auto n = make_line<LineEstimator<T>>(200, 0, 0.1, 4);
  for (std::size_t i = 0; i < 40; ++i) n.x[i] = std::numeric_limits<T>::quiet_NaN();
  const auto rn = ransac(n, RansacOptions{});
  ASSERT_TRUE(rn.ok()) << rn.reason;
  for (std::size_t i = 0; i < 40; ++i) EXPECT_EQ(rn.inlier_mask[i], 0);
  EXPECT_NEAR(-double(rn.model.a) / double(rn.model.b), 0.5, 0.01);
}

TYPED_TEST(RansacTyped, MinIterationsIsHonoured) {
  using T = TypeParam;
  auto e = make_line<LineEstimator<T>>(100, 0, 0.05, 2);
  RansacOptions opt;
  opt.min_iterations = 123;
  EXPECT_EQ(ransac(e, opt).iterations, 123u);
  opt.min_iterations = 0;
  // No outliers: w = 1 after the first good model, so the adaptive rule stops after one sample.
  EXPECT_LE(ransac(e, opt).iterations, 3u);
}

TEST(RansacStoppingRule, KnownValues) {
  // k = ceil(log(1 - p) / log(1 - w^s)).
  EXPECT_EQ(ransac_required_iterations(0.5, 2, 0.99, 100000), 17u);    // log(.01)/log(.75) = 16.0078
  EXPECT_EQ(ransac_required_iterations(0.7, 7, 0.99, 100000), 54u);    // 1-0.7^7 = 0.917646
  EXPECT_EQ(ransac_required_iterations(0.7, 8, 0.99, 100000), 78u);    // 1-0.7^8 = 0.942352
  EXPECT_EQ(ransac_required_iterations(0.5, 4, 0.999, 100000), 108u);  // log(.001)/log(.9375)
  // Guards.
  EXPECT_EQ(ransac_required_iterations(0.5, 7, 1.0, 500), 500u);   // p = 1 never stops early
  EXPECT_EQ(ransac_required_iterations(0.5, 7, 0.0, 500), 1u);     // p = 0 needs one sample
  EXPECT_EQ(ransac_required_iterations(0.0, 7, 0.99, 500), 500u);  // no inliers
  EXPECT_EQ(ransac_required_iterations(1.0, 7, 0.99, 500), 1u);    // all inliers
  EXPECT_EQ(ransac_required_iterations(1e-300, 7, 0.99, 500), 500u);  // w^s underflows
  EXPECT_EQ(ransac_required_iterations(0.1, 8, 0.99, 1000), 1000u);   // 4.6e8 capped
  EXPECT_EQ(ransac_required_iterations(std::nan(""), 7, 0.99, 77), 77u);
  EXPECT_EQ(ransac_required_iterations(0.5, 7, 0.99, 0), 1u);  // cap never below one
}

TEST(RansacDefaults, OptionsAndResult) {
  const RansacOptions o;
  EXPECT_EQ(o.max_residual, 1.0);
  EXPECT_EQ(o.confidence, 0.99);
  EXPECT_EQ(o.min_iterations, 0u);
  EXPECT_EQ(o.max_iterations, 10000u);
  EXPECT_EQ(o.seed, 0u);
  EXPECT_TRUE(o.local_optimisation);
  EXPECT_EQ(o.validate(), Status::Ok);
  const RansacResult<int> r;
  EXPECT_TRUE(r.ok());
  EXPECT_EQ(r.num_inliers, 0u);
}

TEST(RansacOptionsValidate, NamesTheFieldAndBoundsTheIterations) {
  std::string why;
  EXPECT_EQ(RansacOptions{}.validate(&why), Status::Ok);
  EXPECT_TRUE(why.empty());
  auto expect_field = [&](const RansacOptions& o, const char* field) {
    EXPECT_EQ(o.validate(&why), Status::InvalidInput);
    EXPECT_NE(why.find(field), std::string::npos) << why;
  };
  RansacOptions o;
  o.max_iterations = static_cast<std::size_t>(-1);  // hours of sampling: refused
  expect_field(o, "max_iterations");
  o = RansacOptions{};
  o.max_residual = std::nan("");
  expect_field(o, "max_residual");
  o = RansacOptions{};
  o.confidence = 2;
  expect_field(o, "confidence");
  o = RansacOptions{};
  o.min_iterations = 20000;
  expect_field(o, "min_iterations");
  o = RansacOptions{};
  o.max_iterations = RansacOptions::kMaxIterations;
  EXPECT_EQ(o.validate(), Status::Ok);
}

}  // namespace
}  // namespace dyncull
