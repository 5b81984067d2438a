// Counts the heap allocations CullerCore::cull makes per frame after warm-up (a counting global operator new in
// this executable only): none of its own (matching, keyframe store, evidence arrays) with a pipeline that
// does next to nothing, and none in all with the recommended preset (its F and pose fits, depth masks and
// stage reasons reuse buffers kept across frames).
#include "dyncull/culling/culler_core.hpp"

#include "dyncull/core/random.hpp"

#include "support/counting_allocator.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <vector>

namespace dyncull {
namespace {

/// Textured points 2.5-4 m away seen from a camera sliding along x, one descriptor per point, a person box
/// over part of the view; keyframes come from the own policy as the camera moves.
struct View {
  std::vector<Vec2<float>> keys;
  std::vector<std::uint8_t> desc;
  std::vector<float> depth;
  std::vector<Detection<float>> detections;
  Rigid3<float> pose;
};

std::vector<View> sequence(int frames) {
  const PinholeCamera<float> cam = PinholeCamera<float>::tum_fr3();
  std::vector<View> out;
  for (int k = 0; k < frames; ++k) {
    View v;
    Random rng(5);
    v.pose.t = Vec3<float>(-0.03f * float(k), 0.f, 0.f);
    v.depth.assign(640 * 480, 0.f);
    for (int j = 0; j < 900; ++j) {
      const Vec3<float> pw(float(rng.uniform(-2, 2)), float(rng.uniform(-1.4, 1.4)), float(rng.uniform(2.5, 4)));
      std::uint8_t d[32];
      for (auto& b : d) b = static_cast<std::uint8_t>(rng.next() & 0xFF);
      const Vec3<float> pc = v.pose.apply(pw);
      const Vec2<float> px = cam.project(pc);
      if (!cam.in_image(px.x(), px.y(), 16.f)) continue;
      const int u = int(std::lround(px.x())), w = int(std::lround(px.y()));
      for (int dv = -2; dv <= 2; ++dv)
        for (int du = -2; du <= 2; ++du) v.depth[std::size_t((w + dv) * 640 + u + du)] = pc.z();
      v.keys.push_back(px);
      v.desc.insert(v.desc.end(), d, d + 32);
    }
    Detection<float> person;
    person.box = Box<float>{200.f, 100.f, 360.f, 400.f};
    person.class_id = 0;
    person.confidence = 0.9f;
    v.detections.push_back(person);
    out.push_back(std::move(v));
  }
  return out;
}

/// Allocations of each frame of the last round, after `warmup_rounds` replays of the sequence.
std::vector<std::size_t> allocations_per_frame(const CullerCoreOptions<float>& options, const std::vector<View>& seq,
                                               int warmup_rounds, Status* last_status) {
  CullerCore<float> culler(PinholeCamera<float>::tum_fr3(), options);
  std::vector<std::size_t> counts;
  for (int round = 0; round <= warmup_rounds; ++round) {
    for (const View& v : seq) {
      CullerCoreFrame<float> f;
      f.keypoints = points_view(v.keys);
      f.descriptors = DescriptorRows(v.desc.data(), v.keys.size(), 0, 32);
      f.depth_m = DepthView<float>{v.depth.data(), 640, 480, 0, 1.f, 0.f, 1e30f};
      f.detections = &v.detections;
      f.cam_from_world = &v.pose;
      const std::size_t before = test::allocations();
      *last_status = culler.cull(f).status;
      if (round == warmup_rounds) counts.push_back(test::allocations() - before);
    }
  }
  return counts;
}

TEST(CullerAllocations, NoneOfItsOwnPerFrameAfterWarmUp) {
  const std::vector<View> seq = sequence(10);
  CullerCoreOptions<float> own_only;
  own_only.pipeline = presets::none<float>();  // the pipeline does next to nothing: what is left is the culler's
  own_only.pipeline.detections.enabled = false;
  Status status = Status::Ok;
  const std::vector<std::size_t> counts = allocations_per_frame(own_only, seq, 3, &status);
  EXPECT_EQ(status, Status::Ok);
  for (std::size_t k = 0; k < counts.size(); ++k) EXPECT_EQ(counts[k], 0u) << "frame " << k;
}

TEST(CullerAllocations, RecommendedPresetNonePerFrameAfterWarmUp) {
  const std::vector<View> seq = sequence(10);
  Status status = Status::Ok;
  const std::vector<std::size_t> counts = allocations_per_frame(CullerCoreOptions<float>(), seq, 3, &status);
  std::size_t most = 0;
  for (std::size_t c : counts) most = std::max(most, c);
  std::printf("recommended through the culler: at most %zu allocations per frame after warm-up\n", most);
  RecordProperty("recommended", static_cast<int>(most));
  for (std::size_t k = 0; k < counts.size(); ++k) EXPECT_EQ(counts[k], 0u) << "frame " << k;
}

}  // namespace
}  // namespace dyncull
