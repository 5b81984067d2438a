// The combination stages (stages/combine.hpp) on their own: how the semantic, geometric, sub-box and
// multi-view evidence and the CandidatePolicy make each label, with the reason naming the stage that
// decided; a track's static history; the survivor guard's soften and undo; the trace; the keyframe store.
#include "dyncull/culling/stages/combine.hpp"

#include "support/stage_context.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

namespace dyncull {
namespace {

template <class T>
class CombineStageTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(CombineStageTest, Scalars, );  // trailing comma: clang -Wpedantic rejects an empty variadic

using L = FeatureLabel;
using R = CullReason;

/// Evidence of eight features, no sub-box vote, no multi-view flags:
///   feature   semantic                    geometric (source)
///   0         Static                      Static
///   1         Dynamic  HighLevelBox       Static
///   2         Candidate MediumLevelBox    Dynamic (Epipolar)
///   3         Candidate MediumLevelBox    Static
///   4         Static                      Dynamic (Reprojection)
///   5         Static   LowLevelOverride   Dynamic (Epipolar)
///   6         Dynamic  InvalidInput       Dynamic
///   7         Dynamic  DepthMask          Candidate (no evidence)
template <class T>
detail::PipelineWork<T> evidence() {
  detail::PipelineWork<T> w;
  w.semantic.labels = {L::Static, L::Dynamic, L::Candidate, L::Candidate, L::Static, L::Static, L::Dynamic, L::Dynamic};
  w.semantic.reasons = {R::None,           R::HighLevelBox, R::MediumLevelBox, R::MediumLevelBox,
                        R::None,           R::LowLevelOverride, R::InvalidInput, R::DepthMask};
  w.semantic.in_dyn_box = {0, 1, 1, 1, 0, 0, 0, 1};
  w.semantic.in_object.assign(8, 1);
  w.geometric.ok = true;
  w.geometric.labels = {L::Static, L::Static, L::Dynamic, L::Static, L::Dynamic, L::Dynamic, L::Dynamic, L::Candidate};
  w.geometric.source.assign(8, R::Epipolar);
  w.geometric.source[4] = R::Reprojection;
  test::multiview_marks(&w).marks.assign(8, 0);
  w.history_kept.assign(8, 0);
  return w;
}

template <class T>
PipelineResult<T> combined(const PipelineOptions<T>& o, const detail::PipelineWork<T>& w) {
  PipelineResult<T> r = test::fresh_result(o, w.semantic.labels.size());
  detail::combine_evidence(o, w, &r);
  return r;
}

TYPED_TEST(CombineStageTest, EvidenceCombinesInOrderAndTheReasonNamesTheDecidingStage) {
  using T = TypeParam;
  const auto w = evidence<T>();
  const PipelineOptions<T> o;  // Verify candidates
  PipelineResult<T> r = test::fresh_result(o, 8);
  const auto work_before = test::parts_of(w);
  const auto result_before = test::parts_of(r);
  detail::combine_evidence(o, w, &r);
  // 2: a candidate flagged by the epipolar check; 3: a candidate without a flag (Verify: static);
  // 4: flagged outside every box (a flag alone culls nothing there); 5: sheltered by a low-level box.
  EXPECT_EQ(r.labels, (std::vector<L>{L::Static, L::Dynamic, L::Dynamic, L::Static, L::Static, L::Static, L::Dynamic,
                                      L::Dynamic}));
  EXPECT_EQ(r.reasons, (std::vector<R>{R::None, R::HighLevelBox, R::Epipolar, R::None, R::None, R::None,
                                       R::InvalidInput, R::DepthMask}));
  test::expect_only_changed(work_before, test::parts_of(w), {});
  test::expect_only_changed(result_before, test::parts_of(r), {"frame"});
}

TYPED_TEST(CombineStageTest, CandidatePolicyDecidesTheUnflaggedCandidate) {
  using T = TypeParam;
  const auto w = evidence<T>();
  PipelineOptions<T> o;
  o.candidates = CandidatePolicy::Cull;
  auto r = combined(o, w);
  EXPECT_EQ(r.labels[3], L::Dynamic);
  EXPECT_EQ(r.reasons[3], R::MediumLevelBox);
  EXPECT_EQ(r.reasons[2], R::Epipolar);
  o.candidates = CandidatePolicy::Keep;
  r = combined(o, w);
  EXPECT_EQ(r.labels[3], L::Static);
  EXPECT_EQ(r.reasons[3], R::None);
  EXPECT_EQ(r.labels[2], L::Dynamic);  // its own flag still culls it
  EXPECT_EQ(r.reasons[2], R::Epipolar);
}

TYPED_TEST(CombineStageTest, GeometricFlagsOutsideBoxesAloneCullNothing) {
  using T = TypeParam;
  const auto w = evidence<T>();
  const PipelineOptions<T> o;
  const auto r = combined(o, w);
  EXPECT_EQ(r.labels[4], L::Static);
  EXPECT_EQ(r.labels[2], L::Dynamic);  // a candidate's own flag is still evidence
}

TYPED_TEST(CombineStageTest, MultiViewFlagsCullCandidatesAndStatics) {
  using T = TypeParam;
  auto w = evidence<T>();
  test::multiview_marks(&w).ok = true;
  test::multiview_marks(&w).marks[0] = test::multiview_marks(&w).marks[3] = 1;
  const PipelineOptions<T> o;
  const auto r = combined(o, w);
  EXPECT_EQ(r.labels[0], L::Dynamic);
  EXPECT_EQ(r.reasons[0], R::MultiView);
  EXPECT_EQ(r.labels[3], L::Dynamic);
  EXPECT_EQ(r.reasons[3], R::MultiView);
}

/// Five features in a person's box (0-3) or outside it (4), with a sub-box vote:
///   0 semantic Dynamic, in a dynamic sub-box, no flag         -> SubBox
///   1 semantic Dynamic, in a static sub-box                    -> refined to static
///   2 semantic Candidate (a chair), in a dynamic sub-box       -> SubBox (subbox.verifies_candidates)
///   3 semantic Dynamic, in a dynamic sub-box, coherent flag    -> CoherentMotion
///   4 outside, flagged by the epipolar check                   -> static (a flag alone culls nothing there)
template <class T>
detail::PipelineWork<T> voted() {
  detail::PipelineWork<T> w;
  w.semantic.labels = {L::Dynamic, L::Dynamic, L::Candidate, L::Dynamic, L::Static};
  w.semantic.reasons = {R::HighLevelBox, R::HighLevelBox, R::MediumLevelBox, R::HighLevelBox, R::None};
  w.semantic.in_dyn_box = {1, 1, 1, 1, 0};
  w.semantic.in_object.assign(5, 1);
  w.geometric.ok = true;
  w.geometric.labels = {L::Static, L::Static, L::Static, L::Static, L::Dynamic};
  w.geometric.source.assign(5, R::Epipolar);
  w.votes.ok = true;
  w.votes.coherent_ran = true;
  w.votes.evidence = {L::Static, L::Static, L::Static, L::Dynamic, L::Dynamic};
  w.votes.subbox.labels = {L::Dynamic, L::Static, L::Dynamic, L::Dynamic, L::Dynamic};
  w.votes.subbox.reasons = {R::SubBox, R::None, R::SubBox, R::SubBox, R::Epipolar};
  test::multiview_marks(&w).marks.assign(5, 0);
  w.history_kept.assign(5, 0);
  return w;
}

TYPED_TEST(CombineStageTest, SubBoxVoteDecidesInsideTheBoxAndNamesCoherentMotion) {
  using T = TypeParam;
  const auto w = voted<T>();
  PipelineOptions<T> o;
  auto r = combined(o, w);
  EXPECT_EQ(r.labels, (std::vector<L>{L::Dynamic, L::Static, L::Dynamic, L::Dynamic, L::Static}));
  EXPECT_EQ(r.reasons, (std::vector<R>{R::SubBox, R::None, R::SubBox, R::CoherentMotion, R::None}));
  // A candidate left to its own evidence: not flagged itself, so Verify keeps it.
  o.subbox.verifies_candidates = false;
  r = combined(o, w);
  EXPECT_EQ(r.labels[2], L::Static);
  EXPECT_EQ(r.reasons[2], R::None);
}

TYPED_TEST(CombineStageTest, StaticHistoryKeepsATrackStillOverItsLastFramesAgainstItsRegion) {
  using T = TypeParam;
  PipelineOptions<T> o;
  o.reprojection.enabled = true;
  o.static_history.enabled = true;
  o.static_history.min_frames = 2;  // residual below max_residual_px in each of the last 2 frames
  test::StageFrame<T> f(64, 48);
  for (int i = 0; i < 3; ++i) f.add(T(10 + 10 * i), T(10));
  f.track_ids = {7, 8, 9};
  detail::PipelineWork<T> w;
  auto& rp = w.geometric.reprojection;
  rp.labels.assign(3, L::Static);
  rp.residual_px.assign(3, T(0.1));
  StaticHistory history;
  PipelineResult<T> r;
  for (int frame = 0; frame < 2; ++frame) {
    r = test::fresh_result(o, 3);
    r.reprojection.status = Status::Ok;
    // 0 culled for its region (sub-box), 1 for its own flag (not overruled), 2 static.
    r.labels = {L::Dynamic, L::Dynamic, L::Static};
    r.reasons = {R::SubBox, R::Epipolar, R::None};
    detail::apply_static_history(f.frame(), o, w.geometric, &history, &w.still_frames, &w.history_kept, &r);
    ASSERT_TRUE(r.static_history.ran()) << r.static_history.reason;
    if (frame == 0) {
      EXPECT_EQ(r.history_kept, 0u);  // one still frame so far
    }
  }
  EXPECT_EQ(r.labels, (std::vector<L>{L::Static, L::Dynamic, L::Static}));
  EXPECT_EQ(r.reasons, (std::vector<R>{R::None, R::Epipolar, R::None}));
  EXPECT_EQ(w.history_kept, (std::vector<std::uint8_t>{1, 0, 0}));
  EXPECT_EQ(r.history_kept, 1u);
  EXPECT_EQ(r.static_history.reason, "1 feature(s) kept static by their history");

  // Without track ids it says so and keeps nothing.
  f.track_ids.clear();
  r = test::fresh_result(o, 3);
  r.labels = {L::Dynamic, L::Dynamic, L::Static};
  r.reasons = {R::SubBox, R::Epipolar, R::None};
  detail::apply_static_history(f.frame(), o, w.geometric, &history, &w.still_frames, &w.history_kept, &r);
  test::expect_lacks_input(r.static_history, "track_ids");
  EXPECT_EQ(r.labels[0], L::Dynamic);
  EXPECT_EQ(w.history_kept, (std::vector<std::uint8_t>{0, 0, 0}));
}

/// n = 40: need max(min_survivors 30, ceil(0.1 * 40) = 4) = 30 static features.
template <class T>
PipelineResult<T> guarded(std::size_t hard, std::size_t soft) {
  const PipelineOptions<T> o;
  PipelineResult<T> r = test::fresh_result(o, 40);
  for (std::size_t i = 0; i < hard; ++i) {
    r.labels[i] = L::Dynamic;
    r.reasons[i] = R::HighLevelBox;
  }
  for (std::size_t i = hard; i < hard + soft; ++i) {
    r.labels[i] = L::Dynamic;
    r.reasons[i] = R::Epipolar;
  }
  detail::guard_survivors(o, &r);
  return r;
}

TYPED_TEST(CombineStageTest, SurvivorGuardSoftensThenUndoes) {
  using T = TypeParam;
  // 15 static + 20 single-stage (epipolar) culls restored = 35 >= 30: softened, the box culls stand.
  auto r = guarded<T>(5, 20);
  EXPECT_EQ(r.guard, GuardAction::Softened);
  EXPECT_EQ(r.guard_restored, 20u);
  EXPECT_EQ(r.num_static, 35u);
  EXPECT_EQ(r.num_dynamic, 5u);
  EXPECT_EQ(r.reasons[0], R::HighLevelBox);
  EXPECT_EQ(r.labels[5], L::Static);
  EXPECT_EQ(r.reasons[5], R::SurvivorGuardUndo);
  EXPECT_EQ(r.keep[5], 1);
  EXPECT_EQ(r.keep[0], 0);
  // 15 static + 10 soft = 25 < 30: every cull undone.
  r = guarded<T>(15, 10);
  EXPECT_EQ(r.guard, GuardAction::Undone);
  EXPECT_EQ(r.guard_restored, 25u);
  EXPECT_EQ(r.num_static, 40u);
  EXPECT_EQ(r.reasons[0], R::SurvivorGuardUndo);
  // Enough survivors: nothing done.
  r = guarded<T>(5, 5);
  EXPECT_EQ(r.guard, GuardAction::None);
  EXPECT_EQ(r.num_static, 30u);
  EXPECT_TRUE(r.reason.empty()) << r.reason;
}

TYPED_TEST(CombineStageTest, TraceShowsWhatEachStageSaw) {
  using T = TypeParam;
  auto w = evidence<T>();
  const PipelineOptions<T> defaults;  // named: g++ -O3 warns (maybe-uninitialized) on the temporary
  PipelineResult<T> r = combined(defaults, w);
  w.semantic.in_object[1] = 0;
  w.history_kept[6] = 1;
  detail::trace_features(w, &r);
  ASSERT_EQ(r.trace.size(), 8u);
  EXPECT_EQ(r.trace[2].semantic, L::Candidate);
  EXPECT_EQ(r.trace[2].geometric, L::Dynamic);
  EXPECT_EQ(r.trace[2].in_dynamic_box, 1);
  EXPECT_EQ(r.trace[1].in_object, 0);
  EXPECT_EQ(r.trace[6].history_kept, 1);
  w.geometric.ok = false;
  detail::trace_features(w, &r);
  EXPECT_EQ(r.trace[2].geometric, L::Candidate);  // no geometric evidence this frame
}

TYPED_TEST(CombineStageTest, KeyframeStoresTheKeptFeaturesWithTheirDepth) {
  using T = TypeParam;
  test::StageFrame<T> f(64, 48);
  f.fill_depth(2.f);
  f.paint_depth(0, 0, 10, 10, 1.f);
  f.add(T(5), T(5));    // kept, 1 m
  f.add(T(30), T(30));  // culled
  f.add(T(40), T(20));  // kept, 2 m
  const PipelineOptions<T> o;
  PipelineResult<T> r = test::fresh_result(o, 3);
  r.keep = {1, 0, 1};
  KeyframeRing<T> ring(4);
  std::vector<T> depth;
  auto frame = f.frame();
  detail::store_keyframe(frame, r, &depth, &ring);
  EXPECT_TRUE(ring.empty());  // not a keyframe
  frame.is_keyframe = true;
  detail::store_keyframe(frame, r, &depth, &ring);
  ASSERT_EQ(ring.size(), 1u);
  EXPECT_EQ(ring[0].points.size(), 2u);
  EXPECT_EQ(ring[0].depth_m, (std::vector<T>{T(1), T(2)}));
}

}  // namespace
}  // namespace dyncull
