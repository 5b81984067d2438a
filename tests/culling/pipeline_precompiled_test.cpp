// cull_frame taken from dyncull::pipeline (this translation unit sees DYNCULL_PRECOMPILED: the standard
// frame types are declared extern and the solvers declared only) gives the labels, reasons, keep mask and
// status of cull_frame instantiated header-only (pipeline_precompiled_header_only.cpp), frame by frame, for
// every preset, float and double, depth in metres and in TUM units.
#include "culling/pipeline_precompiled_runs.hpp"

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#ifndef DYNCULL_PRECOMPILED
#error "pipeline_precompiled_test links dyncull::pipeline, whose interface defines DYNCULL_PRECOMPILED"
#endif

namespace dyncull {
namespace {

using test::FrameOutcome;
using test::SequenceFrame;

template <class T>
std::vector<FrameOutcome> run_precompiled(const std::vector<SequenceFrame<T>>& seq, const PipelineOptions<T>& options,
                                          bool tum_depth) {
  auto make_float = [&](std::size_t i) {
    PrecompiledCullingFrame<T, float> frame;
    test::fill_common(seq[i], &frame);
    frame.keypoints = &seq[i].scene.keypoints;
    frame.prev_keypoints = &seq[i].scene.prev_keypoints;
    frame.depth = seq[i].scene.depth_view();
    return frame;
  };
  auto make_tum = [&](std::size_t i) {
    PrecompiledCullingFrame<T, std::uint16_t> frame;
    test::fill_common(seq[i], &frame);
    frame.keypoints = &seq[i].scene.keypoints;
    frame.prev_keypoints = &seq[i].scene.prev_keypoints;
    frame.depth = tum_depth_view(seq[i].depth_tum.data(), seq[i].scene.width, seq[i].scene.height);
    return frame;
  };
  return tum_depth ? test::run_sequence(seq, options, make_tum) : test::run_sequence(seq, options, make_float);
}

template <class T>
class PrecompiledPipeline : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(PrecompiledPipeline, Scalars, );  // trailing comma: clang -Wpedantic rejects an empty variadic

TYPED_TEST(PrecompiledPipeline, GivesTheHeaderOnlyLabelsForEveryPresetAndDepthType) {
  using T = TypeParam;
  const std::vector<SequenceFrame<T>> seq = test::precompiled_sequence<T>(6);
  std::size_t culled = 0;
  for (const auto& [name, options] : test::precompiled_presets<T>()) {
    for (bool tum : {false, true}) {
      SCOPED_TRACE(name + (tum ? " (uint16 depth)" : " (float depth)"));
      const std::vector<FrameOutcome> lib = run_precompiled(seq, options, tum);
      const std::vector<FrameOutcome> ref = test::run_header_only(seq, options, tum);
      ASSERT_EQ(lib.size(), ref.size());
      for (std::size_t k = 0; k < lib.size(); ++k) {
        SCOPED_TRACE("frame " + std::to_string(k));
        EXPECT_EQ(lib[k].status, ref[k].status);
        EXPECT_EQ(lib[k].reason, ref[k].reason);
        EXPECT_EQ(lib[k].labels, ref[k].labels);
        EXPECT_EQ(lib[k].reasons, ref[k].reasons);
        EXPECT_EQ(lib[k].keep, ref[k].keep);
        EXPECT_EQ(lib[k].num_static, ref[k].num_static);
        culled += lib[k].labels.size() - lib[k].num_static;
      }
    }
  }
  EXPECT_GT(culled, 0u) << "the sequence culls nothing: the comparison would not exercise the stages";
}

}  // namespace
}  // namespace dyncull
