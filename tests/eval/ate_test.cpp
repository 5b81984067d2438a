#include "dyncull/eval/ate.hpp"

#include "dyncull/core/random.hpp"

#include "eval/synthetic_trajectory.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <type_traits>

namespace {

using namespace dyncull;
using namespace dyncull::eval;

template <class T>
class AteTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(AteTest, Scalars, );

// Positions of order 1-3 m: float round-off after alignment is a few 1e-7 m.
template <class T> T zero_tol() { return std::is_same<T, double>::value ? T(1e-12) : T(2e-6); }

template <class T>
Trajectory<T> transformed(const Trajectory<T>& traj, double scale, const Rigid3<double>& g) {
  Trajectory<T> out = traj;
  for (Rigid3<T>& p : out.poses) {
    Rigid3<double> d = p.template cast<double>();
    d = g * d;
    d.t = scale * d.t + (1.0 - scale) * g.t;  // x -> s R x + t applied to the position
    p = d.template cast<T>();
  }
  return out;
}

TYPED_TEST(AteTest, ZeroErrorAfterKnownRigidTransform) {
  using T = TypeParam;
  const Trajectory<T> gt = synthetic::make_loop<T>(200);
  const Rigid3<double> g = synthetic::some_transform();
  const Trajectory<T> est = transformed(gt, 1.0, g);  // estimate expressed in another world frame
  const AteResult<T> ate = evaluate_ate(gt, est);
  ASSERT_TRUE(ate.ok()) << ate.reason;
  EXPECT_EQ(ate.num_pairs, 200u);
  EXPECT_LT(ate.error_m.max, zero_tol<T>());
  // The alignment is the inverse of g.
  const Mat3<T> R_expected = g.R.transpose().template cast<T>();
  EXPECT_TRUE(ate.groundtruth_from_estimate.R.isApprox(R_expected, T(10) * zero_tol<T>()));
  EXPECT_EQ(ate.groundtruth_from_estimate.scale, T(1));
  ASSERT_EQ(ate.estimate_index.size(), 200u);
  EXPECT_EQ(ate.estimate_index[17], 17u);
}

TYPED_TEST(AteTest, Sim3RemovesScaleOnlyWhenAsked) {
  using T = TypeParam;
  const Trajectory<T> gt = synthetic::make_loop<T>(120);
  const Trajectory<T> est = transformed(gt, 0.37, synthetic::some_transform());  // monocular: unknown scale
  AteOptions sim3;
  sim3.estimate_scale = true;
  const AteResult<T> fitted = evaluate_ate(gt, est, sim3);
  ASSERT_TRUE(fitted.ok()) << fitted.reason;
  EXPECT_LT(fitted.error_m.max, T(10) * zero_tol<T>());
  EXPECT_NEAR(fitted.groundtruth_from_estimate.scale, T(1 / 0.37), T(1e-4));
  // Applying the fitted alignment brings the estimate onto the ground truth, orientations included.
  const Trajectory<T> aligned = apply_alignment(fitted.groundtruth_from_estimate, est);
  ASSERT_EQ(aligned.size(), gt.size());
  for (std::size_t i = 0; i < gt.size(); i += 17) {
    EXPECT_LT((aligned.poses[i].t - gt.poses[i].t).norm(), T(10) * zero_tol<T>()) << i;
    EXPECT_TRUE(aligned.poses[i].R.isApprox(gt.poses[i].R, T(100) * zero_tol<T>())) << i;
    EXPECT_EQ(aligned.stamps[i], est.stamps[i]);
  }
  const AteResult<T> rigid = evaluate_ate(gt, est);
  ASSERT_TRUE(rigid.ok());
  EXPECT_GT(rigid.error_m.rmse, T(0.1));  // an SE(3) fit cannot undo a 0.37 scale
}

TYPED_TEST(AteTest, KnownAlternatingOffsetGivesExactlyThatError) {
  using T = TypeParam;
  // gt on the loop; est = gt +- d along z alternately. The offsets have zero mean and zero
  // correlation with the centred loop (even count), so the optimal alignment is the identity and
  // every error is exactly d: rmse = mean = median = min = max = d, std = 0.
  const T d = T(0.05);
  const Trajectory<T> gt = synthetic::make_loop<T>(100);
  Trajectory<T> est = gt;
  for (std::size_t i = 0; i < est.size(); ++i) est.poses[i].t.z() += (i % 2 ? -d : d);
  const AteResult<T> ate = evaluate_ate(gt, est);
  ASSERT_TRUE(ate.ok()) << ate.reason;
  const T tol = T(100) * zero_tol<T>();
  EXPECT_NEAR(ate.error_m.rmse, d, tol);
  EXPECT_NEAR(ate.error_m.mean, d, tol);
  EXPECT_NEAR(ate.error_m.median, d, tol);
  EXPECT_NEAR(ate.error_m.min, d, tol);
  EXPECT_NEAR(ate.error_m.max, d, tol);
  EXPECT_NEAR(ate.error_m.std, T(0), tol);
}

TYPED_TEST(AteTest, AssociatesDifferentRatesAndIgnoresUnmatchedPoses) {
  using T = TypeParam;
  const Trajectory<T> gt = synthetic::make_loop<T>(300, 100.0);  // 3 s at 100 Hz
  Trajectory<T> est;
  // 30 Hz estimate 4 ms late, sampled from the same loop (positions at the nearest gt pose).
  for (int k = 0; k < 90; ++k) {
    const std::size_t g = static_cast<std::size_t>(std::lround(k * 100.0 / 30.0));
    est.push_back(gt.stamps[g] + 0.004, gt.poses[g]);
  }
  est.push_back(gt.stamps.back() + 5.0, gt.poses.back());  // 5 s after the end: never associates
  const AteResult<T> ate = evaluate_ate(gt, est);
  ASSERT_TRUE(ate.ok()) << ate.reason;
  EXPECT_EQ(ate.num_pairs, 90u);
  EXPECT_LT(ate.error_m.max, zero_tol<T>());
  for (std::size_t i = 0; i < ate.num_pairs; ++i) {
    EXPECT_NEAR(gt.stamps[ate.groundtruth_index[i]], est.stamps[ate.estimate_index[i]] - 0.004, 1e-9);
  }
}

TYPED_TEST(AteTest, FailuresAreStatusesWithReasons) {
  using T = TypeParam;
  const Trajectory<T> gt = synthetic::make_loop<T>(50);
  Trajectory<T> far = gt;
  for (double& s : far.stamps) s += 100.0;
  const AteResult<T> none = evaluate_ate(gt, far);
  EXPECT_EQ(none.status, Status::TooFewPoints);
  EXPECT_NE(none.reason.find("no stamp pairs"), std::string::npos) << none.reason;

  Trajectory<T> two;
  two.push_back(gt.stamps[0], gt.poses[0]);
  two.push_back(gt.stamps[1], gt.poses[1]);
  EXPECT_EQ(evaluate_ate(gt, two).status, Status::TooFewPoints);

  Trajectory<T> line = gt;  // collinear estimate: rotation about the line undetermined
  for (std::size_t i = 0; i < line.size(); ++i) line.poses[i].t = Vec3<T>(T(i) * T(0.01), T(0), T(0));
  const AteResult<T> degenerate = evaluate_ate(line, line);
  EXPECT_EQ(degenerate.status, Status::Degenerate) << degenerate.reason;

  Trajectory<T> broken = gt;
  broken.poses.pop_back();
  EXPECT_EQ(evaluate_ate(gt, broken).status, Status::InvalidInput);
}

TEST(Ate, OptionsValidateNamesTheField) {
  std::string why;
  AteOptions o;
  EXPECT_EQ(o.validate(&why), Status::Ok);
  EXPECT_TRUE(why.empty());
  const Trajectory<double> gt = synthetic::make_loop<double>(50);
  for (double bad : {0.0, -1.0, std::nan(""), HUGE_VAL}) {
    AteOptions b;
    b.association.max_difference_s = bad;
    EXPECT_EQ(b.validate(&why), Status::InvalidInput);
    EXPECT_NE(why.find("association.max_difference_s"), std::string::npos) << why;
    const AteResult<double> r = evaluate_ate(gt, gt, b);
    EXPECT_EQ(r.status, Status::InvalidInput);
    EXPECT_NE(r.reason.find("max_difference_s"), std::string::npos) << r.reason;
  }
  AteOptions b;
  b.association.offset_s = -HUGE_VAL;
  EXPECT_EQ(b.validate(&why), Status::InvalidInput);
  EXPECT_NE(why.find("association.offset_s"), std::string::npos) << why;
  // The window's upper bound is the association's own.
  AteOptions wide;
  wide.association.max_difference_s = 1e9;
  EXPECT_EQ(wide.validate(&why), Status::InvalidInput);
  EXPECT_NE(why.find("AteOptions: association.max_difference_s"), std::string::npos) << why;
  EXPECT_EQ(evaluate_ate(gt, gt, wide).status, Status::InvalidInput);
}

TYPED_TEST(AteTest, LargeFiniteCoordinatesGiveAFiniteError) {
  using T = TypeParam;
  // Trajectories far beyond a lab (double 1e160, float 1e25): squares overflow, the ATE does not.
  const double big = std::is_same<T, double>::value ? 1e160 : 1e25;
  const Trajectory<T> gt = synthetic::make_loop<T>(50);
  Eigen::Matrix<T, 3, Eigen::Dynamic> g(3, 50), e(3, 50);
  for (int i = 0; i < 50; ++i) {
    g.col(i) = gt.poses[static_cast<std::size_t>(i)].t * T(big);
    e.col(i) = g.col(i) + Vec3<T>(T(big), T(-2 * big), T(0.5 * big));  // a pure offset: zero error
    e(0, i) += T(i % 2 ? 0.01 : -0.01) * T(big);
  }
  const AteResult<T> ate = ate_from_positions(e, g);
  ASSERT_TRUE(ate.ok()) << ate.reason;
  EXPECT_TRUE(std::isfinite(ate.error_m.rmse));
  EXPECT_NEAR(ate.error_m.rmse / T(big), T(0.01), T(1e-3));
}

TEST(AteFromPositions, MatchesTrajectoryVersion) {
  const Trajectory<double> gt = synthetic::make_loop<double>(40);
  Eigen::Matrix<double, 3, Eigen::Dynamic> g(3, 40), e(3, 40);
  for (int i = 0; i < 40; ++i) {
    g.col(i) = gt.poses[static_cast<std::size_t>(i)].t;
    e.col(i) = g.col(i) + Vec3<double>(0.01 * std::sin(i), 0.02 * std::cos(3.0 * i), 0.0);
  }
  Trajectory<double> est = gt;
  for (int i = 0; i < 40; ++i) est.poses[static_cast<std::size_t>(i)].t = e.col(i);
  const AteResult<double> a = ate_from_positions(e, g);
  const AteResult<double> b = evaluate_ate(gt, est);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_DOUBLE_EQ(a.error_m.rmse, b.error_m.rmse);
  EXPECT_GT(a.error_m.rmse, 0.001);
  EXPECT_TRUE(a.groundtruth_index.empty());
}

// For any positions: a non-Ok status with a reason, or finite errors and statistics.
TYPED_TEST(AteTest, PropertyErrorsAreFiniteOrTheCallFails) {
  using T = TypeParam;
  dyncull::Random rng(43);
  for (int trial = 0; trial < 300; ++trial) {
    const int n = static_cast<int>(rng.index(10));
    const double magnitude = std::pow(10.0, rng.uniform(-20, std::is_same<T, double>::value ? 300 : 37));
    Eigen::Matrix<T, 3, Eigen::Dynamic> e(3, n), g(3, n);
    for (int i = 0; i < n; ++i) {
      for (int r = 0; r < 3; ++r) {
        const double u = rng.uniform();
        e(r, i) = u < 0.03 ? std::numeric_limits<T>::quiet_NaN() : T(rng.uniform(-1, 1) * magnitude);
        g(r, i) = u > 0.97 ? std::numeric_limits<T>::infinity() : T(rng.uniform(-1, 1) * magnitude);
      }
    }
    const AteResult<T> ate = ate_from_positions(e, g, rng.uniform() < 0.5);
    if (!ate.ok()) {
      EXPECT_FALSE(ate.reason.empty()) << trial;
      continue;
    }
    ASSERT_EQ(ate.errors_m.size(), static_cast<std::size_t>(n));
    for (T x : ate.errors_m) EXPECT_TRUE(std::isfinite(x)) << trial;
    for (T x : {ate.error_m.rmse, ate.error_m.mean, ate.error_m.median, ate.error_m.std, ate.error_m.max}) {
      EXPECT_TRUE(std::isfinite(x)) << trial;
    }
  }
}

}  // namespace
