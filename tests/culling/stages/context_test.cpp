// The per-frame context (stages/context.hpp) on its own: which stage's labels the later stages read, the
// stages' buffers reused from frame to frame (same storage after a second frame of the same size), and
// the caller-owned PipelineState.
#include "dyncull/culling/stages/boxes.hpp"
#include "dyncull/culling/stages/combine.hpp"
#include "dyncull/culling/stages/context.hpp"
#include "dyncull/culling/stages/geometric.hpp"
#include "dyncull/culling/stages/inputs.hpp"
#include "dyncull/culling/stages/listed.hpp"
#include "dyncull/culling/stages/probability.hpp"
#include "dyncull/culling/stages/region_votes.hpp"
#include "dyncull/culling/stages/semantic.hpp"

#include "support/culling_frames.hpp"
#include "support/stage_context.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace dyncull {
namespace {

template <class T>
class ContextTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(ContextTest, Scalars, );  // trailing comma: clang -Wpedantic rejects an empty variadic

using L = FeatureLabel;
using R = CullReason;

TYPED_TEST(ContextTest, LaterStagesReadTheProbabilityLabelsOnlyWhenItRan) {
  using T = TypeParam;
  detail::PipelineWork<T> w;
  w.semantic.labels = {L::Dynamic, L::Candidate};
  w.semantic.reasons = {R::HighLevelBox, R::MediumLevelBox};
  w.probability.labels = {L::Static, L::Dynamic};
  w.probability.reasons = {R::None, R::Probability};
  EXPECT_EQ(&w.semantic_labels(), &w.semantic.labels);
  EXPECT_EQ(&w.semantic_reasons(), &w.semantic.reasons);
  w.probability.ok = true;
  EXPECT_EQ(&w.semantic_labels(), &w.probability.labels);
  EXPECT_EQ(&w.semantic_reasons(), &w.probability.reasons);
}

TYPED_TEST(ContextTest, EvidenceIsTheCoherentStagesWhenItRanAndNamesItsSource) {
  using T = TypeParam;
  detail::PipelineWork<T> w;
  w.geometric.labels = {L::Static, L::Dynamic, L::Static};
  w.geometric.source = {R::Epipolar, R::Reprojection, R::Epipolar};
  w.votes.evidence = {L::Dynamic, L::Dynamic, L::Static};
  EXPECT_EQ(w.evidence(), w.geometric.labels.data());
  EXPECT_EQ(w.evidence_source(1), R::Reprojection);
  w.votes.coherent_ran = true;
  EXPECT_EQ(w.evidence(), w.votes.evidence.data());
  EXPECT_EQ(w.evidence_source(0), R::CoherentMotion);  // flagged by its cell, not by its own check
  EXPECT_EQ(w.evidence_source(1), R::Reprojection);    // flagged by its own check
}

/// The storage of every per-feature buffer of the context.
template <class T>
std::vector<std::pair<std::string, const void*>> storage_of(const detail::PipelineWork<T>& w) {
  return {{"regions.boxes", w.regions.boxes.data()},
          {"regions.dyn_boxes", w.regions.dyn_boxes.data()},
          {"semantic.labels", w.semantic.labels.data()},
          {"semantic.reasons", w.semantic.reasons.data()},
          {"semantic.in_dyn_box", w.semantic.in_dyn_box.data()},
          {"semantic.in_object", w.semantic.in_object.data()},
          {"semantic.object_box_bits", w.semantic.object_box_bits.data()},
          {"probability.labels", w.probability.labels.data()},
          {"probability.reasons", w.probability.reasons.data()},
          {"probability.levels", w.probability.levels.data()},
          {"probability.prev", w.probability.prev.data()},
          {"geometric.moving.labels", w.geometric.moving.labels.data()},
          {"geometric.reprojection.labels", w.geometric.reprojection.labels.data()},
          {"geometric.labels", w.geometric.labels.data()},
          {"geometric.source", w.geometric.source.data()},
          {"votes.evidence", w.votes.evidence.data()},
          {"votes.coherent_eligible", w.votes.coherent_eligible.data()},
          {"votes.subbox.labels", w.votes.subbox.labels.data()},
          {"multiview.mask", w.template marks_of<MultiViewStage<T>>().work.mask.pixels.data()},
          {"multiview.marks", w.template marks_of<MultiViewStage<T>>().marks.data()},
          {"history_kept", w.history_kept.data()}};
}

TYPED_TEST(ContextTest, EveryStageReusesItsBuffersOnTheNextFrame) {
  using T = TypeParam;
  test::SceneConfig config;
  const auto s = test::make_culling_scene<T>(config);
  const auto dets = test::detections_of(s);
  auto frame = test::frame_of(s, dets);
  frame.points_3d = &s.prev_points_world;
  PipelineOptions<T> o;
  o.tracker.enabled = true;
  o.depth_mask.enabled = true;
  o.probability.enabled = true;
  o.reprojection.enabled = true;
  o.coherent_motion.enabled = true;
  o.multiview.enabled = true;
  PipelineState<T> state;
  const auto kf = test::make_scene_keyframe<T>(config, 8, 600);
  state.keyframes.push(kf.cam_from_world, kf.keypoints, kf.depth_m);
  detail::PipelineWork<T>& w = detail::work_of(&state);
  EXPECT_EQ(&w, &state.internals());
  PipelineResult<T>& r = state.result;
  auto run_stages = [&]() {
    detail::begin_frame(o, &r);
    ASSERT_TRUE(detail::accept_inputs(frame, o, &r)) << r.reason;
    detail::collect_boxes(frame, o, &state.tracker, &w.regions, &r);
    detail::classify_by_boxes(frame, o, w.regions, &w.semantic, &r);
    detail::gather_geometric_evidence(frame, o, w.regions, w.semantic, &w.geometric, &r);
    detail::score_probability(frame, o, w.regions, w.semantic, w.geometric, &state.track_states, &w.probability, &r);
    detail::vote_regions(frame, o, 1, w.regions, w.semantic, w.semantic_labels(), w.geometric, &state.subbox_memory,
                         &w.votes, &r);
    detail::run_listed_stages<StageKind::Evidence>(frame, o, state.keyframes, &w, &r);
    detail::combine_evidence(o, w, &r);
    detail::apply_static_history(frame, o, w.geometric, &state.static_history, &w.still_frames, &w.history_kept, &r);
    detail::guard_survivors(o, &r);
  };
  run_stages();
  // Every stage ran, so every buffer above holds this frame's data.
  for (const StageReport* st : {&r.box_rule, &r.depth_mask, &r.probability, &r.moving_consistency, &r.reprojection,
                                &r.coherent_motion, &r.subbox, &r.multiview})
    ASSERT_TRUE(st->ran()) << st->reason;
  const auto first = storage_of(w);
  run_stages();
  const auto second = storage_of(w);
  for (std::size_t k = 0; k < first.size(); ++k) {
    EXPECT_NE(first[k].second, nullptr) << first[k].first;
    EXPECT_EQ(first[k].second, second[k].second) << first[k].first << " was reallocated";
  }
  EXPECT_EQ(r.labels.size(), s.size());
}

TYPED_TEST(ContextTest, ResetForgetsWhatWasCarriedBetweenFrames) {
  using T = TypeParam;
  PipelineState<T> state(3);
  EXPECT_EQ(state.keyframes.capacity(), 3u);
  const std::vector<Vec2<T>> points{Vec2<T>(T(1), T(2))};
  const std::vector<T> depths{T(2)};
  ASSERT_EQ(state.keyframes.push(Rigid3<T>{}, points, depths), Status::Ok);
  state.frame_index = 7;
  state.tracker.update({Detection<T>{Box<T>{T(0), T(0), T(10), T(10)}, 0, T(1)}}, 64, 48);
  ASSERT_EQ(state.tracker.tracks().size(), 1u);
  state.reset();
  EXPECT_EQ(state.frame_index, 0u);
  EXPECT_TRUE(state.keyframes.empty());
  EXPECT_TRUE(state.tracker.tracks().empty());
}

}  // namespace
}  // namespace dyncull
