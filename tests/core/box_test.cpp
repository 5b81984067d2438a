// Tests of core/box.hpp: pixel_rect clipping (inside, partly and fully outside, inverted, NaN), IoU,
// padding, clipping and the small accessors.
#include "dyncull/core/box.hpp"

#include <gtest/gtest.h>

#include <climits>
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

// Finite boxes far beyond the int range: clamped in floating point, never cast out of range
// (undefined behaviour, caught by UBSan) and never wrapped back into the image.
TYPED_TEST(BoxTest, PixelRectOfHugeFiniteBoxes) {
  using T = TypeParam;
  const T big = std::numeric_limits<T>::max();
  EXPECT_TRUE(dyncull::pixel_rect(dyncull::Box<T>{T(5e9), T(10), T(6e9), T(20)}, 640, 480).empty());
  EXPECT_TRUE(dyncull::pixel_rect(dyncull::Box<T>{T(10), T(5e9), T(20), T(6e9)}, 640, 480).empty());
  EXPECT_TRUE(dyncull::pixel_rect(dyncull::Box<T>{T(-6e9), T(10), T(-5e9), T(20)}, 640, 480).empty());
  EXPECT_TRUE(dyncull::pixel_rect(dyncull::Box<T>{T(4294967306.0), T(0), T(4294967316.0), T(20)}, 640, 480).empty());
  EXPECT_TRUE(dyncull::pixel_rect(dyncull::Box<T>{big / T(2), big / T(2), big, big}, 640, 480).empty());
  const auto all = dyncull::pixel_rect(dyncull::Box<T>{-big, -big, big, big}, 640, 480);
  EXPECT_EQ(all.c0, 0);
  EXPECT_EQ(all.r0, 0);
  EXPECT_EQ(all.c1, 640);
  EXPECT_EQ(all.r1, 480);
  const auto part = dyncull::pixel_rect(dyncull::Box<T>{T(-5e9), T(100), T(10), T(5e9)}, 640, 480);
  EXPECT_EQ(part.c0, 0);
  EXPECT_EQ(part.c1, 11);
  EXPECT_EQ(part.r0, 100);
  EXPECT_EQ(part.r1, 480);
  // Image sizes at the ends of the int range.
  const auto wide = dyncull::pixel_rect(dyncull::Box<T>{T(0), T(0), big, T(5)}, INT_MAX, 10);
  EXPECT_EQ(wide.c1, INT_MAX);
  EXPECT_TRUE(dyncull::pixel_rect(dyncull::Box<T>{T(0), T(0), T(5), T(5)}, INT_MIN, -1).empty());
}

// Clipping is the intersection with the pixel centres [0, width-1] x [0, height-1]: an empty
// image or a box that misses the image gives an invalid (inverted) box, never a valid sliver.
TYPED_TEST(BoxTest, ClippingToAnEmptyImageOrMissingItIsInvalid) {
  using T = TypeParam;
  const dyncull::Box<T> b{T(10), T(20), T(30), T(60)};
  for (const auto& c : {b.clipped(0, 0), b.clipped(0, 480), b.clipped(640, 0), b.clipped(-3, -3),
                        b.clipped(INT_MIN, INT_MIN)}) {
    EXPECT_FALSE(c.valid()) << c.x0 << " " << c.y0 << " " << c.x1 << " " << c.y1;
    EXPECT_EQ(c.area(), T(0));
    EXPECT_TRUE(dyncull::pixel_rect(c, 640, 480).empty());
  }
  EXPECT_FALSE((dyncull::Box<T>{T(700), T(10), T(800), T(20)}.clipped(640, 480).valid()));
  EXPECT_FALSE((dyncull::Box<T>{T(10), T(-50), T(20), T(-1)}.clipped(640, 480).valid()));
  EXPECT_FALSE((dyncull::Box<T>{std::numeric_limits<T>::quiet_NaN(), T(0), T(5), T(5)}.clipped(640, 480).valid()));
  // A box touching the last column keeps it.
  const auto edge = dyncull::Box<T>{T(639), T(10), T(800), T(20)}.clipped(640, 480);
  EXPECT_TRUE(edge.valid());
  EXPECT_EQ(edge.x0, T(639));
  EXPECT_EQ(edge.x1, T(639));
  // A one-pixel image.
  const auto one = b.clipped(1, 1);
  EXPECT_FALSE(one.valid());  // b starts at x = 10: misses pixel 0
  const auto cover = dyncull::Box<T>{T(-5), T(-5), T(5), T(5)}.clipped(1, 1);
  EXPECT_TRUE(cover.valid());
  EXPECT_EQ(cover.x1, T(0));
}

TEST(Detection, Defaults) {
  const dyncull::Detection<float> d;
  EXPECT_EQ(d.class_id, -1);
  EXPECT_EQ(d.confidence, 1.f);
  EXPECT_EQ(d.box.area(), 0.f);
}

}  // namespace
