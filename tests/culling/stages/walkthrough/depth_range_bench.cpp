// The depth-range stage of docs/design.md, "Adding a stage", on 1000 box-labelled features over a
// 640 x 480 depth image, float, against the same test written with Eigen (gathered depths compared as
// an array) in the same binary.
#include "dyncull/culling/pipeline.hpp"
#include "dyncull/culling/stages/depth_range.hpp"

#include <Eigen/Core>
#include <benchmark/benchmark.h>

#include <cstddef>
#include <vector>

namespace {
using namespace dyncull;

struct Scene {
  std::vector<Vec2<float>> keypoints;
  std::vector<float> depth;
  Scene() : depth(640 * 480) {
    for (std::size_t p = 0; p < depth.size(); ++p) depth[p] = (p % 640) < 320 ? 2.f : 9.f;
    for (int i = 0; i < 1000; ++i) keypoints.emplace_back(float((i * 13) % 640), float((i * 7) % 480));
  }
};

void BM_Stage_DepthRange(benchmark::State& bm) {
  const Scene scene;
  CullingFrame<float, std::vector<Vec2<float>>> frame;
  frame.keypoints = &scene.keypoints;
  frame.depth = DepthView<float>{scene.depth.data(), 640, 480};
  PipelineOptions<float> o;
  o.depth_range.enabled = true;
  PipelineState<float> state;
  detail::PipelineWork<float>& w = detail::work_of(&state);
  w.semantic.labels.assign(scene.keypoints.size(), FeatureLabel::Dynamic);
  PipelineResult<float>& r = state.result;
  detail::begin_frame(o, &r);
  r.num_features = scene.keypoints.size();
  const detail::StageContext<float> context{w, state.keyframes};
  auto& marks = w.marks_of<DepthRangeStage<float>>();
  for (auto _ : bm) {
    detail::run_listed_stage(frame, o, context, &marks, &r);
    benchmark::DoNotOptimize(marks.marks.data());
  }
}
BENCHMARK(BM_Stage_DepthRange)->Unit(benchmark::kMicrosecond);

void BM_Eigen_DepthRange(benchmark::State& bm) {
  const Scene scene;
  const Eigen::Map<const Eigen::Array2Xf> kp(scene.keypoints[0].data(), 2, long(scene.keypoints.size()));
  const Eigen::Map<const Eigen::ArrayXXf> depth(scene.depth.data(), 640, 480);  // column u, row v
  Eigen::ArrayXf at(kp.cols());
  Eigen::Array<bool, Eigen::Dynamic, 1> off(kp.cols());
  for (auto _ : bm) {
    for (Eigen::Index i = 0; i < kp.cols(); ++i) at(i) = depth(Eigen::Index(kp(0, i)), Eigen::Index(kp(1, i)));
    off = at > 6.f;
    benchmark::DoNotOptimize(off.data());
  }
  bm.counters["off_object"] = double(off.count());
}
BENCHMARK(BM_Eigen_DepthRange)->Unit(benchmark::kMicrosecond);

}  // namespace
