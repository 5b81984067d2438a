// cull_frame for T = double on the precompiled frame types (culling/pipeline_extern.hpp), compiled once for
// dyncull::pipeline; one scalar per file keeps the library's peak compile memory near one instantiation's.
#ifndef DYNCULL_PRECOMPILED
#define DYNCULL_PRECOMPILED 1
#endif
#include "dyncull/culling/pipeline.hpp"

#include <cstdint>

namespace dyncull {

template const PipelineResult<double>& cull_frame(const PrecompiledCullingFrame<double, float>&,
                                                  const PipelineOptions<double>&, PipelineState<double>*);
template const PipelineResult<double>& cull_frame(const PrecompiledCullingFrame<double, std::uint16_t>&,
                                                  const PipelineOptions<double>&, PipelineState<double>*);

}  // namespace dyncull
