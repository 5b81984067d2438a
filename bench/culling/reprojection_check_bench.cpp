// RGB-D reprojection check at ~1000 tracks: ours (PnP-RANSAC outside the boxes, residual of every track) vs
// the epipolar check on the same tracks vs OpenCV solvePnPRansac + projectPoints, same data, with the labels'
// precision and recall as counters.
#include "dyncull/culling/moving_consistency.hpp"
#include "dyncull/culling/reprojection_check.hpp"

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

// The culling scene (walking person, seated person, chair, tv, furniture) with each track's 3-D point
// at the previous frame, and the dynamic-class boxes (person, chair).
struct Data {
  test::CullingScene<float> scene;
  std::vector<std::uint8_t> in_box;
};

const Data& data() {
  static const Data d = [] {
    Data x;
    test::SceneConfig config;
    config.num_uniform = 760;
    x.scene = test::make_culling_scene<float>(config);
    x.in_box.assign(x.scene.size(), 0);
    for (std::size_t i = 0; i < x.scene.size(); ++i)
      for (const auto& det : x.scene.detections)
        if ((det.class_id == 0 || det.class_id == 56) && det.box.contains(x.scene.keypoints[i].x(), x.scene.keypoints[i].y()))
          x.in_box[i] = 1;
    return x;
  }();
  return d;
}

template <class IsDynamic>
void accuracy(benchmark::State& state, IsDynamic&& is_dynamic) {
  const Data& d = data();
  std::vector<std::uint8_t> dyn, truth;
  for (std::size_t i = 0; i < d.scene.size(); ++i) {
    if (!d.scene.track_valid[i]) continue;
    dyn.push_back(is_dynamic(i));
    truth.push_back(d.scene.truth_dynamic[i]);
  }
  const auto pr = test::precision_recall(dyn, truth, truth.size());
  state.counters["precision"] = pr.precision;
  state.counters["recall"] = pr.recall;
  state.counters["tracks"] = double(truth.size());
}

// Ours, default options.
void BM_ReprojectionCheck_Dyncull(benchmark::State& state) {
  const Data& d = data();
  ReprojectionCheckOptions<float> o;
  ReprojectionCheckResult<float> r;
  for (auto _ : state) {
    check_reprojection(d.scene.prev_points_world, d.scene.keypoints, d.scene.camera, o, &r, d.scene.track_valid,
                       d.in_box);
    benchmark::DoNotOptimize(r.labels.data());
  }
  accuracy(state, [&](std::size_t i) { return r.labels[i] == FeatureLabel::Dynamic; });
}
BENCHMARK(BM_ReprojectionCheck_Dyncull)->Unit(benchmark::kMicrosecond);

// Ours with the depth residual at 5 sigma (the recommended preset), reading the scene's depth image.
void BM_ReprojectionCheck_DyncullWithDepth(benchmark::State& state) {
  const Data& d = data();
  ReprojectionCheckOptions<float> o;
  o.max_depth_residual_sigmas = 5.f;
  ReprojectionCheckResult<float> r;
  for (auto _ : state) {
    check_reprojection(d.scene.prev_points_world, d.scene.keypoints, d.scene.camera, o, &r, d.scene.track_valid,
                       d.in_box, d.scene.depth_view());
    benchmark::DoNotOptimize(r.labels.data());
  }
  state.counters["depth_flagged"] = double(r.num_depth_dynamic);
  accuracy(state, [&](std::size_t i) { return r.labels[i] == FeatureLabel::Dynamic; });
}
BENCHMARK(BM_ReprojectionCheck_DyncullWithDepth)->Unit(benchmark::kMicrosecond);

// The epipolar check on the same tracks (what the reprojection check replaces when depth is there).
void BM_ReprojectionCheck_EpipolarOnSameTracks(benchmark::State& state) {
  const Data& d = data();
  MovingConsistencyOptions<float> o;
  MovingConsistencyResult<float> r;
  for (auto _ : state) {
    check_moving_consistency(d.scene.prev_keypoints, d.scene.keypoints, o, &r, d.scene.track_valid, d.in_box);
    benchmark::DoNotOptimize(r.labels.data());
  }
  accuracy(state, [&](std::size_t i) { return r.labels[i] == FeatureLabel::Dynamic; });
}
BENCHMARK(BM_ReprojectionCheck_EpipolarOnSameTracks)->Unit(benchmark::kMicrosecond);

#ifdef DYNCULL_HAS_OPENCV
// Peer: cv::solvePnPRansac (300 iterations, 2 px, 0.999, P3P as ours) on the tracks outside the boxes,
// then cv::projectPoints of every track and the same thresholds (3 px outside, 1.5 px inside boxes).
void BM_ReprojectionCheck_OpenCV(benchmark::State& state) {
  const Data& d = data();
  std::vector<cv::Point3f> fit_world, all_world;
  std::vector<cv::Point2f> fit_px, all_px;
  std::vector<std::uint8_t> all_in_box;
  for (std::size_t i = 0; i < d.scene.size(); ++i) {
    if (!d.scene.track_valid[i]) continue;
    const Vec3<float>& X = d.scene.prev_points_world[i];
    const cv::Point3f P(X.x(), X.y(), X.z());
    const cv::Point2f p(d.scene.keypoints[i].x(), d.scene.keypoints[i].y());
    all_world.push_back(P);
    all_px.push_back(p);
    all_in_box.push_back(d.in_box[i]);
    if (d.in_box[i]) continue;
    fit_world.push_back(P);
    fit_px.push_back(p);
  }
  const auto& c = d.scene.camera;
  const cv::Matx33d K(c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
  cv::Mat rvec, tvec;
  std::vector<int> inliers;
  std::vector<cv::Point2f> projected;
  std::vector<std::uint8_t> dyn(all_px.size());
  for (auto _ : state) {
    cv::setRNGSeed(12345);  // solvePnPRansac samples from OpenCV's global RNG
    cv::solvePnPRansac(fit_world, fit_px, K, cv::noArray(), rvec, tvec, false, 300, 2.0f, 0.999, inliers, cv::SOLVEPNP_P3P);
    cv::projectPoints(all_world, rvec, tvec, K, cv::noArray(), projected);
    for (std::size_t i = 0; i < all_px.size(); ++i) {
      const cv::Point2f e = projected[i] - all_px[i];
      dyn[i] = std::sqrt(e.dot(e)) > (all_in_box[i] ? 1.5f : 3.f);
    }
    benchmark::DoNotOptimize(dyn.data());
  }
  std::size_t k = 0;
  std::vector<std::uint8_t> by_track(d.scene.size(), 0);
  for (std::size_t i = 0; i < d.scene.size(); ++i)
    if (d.scene.track_valid[i]) by_track[i] = dyn[k++];
  accuracy(state, [&](std::size_t i) { return by_track[i] != 0; });
}
BENCHMARK(BM_ReprojectionCheck_OpenCV)->Unit(benchmark::kMicrosecond);
#endif

}  // namespace
