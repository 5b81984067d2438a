// Tests of geometry/bfgs.hpp: convergence on Rosenbrock and quadratics (float and double), the
// iteration limit, non-finite input and objectives that are undefined in part of the domain.
#include "dyncull/geometry/bfgs.hpp"

#include "dyncull/core/random.hpp"

#include <gtest/gtest.h>

#include <limits>

#include <string>

#include <cmath>

namespace {

template <class T>
class BfgsTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(BfgsTest, Scalars, );

template <class T>
struct Rosenbrock {
  T operator()(const Eigen::Matrix<T, 2, 1>& x, Eigen::Matrix<T, 2, 1>* g) const {
    const T a = T(1) - x[0];
    const T b = x[1] - x[0] * x[0];
    (*g)[0] = T(-2) * a - T(400) * x[0] * b;
    (*g)[1] = T(200) * b;
    return a * a + T(100) * b * b;
  }
};

TYPED_TEST(BfgsTest, RosenbrockFromClassicStart) {
  using T = TypeParam;
  dyncull::BfgsOptions options;
  options.max_iterations = 200;
  const auto r = dyncull::bfgs_minimize(Rosenbrock<T>{}, Eigen::Matrix<T, 2, 1>(T(-1.2), T(1)), options);
  ASSERT_TRUE(r.ok()) << r.reason;
  // The valley is flat along x: an error of sqrt(eps) in x costs only eps in f.
  const T tol = (sizeof(T) == sizeof(float)) ? T(2e-2) : T(1e-6);
  EXPECT_NEAR(r.x[0], T(1), tol);
  EXPECT_NEAR(r.x[1], T(1), T(2) * tol);
  EXPECT_LT(r.value, (sizeof(T) == sizeof(float)) ? T(1e-4) : T(1e-12));
  EXPECT_GT(r.iterations, 5);  // not solved by accident in the first step
  EXPECT_LE(r.iterations, 200);
  EXPECT_GE(r.evaluations, r.iterations);
}

TYPED_TEST(BfgsTest, QuadraticFourDimensions) {
  using T = TypeParam;
  using V = Eigen::Matrix<T, 4, 1>;
  using M = Eigen::Matrix<T, 4, 4>;
  M B;
  B << 3, 1, 0, 0.5, 1, 4, 1, 0, 0, 1, 2, 0.3, 0.5, 0, 0.3, 1;
  const M A = B * B.transpose() + M::Identity();  // symmetric positive definite, condition ~ 40
  const V b(T(1), T(-2), T(3), T(0.5));
  const auto f = [&](const V& x, V* g) {
    *g = A * x - b;
    return T(0.5) * x.dot(A * x) - b.dot(x);
  };
  const V expected = A.ldlt().solve(b);
  const auto r = dyncull::bfgs_minimize(f, V(V::Constant(T(10))));
  ASSERT_TRUE(r.ok()) << r.reason;
  const T tol = (sizeof(T) == sizeof(float)) ? T(1e-3) : T(1e-8);
  EXPECT_LT((r.x - expected).norm(), tol);
  // Inexact (Armijo / curvature) line searches: superlinear, a few times n steps, where steepest
  // descent at condition ~40 would need hundreds to reach 1e-8.
  EXPECT_LE(r.iterations, 25);
}

TYPED_TEST(BfgsTest, IllScaledQuadraticTwoDimensions) {
  using T = TypeParam;
  using V = Eigen::Matrix<T, 2, 1>;
  // Curvatures 1 and 1e4, minimum at (300, -200): pixel-like magnitudes.
  const auto f = [](const V& x, V* g) {
    const T dx = x[0] - T(300), dy = x[1] + T(200);
    (*g) << T(2) * dx, T(2e4) * dy;
    return dx * dx + T(1e4) * dy * dy;
  };
  const auto r = dyncull::bfgs_minimize(f, V(T(0), T(0)));
  ASSERT_TRUE(r.ok()) << r.reason;
  const T tol = (sizeof(T) == sizeof(float)) ? T(1e-2) : T(1e-7);
  EXPECT_NEAR(r.x[0], T(300), tol);
  EXPECT_NEAR(r.x[1], T(-200), tol);
}

TYPED_TEST(BfgsTest, IterationLimitReportsNotConverged) {
  using T = TypeParam;
  dyncull::BfgsOptions options;
  options.max_iterations = 3;
  const auto r = dyncull::bfgs_minimize(Rosenbrock<T>{}, Eigen::Matrix<T, 2, 1>(T(-1.2), T(1)), options);
  EXPECT_EQ(r.status, dyncull::Status::NotConverged);
  EXPECT_FALSE(r.ok());
  EXPECT_FALSE(r.reason.empty());
  EXPECT_EQ(r.iterations, 3);
  // Still the best point so far: lower than the start value 24.2.
  EXPECT_LT(r.value, T(24.2));
  EXPECT_TRUE(r.x.allFinite());
}

TYPED_TEST(BfgsTest, BacksOffWhereTheObjectiveIsUndefined) {
  using T = TypeParam;
  using V = Eigen::Matrix<T, 1, 1>;
  // f = x - log x, defined for x > 0 only (NaN beyond); minimum at x = 1.
  const auto f = [](const V& x, V* g) {
    (*g)[0] = T(1) - T(1) / x[0];
    return x[0] - std::log(x[0]);
  };
  const auto r = dyncull::bfgs_minimize(f, V(T(20)));
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_NEAR(r.x[0], T(1), (sizeof(T) == sizeof(float)) ? T(1e-3) : T(1e-7));
}

TYPED_TEST(BfgsTest, NonFiniteStartAndBadOptions) {
  using T = TypeParam;
  using V = Eigen::Matrix<T, 2, 1>;
  const auto nan_start =
      dyncull::bfgs_minimize(Rosenbrock<T>{}, V(dyncull::Constants<T>::nan(), T(0)));
  EXPECT_EQ(nan_start.status, dyncull::Status::NonFinite);
  EXPECT_FALSE(nan_start.reason.empty());

  const auto nan_value = dyncull::bfgs_minimize(
      [](const V&, V* g) {
        g->setZero();
        return dyncull::Constants<T>::nan();
      },
      V(T(0), T(0)));
  EXPECT_EQ(nan_value.status, dyncull::Status::NonFinite);

  dyncull::BfgsOptions bad;
  bad.wolfe_c2 = 1e-5;  // below armijo_c1
  EXPECT_EQ(dyncull::bfgs_minimize(Rosenbrock<T>{}, V(T(0), T(0)), bad).status, dyncull::Status::InvalidInput);
}

TEST(BfgsDefaults, DocumentedValues) {
  const dyncull::BfgsOptions o;
  EXPECT_EQ(o.max_iterations, 100);
  EXPECT_DOUBLE_EQ(o.gradient_tolerance, 1e-10);
  EXPECT_LT(o.armijo_c1, o.wolfe_c2);
  const dyncull::BfgsResult<double, 3> r;
  EXPECT_TRUE(r.ok());
  EXPECT_EQ(r.iterations, 0);
}

TEST(Bfgs, StartAtMinimumReturnsImmediately) {
  using V = Eigen::Vector2d;
  const auto f = [](const V& x, V* g) {
    *g = 2 * x;
    return x.squaredNorm();
  };
  const auto r = dyncull::bfgs_minimize(f, V(0, 0));
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.iterations, 0);
  EXPECT_EQ(r.evaluations, 1);
}

TEST(BfgsOptionsValidate, NamesTheFieldAndBoundsTheIterations) {
  std::string why;
  EXPECT_EQ(dyncull::BfgsOptions{}.validate(&why), dyncull::Status::Ok);
  EXPECT_TRUE(why.empty());
  auto check = [&](dyncull::BfgsOptions o, const char* field) {
    EXPECT_EQ(o.validate(&why), dyncull::Status::InvalidInput);
    EXPECT_NE(why.find(field), std::string::npos) << why;
    const auto r = dyncull::bfgs_minimize(
        [](const Eigen::Vector2d& x, Eigen::Vector2d* g) {
          *g = 2 * x;
          return x.squaredNorm();
        },
        Eigen::Vector2d(1, 1), o);
    EXPECT_EQ(r.status, dyncull::Status::InvalidInput);
    EXPECT_NE(r.reason.find(field), std::string::npos) << r.reason;
  };
  dyncull::BfgsOptions o;
  o.gradient_tolerance = std::nan("");
  check(o, "gradient_tolerance");
  o = {};
  o.function_tolerance = -1;
  check(o, "function_tolerance");
  o = {};
  o.parameter_tolerance = HUGE_VAL;
  check(o, "parameter_tolerance");
  o = {};
  o.max_iterations = 1 << 30;  // unbounded time: refused
  check(o, "max_iterations");
  o = {};
  o.max_line_search_steps = 0;
  check(o, "max_line_search_steps");
  o = {};
  o.wolfe_c2 = 1.5;
  check(o, "wolfe_c2");
}

// For any start, objective behaviour (NaN / Inf / huge values) and options: a non-Ok status with a
// reason, or a finite point, value and gradient.
TYPED_TEST(BfgsTest, PropertyResultIsFiniteOrTheCallFails) {
  using T = TypeParam;
  using V = Eigen::Matrix<T, 2, 1>;
  dyncull::Random rng(88);
  for (int trial = 0; trial < 300; ++trial) {
    const double kind = rng.uniform();
    const T scale = T(std::pow(10.0, rng.uniform(-30, 30)));
    const auto f = [&](const V& x, V* g) -> T {
      if (kind < 0.1 && x.norm() > T(3)) {  // NaN outside a ball
        g->setConstant(std::numeric_limits<T>::quiet_NaN());
        return std::numeric_limits<T>::quiet_NaN();
      }
      if (kind < 0.2 && x(0) > T(1)) {  // +inf beyond a wall
        g->setConstant(T(1));
        return std::numeric_limits<T>::infinity();
      }
      *g = T(2) * scale * x;
      return scale * x.squaredNorm();
    };
    dyncull::BfgsOptions o;
    o.max_iterations = static_cast<int>(rng.index(50));
    if (rng.uniform() < 0.1) o.gradient_tolerance = std::nan("");
    if (rng.uniform() < 0.1) o.armijo_c1 = -1;
    const double u = rng.uniform();
    const V x0(u < 0.05 ? std::numeric_limits<T>::quiet_NaN() : T(rng.uniform(-5, 5)),
               u > 0.95 ? std::numeric_limits<T>::max() : T(rng.uniform(-5, 5)));
    const auto r = dyncull::bfgs_minimize(f, x0, o);
    if (r.status == dyncull::Status::InvalidInput || r.status == dyncull::Status::NonFinite) {
      EXPECT_FALSE(r.reason.empty()) << trial;
      continue;
    }
    // Ok and NotConverged both return the last accepted iterate: it must be finite.
    EXPECT_TRUE(r.x.allFinite()) << trial;
    EXPECT_TRUE(std::isfinite(r.value)) << trial;
    EXPECT_TRUE(r.gradient.allFinite()) << trial;
    if (!r.ok()) {
      EXPECT_FALSE(r.reason.empty()) << trial;
    }
  }
}

}  // namespace
