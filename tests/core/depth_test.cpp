// Tests of core/depth.hpp: uint16 with a scale (TUM 5000 / m), float metres, every "no measurement"
// case (raw 0, NaN, Inf, negative, outside [min_m, max_m], outside the image) and row strides.
#include "dyncull/core/depth.hpp"
#include "dyncull/core/random.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <climits>
#include <cmath>
#include <limits>
#include <string>
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

TEST(DepthView, ValidateNamesTheBadField) {
  const std::vector<std::uint16_t> raw(4, 5000);
  auto view = dyncull::tum_depth_view(raw.data(), 2, 2);
  std::string why;
  EXPECT_EQ(view.validate(&why), dyncull::Status::Ok) << why;
  EXPECT_EQ(dyncull::DepthView<float>{}.validate(), dyncull::Status::Ok);  // no depth image is valid
  view.units_per_metre = -5000.f;
  EXPECT_EQ(view.validate(&why), dyncull::Status::InvalidInput);
  EXPECT_NE(why.find("units_per_metre"), std::string::npos) << why;
  view.units_per_metre = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(view.validate(&why), dyncull::Status::InvalidInput);
  for (float units : {1e-40f, 1e-4f, 2e6f, 1e9f}) {  // no sensor has these units
    view.units_per_metre = units;
    EXPECT_EQ(view.validate(&why), dyncull::Status::InvalidInput) << units;
    EXPECT_NE(why.find("units_per_metre"), std::string::npos) << why;
  }
  view = dyncull::tum_depth_view(raw.data(), 2, 2, 0.f, 0.f);  // no depth can be valid
  EXPECT_EQ(view.validate(&why), dyncull::Status::InvalidInput);
  EXPECT_NE(why.find("max_m"), std::string::npos) << why;
  view = dyncull::tum_depth_view(raw.data(), 2, 2);
  view.stride = 1;
  EXPECT_EQ(view.validate(&why), dyncull::Status::InvalidInput);
  EXPECT_NE(why.find("stride"), std::string::npos) << why;
  view = dyncull::tum_depth_view(raw.data(), 2, 2, 1.f, 0.5f);
  EXPECT_EQ(view.validate(&why), dyncull::Status::InvalidInput);
  EXPECT_NE(why.find("max_m"), std::string::npos) << why;
  view = dyncull::tum_depth_view(raw.data(), 2, 2, -1.f);
  EXPECT_EQ(view.validate(&why), dyncull::Status::InvalidInput);
  EXPECT_NE(why.find("min_m"), std::string::npos) << why;
}

// A depth step 30 px away in a 64 x 48 image (columns 40 on are farther): every radius that reaches it
// finds it, however large, and a radius far beyond the image costs one pass over the image at most.
TEST(DepthStepNear, HugeRadiusIsClampedToTheImage) {
  const int w = 64, h = 48;
  std::vector<float> d(static_cast<std::size_t>(w * h), 2.f);
  for (int y = 0; y < h; ++y)
    for (int x = 40; x < w; ++x) d[static_cast<std::size_t>(y * w + x)] = 3.f;
  const dyncull::DepthView<float> view{d.data(), w, h};
  EXPECT_FALSE(dyncull::depth_step_near(view, 10, 10, 4, 0.05));
  EXPECT_TRUE(dyncull::depth_step_near(view, 10, 10, 30, 0.05));
  const auto start = std::chrono::steady_clock::now();
  EXPECT_TRUE(dyncull::depth_step_near(view, 10, 10, 100000000, 0.05));
  EXPECT_TRUE(dyncull::depth_step_near(view, 10, 10, INT_MAX, 0.05));
  EXPECT_TRUE(dyncull::depth_step_near(view, 10, 10, INT_MAX - 1, 0.05));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(seconds, 1.0);
}

TEST(DepthStepNear, PropertyMatchesTheUnclampedLoopOnSmallRadii) {
  // Reference: the plain loop over every sampled offset (radius small enough not to overflow).
  auto reference = [](const dyncull::DepthView<float>& v, int u, int y, int radius, double ratio) {
    const float z = v.depth_m(u, y);
    if (!(z > 0.f)) return false;
    const int step = radius > 2 ? 2 : 1;
    for (int dy = -radius; dy <= radius; dy += step)
      for (int dx = -radius; dx <= radius; dx += step) {
        if (!v.in_bounds(u + dx, y + dy)) continue;
        const float zz = v.depth_m(u + dx, y + dy);
        if (!(zz > 0.f) || std::abs(zz - z) > static_cast<float>(ratio) * z) return true;
      }
    return false;
  };
  dyncull::Random rng(5);
  for (int trial = 0; trial < 300; ++trial) {
    const int w = 1 + static_cast<int>(rng.index(30)), h = 1 + static_cast<int>(rng.index(30));
    std::vector<float> d(static_cast<std::size_t>(w * h));
    for (float& x : d) x = rng.index(10) == 0 ? std::numeric_limits<float>::quiet_NaN() : static_cast<float>(1.0 + 0.1 * rng.index(3));
    const dyncull::DepthView<float> view{d.data(), w, h};
    const int u = static_cast<int>(rng.index(40)) - 5, y = static_cast<int>(rng.index(40)) - 5;
    const int radius = static_cast<int>(rng.index(40)) - 2;
    const double ratio = rng.uniform(0, 0.2);
    EXPECT_EQ(dyncull::depth_step_near(view, u, y, radius, ratio), reference(view, u, y, radius, ratio))
        << trial << " " << u << "," << y << " r=" << radius;
  }
}

}  // namespace
