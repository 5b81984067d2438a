// Tests of core/types.hpp: rigid transforms compose, invert and report their centre and angle.
#include "dyncull/core/types.hpp"

#include <gtest/gtest.h>

namespace {

template <class T>
class RigidTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(RigidTest, Scalars, );  // trailing comma: clang -Wpedantic rejects an empty variadic

TYPED_TEST(RigidTest, InverseComposesToIdentity) {
  using T = TypeParam;
  dyncull::Rigid3<T> b_from_a;
  b_from_a.R = Eigen::AngleAxis<T>(T(0.3), dyncull::Vec3<T>(1, 2, 3).normalized()).toRotationMatrix();
  b_from_a.t = dyncull::Vec3<T>(0.5, -1, 2);
  const auto id = b_from_a.inverse() * b_from_a;
  const T tol = T(10) * dyncull::Constants<T>::small();
  EXPECT_LT((id.R - dyncull::Mat3<T>::Identity()).norm(), tol);
  EXPECT_LT(id.t.norm(), tol);
  const dyncull::Vec3<T> x(1, 2, 3);
  EXPECT_LT((b_from_a.inverse().apply(b_from_a.apply(x)) - x).norm(), tol);
  // The centre maps to the origin of the target frame.
  EXPECT_LT(b_from_a.apply(b_from_a.centre()).norm(), tol);
  EXPECT_NEAR(dyncull::rotation_angle(b_from_a.R), T(0.3), T(1e3) * dyncull::Constants<T>::epsilon());
}

TEST(RotationAngle, ClampsAtPi) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_NEAR(dyncull::rotation_angle(R), M_PI, 1e-7);
  EXPECT_FALSE(std::isnan(dyncull::rotation_angle(Eigen::Matrix3d(Eigen::Matrix3d::Identity() * 1.0000001))));
}

}  // namespace
