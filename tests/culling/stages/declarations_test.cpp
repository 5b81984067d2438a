// Tests of culling/stages/declarations.hpp: every stage of stages/list.hpp is declared once, in
// front-end order, with the name its option and its report have; what the presets read of a frame follows from the
// declarations; a stage lacking a declared input reports it by name and does not run.
#include "dyncull/culling/presets.hpp"
#include "dyncull/culling/stages/builtin.hpp"
#include "dyncull/culling/stages/declarations.hpp"

#include <gtest/gtest.h>

#include <set>
#include <string>
#include <vector>

namespace dyncull {
namespace {

template <class T>
class Declarations : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(Declarations, Scalars, );  // trailing comma: clang -Wpedantic rejects an empty variadic

TYPED_TEST(Declarations, EveryStageReportOnceInFrontEndOrder) {
  using T = TypeParam;
  std::vector<std::string> names;
  std::set<const void*> reports;
  PipelineResult<T> r;
  for (const StageDeclaration<T>& s : kStages<T>) {
    names.emplace_back(s.name);
    reports.insert(&(r.*s.report));
  }
  EXPECT_EQ(names, (std::vector<std::string>{"detections", "tracker", "box_rule", "depth_mask", "probability",
                                             "moving_consistency", "reprojection", "coherent_motion", "subbox",
                                             "multiview", "static_history"}));
  EXPECT_EQ(reports.size(), names.size());
}

// A stage that runs by its kind is listed where cull_frame runs it (the multi-view check, an evidence stage,
// after the sub-box vote), so the list's order is the order the stages run in.
TYPED_TEST(Declarations, StagesOfAKindAreListedWhereTheyRun) {
  using T = TypeParam;
  EXPECT_TRUE(detail::listed_where_they_run(PipelineStages<T>{}));
  EXPECT_TRUE(detail::listed_where_they_run(StageList<SubBoxStage<T>, MultiViewStage<T>, StaticHistoryStage<T>>{}));
  EXPECT_FALSE(detail::listed_where_they_run(StageList<DepthMaskStage<T>, MultiViewStage<T>, SubBoxStage<T>>{}));
  EXPECT_FALSE(detail::listed_where_they_run(StageList<MultiViewStage<T>, SubBoxStage<T>>{}));
}

// Each declaration's switch is the option of its name: turning one stage's option off turns off that
// declaration alone.
TYPED_TEST(Declarations, SwitchesAreTheStagesOwnOptions) {
  using T = TypeParam;
  PipelineOptions<T> all = presets::recommended<T>();
  all.probability.enabled = all.multiview.enabled = true;
  for (const StageDeclaration<T>& s : kStages<T>) EXPECT_TRUE(s.enabled(all)) << s.name;
  auto off = [&](const std::string& name) {
    PipelineOptions<T> o = all;
    if (name == "detections") o.detections.enabled = false;
    if (name == "tracker") o.tracker.enabled = false;
    if (name == "box_rule") o.box_rule.enabled = false;
    if (name == "depth_mask") o.depth_mask.enabled = false;
    if (name == "probability") o.probability.enabled = false;
    if (name == "moving_consistency") o.moving_consistency.enabled = false;
    if (name == "reprojection") o.reprojection.enabled = false;
    if (name == "coherent_motion") o.coherent_motion.enabled = false;
    if (name == "subbox") o.subbox.enabled = false;
    if (name == "multiview") o.multiview.enabled = false;
    if (name == "static_history") o.static_history.enabled = false;
    return o;
  };
  for (const StageDeclaration<T>& s : kStages<T>) {
    const PipelineOptions<T> o = off(s.name);
    for (const StageDeclaration<T>& other : kStages<T>)
      EXPECT_EQ(other.enabled(o), &other != &s) << "with " << s.name << " off, " << other.name;
  }
}

TYPED_TEST(Declarations, WhatThePresetsReadOfAFrame) {
  using T = TypeParam;
  using I = FrameInput;
  EXPECT_EQ(inputs_read(presets::none<T>()), FrameInputs(I::Detections));
  EXPECT_EQ(inputs_read(presets::zhu_2024<T>()), FrameInputs(I::Detections));
  EXPECT_EQ(inputs_read(presets::rtd_slam<T>()), I::Detections | I::CamFromWorld | I::Depth | I::ReferenceKeyframe);
  EXPECT_EQ(inputs_read(presets::recommended<T>()),
            I::Detections | I::Depth | I::PrevKeypoints | I::Points3d | I::TrackIds);
  // Without the detection filter the box rule reads the boxes itself.
  PipelineOptions<T> unfiltered = presets::zhu_2024<T>();
  unfiltered.detections.enabled = false;
  EXPECT_EQ(inputs_read(unfiltered), FrameInputs(I::Detections));
  unfiltered.box_rule.enabled = false;
  EXPECT_EQ(inputs_read(unfiltered), FrameInputs(0));
  // The epipolar check reads depth only for the occlusion-edge discount, and does without it.
  PipelineOptions<T> epipolar = presets::dfd_slam<T>();
  epipolar.edge_evidence.enabled = true;
  EXPECT_FALSE(reads(inputs_read(epipolar), I::Depth));
  EXPECT_TRUE(reads(inputs_read(epipolar, /*optional=*/true), I::Depth));
}

// A built-in stage whose inputs follow another stage's switch reads the PipelineOptions in its declaration
// (stages/builtin.hpp): the box rule reads the boxes itself without the filter; the reprojection check
// reads depth for its depth residual or the edge discount.
TYPED_TEST(Declarations, BuiltinStagesReadOtherStagesSwitches) {
  using T = TypeParam;
  using I = FrameInput;
  PipelineOptions<T> o = presets::recommended<T>();
  EXPECT_EQ(detail::stage_needs<BoxRuleStage<T>>(o), FrameInputs(0));
  o.detections.enabled = false;
  EXPECT_EQ(detail::stage_needs<BoxRuleStage<T>>(o), FrameInputs(I::Detections));
  EXPECT_EQ(detail::stage_needs<ReprojectionStage<T>>(o), FrameInputs(I::Points3d));
  EXPECT_EQ(detail::stage_uses<ReprojectionStage<T>>(o), FrameInputs(I::Depth));
  o.reprojection.max_depth_residual_sigmas = T(0);
  o.edge_evidence.enabled = false;
  EXPECT_EQ(detail::stage_uses<ReprojectionStage<T>>(o), FrameInputs(0));
  EXPECT_EQ(detail::stage_uses<MovingConsistencyStage<T>>(o), FrameInputs(0));
  o.edge_evidence.enabled = true;
  EXPECT_EQ(detail::stage_uses<MovingConsistencyStage<T>>(o), FrameInputs(I::Depth));
}

/// The check a stage makes before it runs: the inputs its declaration needs, against the frame.
template <class Stage, class T, class Frame>
bool has_inputs(const Frame& frame, const PipelineOptions<T>& o, PipelineResult<T>* r, bool keyframe_stored = true) {
  return detail::has_needed_inputs(frame, detail::stage_needs<Stage>(o), &(r->*Stage::kReport), keyframe_stored);
}

// A frame of 3 keypoints with nothing else: each stage names the first input it lacks.
TYPED_TEST(Declarations, AStageLackingAnInputNamesItAndDoesNotRun) {
  using T = TypeParam;
  const std::vector<Vec2<T>> kp(3, Vec2<T>(10, 10));
  CullingFrame<T, std::vector<Vec2<T>>> frame;
  frame.keypoints = &kp;
  const PipelineOptions<T> o = presets::rtd_slam<T>();
  PipelineResult<T> r;
  EXPECT_FALSE(has_inputs<MultiViewStage<T>>(frame, o, &r));
  EXPECT_EQ(r.multiview.status, Status::MissingInput);
  EXPECT_EQ(r.multiview.reason, "no cam_from_world given");
  const Rigid3<T> lost = [] {
    Rigid3<T> p;
    p.t.x() = Constants<T>::nan();
    return p;
  }();
  frame.cam_from_world = &lost;
  EXPECT_FALSE(has_inputs<MultiViewStage<T>>(frame, o, &r));
  EXPECT_EQ(r.multiview.reason, "cam_from_world not finite (tracking lost)");
  const Rigid3<T> pose;
  const std::vector<float> depth(4, 1.f);
  frame.cam_from_world = &pose;
  frame.depth = DepthView<float>{depth.data(), 2, 2};
  EXPECT_FALSE(has_inputs<MultiViewStage<T>>(frame, o, &r, /*keyframe_stored=*/false));
  EXPECT_EQ(r.multiview.reason, "no reference keyframe stored yet");
  r.multiview = StageReport{};
  EXPECT_TRUE(has_inputs<MultiViewStage<T>>(frame, o, &r));
  EXPECT_EQ(r.multiview.status, Status::Skipped);  // untouched: the stage runs
  EXPECT_TRUE(has_inputs<BoxTrackerStage<T>>(frame, o, &r));  // reads nothing
  EXPECT_FALSE(has_inputs<StaticHistoryStage<T>>(frame, o, &r));
  EXPECT_EQ(r.static_history.reason, "no track_ids given");
}

}  // namespace
}  // namespace dyncull
