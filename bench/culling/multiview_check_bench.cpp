// Multi-view depth check (RTD-SLAM, Gao et al. 2024, §III.A; DynaSLAM) on a keyframe of 600 points 8 frames back
// against a 640x480 depth image: the check against its floor (transform + project + one depth read per point),
// and the region growing of the dynamic seeds against cv::floodFill (fixed range, 4-connected) on the
// same seeds and tolerance.
#include "dyncull/culling/multiview_check.hpp"

#include "support/culling_scenes.hpp"

#include <benchmark/benchmark.h>

#include <vector>

#ifdef DYNCULL_HAS_OPENCV
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#endif

namespace {
using namespace dyncull;

struct Data {
  test::SceneConfig config;
  test::CullingScene<float> scene;
  test::SceneKeyframe<float> keyframe;
  std::vector<std::uint16_t> depth_tum;
  DepthView<std::uint16_t> depth() const {
    return DepthView<std::uint16_t>{depth_tum.data(), scene.width, scene.height, 0, 5000.f, 0.f, 1e30f};
  }
};

const Data& data() {
  static const Data d = [] {
    Data x;
    x.config.num_uniform = 760;
    x.scene = test::make_culling_scene<float>(x.config);
    x.keyframe = test::make_scene_keyframe<float>(x.config, 8, 600);
    x.depth_tum = x.scene.depth_tum();
    return x;
  }();
  return d;
}

void BM_MultiView_Check_Dyncull(benchmark::State& state) {
  const Data& d = data();
  const auto depth = d.depth();
  MultiViewResult<float> r;
  for (auto _ : state) {
    check_multiview(d.keyframe.keypoints, d.keyframe.depth_m, d.keyframe.cam_from_world, d.scene.cam_from_world,
                    depth, d.scene.camera, MultiViewOptions<float>{}, &r);
    benchmark::DoNotOptimize(r.labels.data());
  }
  // Precision against the scene's truth: a flagged point should land (x') on a surface that moves.
  const test::SceneWorld world(d.config);
  std::size_t flagged = 0, on_mover = 0;
  for (std::size_t i = 0; i < r.labels.size(); ++i) {
    if (r.labels[i] != FeatureLabel::Dynamic) continue;
    ++flagged;
    Vec3<double> X;
    double depth_at = 0;
    int part = -1;
    if (world.raycast(0.0, double(r.projected[i].x()), double(r.projected[i].y()), &X, &depth_at, &part) && part >= 0)
      on_mover += world.parts()[static_cast<std::size_t>(part)].moving();
  }
  state.counters["points"] = double(r.num_points);
  state.counters["checked"] = double(r.num_checked);
  state.counters["dynamic"] = double(r.num_dynamic);
  state.counters["flagged_on_mover"] = flagged ? double(on_mover) / double(flagged) : 1.0;
}
BENCHMARK(BM_MultiView_Check_Dyncull)->Unit(benchmark::kMicrosecond);

// Floor: transform, project and read one depth per point, no parallax, window or bookkeeping.
void BM_MultiView_Check_Floor(benchmark::State& state) {
  const Data& d = data();
  const auto depth = d.depth();
  const Rigid3<float> cur_from_ref = d.scene.cam_from_world * d.keyframe.cam_from_world.inverse();
  const auto& cam = d.scene.camera;
  std::vector<std::uint8_t> dyn(d.keyframe.keypoints.size());
  for (auto _ : state) {
    for (std::size_t i = 0; i < d.keyframe.keypoints.size(); ++i) {
      const Vec2<float>& x = d.keyframe.keypoints[i];
      const float z = d.keyframe.depth_m[i];
      const Vec3<float> p((x.x() - cam.cx) / cam.fx * z, (x.y() - cam.cy) / cam.fy * z, z);
      const Vec3<float> q = cur_from_ref.apply(p);
      const int u = static_cast<int>(cam.fx * q.x() / q.z() + cam.cx + 0.5f);
      const int v = static_cast<int>(cam.fy * q.y() / q.z() + cam.cy + 0.5f);
      const float measured = depth.depth_m(u, v);
      dyn[i] = measured > 0.f && q.z() - measured > 0.4f;
    }
    benchmark::DoNotOptimize(dyn.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_MultiView_Check_Floor)->Unit(benchmark::kMicrosecond);

// Region growing of every dynamic seed over the whole image (DynaSLAM's full-image growth).
void BM_MultiView_Grow_Dyncull(benchmark::State& state) {
  const Data& d = data();
  const auto depth = d.depth();
  const auto r = check_multiview(d.keyframe.keypoints, d.keyframe.depth_m, d.keyframe.cam_from_world,
                                 d.scene.cam_from_world, depth, d.scene.camera);
  Mask mask(d.scene.width, d.scene.height);
  std::vector<std::uint32_t> stack;
  std::size_t set = 0;
  for (auto _ : state) {
    std::fill(mask.pixels.begin(), mask.pixels.end(), std::uint8_t(0));
    set = grow_multiview_regions(r, depth, &mask, &stack);
    benchmark::DoNotOptimize(mask.pixels.data());
  }
  state.counters["seeds"] = double(r.num_dynamic);
  state.counters["pixels_set"] = double(set);
}
BENCHMARK(BM_MultiView_Grow_Dyncull)->Unit(benchmark::kMicrosecond);

#ifdef DYNCULL_HAS_OPENCV
// Peer: cv::floodFill per seed on the uint16 depth (as float: floodFill takes 8U or 32F images), fixed
// range +-0.2 m around the seed's measured depth, 4-connected, mask only. Depth conversion excluded.
void BM_MultiView_Grow_PeerCvFloodFill(benchmark::State& state) {
  const Data& d = data();
  const auto depth = d.depth();
  const MultiViewOptions<float> o;
  const auto r = check_multiview(d.keyframe.keypoints, d.keyframe.depth_m, d.keyframe.cam_from_world,
                                 d.scene.cam_from_world, depth, d.scene.camera, o);
  cv::Mat depth_m(d.scene.height, d.scene.width, CV_32FC1);
  for (int v = 0; v < depth_m.rows; ++v)
    for (int u = 0; u < depth_m.cols; ++u) depth_m.at<float>(v, u) = depth.depth_m(u, v);
  cv::Mat mask(d.scene.height + 2, d.scene.width + 2, CV_8UC1);
  const int flags = 4 | cv::FLOODFILL_FIXED_RANGE | cv::FLOODFILL_MASK_ONLY | (1 << 8);
  for (auto _ : state) {
    mask.setTo(0);
    for (std::size_t i = 0; i < r.labels.size(); ++i) {
      if (r.labels[i] != FeatureLabel::Dynamic) continue;
      const cv::Point seed(static_cast<int>(std::lround(r.projected[i].x())), static_cast<int>(std::lround(r.projected[i].y())));
      if (mask.at<std::uint8_t>(seed.y + 1, seed.x + 1)) continue;
      const float seed_d = r.measured_depth_m[i];
      // Fixed range relative to the seed pixel's own value; the window is set so it covers the same
      // [d' - 0.2, d' + 0.2] interval as ours.
      const float at_seed = depth_m.at<float>(seed);
      const float tol = float(MultiViewOptions<float>::kRegionDepthToleranceM);
      const float lo = at_seed - (seed_d - tol), hi = (seed_d + tol) - at_seed;
      cv::floodFill(depth_m, mask, seed, cv::Scalar(), nullptr, cv::Scalar(std::max(0.f, lo)), cv::Scalar(std::max(0.f, hi)), flags);
    }
    benchmark::DoNotOptimize(mask.data);
  }
  Mask ours(d.scene.width, d.scene.height);
  std::vector<std::uint32_t> stack;
  grow_multiview_regions(r, depth, &ours, &stack);
  std::size_t differ = 0, set = 0;
  for (int v = 0; v < d.scene.height; ++v)
    for (int u = 0; u < d.scene.width; ++u) {
      const bool a = mask.at<std::uint8_t>(v + 1, u + 1) != 0;
      set += a;
      differ += a != ours.test(u, v);
    }
  state.counters["pixels_set"] = double(set);
  state.counters["pixels_differing_from_ours"] = double(differ);
}
BENCHMARK(BM_MultiView_Grow_PeerCvFloodFill)->Unit(benchmark::kMicrosecond);
#endif

}  // namespace

BENCHMARK_MAIN();
