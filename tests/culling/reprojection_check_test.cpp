// Tests of the RGB-D reprojection check: pose from the tracks outside the boxes, residual of every track.
#include "dyncull/culling/moving_consistency.hpp"
#include "dyncull/culling/reprojection_check.hpp"

#include "dyncull/core/random.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace dyncull {
namespace {

template <class T>
class ReprojectionCheckTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(ReprojectionCheckTest, Scalars, );  // trailing comma: clang -Wpedantic rejects an empty variadic

/// A reference camera at the world origin, a current camera moved 12 cm sideways, a static room at
/// 2-5 m and an object at about 2 m that moves along the reference camera's rays (15 % further away).
/// Such a point stays on its epipolar line: the epipolar check cannot see it; the reprojection can.
template <class T>
struct AlongRayScene {
  PinholeCamera<T> camera = PinholeCamera<double>::tum_fr3().cast<T>();
  Rigid3<T> cam_from_world;
  std::vector<Vec3<T>> points;             ///< reference 3-D points (world = reference camera)
  std::vector<Vec2<T>> ref_pixels, pixels;  ///< observations in the reference and current image
  std::vector<std::uint8_t> moving, in_box;
};

template <class T>
AlongRayScene<T> make_along_ray_scene(double noise_px = 0.3, std::uint64_t seed = 3) {
  AlongRayScene<T> s;
  const PinholeCamera<double> cam = PinholeCamera<double>::tum_fr3();
  Rigid3<double> cw;
  cw.R = Eigen::AngleAxisd(0.02, Vec3<double>(0.2, 1, 0.1).normalized()).toRotationMatrix();
  cw.t = Vec3<double>(-0.12, 0.02, 0.03);
  s.cam_from_world = cw.cast<T>();
  Random rng(seed);
  auto add = [&](const Vec3<double>& X, bool moving) {
    const Vec3<double> X_now = moving ? Vec3<double>(1.15 * X) : X;
    const Vec2<double> ref = cam.project(X), cur = cam.project(cw.apply(X_now));
    if (!cam.in_image(ref.x(), ref.y()) || !cam.in_image(cur.x(), cur.y())) return;
    s.points.push_back(X.cast<T>());
    s.ref_pixels.push_back(Vec2<T>(T(ref.x() + noise_px * rng.normal()), T(ref.y() + noise_px * rng.normal())));
    s.pixels.push_back(Vec2<T>(T(cur.x() + noise_px * rng.normal()), T(cur.y() + noise_px * rng.normal())));
    s.moving.push_back(moving);
    s.in_box.push_back(moving);
  };
  for (int i = 0; i < 300; ++i) {
    const double z = rng.uniform(2.0, 5.0);
    add(Vec3<double>(rng.uniform(-0.55, 0.55) * z, rng.uniform(-0.4, 0.4) * z, z), false);
  }
  for (int i = 0; i < 80; ++i) {
    const double z = rng.uniform(1.8, 2.2);
    add(Vec3<double>(rng.uniform(-0.15, 0.15) * z, rng.uniform(-0.2, 0.2) * z, z), true);
  }
  return s;
}

template <class T>
double flagged_rate(const std::vector<FeatureLabel>& labels, const std::vector<std::uint8_t>& moving, bool want) {
  std::size_t n = 0, d = 0;
  for (std::size_t i = 0; i < labels.size(); ++i)
    if (bool(moving[i]) == want) {
      ++n;
      d += labels[i] == FeatureLabel::Dynamic;
    }
  return n ? double(d) / double(n) : 0.0;
}

// The object's motion is along its epipolar lines: the epipolar check (1 px in boxes, as the recommended
// preset) flags only noise on it, the reprojection check all of it (measured 100 %: 15 % of 2 m seen over
// a 12 cm baseline is 3-4 px). Static tracks: 0.3 px noise per end, 3 px outside boxes: none flagged.
TYPED_TEST(ReprojectionCheckTest, SeesMotionAlongTheEpipolarLine) {
  using T = TypeParam;
  const auto s = make_along_ray_scene<T>();
  const auto r = check_reprojection(s.points, s.pixels, s.camera, ReprojectionCheckOptions<T>{}, nullptr, s.in_box);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_TRUE(r.fitted_outside_boxes);
  EXPECT_EQ(r.num_valid, s.points.size());
  EXPECT_LT(r.num_fit, r.num_valid);
  EXPECT_GT(flagged_rate<T>(r.labels, s.moving, true), 0.95);
  EXPECT_LT(flagged_rate<T>(r.labels, s.moving, false), 0.02);
  EXPECT_EQ(r.num_dynamic + r.num_static, r.num_valid);
  // The fitted pose is the camera's.
  EXPECT_LT((r.cam_from_world.t - s.cam_from_world.t).norm(), T(0.01));
  EXPECT_LT((r.cam_from_world.R - s.cam_from_world.R).norm(), T(2e-3));
  // Residuals agree with a direct projection, and no in-box track was used in the fit.
  for (std::size_t i = 0; i < s.points.size(); i += 17) {
    const Vec2<T> q = s.camera.project(r.cam_from_world.apply(s.points[i]));
    EXPECT_NEAR(double(r.residual_px[i]), double((q - s.pixels[i]).norm()), 1e-3);
    // The vector is measured minus predicted.
    EXPECT_NEAR(double(r.residual_vec[i].x()), double(s.pixels[i].x() - q.x()), 1e-3);
    EXPECT_NEAR(double(r.residual_vec[i].y()), double(s.pixels[i].y() - q.y()), 1e-3);
    if (s.in_box[i]) {
      EXPECT_EQ(r.inlier_mask[i], 0);
    }
  }

  // The static tracks' noise: 0.3 px at each end (the reference pixel enters through nothing here, the
  // points are exact), so one residual component has sd 0.3; the robust estimate lands near it.
  EXPECT_GT(double(r.inlier_noise_px), 0.2);
  EXPECT_LT(double(r.inlier_noise_px), 0.4);

  // The epipolar check on the same tracks is blind to this motion.
  MovingConsistencyOptions<T> epi;
  epi.max_epipolar_distance_in_boxes_px = T(1);
  const auto e = check_moving_consistency(s.ref_pixels, s.pixels, epi, nullptr, s.in_box);
  ASSERT_TRUE(e.ok()) << e.reason;
  EXPECT_LT(flagged_rate<T>(e.labels, s.moving, true), 0.1);
}

// The limits rise with the frame's own static-track noise (kNoiseMultiple times inlier_noise_px): at
// 0.8 px per component (a real camera's blur and calibration) a fixed 1.5 px flags about a sixth of the
// still tracks in a box; at 0.3 px (the simulator's) the 1.5 px limit stands.
TYPED_TEST(ReprojectionCheckTest, LimitsRiseWithTheFramesNoise) {
  using T = TypeParam;
  for (double noise : {0.3, 0.8}) {
    auto s = make_along_ray_scene<T>(noise, 7);
    // Every fourth static track lies in a box (a still chair), one of them displaced by 2.5 px.
    std::size_t displaced = s.points.size();
    for (std::size_t i = 0; i < s.points.size(); ++i) {
      if (s.moving[i] || i % 4 != 0) continue;
      s.in_box[i] = 1;
      if (displaced == s.points.size()) {
        displaced = i;
        s.pixels[i] = Vec2<T>(T(s.camera.project(s.cam_from_world.apply(s.points[i])).x() + T(2.5)),
                              s.camera.project(s.cam_from_world.apply(s.points[i])).y());
      }
    }
    const auto r = check_reprojection(s.points, s.pixels, s.camera, ReprojectionCheckOptions<T>{}, nullptr, s.in_box);
    ASSERT_TRUE(r.ok()) << r.reason;
    EXPECT_NEAR(double(r.inlier_noise_px), noise, 0.35 * noise) << noise;
    std::size_t still_in_box = 0, flagged = 0;
    for (std::size_t i = 0; i < s.points.size(); ++i) {
      if (s.moving[i] || !s.in_box[i] || i == displaced) continue;
      ++still_in_box;
      flagged += r.labels[i] == FeatureLabel::Dynamic;
    }
    ASSERT_GT(still_in_box, 50u);
    EXPECT_LT(double(flagged), 0.03 * double(still_in_box)) << noise << " px: " << flagged << " of " << still_in_box;
    // 2.5 px is motion against 0.3 px of noise (1.5 px limit), noise against 0.8 px (a 4 px limit).
    EXPECT_EQ(r.labels[displaced], noise < 0.5 ? FeatureLabel::Dynamic : FeatureLabel::Static) << noise;
  }
}

/// The along-ray scene's object moved instead along the *current* camera's rays (towards the camera, as a
/// walker heading for it): it projects where its reference point does, and only depth can tell. The depth
/// image (float metres) holds at each track's pixel the nearest track's current depth with the Kinect axial
/// noise sigma(z), 0 elsewhere; `occluded` marks the wall tracks the object hides (their pixel shows it).
template <class T>
struct TowardsCameraScene {
  AlongRayScene<T> base;
  std::vector<float> depth = std::vector<float>(640 * 480, 0.f);
  std::vector<std::uint8_t> occluded;
  DepthView<float> view() const { return DepthView<float>{depth.data(), 640, 480, 0, 1.f, 0.4f, 8.f}; }
};

template <class T>
TowardsCameraScene<T> make_towards_camera_scene(double approach_m) {
  TowardsCameraScene<T> s;
  s.base = make_along_ray_scene<T>(0.3, 5);
  const Rigid3<double> cw = s.base.cam_from_world.template cast<double>();
  const PinholeCamera<double> cam = PinholeCamera<double>::tum_fr3();
  Random rng(11);
  const std::size_t n = s.base.points.size();
  std::vector<double> true_z(640 * 480, 0.0);
  std::vector<std::size_t> pixel_of(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    Vec3<double> pc = cw.apply(s.base.points[i].template cast<double>());
    if (s.base.moving[i]) pc *= (pc.norm() - approach_m) / pc.norm();  // along the current ray
    const Vec2<double> px = cam.project(pc);
    s.base.pixels[i] = Vec2<T>(T(px.x() + 0.3 * rng.normal()), T(px.y() + 0.3 * rng.normal()));
    const int u = int(std::lround(double(s.base.pixels[i].x()))), v = int(std::lround(double(s.base.pixels[i].y())));
    pixel_of[i] = std::size_t(std::clamp(v, 0, 479)) * 640 + std::size_t(std::clamp(u, 0, 639));
    double& z = true_z[pixel_of[i]];
    if (z == 0.0 || pc.z() < z) z = pc.z();  // the nearest surface is what the sensor sees
  }
  for (std::size_t k = 0; k < true_z.size(); ++k)
    if (true_z[k] > 0) {
      const double sigma = 0.0012 + 0.0019 * (true_z[k] - 0.4) * (true_z[k] - 0.4);
      s.depth[k] = float(true_z[k] + sigma * rng.normal());
    }
  s.occluded.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3<double> pc = cw.apply(s.base.points[i].template cast<double>());
    s.occluded[i] = !s.base.moving[i] && true_z[pixel_of[i]] < pc.z() - 0.05;
  }
  return s;
}

// An object 2 m away coming 8 cm closer along the current rays (about 9 sigma of the depth difference at
// 2 m): the pixel residual sees noise only, the depth residual all of it; static tracks (depth noise of 1
// sigma) stay static at 5 sigma. Without a depth image, or with the option off, the labels are the pixel
// residual's.
TYPED_TEST(ReprojectionCheckTest, DepthResidualSeesMotionAlongTheViewingRay) {
  using T = TypeParam;
  const auto s = make_towards_camera_scene<T>(0.08);
  const auto& b = s.base;
  ReprojectionCheckOptions<T> o;
  const auto pixel_only = check_reprojection(b.points, b.pixels, b.camera, o, nullptr, b.in_box, s.view());
  ASSERT_TRUE(pixel_only.ok()) << pixel_only.reason;
  EXPECT_LT(flagged_rate<T>(pixel_only.labels, b.moving, true), 0.2);
  EXPECT_TRUE(std::isnan(double(pixel_only.depth_residual_m[0])));  // off: not evaluated
  o.max_depth_residual_sigmas = T(5);
  const auto with_depth = check_reprojection(b.points, b.pixels, b.camera, o, nullptr, b.in_box, s.view());
  ASSERT_TRUE(with_depth.ok()) << with_depth.reason;
  EXPECT_GT(flagged_rate<T>(with_depth.labels, b.moving, true), 0.95);
  EXPECT_EQ(with_depth.num_dynamic - pixel_only.num_dynamic, with_depth.num_depth_dynamic);
  double moving_dz = 0;
  std::size_t moving_n = 0, static_n = 0, static_flagged = 0, hidden = 0;
  for (std::size_t i = 0; i < b.points.size(); ++i) {
    const double dz = double(with_depth.depth_residual_m[i]);
    ASSERT_FALSE(std::isnan(dz)) << i;
    if (b.moving[i]) {
      moving_dz += dz;
      ++moving_n;
    } else if (s.occluded[i]) {
      ++hidden;  // a wall point behind the object: its pixel shows the object, and it is flagged
      EXPECT_EQ(with_depth.labels[i], FeatureLabel::Dynamic) << i;
    } else {
      ++static_n;
      static_flagged += with_depth.labels[i] == FeatureLabel::Dynamic;
      EXPECT_LT(std::abs(dz), 0.15) << i;  // 2-5 m walls: sigma up to 5 cm
    }
  }
  ASSERT_GT(moving_n, 50u);
  ASSERT_GT(static_n, 200u);
  EXPECT_LE(static_flagged, static_n / 50) << "hidden wall tracks: " << hidden;
  EXPECT_NEAR(moving_dz / double(moving_n), -0.08 * 0.99, 0.01);  // closer: measured < predicted
  // No depth image: the option has nothing to compare; a pixel without depth is not evaluated either.
  const auto no_depth = check_reprojection(b.points, b.pixels, b.camera, o, nullptr, b.in_box);
  EXPECT_EQ(no_depth.num_dynamic, pixel_only.num_dynamic);
  auto holes = s;
  std::fill(holes.depth.begin(), holes.depth.end(), 0.f);
  const auto none = check_reprojection(b.points, b.pixels, b.camera, o, nullptr, b.in_box, holes.view());
  EXPECT_EQ(none.num_dynamic, pixel_only.num_dynamic);
  EXPECT_EQ(none.num_depth_dynamic, 0u);
  o.max_depth_residual_sigmas = T(-1);
  EXPECT_EQ(check_reprojection(b.points, b.pixels, b.camera, o, nullptr, nullptr, s.view()).status, Status::InvalidInput);
}

TYPED_TEST(ReprojectionCheckTest, BadInputGetsAReason) {
  using T = TypeParam;
  auto s = make_along_ray_scene<T>();
  const ReprojectionCheckOptions<T> options;

  std::vector<Vec3<T>> short_points(s.points.begin(), s.points.begin() + 10);
  auto r = check_reprojection(short_points, s.pixels, s.camera, options);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_FALSE(r.reason.empty());
  EXPECT_EQ(r.labels.size(), s.pixels.size());
  for (FeatureLabel l : r.labels) EXPECT_EQ(l, FeatureLabel::Candidate);

  const std::vector<Vec3<T>> no_points;
  const std::vector<Vec2<T>> no_pixels;
  r = check_reprojection(no_points, no_pixels, s.camera, options);
  EXPECT_EQ(r.status, Status::Skipped);
  EXPECT_FALSE(r.reason.empty());
  EXPECT_TRUE(r.labels.empty());

  ReprojectionCheckOptions<T> bad = options;
  bad.max_residual_in_boxes_px = T(0);
  EXPECT_EQ(check_reprojection(s.points, s.pixels, s.camera, bad).status, Status::InvalidInput);
  PinholeCamera<T> no_camera;
  no_camera.fx = T(0);
  EXPECT_EQ(check_reprojection(s.points, s.pixels, no_camera, options).status, Status::InvalidInput);

  // Missing depth (NaN point), a NaN pixel and an invalid track: Candidate with a NaN residual; the rest
  // is still labelled.
  const T nan = std::numeric_limits<T>::quiet_NaN();
  s.points[0] = Vec3<T>(nan, nan, nan);
  s.pixels[1].x() = nan;
  std::vector<std::uint8_t> valid(s.points.size(), 1);
  valid[2] = 0;
  r = check_reprojection(s.points, s.pixels, s.camera, options, valid, s.in_box);
  ASSERT_TRUE(r.ok()) << r.reason;
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(r.labels[i], FeatureLabel::Candidate) << i;
    EXPECT_TRUE(std::isnan(double(r.residual_px[i]))) << i;
    EXPECT_FALSE(r.residual_vec[i].allFinite()) << i;
  }
  EXPECT_EQ(r.num_valid, s.points.size() - 3);
  EXPECT_EQ(r.num_dynamic + r.num_static, r.num_valid);

  // Too few points with depth: skipped, not guessed.
  std::vector<Vec3<T>> sparse(s.points.size(), Vec3<T>(nan, nan, nan));
  for (std::size_t i = 0; i < 10; ++i) sparse[i] = s.points[i + 3];
  r = check_reprojection(sparse, s.pixels, s.camera, options);
  EXPECT_EQ(r.status, Status::Skipped);
  EXPECT_NE(r.reason.find("3-D point"), std::string::npos) << r.reason;

  // Every track on one 3-D point (degenerate): no pose, a reason, every label Candidate.
  const std::vector<Vec3<T>> one_point(s.points.size(), Vec3<T>(T(0.1), T(0.2), T(3)));
  r = check_reprojection(one_point, s.pixels, s.camera, options);
  EXPECT_FALSE(r.ok());
  EXPECT_FALSE(r.reason.empty());
  EXPECT_TRUE(std::isnan(double(r.inlier_noise_px)));
  for (FeatureLabel l : r.labels) EXPECT_EQ(l, FeatureLabel::Candidate);
}

TEST(ReprojectionCheck, BuffersAreReusedAcrossFrames) {
  const auto s = make_along_ray_scene<double>();
  ReprojectionCheckResult<double> r;
  check_reprojection(s.points, s.pixels, s.camera, ReprojectionCheckOptions<double>{}, &r, nullptr, s.in_box);
  ASSERT_TRUE(r.ok()) << r.reason;
  const auto* labels = r.labels.data();
  const auto* scratch = r.scratch_points.data();
  const std::size_t dyn = r.num_dynamic;
  check_reprojection(s.points, s.pixels, s.camera, ReprojectionCheckOptions<double>{}, &r, nullptr, s.in_box);
  EXPECT_EQ(r.labels.data(), labels);
  EXPECT_EQ(r.scratch_points.data(), scratch);
  EXPECT_EQ(r.num_dynamic, dyn);
}

// Flags of another length than the tracks: InvalidInput naming them and both sizes, every track Candidate,
// and no flag read past the end (AddressSanitizer would report it).
TYPED_TEST(ReprojectionCheckTest, FlagsOfAnotherLengthAreInvalidInputAndNotRead) {
  using T = TypeParam;
  const auto s = make_along_ray_scene<T>();
  const std::size_t n = s.pixels.size();
  const std::vector<std::uint8_t> few(10, 1), all(n, 1);
  const ReprojectionCheckOptions<T> o;
  const auto short_valid = check_reprojection(s.points, s.pixels, s.camera, o, few, all);
  const auto short_in_box = check_reprojection(s.points, s.pixels, s.camera, o, all, few);
  EXPECT_EQ(short_valid.status, Status::InvalidInput);
  EXPECT_EQ(short_valid.reason, "valid has 10 entries for " + std::to_string(n) + " tracks");
  EXPECT_EQ(short_in_box.status, Status::InvalidInput);
  EXPECT_EQ(short_in_box.reason, "in_box has 10 entries for " + std::to_string(n) + " tracks");
  for (const auto* r : {&short_valid, &short_in_box}) {
    ASSERT_EQ(r->labels.size(), n);
    for (FeatureLabel l : r->labels) EXPECT_EQ(l, FeatureLabel::Candidate);
  }
  EXPECT_EQ(check_reprojection(s.points, s.pixels, s.camera, o, FlagView(nullptr, n)).status, Status::InvalidInput);
  EXPECT_TRUE(check_reprojection(s.points, s.pixels, s.camera, o, all, s.in_box).ok());
}

}  // namespace
}  // namespace dyncull
