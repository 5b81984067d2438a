// Matched points for the mixing-rule programs (docs/design.md): a fronto-parallel grid seen from a
// camera translated along x, enough for F-RANSAC to find inliers.
#pragma once

#include "dyncull/core/types.hpp"

#include <vector>

namespace mixing {

inline void make_points(std::vector<dyncull::Vec2<double>>* a, std::vector<dyncull::Vec2<double>>* b) {
  for (int i = 0; i < 40; ++i) {
    const double x = 10.0 * (i % 7), y = 9.0 * (i / 7), z = 2.0 + 0.1 * (i % 5);
    a->emplace_back(500.0 * x / (10.0 * z) + 320.0, 500.0 * y / (10.0 * z) + 240.0);
    b->emplace_back(500.0 * (x + 1.0) / (10.0 * z) + 320.0, 500.0 * y / (10.0 * z) + 240.0);
  }
}

}  // namespace mixing
