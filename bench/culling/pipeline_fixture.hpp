/// @file pipeline_fixture.hpp
/// The culling benches' realistic frame: a ray-cast scene (tests/support/culling_scenes.hpp) at about 1000
/// features, 5 boxes (person, sitting person, chair, TV and a cup), 640x480 depth, a keyframe 8 frames back.
#pragma once

#include "dyncull/culling/pipeline_types.hpp"

#include "support/culling_frames.hpp"
#include "support/culling_scenes.hpp"

#include <cstdint>
#include <vector>

namespace dyncull {
namespace bench {

struct PipelineBenchData {
  test::CullingScene<float> scene;
  test::SceneKeyframe<float> keyframe;
  std::vector<Detection<float>> dets;
  std::vector<std::int64_t> ids;  ///< a track id per feature
};

inline const PipelineBenchData& pipeline_bench_data() {
  static const PipelineBenchData d = [] {
    PipelineBenchData x;
    test::SceneConfig config;
    config.num_uniform = 760;
    x.scene = test::make_culling_scene<float>(config);
    x.keyframe = test::make_scene_keyframe<float>(config, 8, 600);
    x.dets = x.scene.detections;
    // A fifth box: a cup (medium level) on the desk.
    x.dets.push_back(Detection<float>{Box<float>{300.f, 330.f, 360.f, 390.f}, 41, 0.8f});
    x.ids.resize(x.scene.size());
    for (std::size_t i = 0; i < x.ids.size(); ++i) x.ids[i] = static_cast<std::int64_t>(i);
    return x;
  }();
  return d;
}

/// The frame as a front end passes it. with_points: each track's 3-D point at the previous frame (the
/// reprojection check's input); with_ids: the track ids (sub-box memory, static history).
inline CullingFrame<float, std::vector<Vec2<float>>> pipeline_bench_frame(const PipelineBenchData& d,
                                                                          bool with_points = false,
                                                                          bool with_ids = false) {
  auto frame = test::frame_of(d.scene, d.dets);
  if (with_points) frame.points_3d = &d.scene.prev_points_world;
  if (with_ids) frame.track_ids = &d.ids;
  return frame;
}

}  // namespace bench
}  // namespace dyncull
