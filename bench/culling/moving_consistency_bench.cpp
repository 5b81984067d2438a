// Moving-consistency check (DFD-SLAM eq. 1-3) at ~1000 tracks: ours vs its own parts (F-RANSAC + one batch
// distance pass, the 1.2x target) vs OpenCV findFundamentalMat + computeCorrespondEpilines, same data.
#include "dyncull/culling/moving_consistency.hpp"

#include "support/culling_scenes.hpp"

#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#ifdef DYNCULL_HAS_OPENCV
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#endif

namespace {
using namespace dyncull;

// The culling scene (person, seated person, chair, tv, furniture), ~1000 tracks, dynamic-class boxes.
struct Data {
  test::CullingScene<float> scene;
  std::vector<std::uint8_t> in_box;
  std::vector<Vec2<float>> prev, cur;  // valid tracks only (for the parts / peers)
  std::vector<std::uint8_t> truth;
};

const Data& data() {
  static const Data d = [] {
    Data x;
    test::SceneConfig config;
    config.num_uniform = 760;
    x.scene = test::make_culling_scene<float>(config);
    x.in_box.assign(x.scene.size(), 0);
    for (std::size_t i = 0; i < x.scene.size(); ++i) {
      for (const auto& det : x.scene.detections)
        if ((det.class_id == 0 || det.class_id == 56) && det.box.contains(x.scene.keypoints[i].x(), x.scene.keypoints[i].y()))
          x.in_box[i] = 1;
      if (!x.scene.track_valid[i]) continue;
      x.prev.push_back(x.scene.prev_keypoints[i]);
      x.cur.push_back(x.scene.keypoints[i]);
      x.truth.push_back(x.scene.truth_dynamic[i]);
    }
    return x;
  }();
  return d;
}

template <class Labels>
void accuracy(benchmark::State& state, const Labels& dyn, const std::vector<std::uint8_t>& truth) {
  const auto pr = test::precision_recall(dyn, truth, truth.size());
  state.counters["precision"] = pr.precision;
  state.counters["recall"] = pr.recall;
  state.counters["tracks"] = double(truth.size());
}

// Ours, default options (F fitted outside the boxes, 2 inlier refits).
void BM_MovingConsistency_Dyncull(benchmark::State& state) {
  const Data& d = data();
  MovingConsistencyOptions<float> o;
  o.refit_iterations = int(state.range(0));
  const bool boxes = state.range(1) != 0;
  MovingConsistencyResult<float> r;
  for (auto _ : state) {
    check_moving_consistency(d.scene.prev_keypoints, d.scene.keypoints, o, &r, d.scene.track_valid,
                             boxes ? FlagView(d.in_box) : nullptr);
    benchmark::DoNotOptimize(r.labels.data());
  }
  std::vector<std::uint8_t> dyn, truth;
  for (std::size_t i = 0; i < d.scene.size(); ++i) {
    if (!d.scene.track_valid[i]) continue;
    dyn.push_back(r.labels[i] == FeatureLabel::Dynamic);
    truth.push_back(d.scene.truth_dynamic[i]);
  }
  accuracy(state, dyn, truth);
}
BENCHMARK(BM_MovingConsistency_Dyncull)->Args({0, 0})->Args({2, 0})->Args({0, 1})->Args({2, 1})->Unit(benchmark::kMicrosecond);

// A camera that did not move, with nothing moving in view: range(0) = 0 gives every track the same pixel in
// both frames (no baseline: no 7-point sample can give a model), 1 gives them 0.25 px of noise at both ends
// (nearly still: every F = [e]x fits within the noise). Counter `ransac_iterations` = samples drawn per call.
void BM_MovingConsistency_StillCamera(benchmark::State& state) {
  test::SceneConfig config;
  config.static_camera = true;
  config.walking = config.sitting = config.chair = false;
  config.num_uniform = 760;
  config.pixel_noise = state.range(0) == 0 ? 0.0 : 0.25;
  const auto scene = test::make_culling_scene<float>(config);
  const MovingConsistencyOptions<float> o;
  MovingConsistencyResult<float> r;
  for (auto _ : state) {
    check_moving_consistency(scene.prev_keypoints, scene.keypoints, o, &r, scene.track_valid);
    benchmark::DoNotOptimize(r.labels.data());
  }
  state.counters["ransac_iterations"] = double(r.ransac_iterations);
  state.counters["degenerate"] = r.status == Status::Degenerate;
  state.counters["tracks"] = double(r.num_valid);
}
BENCHMARK(BM_MovingConsistency_StillCamera)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

// The floor: F-RANSAC on all valid tracks plus one batch eq. 3 pass (what the check must not exceed by 1.2x).
void BM_MovingConsistency_PartsFloor(benchmark::State& state) {
  const Data& d = data();
  const FundamentalOptions<float> fo = MovingConsistencyOptions<float>{}.fundamental_fit();
  std::vector<float> dist(d.cur.size());
  for (auto _ : state) {
    const auto f = estimate_fundamental_ransac(d.prev, d.cur, fo);
    epipolar_distances(f.F, d.prev, d.cur, dist.data());
    benchmark::DoNotOptimize(dist.data());
  }
  const auto f = estimate_fundamental_ransac(d.prev, d.cur, fo);
  epipolar_distances(f.F, d.prev, d.cur, dist.data());
  std::vector<std::uint8_t> dyn(dist.size());
  for (std::size_t i = 0; i < dist.size(); ++i) dyn[i] = dist[i] > 1.f;
  accuracy(state, dyn, d.truth);
}
BENCHMARK(BM_MovingConsistency_PartsFloor)->Unit(benchmark::kMicrosecond);

#ifdef DYNCULL_HAS_OPENCV
// Peer: cv::findFundamentalMat (method, 1 px, 0.99) + cv::computeCorrespondEpilines + distance loop.
void BM_MovingConsistency_OpenCV(benchmark::State& state) {
  const Data& d = data();
  std::vector<cv::Point2f> a, b;
  for (std::size_t i = 0; i < d.cur.size(); ++i) {
    a.emplace_back(d.prev[i].x(), d.prev[i].y());
    b.emplace_back(d.cur[i].x(), d.cur[i].y());
  }
  const int method = int(state.range(0));
  std::vector<cv::Vec3f> lines;
  std::vector<std::uint8_t> dyn(a.size());
  for (auto _ : state) {
    const cv::Mat F = cv::findFundamentalMat(a, b, method, 1.0, 0.99);
    if (F.rows != 3) continue;
    cv::computeCorrespondEpilines(a, 1, F, lines);
    for (std::size_t i = 0; i < a.size(); ++i) {
      const cv::Vec3f& l = lines[i];  // normalised: a^2 + b^2 = 1
      dyn[i] = std::abs(l[0] * b[i].x + l[1] * b[i].y + l[2]) > 1.f;
    }
    benchmark::DoNotOptimize(dyn.data());
  }
  accuracy(state, dyn, d.truth);
}
BENCHMARK(BM_MovingConsistency_OpenCV)->Arg(cv::FM_RANSAC)->Arg(cv::USAC_DEFAULT)->Unit(benchmark::kMicrosecond);
#endif

}  // namespace
