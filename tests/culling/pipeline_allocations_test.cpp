// Counts the heap allocations cull_frame makes per frame after warm-up, for the recommended preset and
// each paper's, on a synthetic sequence (a counting global operator new in this executable only).
#include "dyncull/culling/pipeline.hpp"
#include "dyncull/culling/presets.hpp"

#include "support/culling_frames.hpp"
#include "support/culling_scenes.hpp"

#include "support/counting_allocator.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <vector>

namespace dyncull {
namespace {

struct Frame {
  test::CullingScene<float> scene;
  std::vector<Detection<float>> detections;
  std::vector<std::int64_t> ids;
};

/// Allocations of each frame after `warmup` frames of the same sequence replayed (same sizes each round).
std::vector<std::size_t> allocations_per_frame(const PipelineOptions<float>& options, const std::vector<Frame>& seq,
                                               int warmup_rounds) {
  // Two keyframe slots: the ring is full, and its slots' buffers reused, before the counted round.
  PipelineState<float> state(2);
  std::vector<std::size_t> counts;
  for (int round = 0; round <= warmup_rounds; ++round) {
    for (std::size_t k = 0; k < seq.size(); ++k) {
      const Frame& f = seq[k];
      auto frame = test::frame_of(f.scene, f.detections);
      frame.track_ids = &f.ids;
      frame.points_3d = &f.scene.prev_points_world;
      frame.is_keyframe = k == 0;
      frame.evidence_frames = 2;
      const std::size_t before = test::allocations();
      cull_frame(frame, options, &state);
      if (round == warmup_rounds) counts.push_back(test::allocations() - before);
    }
  }
  return counts;
}

TEST(PipelineAllocations, PerFrameAfterWarmUpStayWithinEachPresetsBound) {
  std::vector<Frame> seq;
  for (int k = 0; k < 3; ++k) {
    test::SceneConfig config;
    config.seed = 300 + static_cast<std::uint64_t>(k);
    Frame f;
    f.scene = test::make_culling_scene<float>(config);
    for (const auto& d : f.scene.detections) f.detections.push_back(d);
    for (std::size_t i = 0; i < f.scene.size(); ++i) f.ids.push_back(static_cast<std::int64_t>(i));
    seq.push_back(std::move(f));
  }
  // Bounds at what the pipeline reaches; the allocations left are listed in docs/design.md (the geometric
  // checks' solvers, new ids in the track store, and the frame's reason when a stage lacks an input).
  // dld_slam's are the ids frame 0 has and frame 2 lacks: 6 with g++, 8 with clang (the scene's sampling).
  struct Named {
    const char* name;
    PipelineOptions<float> options;
    std::size_t most_allowed;
  };
  const Named all[] = {{"recommended", presets::recommended<float>(), 63}, {"dld_slam", presets::dld_slam<float>(), 8},
                       {"rtd_slam", presets::rtd_slam<float>(), 1},       {"zhu_2024", presets::zhu_2024<float>(), 0},
                       {"dfd_slam", presets::dfd_slam<float>(), 51},      {"zhang_2023", presets::zhang_2023<float>(), 0}};
  for (const Named& p : all) {
    const std::vector<std::size_t> counts = allocations_per_frame(p.options, seq, 3);
    std::size_t most = 0;
    for (std::size_t c : counts) most = std::max(most, c);
    std::printf("%-12s allocations per frame after warm-up: at most %zu (frames:", p.name, most);
    for (std::size_t c : counts) std::printf(" %zu", c);
    std::printf(")\n");
    RecordProperty(p.name, static_cast<int>(most));
    for (std::size_t k = 0; k < counts.size(); ++k) EXPECT_LE(counts[k], p.most_allowed) << p.name << " frame " << k;
  }
}

}  // namespace
}  // namespace dyncull
