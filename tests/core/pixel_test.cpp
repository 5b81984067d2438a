// Tests of core/pixel.hpp: nearest-pixel rounding, image bounds, and NaN / Inf / huge coordinates
// that must never map to a pixel (in particular not wrap back into the image).
#include "dyncull/core/pixel.hpp"

#include <gtest/gtest.h>

#include <climits>
#include <cmath>
#include <limits>

namespace {
using namespace dyncull;

template <class T>
class PixelTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(PixelTest, Scalars, );

TYPED_TEST(PixelTest, NearestCentreInsideTheImage) {
  using T = TypeParam;
  int u = -7;
  EXPECT_TRUE(pixel_index(T(0), 640, &u));
  EXPECT_EQ(u, 0);
  EXPECT_TRUE(pixel_index(T(10.4), 640, &u));
  EXPECT_EQ(u, 10);
  EXPECT_TRUE(pixel_index(T(10.5), 640, &u));  // half away from zero, as std::lround
  EXPECT_EQ(u, 11);
  EXPECT_TRUE(pixel_index(T(-0.4), 640, &u));
  EXPECT_EQ(u, 0);
  EXPECT_TRUE(pixel_index(T(639.49), 640, &u));
  EXPECT_EQ(u, 639);
  int x = -1, y = -1;
  EXPECT_TRUE(pixel_of(T(3.2), T(4.8), 640, 480, &x, &y));
  EXPECT_EQ(x, 3);
  EXPECT_EQ(y, 5);
}

TYPED_TEST(PixelTest, OutsideNonFiniteAndHugeCoordinatesHaveNoPixel) {
  using T = TypeParam;
  const T nan = std::numeric_limits<T>::quiet_NaN(), inf = std::numeric_limits<T>::infinity();
  const T bad[] = {T(-0.5), T(-1), T(639.5), T(640), nan, inf, -inf, std::numeric_limits<T>::max(),
                   std::numeric_limits<T>::lowest(), T(4294967306.0) /* 2^32 + 10 */, T(-4294967286.0),
                   T(2147483648.0), T(1e30)};
  for (const T x : bad) {
    int u = -7;
    EXPECT_FALSE(pixel_index(x, 640, &u)) << x;
    EXPECT_EQ(u, -7) << x;  // untouched
    int pu = -7, pv = -7;
    EXPECT_FALSE(pixel_of(x, T(10), 640, 480, &pu, &pv)) << x;
    EXPECT_FALSE(pixel_of(T(10), x, 640, 480, &pu, &pv)) << x;
    EXPECT_EQ(pu, -7);
    EXPECT_EQ(pv, -7);
  }
  // Empty and negative image sizes hold no pixel.
  int u = -7;
  EXPECT_FALSE(pixel_index(T(0), 0, &u));
  EXPECT_FALSE(pixel_index(T(0), -5, &u));
  EXPECT_FALSE(pixel_index(T(0), INT_MIN, &u));
  // The largest image: the last pixel is reachable, the one past it is not.
  EXPECT_TRUE(pixel_index(T(1000), INT_MAX, &u));
  EXPECT_FALSE(pixel_index(T(2147483648.0), INT_MAX, &u));
}

TYPED_TEST(PixelTest, ClampedIntTruncatesInsideTheRangeAndClampsOutside) {
  using T = TypeParam;
  const T nan = std::numeric_limits<T>::quiet_NaN(), inf = std::numeric_limits<T>::infinity();
  EXPECT_EQ(clamped_int(T(3.9), 0, 10), 3);
  EXPECT_EQ(clamped_int(T(-2.5), -5, 10), -2);  // toward zero, as static_cast<int>
  EXPECT_EQ(clamped_int(T(0), 0, 10), 0);
  EXPECT_EQ(clamped_int(T(9.99), 0, 10), 9);
  EXPECT_EQ(clamped_int(T(10), 0, 10), 10);
  EXPECT_EQ(clamped_int(T(-0.5), 0, 10), 0);
  for (const T x : {inf, std::numeric_limits<T>::max(), T(4294967306.0), T(2147483648.0)}) {
    EXPECT_EQ(clamped_int(x, 0, 255), 255) << x;
    EXPECT_EQ(clamped_int(x, INT_MIN, INT_MAX), INT_MAX) << x;
  }
  for (const T x : {nan, -inf, std::numeric_limits<T>::lowest(), T(-4294967286.0)}) {
    EXPECT_EQ(clamped_int(x, 1, 255), 1) << x;
    EXPECT_EQ(clamped_int(x, INT_MIN, INT_MAX), INT_MIN) << x;
  }
}

TYPED_TEST(PixelTest, CheckedIntRefusesNonFiniteAndOutOfRangeValues) {
  using T = TypeParam;
  const T nan = std::numeric_limits<T>::quiet_NaN(), inf = std::numeric_limits<T>::infinity();
  int v = -7;
  EXPECT_TRUE(checked_int(T(79.9), 0, 79, &v));
  EXPECT_EQ(v, 79);
  EXPECT_TRUE(checked_int(T(-1.5), -1, 79, &v));
  EXPECT_EQ(v, -1);
  v = -7;
  for (const T x : {nan, inf, -inf, T(80), T(-2), T(4294967296.0), T(1e30), std::numeric_limits<T>::lowest()}) {
    EXPECT_FALSE(checked_int(x, -1, 79, &v)) << x;
    EXPECT_EQ(v, -7) << x;  // untouched
  }
  EXPECT_TRUE(checked_int(T(-2147483648.0), INT_MIN, INT_MAX, &v));
  EXPECT_EQ(v, INT_MIN);
  EXPECT_FALSE(checked_int(T(2147483648.0), INT_MIN, INT_MAX, &v));
}

}  // namespace
