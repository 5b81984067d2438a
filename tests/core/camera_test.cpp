// Tests of core/camera.hpp: projection and back-projection are inverse (float and double), the ray is
// the unit-depth back-projection, in_image honours the border, and K has the usual layout.
#include "dyncull/core/camera.hpp"

#include <gtest/gtest.h>

#include <limits>

namespace {

template <class T>
class CameraTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(CameraTest, Scalars, );

TYPED_TEST(CameraTest, ProjectBackprojectRoundTrip) {
  using T = TypeParam;
  const auto cam = dyncull::PinholeCamera<T>::tum_fr3();
  // Relative tolerance: a few eps of the pixel / metre magnitudes involved.
  const T tol = T(64) * dyncull::Constants<T>::epsilon();
  for (T z : {T(0.5), T(2), T(7.5)}) {
    for (T u : {T(0), T(100.25), T(639)}) {
      for (T v : {T(0), T(240.5), T(479)}) {
        const dyncull::Vec2<T> uv(u, v);
        const dyncull::Vec3<T> p = cam.backproject(uv, z);
        EXPECT_NEAR(p.z(), z, tol * z);
        const dyncull::Vec2<T> back = cam.project(p);
        EXPECT_NEAR(back.x(), u, tol * T(640));
        EXPECT_NEAR(back.y(), v, tol * T(640));
        EXPECT_LT((cam.ray(uv) * z - p).norm(), tol * T(10));
      }
    }
  }
  // The principal point is on the optical axis.
  const dyncull::Vec3<T> axis = cam.backproject(dyncull::Vec2<T>(cam.cx, cam.cy), T(3));
  EXPECT_NEAR(axis.x(), T(0), tol);
  EXPECT_NEAR(axis.y(), T(0), tol);
}

TYPED_TEST(CameraTest, UsesFyForY) {
  using T = TypeParam;
  // fx != fy exposes the typo of Zhu et al. (2024) eq. 6 (y divided by fx).
  const dyncull::PinholeCamera<T> cam{T(500), T(600), T(320), T(240), 640, 480};
  const dyncull::Vec3<T> p = cam.backproject(dyncull::Vec2<T>(320, 300), T(2));
  EXPECT_NEAR(p.y(), T(60) * T(2) / T(600), T(1e-6));
  EXPECT_NEAR(cam.project(dyncull::Vec3<T>(T(1), T(1), T(2))).y(), T(240) + T(300), T(1e-4));
}

TYPED_TEST(CameraTest, InImageAndBorder) {
  using T = TypeParam;
  const dyncull::PinholeCamera<T> cam;  // 640 x 480
  EXPECT_TRUE(cam.in_image(T(0), T(0)));
  EXPECT_TRUE(cam.in_image(T(639), T(479)));
  EXPECT_FALSE(cam.in_image(T(639.5), T(10)));
  EXPECT_FALSE(cam.in_image(T(-0.01), T(10)));
  EXPECT_FALSE(cam.in_image(T(10), T(480)));
  EXPECT_FALSE(cam.in_image(T(3), T(100), T(5)));
  EXPECT_TRUE(cam.in_image(T(5), T(5), T(5)));
  EXPECT_FALSE(cam.in_image(T(635), T(100), T(5)));
  EXPECT_FALSE(cam.in_image(dyncull::Constants<T>::nan(), T(100)));
}

TYPED_TEST(CameraTest, IntrinsicMatrixValidityAndCast) {
  using T = TypeParam;
  const auto cam = dyncull::PinholeCamera<T>::tum_fr3();
  const dyncull::Mat3<T> K = cam.K();
  EXPECT_EQ(K(0, 0), cam.fx);
  EXPECT_EQ(K(1, 1), cam.fy);
  EXPECT_EQ(K(0, 2), cam.cx);
  EXPECT_EQ(K(1, 2), cam.cy);
  EXPECT_EQ(K(2, 2), T(1));
  EXPECT_EQ(K(0, 1), T(0));
  EXPECT_EQ(K(1, 0), T(0));
  EXPECT_EQ(K(2, 0), T(0));
  // K times the ray of a pixel gives the homogeneous pixel.
  const dyncull::Vec3<T> h = K * cam.ray(dyncull::Vec2<T>(T(100), T(50)));
  EXPECT_NEAR(h.x(), T(100), T(1e-3));
  EXPECT_NEAR(h.y(), T(50), T(1e-3));
  EXPECT_TRUE(cam.valid());
  auto bad = cam;
  bad.fx = T(0);
  EXPECT_FALSE(bad.valid());
  bad = cam;
  bad.cy = dyncull::Constants<T>::nan();
  EXPECT_FALSE(bad.valid());
  bad = cam;
  bad.width = 0;
  EXPECT_FALSE(bad.valid());
  const auto d = cam.template cast<double>();
  EXPECT_NEAR(d.fx, 535.4, 1e-4);
  EXPECT_EQ(d.width, 640);
  EXPECT_EQ(d.height, 480);
}

// Infinite focal lengths and image sizes at the ends of the int range: no overflow, no
// camera that claims validity while projecting everything to Inf.
TYPED_TEST(CameraTest, NonFiniteFocalLengthsAndExtremeSizes) {
  using T = TypeParam;
  dyncull::PinholeCamera<T> cam;
  cam.fx = std::numeric_limits<T>::infinity();
  EXPECT_FALSE(cam.valid());
  cam = dyncull::PinholeCamera<T>{};
  cam.fy = std::numeric_limits<T>::quiet_NaN();
  EXPECT_FALSE(cam.valid());
  cam = dyncull::PinholeCamera<T>{};
  cam.width = std::numeric_limits<int>::min();
  cam.height = std::numeric_limits<int>::min();
  EXPECT_FALSE(cam.valid());
  EXPECT_FALSE(cam.in_image(T(0), T(0)));  // no int overflow computing the far edge
  cam.width = std::numeric_limits<int>::max();
  cam.height = 10;
  EXPECT_TRUE(cam.in_image(T(1e9), T(5)));
}

TEST(Camera, DefaultsAreTumDefaults) {
  const dyncull::PinholeCamera<double> cam;
  EXPECT_EQ(cam.fx, 525.0);
  EXPECT_EQ(cam.cx, 319.5);
  EXPECT_EQ(cam.width, 640);
  EXPECT_EQ(cam.height, 480);
  const auto fr3 = dyncull::PinholeCamera<double>::tum_fr3();
  EXPECT_DOUBLE_EQ(fr3.fy, 539.2);
  EXPECT_DOUBLE_EQ(fr3.cy, 247.6);
}

}  // namespace
