// Tests of geometry/icp.hpp: recovery of a known motion (float and double), partial overlap with the
// correspondence distance, association vs a brute-force oracle, Open3D-style statistics, bad input.
#include "dyncull/geometry/icp.hpp"

#include "support/adversarial.hpp"
#include "support/pose_data.hpp"

#include <gtest/gtest.h>

#include <string>

#include <limits>
#include <vector>

using dyncull::test::solver_value;

namespace {

using dyncull::IcpOptions;
using dyncull::Random;
using dyncull::Rigid3;
using dyncull::Status;
using dyncull::Vec3;

using dyncull::test::room_cloud;

template <class T>
class IcpTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(IcpTest, Scalars, dyncull::test::ScalarNames);

TYPED_TEST(IcpTest, RecoversSmallMotionExactly) {
  using T = TypeParam;
  Random rng(81);
  const auto target = room_cloud<T>(rng, 4000);
  // Source = target moved by the inverse of a small motion: ICP must find target_from_source.
  const Rigid3<T> truth = dyncull::test::random_rigid<T>(rng, 0.05, 0.03);
  const Rigid3<T> source_from_target = truth.inverse();
  std::vector<Vec3<T>> source;
  for (const auto& p : target) source.push_back(source_from_target.apply(p));
  IcpOptions<T> o;
  o.max_correspondence_distance_m = T(0.2);
  o.max_iterations = 100;
  o.relative_fitness = T(1e-9);  // fitness stays exactly 1: the rmse decides
  o.relative_rmse = std::is_same<T, double>::value ? T(1e-12) : T(1e-7);
  const auto r = dyncull::icp_point_to_point(source, target, Rigid3<T>{}, o);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.fitness, T(1));
  // Identical clouds: the fixed point is exact (double 1e-9; float limited to ~1e-5 by the coordinates).
  const double tol = std::is_same<T, double>::value ? 1e-9 : 2e-4;
  EXPECT_LT((r.target_from_source.R - truth.R).norm(), tol);
  EXPECT_LT((r.target_from_source.t - truth.t).norm(), tol);
  EXPECT_LT(r.rmse, T(tol));
}

TYPED_TEST(IcpTest, PartialOverlapAndNoise) {
  using T = TypeParam;
  Random rng(82);
  const auto cloud = room_cloud<T>(rng, 6000);
  const Rigid3<T> truth = dyncull::test::random_rigid<T>(rng, 0.03, 0.02);
  std::vector<Vec3<T>> target(cloud.begin(), cloud.begin() + 5000);  // overlap: 4000 of 5000
  std::vector<Vec3<T>> source;
  const Rigid3<T> inv = truth.inverse();
  for (std::size_t i = 1000; i < cloud.size(); ++i) {
    const Vec3<T> noise(T(0.002 * rng.normal()), T(0.002 * rng.normal()), T(0.002 * rng.normal()));
    source.push_back(inv.apply(cloud[i]) + noise);
  }
  IcpOptions<T> o;
  o.max_correspondence_distance_m = T(0.05);
  o.max_iterations = 60;
  const auto r = dyncull::icp_point_to_point(source, target, Rigid3<T>{}, o);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_LT(dyncull::test::rotation_error_deg(r.target_from_source, truth), 0.1);
  EXPECT_LT(dyncull::test::translation_error(r.target_from_source, truth), 0.003);
  // Random 2 cm sampling: the nearest target point of an overlapping source point is ~1 cm away.
  EXPECT_GT(r.fitness, T(0.7));
  EXPECT_LT(r.rmse, T(0.03));
  EXPECT_GT(r.iterations, 1);
}

// The reported statistics are those of a brute-force association at the returned transform.
TEST(IcpOracle, StatisticsMatchBruteForce) {
  Random rng(83);
  const auto target = room_cloud<double>(rng, 1500);
  std::vector<Vec3<double>> source;
  const Rigid3<double> motion = dyncull::test::random_rigid<double>(rng, 0.05, 0.05);
  for (int i = 0; i < 1200; ++i) source.push_back(motion.apply(target[static_cast<std::size_t>(i)]));
  IcpOptions<double> o;
  o.max_correspondence_distance_m = 0.04;
  o.max_iterations = 3;  // stop before convergence on purpose
  const auto r = dyncull::icp_point_to_point(source, target, Rigid3<double>{}, o);
  ASSERT_TRUE(r.ok()) << r.reason;
  std::size_t count = 0;
  double sum = 0;
  for (const auto& s : source) {
    const Vec3<double> q = r.target_from_source.apply(s);
    double best = std::numeric_limits<double>::infinity();
    for (const auto& t : target) best = std::min(best, (t - q).squaredNorm());
    if (best < 0.04 * 0.04) ++count, sum += best;
  }
  EXPECT_EQ(r.num_correspondences, count);
  EXPECT_NEAR(r.fitness, static_cast<double>(count) / 1200.0, 1e-12);
  EXPECT_NEAR(r.rmse, std::sqrt(sum / static_cast<double>(count)), 1e-12);
  EXPECT_EQ(r.iterations, 3);
  EXPECT_FALSE(r.converged);
}

TYPED_TEST(IcpTest, BadInputReportsStatus) {
  using T = TypeParam;
  Random rng(84);
  const auto target = room_cloud<T>(rng, 200);
  std::vector<Vec3<T>> two(target.begin(), target.begin() + 2);
  EXPECT_EQ(dyncull::icp_point_to_point(two, target, Rigid3<T>{}).status, Status::TooFewPoints);
  EXPECT_EQ(dyncull::icp_point_to_point(target, std::vector<Vec3<T>>{}, Rigid3<T>{}).status, Status::TooFewPoints);
  // Far apart clouds: no correspondence within the distance.
  Rigid3<T> far;
  far.t = Vec3<T>(100, 0, 0);
  const auto r = dyncull::icp_point_to_point(target, target, far);
  EXPECT_EQ(r.status, Status::TooFewPoints);
  EXPECT_FALSE(r.reason.empty());
  Rigid3<T> nan_pose;
  nan_pose.t.x() = std::numeric_limits<T>::quiet_NaN();
  EXPECT_EQ(dyncull::icp_point_to_point(target, target, nan_pose).status, Status::NonFinite);
  IcpOptions<T> bad;
  bad.max_correspondence_distance_m = T(-1);
  EXPECT_EQ(dyncull::icp_point_to_point(target, target, Rigid3<T>{}, bad).status, Status::InvalidInput);
  // NaN source points are skipped, the rest aligns.
  auto with_nan = target;
  with_nan[3].y() = std::numeric_limits<T>::quiet_NaN();
  const auto ok = dyncull::icp_point_to_point(with_nan, target, Rigid3<T>{});
  EXPECT_TRUE(ok.ok()) << ok.reason;
  // Collinear clouds leave the rotation about the line free: Degenerate.
  std::vector<Vec3<T>> line;
  for (int i = 0; i < 50; ++i) line.push_back(Vec3<T>(T(0.01) * T(i), T(0), T(0)));
  EXPECT_EQ(dyncull::icp_point_to_point(line, line, Rigid3<T>{}).status, Status::Degenerate);
}

TEST(IcpOptionsValidate, NamesTheFieldAndBoundsTheIterations) {
  std::string why;
  EXPECT_EQ(IcpOptions<double>{}.validate(&why), Status::Ok);
  EXPECT_TRUE(why.empty());
  Random rng(85);
  const auto target = room_cloud<double>(rng, 100);
  auto check = [&](const IcpOptions<double>& bad, const char* field) {
    EXPECT_EQ(bad.validate(&why), Status::InvalidInput);
    EXPECT_NE(why.find(field), std::string::npos) << why;
    const auto r = dyncull::icp_point_to_point(target, target, Rigid3<double>{}, bad);
    EXPECT_EQ(r.status, Status::InvalidInput);
    EXPECT_NE(r.reason.find(field), std::string::npos) << r.reason;
  };
  IcpOptions<double> bad;
  bad.max_iterations = 1 << 30;
  check(bad, "max_iterations");
  bad = {};
  bad.max_correspondence_distance_m = HUGE_VAL;
  check(bad, "max_correspondence_distance_m");
  bad = {};
  bad.relative_fitness = std::nan("");
  check(bad, "relative_fitness");
  bad = {};
  bad.relative_rmse = HUGE_VAL;
  check(bad, "relative_rmse");
}

// For any clouds, start and options: a non-Ok status with a reason, or a finite transform and statistics.
TYPED_TEST(IcpTest, PropertyTransformIsFiniteOrTheCallFails) {
  using T = TypeParam;
  Random rng(86);
  for (int trial = 0; trial < 150; ++trial) {
    auto target = room_cloud<T>(rng, static_cast<int>(rng.index(60)));
    const bool clean = rng.uniform() < 0.3;
    std::vector<Vec3<T>> source = target;
    const Rigid3<T> motion = dyncull::test::random_rigid<T>(rng, 0.05, 0.05);
    for (auto& p : source) p = motion.apply(p);
    if (!clean) {
      for (auto* cloud : {&source, &target}) {
        for (auto& p : *cloud) {
          if (rng.uniform() < 0.2) {
            p = Vec3<T>(solver_value<T>(rng, -3, 3), solver_value<T>(rng, -3, 3), solver_value<T>(rng, -3, 3));
          }
        }
      }
    }
    IcpOptions<T> o;
    o.max_iterations = static_cast<int>(rng.index(40)) - (rng.uniform() < 0.05 ? 50 : 0);
    o.max_correspondence_distance_m = rng.uniform() < 0.1 ? solver_value<T>(rng, 0, 1) : T(rng.uniform(0.01, 1));
    o.estimate_scale = rng.uniform() < 0.3;
    Rigid3<T> start;
    if (rng.uniform() < 0.1) start.t.y() = solver_value<T>(rng, -1, 1);
    const auto r = dyncull::icp_point_to_point(source, target, start, o);
    if (!r.ok()) {
      EXPECT_FALSE(r.reason.empty()) << trial;
      continue;
    }
    EXPECT_TRUE(r.target_from_source.all_finite()) << trial;
    EXPECT_TRUE(std::isfinite(r.scale) && std::isfinite(r.rmse) && std::isfinite(r.fitness)) << trial;
    EXPECT_GE(r.fitness, T(0));
    EXPECT_LE(r.fitness, T(1));
  }
}

}  // namespace
