// The depth-range stage of docs/design.md, "Adding a stage", inside cull_frame once listed in
// stages/list.hpp: box labels beyond its range are dropped, its report and options are named as the
// stage, its missing input is named in the frame's reason, its options are validated, and it is declared
// between the depth masks and the geometric stages.
#include "dyncull/culling/pipeline.hpp"
#include "dyncull/culling/stages/depth_range.hpp"

#include <gtest/gtest.h>

#include <cstddef>
#include <string>
#include <vector>

namespace dyncull {
namespace {

template <class T>
class DepthRangeStageTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(DepthRangeStageTest, Scalars, );  // trailing comma: clang -Wpedantic rejects an empty variadic

/// A person's box over the left half of a 200 x 100 depth image: the person at 2 m in columns below 50,
/// the wall at 9 m behind; features on the person (0), on the wall inside the box (1) and outside it (2).
template <class T>
struct PersonBeforeAWall {
  std::vector<Vec2<T>> keypoints{{T(20), T(50)}, {T(80), T(50)}, {T(150), T(50)}};
  std::vector<Detection<T>> boxes{{Box<T>{T(0), T(0), T(100), T(99)}, /*class_id=*/0, T(0.9)}};
  std::vector<float> depth;
  PersonBeforeAWall() : depth(200 * 100) {
    for (int v = 0; v < 100; ++v)
      for (int u = 0; u < 200; ++u) depth[static_cast<std::size_t>(v * 200 + u)] = u < 50 ? 2.f : 9.f;
  }
  CullingFrame<T, std::vector<Vec2<T>>> frame(bool with_depth = true) const {
    CullingFrame<T, std::vector<Vec2<T>>> f;
    f.keypoints = &keypoints;
    f.detections = &boxes;
    if (with_depth) f.depth = DepthView<float>{depth.data(), 200, 100};
    return f;
  }
};

/// The box rule and the new stage.
template <class T>
PipelineOptions<T> box_rule_with_depth_range() {
  PipelineOptions<T> o;
  o.detections.enabled = o.moving_consistency.enabled = o.subbox.enabled = false;
  o.depth_range.enabled = true;
  o.guard.enabled = false;  // four features: the survivor guard would undo every cull
  return o;
}

TYPED_TEST(DepthRangeStageTest, BoxLabelsBeyondTheRangeAreDropped) {
  using T = TypeParam;
  const PersonBeforeAWall<T> scene;
  PipelineState<T> state;
  const PipelineResult<T>& r = cull_frame(scene.frame(), box_rule_with_depth_range<T>(), &state);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_TRUE(r.depth_range.ran());
  EXPECT_EQ(r.keep, (std::vector<std::uint8_t>{0, 1, 1}));
  EXPECT_EQ(r.reasons[0], CullReason::HighLevelBox);
  EXPECT_EQ(r.trace[1].in_object, 0u);
}

TYPED_TEST(DepthRangeStageTest, MissingDepthIsNamed) {
  using T = TypeParam;
  const PersonBeforeAWall<T> scene;
  PipelineState<T> state;
  const PipelineResult<T>& r = cull_frame(scene.frame(false), box_rule_with_depth_range<T>(), &state);
  EXPECT_EQ(r.status, Status::MissingInput);
  EXPECT_EQ(r.reason, "depth_range: no depth given");
  EXPECT_EQ(r.keep, (std::vector<std::uint8_t>{0, 0, 1}));  // the box rule's labels stand
}

TYPED_TEST(DepthRangeStageTest, OptionsAreValidatedUnderTheStageName) {
  using T = TypeParam;
  auto o = box_rule_with_depth_range<T>();
  o.depth_range.max_depth_m = 0;
  std::string why;
  EXPECT_EQ(o.validate(&why), Status::InvalidInput);
  EXPECT_EQ(why.find("depth_range.max_depth_m"), 0u) << why;
}

TYPED_TEST(DepthRangeStageTest, DeclaredBetweenTheDepthMasksAndTheGeometricStages) {
  using T = TypeParam;
  EXPECT_LT(stage_index<T>("depth_mask"), stage_index<T>("depth_range"));
  EXPECT_LT(stage_index<T>("depth_range"), stage_index<T>("probability"));
  EXPECT_TRUE(reads(inputs_read(box_rule_with_depth_range<T>()), FrameInput::Depth));
}

TYPED_TEST(DepthRangeStageTest, DisabledLeavesTheBoxRuleAlone) {
  using T = TypeParam;
  const PersonBeforeAWall<T> scene;
  auto o = box_rule_with_depth_range<T>();
  o.depth_range.enabled = false;
  PipelineState<T> state;
  const PipelineResult<T>& r = cull_frame(scene.frame(), o, &state);
  EXPECT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.keep, (std::vector<std::uint8_t>{0, 0, 1}));
}

}  // namespace
}  // namespace dyncull
