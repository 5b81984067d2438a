// A header-only translation unit of the mixing-rule programs (docs/design.md): DYNCULL_PRECOMPILED is
// dropped, so the F solvers are defined inline here. Beside header_only_main.cpp it makes a well-formed
// header-only program; beside precompiled_side.cpp, one that breaks the rule and must fail to link.
#undef DYNCULL_PRECOMPILED

#include "dyncull/geometry/fundamental.hpp"

#include <cstddef>
#include <vector>

std::size_t header_only_inliers(const std::vector<dyncull::Vec2<double>>& a, const std::vector<dyncull::Vec2<double>>& b) {
  return dyncull::estimate_fundamental_ransac(a, b, dyncull::FundamentalOptions<double>{}).num_inliers;
}
