// Tests of core/depth.hpp: uint16 with a scale (TUM 5000 / m), float metres, every "no measurement"
// case (raw 0, NaN, Inf, negative, outside [min_m, max_m], outside the image) and row strides.
#include "dyncull/core/depth.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace {

TEST(DepthView, TumUint16Scale) {
  // 3 x 2 image: 1 m, 2.5 m, no measurement / 0.2 m, 12 m, 65535 raw (13.107 m).
  const std::vector<std::uint16_t> raw{5000, 12500, 0, 1000, 60000, 65535};
  const auto view = dyncull::tum_depth_view(raw.data(), 3, 2);
  EXPECT_FALSE(view.empty());
  EXPECT_FLOAT_EQ(view.depth_m(0, 0), 1.0f);
  EXPECT_FLOAT_EQ(view.depth_m(1, 0), 2.5f);
  EXPECT_EQ(view.depth_m(2, 0), 0.f);
  EXPECT_FLOAT_EQ(view.depth_m(0, 1), 0.2f);
  EXPECT_FLOAT_EQ(view.depth_m(2, 1), 65535.f / 5000.f);
  EXPECT_EQ(view.raw(1, 1), 60000);
  EXPECT_DOUBLE_EQ(view.to_raw(2.0), 10000.0);

  // TUM's reliable range [0.4, 10] m: 0.2 m and 12 m become "no measurement".
  const auto ranged = dyncull::tum_depth_view(raw.data(), 3, 2, 0.4f, 10.f);
  EXPECT_EQ(ranged.depth_m(0, 1), 0.f);
  EXPECT_EQ(ranged.depth_m(1, 1), 0.f);
  EXPECT_FLOAT_EQ(ranged.depth_m(0, 0), 1.0f);
}

TEST(DepthView, OutOfBoundsIsNoMeasurement) {
  const std::vector<std::uint16_t> raw(4, 5000);
  const auto view = dyncull::tum_depth_view(raw.data(), 2, 2);
  EXPECT_FLOAT_EQ(view.depth_m(1, 1), 1.f);
  EXPECT_EQ(view.depth_m(-1, 0), 0.f);
  EXPECT_EQ(view.depth_m(0, -1), 0.f);
  EXPECT_EQ(view.depth_m(2, 0), 0.f);
  EXPECT_EQ(view.depth_m(0, 2), 0.f);
  EXPECT_FALSE(view.in_bounds(2, 1));
  EXPECT_TRUE(dyncull::DepthView<std::uint16_t>{}.empty());
  const dyncull::DepthView<float> zero_size{nullptr, 0, 0};
  EXPECT_TRUE(zero_size.empty());
  EXPECT_EQ(zero_size.depth_m(0, 0), 0.f);
}

TEST(DepthView, FloatMetresInvalidValues) {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const std::vector<float> d{1.5f, nan, inf, -2.f, 0.f, 3.25f};
  const dyncull::DepthView<float> view{d.data(), 3, 2};
  EXPECT_FLOAT_EQ(view.depth_m(0, 0), 1.5f);
  EXPECT_EQ(view.depth_m(1, 0), 0.f);
  EXPECT_EQ(view.depth_m(2, 0), 0.f);
  EXPECT_EQ(view.depth_m(0, 1), 0.f);
  EXPECT_EQ(view.depth_m(1, 1), 0.f);
  EXPECT_FLOAT_EQ(view.depth_m(2, 1), 3.25f);
  const std::vector<double> dd{0.75, std::nan("")};
  const dyncull::DepthView<double> dview{dd.data(), 2, 1};
  EXPECT_FLOAT_EQ(dview.depth_m(0, 0), 0.75f);
  EXPECT_EQ(dview.depth_m(1, 0), 0.f);
}

TEST(DepthView, RowStrideSkipsPadding) {
  // 3 x 3 image stored with 5 elements per row (a cv::Mat ROI); padding holds a poison value.
  std::vector<std::uint16_t> buf(15, 11111);
  for (int v = 0; v < 3; ++v)
    for (int u = 0; u < 3; ++u) buf[static_cast<std::size_t>(v * 5 + u)] = static_cast<std::uint16_t>(1000 * (v * 3 + u + 1));
  dyncull::DepthView<std::uint16_t> view{buf.data(), 3, 3, 5, 1000.f};
  EXPECT_EQ(view.row_stride(), 5);
  for (int v = 0; v < 3; ++v)
    for (int u = 0; u < 3; ++u) EXPECT_FLOAT_EQ(view.depth_m(u, v), float(v * 3 + u + 1)) << u << "," << v;
  view.stride = 0;  // 0 means "width"
  EXPECT_EQ(view.row_stride(), 3);
}

// Nguyen et al. 2012 (Kinect v1): 1.2 mm at 0.4 m, growing with the square of the distance beyond it.
TEST(AxialDepthSigma, KinectModelAndItsParameters) {
  EXPECT_DOUBLE_EQ(dyncull::axial_depth_sigma_m(0.4), 0.0012);
  EXPECT_NEAR(dyncull::axial_depth_sigma_m(2.4), 0.0012 + 0.0019 * 4.0, 1e-15);
  EXPECT_NEAR(dyncull::axial_depth_sigma_m(3.0f), 0.0012f + 0.0019f * 6.76f, 1e-7f);
  EXPECT_DOUBLE_EQ(dyncull::axial_depth_sigma_m(1.0, 0.001, 0.01, 0.5), 0.001 + 0.01 * 0.25);
}

}  // namespace
