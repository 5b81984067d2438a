// One frame of culling at ~1000 features, 5 boxes, 640x480 depth: the recommended pipeline (box rule,
// depth mask, epipolar + sub-box, box tracker, guard), with the multi-view check added, and everything
// on (plus probability), against cv::calcOpticalFlowPyrLK on the same features (target: <= 0.05x of LK).
#include "dyncull/culling/pipeline.hpp"
#include "dyncull/culling/presets.hpp"

#include "culling/pipeline_fixture.hpp"

#include <benchmark/benchmark.h>

#include <vector>

#ifdef DYNCULL_HAS_OPENCV
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#endif

namespace {
using namespace dyncull;
using Data = bench::PipelineBenchData;

const Data& data() { return bench::pipeline_bench_data(); }

/// with_points: each track's 3-D point at the previous frame (the recommended preset's RGB-D input);
/// with_ids: a track id per feature (the sub-box memory's input).
void run_pipeline(benchmark::State& state, const PipelineOptions<float>& options, bool with_points = false,
                  bool with_ids = false) {
  const Data& d = data();
  PipelineState<float> st;
  st.keyframes.push(d.keyframe.cam_from_world, d.keyframe.keypoints, d.keyframe.depth_m);
  const auto frame = bench::pipeline_bench_frame(d, with_points, with_ids);
  std::size_t dyn = 0;
  for (auto _ : state) {
    const auto& r = cull_frame(frame, options, &st);
    dyn = r.num_dynamic;
    benchmark::DoNotOptimize(r.labels.data());
  }
  const auto& r = st.result;
  std::vector<std::uint8_t> pred(r.labels.size());
  for (std::size_t i = 0; i < pred.size(); ++i) pred[i] = r.labels[i] == FeatureLabel::Dynamic;
  const auto pr = test::precision_recall(pred, d.scene.truth_dynamic, pred.size());
  state.counters["features"] = double(pred.size());
  state.counters["boxes"] = double(d.dets.size());
  state.counters["dynamic"] = double(dyn);
  state.counters["precision"] = pr.precision;
  state.counters["recall"] = pr.recall;
  state.counters["multiview_ran"] = r.multiview.ran();
  state.counters["subbox_ran"] = r.subbox.ran();
  state.counters["reprojection_ran"] = r.reprojection.ran();
  state.counters["history_kept"] = double(r.history_kept);
}

void BM_Pipeline_Recommended(benchmark::State& state) { run_pipeline(state, presets::recommended<float>()); }
BENCHMARK(BM_Pipeline_Recommended)->Unit(benchmark::kMicrosecond);

// The same preset given 3-D points: the reprojection check replaces the epipolar labels (both run).
void BM_Pipeline_RecommendedWithPoints(benchmark::State& state) {
  run_pipeline(state, presets::recommended<float>(), true);
}
BENCHMARK(BM_Pipeline_RecommendedWithPoints)->Unit(benchmark::kMicrosecond);

// With points and track ids, as dynamic_vo runs the preset: its static history runs too (the same frame
// repeated, so from the 6th iteration on it keeps the tracks still in all of them).
void BM_Pipeline_RecommendedWithPointsAndIds(benchmark::State& state) {
  run_pipeline(state, presets::recommended<float>(), true, true);
}
BENCHMARK(BM_Pipeline_RecommendedWithPointsAndIds)->Unit(benchmark::kMicrosecond);

// The multi-view check (left out of the recommended preset) on top.
void BM_Pipeline_RecommendedPlusMultiView(benchmark::State& state) {
  PipelineOptions<float> o = presets::recommended<float>();
  o.multiview.enabled = true;
  run_pipeline(state, o);
}
BENCHMARK(BM_Pipeline_RecommendedPlusMultiView)->Unit(benchmark::kMicrosecond);

void BM_Pipeline_AllStrategies(benchmark::State& state) {
  PipelineOptions<float> o = presets::recommended<float>();
  o.multiview.enabled = true;
  o.probability.enabled = true;
  run_pipeline(state, o);
}
BENCHMARK(BM_Pipeline_AllStrategies)->Unit(benchmark::kMicrosecond);

void BM_Pipeline_SemanticOnly(benchmark::State& state) { run_pipeline(state, presets::zhang_2023<float>()); }
BENCHMARK(BM_Pipeline_SemanticOnly)->Unit(benchmark::kMicrosecond);

#ifdef DYNCULL_HAS_OPENCV
// Peer: pyramidal LK (21x21 window, 3 levels, 30 iterations / 0.01) of the same features between two
// textured 640x480 frames shifted by a few pixels.
void BM_Pipeline_PeerLK(benchmark::State& state) {
  const Data& d = data();
  cv::Mat noise(480, 640, CV_8U);
  cv::randu(noise, 0, 255);
  cv::Mat prev;
  cv::GaussianBlur(noise, prev, cv::Size(0, 0), 2.0);
  cv::Mat cur;
  const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, 3.5, 0, 1, -2.25);
  cv::warpAffine(prev, cur, shift, prev.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  std::vector<cv::Point2f> p0, p1;
  for (const auto& k : d.scene.keypoints) p0.emplace_back(k.x(), k.y());
  std::vector<std::uint8_t> status;
  std::vector<float> err;
  const cv::TermCriteria term(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01);
  for (auto _ : state) {
    cv::calcOpticalFlowPyrLK(prev, cur, p0, p1, status, err, cv::Size(21, 21), 3, term);
    benchmark::DoNotOptimize(p1.data());
  }
  state.counters["features"] = double(p0.size());
}
BENCHMARK(BM_Pipeline_PeerLK)->Unit(benchmark::kMicrosecond);
#endif

}  // namespace

namespace {
// Cost of each stage: the recommended pipeline with one stage switched off (arg: 0 assignment of
// overlapping masks by depth, 1 depth mask, 2 sub-box, 3 moving consistency (and so sub-box), 4 box tracker,
// 5 low-level shelter by depth).
void BM_Pipeline_RecommendedWithout(benchmark::State& state) {
  dyncull::PipelineOptions<float> o = dyncull::presets::recommended<float>();
  switch (state.range(0)) {
    case 0: o.depth_mask.assign_overlaps_by_depth = false; break;
    case 1: o.depth_mask.enabled = false; break;
    case 2: o.subbox.enabled = false; break;
    case 3: o.moving_consistency.enabled = false; break;
    case 4: o.tracker.enabled = false; break;
    default: o.depth_mask.low_override_by_depth = false; break;
  }
  run_pipeline(state, o);
}
BENCHMARK(BM_Pipeline_RecommendedWithout)->DenseRange(0, 5)->Unit(benchmark::kMicrosecond);
}  // namespace
