// Projection kernels: project_points (1000 points) vs cv::projectPoints, depth_to_points on a 640x480
// TUM-style depth image with a dynamic mask vs a plain per-pixel PinholeCamera::backproject loop
// (cv::rgbd::depthTo3d is not linked: the build's OpenCV components do not include rgbd), and
// voxel downsampling of the resulting cloud.
#include "dyncull/geometry/projection.hpp"

#include "support/pose_data.hpp"

#include <benchmark/benchmark.h>

#include <vector>

#ifdef DYNCULL_HAS_OPENCV
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#endif

namespace {

using dyncull::PinholeCamera;
using dyncull::Random;
using dyncull::Rigid3;
using dyncull::Vec2;
using dyncull::Vec3;

struct DepthFrame {
  std::vector<std::uint16_t> depth;
  dyncull::Mask dynamic;
  PinholeCamera<float> camera = PinholeCamera<float>::tum_fr3();
};
// A slanted wall at 1.5-4 m with 5 % holes and a 200x300 "person" box masked as dynamic.
DepthFrame make_frame() {
  DepthFrame f;
  Random rng(97);
  f.depth.resize(640 * 480);
  for (int v = 0; v < 480; ++v)
    for (int u = 0; u < 640; ++u)
      f.depth[static_cast<std::size_t>(v * 640 + u)] =
          rng.uniform() < 0.05 ? 0 : static_cast<std::uint16_t>(5000.0 * (1.5 + 2.5 * u / 640.0));
  f.dynamic.reset(640, 480);
  for (int v = 100; v < 400; ++v)
    for (int u = 200; u < 400; ++u) f.dynamic.view().at(u, v) = 1;
  return f;
}

void BM_dyncull_depth_to_points(benchmark::State& state) {
  const DepthFrame f = make_frame();
  const auto view = dyncull::tum_depth_view(f.depth.data(), 640, 480);
  dyncull::DepthCloud<float> cloud;
  const int stride = static_cast<int>(state.range(0));
  for (auto _ : state) {
    dyncull::depth_to_points(view, f.camera, f.dynamic.view(), stride, &cloud);
    benchmark::DoNotOptimize(cloud.points.data());
  }
  state.counters["points"] = static_cast<double>(cloud.points.size());
}
BENCHMARK(BM_dyncull_depth_to_points)->Arg(1)->Arg(4)->Unit(benchmark::kMicrosecond);

// Peer: the obvious loop a user would write with the core camera (per-pixel backproject, branchy mask).
void BM_naive_depth_to_points(benchmark::State& state) {
  const DepthFrame f = make_frame();
  std::vector<Vec3<float>> pts;
  for (auto _ : state) {
    pts.clear();
    for (int v = 0; v < 480; ++v)
      for (int u = 0; u < 640; ++u) {
        if (f.dynamic.test(u, v)) continue;
        const std::uint16_t d = f.depth[static_cast<std::size_t>(v * 640 + u)];
        if (d == 0) continue;
        pts.push_back(f.camera.backproject(Vec2<float>(float(u), float(v)), float(d) / 5000.f));
      }
    benchmark::DoNotOptimize(pts.data());
  }
  state.counters["points"] = static_cast<double>(pts.size());
}
BENCHMARK(BM_naive_depth_to_points)->Unit(benchmark::kMicrosecond);

void BM_dyncull_voxel_downsample(benchmark::State& state) {
  const DepthFrame f = make_frame();
  const auto cloud = dyncull::depth_to_points(dyncull::tum_depth_view(f.depth.data(), 640, 480), f.camera,
                                              f.dynamic.view(), 1);
  dyncull::VoxelDownsampler<float> ds;
  std::vector<Vec3<float>> out;
  for (auto _ : state) {
    ds.run(cloud.points, 0.05f, &out);
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["in"] = static_cast<double>(cloud.points.size());
  state.counters["out"] = static_cast<double>(out.size());
}
BENCHMARK(BM_dyncull_voxel_downsample)->Unit(benchmark::kMicrosecond);

template <class T>
void BM_dyncull_project_points(benchmark::State& state) {
  const auto s = dyncull::test::make_pnp_scene<T>(98, 1000);
  std::vector<Vec2<T>> px(s.world.size());
  std::vector<std::uint8_t> valid(s.world.size());
  for (auto _ : state) {
    benchmark::DoNotOptimize(dyncull::project_points(s.camera, s.cam_from_world, s.world, px.data(), valid.data()));
    benchmark::DoNotOptimize(px.data());
  }
}
BENCHMARK_TEMPLATE(BM_dyncull_project_points, float)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(BM_dyncull_project_points, double)->Unit(benchmark::kMicrosecond);

#ifdef DYNCULL_HAS_OPENCV
void BM_opencv_project_points(benchmark::State& state) {
  const auto s = dyncull::test::make_pnp_scene<double>(98, 1000);
  std::vector<cv::Point3d> obj;
  for (const auto& p : s.world) obj.emplace_back(p.x(), p.y(), p.z());
  cv::Mat K, R, rvec, tvec;
  cv::eigen2cv(s.camera.K(), K);
  cv::eigen2cv(s.cam_from_world.R, R);
  cv::Rodrigues(R, rvec);
  cv::eigen2cv(s.cam_from_world.t, tvec);
  std::vector<cv::Point2d> px;
  for (auto _ : state) {
    cv::projectPoints(obj, rvec, tvec, K, cv::noArray(), px);
    benchmark::DoNotOptimize(px.data());
  }
}
BENCHMARK(BM_opencv_project_points)->Unit(benchmark::kMicrosecond);
#endif

}  // namespace
