// The large-displacement stage of docs/design.md, "Adding a stage", inside cull_frame once listed in
// stages/list.hpp: its flags cull with its reason, its report and options are named as the stage, its
// missing input is named in the frame's reason, its options are validated, and it is declared.
#include "dyncull/culling/pipeline.hpp"
#include "dyncull/culling/stages/large_displacement.hpp"

#include <gtest/gtest.h>

#include <cstddef>
#include <string>
#include <vector>

namespace dyncull {
namespace {

template <class T>
class LargeDisplacementStageTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(LargeDisplacementStageTest, Scalars, );  // trailing comma: clang -Wpedantic rejects an empty variadic

/// 40 features on a grid, tracked from 2 px to the left; features 5, 17 and 30 jumped 60 px.
template <class T>
struct Tracks {
  std::vector<Vec2<T>> keypoints, prev;
  Tracks() {
    for (int i = 0; i < 40; ++i) {
      const Vec2<T> p(T(20 + 15 * (i % 8)), T(20 + 15 * (i / 8)));
      keypoints.push_back(p);
      prev.push_back(p - Vec2<T>(T(i == 5 || i == 17 || i == 30 ? 60 : 2), T(0)));
    }
  }
  CullingFrame<T, std::vector<Vec2<T>>> frame(bool with_prev = true) const {
    CullingFrame<T, std::vector<Vec2<T>>> f;
    f.keypoints = &keypoints;
    f.prev_keypoints = with_prev ? &prev : nullptr;
    return f;
  }
};

/// Only the new stage on: the box stages and the epipolar check would need detections and more tracks.
template <class T>
PipelineOptions<T> only_large_displacement() {
  PipelineOptions<T> o;
  o.detections.enabled = o.box_rule.enabled = o.moving_consistency.enabled = o.subbox.enabled = false;
  o.large_displacement.enabled = true;
  return o;
}

TYPED_TEST(LargeDisplacementStageTest, FlagsCullWithTheStageReason) {
  using T = TypeParam;
  const Tracks<T> tracks;
  PipelineState<T> state;
  const PipelineResult<T>& r = cull_frame(tracks.frame(), only_large_displacement<T>(), &state);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_TRUE(r.large_displacement.ran());
  EXPECT_EQ(r.large_displacement.num_dynamic, 3u);
  for (std::size_t i = 0; i < 40; ++i) {
    const bool jumped = i == 5 || i == 17 || i == 30;
    EXPECT_EQ(r.labels[i], jumped ? FeatureLabel::Dynamic : FeatureLabel::Static) << i;
    EXPECT_EQ(r.reasons[i], jumped ? CullReason::ListedStage : CullReason::None) << i;
    EXPECT_EQ(r.keep[i], jumped ? 0 : 1) << i;
  }
}

TYPED_TEST(LargeDisplacementStageTest, MissingPrevKeypointsAreNamed) {
  using T = TypeParam;
  const Tracks<T> tracks;
  PipelineState<T> state;
  const PipelineResult<T>& r = cull_frame(tracks.frame(false), only_large_displacement<T>(), &state);
  EXPECT_EQ(r.status, Status::MissingInput);
  EXPECT_EQ(r.reason, "large_displacement: no prev_keypoints given");
  EXPECT_TRUE(r.labelled());
  EXPECT_EQ(r.num_dynamic, 0u);
}

TYPED_TEST(LargeDisplacementStageTest, OptionsAreValidatedUnderTheStageName) {
  using T = TypeParam;
  const Tracks<T> tracks;
  auto o = only_large_displacement<T>();
  o.large_displacement.max_displacement_px = T(-1);
  std::string why;
  EXPECT_EQ(o.validate(&why), Status::InvalidInput);
  EXPECT_EQ(why.find("large_displacement.max_displacement_px"), 0u) << why;
  PipelineState<T> state;
  const PipelineResult<T>& r = cull_frame(tracks.frame(), o, &state);
  EXPECT_TRUE(r.refused);
  EXPECT_EQ(r.num_dynamic, 0u);
}

TYPED_TEST(LargeDisplacementStageTest, DeclaredBetweenTheRegionVotesAndTheStaticHistory) {
  using T = TypeParam;
  EXPECT_LT(stage_index<T>("subbox"), stage_index<T>("large_displacement"));
  EXPECT_LT(stage_index<T>("large_displacement"), stage_index<T>("static_history"));
  EXPECT_TRUE(reads(inputs_read(only_large_displacement<T>()), FrameInput::PrevKeypoints));
  EXPECT_FALSE(reads(inputs_read(only_large_displacement<T>()), FrameInput::Depth));
}

TYPED_TEST(LargeDisplacementStageTest, DisabledCullsNothing) {
  using T = TypeParam;
  const Tracks<T> tracks;
  auto o = only_large_displacement<T>();
  o.large_displacement.enabled = false;
  PipelineState<T> state;
  const PipelineResult<T>& r = cull_frame(tracks.frame(), o, &state);
  EXPECT_TRUE(r.ok()) << r.reason;
  EXPECT_FALSE(r.large_displacement.enabled);
  EXPECT_EQ(r.num_dynamic, 0u);
}

}  // namespace
}  // namespace dyncull
