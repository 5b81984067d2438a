// Tests of core/box.hpp: pixel_rect clipping (inside, partly and fully outside, inverted, NaN), IoU,
// padding, clipping and the small accessors.
#include "dyncull/core/box.hpp"

#include <gtest/gtest.h>

#include <limits>

namespace {

template <class T>
class BoxTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(BoxTest, Scalars, );

TYPED_TEST(BoxTest, PixelRectInsideUsesPixelCentres) {
  using T = TypeParam;
  // Columns whose centre u satisfies 10.2 <= u <= 20.7: 11..20; rows 5..8 inclusive.
  const dyncull::Box<T> b{T(10.2), T(5), T(20.7), T(8)};
  const auto r = dyncull::pixel_rect(b, 640, 480);
  EXPECT_EQ(r.c0, 11);
  EXPECT_EQ(r.c1, 21);
  EXPECT_EQ(r.r0, 5);
  EXPECT_EQ(r.r1, 9);
  EXPECT_EQ(r.width(), 10);
  EXPECT_EQ(r.height(), 4);
  EXPECT_EQ(r.area(), 40);
  EXPECT_FALSE(r.empty());
}

TYPED_TEST(BoxTest, PixelRectClipsAndEmpties) {
  using T = TypeParam;
  // Partly outside on the top-left and bottom-right.
  const auto r1 = dyncull::pixel_rect(dyncull::Box<T>{T(-50), T(-3), T(10), T(600)}, 640, 480);
  EXPECT_EQ(r1.c0, 0);
  EXPECT_EQ(r1.r0, 0);
  EXPECT_EQ(r1.c1, 11);
  EXPECT_EQ(r1.r1, 480);
  // Covering the whole image and more.
  const auto all = dyncull::pixel_rect(dyncull::Box<T>{T(-1e6), T(-1e6), T(1e6), T(1e6)}, 640, 480);
  EXPECT_EQ(all.area(), 640 * 480);
  // Fully outside: right of, below, left of the image.
  EXPECT_TRUE(dyncull::pixel_rect(dyncull::Box<T>{T(700), T(10), T(800), T(20)}, 640, 480).empty());
  EXPECT_TRUE(dyncull::pixel_rect(dyncull::Box<T>{T(10), T(500), T(20), T(600)}, 640, 480).empty());
  EXPECT_TRUE(dyncull::pixel_rect(dyncull::Box<T>{T(-30), T(10), T(-1), T(20)}, 640, 480).empty());
  EXPECT_EQ(dyncull::pixel_rect(dyncull::Box<T>{T(-30), T(10), T(-1), T(20)}, 640, 480).area(), 0);
  // Inverted, NaN and infinite boxes are empty, never garbage.
  EXPECT_TRUE(dyncull::pixel_rect(dyncull::Box<T>{T(20), T(10), T(10), T(20)}, 640, 480).empty());
  const T nan = std::numeric_limits<T>::quiet_NaN();
  EXPECT_TRUE(dyncull::pixel_rect(dyncull::Box<T>{nan, T(10), T(20), T(20)}, 640, 480).empty());
  EXPECT_TRUE(dyncull::pixel_rect(dyncull::Box<T>{T(0), T(0), std::numeric_limits<T>::infinity(), T(20)}, 640, 480).empty());
  // A sliver between two pixel centres holds no pixel.
  EXPECT_TRUE(dyncull::pixel_rect(dyncull::Box<T>{T(10.2), T(10.2), T(10.8), T(10.8)}, 640, 480).empty());
  // Zero-size image.
  EXPECT_TRUE(dyncull::pixel_rect(dyncull::Box<T>{T(0), T(0), T(5), T(5)}, 0, 0).empty());
}

TYPED_TEST(BoxTest, IntersectionOverUnion) {
  using T = TypeParam;
  const dyncull::Box<T> a{T(0), T(0), T(10), T(10)};
  EXPECT_NEAR(dyncull::iou(a, a), T(1), T(1e-6));
  EXPECT_EQ(dyncull::iou(a, dyncull::Box<T>{T(20), T(20), T(30), T(30)}), T(0));
  // Half overlap: intersection 50, union 150.
  EXPECT_NEAR(dyncull::iou(a, dyncull::Box<T>{T(5), T(0), T(15), T(10)}), T(1) / T(3), T(1e-6));
  // Contained: 25 / 100.
  EXPECT_NEAR(dyncull::iou(a, dyncull::Box<T>{T(2), T(2), T(7), T(7)}), T(0.25), T(1e-6));
  EXPECT_EQ(dyncull::iou(dyncull::Box<T>{}, dyncull::Box<T>{}), T(0));  // empty boxes: 0, not NaN
  EXPECT_EQ(dyncull::iou(a, dyncull::Box<T>{T(10), T(0), T(20), T(10)}), T(0));  // touching edge
  EXPECT_NEAR(dyncull::iou(a, dyncull::Box<T>{T(5), T(0), T(15), T(10)}),
              dyncull::iou(dyncull::Box<T>{T(5), T(0), T(15), T(10)}, a), T(1e-7));
}

TYPED_TEST(BoxTest, PaddedClippedAndAccessors) {
  using T = TypeParam;
  const dyncull::Box<T> b{T(10), T(20), T(30), T(60)};
  EXPECT_EQ(b.width(), T(20));
  EXPECT_EQ(b.height(), T(40));
  EXPECT_EQ(b.area(), T(800));
  EXPECT_EQ(b.centre(), dyncull::Vec2<T>(T(20), T(40)));
  EXPECT_TRUE(b.contains(T(10), T(60)));
  EXPECT_FALSE(b.contains(T(9.9), T(30)));
  EXPECT_TRUE(b.valid());
  const auto p = b.padded(T(5));
  EXPECT_EQ(p.x0, T(5));
  EXPECT_EQ(p.y1, T(65));
  const auto shrunk = b.padded(T(-15));  // shrinks past empty: width -10
  EXPECT_FALSE(shrunk.valid());
  EXPECT_EQ(shrunk.area(), T(0));
  const auto c = dyncull::Box<T>{T(-5), T(-5), T(700), T(100)}.clipped(640, 480);
  EXPECT_EQ(c.x0, T(0));
  EXPECT_EQ(c.y0, T(0));
  EXPECT_EQ(c.x1, T(639));
  EXPECT_EQ(c.y1, T(100));
  const auto d = b.template cast<double>();
  EXPECT_EQ(d.x1, 30.0);
  EXPECT_FALSE((dyncull::Box<T>{std::numeric_limits<T>::quiet_NaN(), T(0), T(1), T(1)}.finite()));
}

TEST(Detection, Defaults) {
  const dyncull::Detection<float> d;
  EXPECT_EQ(d.class_id, -1);
  EXPECT_EQ(d.confidence, 1.f);
  EXPECT_EQ(d.box.area(), 0.f);
}

}  // namespace
