// core/camera_bounds.hpp on its own: the plausible-camera check every camera passes where it enters
// (culler, sequence reader, host). Real cameras pass; each absurd value is refused naming itself.
#include "dyncull/core/camera_bounds.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <string>

namespace {

using namespace dyncull;

TEST(CameraBounds, RealCamerasPass) {
  const double tum_fr1[5] = {0.2624, -0.9531, -0.0054, 0.0026, 1.1633};
  std::string why;
  EXPECT_EQ(check_camera(517.3, 516.5, 318.6, 255.3, 640, 480, tum_fr1, 5, 5000.0, &why), Status::Ok) << why;
  EXPECT_EQ(check_camera(542.8, 542.6, 315.6, 237.8, 640, 480, nullptr, 0, 5000.0, &why), Status::Ok) << why;
  EXPECT_EQ(check_camera(600, 600, 320, 240, 640, 480, nullptr, 0, 1.0, &why), Status::Ok) << why;  // metres
}

TEST(CameraBounds, EachAbsurdValueIsRefusedNamingIt) {
  std::string why;
  EXPECT_EQ(check_intrinsics(1e-300, 500, 320, 240, 640, 480, &why), Status::InvalidInput);
  EXPECT_NE(why.find("f"), std::string::npos) << why;
  EXPECT_EQ(check_intrinsics(500, 500, -1e300, 240, 640, 480, &why), Status::InvalidInput);
  EXPECT_NE(why.find("cx"), std::string::npos) << why;
  EXPECT_EQ(check_intrinsics(500, std::numeric_limits<double>::quiet_NaN(), 320, 240, 640, 480, &why),
            Status::InvalidInput);
  EXPECT_EQ(check_intrinsics(500, 500, 320, 240, 0, 480, &why), Status::InvalidInput);
  const double huge_k1[5] = {1e300, 0, 0, 0, 0};
  EXPECT_EQ(check_distortion(huge_k1, 5, &why), Status::InvalidInput);
  EXPECT_NE(why.find("k1"), std::string::npos) << why;
  EXPECT_EQ(check_depth_units(1e-300, &why), Status::InvalidInput);
  EXPECT_NE(why.find("depth units per metre"), std::string::npos) << why;
  EXPECT_EQ(check_depth_units(std::numeric_limits<double>::infinity(), &why), Status::InvalidInput);
}

}  // namespace
