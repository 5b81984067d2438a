// Kinect depth model: the empirical sigma, quantisation to 1/5000 m, holes at discontinuities,
// the border band, range limits and determinism.
#include "dyncull/sim/depth_noise.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <vector>

namespace {

using namespace dyncull::sim;

TEST(SimDepthNoise, SigmaFollowsTheQuadraticModel) {
  EXPECT_DOUBLE_EQ(kinect_depth_sigma_m(0.4), 0.0012);
  EXPECT_NEAR(kinect_depth_sigma_m(2.4), 0.0012 + 0.0019 * 4.0, 1e-15);
  EXPECT_GT(kinect_depth_sigma_m(5.0), kinect_depth_sigma_m(3.0));
}

TEST(SimDepthNoise, ApproximateNormalHasUnitVariance) {
  std::uint64_t state = 7;
  double sum = 0, sum_sq = 0;
  constexpr int kN = 200000;
  for (int k = 0; k < kN; ++k) {
    const double x = detail::approx_normal(detail::splitmix(state));
    sum += x;
    sum_sq += x * x;
  }
  const double mean = sum / kN, var = sum_sq / kN - mean * mean;
  EXPECT_NEAR(mean, 0.0, 0.01);   // standard error 1/sqrt(2e5) = 0.0022
  EXPECT_NEAR(var, 1.0, 0.02);
}

// A flat wall at 3 m: the empirical noise matches sigma(3), every value is on the 1/5000 m grid,
// the border band is empty and nothing else is a hole.
TEST(SimDepthNoise, FlatWallNoiseQuantisationAndBorder) {
  const int w = 200, h = 150;
  DepthNoiseOptions o;
  std::vector<float> depth(static_cast<std::size_t>(w * h), 3.0f);
  apply_depth_noise(depth.data(), w, h, o, 42);
  double sum = 0, sum_sq = 0;
  int n = 0;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const float d = depth[static_cast<std::size_t>(v * w + u)];
      const bool band = u < o.border_px || v < o.border_px || u >= w - o.border_px || v >= h - o.border_px;
      if (band) {
        EXPECT_EQ(d, 0.f);
        continue;
      }
      ASSERT_GT(d, 0.f);
      const double units = d * 5000.0;
      EXPECT_NEAR(units, std::round(units), 1e-2);
      sum += d - 3.0;
      sum_sq += (d - 3.0) * (d - 3.0);
      ++n;
    }
  }
  const double sigma = kinect_depth_sigma_m(3.0);
  EXPECT_NEAR(sum / n, 0.0, 0.1 * sigma);
  EXPECT_NEAR(std::sqrt(sum_sq / n), sigma, 0.05 * sigma);  // quantisation (0.2 mm step) adds ~0.3 % here
}

TEST(SimDepthNoise, HolesAtDiscontinuitiesAndOutOfRange) {
  const int w = 64, h = 48;
  DepthNoiseOptions o;
  o.border_px = 0;
  std::vector<float> depth(static_cast<std::size_t>(w * h));
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) depth[static_cast<std::size_t>(v * w + u)] = u < 32 ? 1.5f : 4.0f;
  depth[static_cast<std::size_t>(5 * w + 5)] = 0.2f;   // closer than min range
  depth[static_cast<std::size_t>(40 * w + 50)] = 9.f;  // farther than max range
  apply_depth_noise(depth.data(), w, h, o, 1);
  for (int v = 0; v < h; ++v) {
    EXPECT_EQ(depth[static_cast<std::size_t>(v * w + 31)], 0.f) << v;  // both sides of the edge
    EXPECT_EQ(depth[static_cast<std::size_t>(v * w + 32)], 0.f) << v;
    EXPECT_GT(depth[static_cast<std::size_t>(v * w + 20)], 0.f) << v;  // away from it: measured
  }
  EXPECT_EQ(depth[static_cast<std::size_t>(5 * w + 5)], 0.f);
  EXPECT_EQ(depth[static_cast<std::size_t>(40 * w + 50)], 0.f);
}

TEST(SimDepthNoise, DeterministicPerSeedAndSafeOnEmptyInput) {
  std::vector<float> a(1000, 2.f), b(1000, 2.f), c(1000, 2.f);
  DepthNoiseOptions o;
  o.border_px = 1;
  apply_depth_noise(a.data(), 50, 20, o, 9);
  apply_depth_noise(b.data(), 50, 20, o, 9);
  apply_depth_noise(c.data(), 50, 20, o, 10);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  apply_depth_noise(nullptr, 50, 20, o, 9);  // no crash
  apply_depth_noise(a.data(), 0, 20, o, 9);
  EXPECT_EQ(a, b);
}

}  // namespace
