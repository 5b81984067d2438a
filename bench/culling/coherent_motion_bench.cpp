// Cell-level coherent-motion evidence at ~1100 tracks and 4 boxes (the seated person swaying about 1 px a
// frame): the median test of every 3x3 cell after the reprojection check, against that check itself, so
// the stage's share of the geometric evidence's cost is measured in one run. No peer library does this.
#include "dyncull/culling/coherent_motion.hpp"
#include "dyncull/culling/reprojection_check.hpp"

#include "support/culling_scenes.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <vector>

namespace {
using namespace dyncull;

struct Data {
  test::CullingScene<float> scene;
  std::vector<Detection<float>> boxes;  // person / chair boxes, as the pipeline passes them
  std::vector<std::uint8_t> in_box;
  ReprojectionCheckResult<float> reprojection;
};

const Data& data() {
  static const Data d = [] {
    Data x;
    test::SceneConfig config;
    config.num_uniform = 760;
    config.sway_scale = 0.25;
    x.scene = test::make_culling_scene<float>(config);
    x.in_box.assign(x.scene.size(), 0);
    for (const auto& det : x.scene.detections) {
      if (det.class_id != 0 && det.class_id != 56) continue;
      x.boxes.push_back(det);
      for (std::size_t i = 0; i < x.scene.size(); ++i)
        if (det.box.contains(x.scene.keypoints[i].x(), x.scene.keypoints[i].y())) x.in_box[i] = 1;
    }
    check_reprojection(x.scene.prev_points_world, x.scene.keypoints, x.scene.camera, ReprojectionCheckOptions<float>{},
                       &x.reprojection, x.scene.track_valid, x.in_box);
    return x;
  }();
  return d;
}

void BM_CoherentMotion_Cells(benchmark::State& state) {
  const Data& d = data();
  if (!d.reprojection.ok()) {
    state.SkipWithError(d.reprojection.reason.c_str());
    return;
  }
  std::vector<FeatureLabel> labels(d.reprojection.labels.size());
  CoherentMotionResult<float> r;
  const CoherentMotionOptions<float> o;
  for (auto _ : state) {
    std::copy(d.reprojection.labels.begin(), d.reprojection.labels.end(), labels.begin());
    flag_coherent_cells(d.scene.keypoints, d.reprojection.residual_vec, d.boxes, 3, d.reprojection.inlier_noise_px,
                        o, labels.data(), &r);
    benchmark::DoNotOptimize(labels.data());
  }
  state.counters["features"] = double(labels.size());
  state.counters["boxes"] = double(d.boxes.size());
  state.counters["cells_tested"] = double(r.num_cells_tested);
  state.counters["cells_flagged"] = double(r.num_cells_flagged);
  state.counters["features_flagged"] = double(r.num_flagged);
}
BENCHMARK(BM_CoherentMotion_Cells)->Unit(benchmark::kMicrosecond);

// The reprojection check on the same tracks (PnP-RANSAC outside the boxes and every residual): the
// stage the cell test rides on.
void BM_CoherentMotion_ReprojectionCheck(benchmark::State& state) {
  const Data& d = data();
  ReprojectionCheckResult<float> r;
  for (auto _ : state) {
    check_reprojection(d.scene.prev_points_world, d.scene.keypoints, d.scene.camera, ReprojectionCheckOptions<float>{}, &r,
                       d.scene.track_valid, d.in_box);
    benchmark::DoNotOptimize(r.labels.data());
  }
  state.counters["features"] = double(r.labels.size());
}
BENCHMARK(BM_CoherentMotion_ReprojectionCheck)->Unit(benchmark::kMicrosecond);

}  // namespace
