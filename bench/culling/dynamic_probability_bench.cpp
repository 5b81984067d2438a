// Dynamic probability (DLD-SLAM eq. 3-5) at 1000 features, 5 boxes' worth of masked features.
// Baseline: the paper's plain loop (mean flow of static features, fixed t) to show what the
// robust median/MAD threshold and the track store cost on top.
#include "dyncull/culling/dynamic_probability.hpp"
#include "dyncull/core/random.hpp"

#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

namespace {
using namespace dyncull;

struct Data {
  std::vector<Vec2<float>> prev, curr;
  std::vector<MotionLevel> levels;
  std::vector<std::int64_t> ids;
  std::size_t movers = 0;
};

// 700 background features, 300 in five masks (3 people, 1 chair, 1 tv); 2 of the people walk.
Data make() {
  Random rng(4);
  Data d;
  const MotionLevel mask_level[5] = {MotionLevel::High, MotionLevel::High, MotionLevel::High, MotionLevel::Medium,
                                     MotionLevel::Low};
  for (int i = 0; i < 1000; ++i) {
    const Vec2<float> p(float(rng.uniform(0, 640)), float(rng.uniform(0, 480)));
    Vec2<float> flow(2.f + 0.3f * float(rng.normal()), 1.f + 0.3f * float(rng.normal()));
    MotionLevel l = MotionLevel::Ignore;
    if (i >= 700) {
      const int m = (i - 700) / 60;
      l = mask_level[m];
      if (m < 2) {
        flow.x() += 5.f;
        ++d.movers;
      }
    }
    d.prev.push_back(p);
    d.curr.push_back(p + flow);
    d.levels.push_back(l);
    d.ids.push_back(i);
  }
  return d;
}

void BM_DynamicProbability_MeanFlow(benchmark::State& state) {
  const Data d = make();
  const DynamicProbabilityOptions<float> o;
  TrackStateStore store(1);
  std::size_t dyn = 0;
  for (auto _ : state) {
    store.begin_frame();
    const auto r = dynamic_probability(d.prev, d.curr, d.levels, o, EgoMotion<float>{}, &store, &d.ids);
    dyn = r.num_dynamic;
    benchmark::DoNotOptimize(r.labels.data());
  }
  state.counters["dynamic"] = double(dyn);
  state.counters["true_movers"] = double(d.movers);
}
BENCHMARK(BM_DynamicProbability_MeanFlow)->Unit(benchmark::kMicrosecond);

void BM_DynamicProbability_MeanFlowNoTrackStore(benchmark::State& state) {
  const Data d = make();
  const DynamicProbabilityOptions<float> o;
  std::size_t dyn = 0;
  for (auto _ : state) {
    const auto r = dynamic_probability(d.prev, d.curr, d.levels, o);
    dyn = r.num_dynamic;
    benchmark::DoNotOptimize(r.labels.data());
  }
  state.counters["dynamic"] = double(dyn);
}
BENCHMARK(BM_DynamicProbability_MeanFlowNoTrackStore)->Unit(benchmark::kMicrosecond);

void BM_DynamicProbability_Fundamental(benchmark::State& state) {
  const Data d = make();
  const DynamicProbabilityOptions<float> o;
  EgoMotion<float> e;
  e.model = FlowModel::Fundamental;
  // Pure vertical translation (K = I): epipolar lines are columns, so horizontal walkers are off them.
  e.matrix << 0, 0, 1, 0, 0, 0, -1, 0, 0;
  std::size_t dyn = 0;
  for (auto _ : state) {
    const auto r = dynamic_probability(d.prev, d.curr, d.levels, o, e);
    dyn = r.num_dynamic;
    benchmark::DoNotOptimize(r.labels.data());
  }
  state.counters["dynamic"] = double(dyn);
}
BENCHMARK(BM_DynamicProbability_Fundamental)->Unit(benchmark::kMicrosecond);

// Baseline: DLD-SLAM eq. 4-5 literally (mean of static flow, fixed t = 1.5 px, no K).
void BM_DynamicProbability_PlainLoopBaseline(benchmark::State& state) {
  const Data d = make();
  std::vector<std::uint8_t> dynamic(d.prev.size());
  std::size_t dyn = 0;
  for (auto _ : state) {
    Vec2<float> mean = Vec2<float>::Zero();
    int n = 0;
    for (std::size_t i = 0; i < d.prev.size(); ++i)
      if (d.levels[i] == MotionLevel::Ignore) {
        mean += d.curr[i] - d.prev[i];
        ++n;
      }
    mean /= float(n > 0 ? n : 1);
    dyn = 0;
    for (std::size_t i = 0; i < d.prev.size(); ++i) {
      const bool m = (d.curr[i] - d.prev[i] - mean).norm() > 1.5f;
      const float p = 0.4f * motion_level_score<float>(d.levels[i]) + 0.4f * float(m);
      dynamic[i] = d.levels[i] != MotionLevel::Ignore && p >= 0.55f;
      dyn += dynamic[i];
    }
    benchmark::DoNotOptimize(dynamic.data());
  }
  state.counters["dynamic"] = double(dyn);
}
BENCHMARK(BM_DynamicProbability_PlainLoopBaseline)->Unit(benchmark::kMicrosecond);
}  // namespace
