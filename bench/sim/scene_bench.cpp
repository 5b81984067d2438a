// Synthetic scene: time to render one 640x480 frame per camera motion (with and without the
// Kinect depth model), the depth model against an OpenCV cv::randn peer, OpenCV FAST on the
// rendered frame as the front end's cost scale, and how far a front end without culling is pulled
// off: OpenCV ORB + solvePnPRansac between frames 5 apart, all features vs. static-truth features.
#include "dyncull/sim/scene.hpp"
#include "dyncull/sim/truth.hpp"

#include <benchmark/benchmark.h>

#ifdef DYNCULL_HAS_OPENCV
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#endif

#include <algorithm>
#include <cmath>
#include <vector>

namespace {

using namespace dyncull::sim;

double person_share(const FrameData& f) {
  std::size_t n = 0;
  for (std::uint16_t id : f.instance) n += instance_class(id) == CocoClass::kPerson ? 1 : 0;
  return static_cast<double>(n) / static_cast<double>(f.instance.size());
}

void BM_RenderFrame(benchmark::State& state) {
  SceneOptions o;
  o.motion = static_cast<CameraMotion>(state.range(0));
  o.depth_noise = state.range(1) != 0;
  const Scene scene(o);
  FrameData f;
  int index = 0;
  double coverage = 0;
  std::int64_t frames = 0;
  for (auto _ : state) {
    scene.render(index, &f);
    benchmark::DoNotOptimize(f.rgb.data());
    benchmark::DoNotOptimize(f.depth_m.data());
    state.PauseTiming();
    coverage += person_share(f);
    ++frames;
    index = (index + 37) % scene.num_frames();  // walk through the sequence
    state.ResumeTiming();
  }
  state.counters["person_coverage"] = coverage / static_cast<double>(std::max<std::int64_t>(frames, 1));
  state.counters["frames_per_s"] = benchmark::Counter(static_cast<double>(frames), benchmark::Counter::kIsRate);
  state.SetLabel(std::string(to_string(o.motion)) + (o.depth_noise ? " +depth noise" : " exact depth"));
}
BENCHMARK(BM_RenderFrame)
    ->ArgsProduct({{0, 1, 2, 3}, {1}})
    ->Args({1, 0})
    ->Unit(benchmark::kMillisecond);

/// Noiseless depth of one frame, reused by the depth-model benchmarks.
std::vector<float> clean_depth() {
  SceneOptions o;
  o.depth_noise = false;
  const Scene scene(o);
  FrameData f;
  scene.render(60, &f);
  return f.depth_m;
}

void BM_DepthNoise(benchmark::State& state) {
  const std::vector<float> clean = clean_depth();
  std::vector<float> depth(clean.size());
  const DepthNoiseOptions o;
  std::uint64_t seed = 0;
  for (auto _ : state) {
    std::copy(clean.begin(), clean.end(), depth.begin());
    apply_depth_noise(depth.data(), 640, 480, o, ++seed);
    benchmark::DoNotOptimize(depth.data());
  }
  std::size_t holes = 0;
  for (float d : depth) holes += d == 0.f ? 1 : 0;
  state.counters["hole_fraction"] = static_cast<double>(holes) / static_cast<double>(depth.size());
  state.SetLabel("sigma(z) noise + quantisation + edge holes + border");
}
BENCHMARK(BM_DepthNoise)->Unit(benchmark::kMillisecond);

#ifdef DYNCULL_HAS_OPENCV
// Peer: the same per-pixel sigma(z) Gaussian noise and 1/5000 quantisation with OpenCV array ops
// (cv::randn, no holes): what a user would write without the model.
void BM_DepthNoiseOpenCv(benchmark::State& state) {
  const std::vector<float> clean_vec = clean_depth();
  const cv::Mat clean(480, 640, CV_32F, const_cast<float*>(clean_vec.data()));
  cv::Mat noise(480, 640, CV_32F), sigma, depth;
  cv::RNG rng(1);
  for (auto _ : state) {
    cv::Mat dz = clean - 0.4f;
    sigma = 0.0012f + 0.0019f * dz.mul(dz);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, 1.0);
    depth = clean + sigma.mul(noise);
    depth.convertTo(depth, CV_16U, 5000.0);  // quantise (rounds)
    benchmark::DoNotOptimize(depth.data);
  }
  state.SetLabel("cv::RNG normal + array ops + convertTo (no holes)");
}
BENCHMARK(BM_DepthNoiseOpenCv)->Unit(benchmark::kMillisecond);

// Reference scale: OpenCV FAST (threshold 20) on a rendered frame; counters = corners per frame
// and the share of them on people.
void BM_OpenCvFastOnFrame(benchmark::State& state) {
  const Scene scene(SceneOptions{});
  FrameData f;
  scene.render(100, &f);
  const cv::Mat gray(f.height, f.width, CV_8UC1, f.gray.data());
  auto fast = cv::FastFeatureDetector::create(20, true);
  std::vector<cv::KeyPoint> kps;
  for (auto _ : state) {
    fast->detect(gray, kps);
    benchmark::DoNotOptimize(kps.data());
  }
  std::vector<std::uint16_t> instance;
  truth_at_points(f, kps, nullptr, &instance);
  std::size_t on_people = 0;
  for (std::uint16_t id : instance) on_people += instance_class(id) == CocoClass::kPerson ? 1 : 0;
  state.counters["corners"] = static_cast<double>(kps.size());
  state.counters["share_on_people"] = static_cast<double>(on_people) / static_cast<double>(std::max<std::size_t>(kps.size(), 1));
  state.counters["person_coverage"] = person_share(f);
}
BENCHMARK(BM_OpenCvFastOnFrame)->Unit(benchmark::kMillisecond);

/// Median rotation (deg), median and 90th-percentile translation (cm) error of OpenCV PnP-RANSAC between frames 5 apart,
/// using ORB matches with depth from the first frame; `cull` drops features on moving truth.
struct PullResult {
  double rot_deg = 0, trans_cm = 0, trans_p90_cm = 0, moving_inlier_share = 0;
};

PullResult front_end_pull(const Scene& scene, bool cull, int pairs) {
  cv::setRNGSeed(12345);  // solvePnPRansac samples from OpenCV's global RNG: reset it per run
  auto orb = cv::ORB::create(1500);
  cv::BFMatcher matcher(cv::NORM_HAMMING, true);
  const auto cam = scene.camera();
  const cv::Mat K = (cv::Mat_<double>(3, 3) << cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1);
  std::vector<double> rot, trans;
  double moving_inliers = 0, inliers_total = 0;
  FrameData a, b;
  for (int p = 0; p < pairs; ++p) {
    const int i = 3 + p * (290 / pairs), j = i + 5;  // pairs spread over the sequence
    scene.render(i, &a);
    scene.render(j, &b);
    const cv::Mat ga(a.height, a.width, CV_8UC1, a.gray.data()), gb(b.height, b.width, CV_8UC1, b.gray.data());
    std::vector<cv::KeyPoint> ka, kb;
    cv::Mat da, db;
    orb->detectAndCompute(ga, cv::noArray(), ka, da);
    orb->detectAndCompute(gb, cv::noArray(), kb, db);
    std::vector<cv::DMatch> matches;
    matcher.match(da, db, matches);
    std::vector<cv::Point3f> world;
    std::vector<cv::Point2f> pixels;
    std::vector<std::uint8_t> moving_flag;
    for (const auto& m : matches) {
      const PointTruth t = truth_at(a, ka[static_cast<std::size_t>(m.queryIdx)].pt.x, ka[static_cast<std::size_t>(m.queryIdx)].pt.y);
      if (!t.inside || t.depth_m <= 0.f) continue;
      if (cull && t.moving) continue;
      const auto& pt = ka[static_cast<std::size_t>(m.queryIdx)].pt;
      const dyncull::Vec3<double> pc = cam.backproject(dyncull::Vec2<double>(pt.x, pt.y), t.depth_m);
      world.emplace_back(static_cast<float>(pc.x()), static_cast<float>(pc.y()), static_cast<float>(pc.z()));
      pixels.push_back(kb[static_cast<std::size_t>(m.trainIdx)].pt);
      moving_flag.push_back(t.moving);
    }
    if (world.size() < 10) continue;
    cv::Mat rvec, tvec;
    std::vector<int> inliers;
    // Frame a's camera frame is the "world": the estimate is b_from_a.
    // SQPnP: the default ITERATIVE refinement sometimes diverges by metres on these mostly planar
    // static points even with hundreds of inliers, which would measure OpenCV, not the scene.
    cv::solvePnPRansac(world, pixels, K, cv::noArray(), rvec, tvec, false, 200, 2.0f, 0.99, inliers,
                       cv::SOLVEPNP_SQPNP);
    for (int k : inliers) moving_inliers += moving_flag[static_cast<std::size_t>(k)];
    inliers_total += static_cast<double>(inliers.size());
    cv::Mat Rm;
    cv::Rodrigues(rvec, Rm);
    dyncull::Rigid3<double> est;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) est.R(r, c) = Rm.at<double>(r, c);
      est.t[r] = tvec.at<double>(r);
    }
    const dyncull::Rigid3<double> truth = b.world_from_cam.inverse() * a.world_from_cam;
    const dyncull::Rigid3<double> err = truth.inverse() * est;
    rot.push_back(dyncull::rotation_angle(err.R) * 57.29577951308232);
    trans.push_back(100.0 * err.t.norm());
  }
  PullResult r;
  if (rot.empty()) return r;
  std::sort(rot.begin(), rot.end());
  std::sort(trans.begin(), trans.end());
  r.trans_p90_cm = trans[trans.size() * 9 / 10];
  r.rot_deg = rot[rot.size() / 2];
  r.trans_cm = trans[trans.size() / 2];
  r.moving_inlier_share = inliers_total > 0 ? moving_inliers / inliers_total : 0;
  return r;
}

void BM_FrontEndPull(benchmark::State& state) {
  SceneOptions o;
  o.motion = static_cast<CameraMotion>(state.range(0));
  const bool cull = state.range(1) != 0;
  o.actors.wall_contrast = static_cast<double>(state.range(2)) / 100.0;
  const Scene scene(o);
  PullResult r;
  for (auto _ : state) {
    r = front_end_pull(scene, cull, 40);
    benchmark::DoNotOptimize(r);
  }
  state.counters["median_rot_err_deg"] = r.rot_deg;
  state.counters["median_trans_err_cm"] = r.trans_cm;
  state.counters["p90_trans_err_cm"] = r.trans_p90_cm;
  state.counters["moving_inlier_share"] = r.moving_inlier_share;
  state.SetLabel(std::string(to_string(o.motion)) + (cull ? " truth-culled" : " no culling") + " wall contrast " +
                 std::to_string(state.range(2)) + "%");
}
// Third argument: wall texture contrast in percent (100 = default; 70 = plainer walls, harder).
BENCHMARK(BM_FrontEndPull)
    ->ArgsProduct({{0, 1, 2, 3}, {0, 1}, {100}})
    ->Args({1, 0, 70})
    ->Args({1, 1, 70})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);
#endif

}  // namespace
