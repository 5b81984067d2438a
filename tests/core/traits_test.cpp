// Tests of core/traits.hpp: points read from Eigen vectors, x/y(/z) structs, .pt keypoints and a user
// specialisation, without copies, plus the container helpers.
#include "dyncull/core/traits.hpp"

#include <gtest/gtest.h>

#include <array>
#include <type_traits>
#include <vector>

namespace user {
struct XY {
  float x, y;
};
struct XYZ {
  double x, y, z;
};
struct Keypoint {  // cv::KeyPoint look-alike
  XY pt;
  float response;
};
struct Polar {  // needs a user specialisation: coordinates in an array
  double coords[2];
};
}  // namespace user

namespace dyncull {
template <>
struct PointTraits<user::Polar> {
  static constexpr bool specialised = true;
  static constexpr int dim = 2;
  using Scalar = double;
  static double x(const user::Polar& p) { return p.coords[0]; }
  static double y(const user::Polar& p) { return p.coords[1]; }
};
}  // namespace dyncull

namespace {

static_assert(dyncull::is_point_v<Eigen::Vector2f>, "Eigen 2-vectors are points");
static_assert(dyncull::is_point_v<Eigen::Vector3d> && dyncull::PointTraits<Eigen::Vector3d>::dim == 3, "3-D");
static_assert(dyncull::is_point_v<user::XY> && dyncull::PointTraits<user::XY>::dim == 2, "x/y struct");
static_assert(dyncull::PointTraits<user::XYZ>::dim == 3, "x/y/z struct");
static_assert(dyncull::is_point_v<user::Keypoint>, ".pt struct");
static_assert(dyncull::is_point_v<user::Polar>, "user specialisation");
static_assert(!dyncull::is_point_v<int> && !dyncull::is_point_v<std::vector<float>>, "not points");
static_assert(dyncull::is_point_container_v<std::vector<user::XY>>, "vector of points");
static_assert(dyncull::is_point_container_v<std::array<Eigen::Vector2d, 3>>, "array of points");
static_assert(!dyncull::is_point_container_v<std::vector<int>>, "vector of ints");
static_assert(std::is_same<dyncull::PointTraits<user::Keypoint>::Scalar, float>::value, "scalar of .pt");
static_assert(std::is_same<decltype(dyncull::point_x(user::XY{})), float>::value, "native scalar");
static_assert(std::is_same<decltype(dyncull::point_x<double>(user::XY{})), double>::value, "requested scalar");

TEST(PointTraits, ReadsEveryKind) {
  EXPECT_EQ(dyncull::point_x(Eigen::Vector2f(1.5f, 2.5f)), 1.5f);
  EXPECT_EQ(dyncull::point_y(Eigen::Vector2d(1.5, 2.5)), 2.5);
  EXPECT_EQ(dyncull::point_z(Eigen::Vector3d(1, 2, 3)), 3.0);
  EXPECT_EQ(dyncull::point_y(user::XY{4.f, 5.f}), 5.f);
  EXPECT_EQ(dyncull::point_z(user::XYZ{1, 2, 9}), 9.0);
  EXPECT_EQ(dyncull::point_x(user::Keypoint{{7.f, 8.f}, 0.3f}), 7.f);
  EXPECT_EQ(dyncull::point_y(user::Polar{{3.0, -4.0}}), -4.0);
  const Eigen::Vector2d v = dyncull::to_vec2<double>(user::Keypoint{{7.25f, 8.5f}, 0.f});
  EXPECT_EQ(v, Eigen::Vector2d(7.25, 8.5));
  const Eigen::Vector3f w = dyncull::to_vec3<float>(user::XYZ{1, 2, 3});
  EXPECT_EQ(w, Eigen::Vector3f(1, 2, 3));
}

TEST(PointTraits, ReadsWithoutCopies) {
  // The traits return values read straight from the caller's object: references into a container
  // see later writes.
  std::vector<user::Keypoint> kps{{{1.f, 2.f}, 0.f}};
  const auto& ref = kps[0];
  kps[0].pt.x = 42.f;
  EXPECT_EQ(dyncull::point_x(ref), 42.f);
  using Point = dyncull::container_point_t<std::vector<user::Keypoint>>;
  static_assert(std::is_same<Point, user::Keypoint>::value, "container element type");
}

}  // namespace
