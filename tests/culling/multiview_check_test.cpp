// Tests of the multi-view depth check (RTD-SLAM, Gao et al. 2024, §III.A) on ray-cast scenes with known motion.
#include "dyncull/culling/multiview_check.hpp"

#include "support/culling_scenes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

namespace dyncull {
namespace {

using test::SceneConfig;
using test::SceneKind;
using test::SceneWorld;

template <class T>
class MultiViewTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(MultiViewTest, Scalars, );  // trailing comma: clang -Wpedantic rejects an empty variadic

// Keyframe 8 frames back: the walking person has moved 0.32 m, the chair 0.24 m sideways.
constexpr int kFramesBack = 8;

TYPED_TEST(MultiViewTest, FlagsSurfacesThatMovedInFrontOfTheKeyframeView) {
  using T = TypeParam;
  SceneConfig config;
  const SceneWorld world(config);
  const auto scene = test::make_culling_scene<T>(config);
  const auto kf = test::make_scene_keyframe<T>(config, kFramesBack, 1500);
  const auto r = check_multiview(kf.keypoints, kf.depth_m, kf.cam_from_world, scene.cam_from_world,
                                 scene.depth_view(), scene.camera, MultiViewOptions<T>{});
  ASSERT_TRUE(r.ok()) << r.reason;
  ASSERT_EQ(r.labels.size(), kf.keypoints.size());
  // Truth at x': which surface the current frame shows there, and whether the remembered surface is
  // really more than tau_d behind it (then the keyframe point is now occluded by something that moved).
  std::size_t tp = 0, fp = 0, fn = 0, static_occlusion = 0;
  for (std::size_t i = 0; i < r.labels.size(); ++i) {
    if (r.outcome[i] != MultiViewOutcome::Checked) continue;
    Vec3<double> X;
    double d = 0;
    int part = -1;
    ASSERT_TRUE(world.raycast(0.0, double(r.projected[i].x()), double(r.projected[i].y()), &X, &d, &part));
    const bool on_mover = part >= 0 && world.parts()[static_cast<std::size_t>(part)].moving();
    // The window search (radius 2) may find the remembered surface itself beside a mover's edge:
    // a miss counts only when x' is at least 3 px inside the mover.
    bool inside = on_mover;
    for (int k = 0; k < 4 && inside; ++k) {
      Vec3<double> Xk;
      double dk = 0;
      int pk = -1;
      const double du = (k == 0) ? 3 : (k == 1 ? -3 : 0), dv = (k == 2) ? 3 : (k == 3 ? -3 : 0);
      inside = world.raycast(0.0, double(r.projected[i].x()) + du, double(r.projected[i].y()) + dv, &Xk, &dk, &pk) &&
               pk >= 0 && world.parts()[static_cast<std::size_t>(pk)].moving();
    }
    const bool occluded_by_mover = inside && double(r.projected_depth_m[i]) - d > 0.6;
    const bool flagged = r.labels[i] == FeatureLabel::Dynamic;
    // A static surface in front of the remembered one (furniture edges after 15 cm of camera motion)
    // is flagged too: the method cannot tell occlusion by a static object from motion below 30 deg of
    // parallax. Those flags are counted apart; a flag where the remembered surface is visible is an error.
    const bool visible = std::abs(double(r.projected_depth_m[i]) - d) < 0.1;
    tp += flagged && on_mover;
    fp += flagged && !on_mover && visible;
    static_occlusion += flagged && !on_mover && !visible;
    fn += !flagged && occluded_by_mover;
  }
  // Visible static surfaces project onto themselves up to the window search and rounding: a flag there
  // can only come from a depth edge within 2 px. Allow at most 3 % of the flags.
  EXPECT_GT(tp, 20u);
  EXPECT_LE(double(fp), 0.03 * double(tp + fp)) << "tp " << tp << " fp " << fp;
  // Static occlusions exist in this scene (desk, bookcase, cabinet edges) but stay a minority of flags.
  EXPECT_LT(static_occlusion, tp) << "static occlusion flags " << static_occlusion;
  // Points clearly (> 0.6 m) occluded by a mover, away from its edges, must all be caught.
  EXPECT_EQ(fn, 0u) << "tp " << tp << " fn " << fn;
  EXPECT_EQ(r.num_dynamic, tp + fp + static_occlusion);
}

TYPED_TEST(MultiViewTest, RegionGrowingLabelsCurrentFeaturesOnTheWalkingPerson) {
  using T = TypeParam;
  SceneConfig config;
  config.sitting = false;  // the sitting person's lean is too small for a 0.4 m depth test
  const auto scene = test::make_culling_scene<T>(config);
  const auto kf = test::make_scene_keyframe<T>(config, kFramesBack, 1500);
  MultiViewOptions<T> options;
  const auto r = check_multiview(kf.keypoints, kf.depth_m, kf.cam_from_world, scene.cam_from_world,
                                 scene.depth_view(), scene.camera, options);
  ASSERT_TRUE(r.ok()) << r.reason;
  Mask mask;
  std::vector<std::uint32_t> stack;
  const std::size_t pixels = grow_multiview_regions(r, scene.depth_view(), &mask, &stack);
  EXPECT_GT(pixels, 1000u);
  std::vector<std::uint8_t> predicted(scene.size());
  for (std::size_t i = 0; i < scene.size(); ++i)
    predicted[i] = mask.test(int(std::lround(double(scene.keypoints[i].x()))), int(std::lround(double(scene.keypoints[i].y()))));
  const auto pr = test::precision_recall(predicted, scene.truth_dynamic, scene.size());
  // Region growing leaks into the floor where the feet touch it (same depth), so precision is
  // bounded by that band; recall covers both movers' visible faces.
  EXPECT_GE(pr.precision, 0.8) << "tp " << pr.tp << " fp " << pr.fp;
  EXPECT_GE(pr.recall, 0.85) << "tp " << pr.tp << " fn " << pr.fn;
}

TYPED_TEST(MultiViewTest, ScanlineRegionGrowingMatchesPixelwiseFloodFill) {
  using T = TypeParam;
  SceneConfig config;
  const auto scene = test::make_culling_scene<T>(config);
  const auto kf = test::make_scene_keyframe<T>(config, kFramesBack, 800);
  MultiViewOptions<T> options;
  const auto r = check_multiview(kf.keypoints, kf.depth_m, kf.cam_from_world, scene.cam_from_world,
                                 scene.depth_view(), scene.camera, options);
  ASSERT_GT(r.num_dynamic, 0u);
  Mask fast;
  std::vector<std::uint32_t> stack;
  const std::size_t n_fast = grow_multiview_regions(r, scene.depth_view(), &fast, &stack);
  // Oracle: plain 4-neighbour breadth-first fill with the documented joining rule.
  const int W = scene.width, H = scene.height;
  Mask ref(W, H);
  std::size_t n_ref = 0;
  for (std::size_t i = 0; i < r.labels.size(); ++i) {
    if (r.labels[i] != FeatureLabel::Dynamic) continue;
    const int su = int(std::lround(double(r.projected[i].x()))), sv = int(std::lround(double(r.projected[i].y())));
    if (ref.test(su, sv)) continue;
    const double seed = double(r.measured_depth_m[i]);
    std::vector<std::pair<int, int>> queue{{su, sv}};
    ref.pixels[static_cast<std::size_t>(sv * W + su)] = 1;
    ++n_ref;
    for (std::size_t q = 0; q < queue.size(); ++q) {
      const int x = queue[q].first, y = queue[q].second;
      const int nx[4] = {x - 1, x + 1, x, x}, ny[4] = {y, y, y - 1, y + 1};
      for (int k = 0; k < 4; ++k) {
        if (nx[k] < 0 || ny[k] < 0 || nx[k] >= W || ny[k] >= H || ref.test(nx[k], ny[k])) continue;
        const double d = double(scene.depth[static_cast<std::size_t>(ny[k] * W + nx[k])]);
        if (!(d > 0) || std::abs(d - seed) > double(T(MultiViewOptions<T>::kRegionDepthToleranceM))) continue;
        ref.pixels[static_cast<std::size_t>(ny[k] * W + nx[k])] = 1;
        ++n_ref;
        queue.emplace_back(nx[k], ny[k]);
      }
    }
  }
  // Equal up to pixels exactly at the tolerance (float rounding of the raw-unit bounds).
  std::size_t differ = 0;
  for (std::size_t i = 0; i < ref.pixels.size(); ++i) differ += (ref.pixels[i] != 0) != (fast.pixels[i] != 0);
  EXPECT_LE(differ, n_ref / 1000) << "fast " << n_fast << " ref " << n_ref;
  EXPECT_EQ(n_fast, fast.count());
}

// The integer fast path (TUM uint16, bounds rounded inwards to raw units) against a breadth-first fill
// that converts every raw value to metres: exactly the same pixels.
TYPED_TEST(MultiViewTest, Uint16RegionGrowingMatchesPixelwiseFloodFill) {
  using T = TypeParam;
  SceneConfig config;
  const auto scene = test::make_culling_scene<T>(config);
  const auto kf = test::make_scene_keyframe<T>(config, kFramesBack, 800);
  const auto raw = scene.depth_tum();
  const auto view = tum_depth_view(raw.data(), scene.width, scene.height);
  MultiViewOptions<T> options;
  const auto r = check_multiview(kf.keypoints, kf.depth_m, kf.cam_from_world, scene.cam_from_world, view,
                                 scene.camera, options);
  ASSERT_GT(r.num_dynamic, 0u);
  Mask fast;
  std::vector<std::uint32_t> stack;
  const std::size_t n_fast = grow_multiview_regions(r, view, &fast, &stack);
  const int W = scene.width, H = scene.height;
  Mask ref(W, H);
  for (std::size_t i = 0; i < r.labels.size(); ++i) {
    if (r.labels[i] != FeatureLabel::Dynamic) continue;
    const int su = int(std::lround(double(r.projected[i].x()))), sv = int(std::lround(double(r.projected[i].y())));
    if (ref.test(su, sv)) continue;
    const double seed = double(r.measured_depth_m[i]);
    const double tol = double(T(MultiViewOptions<T>::kRegionDepthToleranceM));
    std::vector<std::pair<int, int>> queue{{su, sv}};
    ref.pixels[static_cast<std::size_t>(sv * W + su)] = 1;
    for (std::size_t q = 0; q < queue.size(); ++q) {
      const int x = queue[q].first, y = queue[q].second;
      const int nx[4] = {x - 1, x + 1, x, x}, ny[4] = {y, y, y - 1, y + 1};
      for (int k = 0; k < 4; ++k) {
        if (nx[k] < 0 || ny[k] < 0 || nx[k] >= W || ny[k] >= H || ref.test(nx[k], ny[k])) continue;
        const double units = double(raw[static_cast<std::size_t>(ny[k] * W + nx[k])]);
        // Same joining rule in metres: lo <= d <= hi, with the bounds in raw units as the header defines.
        if (!(units > 0) || units < std::max(seed - tol, 1e-9) * 5000.0 || units > (seed + tol) * 5000.0) continue;
        ref.pixels[static_cast<std::size_t>(ny[k] * W + nx[k])] = 1;
        queue.emplace_back(nx[k], ny[k]);
      }
    }
  }
  EXPECT_EQ(fast.pixels, ref.pixels) << "fast " << n_fast << " ref " << ref.count();
  EXPECT_EQ(n_fast, fast.count());
}

TYPED_TEST(MultiViewTest, Uint16TumDepthGivesTheSameLabels) {
  using T = TypeParam;
  SceneConfig config;
  const auto scene = test::make_culling_scene<T>(config);
  const auto kf = test::make_scene_keyframe<T>(config, kFramesBack, 600);
  const auto raw = scene.depth_tum();
  const auto a = check_multiview(kf.keypoints, kf.depth_m, kf.cam_from_world, scene.cam_from_world,
                                 scene.depth_view(), scene.camera, MultiViewOptions<T>{});
  const auto b = check_multiview(kf.keypoints, kf.depth_m, kf.cam_from_world, scene.cam_from_world,
                                 tum_depth_view(raw.data(), scene.width, scene.height), scene.camera,
                                 MultiViewOptions<T>{});
  ASSERT_TRUE(a.ok() && b.ok());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < a.labels.size(); ++i) differ += a.labels[i] != b.labels[i];
  // 0.2 mm quantisation can flip only points within 0.2 mm of the threshold: none expected.
  EXPECT_LE(differ, 1u);
  EXPECT_EQ(a.num_checked, b.num_checked);
}

TYPED_TEST(MultiViewTest, ReportsSkippedWithoutKeyframeOrPose) {
  using T = TypeParam;
  const auto scene = test::make_culling_scene<T>(SceneConfig{});
  const std::vector<Vec2<T>> none;
  const std::vector<T> no_depth;
  const auto r = check_multiview(none, no_depth, scene.cam_from_world, scene.cam_from_world, scene.depth_view(),
                                 scene.camera, MultiViewOptions<T>{});
  EXPECT_EQ(r.status, Status::Skipped);
  EXPECT_FALSE(r.reason.empty());

  const std::vector<Vec2<T>> pts{Vec2<T>(100, 100)};
  const std::vector<T> d{T(2)};
  Rigid3<T> lost = scene.cam_from_world;
  lost.t.x() = Constants<T>::nan();
  const auto s = check_multiview(pts, d, scene.cam_from_world, lost, scene.depth_view(), scene.camera,
                                 MultiViewOptions<T>{});
  EXPECT_EQ(s.status, Status::Skipped);
  EXPECT_NE(s.reason.find("pose"), std::string::npos);
  EXPECT_EQ(s.labels.size(), 1u);
  EXPECT_EQ(s.labels[0], FeatureLabel::Candidate);

  const auto e = check_multiview(pts, d, scene.cam_from_world, scene.cam_from_world, DepthView<float>{},
                                 scene.camera, MultiViewOptions<T>{});
  EXPECT_EQ(e.status, Status::Skipped);
}

TYPED_TEST(MultiViewTest, SkipsLargeParallaxMissingDepthAndNonFinite) {
  using T = TypeParam;
  PinholeCamera<T> cam;
  // Current frame: a flat wall at 1 m (so every projection finds depth).
  std::vector<float> wall(static_cast<std::size_t>(cam.width * cam.height), 1.f);
  const DepthView<float> depth{wall.data(), cam.width, cam.height};
  Rigid3<T> ref, cur;
  // Camera moved 1 m sideways and turned 45 deg back towards the point at (0, 0, 1): rays differ by 45 deg.
  cur.R = Eigen::AngleAxis<T>(T(0.25) * Constants<T>::pi(), Vec3<T>::UnitY()).toRotationMatrix();
  cur.t = -(cur.R * Vec3<T>(T(1), T(0), T(0)));
  const std::vector<Vec2<T>> pts{Vec2<T>(cam.cx, cam.cy), Vec2<T>(cam.cx, cam.cy), Vec2<T>(Constants<T>::nan(), T(3))};
  const std::vector<T> d{T(1), T(0), T(1)};
  const auto r = check_multiview(pts, d, ref, cur, depth, cam, MultiViewOptions<T>{});
  EXPECT_EQ(r.outcome[0], MultiViewOutcome::LargeParallax);
  EXPECT_EQ(r.outcome[1], MultiViewOutcome::NoReferenceDepth);
  EXPECT_EQ(r.outcome[2], MultiViewOutcome::NonFinite);
  EXPECT_EQ(r.num_large_parallax, 1u);
  EXPECT_EQ(r.status, Status::TooFewPoints);
  for (auto l : r.labels) EXPECT_EQ(l, FeatureLabel::Candidate);

  // With a 60 deg limit the same point is compared: it projects to the image centre at depth sqrt(2) and
  // the wall at 1 m is in front of it, so it is dynamic only if that gap exceeds tau_d.
  MultiViewOptions<T> wide;
  wide.max_parallax_deg = T(60);
  const auto w = check_multiview(pts, d, ref, cur, depth, cam, wide);
  EXPECT_EQ(w.outcome[0], MultiViewOutcome::Checked);
  EXPECT_NEAR(double(w.projected_depth_m[0]), std::sqrt(2.0), 1e-4);
  EXPECT_EQ(w.labels[0], FeatureLabel::Dynamic);  // sqrt(2) - 1 = 0.414 > 0.4
}

TYPED_TEST(MultiViewTest, KeyframeRingKeepsNewestAndSelectsLargestMotionFirst) {
  using T = TypeParam;
  KeyframeRing<T> ring(5);
  EXPECT_TRUE(ring.empty());
  const std::vector<Vec2<T>> pts{Vec2<T>(1, 2), Vec2<T>(3, 4), Vec2<T>(5, 6)};
  const std::vector<T> depth{T(1), T(0), T(2)};  // the middle one has no depth: not stored
  for (int k = 0; k < 8; ++k) {
    Rigid3<T> pose;
    pose.t = Vec3<T>(T(0.1) * T(k), T(0), T(0));
    ring.push(pose, pts, depth);
  }
  EXPECT_EQ(ring.size(), 5u);
  EXPECT_NEAR(double(ring[0].cam_from_world.t.x()), 0.7, 1e-6);  // newest
  EXPECT_NEAR(double(ring[4].cam_from_world.t.x()), 0.3, 1e-6);  // oldest kept
  EXPECT_EQ(ring[0].points.size(), 2u);
  // A keep mask of another length than the points is refused before a flag is read; one that fits selects.
  const std::vector<std::uint8_t> short_keep(1, 1), keep{0, 1, 1};
  EXPECT_EQ(ring.push(Rigid3<T>{}, pts, depth, short_keep), Status::InvalidInput);
  EXPECT_NEAR(double(ring[0].cam_from_world.t.x()), 0.7, 1e-6) << "nothing stored";
  KeyframeRing<T> kept(2);
  ASSERT_EQ(kept.push(Rigid3<T>{}, pts, depth, keep), Status::Ok);
  EXPECT_EQ(kept[0].points.size(), 1u);
  std::size_t idx[3];
  Rigid3<T> cur;
  cur.t = Vec3<T>(T(0.8), T(0), T(0));
  ASSERT_EQ(ring.select_references(cur, 3, idx), 3u);
  EXPECT_EQ(idx[0], 4u);  // 0.5 m away
  EXPECT_EQ(idx[1], 3u);
  EXPECT_EQ(idx[2], 2u);
}

}  // namespace
}  // namespace dyncull
