// Each stage of the culling pipeline (culling/stages/*.hpp) alone on one realistic frame (about 1000
// features, 5 boxes, 640x480 depth; pipeline_fixture.hpp), float: the recommended preset given 3-D points
// and track ids, with the multi-view check verifying its candidates (one stored keyframe), and the
// probability switched on for its own case only (its decisions leave the multi-view check no candidates).
// The earlier stages run once before the timed loop; the loop repeats only the stage named.
#include "dyncull/culling/stages/boxes.hpp"
#include "dyncull/culling/stages/combine.hpp"
#include "dyncull/culling/stages/context.hpp"
#include "dyncull/culling/stages/geometric.hpp"
#include "dyncull/culling/stages/inputs.hpp"
#include "dyncull/culling/stages/listed.hpp"
#include "dyncull/culling/stages/multiview.hpp"
#include "dyncull/culling/stages/probability.hpp"
#include "dyncull/culling/stages/region_votes.hpp"
#include "dyncull/culling/stages/semantic.hpp"
#include "dyncull/culling/presets.hpp"

#include "culling/pipeline_fixture.hpp"

#include <benchmark/benchmark.h>

#include <vector>

namespace {
using namespace dyncull;

enum class Stage { Inputs = 0, Boxes, Semantic, Geometric, Probability, RegionVotes, MultiView, Combine };

PipelineOptions<float> options_for(Stage stage) {
  PipelineOptions<float> o = presets::recommended<float>();
  o.multiview.enabled = true;
  o.probability.enabled = stage == Stage::Probability;
  return o;
}

/// One frame's context, the stages before `upto` already run on it.
struct StageRun {
  const bench::PipelineBenchData& d = bench::pipeline_bench_data();
  const CullingFrame<float, std::vector<Vec2<float>>> frame = bench::pipeline_bench_frame(d, true, true);
  const PipelineOptions<float> o;
  PipelineState<float> state;
  detail::PipelineWork<float>& w = detail::work_of(&state);
  PipelineResult<float>& r = state.result;

  explicit StageRun(Stage upto) : o(options_for(upto)) {
    state.keyframes.push(d.keyframe.cam_from_world, d.keyframe.keypoints, d.keyframe.depth_m);
    for (int k = 0; k < static_cast<int>(upto); ++k) run(static_cast<Stage>(k));
  }
  void run(Stage stage) {
    switch (stage) {
      case Stage::Inputs:
        detail::begin_frame(o, &r);
        detail::accept_inputs(frame, o, &r);
        break;
      case Stage::Boxes: detail::collect_boxes(frame, o, &state.tracker, &w.regions, &r); break;
      case Stage::Semantic: detail::classify_by_boxes(frame, o, w.regions, &w.semantic, &r); break;
      case Stage::Geometric:
        detail::gather_geometric_evidence(frame, o, w.regions, w.semantic, &w.geometric, &r);
        break;
      case Stage::Probability:
        detail::score_probability(frame, o, w.regions, w.semantic, w.geometric, &state.track_states, &w.probability,
                                  &r);
        break;
      case Stage::RegionVotes:
        detail::vote_regions(frame, o, 1, w.regions, w.semantic, w.semantic_labels(), w.geometric,
                             &state.subbox_memory, &w.votes, &r);
        break;
      case Stage::MultiView:
        detail::run_listed_stage(frame, o, detail::StageContext<float>{w, state.keyframes},
                                   &w.marks_of<MultiViewStage<float>>(), &r);
        break;
      case Stage::Combine:
        detail::combine_evidence(o, w, &r);
        detail::apply_static_history(frame, o, w.geometric, &state.static_history, &w.still_frames,
                                     &w.history_kept, &r);
        detail::guard_survivors(o, &r);
        detail::trace_features(w, &r);
        break;
    }
  }
};

void run_stage(benchmark::State& bm, Stage stage, const StageReport* (*report)(const PipelineResult<float>&)) {
  StageRun s(stage);
  for (auto _ : bm) {
    s.run(stage);
    benchmark::DoNotOptimize(s.r.labels.data());
  }
  // Counts of one run of the stage (repeated runs add to a report that the frame's first stage resets).
  StageRun once(stage);
  once.run(stage);
  bm.counters["features"] = double(once.r.num_features);
  bm.counters["boxes"] = double(once.w.regions.boxes.size());
  bm.counters["culled"] = double(once.r.num_dynamic);  // set by the combination stage
  if (report) {
    bm.counters["ran"] = report(once.r)->ran();
    bm.counters["dynamic"] = double(report(once.r)->num_dynamic);
  }
}

void BM_Stage_Inputs(benchmark::State& bm) { run_stage(bm, Stage::Inputs, nullptr); }
BENCHMARK(BM_Stage_Inputs)->Unit(benchmark::kMicrosecond);

// Detection filter and box tracker (the same boxes every iteration: matched, none carried).
void BM_Stage_Boxes(benchmark::State& bm) {
  run_stage(bm, Stage::Boxes, [](const PipelineResult<float>& r) { return &r.tracker; });
}
BENCHMARK(BM_Stage_Boxes)->Unit(benchmark::kMicrosecond);

// Box rule, robust depth masks, overlaps assigned and low-level shelters checked by depth.
void BM_Stage_Semantic(benchmark::State& bm) {
  run_stage(bm, Stage::Semantic, [](const PipelineResult<float>& r) { return &r.depth_mask; });
}
BENCHMARK(BM_Stage_Semantic)->Unit(benchmark::kMicrosecond);

// Epipolar check (F-RANSAC outside the boxes) and reprojection check (PnP-RANSAC), depth-edge discount.
void BM_Stage_Geometric(benchmark::State& bm) {
  run_stage(bm, Stage::Geometric, [](const PipelineResult<float>& r) { return &r.reprojection; });
}
BENCHMARK(BM_Stage_Geometric)->Unit(benchmark::kMicrosecond);

void BM_Stage_Probability(benchmark::State& bm) {
  run_stage(bm, Stage::Probability, [](const PipelineResult<float>& r) { return &r.probability; });
}
BENCHMARK(BM_Stage_Probability)->Unit(benchmark::kMicrosecond);

// Coherent cells (when on in the preset) and the sub-box vote.
void BM_Stage_RegionVotes(benchmark::State& bm) {
  run_stage(bm, Stage::RegionVotes, [](const PipelineResult<float>& r) { return &r.subbox; });
}
BENCHMARK(BM_Stage_RegionVotes)->Unit(benchmark::kMicrosecond);

// Against one stored keyframe (600 points), the region grown over the whole depth image.
void BM_Stage_MultiView(benchmark::State& bm) {
  run_stage(bm, Stage::MultiView, [](const PipelineResult<float>& r) { return &r.multiview; });
}
BENCHMARK(BM_Stage_MultiView)->Unit(benchmark::kMicrosecond);

// Combination, static history, survivor guard and trace.
void BM_Stage_Combine(benchmark::State& bm) {
  run_stage(bm, Stage::Combine, [](const PipelineResult<float>& r) { return &r.static_history; });
}
BENCHMARK(BM_Stage_Combine)->Unit(benchmark::kMicrosecond);

}  // namespace
