// The box-margin stage of docs/design.md, "Adding a stage", inside cull_frame once listed in
// stages/list.hpp: its candidates are culled with its reason, its report and options are named as the
// stage, its missing input is named in the frame's reason, its options are validated, and it is declared
// between the depth masks and the geometric stages.
#include "dyncull/culling/pipeline.hpp"
#include "dyncull/culling/stages/box_margin.hpp"

#include <gtest/gtest.h>

#include <cstddef>
#include <string>
#include <vector>

namespace dyncull {
namespace {

template <class T>
class BoxMarginStageTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(BoxMarginStageTest, Scalars, );  // trailing comma: clang -Wpedantic rejects an empty variadic

/// A person's box over x in [50, 100]; features inside it (0), 5 px left and right of it (1, 2) and far
/// from it (3).
template <class T>
struct PersonFrame {
  std::vector<Vec2<T>> keypoints{{T(75), T(100)}, {T(45), T(100)}, {T(105), T(100)}, {T(200), T(100)}};
  std::vector<Detection<T>> boxes{{Box<T>{T(50), T(50), T(100), T(150)}, /*class_id=*/0, T(0.9)}};
  CullingFrame<T, std::vector<Vec2<T>>> frame(bool with_boxes = true) const {
    CullingFrame<T, std::vector<Vec2<T>>> f;
    f.keypoints = &keypoints;
    f.detections = with_boxes ? &boxes : nullptr;
    return f;
  }
};

/// The box rule and the new stage; candidates culled, so the stage's labels show in the result.
template <class T>
PipelineOptions<T> box_rule_with_margin() {
  PipelineOptions<T> o;
  o.detections.enabled = o.moving_consistency.enabled = o.subbox.enabled = false;
  o.box_margin.enabled = true;
  o.guard.enabled = false;  // four features: the survivor guard would undo every cull
  o.candidates = CandidatePolicy::Cull;
  return o;
}

TYPED_TEST(BoxMarginStageTest, CandidatesInTheMarginCullWithTheStageReason) {
  using T = TypeParam;
  const PersonFrame<T> person;
  PipelineState<T> state;
  const PipelineResult<T>& r = cull_frame(person.frame(), box_rule_with_margin<T>(), &state);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_TRUE(r.box_margin.ran());
  EXPECT_EQ(r.reasons, (std::vector<CullReason>{CullReason::HighLevelBox, CullReason::ListedStage,
                                                CullReason::ListedStage, CullReason::None}));
  EXPECT_EQ(r.keep, (std::vector<std::uint8_t>{0, 0, 0, 1}));
}

TYPED_TEST(BoxMarginStageTest, CandidatesAreVerifiedAsTheBoxRulesAre) {
  using T = TypeParam;
  const PersonFrame<T> person;
  auto o = box_rule_with_margin<T>();
  o.candidates = CandidatePolicy::Verify;  // no geometric stage flags them: they stay
  PipelineState<T> state;
  const PipelineResult<T>& r = cull_frame(person.frame(), o, &state);
  EXPECT_EQ(r.keep, (std::vector<std::uint8_t>{0, 1, 1, 1}));
}

TYPED_TEST(BoxMarginStageTest, MissingDetectionsAreNamed) {
  using T = TypeParam;
  const PersonFrame<T> person;
  PipelineState<T> state;
  const PipelineResult<T>& r = cull_frame(person.frame(false), box_rule_with_margin<T>(), &state);
  EXPECT_EQ(r.status, Status::MissingInput);
  EXPECT_NE(r.reason.find("box_margin: no detections given"), std::string::npos) << r.reason;
  EXPECT_EQ(r.num_dynamic, 0u);
}

TYPED_TEST(BoxMarginStageTest, OptionsAreValidatedUnderTheStageName) {
  using T = TypeParam;
  auto o = box_rule_with_margin<T>();
  o.box_margin.margin_px = T(-1);
  std::string why;
  EXPECT_EQ(o.validate(&why), Status::InvalidInput);
  EXPECT_EQ(why.find("box_margin.margin_px"), 0u) << why;
}

TYPED_TEST(BoxMarginStageTest, DeclaredBetweenTheDepthMasksAndTheGeometricStages) {
  using T = TypeParam;
  EXPECT_LT(stage_index<T>("depth_mask"), stage_index<T>("box_margin"));
  EXPECT_LT(stage_index<T>("box_margin"), stage_index<T>("probability"));
  EXPECT_TRUE(reads(inputs_read(box_rule_with_margin<T>()), FrameInput::Detections));
}

TYPED_TEST(BoxMarginStageTest, DisabledLeavesTheBoxRuleAlone) {
  using T = TypeParam;
  const PersonFrame<T> person;
  auto o = box_rule_with_margin<T>();
  o.box_margin.enabled = false;
  PipelineState<T> state;
  const PipelineResult<T>& r = cull_frame(person.frame(), o, &state);
  EXPECT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.keep, (std::vector<std::uint8_t>{0, 1, 1, 1}));
}

}  // namespace
}  // namespace dyncull
