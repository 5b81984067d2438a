/// @file pipeline_extern.hpp
/// The instantiations of cull_frame (culling/pipeline.hpp) compiled once into the dyncull::pipeline library:
/// the scalar float or double, keypoints and their previous positions as std::vector of Vec2, depth as metres
/// (float) or TUM/Kinect units (std::uint16_t), 3-D points as std::vector of Vec3. Build plumbing, no paper.
#pragma once

#include "dyncull/culling/pipeline.hpp"

#include <cstdint>
#include <vector>

namespace dyncull {

/// The frame types dyncull::pipeline instantiates cull_frame for (T float or double, Raw float or
/// std::uint16_t). Other frame types are instantiated header-only in the calling translation unit.
template <class T, class Raw>
using PrecompiledCullingFrame = CullingFrame<T, std::vector<Vec2<T>>, std::vector<Vec2<T>>, Raw, std::vector<Vec3<T>>>;

#if defined(DYNCULL_PRECOMPILED)
extern template const PipelineResult<float>& cull_frame(const PrecompiledCullingFrame<float, float>&,
                                                        const PipelineOptions<float>&, PipelineState<float>*);
extern template const PipelineResult<float>& cull_frame(const PrecompiledCullingFrame<float, std::uint16_t>&,
                                                        const PipelineOptions<float>&, PipelineState<float>*);
extern template const PipelineResult<double>& cull_frame(const PrecompiledCullingFrame<double, float>&,
                                                         const PipelineOptions<double>&, PipelineState<double>*);
extern template const PipelineResult<double>& cull_frame(const PrecompiledCullingFrame<double, std::uint16_t>&,
                                                         const PipelineOptions<double>&, PipelineState<double>*);
#endif

}  // namespace dyncull
