// Heap allocations of cull_frame per frame after warm-up, for the recommended preset and each paper's, as
// Google Benchmark counters (the figures of docs/benchmarks.md come from this binary's JSON). The sequence
// is that of tests/culling/pipeline_allocations_test.cpp: three frames of the synthetic culling scene with
// 3-D points and track ids, a keyframe ring of two slots, replayed; the timed rounds follow three warm-up
// rounds. A binary of its own: the counting operator new replaces allocation for the whole executable, and
// the timing benches (and their OpenCV peers) should not pay for the count.
#include "dyncull/culling/pipeline.hpp"
#include "dyncull/culling/presets.hpp"

#include "support/allocation_sequence.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace {
using namespace dyncull;

const std::vector<test::AllocationFrame>& sequence() {
  static const std::vector<test::AllocationFrame> seq = test::allocation_sequence();
  return seq;
}

struct Preset {
  const char* name;
  PipelineOptions<float> (*make)();
};
const Preset kPresets[] = {{"recommended", &presets::recommended<float>}, {"dfd_slam", &presets::dfd_slam<float>},
                           {"dld_slam", &presets::dld_slam<float>},       {"rtd_slam", &presets::rtd_slam<float>},
                           {"zhu_2024", &presets::zhu_2024<float>},       {"zhang_2023", &presets::zhang_2023<float>}};

/// Counters: `allocs_per_frame` = the most any frame made after warm-up (the figure the test bounds),
/// `allocs_mean` = their mean.
void BM_Allocations(benchmark::State& bstate) {
  const Preset& preset = kPresets[bstate.range(0)];
  const PipelineOptions<float> options = preset.make();
  const std::vector<test::AllocationFrame>& seq = sequence();
  PipelineState<float> state(2);  // two keyframe slots: full, and their buffers reused, before the count
  for (int round = 0; round < 3; ++round) test::count_allocations_round(seq, options, &state, nullptr);
  std::vector<std::size_t> counts;
  counts.reserve(1 << 16);
  for (auto _ : bstate) {
    if (counts.size() + seq.size() > counts.capacity()) counts.clear();
    test::count_allocations_round(seq, options, &state, &counts);
  }
  std::size_t most = 0, sum = 0;
  for (std::size_t c : counts) {
    most = std::max(most, c);
    sum += c;
  }
  bstate.counters["allocs_per_frame"] = double(most);
  bstate.counters["allocs_mean"] = counts.empty() ? 0.0 : double(sum) / double(counts.size());
  bstate.SetLabel(preset.name);
}
BENCHMARK(BM_Allocations)->DenseRange(0, 5)->Unit(benchmark::kMicrosecond);

}  // namespace
