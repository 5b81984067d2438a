// Keypoint and projection coordinates beyond the int range (x = 2^32 + 10) must not wrap back into
// the image: every stage that reads a pixel at a user coordinate maps it through pixel_of first.
// The images here are filled everywhere, so a wrapped read anywhere would be seen.
#include "dyncull/culling/depth_mask.hpp"
#include "dyncull/culling/multiview_check.hpp"
#include "dyncull/culling/pipeline.hpp"
#include "dyncull/culling/reprojection_check.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

namespace dyncull {
namespace {

template <class T>
class PixelCoordinates : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(PixelCoordinates, Scalars, );

// 2^32 + 10: std::lround then a cast to int gives pixel 10 (double) or 0 (float, which rounds it to 2^32).
template <class T>
T beyond_int() {
  return T(4294967306.0);
}

TYPED_TEST(PixelCoordinates, PipelineKeypointBeyondTheIntRangeIsNotInTheImage) {
  using T = TypeParam;
  const std::vector<Vec2<T>> kp = {Vec2<T>(beyond_int<T>(), T(10)), Vec2<T>(T(10), beyond_int<T>()),
                                   Vec2<T>(-beyond_int<T>(), T(10)), Vec2<T>(T(10.4), T(20.6))};
  for (std::size_t i = 0; i < 3; ++i) {
    int u = -1, v = -1;
    EXPECT_FALSE(detail::keypoint_in_image<T>(kp, i, 640, 480, &u, &v)) << "keypoint " << i << " read (" << u << ", " << v << ")";
  }
  int u = -1, v = -1;
  ASSERT_TRUE(detail::keypoint_in_image<T>(kp, 3, 640, 480, &u, &v));
  EXPECT_EQ(u, 10);
  EXPECT_EQ(v, 21);
}

TYPED_TEST(PixelCoordinates, ReprojectionDepthResidualIsNotReadAtAWrappedPixel) {
  using T = TypeParam;
  const PinholeCamera<T> camera;
  std::vector<Vec3<T>> points;
  std::vector<Vec2<T>> pixels;
  for (int j = 0; j < 6; ++j) {
    for (int i = 0; i < 6; ++i) {
      const Vec3<T> X(T(-1) + T(0.4) * T(i), T(-0.8) + T(0.3) * T(j), T(2) + T(0.1) * T((i + j) % 4));
      points.push_back(X);
      pixels.push_back(camera.project(X));
    }
  }
  const std::size_t bad = points.size();
  points.push_back(Vec3<T>(T(0), T(0), T(2)));
  pixels.push_back(Vec2<T>(beyond_int<T>(), T(240)));
  std::vector<float> depth_m(640 * 480, 1.f);  // a measurement at every pixel
  const DepthView<float> depth{depth_m.data(), 640, 480};
  ReprojectionCheckOptions<T> options;
  options.max_depth_residual_sigmas = T(3);
  const auto r = check_reprojection(points, pixels, camera, options, nullptr, nullptr, depth);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_TRUE(std::isnan(r.depth_residual_m[bad])) << r.depth_residual_m[bad];
  EXPECT_EQ(r.labels[bad], FeatureLabel::Dynamic);  // by its pixel residual
  EXPECT_FALSE(std::isnan(r.depth_residual_m[0]));  // an ordinary track does read its depth
}

TYPED_TEST(PixelCoordinates, MultiViewProjectionBeyondTheIntRangeHasNoMeasuredDepth) {
  using T = TypeParam;
  const PinholeCamera<T> camera;
  std::vector<float> depth_m(640 * 480, 0.5f);  // something nearer than every keyframe point
  const DepthView<float> depth{depth_m.data(), 640, 480};
  const std::vector<Vec2<T>> ref = {Vec2<T>(beyond_int<T>(), T(10)), Vec2<T>(T(10), T(10))};
  const std::vector<T> ref_depth = {T(1), T(1)};
  MultiViewOptions<T> options;
  options.border_px = T(-1e10);  // lets the projection past the camera's own bounds test
  MultiViewResult<T> r;
  check_multiview(ref, ref_depth, Rigid3<T>(), Rigid3<T>(), depth, camera, options, &r);
  if (r.ok()) {
    EXPECT_NE(r.outcome[0], MultiViewOutcome::Checked);
    EXPECT_EQ(r.measured_depth_m[0], T(0));
    EXPECT_NE(r.labels[0], FeatureLabel::Dynamic);
    EXPECT_EQ(r.outcome[1], MultiViewOutcome::Checked);
    EXPECT_EQ(r.labels[1], FeatureLabel::Dynamic);
  } else {
    EXPECT_EQ(r.status, Status::InvalidInput) << r.reason;  // a negative border may be refused instead
  }
}

TYPED_TEST(PixelCoordinates, MultiViewRegionIsNotSeededAtAWrappedPixel) {
  using T = TypeParam;
  std::vector<float> depth_m(640 * 480, 1.f);
  const DepthView<float> depth{depth_m.data(), 640, 480};
  MultiViewResult<T> result;
  result.labels = {FeatureLabel::Dynamic, FeatureLabel::Dynamic};
  result.outcome = {MultiViewOutcome::Checked, MultiViewOutcome::Checked};
  result.projected = {Vec2<T>(beyond_int<T>(), T(10)), Vec2<T>(T(10), -beyond_int<T>())};
  result.projected_depth_m = {T(1), T(1)};
  result.measured_depth_m = {T(1), T(1)};
  Mask mask;
  std::vector<std::uint32_t> stack;
  EXPECT_EQ(grow_multiview_regions(result, depth, &mask, &stack), 0u);
  EXPECT_EQ(mask.count(), 0u);
}

TYPED_TEST(PixelCoordinates, DepthMaskPointBeyondTheIntRangeIsOutsideEveryBox) {
  using T = TypeParam;
  std::vector<float> depth_m(640 * 480, 1.f);
  const DepthView<float> depth{depth_m.data(), 640, 480};
  const std::vector<Box<T>> boxes = {Box<T>{T(0), T(0), T(639), T(479)}};
  const std::vector<Vec2<T>> pts = {Vec2<T>(beyond_int<T>(), T(10)), Vec2<T>(T(10), T(1e30)), Vec2<T>(T(10), T(10))};
  const DepthMaskResult r = depth_mask(depth, boxes, pts, DepthMaskOptions{});
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.labels[0], FeatureLabel::Static);
  EXPECT_EQ(r.box_index[0], -1);
  EXPECT_EQ(r.labels[1], FeatureLabel::Static);
  EXPECT_EQ(r.box_index[1], -1);
  EXPECT_EQ(r.box_index[2], 0);  // the ordinary point is in the box
  EXPECT_EQ(r.num_in_boxes, 1u);
}

}  // namespace
}  // namespace dyncull
