// cull_frame for T = float on the precompiled frame types (culling/pipeline_extern.hpp), compiled once for
// dyncull::pipeline; one scalar per file keeps the library's peak compile memory near one instantiation's.
#ifndef DYNCULL_PRECOMPILED
#define DYNCULL_PRECOMPILED 1
#endif
#include "dyncull/culling/pipeline.hpp"

#include <cstdint>

namespace dyncull {

template const PipelineResult<float>& cull_frame(const PrecompiledCullingFrame<float, float>&,
                                                 const PipelineOptions<float>&, PipelineState<float>*);
template const PipelineResult<float>& cull_frame(const PrecompiledCullingFrame<float, std::uint16_t>&,
                                                 const PipelineOptions<float>&, PipelineState<float>*);

}  // namespace dyncull
