#include "dyncull/eval/rpe.hpp"

#include "eval/synthetic_trajectory.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <type_traits>

namespace {

using namespace dyncull;
using namespace dyncull::eval;

template <class T>
class RpeTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(RpeTest, Scalars, );

template <class T> double tol_m() { return std::is_same<T, double>::value ? 1e-12 : 2e-6; }
template <class T> double tol_deg() { return std::is_same<T, double>::value ? 1e-5 : 2e-4; }

// Straight-line ground truth (identity rotation, step v along z) and an estimate whose every step has
// an extra translation b and an extra yaw alpha about z: E = (Rz(alpha), b + (I - Rz(alpha)) v) and
// (I - Rz) v = 0 for v on the axis, so each 1-frame pair has |t(E)| = |b| and angle alpha.
template <class T>
void make_drifting_pair(int n, double rate_hz, const Vec3<double>& v, const Vec3<double>& b, double alpha_rad,
                        Trajectory<T>* gt, Trajectory<T>* est) {
  Rigid3<double> step;  // the estimate's per-frame motion P_k^-1 P_{k+1}
  step.R = Eigen::AngleAxisd(alpha_rad, Vec3<double>::UnitZ()).toRotationMatrix();
  step.t = v + b;
  Rigid3<double> p;
  for (int k = 0; k < n; ++k) {
    Rigid3<double> q;
    q.t = k * v;
    gt->push_back(100.0 + k / rate_hz, q.template cast<T>());
    est->push_back(100.0 + k / rate_hz, p.template cast<T>());
    p = p * step;
  }
}

TYPED_TEST(RpeTest, ZeroErrorWhenTheEstimateLivesInAnotherWorldFrame) {
  using T = TypeParam;
  const Trajectory<T> gt = synthetic::make_loop<T>(150);
  Trajectory<T> est = gt;
  const Rigid3<double> g = synthetic::some_transform();
  for (Rigid3<T>& p : est.poses) p = (g * p.template cast<double>()).template cast<T>();
  for (DeltaUnit unit : {DeltaUnit::Frames, DeltaUnit::Seconds, DeltaUnit::Metres, DeltaUnit::Degrees}) {
    RpeOptions options;
    options.delta_unit = unit;
    options.delta = unit == DeltaUnit::Degrees ? 10.0 : (unit == DeltaUnit::Metres ? 0.2 : 1.0);
    const RpeResult<T> rpe = evaluate_rpe(gt, est, options);
    ASSERT_TRUE(rpe.ok()) << to_string(unit) << ": " << rpe.reason;
    EXPECT_GT(rpe.num_pairs, 50u) << to_string(unit);
    EXPECT_LT(rpe.translation_m.max, 10 * tol_m<T>()) << to_string(unit);
    EXPECT_LT(rpe.rotation_deg.max, 10 * tol_deg<T>()) << to_string(unit);
  }
}

TYPED_TEST(RpeTest, KnownPerStepDriftOneFrame) {
  using T = TypeParam;
  Trajectory<T> gt, est;
  const Vec3<double> b(0.003, -0.004, 0.0);  // |b| = 5 mm per frame
  const double alpha = 0.2 * Constants<double>::deg_to_rad();
  make_drifting_pair<T>(100, 30.0, Vec3<double>(0, 0, 0.01), b, alpha, &gt, &est);
  RpeOptions options;
  options.delta_unit = DeltaUnit::Frames;
  const RpeResult<T> rpe = evaluate_rpe(gt, est, options);
  ASSERT_TRUE(rpe.ok()) << rpe.reason;
  // TUM drops the pair whose j is the last pose, and the last pose pairs with itself: n - 2 pairs.
  EXPECT_EQ(rpe.num_pairs, 98u);
  EXPECT_EQ(rpe.pairs.front().estimate_i, 0u);
  EXPECT_EQ(rpe.pairs.back().estimate_j, 98u);
  EXPECT_NEAR(rpe.translation_m.rmse, 0.005, tol_m<T>() * 100);
  EXPECT_NEAR(rpe.translation_m.std, 0.0, tol_m<T>() * 100);
  EXPECT_NEAR(rpe.rotation_deg.mean, 0.2, tol_deg<T>());
  EXPECT_NEAR(rpe.rotation_deg.max, 0.2, tol_deg<T>());
}

TYPED_TEST(RpeTest, OneSecondDeltaPairsThirtyFramesApart) {
  using T = TypeParam;
  Trajectory<T> gt, est;
  // Pure translation drift: over 30 steps the estimate drifts 30 b.
  make_drifting_pair<T>(120, 30.0, Vec3<double>(0.01, 0, 0), Vec3<double>(0, 0.001, 0), 0.0, &gt, &est);
  const RpeResult<T> rpe = evaluate_rpe(gt, est);  // default: 1 second
  ASSERT_TRUE(rpe.ok()) << rpe.reason;
  EXPECT_EQ(rpe.num_pairs, 120u - 31u);  // i + 30 must be below the last index
  for (const RpePair<T>& p : rpe.pairs) EXPECT_EQ(p.estimate_j - p.estimate_i, 30u);
  EXPECT_NEAR(rpe.translation_m.mean, 0.030, tol_m<T>() * 1000);
  EXPECT_NEAR(rpe.rotation_deg.max, 0.0, tol_deg<T>());
}

TYPED_TEST(RpeTest, GroundTruthGapsDropPairs) {
  using T = TypeParam;
  const Trajectory<T> full = synthetic::make_loop<T>(300, 100.0);
  Trajectory<T> gt;  // 100 Hz ground truth with a 0.2 s hole
  for (std::size_t i = 0; i < full.size(); ++i) {
    if (i < 100 || i >= 120) gt.push_back(full.stamps[i], full.poses[i]);
  }
  Trajectory<T> est;  // 25 Hz estimate over the whole span
  for (std::size_t i = 0; i < full.size(); i += 4) est.push_back(full.stamps[i], full.poses[i]);
  RpeOptions options;
  options.delta_unit = DeltaUnit::Frames;
  const RpeResult<T> rpe = evaluate_rpe(gt, est, options);
  ASSERT_TRUE(rpe.ok()) << rpe.reason;
  EXPECT_NEAR(rpe.max_gap_s, 0.02, 1e-9);  // 2 x median interval
  EXPECT_GT(rpe.num_dropped_gap, 0u);
  EXPECT_EQ(rpe.num_pairs + rpe.num_dropped_gap, est.size() - 2);
  // Pairs next to the hole keep a ground-truth pose up to 0.01 s away (within the gap limit, as TUM),
  // so only most pairs are exact.
  EXPECT_LT(rpe.translation_m.median, 10 * tol_m<T>());
  EXPECT_GT(rpe.translation_m.max, 0.001);
}

TYPED_TEST(RpeTest, FloatAgreesWithDouble) {
  using T = TypeParam;
  Trajectory<double> gt_d = synthetic::make_loop<double>(200);
  Trajectory<double> est_d = gt_d;
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.002);
  for (Rigid3<double>& p : est_d.poses) {
    p.t += Vec3<double>(noise(rng), noise(rng), noise(rng));
    p.R = p.R * Eigen::AngleAxisd(noise(rng), Vec3<double>(noise(rng), noise(rng), 1).normalized()).toRotationMatrix();
  }
  Trajectory<T> gt, est;
  for (std::size_t i = 0; i < gt_d.size(); ++i) {
    gt.push_back(gt_d.stamps[i], gt_d.poses[i].template cast<T>());
    est.push_back(est_d.stamps[i], est_d.poses[i].template cast<T>());
  }
  RpeOptions options;
  options.delta_unit = DeltaUnit::Frames;
  const RpeResult<double> ref = evaluate_rpe(gt_d, est_d, options);
  const RpeResult<T> rpe = evaluate_rpe(gt, est, options);
  ASSERT_TRUE(ref.ok() && rpe.ok());
  EXPECT_EQ(rpe.num_pairs, ref.num_pairs);
  EXPECT_NEAR(rpe.translation_m.rmse, ref.translation_m.rmse, 1e-6);
  EXPECT_NEAR(rpe.rotation_deg.rmse, ref.rotation_deg.rmse, 1e-4);
  EXPECT_GT(ref.rotation_deg.rmse, 0.05);
}

TYPED_TEST(RpeTest, MotionBeyondTheScalarRangeIsReportedNotOkWithInfiniteStatistics) {
  using T = TypeParam;
  // Estimate positions alternating between +-0.9 * max: each relative motion is 1.8 * max, beyond T.
  const Trajectory<T> gt = synthetic::make_loop<T>(40);
  Trajectory<T> est = gt;
  for (std::size_t i = 0; i < est.size(); ++i) {
    est.poses[i].t = Vec3<T>(std::numeric_limits<T>::max() * T(i % 2 ? 0.9 : -0.9), T(0), T(0));
  }
  RpeOptions o;
  o.delta = 1;
  o.delta_unit = DeltaUnit::Frames;
  const RpeResult<T> r = evaluate_rpe(gt, est, o);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.reason.find("translation"), std::string::npos) << r.reason;
}

TEST(Rpe, OptionsValidateNamesTheField) {
  std::string why;
  RpeOptions o;
  EXPECT_EQ(o.validate(&why), Status::Ok);
  EXPECT_TRUE(why.empty());
  const Trajectory<double> gt = synthetic::make_loop<double>(50);
  auto expect_field = [&](const RpeOptions& bad, const char* field) {
    EXPECT_EQ(bad.validate(&why), Status::InvalidInput);
    EXPECT_NE(why.find(field), std::string::npos) << why;
    const RpeResult<double> r = evaluate_rpe(gt, gt, bad);
    EXPECT_EQ(r.status, Status::InvalidInput);
    EXPECT_NE(r.reason.find(field), std::string::npos) << r.reason;
  };
  RpeOptions bad = o;
  bad.delta = -1;
  expect_field(bad, "delta");
  bad = o;
  bad.scale = std::numeric_limits<double>::infinity();
  expect_field(bad, "scale");
  bad = o;
  bad.offset_s = std::nan("");
  expect_field(bad, "offset_s");
  bad = o;
  bad.delta_unit = static_cast<DeltaUnit>(42);
  expect_field(bad, "delta_unit");
}

TEST(Rpe, FixedScaleMultipliesEstimateMotions) {
  Trajectory<double> gt, est;
  make_drifting_pair<double>(50, 30.0, Vec3<double>(0.01, 0, 0), Vec3<double>::Zero(), 0.0, &gt, &est);
  for (Rigid3<double>& p : est.poses) p.t *= 0.5;  // monocular estimate at half scale
  RpeOptions options;
  options.delta_unit = DeltaUnit::Frames;
  EXPECT_NEAR(evaluate_rpe(gt, est, options).translation_m.mean, 0.005, 1e-12);
  options.scale = 2.0;
  EXPECT_NEAR(evaluate_rpe(gt, est, options).translation_m.max, 0.0, 1e-12);
}

TEST(Rpe, FindClosestIndexAgreesWithBruteForce) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 100.0);
  std::vector<double> list(257);
  for (double& x : list) x = u(rng);
  std::sort(list.begin(), list.end());
  for (int trial = 0; trial < 1000; ++trial) {
    const double t = u(rng) * 1.2 - 10.0;
    std::size_t best = 0;
    for (std::size_t i = 1; i < list.size(); ++i) {
      if (std::abs(list[i] - t) < std::abs(list[best] - t)) best = i;
    }
    EXPECT_EQ(dyncull::eval::detail::find_closest_index(list, t), best) << t;
  }
}

TEST(Rpe, FailuresAreStatuses) {
  const Trajectory<double> gt = synthetic::make_loop<double>(50);
  Trajectory<double> one;
  one.push_back(gt.stamps[0], gt.poses[0]);
  EXPECT_EQ(evaluate_rpe(gt, one).status, Status::TooFewPoints);
  RpeOptions bad;
  bad.delta = 0.0;
  EXPECT_EQ(evaluate_rpe(gt, gt, bad).status, Status::InvalidInput);
  bad.delta = std::nan("");
  EXPECT_EQ(evaluate_rpe(gt, gt, bad).status, Status::InvalidInput);
  // Estimate far in the future: every estimate stamp maps to the same last gt stamp -> no overlap.
  Trajectory<double> late = gt;
  for (double& s : late.stamps) s += 1000.0;
  const RpeResult<double> r = evaluate_rpe(gt, late);
  EXPECT_EQ(r.status, Status::TooFewPoints);
  EXPECT_NE(r.reason.find("overlap"), std::string::npos) << r.reason;
}

// For any poses and options: a non-Ok status with a reason, or finite errors and statistics.
TYPED_TEST(RpeTest, PropertyErrorsAreFiniteOrTheCallFails) {
  using T = TypeParam;
  std::mt19937_64 rng(90);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  for (int trial = 0; trial < 150; ++trial) {
    const int n = static_cast<int>(uni(rng) * 40);
    Trajectory<T> gt = synthetic::make_loop<T>(std::max(n, 1));
    Trajectory<T> est = gt;
    const double magnitude = std::pow(10.0, uni(rng) * (std::is_same<T, double>::value ? 310 : 40) - 5);
    for (std::size_t i = 0; i < est.size(); ++i) {
      const double u = uni(rng);
      if (u < 0.3) est.poses[i].t *= T(std::min(magnitude, double(std::numeric_limits<T>::max())));
      if (u > 0.97) est.poses[i].t.y() = std::numeric_limits<T>::quiet_NaN();
      if (u > 0.95 && u <= 0.97) est.stamps[i] = std::numeric_limits<double>::infinity();
    }
    RpeOptions o;
    const double k = uni(rng);
    o.delta_unit = k < 0.25 ? DeltaUnit::Frames : k < 0.5 ? DeltaUnit::Seconds : k < 0.75 ? DeltaUnit::Metres
                                                                                            : DeltaUnit::Degrees;
    o.delta = uni(rng) < 0.05 ? -1.0 : 0.01 + uni(rng) * 5;
    o.scale = uni(rng) < 0.05 ? std::nan("") : 0.5 + uni(rng);
    const RpeResult<T> r = evaluate_rpe(gt, est, o);
    if (!r.ok()) {
      EXPECT_FALSE(r.reason.empty()) << trial;
      continue;
    }
    for (const auto& p : r.pairs) EXPECT_TRUE(std::isfinite(p.translation_m) && std::isfinite(p.rotation_deg)) << trial;
    for (const ErrorStatistics<T>* s : {&r.translation_m, &r.rotation_deg}) {
      EXPECT_TRUE(s->ok()) << trial;
      EXPECT_TRUE(std::isfinite(s->rmse) && std::isfinite(s->max)) << trial;
    }
  }
}

}  // namespace
