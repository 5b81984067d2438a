/// @file pipeline_precompiled_runs.hpp
/// A short synthetic sequence run through cull_frame, recording every frame's outcome, shared by the
/// translation unit that takes cull_frame from dyncull::pipeline (DYNCULL_PRECOMPILED) and the one that
/// instantiates it header-only, so the two can be compared label by label.
#pragma once

#include "dyncull/culling/pipeline.hpp"
#include "dyncull/culling/presets.hpp"

#include "support/culling_frames.hpp"
#include "support/culling_scenes.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace dyncull {
namespace test {

/// One frame of the sequence with everything a front end can give (tracks, ids, 3-D points, both depths).
template <class T>
struct SequenceFrame {
  CullingScene<T> scene;
  std::vector<Detection<T>> detections;
  std::vector<std::int64_t> ids;
  std::vector<std::uint16_t> depth_tum;
  bool keyframe = false;
};

/// Frame k: the scene drawn with seed k, tracks over 1-3 frames, the first box missed in frame 3, a keyframe
/// every third frame (so the multi-view check has references).
template <class T>
std::vector<SequenceFrame<T>> precompiled_sequence(int frames) {
  SceneConfig config;
  std::vector<SequenceFrame<T>> out;
  for (int k = 0; k < frames; ++k) {
    config.seed = 300 + static_cast<std::uint64_t>(k);
    config.frames_between = 1 + k % 3;
    SequenceFrame<T> f;
    f.scene = make_culling_scene<T>(config);
    const std::vector<Detection<T>> all = detections_of(f.scene);
    for (std::size_t b = 0; b < all.size(); ++b)
      if (!(k == 3 && b == 0)) f.detections.push_back(all[b]);
    f.ids.resize(f.scene.size());
    for (std::size_t i = 0; i < f.ids.size(); ++i) f.ids[i] = static_cast<std::int64_t>(i);
    f.depth_tum = f.scene.depth_tum();
    f.keyframe = k % 3 == 0;
    out.push_back(std::move(f));
  }
  return out;
}

/// What a frame's result says, feature by feature.
struct FrameOutcome {
  Status status = Status::Ok;
  std::string reason;
  std::vector<FeatureLabel> labels;
  std::vector<CullReason> reasons;
  std::vector<std::uint8_t> keep;
  std::size_t num_static = 0;
};

/// The papers' presets and the recommended one.
template <class T>
std::vector<std::pair<std::string, PipelineOptions<T>>> precompiled_presets() {
  return {{"none", presets::none<T>()},         {"dld_slam", presets::dld_slam<T>()},
          {"rtd_slam", presets::rtd_slam<T>()}, {"zhu_2024", presets::zhu_2024<T>()},
          {"dfd_slam", presets::dfd_slam<T>()}, {"zhang_2023", presets::zhang_2023<T>()},
          {"recommended", presets::recommended<T>()}};
}

/// Runs the sequence with one state; make_frame(i) gives the CullingFrame of frame i.
template <class T, class MakeFrame>
std::vector<FrameOutcome> run_sequence(const std::vector<SequenceFrame<T>>& seq, const PipelineOptions<T>& options,
                                       MakeFrame make_frame) {
  PipelineState<T> state;
  std::vector<FrameOutcome> out;
  for (std::size_t i = 0; i < seq.size(); ++i) {
    const PipelineResult<T>& r = cull_frame(make_frame(i), options, &state);
    out.push_back(FrameOutcome{r.status, r.reason, r.labels, r.reasons, r.keep, r.num_static});
  }
  return out;
}

/// Sets the fields every run passes (tracks, ids, 3-D points, detections, camera, pose, keyframe flag).
template <class T, class Frame>
void fill_common(const SequenceFrame<T>& f, Frame* frame) {
  frame->track_valid = f.scene.track_valid;
  frame->track_ids = &f.ids;
  frame->points_3d = &f.scene.prev_points_world;
  frame->detections = &f.detections;
  frame->camera = f.scene.camera;
  frame->cam_from_world = &f.scene.cam_from_world;
  frame->is_keyframe = f.keyframe;
  frame->evidence_frames = 1;
}

/// The header-only runs (pipeline_precompiled_header_only.cpp): keypoints as a plain xy struct, so
/// cull_frame is instantiated in that translation unit and not taken from the library.
template <class T>
std::vector<FrameOutcome> run_header_only(const std::vector<SequenceFrame<T>>& seq, const PipelineOptions<T>& options,
                                          bool tum_depth);

}  // namespace test
}  // namespace dyncull
