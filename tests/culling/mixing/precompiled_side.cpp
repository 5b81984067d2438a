// The precompiled side of the mixing-rule programs (docs/design.md): F-RANSAC from dyncull::pipeline or
// dyncull::culler (DYNCULL_PRECOMPILED), and, when built with the header-only side, a call into it. Alone
// it links and runs: the library by itself is a well-formed program.
#include "dyncull/geometry/fundamental.hpp"
#include "points.hpp"

#include <cstddef>
#include <cstdio>
#include <vector>

#ifndef DYNCULL_PRECOMPILED
#error "the precompiled side takes the solvers from the library: it is built with DYNCULL_PRECOMPILED"
#endif

#ifdef DYNCULL_WITH_HEADER_ONLY_SIDE
std::size_t header_only_inliers(const std::vector<dyncull::Vec2<double>>& a, const std::vector<dyncull::Vec2<double>>& b);
#endif

int main() {
  std::vector<dyncull::Vec2<double>> a, b;
  mixing::make_points(&a, &b);
  std::size_t n = dyncull::estimate_fundamental_ransac(a, b, dyncull::FundamentalOptions<double>{}).num_inliers;
#ifdef DYNCULL_WITH_HEADER_ONLY_SIDE
  n += header_only_inliers(a, b);
#endif
  std::printf("inliers %zu\n", n);
  return n > 0 ? 0 : 1;
}
