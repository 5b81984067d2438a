// Tests of ceres/pose_refinement.hpp: Ceres with EigenQuaternionManifold reaches the same optimum as
// the core Levenberg-Marquardt of geometry/pnp.hpp (least squares and Huber), float and double.
#include "dyncull/ceres/pose_refinement.hpp"

#include "support/pose_data.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <vector>

namespace {

using dyncull::PoseRefinementOptions;
using dyncull::Rigid3;
using dyncull::Status;
using dyncull::Vec2;
using dyncull::Vec3;
using dyncull::test::make_pnp_scene;
using dyncull::test::rotation_error_deg;
using dyncull::test::translation_error;

template <class T>
class CeresPoseTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(CeresPoseTest, Scalars, dyncull::test::ScalarNames);

TYPED_TEST(CeresPoseTest, AgreesWithCoreRefinement) {
  using T = TypeParam;
  const bool dbl = std::is_same<T, double>::value;
  for (bool huber : {false, true}) {
    auto s = make_pnp_scene<T>(301, 300, 0.5, 0.0);
    for (std::size_t i = 0; i < 15; ++i) s.pixels[i] += Vec2<T>(T(12), T(-7));  // outliers for the Huber case
    Rigid3<T> start = s.cam_from_world;
    start.t += Vec3<T>(T(0.04), T(-0.02), T(0.03));
    start.R = start.R * Eigen::AngleAxis<T>(T(0.01), Vec3<T>::UnitY()).toRotationMatrix();
    PoseRefinementOptions<T> o;
    o.huber = huber;
    o.huber_threshold_px = T(1);
    o.max_iterations = 50;
    const auto core = dyncull::refine_pose(s.world, s.pixels, s.camera, start, o);
    const auto ceres = dyncull::refine_pose_ceres(s.world, s.pixels, s.camera, start, o);
    ASSERT_TRUE(core.ok()) << core.reason;
    ASSERT_TRUE(ceres.ok()) << ceres.reason;
    EXPECT_EQ(core.num_points, ceres.num_points);
    // Same cost convention: the initial costs agree to rounding, the minima to the solvers' tolerance.
    // (float: the core stores normalised image coordinates in float, 1e-7 relative.)
    EXPECT_NEAR(core.initial_cost, ceres.initial_cost, (dbl ? 1e-9 : 1e-5) * core.initial_cost);
    EXPECT_NEAR(core.final_cost, ceres.final_cost, (dbl ? 1e-8 : 1e-4) * core.final_cost) << "huber " << huber;
    EXPECT_LT(rotation_error_deg(core.cam_from_world, ceres.cam_from_world), dbl ? 1e-6 : 1e-3);
    EXPECT_LT(translation_error(core.cam_from_world, ceres.cam_from_world), dbl ? 1e-8 : 1e-4);
    // rmse is not the minimised quantity under Huber: it moves along the cost's flat directions.
    EXPECT_NEAR(core.rmse_px, ceres.rmse_px, dbl ? 1e-6 : 1e-3);
    EXPECT_LT(ceres.final_cost, ceres.initial_cost);
  }
}

TYPED_TEST(CeresPoseTest, MaskAndBadInput) {
  using T = TypeParam;
  const auto s = make_pnp_scene<T>(302, 50, 0.5, 0.0);
  std::vector<std::uint8_t> mask(50, 0);
  mask[0] = mask[1] = 1;
  EXPECT_EQ(dyncull::refine_pose_ceres(s.world, s.pixels, s.camera, s.cam_from_world, {}, mask).status,
            Status::TooFewPoints);
  std::fill(mask.begin(), mask.end(), 1);
  const auto r = dyncull::refine_pose_ceres(s.world, s.pixels, s.camera, s.cam_from_world, {}, mask);
  EXPECT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.num_points, 50u);
  Rigid3<T> nan_pose;
  nan_pose.R(0, 0) = std::numeric_limits<T>::quiet_NaN();
  EXPECT_EQ(dyncull::refine_pose_ceres(s.world, s.pixels, s.camera, nan_pose).status, Status::NonFinite);
  std::vector<Vec2<T>> fewer(s.pixels.begin(), s.pixels.begin() + 10);
  EXPECT_EQ(dyncull::refine_pose_ceres(s.world, fewer, s.camera, s.cam_from_world).status, Status::InvalidInput);
  // A mask of another length is refused before a flag is read.
  const std::vector<std::uint8_t> short_mask(10, 1);
  const auto m = dyncull::refine_pose_ceres(s.world, s.pixels, s.camera, s.cam_from_world, {}, short_mask);
  EXPECT_EQ(m.status, Status::InvalidInput);
  EXPECT_EQ(m.reason, "refine_pose_ceres: mask has 10 entries for 50 correspondences");
}

TYPED_TEST(CeresPoseTest, InvalidOptionsAreRefusedWithTheFieldNamed) {
  using T = TypeParam;
  const auto s = make_pnp_scene<T>(303, 50, 0.5, 0.0);
  const T nan = std::numeric_limits<T>::quiet_NaN();
  const auto refused = [&](const PoseRefinementOptions<T>& o, const char* field) {
    const auto r = dyncull::refine_pose_ceres(s.world, s.pixels, s.camera, s.cam_from_world, o);
    EXPECT_EQ(r.status, Status::InvalidInput) << field;
    EXPECT_NE(r.reason.find(field), std::string::npos) << r.reason;
    // The same options are refused the same way by the core refinement.
    EXPECT_EQ(dyncull::refine_pose(s.world, s.pixels, s.camera, s.cam_from_world, o).status, Status::InvalidInput);
  };
  PoseRefinementOptions<T> o;
  o.max_iterations = 1000000;  // unbounded time
  refused(o, "max_iterations");
  o = {};
  o.step_tolerance = nan;
  refused(o, "step_tolerance");
  o = {};
  o.cost_tolerance = T(-1);
  refused(o, "cost_tolerance");
  o = {};
  o.huber = true;
  o.huber_threshold_px = std::numeric_limits<T>::infinity();
  refused(o, "huber_threshold_px");
  o = {};
  o.initial_damping = nan;
  refused(o, "initial_damping");
}

}  // namespace
