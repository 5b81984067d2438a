// The header-only control of the mixing rule (docs/design.md): two header-only translation units
// (this one and header_only_side.cpp) both define the solvers inline and the guard's marker, and the
// program links and runs: the marker's COMDAT group merges them.
#include "dyncull/geometry/fundamental.hpp"
#include "points.hpp"

#include <cstddef>
#include <cstdio>
#include <vector>

#ifdef DYNCULL_PRECOMPILED
#error "the header-only control links neither dyncull::pipeline nor dyncull::culler"
#endif

std::size_t header_only_inliers(const std::vector<dyncull::Vec2<double>>& a, const std::vector<dyncull::Vec2<double>>& b);

int main() {
  std::vector<dyncull::Vec2<double>> a, b;
  mixing::make_points(&a, &b);
  const std::size_t n = dyncull::estimate_fundamental_ransac(a, b, dyncull::FundamentalOptions<double>{}).num_inliers +
                        header_only_inliers(a, b);
  std::printf("inliers %zu\n", n);
  return n > 0 ? 0 : 1;
}
