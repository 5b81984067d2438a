// Lambda Twist P3P (no template parameter) and PnP-RANSAC for the pipeline's point containers, compiled
// once for dyncull::pipeline (geometry/pnp.hpp declares them when a translation unit defines
// DYNCULL_PRECOMPILED).
#ifndef DYNCULL_PRECOMPILED
#define DYNCULL_PRECOMPILED 1
#endif
#define DYNCULL_PNP_SOURCE 1
#include "dyncull/geometry/pnp.hpp"

#include <vector>

namespace dyncull {

template PnpResult<float> solve_pnp_ransac(const std::vector<Vec3<float>>&, const std::vector<Vec2<float>>&,
                                           const PinholeCamera<float>&, const PnpOptions<float>&);
template PnpResult<double> solve_pnp_ransac(const std::vector<Vec3<double>>&, const std::vector<Vec2<double>>&,
                                            const PinholeCamera<double>&, const PnpOptions<double>&);
template void solve_pnp_ransac(const std::vector<Vec3<float>>&, const std::vector<Vec2<float>>&,
                               const PinholeCamera<float>&, const PnpOptions<float>&, PnpWorkspace<float>*,
                               PnpResult<float>*);
template void solve_pnp_ransac(const std::vector<Vec3<double>>&, const std::vector<Vec2<double>>&,
                               const PinholeCamera<double>&, const PnpOptions<double>&, PnpWorkspace<double>*,
                               PnpResult<double>*);

}  // namespace dyncull
