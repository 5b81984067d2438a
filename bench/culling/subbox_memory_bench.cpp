// The last sub-box vote of 5 tracked boxes kept and recalled for a frame whose baseline is too short to vote:
// remember_states + recall_states + apply_subbox_states on 1100 features. There is no peer: the figure to
// compare with is the pipeline's own cost (pipeline_bench, about 0.25-0.45 ms a frame).
#include "dyncull/culling/subbox_memory.hpp"

#include <benchmark/benchmark.h>

#include <cstdint>
#include <vector>

namespace {
using namespace dyncull;

void BM_SubBoxMemory_LastVoteFrame(benchmark::State& state) {
  constexpr std::size_t kPoints = 1100, kBoxes = 5;
  std::vector<Vec2<float>> points(kPoints);
  std::vector<FeatureLabel> geometric(kPoints, FeatureLabel::Static);
  for (std::size_t i = 0; i < kPoints; ++i) {
    points[i] = Vec2<float>(float((i * 53) % 640), float((i * 29) % 480));
    if (i % 7 == 0) geometric[i] = FeatureLabel::Dynamic;
  }
  std::vector<Box<float>> boxes;
  for (std::size_t b = 0; b < kBoxes; ++b)
    boxes.push_back(Box<float>{float(b * 120), 60.f, float(b * 120 + 140), 460.f});
  const std::vector<std::int64_t> ids = {1, 2, 3, 4, 5};
  SubBoxResult<float> votes;
  votes.cells.assign(kBoxes * 9, 0);
  votes.dyn_count.assign(kBoxes * 9, 0);
  votes.static_count.assign(kBoxes * 9, 3);
  for (std::size_t b = 0; b < kBoxes; ++b) votes.cells[b * 9] = 1;
  const SubBoxOptions<float> options;
  SubBoxMemory memory;
  SubBoxResult<float> out;
  std::vector<std::uint8_t> states;
  std::uint64_t frame = 0;
  for (auto _ : state) {
    ++frame;
    memory.remember_states(ids, votes, options, frame, 2);
    memory.recall_states(ids, 3, frame + 1, 2, &states);
    apply_subbox_states(points, geometric, boxes, states, options, &out);
    benchmark::DoNotOptimize(out.labels.data());
  }
  state.counters["dynamic"] = double(out.num_dynamic);
}
BENCHMARK(BM_SubBoxMemory_LastVoteFrame)->Unit(benchmark::kMicrosecond);
}  // namespace
