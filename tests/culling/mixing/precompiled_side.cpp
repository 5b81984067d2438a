// The precompiled side of the mixing programs (docs/design.md): F-RANSAC from dyncull::pipeline
// (DYNCULL_PRECOMPILED from the library's interface), and, when built with the header-only side, a call
// into it. Alone it links and runs: the library by itself is a well-formed program.
#include "dyncull/geometry/fundamental.hpp"

#include <cstddef>
#include <cstdio>
#include <vector>

#ifndef DYNCULL_PRECOMPILED
#error "the precompiled side links dyncull::pipeline, whose interface defines DYNCULL_PRECOMPILED"
#endif

#ifdef DYNCULL_WITH_HEADER_ONLY_SIDE
std::size_t header_only_inliers(const std::vector<dyncull::Vec2<double>>& a, const std::vector<dyncull::Vec2<double>>& b);
#endif

int main() {
  std::vector<dyncull::Vec2<double>> a, b;
  for (int i = 0; i < 40; ++i) {
    const double x = 10.0 * (i % 7), y = 9.0 * (i / 7), z = 2.0 + 0.1 * (i % 5);
    a.emplace_back(500.0 * x / (10.0 * z) + 320.0, 500.0 * y / (10.0 * z) + 240.0);
    b.emplace_back(500.0 * (x + 1.0) / (10.0 * z) + 320.0, 500.0 * y / (10.0 * z) + 240.0);
  }
  std::size_t n = dyncull::estimate_fundamental_ransac(a, b, dyncull::FundamentalOptions<double>{}).num_inliers;
#ifdef DYNCULL_WITH_HEADER_ONLY_SIDE
  n += header_only_inliers(a, b);
#endif
  std::printf("inliers %zu\n", n);
  return 0;
}
