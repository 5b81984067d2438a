// Tests of geometry/rotation_centre.hpp (DFD-SLAM, Qian et al. 2024, Algorithm 2): exact centre and angle on synthetic
// rotations, agreement of the normal equations, BFGS and Ceres, robust losses against outlier flow,
// and every "no rotation" reason (translation, zoom, too few, NaN, size mismatch).
#include "dyncull/geometry/rotation_centre.hpp"

#include "dyncull/core/random.hpp"

#include <gtest/gtest.h>

#include "support/adversarial.hpp"

#include <string>

#ifdef DYNCULL_HAS_CERES
#include <ceres/ceres.h>
#endif

#include <cmath>
#include <limits>
#include <vector>

using dyncull::test::solver_value;

namespace {

using dyncull::RobustLoss;
using dyncull::RotationCentreOptions;
using dyncull::RotationCentreSolver;
using dyncull::Status;

template <class T>
struct Flow {
  std::vector<Eigen::Matrix<T, 2, 1>> p1, p2;
};

/// n points uniform in a 640 x 480 image, rotated by `angle_rad` about `centre`, with Gaussian noise.
template <class T>
Flow<T> rotation_flow(std::size_t n, double cx, double cy, double angle_rad, double noise_px, std::uint64_t seed) {
  dyncull::Random rng(seed);
  Flow<T> f;
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  for (std::size_t i = 0; i < n; ++i) {
    const double x = rng.uniform(0, 639), y = rng.uniform(0, 479);
    const double dx = x - cx, dy = y - cy;
    const double x2 = cx + c * dx - s * dy + noise_px * rng.normal();
    const double y2 = cy + s * dx + c * dy + noise_px * rng.normal();
    f.p1.emplace_back(T(x), T(y));
    f.p2.emplace_back(T(x2), T(y2));
  }
  return f;
}

template <class T>
class RotationCentreTest : public ::testing::Test {
 protected:
  static constexpr bool kFloat = sizeof(T) == sizeof(float);
};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(RotationCentreTest, Scalars, );

TYPED_TEST(RotationCentreTest, ExactRotationRecoversCentreAndAngle) {
  using T = TypeParam;
  const double angle = 25.0 * M_PI / 180.0;
  const auto flow = rotation_flow<T>(300, 350.0, 220.0, angle, 0.0, 7);
  const auto r = dyncull::estimate_rotation_centre(flow.p1, flow.p2, 640, 480);
  ASSERT_TRUE(r.ok()) << r.reason;
  // float: coordinates of order 500 carry ~3e-5 px of rounding; the 2x2 solve amplifies it a little.
  const T tol_px = this->kFloat ? T(2e-2) : T(1e-8);
  EXPECT_NEAR(r.centre.x(), T(350), tol_px);
  EXPECT_NEAR(r.centre.y(), T(220), tol_px);
  EXPECT_NEAR(r.angle_deg(), T(25), this->kFloat ? T(1e-3) : T(1e-9));
  EXPECT_NEAR(r.signed_angle_deg(), T(25), this->kFloat ? T(1e-3) : T(1e-9));
  EXPECT_EQ(r.num_vectors, 300u);
  EXPECT_EQ(r.num_inliers, 300u);
  EXPECT_LT(r.cost, this->kFloat ? T(1e-2) : T(1e-12));
  EXPECT_GT(r.eigenvalue_ratio, T(0.1));  // directions all round: well conditioned
}

TYPED_TEST(RotationCentreTest, NegativeRotationHasNegativeSignedAngle) {
  using T = TypeParam;
  const auto flow = rotation_flow<T>(200, 300.0, 260.0, -0.2, 0.0, 3);
  const auto r = dyncull::estimate_rotation_centre(flow.p1, flow.p2, 640, 480);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_NEAR(r.signed_angle_rad, T(-0.2), T(1e-4));
  EXPECT_NEAR(r.angle_rad, T(0.2), T(1e-4));
}

TYPED_TEST(RotationCentreTest, BfgsAgreesWithNormalEquations) {
  using T = TypeParam;
  // Noisy flow so that the minimum has a non-zero cost and BFGS has real work to do.
  const auto flow = rotation_flow<T>(500, 420.0, 180.0, 0.35, 0.7, 11);
  RotationCentreOptions exact;
  RotationCentreOptions bfgs;
  bfgs.solver = RotationCentreSolver::Bfgs;
  const auto a = dyncull::estimate_rotation_centre(flow.p1, flow.p2, 640, 480, exact);
  const auto b = dyncull::estimate_rotation_centre(flow.p1, flow.p2, 640, 480, bfgs);
  ASSERT_TRUE(a.ok()) << a.reason;
  ASSERT_TRUE(b.ok()) << b.reason;
  EXPECT_LT((a.centre - b.centre).norm(), this->kFloat ? T(5e-3) : T(1e-6));
  EXPECT_GT(b.iterations, 0);
  EXPECT_NEAR(a.cost, b.cost, T(1e-4) * a.cost);
  // The noisy centre is still near the truth.
  EXPECT_LT((a.centre - dyncull::Vec2<T>(420, 180)).norm(), T(1));
}

TYPED_TEST(RotationCentreTest, RobustLossesResistOutlierFlow) {
  using T = TypeParam;
  auto flow = rotation_flow<T>(400, 320.0, 240.0, 0.4, 0.3, 5);
  // 30 % of the vectors belong to an object translating to the right: their bisectors are vertical
  // lines far from the true centre.
  dyncull::Random rng(99);
  for (std::size_t i = 0; i < 120; ++i) {
    const T x = T(rng.uniform(450, 630)), y = T(rng.uniform(300, 470));
    flow.p1[i] = {x, y};
    flow.p2[i] = {x + T(30), y + T(2)};
  }
  const dyncull::Vec2<T> truth(320, 240);
  RotationCentreOptions plain;
  plain.min_inlier_fraction = 0.5;
  const auto r_plain = dyncull::estimate_rotation_centre(flow.p1, flow.p2, 640, 480, plain);
  const T err_plain = (r_plain.centre - truth).norm();
  EXPECT_GT(err_plain, T(3)) << "outliers should bias plain least squares";

  for (RobustLoss loss : {RobustLoss::Huber, RobustLoss::Cauchy}) {
    for (RotationCentreSolver solver : {RotationCentreSolver::NormalEquations, RotationCentreSolver::Bfgs}) {
      RotationCentreOptions o;
      o.loss = loss;
      o.solver = solver;
      o.loss_scale_px = 2.0;
      const auto r = dyncull::estimate_rotation_centre(flow.p1, flow.p2, 640, 480, o);
      ASSERT_TRUE(r.ok()) << to_string(loss) << " " << to_string(solver) << ": " << r.reason;
      const T err = (r.centre - truth).norm();
      EXPECT_LT(err, loss == RobustLoss::Cauchy ? T(0.5) : T(3)) << to_string(loss) << " " << to_string(solver);
      EXPECT_LT(err, err_plain) << to_string(loss) << " " << to_string(solver);
      // eq. 15 rejects the translating object's vectors.
      std::size_t outliers_kept = 0;
      for (std::size_t i = 0; i < 120; ++i) outliers_kept += r.inlier_mask[i];
      EXPECT_LT(outliers_kept, 12u);
      EXPECT_NEAR(r.angle_rad, T(0.4), T(0.02));
    }
  }
  // Normal-equation IRLS and BFGS minimise the same convex Huber cost: same centre.
  RotationCentreOptions h1, h2;
  h1.loss = h2.loss = RobustLoss::Huber;
  h2.solver = RotationCentreSolver::Bfgs;
  const auto a = dyncull::estimate_rotation_centre(flow.p1, flow.p2, 640, 480, h1);
  const auto b = dyncull::estimate_rotation_centre(flow.p1, flow.p2, 640, 480, h2);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_LT((a.centre - b.centre).norm(), this->kFloat ? T(2e-2) : T(1e-4));
}

TYPED_TEST(RotationCentreTest, TranslationIsDegenerate) {
  using T = TypeParam;
  dyncull::Random rng(1);
  Flow<T> f;
  for (int i = 0; i < 200; ++i) {
    const T x = T(rng.uniform(0, 639)), y = T(rng.uniform(0, 479));
    f.p1.emplace_back(x, y);
    f.p2.emplace_back(x + T(8) + T(0.2 * rng.normal()), y + T(3) + T(0.2 * rng.normal()));
  }
  for (RotationCentreSolver solver : {RotationCentreSolver::NormalEquations, RotationCentreSolver::Bfgs}) {
    RotationCentreOptions o;
    o.solver = solver;
    const auto r = dyncull::estimate_rotation_centre(f.p1, f.p2, 640, 480, o);
    EXPECT_EQ(r.status, Status::Degenerate) << r.reason;
    EXPECT_NE(r.reason.find("translation"), std::string::npos) << r.reason;
    EXPECT_LT(r.eigenvalue_ratio, T(1e-2));
  }
}

TYPED_TEST(RotationCentreTest, ZoomFailsTheEquidistanceFilter) {
  using T = TypeParam;
  // Radial flow (camera moving forward): bisectors meet near the focus of expansion but every end
  // point is 5 % farther from it than the start, far more than the 2 px of eq. 15.
  dyncull::Random rng(2);
  Flow<T> f;
  for (int i = 0; i < 200; ++i) {
    const double x = rng.uniform(0, 639), y = rng.uniform(0, 479);
    f.p1.emplace_back(T(x), T(y));
    f.p2.emplace_back(T(320 + 1.05 * (x - 320)), T(240 + 1.05 * (y - 240)));
  }
  const auto r = dyncull::estimate_rotation_centre(f.p1, f.p2, 640, 480);
  EXPECT_EQ(r.status, Status::TooFewPoints);
  EXPECT_NE(r.reason.find("eq. 15"), std::string::npos) << r.reason;
  EXPECT_LT(r.num_inliers, r.num_vectors / 2);
}

TYPED_TEST(RotationCentreTest, TooFewAndStaticFlow) {
  using T = TypeParam;
  const auto few = rotation_flow<T>(5, 320, 240, 0.5, 0.0, 4);
  const auto r_few = dyncull::estimate_rotation_centre(few.p1, few.p2, 640, 480);
  EXPECT_EQ(r_few.status, Status::TooFewPoints);
  EXPECT_FALSE(r_few.reason.empty());

  auto still = rotation_flow<T>(100, 320, 240, 0.0, 0.0, 4);  // zero-length vectors
  const auto r_still = dyncull::estimate_rotation_centre(still.p1, still.p2, 640, 480);
  EXPECT_EQ(r_still.status, Status::TooFewPoints);
  EXPECT_EQ(r_still.num_vectors, 0u);

  const std::vector<dyncull::Vec2<T>> empty;
  EXPECT_EQ(dyncull::estimate_rotation_centre(empty, empty, 640, 480).status, Status::TooFewPoints);
}

TYPED_TEST(RotationCentreTest, NonFiniteVectorsAreSkippedOrReported) {
  using T = TypeParam;
  auto flow = rotation_flow<T>(100, 300, 200, 0.5, 0.0, 8);
  for (std::size_t i = 0; i < 100; i += 10) flow.p2[i].x() = dyncull::Constants<T>::nan();
  flow.p1[5].y() = std::numeric_limits<T>::infinity();
  const auto r = dyncull::estimate_rotation_centre(flow.p1, flow.p2, 640, 480);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.num_vectors, 89u);
  EXPECT_EQ(r.inlier_mask[0], 0);
  EXPECT_EQ(r.inlier_mask[5], 0);
  EXPECT_NEAR(r.centre.x(), T(300), T(0.05));

  for (auto& p : flow.p1) p.x() = dyncull::Constants<T>::nan();
  const auto all_nan = dyncull::estimate_rotation_centre(flow.p1, flow.p2, 640, 480);
  EXPECT_EQ(all_nan.status, Status::NonFinite);
  EXPECT_FALSE(all_nan.reason.empty());
}

TYPED_TEST(RotationCentreTest, SizeMismatchAndBadOptions) {
  using T = TypeParam;
  auto flow = rotation_flow<T>(50, 300, 200, 0.5, 0.0, 8);
  flow.p2.pop_back();
  const auto r = dyncull::estimate_rotation_centre(flow.p1, flow.p2, 640, 480);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_EQ(r.inlier_mask.size(), 50u);
  flow.p2.push_back(flow.p2.back());
  RotationCentreOptions o;
  o.min_inlier_fraction = 2.0;
  EXPECT_EQ(dyncull::estimate_rotation_centre(flow.p1, flow.p2, 640, 480, o).status, Status::InvalidInput);
  RotationCentreOptions bad_scale;
  bad_scale.loss = RobustLoss::Huber;
  bad_scale.loss_scale_px = 0.0;
  EXPECT_EQ(dyncull::estimate_rotation_centre(flow.p1, flow.p2, 640, 480, bad_scale).status, Status::InvalidInput);
}

// Containers of user structs with x/y members (cv::Point2f-like) work through PointTraits, and the
// computation scalar can differ from the point scalar.
struct UserPoint {
  float x, y;
};

TEST(RotationCentre, UserPointStructsAndExplicitScalar) {
  const auto flow = rotation_flow<double>(120, 310, 250, 0.3, 0.0, 9);
  std::vector<UserPoint> a, b;
  for (std::size_t i = 0; i < flow.p1.size(); ++i) {
    a.push_back({float(flow.p1[i].x()), float(flow.p1[i].y())});
    b.push_back({float(flow.p2[i].x()), float(flow.p2[i].y())});
  }
  const auto rf = dyncull::estimate_rotation_centre(a, b, 640, 480);
  static_assert(std::is_same<decltype(rf.angle_rad), float>::value, "scalar follows the points by default");
  const auto rd = dyncull::estimate_rotation_centre<double>(a, b, 640, 480);
  static_assert(std::is_same<decltype(rd.angle_rad), double>::value, "explicit scalar");
  ASSERT_TRUE(rf.ok() && rd.ok());
  EXPECT_NEAR(rd.centre.x(), 310, 1e-2);  // float input rounding only
  EXPECT_NEAR(rd.centre.y(), 250, 1e-2);
  EXPECT_NEAR(rd.angle_rad, 0.3, 1e-4);
}

TEST(RotationCentre, LowLevelPiecesMatchEquationFive) {
  // Two flow vectors with known bisectors: (0,0)->(2,0) gives x = 1; (0,0)->(0,4) gives y = 2.
  std::vector<Eigen::Vector2d> p1{{0, 0}, {0, 0}}, p2{{2, 0}, {0, 4}};
  dyncull::BisectorLines<double> lines;
  ASSERT_EQ(dyncull::make_bisector_lines(p1, p2, Eigen::Vector2d(5, 5), 0.5, &lines), 2u);
  const auto s = dyncull::solve_centre_normal_equations(lines);
  ASSERT_TRUE(s.ok()) << s.reason;
  EXPECT_NEAR(s.centre.x(), 1.0, 1e-12);
  EXPECT_NEAR(s.centre.y(), 2.0, 1e-12);
  EXPECT_NEAR(s.eigenvalue_ratio, 1.0, 1e-12);
  // eq. 5 at (4, 6): distances 3 and 4 -> 25; gradient eq. 7-8 = (6, 8).
  Eigen::Vector2d g;
  EXPECT_NEAR(dyncull::bisector_cost(lines, Eigen::Vector2d(4, 6), RobustLoss::None, 3.0, &g), 25.0, 1e-12);
  EXPECT_NEAR(g.x(), 6.0, 1e-12);
  EXPECT_NEAR(g.y(), 8.0, 1e-12);
  // Huber with k = 3: 3^2 + (2*3*4 - 9).
  EXPECT_NEAR(dyncull::bisector_cost(lines, Eigen::Vector2d(4, 6), RobustLoss::Huber, 3.0), 9.0 + 15.0, 1e-12);
  // Central differences confirm the robust gradients.
  for (RobustLoss loss : {RobustLoss::None, RobustLoss::Huber, RobustLoss::Cauchy}) {
    const Eigen::Vector2d x(3.3, 7.1);
    dyncull::bisector_cost(lines, x, loss, 3.0, &g);
    const double h = 1e-6;
    for (int d = 0; d < 2; ++d) {
      Eigen::Vector2d xp = x, xm = x;
      xp[d] += h;
      xm[d] -= h;
      const double num = (dyncull::bisector_cost(lines, xp, loss, 3.0) - dyncull::bisector_cost(lines, xm, loss, 3.0)) / (2 * h);
      EXPECT_NEAR(g[d], num, 1e-6) << to_string(loss) << " d" << d;
    }
  }
}

TEST(RotationCentre, DefaultsAreDocumented) {
  const RotationCentreOptions o;
  EXPECT_EQ(o.solver, RotationCentreSolver::NormalEquations);
  EXPECT_EQ(o.loss, RobustLoss::None);
  EXPECT_DOUBLE_EQ(o.distance_threshold_px, 2.0);
  EXPECT_DOUBLE_EQ(o.min_eigenvalue_ratio, 1e-2);
  EXPECT_EQ(o.min_vectors, 8u);
  const dyncull::RotationCentreResult<float> r;
  EXPECT_TRUE(r.ok());
  EXPECT_EQ(r.num_inliers, 0u);
}

#ifdef DYNCULL_HAS_CERES
/// eq. 5 on the same normalised lines, for Ceres' GradientProblemSolver.
class BisectorObjective final : public ceres::FirstOrderFunction {
 public:
  explicit BisectorObjective(const dyncull::BisectorLines<double>* lines) : lines_(lines) {}
  bool Evaluate(const double* x, double* cost, double* gradient) const override {
    Eigen::Vector2d g;
    cost[0] = dyncull::bisector_cost(*lines_, Eigen::Vector2d(x[0], x[1]), RobustLoss::None, 3.0, &g);
    if (gradient) {
      gradient[0] = g.x();
      gradient[1] = g.y();
    }
    return true;
  }
  int NumParameters() const override { return 2; }

 private:
  const dyncull::BisectorLines<double>* lines_;
};

TEST(RotationCentre, AgreesWithCeresBfgs) {
  for (std::uint64_t seed : {21u, 22u, 23u}) {
    const auto flow = rotation_flow<double>(500, 250.0 + 20.0 * double(seed - 21), 260.0, 0.3, 0.8, seed);
    dyncull::BisectorLines<double> lines;
    dyncull::make_bisector_lines(flow.p1, flow.p2, Eigen::Vector2d(319.5, 239.5), 0.5, &lines);
    const auto exact = dyncull::solve_centre_normal_equations(lines);
    const auto ours = dyncull::solve_centre_bfgs(lines, Eigen::Vector2d(319.5, 239.5));
    ASSERT_TRUE(exact.ok() && ours.ok()) << exact.reason << ours.reason;

    ceres::GradientProblem problem(new BisectorObjective(&lines));
    ceres::GradientProblemSolver::Options copt;
    copt.line_search_direction_type = ceres::BFGS;
    // Tight enough for a 1e-12 px reference, loose enough that Ceres' line search does not complain.
    copt.function_tolerance = 1e-15;
    copt.gradient_tolerance = 1e-11;
    copt.parameter_tolerance = 1e-14;
    ceres::GradientProblemSolver::Summary summary;
    double x[2] = {319.5, 239.5};
    ceres::Solve(copt, problem, x, &summary);
    ASSERT_TRUE(summary.IsSolutionUsable()) << summary.BriefReport();
    const Eigen::Vector2d ceres_centre(x[0], x[1]);
    EXPECT_LT((exact.centre - ceres_centre).norm(), 1e-6) << summary.BriefReport();
    EXPECT_LT((ours.centre - ceres_centre).norm(), 1e-6) << summary.BriefReport();
  }
}
#endif

TEST(RotationCentreOptionsValidate, NamesTheFieldIncludingNestedBfgs) {
  std::string why;
  EXPECT_EQ(RotationCentreOptions{}.validate(&why), Status::Ok);
  EXPECT_TRUE(why.empty());
  const auto flow = rotation_flow<double>(60, 300, 200, 0.4, 0.0, 9);
  auto check = [&](const RotationCentreOptions& bad, const char* field) {
    EXPECT_EQ(bad.validate(&why), Status::InvalidInput);
    EXPECT_NE(why.find(field), std::string::npos) << why;
    const auto r = dyncull::estimate_rotation_centre(flow.p1, flow.p2, 640, 480, bad);
    EXPECT_EQ(r.status, Status::InvalidInput);
    EXPECT_NE(r.reason.find(field), std::string::npos) << r.reason;
  };
  RotationCentreOptions bad;
  bad.loss_scale_px = std::nan("");
  check(bad, "loss_scale_px");
  bad = {};
  bad.solver = static_cast<RotationCentreSolver>(7);
  check(bad, "solver");
  bad = {};
  bad.loss = static_cast<RobustLoss>(9);
  check(bad, "loss");
  bad = {};
  bad.min_eigenvalue_ratio = 2;
  check(bad, "min_eigenvalue_ratio");
  bad = {};
  bad.distance_threshold_px = HUGE_VAL;
  check(bad, "distance_threshold_px");
  bad = {};
  bad.max_irls_iterations = 1 << 30;
  check(bad, "max_irls_iterations");
  bad = {};
  bad.min_flow_px = std::nan("");
  check(bad, "min_flow_px");
  bad = {};
  bad.bfgs.max_iterations = -1;
  check(bad, "bfgs.max_iterations");
}

// For any flow and options (both solvers, every loss): a non-Ok status with a reason, or a finite
// centre, angle, cost and conditioning.
TYPED_TEST(RotationCentreTest, PropertyCentreIsFiniteOrTheCallFails) {
  using T = TypeParam;
  dyncull::Random rng(89);
  for (int trial = 0; trial < 200; ++trial) {
    auto flow = rotation_flow<T>(rng.index(60), rng.uniform(0, 640), rng.uniform(0, 480), rng.uniform(-1, 1),
                                 rng.uniform(0, 2), static_cast<std::uint64_t>(trial));
    if (rng.uniform() < 0.7) {
      for (auto* pts : {&flow.p1, &flow.p2}) {
        for (auto& p : *pts) {
          if (rng.uniform() < 0.15) p = Eigen::Matrix<T, 2, 1>(solver_value<T>(rng, 0, 640), solver_value<T>(rng, 0, 480));
        }
      }
    }
    RotationCentreOptions o;
    o.solver = rng.uniform() < 0.5 ? RotationCentreSolver::Bfgs : RotationCentreSolver::NormalEquations;
    const double l = rng.uniform();
    o.loss = l < 0.33 ? RobustLoss::None : l < 0.66 ? RobustLoss::Huber : RobustLoss::Cauchy;
    o.loss_scale_px = rng.uniform() < 0.05 ? -1.0 : rng.uniform(0.5, 5);
    o.min_vectors = rng.index(12);
    o.min_inliers = rng.index(12);
    o.min_inlier_fraction = rng.uniform() < 0.05 ? 2.0 : rng.uniform(0, 1);
    const auto r = dyncull::estimate_rotation_centre(flow.p1, flow.p2, 640, 480, o);
    if (!r.ok()) {
      EXPECT_FALSE(r.reason.empty()) << trial;
      continue;
    }
    EXPECT_TRUE(r.centre.allFinite()) << trial;
    EXPECT_TRUE(std::isfinite(r.angle_rad) && std::isfinite(r.signed_angle_rad)) << trial;
    EXPECT_TRUE(std::isfinite(r.cost) && std::isfinite(r.eigenvalue_ratio)) << trial;
    EXPECT_EQ(r.inlier_mask.size(), flow.p1.size());
  }
}

}  // namespace
