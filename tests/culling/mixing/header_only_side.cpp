// The header-only side of a program that breaks the mixing rule (docs/design.md): this translation unit
// drops DYNCULL_PRECOMPILED, so the F solvers are defined inline here, while the other unit of the same
// program takes them from dyncull::pipeline. The link must fail on the rule's marker symbols.
#undef DYNCULL_PRECOMPILED

#include "dyncull/geometry/fundamental.hpp"

#include <cstddef>
#include <vector>

std::size_t header_only_inliers(const std::vector<dyncull::Vec2<double>>& a, const std::vector<dyncull::Vec2<double>>& b) {
  return dyncull::estimate_fundamental_ransac(a, b, dyncull::FundamentalOptions<double>{}).num_inliers;
}
