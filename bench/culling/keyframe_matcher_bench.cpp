// The culler's own correspondence step: guided Hamming matching of ~1000 ORB keypoints of a 640x480
// synthetic frame to a keyframe 3 frames earlier (pose-and-depth prediction, rotated rays, same pixel),
// against the front end's own costs in the same binary: cv::ORB detectAndCompute of those features,
// cv::BFMatcher(NORM_HAMMING) knn matching of the same sets and cv::calcOpticalFlowPyrLK of the same
// points. Counter `vs_orb` = time per call / ORB detectAndCompute's on the same frame (target < 0.1);
// `inliers` = share of matches the true motion confirms within 3 px. BM_KeyframeMatcherClustered: the
// same matcher on keypoints clustered in a 20 px patch, its worst case.
#include "dyncull/culling/keyframe_matcher.hpp"

#include "dyncull/core/random.hpp"
#include "dyncull/sim/scene.hpp"

#include <benchmark/benchmark.h>

#ifdef DYNCULL_HAS_OPENCV
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/video/tracking.hpp>
#endif

#include "culling/cpu_time.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace {

using dyncull::bench::cpu_seconds;

using dyncull::Vec2;
using dyncull::Vec3;

/// Keyframe and current frame: keypoints, 32-byte descriptors, the keyframe's 3-D points from its depth
/// (NaN without depth) and the true current_from_keyframe motion.
struct MatchData {
  dyncull::PinholeCamera<float> camera;
  std::vector<Vec2<float>> kf_kp, cur_kp;
  std::vector<Vec3<float>> kf_pts;
  std::vector<std::uint8_t> kf_desc, cur_desc;
  dyncull::Rigid3<float> cam_from_kf;
  double orb_seconds = 0;  // one ORB detectAndCompute of the current frame (0 without OpenCV)
#ifdef DYNCULL_HAS_OPENCV
  cv::Mat kf_gray, cur_gray, kf_mat, cur_mat;
  std::vector<cv::KeyPoint> kf_cv, cur_cv;
#endif
};

#ifdef DYNCULL_HAS_OPENCV
std::vector<std::uint8_t> rows_of(const cv::Mat& m) {
  std::vector<std::uint8_t> v;
  for (int r = 0; r < m.rows; ++r) v.insert(v.end(), m.ptr<std::uint8_t>(r), m.ptr<std::uint8_t>(r) + 32);
  return v;
}

MatchData build_data() {
  using namespace dyncull::sim;
  cv::setNumThreads(1);  // every peer on one core, as the culler runs
  MatchData d;
  const Scene scene(SceneOptions{});
  FrameData a, b;
  scene.render(100, &a);
  scene.render(103, &b);
  d.camera = scene.camera().cast<float>();
  d.cam_from_kf = (b.world_from_cam.inverse() * a.world_from_cam).cast<float>();
  d.kf_gray = cv::Mat(a.height, a.width, CV_8UC1, a.gray.data()).clone();
  d.cur_gray = cv::Mat(b.height, b.width, CV_8UC1, b.gray.data()).clone();
  auto orb = cv::ORB::create(1000);
  orb->detectAndCompute(d.kf_gray, cv::noArray(), d.kf_cv, d.kf_mat);
  orb->detectAndCompute(d.cur_gray, cv::noArray(), d.cur_cv, d.cur_mat);
  // ORB's reference time: the median of a few runs on the current frame.
  std::vector<double> t;
  std::vector<cv::KeyPoint> k;
  cv::Mat desc;
  for (int i = 0; i < 15; ++i) {
    const double t0 = cpu_seconds();
    orb->detectAndCompute(d.cur_gray, cv::noArray(), k, desc);
    t.push_back(cpu_seconds() - t0);
  }
  std::sort(t.begin(), t.end());
  d.orb_seconds = t[t.size() / 2];
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (const auto& kp : d.kf_cv) {
    d.kf_kp.emplace_back(kp.pt.x, kp.pt.y);
    const long u = std::lround(kp.pt.x), v = std::lround(kp.pt.y);
    const float z = (u >= 0 && v >= 0 && u < a.width && v < a.height) ? a.depth_m[std::size_t(v * a.width + u)] : 0.f;
    d.kf_pts.push_back(z > 0.f ? d.camera.backproject(Vec2<float>(kp.pt.x, kp.pt.y), z) : Vec3<float>(nan, nan, nan));
  }
  for (const auto& kp : d.cur_cv) d.cur_kp.emplace_back(kp.pt.x, kp.pt.y);
  d.kf_desc = rows_of(d.kf_mat);
  d.cur_desc = rows_of(d.cur_mat);
  return d;
}
#else
// Without OpenCV: 1000 random keypoints with depth, moved 2 cm, random descriptors with 6 bits flipped.
MatchData build_data() {
  MatchData d;
  d.camera = dyncull::PinholeCamera<float>::tum_fr3();
  d.cam_from_kf.t = Vec3<float>(0.02f, 0.f, 0.f);
  dyncull::Random rng(5);
  for (int i = 0; i < 1000; ++i) {
    const Vec2<float> uv(float(rng.uniform(0, 639)), float(rng.uniform(0, 479)));
    d.kf_kp.push_back(uv);
    d.kf_pts.push_back(d.camera.backproject(uv, float(rng.uniform(1, 5))));
    d.cur_kp.push_back(d.camera.project(d.cam_from_kf.apply(d.kf_pts.back())));
  }
  d.kf_desc.resize(32 * 1000);
  for (auto& x : d.kf_desc) x = static_cast<std::uint8_t>(rng.next() >> 56);
  d.cur_desc = d.kf_desc;
  for (int f = 0; f < 6000; ++f) d.cur_desc[rng.index(32000)] ^= static_cast<std::uint8_t>(1u << rng.index(8));
  return d;
}
#endif

const MatchData& data() {
  static const MatchData d = build_data();
  return d;
}

/// Share of matched pairs whose keyframe point, moved by the true motion, lands within 3 px of the
/// current keypoint (only points with depth are judged).
double inlier_share(const MatchData& d, const dyncull::KeyframeMatchResult<float>& r) {
  std::size_t judged = 0, good = 0;
  for (std::size_t i = 0; i < r.keyframe_index.size(); ++i) {
    const int k = r.keyframe_index[i];
    if (k < 0 || !d.kf_pts[std::size_t(k)].allFinite()) continue;
    ++judged;
    const Vec2<float> p = d.camera.project(d.cam_from_kf.apply(d.kf_pts[std::size_t(k)]));
    good += (p - d.cur_kp[i]).squaredNorm() <= 9.f;
  }
  return judged ? double(good) / double(judged) : 0.0;
}

/// Mean number of current keypoints inside a keyframe point's search disc (the scan's work).
double mean_candidates(const MatchData& d, const dyncull::KeyframeMatchWorkspace<float>& ws,
                       const dyncull::KeyframeMatchOptions& o) {
  double sum = 0;
  std::size_t searched = 0;
  for (std::size_t k = 0; k < ws.pred_x.size(); ++k) {
    if (!std::isfinite(ws.pred_x[k])) continue;
    ++searched;
    const double r = ws.pred_depth[k] ? o.radius_px : o.radius_unpredicted_px;
    for (const auto& c : d.cur_kp)
      sum += (c - Vec2<float>(ws.pred_x[k], ws.pred_y[k])).squaredNorm() <= float(r * r);
  }
  return searched ? sum / double(searched) : 0.0;
}

/// range(0): 0 = pose and depth, 1 = pose without depth (rotated rays), 2 = no pose (same pixel).
void BM_KeyframeMatcher(benchmark::State& state) {
  const MatchData& d = data();
  const int mode = static_cast<int>(state.range(0));
  const std::vector<Vec3<float>> no_depth;
  const std::vector<Vec3<float>>& pts = mode == 0 ? d.kf_pts : no_depth;
  const dyncull::Rigid3<float>* pose = mode == 2 ? nullptr : &d.cam_from_kf;
  dyncull::KeyframeMatchWorkspace<float> ws;
  dyncull::KeyframeMatchResult<float> r;
  const dyncull::KeyframeMatchOptions o;
  const dyncull::DescriptorRows kf(d.kf_desc.data(), d.kf_kp.size()), cur(d.cur_desc.data(), d.cur_kp.size());
  const double t0 = cpu_seconds();
  for (auto _ : state) {
    dyncull::match_to_keyframe(d.kf_kp, pts, kf, d.cur_kp, cur, d.camera, pose, o, ws, &r);
    benchmark::DoNotOptimize(r.keyframe_index.data());
  }
  const double per_call = (cpu_seconds() - t0) / double(state.iterations());
  state.counters["keypoints"] = double(d.cur_kp.size());
  state.counters["matched"] = double(r.matched);
  state.counters["inliers"] = inlier_share(d, r);
  state.counters["candidates"] = mean_candidates(d, ws, o);
  state.counters["capped"] = double(r.searches_capped);  // searches subsampled by max_candidates: 0 here
  if (d.orb_seconds > 0) state.counters["vs_orb"] = per_call / d.orb_seconds;
  state.SetLabel(mode == 0 ? "pose + depth" : (mode == 1 ? "pose, no depth" : "no pose"));
}
BENCHMARK(BM_KeyframeMatcher)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);

/// The worst case of a per-disc search: range(0) keyframe and as many current keypoints, all in one 20 px
/// patch, random descriptors, no pose (every disc holds the whole patch). KeyframeMatchOptions::max_candidates
/// bounds each search, so the time grows linearly with the keypoints. Counters: `examined` = current
/// keypoints examined per keyframe point, `capped` = share of searches that were subsampled.
void BM_KeyframeMatcherClustered(benchmark::State& state) {
  const std::size_t n = static_cast<std::size_t>(state.range(0));
  dyncull::Random rng(7);
  std::vector<Vec2<float>> kf, cur;
  for (std::size_t i = 0; i < n; ++i) {
    kf.emplace_back(float(300 + rng.uniform(0, 20)), float(200 + rng.uniform(0, 20)));
    cur.emplace_back(float(300 + rng.uniform(0, 20)), float(200 + rng.uniform(0, 20)));
  }
  std::vector<std::uint8_t> kd(32 * n), cd(32 * n);
  for (auto& b : kd) b = static_cast<std::uint8_t>(rng.next() >> 56);
  for (auto& b : cd) b = static_cast<std::uint8_t>(rng.next() >> 56);
  const std::vector<Vec3<float>> no_depth;
  const auto camera = dyncull::PinholeCamera<float>::tum_fr3();
  dyncull::KeyframeMatchWorkspace<float> ws;
  dyncull::KeyframeMatchResult<float> r;
  const dyncull::KeyframeMatchOptions o;
  for (auto _ : state) {
    dyncull::match_to_keyframe(kf, no_depth, dyncull::DescriptorRows(kd.data(), n), cur,
                               dyncull::DescriptorRows(cd.data(), n), camera, nullptr, o, ws, &r);
    benchmark::DoNotOptimize(r.keyframe_index.data());
  }
  state.counters["keypoints"] = double(n);
  state.counters["examined"] = double(r.examined) / double(n);
  state.counters["capped"] = double(r.searches_capped) / double(n);
  state.SetLabel("20 px patch, no pose");
}
BENCHMARK(BM_KeyframeMatcherClustered)->Arg(1000)->Arg(5000)->Arg(20000)->Unit(benchmark::kMillisecond);

#ifdef DYNCULL_HAS_OPENCV
void BM_OpenCvOrbDetectAndCompute(benchmark::State& state) {
  const MatchData& d = data();
  auto orb = cv::ORB::create(1000);
  std::vector<cv::KeyPoint> k;
  cv::Mat desc;
  for (auto _ : state) {
    orb->detectAndCompute(d.cur_gray, cv::noArray(), k, desc);
    benchmark::DoNotOptimize(desc.data);
  }
  state.counters["keypoints"] = double(k.size());
}
BENCHMARK(BM_OpenCvOrbDetectAndCompute)->Unit(benchmark::kMicrosecond);

void BM_OpenCvBfKnnMatch(benchmark::State& state) {
  const MatchData& d = data();
  cv::BFMatcher matcher(cv::NORM_HAMMING);
  std::vector<std::vector<cv::DMatch>> knn;
  const double t0 = cpu_seconds();
  for (auto _ : state) {
    matcher.knnMatch(d.cur_mat, d.kf_mat, knn, 2);
    benchmark::DoNotOptimize(knn.data());
  }
  const double per_call = (cpu_seconds() - t0) / double(state.iterations());
  state.counters["vs_orb"] = per_call / d.orb_seconds;
}
BENCHMARK(BM_OpenCvBfKnnMatch)->Unit(benchmark::kMicrosecond);

/// range(0) x range(0) window, range(1) pyramid levels (maxLevel + 1): the keyframe's ORB points tracked
/// into the current frame.
void BM_OpenCvPyrLK(benchmark::State& state) {
  const MatchData& d = data();
  const int win = static_cast<int>(state.range(0)), levels = static_cast<int>(state.range(1));
  std::vector<cv::Point2f> from, to;
  for (const auto& kp : d.kf_cv) from.push_back(kp.pt);
  std::vector<std::uint8_t> status;
  std::vector<float> err;
  const double t0 = cpu_seconds();
  for (auto _ : state) {
    cv::calcOpticalFlowPyrLK(d.kf_gray, d.cur_gray, from, to, status, err, cv::Size(win, win), levels - 1);
    benchmark::DoNotOptimize(to.data());
  }
  const double per_call = (cpu_seconds() - t0) / double(state.iterations());
  state.counters["vs_orb"] = per_call / d.orb_seconds;
  state.counters["tracked"] = double(std::count(status.begin(), status.end(), std::uint8_t(1)));
}
BENCHMARK(BM_OpenCvPyrLK)->Args({11, 2})->Args({21, 3})->Unit(benchmark::kMicrosecond);
#endif

}  // namespace
