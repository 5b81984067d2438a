// The stateful culler's whole per-frame cost, templated core (culling/culler_core.hpp) and compiled public
// culler (culling/culler.hpp): its own guided matching to the keyframe, the keyframe's 3-D points, the
// recommended pipeline, the keyframe policy, on ~1000 ORB features of the
// 640x480 synthetic walking scene, next to cv::ORB detectAndCompute of the same frames in the same binary.
// Counter `vs_orb` = the culler's CPU time per frame / ORB's on the same frames (target <= 0.35);
// `keyframes` = share of frames that became keyframes.
#include "dyncull/culling/culler.hpp"
#include "dyncull/culling/culler_core.hpp"

#include "dyncull/sim/scene.hpp"

#include <benchmark/benchmark.h>

#ifdef DYNCULL_HAS_OPENCV
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#endif

#include "culling/cpu_time.hpp"

#include <algorithm>
#include <array>
#include <memory>
#include <chrono>
#include <cstdint>
#include <vector>

namespace {

using dyncull::bench::cpu_seconds;

#ifdef DYNCULL_HAS_OPENCV
using dyncull::Vec2;

struct Frame {
  cv::Mat gray;
  std::vector<Vec2<float>> keys;
  std::vector<std::uint8_t> descriptors;  // 32 bytes per key
  std::vector<float> depth;
  std::vector<dyncull::Detection<float>> detections;
  dyncull::Rigid3<float> cam_from_world;
};

struct Sequence {
  dyncull::PinholeCamera<float> camera;
  std::vector<Frame> frames;
  double orb_seconds = 0;  // median ORB detectAndCompute per frame
  std::size_t features = 0;
};

const Sequence& sequence() {
  static const Sequence seq = [] {
    cv::setNumThreads(1);  // ORB on one core, as the culler runs
    Sequence s;
    dyncull::sim::SceneOptions options;
    options.num_frames = 30;
    const dyncull::sim::Scene scene(options);
    s.camera = scene.camera().cast<float>();
    auto orb = cv::ORB::create(1000);
    std::vector<double> t;
    dyncull::sim::FrameData f;
    for (int i = 0; i < options.num_frames; ++i) {
      scene.render(i, &f);
      Frame fr;
      cv::Mat(f.height, f.width, CV_8UC1, f.gray.data()).copyTo(fr.gray);
      std::vector<cv::KeyPoint> keys;
      cv::Mat desc;
      orb->detectAndCompute(fr.gray, cv::noArray(), keys, desc);  // warm
      for (int r = 0; r < 5; ++r) {
        const double t0 = cpu_seconds();
        orb->detectAndCompute(fr.gray, cv::noArray(), keys, desc);
        t.push_back(cpu_seconds() - t0);
      }
      for (const cv::KeyPoint& k : keys) fr.keys.emplace_back(k.pt.x, k.pt.y);
      fr.descriptors.assign(desc.datastart, desc.dataend);
      fr.depth = f.depth_m;
      fr.detections = f.detections;
      fr.cam_from_world = f.world_from_cam.inverse().cast<float>();
      s.features += keys.size();
      s.frames.push_back(std::move(fr));
    }
    std::nth_element(t.begin(), t.begin() + long(t.size() / 2), t.end());
    s.orb_seconds = t[t.size() / 2];
    return s;
  }();
  return seq;
}

/// The core's frame of sequence frame `f`.
dyncull::CullerCoreFrame<float> core_frame(const Sequence& s, const Frame& f) {
  dyncull::CullerCoreFrame<float> in;
  in.keypoints = dyncull::points_view(f.keys);
  in.descriptors = dyncull::DescriptorRows(f.descriptors.data(), f.keys.size(), 32, 32);
  in.depth_m = dyncull::DepthView<float>{f.depth.data(), s.camera.width, s.camera.height, 0, 1.f, 0.4f, 8.f};
  in.detections = &f.detections;
  in.cam_from_world = &f.cam_from_world;
  return in;
}

/// One pass over the sequence with a fresh culler per iteration (`make`), each frame culled by
/// `cull(culler, i)` after an untimed `prepare(i)`; the first frame (no keyframe yet) is not timed.
template <class Make, class Cull, class Prepare = void (*)(std::size_t)>
void time_sequence(benchmark::State& state, const Sequence& s, Make make, Cull cull,
                   Prepare prepare = [](std::size_t) {}) {
  double seconds = 0;
  std::size_t frames = 0, keyframes = 0;
  for (auto _ : state) {
    auto culler = make();
    for (std::size_t i = 0; i < s.frames.size(); ++i) {
      prepare(i);
      const double t0 = cpu_seconds();
      const dyncull::CullerResult& r = cull(*culler, i);
      const double dt = cpu_seconds() - t0;
      benchmark::DoNotOptimize(r.num_kept);
      if (i == 0) continue;
      seconds += dt;
      ++frames;
      keyframes += r.keyframe;
    }
  }
  const double per_frame = seconds / double(frames);
  state.counters["frame_us"] = 1e6 * per_frame;
  state.counters["orb_us"] = 1e6 * s.orb_seconds;
  state.counters["vs_orb"] = per_frame / s.orb_seconds;
  state.counters["features"] = double(s.features) / double(s.frames.size());
  state.counters["keyframes"] = double(keyframes) / double(frames);
}

/// The templated core (culling/culler_core.hpp), header-only.
void BM_CullerPerFrame(benchmark::State& state) {
  const Sequence& s = sequence();
  time_sequence(
      state, s, [&] { return std::make_unique<dyncull::CullerCore<float>>(s.camera); },
      [&](dyncull::CullerCore<float>& c, std::size_t i) -> const dyncull::CullerResult& {
        return c.cull(core_frame(s, s.frames[i]));
      });
}
BENCHMARK(BM_CullerPerFrame)->Unit(benchmark::kMillisecond);

/// The templated core reading each frame's depth from one buffer the frame's depth is written into just
/// before the (timed) cull, as a host writes it when it converts the depth image (ORB-SLAM2/3: to float
/// metres, then reading it at every keypoint): the depth is in cache, as in a host. The case above reads
/// the frame's own stored image, cold after the other frames.
void BM_CullerPerFrameHostDepth(benchmark::State& state) {
  const Sequence& s = sequence();
  std::vector<float> depth(s.frames[0].depth.size());
  time_sequence(
      state, s, [&] { return std::make_unique<dyncull::CullerCore<float>>(s.camera); },
      [&](dyncull::CullerCore<float>& c, std::size_t i) -> const dyncull::CullerResult& {
        dyncull::CullerCoreFrame<float> in = core_frame(s, s.frames[i]);
        in.depth_m.data = depth.data();
        return c.cull(in);
      },
      [&](std::size_t i) { std::copy(s.frames[i].depth.begin(), s.frames[i].depth.end(), depth.begin()); });
}
BENCHMARK(BM_CullerPerFrameHostDepth)->Unit(benchmark::kMillisecond);

/// The public culler (culling/culler.hpp, compiled into dyncull::culler) on the same frames: the same core
/// behind the C++11 header, boxes and pose converted per frame.
void BM_PublicCullerPerFrame(benchmark::State& state) {
  const Sequence& s = sequence();
  std::vector<std::vector<dyncull::DetectedBox>> boxes(s.frames.size());
  std::vector<std::array<double, 12>> poses(s.frames.size());
  for (std::size_t i = 0; i < s.frames.size(); ++i) {
    for (const auto& d : s.frames[i].detections)
      boxes[i].emplace_back(d.box.x0, d.box.y0, d.box.x1, d.box.y1, d.class_id, d.confidence);
    const dyncull::Rigid3<float>& p = s.frames[i].cam_from_world;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) poses[i][std::size_t(4 * r + c)] = p.R(r, c);
      poses[i][std::size_t(4 * r + 3)] = p.t(r);
    }
  }
  const dyncull::CullerCamera camera(s.camera.fx, s.camera.fy, s.camera.cx, s.camera.cy, s.camera.width,
                                     s.camera.height);
  time_sequence(
      state, s, [&] { return std::make_unique<dyncull::Culler>(camera); },
      [&](dyncull::Culler& c, std::size_t i) -> const dyncull::CullerResult& {
        const dyncull::CullerCoreFrame<float> core = core_frame(s, s.frames[i]);
        dyncull::CullerFrame in;
        in.keypoints = core.keypoints;
        in.descriptors = core.descriptors;
        in.depth_m = core.depth_m;
        in.detections = &boxes[i];
        in.cam_from_world = poses[i].data();
        return c.cull(in);
      });
}
BENCHMARK(BM_PublicCullerPerFrame)->Unit(benchmark::kMillisecond);

void BM_OpenCvOrbDetectAndCompute(benchmark::State& state) {
  const Sequence& s = sequence();
  auto orb = cv::ORB::create(1000);
  std::vector<cv::KeyPoint> keys;
  cv::Mat desc;
  std::size_t i = 0;
  for (auto _ : state) {
    orb->detectAndCompute(s.frames[i].gray, cv::noArray(), keys, desc);
    benchmark::DoNotOptimize(keys.data());
    i = (i + 1) % s.frames.size();
  }
}
BENCHMARK(BM_OpenCvOrbDetectAndCompute)->Unit(benchmark::kMicrosecond);
#else
void BM_CullerNeedsOpenCv(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(cpu_seconds());
  state.SetLabel("built without OpenCV: no ORB to compare with");
}
BENCHMARK(BM_CullerNeedsOpenCv);
#endif

}  // namespace
