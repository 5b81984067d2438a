// The sequence on which cull_frame's heap allocations per frame are counted, shared by the allocation
// test (tests/culling/pipeline_allocations_test.cpp, which bounds them) and the allocation bench
// (bench/culling/allocations_bench.cpp, which reports them): three frames of the synthetic culling scene
// with 3-D points and track ids, the first a keyframe, replayed round after round. Needs the counting
// operator new of counting_allocator.hpp in the same executable.
#pragma once

#include "dyncull/culling/pipeline.hpp"

#include "support/counting_allocator.hpp"
#include "support/culling_frames.hpp"
#include "support/culling_scenes.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace dyncull {
namespace test {

struct AllocationFrame {
  CullingScene<float> scene;
  std::vector<Detection<float>> detections;
  std::vector<std::int64_t> ids;
};

inline std::vector<AllocationFrame> allocation_sequence() {
  std::vector<AllocationFrame> seq;
  for (int k = 0; k < 3; ++k) {
    SceneConfig config;
    config.seed = 300 + static_cast<std::uint64_t>(k);
    AllocationFrame f;
    f.scene = make_culling_scene<float>(config);
    for (const auto& d : f.scene.detections) f.detections.push_back(d);
    for (std::size_t i = 0; i < f.scene.size(); ++i) f.ids.push_back(static_cast<std::int64_t>(i));
    seq.push_back(std::move(f));
  }
  return seq;
}

/// One round over the sequence; appends each frame's allocation count to `counts` when it is given.
inline void count_allocations_round(const std::vector<AllocationFrame>& seq, const PipelineOptions<float>& options,
                                    PipelineState<float>* state, std::vector<std::size_t>* counts) {
  for (std::size_t k = 0; k < seq.size(); ++k) {
    const AllocationFrame& f = seq[k];
    auto frame = frame_of(f.scene, f.detections);
    frame.track_ids = &f.ids;
    frame.points_3d = &f.scene.prev_points_world;
    frame.is_keyframe = k == 0;
    frame.evidence_frames = 2;
    const std::size_t before = allocations();
    cull_frame(frame, options, state);
    const std::size_t n = allocations() - before;
    if (counts) counts->push_back(n);
  }
}

}  // namespace test
}  // namespace dyncull
