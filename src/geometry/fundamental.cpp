// The fundamental-matrix solvers without a template parameter, and F-RANSAC / 8-point for the pipeline's
// point containers, compiled once for dyncull::pipeline (geometry/fundamental.hpp declares them when a
// translation unit defines DYNCULL_PRECOMPILED).
#ifndef DYNCULL_PRECOMPILED
#define DYNCULL_PRECOMPILED 1
#endif
#define DYNCULL_FUNDAMENTAL_SOURCE 1
#include "dyncull/geometry/fundamental.hpp"

#include <vector>

namespace dyncull {

template FundamentalResult<float> estimate_fundamental_ransac(const std::vector<Vec2<float>>&,
                                                              const std::vector<Vec2<float>>&,
                                                              const FundamentalOptions<float>&);
template FundamentalResult<double> estimate_fundamental_ransac(const std::vector<Vec2<double>>&,
                                                               const std::vector<Vec2<double>>&,
                                                               const FundamentalOptions<double>&);
template FundamentalResult<float> fundamental_8point(const std::vector<Vec2<float>>&, const std::vector<Vec2<float>>&);
template FundamentalResult<double> fundamental_8point(const std::vector<Vec2<double>>&,
                                                      const std::vector<Vec2<double>>&);
template void estimate_fundamental_ransac(const std::vector<Vec2<float>>&, const std::vector<Vec2<float>>&,
                                          const FundamentalOptions<float>&, FundamentalWorkspace<float>*,
                                          FundamentalResult<float>*);
template void estimate_fundamental_ransac(const std::vector<Vec2<double>>&, const std::vector<Vec2<double>>&,
                                          const FundamentalOptions<double>&, FundamentalWorkspace<double>*,
                                          FundamentalResult<double>*);
template void fundamental_8point(const std::vector<Vec2<float>>&, const std::vector<Vec2<float>>&,
                                 FundamentalWorkspace<float>*, FundamentalResult<float>*);
template void fundamental_8point(const std::vector<Vec2<double>>&, const std::vector<Vec2<double>>&,
                                 FundamentalWorkspace<double>*, FundamentalResult<double>*);

}  // namespace dyncull
