// The large-displacement stage of docs/design.md, "Adding a stage", on 1000 tracks, float, against the
// same test written with Eigen (column norms of the displacements) in the same binary.
#include "dyncull/culling/pipeline.hpp"
#include "dyncull/culling/stages/large_displacement.hpp"

#include <Eigen/Core>
#include <benchmark/benchmark.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace {
using namespace dyncull;

struct Tracks {
  std::vector<Vec2<float>> keypoints, prev;
  explicit Tracks(int n) {
    for (int i = 0; i < n; ++i) {
      const Vec2<float> p(float(i % 640), float((i * 7) % 480));
      keypoints.push_back(p);
      prev.push_back(p - Vec2<float>(i % 50 == 0 ? 60.f : 2.f, 1.f));
    }
  }
};

void BM_Stage_LargeDisplacement(benchmark::State& bm) {
  const Tracks tracks(1000);
  CullingFrame<float, std::vector<Vec2<float>>> frame;
  frame.keypoints = &tracks.keypoints;
  frame.prev_keypoints = &tracks.prev;
  PipelineOptions<float> o;
  o.large_displacement.enabled = true;
  PipelineState<float> state;
  detail::PipelineWork<float>& w = detail::work_of(&state);
  PipelineResult<float>& r = state.result;
  detail::begin_frame(o, &r);
  r.num_features = tracks.keypoints.size();
  const detail::StageContext<float> context{w, state.keyframes};
  auto& flags = w.marks_of<LargeDisplacementStage<float>>();
  for (auto _ : bm) {
    r.large_displacement.num_dynamic = 0;
    detail::run_listed_stage(frame, o, context, &flags, &r);
    benchmark::DoNotOptimize(flags.marks.data());
  }
  bm.counters["flagged"] = double(r.large_displacement.num_dynamic);
}
BENCHMARK(BM_Stage_LargeDisplacement)->Unit(benchmark::kMicrosecond);

void BM_Eigen_LargeDisplacement(benchmark::State& bm) {
  const Tracks tracks(1000);
  const Eigen::Map<const Eigen::Matrix2Xf> now(tracks.keypoints[0].data(), 2, long(tracks.keypoints.size()));
  const Eigen::Map<const Eigen::Matrix2Xf> before(tracks.prev[0].data(), 2, long(tracks.prev.size()));
  Eigen::Array<bool, 1, Eigen::Dynamic> flagged(now.cols());
  for (auto _ : bm) {
    flagged = (now - before).colwise().squaredNorm().array() > 40.f * 40.f;
    benchmark::DoNotOptimize(flagged.data());
  }
  bm.counters["flagged"] = double(flagged.count());
}
BENCHMARK(BM_Eigen_LargeDisplacement)->Unit(benchmark::kMicrosecond);

}  // namespace
