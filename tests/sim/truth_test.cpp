// Keypoint truth lookup: nearest pixel of sub-pixel positions for any point type (float and
// double Eigen vectors, structs with x/y), and defined results outside the image.
#include "dyncull/sim/truth.hpp"

#include "dyncull/core/pixel.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace {

using namespace dyncull::sim;

FrameData tiny_frame() {
  FrameData f;
  f.width = 4;
  f.height = 3;
  f.instance.assign(12, 0);
  f.moving.assign(12, 0);
  f.depth_m.assign(12, 1.f);
  f.instance[1 * 4 + 2] = 5;  // pixel (u = 2, v = 1)
  f.moving[1 * 4 + 2] = 1;
  f.depth_m[1 * 4 + 2] = 2.5f;
  return f;
}

template <class T>
class SimTruthTyped : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(SimTruthTyped, Scalars, );  // trailing comma: clang -Wpedantic rejects an empty variadic

TYPED_TEST(SimTruthTyped, NearestPixelOfEigenPoints) {
  using V = dyncull::Vec2<TypeParam>;
  const FrameData f = tiny_frame();
  const std::vector<V> points = {V(TypeParam(2.4), TypeParam(0.6)), V(TypeParam(1.6), TypeParam(1.0)),
                                 V(TypeParam(-0.6), TypeParam(0)), V(TypeParam(3.49), TypeParam(2.49)),
                                 V(std::numeric_limits<TypeParam>::quiet_NaN(), TypeParam(1))};
  std::vector<std::uint8_t> moving;
  std::vector<std::uint16_t> instance;
  EXPECT_EQ(truth_at_points(f, points, &moving, &instance), 3u);
  EXPECT_EQ(moving, (std::vector<std::uint8_t>{1, 1, 0, 0, 0}));  // (1.6, 1.0) rounds to (2, 1)
  EXPECT_EQ(instance, (std::vector<std::uint16_t>{5, 5, 0, 0, 0}));
}

struct Keypoint {
  float x, y;
};

TEST(SimTruth, SinglePointAndStructPoints) {
  const FrameData f = tiny_frame();
  const PointTruth t = truth_at(f, 2.2, 1.3);
  EXPECT_TRUE(t.inside);
  EXPECT_EQ(t.moving, 1);
  EXPECT_EQ(t.instance, 5);
  EXPECT_FLOAT_EQ(t.depth_m, 2.5f);
  EXPECT_FALSE(truth_at(f, 4.6, 0).inside);
  EXPECT_FALSE(truth_at(f, 0, -0.51).inside);
  EXPECT_TRUE(truth_at(f, 0, -0.49).inside);
  const std::vector<Keypoint> kps = {{2.f, 1.f}, {0.f, 0.f}};
  std::vector<std::uint8_t> moving;
  EXPECT_EQ(truth_at_points(f, kps, &moving), 2u);
  EXPECT_EQ(moving, (std::vector<std::uint8_t>{1, 0}));
  const FrameData empty;
  EXPECT_EQ(truth_at_points(empty, kps, &moving), 0u);  // no buffers: everything outside
  EXPECT_EQ(moving, (std::vector<std::uint8_t>{0, 0}));
}

TEST(SimTruth, AgreesWithARenderedFrame) {
  SceneOptions o;
  o.width = 160;
  o.height = 120;
  o.num_frames = 1;
  const Scene scene(o);
  FrameData f;
  scene.render(0, &f);
  std::vector<dyncull::Vec2<double>> points;
  for (int v = 0; v < f.height; v += 3)
    for (int u = 0; u < f.width; u += 3) points.emplace_back(u + 0.3, v - 0.2);
  std::vector<std::uint8_t> moving;
  std::vector<std::uint16_t> instance;
  truth_at_points(f, points, &moving, &instance);
  std::size_t k = 0, moving_count = 0;
  for (int v = 0; v < f.height; v += 3) {
    for (int u = 0; u < f.width; u += 3, ++k) {
      const std::size_t i = static_cast<std::size_t>(v * f.width + u);
      EXPECT_EQ(moving[k], f.moving[i]);
      EXPECT_EQ(instance[k], f.instance[i]);
      moving_count += moving[k];
    }
  }
  EXPECT_GT(moving_count, 0u);
}


TEST(SimTruth, CoordinatesBeyondTheIntRangeOrNonFiniteAreOutside) {
  const FrameData f = tiny_frame();
  const double inf = std::numeric_limits<double>::infinity();
  // 2^32 + 2 and 2^64 + 2 wrap to pixel 2 in a 32- or 64-bit integer; 1e300 overflows every integer.
  for (double big : {4294967298.0, 18446744073709551618.0, 9.3e18, -9.3e18, 1e300, -1e300, inf, -inf,
                     std::numeric_limits<double>::quiet_NaN()}) {
    EXPECT_FALSE(truth_at(f, big, 1.0).inside) << big;
    EXPECT_FALSE(truth_at(f, 2.0, big).inside) << big;
  }
  // Rounding half away from zero, the same rule as pixel_of: -0.5 is pixel -1, 3.5 is pixel 4.
  EXPECT_FALSE(truth_at(f, -0.5, 1.0).inside);
  EXPECT_TRUE(truth_at(f, -0.49, 1.0).inside);
  EXPECT_FALSE(truth_at(f, 3.5, 1.0).inside);
  EXPECT_FALSE(truth_at(f, 1.0, 2.5).inside);
  for (double x = -1.5; x <= 4.5; x += 0.25)
    for (double y = -1.5; y <= 3.5; y += 0.25) {
      int u = -1, v = -1;
      const bool in = dyncull::pixel_of(x, y, f.width, f.height, &u, &v);
      const PointTruth t = truth_at(f, x, y);
      ASSERT_EQ(t.inside, in) << x << ", " << y;
      if (in) {
        EXPECT_EQ(t.instance, f.instance[static_cast<std::size_t>(v * f.width + u)]);
      }
    }
}

TEST(SimTruth, FrameWithShortBuffersOrBadSizeReadsNothing) {
  FrameData f = tiny_frame();
  f.depth_m.resize(5);  // shorter than width * height: pixels past it are not read
  EXPECT_TRUE(truth_at(f, 0.0, 1.0).inside);
  EXPECT_FALSE(truth_at(f, 2.0, 2.0).inside);
  FrameData g = tiny_frame();
  g.width = -4;
  EXPECT_FALSE(truth_at(g, 0.0, 0.0).inside);
}

}  // namespace
