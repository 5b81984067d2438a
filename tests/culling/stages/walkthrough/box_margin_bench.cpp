// The box-margin stage of docs/design.md, "Adding a stage", on 1000 features and 4 person boxes, float,
// against the same test written with Eigen (array comparisons per box) in the same binary.
#include "dyncull/culling/pipeline.hpp"
#include "dyncull/culling/stages/box_margin.hpp"

#include <Eigen/Core>
#include <benchmark/benchmark.h>

#include <cstddef>
#include <vector>

namespace {
using namespace dyncull;

struct People {
  std::vector<Vec2<float>> keypoints;
  std::vector<Detection<float>> boxes;
  People() {
    for (int i = 0; i < 1000; ++i) keypoints.emplace_back(float((i * 13) % 640), float((i * 7) % 480));
    for (int k = 0; k < 4; ++k) boxes.push_back({Box<float>{60.f + 140.f * k, 80.f, 140.f + 140.f * k, 400.f}, 0, 0.9f});
  }
};

void BM_Stage_BoxMargin(benchmark::State& bm) {
  const People people;
  CullingFrame<float, std::vector<Vec2<float>>> frame;
  frame.keypoints = &people.keypoints;
  frame.detections = &people.boxes;
  PipelineOptions<float> o;
  o.box_margin.enabled = true;
  PipelineState<float> state;
  detail::PipelineWork<float>& w = detail::work_of(&state);
  w.regions.dyn_boxes = people.boxes;
  PipelineResult<float>& r = state.result;
  detail::begin_frame(o, &r);
  r.num_features = people.keypoints.size();
  const detail::StageContext<float> context{w, state.keyframes};
  auto& marks = w.marks_of<BoxMarginStage<float>>();
  for (auto _ : bm) {
    r.box_margin.num_dynamic = 0;
    detail::run_listed_stage(frame, o, context, &marks, &r);
    benchmark::DoNotOptimize(marks.marks.data());
  }
}
BENCHMARK(BM_Stage_BoxMargin)->Unit(benchmark::kMicrosecond);

void BM_Eigen_BoxMargin(benchmark::State& bm) {
  const People people;
  const Eigen::Map<const Eigen::Array2Xf> kp(people.keypoints[0].data(), 2, long(people.keypoints.size()));
  Eigen::Array<bool, 1, Eigen::Dynamic> candidate(kp.cols());
  const float margin = 12.f;
  for (auto _ : bm) {
    candidate.setConstant(false);
    for (const Detection<float>& d : people.boxes) {
      const Box<float>& b = d.box;
      const auto inside = kp.row(0) >= b.x0 && kp.row(0) <= b.x1 && kp.row(1) >= b.y0 && kp.row(1) <= b.y1;
      const auto near = kp.row(0) >= b.x0 - margin && kp.row(0) <= b.x1 + margin && kp.row(1) >= b.y0 - margin &&
                        kp.row(1) <= b.y1 + margin;
      candidate = candidate || (near && !inside);
    }
    benchmark::DoNotOptimize(candidate.data());
  }
  bm.counters["candidates"] = double(candidate.count());
}
BENCHMARK(BM_Eigen_BoxMargin)->Unit(benchmark::kMicrosecond);

}  // namespace
