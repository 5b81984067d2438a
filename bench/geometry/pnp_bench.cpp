// PnP-RANSAC and pose refinement: dyncull vs cv::solvePnPRansac (P3P, EPnP) and cv::solvePnPRefineLM,
// 1000 (and 100) correspondences, 0.5 px noise, 30 % outliers; accuracy as counters.
#include "dyncull/geometry/pnp.hpp"
#ifdef DYNCULL_HAS_CERES
#include "dyncull/ceres/pose_refinement.hpp"
#endif

#include "support/pose_data.hpp"

#include <benchmark/benchmark.h>

#include <vector>

#ifdef DYNCULL_HAS_OPENCV
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#endif

namespace {

using dyncull::Rigid3;
using dyncull::test::make_pnp_scene;
using dyncull::test::rotation_error_deg;
using dyncull::test::translation_error;

constexpr int kScenes = 8;  // several data sets: RANSAC time depends on the data

template <class T>
std::vector<dyncull::test::PnpScene<T>> scenes(int n) {
  std::vector<dyncull::test::PnpScene<T>> out;
  for (int i = 0; i < kScenes; ++i) out.push_back(make_pnp_scene<T>(100 + static_cast<std::uint64_t>(i), n, 0.5, 0.3));
  return out;
}

template <class T>
void BM_dyncull_pnp_ransac(benchmark::State& state) {
  const auto data = scenes<T>(static_cast<int>(state.range(0)));
  dyncull::PnpOptions<T> o;
  double rot = 0, trans = 0, count = 0;
  std::size_t k = 0;
  for (auto _ : state) {
    const auto& s = data[k++ % data.size()];
    const auto r = dyncull::solve_pnp_ransac(s.world, s.pixels, s.camera, o);
    benchmark::DoNotOptimize(r.cam_from_world.t.data());
    rot += rotation_error_deg(r.cam_from_world, s.cam_from_world);
    trans += translation_error(r.cam_from_world, s.cam_from_world);
    count += 1;
  }
  state.counters["rot_err_deg"] = rot / count;
  state.counters["trans_err_mm"] = 1000 * trans / count;
}
BENCHMARK_TEMPLATE(BM_dyncull_pnp_ransac, double)->Arg(1000)->Arg(100)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(BM_dyncull_pnp_ransac, float)->Arg(1000)->Unit(benchmark::kMicrosecond);

void BM_dyncull_refine_pose(benchmark::State& state) {
  auto s = make_pnp_scene<double>(200, static_cast<int>(state.range(0)), 0.5, 0.0);
  Rigid3<double> start = s.cam_from_world;
  start.t += dyncull::Vec3<double>(0.02, -0.01, 0.03);
  for (auto _ : state) {
    const auto r = dyncull::refine_pose(s.world, s.pixels, s.camera, start);
    benchmark::DoNotOptimize(r.cam_from_world.t.data());
  }
  const auto r = dyncull::refine_pose(s.world, s.pixels, s.camera, start);
  state.counters["rot_err_deg"] = rotation_error_deg(r.cam_from_world, s.cam_from_world);
}
BENCHMARK(BM_dyncull_refine_pose)->Arg(1000)->Unit(benchmark::kMicrosecond);

#ifdef DYNCULL_HAS_CERES
void BM_ceres_refine_pose(benchmark::State& state) {
  auto s = make_pnp_scene<double>(200, static_cast<int>(state.range(0)), 0.5, 0.0);
  Rigid3<double> start = s.cam_from_world;
  start.t += dyncull::Vec3<double>(0.02, -0.01, 0.03);
  for (auto _ : state) {
    const auto r = dyncull::refine_pose_ceres(s.world, s.pixels, s.camera, start);
    benchmark::DoNotOptimize(r.cam_from_world.t.data());
  }
  const auto r = dyncull::refine_pose_ceres(s.world, s.pixels, s.camera, start);
  state.counters["rot_err_deg"] = rotation_error_deg(r.cam_from_world, s.cam_from_world);
}
BENCHMARK(BM_ceres_refine_pose)->Arg(1000)->Unit(benchmark::kMicrosecond);
#endif

#ifdef DYNCULL_HAS_OPENCV
struct CvScene {
  std::vector<cv::Point3d> obj;
  std::vector<cv::Point2d> img;
  cv::Mat K;
};
CvScene to_cv(const dyncull::test::PnpScene<double>& s) {
  CvScene c;
  for (std::size_t i = 0; i < s.world.size(); ++i) {
    c.obj.emplace_back(s.world[i].x(), s.world[i].y(), s.world[i].z());
    c.img.emplace_back(s.pixels[i].x(), s.pixels[i].y());
  }
  cv::eigen2cv(s.camera.K(), c.K);
  return c;
}
Rigid3<double> from_cv(const cv::Mat& rvec, const cv::Mat& tvec) {
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  Rigid3<double> g;
  cv::cv2eigen(R, g.R);
  cv::cv2eigen(tvec, g.t);
  return g;
}

void BM_opencv_pnp_ransac(benchmark::State& state) {
  const auto data = scenes<double>(static_cast<int>(state.range(0)));
  std::vector<CvScene> cvd;
  for (const auto& s : data) cvd.push_back(to_cv(s));
  const int method = static_cast<int>(state.range(1));
  double rot = 0, trans = 0, count = 0;
  std::size_t k = 0;
  for (auto _ : state) {
    const std::size_t i = k++ % data.size();
    cv::Mat rvec, tvec;
    // Same threshold (2 px), confidence and iteration cap as dyncull's defaults.
    cv::solvePnPRansac(cvd[i].obj, cvd[i].img, cvd[i].K, cv::noArray(), rvec, tvec, false, 1000, 2.0f, 0.99,
                       cv::noArray(), method);
    benchmark::DoNotOptimize(tvec.data);
    const auto g = from_cv(rvec, tvec);
    rot += rotation_error_deg(g, data[i].cam_from_world);
    trans += translation_error(g, data[i].cam_from_world);
    count += 1;
  }
  state.counters["rot_err_deg"] = rot / count;
  state.counters["trans_err_mm"] = 1000 * trans / count;
}
BENCHMARK(BM_opencv_pnp_ransac)
    ->Args({1000, cv::SOLVEPNP_P3P})
    ->Args({1000, cv::SOLVEPNP_EPNP})
    ->Args({100, cv::SOLVEPNP_P3P})
    ->Unit(benchmark::kMicrosecond);

void BM_opencv_refine_lm(benchmark::State& state) {
  auto s = make_pnp_scene<double>(200, static_cast<int>(state.range(0)), 0.5, 0.0);
  const auto c = to_cv(s);
  Rigid3<double> start = s.cam_from_world;
  start.t += dyncull::Vec3<double>(0.02, -0.01, 0.03);
  cv::Mat R0, rvec0, tvec0;
  cv::eigen2cv(start.R, R0);
  cv::Rodrigues(R0, rvec0);
  cv::eigen2cv(start.t, tvec0);
  for (auto _ : state) {
    cv::Mat rvec = rvec0.clone(), tvec = tvec0.clone();
    cv::solvePnPRefineLM(c.obj, c.img, c.K, cv::noArray(), rvec, tvec);
    benchmark::DoNotOptimize(tvec.data);
  }
}
BENCHMARK(BM_opencv_refine_lm)->Arg(1000)->Unit(benchmark::kMicrosecond);
#endif

}  // namespace
