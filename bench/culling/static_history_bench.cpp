// Static history bookkeeping for one frame: 1100 tracks (5 % replaced by new ones each frame, as a front end
// loses and detects features), a seventh of them flagged. There is no peer: the figure to compare with is the
// pipeline's own cost (pipeline_bench, BM_Pipeline_RecommendedWithPointsAndIds runs it inside the preset).
#include "dyncull/culling/static_history.hpp"

#include <benchmark/benchmark.h>

#include <cstdint>
#include <utility>
#include <vector>

namespace {
using namespace dyncull;

// arg 0: tracks in creation order, as a front end keeps them (5 % dropped, as many new ids appended).
// arg 1: new ids written over lost ones in place. arg 2: the ids in an order unrelated to their values, as
// the culler gives them (keypoint order, a matched keypoint taking its keyframe point's id).
void BM_StaticHistory_Update(benchmark::State& state) {
  constexpr std::size_t kTracks = 1100;
  const bool in_place = state.range(0) == 1, shuffled = state.range(0) == 2;
  std::vector<std::int64_t> ids(kTracks);
  for (std::size_t i = 0; i < kTracks; ++i) ids[i] = static_cast<std::int64_t>(i);
  std::vector<FeatureLabel> labels(kTracks, FeatureLabel::Static);
  std::vector<float> residuals(kTracks, 0.3f);
  for (std::size_t i = 0; i < kTracks; i += 7) {
    labels[i] = FeatureLabel::Dynamic;
    residuals[i] = 3.f;
  }
  StaticHistory history;
  std::vector<std::uint16_t> counts;
  std::uint64_t frame = 0;
  std::int64_t next_id = static_cast<std::int64_t>(kTracks);
  for (auto _ : state) {
    ++frame;
    if (in_place || shuffled) {
      for (std::size_t k = 0; k < kTracks / 20; ++k) ids[(frame * 37 + k * 19) % kTracks] = next_id++;
      if (shuffled)
        for (std::size_t i = kTracks - 1; i > 0; --i) std::swap(ids[i], ids[(i * 7919 + frame) % (i + 1)]);
    } else {
      // Every 20th track lost (the erase keeps the order), as many new ones appended.
      std::size_t w = 0;
      for (std::size_t i = 0; i < kTracks; ++i)
        if ((i + frame) % 20 != 0) ids[w++] = ids[i];
      while (w < kTracks) ids[w++] = next_id++;
    }
    history.update(ids, labels, residuals, true, 0.8f, &counts);
    benchmark::DoNotOptimize(counts.data());
  }
  state.counters["tracks"] = double(history.num_tracks());
}
BENCHMARK(BM_StaticHistory_Update)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);
}  // namespace
