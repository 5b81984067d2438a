// Tests of geometry/pnp.hpp: P3P exactness (double), DLT and LM refinement (float and double),
// PnP-RANSAC with 0.5 px noise and 30 % outliers, degenerate inputs, and OpenCV cross-checks.
#include "dyncull/geometry/pnp.hpp"

#include "support/adversarial.hpp"
#include "support/pose_data.hpp"

#include <gtest/gtest.h>

#include <string>

#include <limits>
#include <vector>

#ifdef DYNCULL_HAS_OPENCV
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

using dyncull::test::solver_value;
#endif

namespace {

using dyncull::PnpOptions;
using dyncull::Random;
using dyncull::Rigid3;
using dyncull::Status;
using dyncull::Vec2;
using dyncull::Vec3;
using dyncull::test::make_pnp_scene;
using dyncull::test::rotation_error_deg;
using dyncull::test::translation_error;

// P3P is double-only (documented in pnp.hpp): closed-form cubic and quadratic roots.
TEST(P3P, RecoversPoseExactlyAmongSolutions) {
  Random rng(21);
  int found = 0;
  const int trials = 200;
  for (int trial = 0; trial < trials; ++trial) {
    const auto scene = make_pnp_scene<double>(1000 + static_cast<std::uint64_t>(trial), 3);
    Vec3<double> bearings[3], world[3];
    for (int k = 0; k < 3; ++k) {
      bearings[k] = scene.camera.ray(scene.pixels[static_cast<std::size_t>(k)]).normalized();
      world[k] = scene.world[static_cast<std::size_t>(k)];
    }
    Rigid3<double> poses[4];
    const int m = dyncull::solve_p3p(bearings, world, poses);
    ASSERT_GE(m, 1) << "trial " << trial;
    ASSERT_LE(m, 4);
    double best = std::numeric_limits<double>::infinity();
    for (int k = 0; k < m; ++k) {
      // Every solution must reproject the three points exactly (they are all valid P3P solutions).
      for (int j = 0; j < 3; ++j) {
        const Vec3<double> pc = poses[k].apply(world[j]);
        EXPECT_GT(pc.z(), 0);
        EXPECT_LT((pc.normalized() - bearings[j]).norm(), 1e-9);
      }
      best = std::min(best, (poses[k].R - scene.cam_from_world.R).norm() +
                                (poses[k].t - scene.cam_from_world.t).norm());
    }
    found += best < 1e-9;
  }
  EXPECT_EQ(found, trials);
}

TEST(P3P, CollinearPointsGiveNoSolution) {
  Vec3<double> bearings[3] = {Vec3<double>(0, 0, 1), Vec3<double>(0.1, 0, 1).normalized(),
                              Vec3<double>(0.2, 0, 1).normalized()};
  Vec3<double> world[3] = {Vec3<double>(0, 0, 5), Vec3<double>(0.5, 0, 5), Vec3<double>(1, 0, 5)};
  Rigid3<double> poses[4];
  EXPECT_EQ(dyncull::solve_p3p(bearings, world, poses), 0);
}

template <class T>
class PnpTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(PnpTest, Scalars, dyncull::test::ScalarNames);

template <class T>
constexpr bool is_double() {
  return std::is_same<T, double>::value;
}

TYPED_TEST(PnpTest, DltAndRefinementExactWithoutNoise) {
  using T = TypeParam;
  const auto s = make_pnp_scene<T>(31, 100);
  const auto dlt = dyncull::solve_pnp_dlt(s.world, s.pixels, s.camera);
  ASSERT_TRUE(dlt.ok()) << dlt.reason;
  // Exact data: DLT alone is exact up to conditioning (double 1e-9, float ~1e-3 rad).
  EXPECT_LT(rotation_error_deg(dlt.cam_from_world, s.cam_from_world), is_double<T>() ? 1e-7 : 0.1);
  const auto r = dyncull::solve_pnp(s.world, s.pixels, s.camera);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.num_inliers, 100u);
  // double: 1e-9 relative; float: single precision pixels (~1e-4 px at 640) limit the pose to ~1e-4.
  EXPECT_LT(rotation_error_deg(r.cam_from_world, s.cam_from_world), is_double<T>() ? 1e-7 : 5e-3);
  EXPECT_LT(translation_error(r.cam_from_world, s.cam_from_world),
            is_double<T>() ? 1e-9 * (1 + s.cam_from_world.t.norm()) : 1e-3);
  EXPECT_LT(r.rmse_px, is_double<T>() ? 1e-6 : 1e-2);
}

TYPED_TEST(PnpTest, CoplanarPointsUseP3PFallback) {
  using T = TypeParam;
  auto s = make_pnp_scene<T>(32, 60);
  // Put all world points on the plane z_world = 0 seen obliquely, re-projecting their pixels.
  const Rigid3<double> cfw = s.cam_from_world.template cast<double>();
  Random rng(5);
  for (std::size_t i = 0; i < s.world.size(); ++i) {
    Vec3<double> pw(rng.uniform(-2, 2), rng.uniform(-2, 2), 0.0);
    Rigid3<double> shift;
    shift.t = Vec3<double>(0, 0, 5);
    const Rigid3<double> cam_from_plane = shift;
    s.world[i] = pw.cast<T>();
    s.pixels[i] = s.camera.template cast<double>().project(cam_from_plane.apply(pw)).template cast<T>();
  }
  (void)cfw;
  s.cam_from_world = Rigid3<T>{};
  s.cam_from_world.t = Vec3<T>(0, 0, 5);
  EXPECT_EQ(dyncull::solve_pnp_dlt(s.world, s.pixels, s.camera).status, Status::Degenerate);
  const auto r = dyncull::solve_pnp(s.world, s.pixels, s.camera);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_LT(rotation_error_deg(r.cam_from_world, s.cam_from_world), is_double<T>() ? 1e-7 : 5e-3);
  EXPECT_LT(translation_error(r.cam_from_world, s.cam_from_world), is_double<T>() ? 1e-8 : 1e-3);
}

TYPED_TEST(PnpTest, RansacWithNoiseAndOutliers) {
  using T = TypeParam;
  for (std::uint64_t seed : {41u, 42u, 43u}) {
    const auto s = make_pnp_scene<T>(seed, 1000, 0.5, 0.3);
    PnpOptions<T> o;
    o.ransac.seed = seed;
    const auto r = dyncull::solve_pnp_ransac(s.world, s.pixels, s.camera, o);
    ASSERT_TRUE(r.ok()) << r.reason;
    // 0.5 px noise, ~700 inliers at 2-8 m: the pose is good to ~0.02 deg and ~2 mm (PoseLib: 0.006 deg, 0.26 mm).
    EXPECT_LT(rotation_error_deg(r.cam_from_world, s.cam_from_world), 0.05);
    EXPECT_LT(translation_error(r.cam_from_world, s.cam_from_world), 0.01);
    std::size_t true_in = 0, agree = 0;
    for (std::size_t i = 0; i < s.world.size(); ++i) {
      true_in += !s.is_outlier[i];
      agree += (r.inlier_mask[i] != 0) == (s.is_outlier[i] == 0);
    }
    EXPECT_GT(static_cast<double>(agree) / 1000.0, 0.97);  // a few random outliers land within 2 px
    EXPECT_GT(r.num_inliers, true_in * 95 / 100);
    EXPECT_LT(r.rmse_px, 1.0);
  }
}

TYPED_TEST(PnpTest, RansacDeterministicForSeed) {
  using T = TypeParam;
  const auto s = make_pnp_scene<T>(44, 300, 0.5, 0.4);
  PnpOptions<T> o;
  o.ransac.seed = 3;
  const auto a = dyncull::solve_pnp_ransac(s.world, s.pixels, s.camera, o);
  const auto b = dyncull::solve_pnp_ransac(s.world, s.pixels, s.camera, o);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a.inlier_mask, b.inlier_mask);
  EXPECT_EQ(a.cam_from_world.R, b.cam_from_world.R);
  EXPECT_EQ(a.iterations, b.iterations);
}

TYPED_TEST(PnpTest, KeptWorkspaceGivesTheFreshResultWhateverCameBefore) {
  using T = TypeParam;
  // Sizes and outcomes in turn (large, too few points, small, medium): nothing may carry over.
  std::vector<dyncull::test::PnpScene<T>> scenes = {make_pnp_scene<T>(46, 1000, 0.5, 0.3),
                                                    make_pnp_scene<T>(47, 3, 0.5, 0.0),
                                                    make_pnp_scene<T>(48, 40, 0.5, 0.2),
                                                    make_pnp_scene<T>(49, 300, 0.5, 0.4)};
  PnpOptions<T> o;
  dyncull::PnpWorkspace<T> workspace;
  dyncull::PnpResult<T> kept;
  for (int round = 0; round < 2; ++round) {
    for (std::size_t k = 0; k < scenes.size(); ++k) {
      const auto& s = scenes[k];
      dyncull::solve_pnp_ransac(s.world, s.pixels, s.camera, o, &workspace, &kept);
      const auto fresh = dyncull::solve_pnp_ransac(s.world, s.pixels, s.camera, o);
      EXPECT_EQ(kept.status, fresh.status) << "scene " << k;
      EXPECT_EQ(kept.reason, fresh.reason) << "scene " << k;
      EXPECT_EQ(kept.cam_from_world.R, fresh.cam_from_world.R) << "scene " << k;  // bit for bit
      EXPECT_EQ(kept.cam_from_world.t, fresh.cam_from_world.t) << "scene " << k;
      EXPECT_EQ(kept.inlier_mask, fresh.inlier_mask) << "scene " << k;
      EXPECT_EQ(kept.num_inliers, fresh.num_inliers) << "scene " << k;
      EXPECT_EQ(kept.iterations, fresh.iterations) << "scene " << k;
      EXPECT_EQ(kept.rmse_px, fresh.rmse_px) << "scene " << k;
    }
  }
  EXPECT_EQ(kept.status, Status::Ok);  // the last scene is an ordinary one
}

TYPED_TEST(PnpTest, HuberRefinementResistsOutliers) {
  using T = TypeParam;
  auto s = make_pnp_scene<T>(45, 200, 0.5, 0.0);
  for (std::size_t i = 0; i < 20; ++i) s.pixels[i] += Vec2<T>(T(15), T(-10));  // gross errors left in
  Rigid3<T> start = s.cam_from_world;
  start.t += Vec3<T>(T(0.05), T(-0.03), T(0.02));
  dyncull::PoseRefinementOptions<T> ls, hub;
  hub.huber = true;
  hub.huber_threshold_px = T(1);
  const auto a = dyncull::refine_pose(s.world, s.pixels, s.camera, start, ls);
  const auto b = dyncull::refine_pose(s.world, s.pixels, s.camera, start, hub);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_LT(b.final_cost, b.initial_cost);
  EXPECT_LT(translation_error(b.cam_from_world, s.cam_from_world),
            0.5 * translation_error(a.cam_from_world, s.cam_from_world));
  // With a mask excluding the corrupted points, plain least squares is as good as Huber.
  std::vector<std::uint8_t> mask(200, 1);
  std::fill(mask.begin(), mask.begin() + 20, 0);
  const auto c = dyncull::refine_pose(s.world, s.pixels, s.camera, start, ls, mask);
  ASSERT_TRUE(c.ok());
  EXPECT_EQ(c.num_points, 180u);
  EXPECT_LT(translation_error(c.cam_from_world, s.cam_from_world), 0.01);
  EXPECT_LT(c.rmse_px, 1.0);
}

TYPED_TEST(PnpTest, DegenerateInputsReportStatus) {
  using T = TypeParam;
  const auto s = make_pnp_scene<T>(46, 10);
  std::vector<Vec3<T>> w3(s.world.begin(), s.world.begin() + 3);
  std::vector<Vec2<T>> p3(s.pixels.begin(), s.pixels.begin() + 3);
  EXPECT_EQ(dyncull::solve_pnp_ransac(w3, p3, s.camera).status, Status::TooFewPoints);
  EXPECT_EQ(dyncull::solve_pnp(w3, p3, s.camera).status, Status::TooFewPoints);
  EXPECT_EQ(dyncull::solve_pnp_dlt(w3, p3, s.camera).status, Status::TooFewPoints);

  std::vector<Vec2<T>> p9(s.pixels.begin(), s.pixels.begin() + 9);
  EXPECT_EQ(dyncull::solve_pnp_ransac(s.world, p9, s.camera).status, Status::InvalidInput);

  // NaN: skipped when enough finite correspondences remain, NonFinite when they do not.
  auto w = s.world;
  w[2].x() = std::numeric_limits<T>::quiet_NaN();
  const auto r = dyncull::solve_pnp(w, s.pixels, s.camera);
  EXPECT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.inlier_mask[2], 0);
  std::vector<Vec3<T>> w5(w.begin(), w.begin() + 4);
  std::vector<Vec2<T>> p5(s.pixels.begin(), s.pixels.begin() + 4);
  EXPECT_EQ(dyncull::solve_pnp_ransac(w5, p5, s.camera).status, Status::NonFinite);

  // Collinear world points: no pose, a status, no crash.
  std::vector<Vec3<T>> line;
  std::vector<Vec2<T>> pix;
  for (int i = 0; i < 20; ++i) {
    line.push_back(Vec3<T>(T(0.1) * T(i), T(0), T(4)));
    pix.push_back(s.camera.project(line.back()));
  }
  EXPECT_FALSE(dyncull::solve_pnp_ransac(line, pix, s.camera).ok());
  EXPECT_FALSE(dyncull::solve_pnp(line, pix, s.camera).ok());

  // Duplicate points only.
  std::vector<Vec3<T>> dup(10, s.world[0]);
  std::vector<Vec2<T>> dpx(10, s.pixels[0]);
  EXPECT_FALSE(dyncull::solve_pnp_ransac(dup, dpx, s.camera).ok());

  // Invalid camera and a refinement starting from NaN.
  dyncull::PinholeCamera<T> bad = s.camera;
  bad.fx = T(0);
  EXPECT_EQ(dyncull::solve_pnp_ransac(s.world, s.pixels, bad).status, Status::InvalidInput);
  Rigid3<T> nan_pose;
  nan_pose.t.x() = std::numeric_limits<T>::quiet_NaN();
  EXPECT_EQ(dyncull::refine_pose(s.world, s.pixels, s.camera, nan_pose).status, Status::NonFinite);
  // All points behind the camera.
  Rigid3<T> behind;
  behind.t = Vec3<T>(0, 0, -100);
  EXPECT_EQ(dyncull::refine_pose(s.world, s.pixels, s.camera, behind).status, Status::TooFewPoints);
}

#ifdef DYNCULL_HAS_OPENCV
TEST(PnpVsOpenCV, SameAccuracyAsSolvePnPRansacP3P) {
  double ours_r = 0, ours_t = 0, cv_r = 0, cv_t = 0;
  for (std::uint64_t seed = 50; seed < 55; ++seed) {
    const auto s = make_pnp_scene<double>(seed, 1000, 0.5, 0.3);
    const auto r = dyncull::solve_pnp_ransac(s.world, s.pixels, s.camera);
    ASSERT_TRUE(r.ok());
    ours_r += rotation_error_deg(r.cam_from_world, s.cam_from_world);
    ours_t += translation_error(r.cam_from_world, s.cam_from_world);
    std::vector<cv::Point3d> obj;
    std::vector<cv::Point2d> img;
    for (std::size_t i = 0; i < s.world.size(); ++i) {
      obj.emplace_back(s.world[i].x(), s.world[i].y(), s.world[i].z());
      img.emplace_back(s.pixels[i].x(), s.pixels[i].y());
    }
    cv::Mat K;
    cv::eigen2cv(s.camera.K(), K);
    cv::Mat rvec, tvec, R;
    ASSERT_TRUE(cv::solvePnPRansac(obj, img, K, cv::noArray(), rvec, tvec, false, 1000, 2.0f, 0.99, cv::noArray(),
                                   cv::SOLVEPNP_P3P));
    cv::Rodrigues(rvec, R);
    Rigid3<double> c;
    cv::cv2eigen(R, c.R);
    cv::cv2eigen(tvec, c.t);
    cv_r += rotation_error_deg(c, s.cam_from_world);
    cv_t += translation_error(c, s.cam_from_world);
    // Same all-point refinement on cv's pose and ours end at the same optimum of the inlier set.
    EXPECT_LT(rotation_error_deg(c, r.cam_from_world), 0.1);
  }
  EXPECT_LE(ours_r, cv_r * 1.05);
  EXPECT_LE(ours_t, cv_t * 1.05);
}

TEST(PnpVsOpenCV, RefinementMatchesSolvePnPIterative) {
  const auto s = make_pnp_scene<double>(60, 300, 0.5, 0.0);
  const auto r = dyncull::solve_pnp(s.world, s.pixels, s.camera);
  ASSERT_TRUE(r.ok());
  std::vector<cv::Point3d> obj;
  std::vector<cv::Point2d> img;
  for (std::size_t i = 0; i < s.world.size(); ++i) {
    obj.emplace_back(s.world[i].x(), s.world[i].y(), s.world[i].z());
    img.emplace_back(s.pixels[i].x(), s.pixels[i].y());
  }
  cv::Mat K;
  cv::eigen2cv(s.camera.K(), K);
  cv::Mat rvec, tvec, R;
  ASSERT_TRUE(cv::solvePnP(obj, img, K, cv::noArray(), rvec, tvec, false, cv::SOLVEPNP_ITERATIVE));
  cv::Rodrigues(rvec, R);
  Rigid3<double> c;
  cv::cv2eigen(R, c.R);
  cv::cv2eigen(tvec, c.t);
  // Both minimise the same sum of squared reprojection errors: same minimum.
  EXPECT_LT(rotation_error_deg(c, r.cam_from_world), 1e-4);
  EXPECT_LT(translation_error(c, r.cam_from_world), 1e-5);
}
#endif

TEST(PnpOptionsValidate, NamesTheFieldIncludingNestedOptions) {
  std::string why;
  EXPECT_EQ(PnpOptions<double>{}.validate(&why), Status::Ok);
  EXPECT_TRUE(why.empty());
  EXPECT_EQ(dyncull::PoseRefinementOptions<float>{}.validate(&why), Status::Ok);
  const auto s = make_pnp_scene<double>(5, 30);
  auto check = [&](const PnpOptions<double>& bad, const char* field) {
    EXPECT_EQ(bad.validate(&why), Status::InvalidInput);
    EXPECT_NE(why.find(field), std::string::npos) << why;
    for (const auto& r : {dyncull::solve_pnp(s.world, s.pixels, s.camera, bad),
                          dyncull::solve_pnp_ransac(s.world, s.pixels, s.camera, bad)}) {
      EXPECT_EQ(r.status, Status::InvalidInput);
      EXPECT_NE(r.reason.find(field), std::string::npos) << r.reason;
      EXPECT_EQ(r.inlier_mask.size(), s.world.size());
    }
    const auto rr = dyncull::refine_pose(s.world, s.pixels, s.camera, s.cam_from_world, bad.refinement);
    if (bad.refinement.validate() != Status::Ok) {
      EXPECT_EQ(rr.status, Status::InvalidInput);
    }
  };
  PnpOptions<double> bad;
  bad.refinement.max_iterations = 1 << 30;  // unbounded time: refused
  check(bad, "refinement.max_iterations");
  bad = {};
  bad.refinement.huber_threshold_px = std::nan("");  // accepted while huber was off
  check(bad, "refinement.huber_threshold_px");
  bad = {};
  bad.refinement.step_tolerance = -1;
  check(bad, "refinement.step_tolerance");
  bad = {};
  bad.refinement.initial_damping = HUGE_VAL;
  check(bad, "refinement.initial_damping");
  bad = {};
  bad.ransac.max_residual = 0;
  check(bad, "ransac.max_residual");
}

// For any correspondences, camera and options: a non-Ok status with a reason, or a finite pose with a
// consistent mask (solve_pnp, solve_pnp_ransac, solve_pnp_dlt, refine_pose), float and double.
template <class T>
void pnp_property(std::uint64_t seed) {
  Random rng(seed);
  for (int trial = 0; trial < 150; ++trial) {
    const int n = static_cast<int>(rng.index(30));
    auto s = make_pnp_scene<T>(seed + static_cast<std::uint64_t>(trial), n, 0.5, 0.2);
    const bool half_clean = rng.uniform() < 0.5;
    for (std::size_t i = 0; i < s.world.size(); ++i) {
      if (half_clean && rng.uniform() < 0.8) continue;
      if (rng.uniform() < 0.5) {
        s.world[i] = Vec3<T>(solver_value<T>(rng, -3, 3), solver_value<T>(rng, -3, 3), solver_value<T>(rng, 0, 8));
      }
      if (rng.uniform() < 0.5) s.pixels[i] = Vec2<T>(solver_value<T>(rng, 0, 640), solver_value<T>(rng, 0, 480));
    }
    if (rng.uniform() < 0.1) s.camera.fx = solver_value<T>(rng, 1, 1000);
    PnpOptions<T> o;
    o.ransac.max_iterations = 1 + rng.index(200);
    o.ransac.seed = static_cast<std::uint64_t>(trial);
    o.refine = rng.uniform() < 0.7;
    o.refinement.huber = rng.uniform() < 0.3;
    if (rng.uniform() < 0.1) o.refinement.max_iterations = -3;
    if (rng.uniform() < 0.1) o.ransac.max_residual = std::nan("");
    const std::size_t n_total = s.world.size();
    auto check = [&](const dyncull::PnpResult<T>& r, const char* which) {
      if (!r.ok()) {
        EXPECT_FALSE(r.reason.empty()) << which << " trial " << trial;
        return;
      }
      EXPECT_TRUE(r.cam_from_world.all_finite()) << which << " trial " << trial;
      EXPECT_TRUE(std::isfinite(r.rmse_px)) << which << " trial " << trial;
      ASSERT_EQ(r.inlier_mask.size(), n_total) << which;
      std::size_t count = 0;
      for (auto m : r.inlier_mask) count += m;
      EXPECT_EQ(count, r.num_inliers) << which << " trial " << trial;
    };
    check(dyncull::solve_pnp(s.world, s.pixels, s.camera, o), "solve_pnp");
    check(dyncull::solve_pnp_ransac(s.world, s.pixels, s.camera, o), "solve_pnp_ransac");
    check(dyncull::solve_pnp_dlt(s.world, s.pixels, s.camera), "solve_pnp_dlt");
    Rigid3<T> start = s.cam_from_world;
    if (rng.uniform() < 0.2) start.t.x() = solver_value<T>(rng, -1, 1);
    const auto r = dyncull::refine_pose(s.world, s.pixels, s.camera, start, o.refinement);
    if (!r.ok()) {
      EXPECT_FALSE(r.reason.empty()) << "refine_pose trial " << trial;
    } else {
      EXPECT_TRUE(r.cam_from_world.all_finite()) << "refine_pose trial " << trial;
      EXPECT_TRUE(std::isfinite(r.final_cost) && std::isfinite(r.rmse_px)) << "refine_pose trial " << trial;
    }
  }
}

TEST(PnpProperty, FloatPoseIsFiniteOrTheCallFails) { pnp_property<float>(61); }
TEST(PnpProperty, DoublePoseIsFiniteOrTheCallFails) { pnp_property<double>(62); }

// A mask of another length than the correspondences: InvalidInput naming it and both sizes, nothing read
// past the end (AddressSanitizer).
TYPED_TEST(PnpTest, MaskOfAnotherLengthIsInvalidInputAndNotRead) {
  using T = TypeParam;
  const auto s = make_pnp_scene<T>(45, 50, 0.5, 0.0);
  const std::vector<std::uint8_t> few(10, 1), all(50, 1);
  const auto r = dyncull::refine_pose(s.world, s.pixels, s.camera, s.cam_from_world, {}, few);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_EQ(r.reason, "refine_pose: mask has 10 entries for 50 correspondences");
  EXPECT_TRUE(dyncull::refine_pose(s.world, s.pixels, s.camera, s.cam_from_world, {}, all).ok());
}

}  // namespace
