// The header-only side of pipeline_precompiled_test: this translation unit drops DYNCULL_PRECOMPILED, so
// the headers define the solvers inline and cull_frame is instantiated here, for keypoints held as a plain
// xy struct (a frame type the library does not hold).
#undef DYNCULL_PRECOMPILED
// The mixing rule's link guard (core/precompiled.hpp) is off in this test only: comparing the two forms in
// one binary is its purpose, and both come from the same source tree and flags.
#define DYNCULL_UNGUARDED_MIXING

#include "culling/pipeline_precompiled_runs.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace dyncull {
namespace test {
namespace {

template <class T>
struct XY {
  T x, y;
};

template <class T>
std::vector<XY<T>> xy_of(const std::vector<Vec2<T>>& points) {
  std::vector<XY<T>> out;
  for (const Vec2<T>& p : points) out.push_back(XY<T>{p.x(), p.y()});
  return out;
}

}  // namespace

template <class T>
std::vector<FrameOutcome> run_header_only(const std::vector<SequenceFrame<T>>& seq, const PipelineOptions<T>& options,
                                          bool tum_depth) {
  std::vector<std::vector<XY<T>>> keypoints, prev;
  for (const SequenceFrame<T>& f : seq) {
    keypoints.push_back(xy_of(f.scene.keypoints));
    prev.push_back(xy_of(f.scene.prev_keypoints));
  }
  auto make_float = [&](std::size_t i) {
    CullingFrame<T, std::vector<XY<T>>, std::vector<XY<T>>, float> frame;
    fill_common(seq[i], &frame);
    frame.keypoints = &keypoints[i];
    frame.prev_keypoints = &prev[i];
    frame.depth = seq[i].scene.depth_view();
    return frame;
  };
  auto make_tum = [&](std::size_t i) {
    CullingFrame<T, std::vector<XY<T>>, std::vector<XY<T>>, std::uint16_t> frame;
    fill_common(seq[i], &frame);
    frame.keypoints = &keypoints[i];
    frame.prev_keypoints = &prev[i];
    frame.depth = tum_depth_view(seq[i].depth_tum.data(), seq[i].scene.width, seq[i].scene.height);
    return frame;
  };
  return tum_depth ? run_sequence(seq, options, make_tum) : run_sequence(seq, options, make_float);
}

template std::vector<FrameOutcome> run_header_only(const std::vector<SequenceFrame<float>>&,
                                                   const PipelineOptions<float>&, bool);
template std::vector<FrameOutcome> run_header_only(const std::vector<SequenceFrame<double>>&,
                                                   const PipelineOptions<double>&, bool);

}  // namespace test
}  // namespace dyncull
