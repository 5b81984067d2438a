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

}  // namespace
