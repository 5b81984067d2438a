// The probability stage (stages/probability.hpp) on its own: P = a1 S + a2 M + a3 K (DLD-SLAM eq. 3-5)
// for the features in the object masks, computed by hand below; the other features keep their semantic
// label. Also the temporal term over two frames and what it reports without tracks.
#include "dyncull/culling/stages/probability.hpp"

#include "support/stage_context.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

namespace dyncull {
namespace {

template <class T>
class ProbabilityStageTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(ProbabilityStageTest, Scalars, );  // trailing comma: clang -Wpedantic rejects an empty variadic

using L = FeatureLabel;
using R = CullReason;

/// Features (flow in px; the camera's flow is (2, 0)):
///   0-9   background, flow (2, 0)                  (reference set)
///   10-12 on the person (mask of box 0), still     13-15 on the person, flow (12, 0)
///   16    in the person's box, off its mask        17 on the chair (box 1), flow (12, 0)
///   18    on the chair, still                      19 background, semantic InvalidInput
/// `moving_now`: whether 13-15 and 17 move this frame.
template <class T>
test::StageFrame<T> frame_with_flows(bool moving_now) {
  test::StageFrame<T> f(64, 48);
  f.detect(0, T(10), T(10), T(30), T(40));
  f.detect(56, T(40), T(30), T(60), T(46));
  auto add = [&](T x, T y, T flow) { f.add(x + flow, y, x, y); };
  for (int k = 0; k < 10; ++k) add(T(2 + 6 * k), T(4), T(2));
  for (int k = 0; k < 6; ++k) add(T(14 + 2 * k), T(20), T(moving_now && k >= 3 ? 12 : 2));
  add(T(12), T(12), T(2));
  add(T(45), T(40), T(moving_now ? 12 : 2));
  add(T(55), T(40), T(2));
  add(T(5), T(44), T(2));
  return f;
}

/// The semantic evidence the earlier stages would leave: person features Dynamic (depth mask), chair
/// features candidates, 16 static in its box's background, 19 invalid.
template <class T>
detail::SemanticEvidence<T> semantic_evidence() {
  detail::SemanticEvidence<T> s;
  const std::size_t n = 20;
  s.rule_ok = true;
  s.masks = true;
  s.labels.assign(n, L::Static);
  s.reasons.assign(n, R::None);
  s.in_dyn_box.assign(n, 0);
  s.in_object.assign(n, 0);
  s.rule.box_index.assign(n, -1);
  for (std::size_t i = 10; i < 16; ++i) {
    s.labels[i] = L::Dynamic;
    s.reasons[i] = R::DepthMask;
    s.in_dyn_box[i] = s.in_object[i] = 1;
    s.rule.box_index[i] = 0;
  }
  s.in_dyn_box[16] = 1;
  s.rule.box_index[16] = 0;
  for (std::size_t i = 17; i < 19; ++i) {
    s.labels[i] = L::Candidate;
    s.reasons[i] = R::MediumLevelBox;
    s.in_dyn_box[i] = s.in_object[i] = 1;
    s.rule.box_index[i] = 1;
  }
  s.labels[19] = L::Dynamic;
  s.reasons[19] = R::InvalidInput;
  return s;
}

template <class T>
PipelineOptions<T> probability_on() {
  PipelineOptions<T> o;
  o.probability.enabled = true;  // a1 0.4, a2 0.4, a3 0.2, threshold 0.55, motion threshold >= 1.5 px
  return o;
}

TYPED_TEST(ProbabilityStageTest, ScoresTheMaskedFeaturesAndLeavesTheOthers) {
  using T = TypeParam;
  const auto f = frame_with_flows<T>(true);
  const auto o = probability_on<T>();
  detail::PipelineWork<T> w;
  w.regions.boxes = f.detections;
  w.semantic = semantic_evidence<T>();
  PipelineResult<T> r = test::fresh_result(o, f.size());
  TrackStateStore store;
  const auto work_before = test::parts_of(w);
  const auto result_before = test::parts_of(r);
  detail::score_probability(f.frame(), o, w.regions, w.semantic, w.geometric, &store, &w.probability, &r);

  ASSERT_TRUE(r.probability.ran()) << r.probability.reason;
  ASSERT_TRUE(w.probability.ok);
  // Reference flow: median of the 12 unmasked features, (2, 0), all residuals 0, so t = 1.5 px.
  // Person (S = 1): still 0.4 -> static; flow residual 10 px (M = 1): 0.8 -> dynamic.
  // Chair (S = 0.5): moving 0.2 + 0.4 = 0.6 -> dynamic; still 0.2 -> static. No track ids: K = 0.
  std::vector<L> want_labels(20, L::Static);
  std::vector<R> want_reasons(20, R::None);
  for (std::size_t i : {13, 14, 15, 17}) {
    want_labels[i] = L::Dynamic;
    want_reasons[i] = R::Probability;
  }
  want_labels[19] = L::Dynamic;  // invalid input is never re-decided
  want_reasons[19] = R::InvalidInput;
  EXPECT_EQ(w.probability.labels, want_labels);
  EXPECT_EQ(w.probability.reasons, want_reasons);
  std::vector<MotionLevel> want_levels(20, MotionLevel::Ignore);
  for (std::size_t i = 10; i < 16; ++i) want_levels[i] = MotionLevel::High;
  want_levels[17] = want_levels[18] = MotionLevel::Medium;
  EXPECT_EQ(w.probability.levels, want_levels);
  EXPECT_EQ(r.probability.num_dynamic, 4u);

  test::expect_only_changed(work_before, test::parts_of(w), {"probability"});
  test::expect_only_changed(result_before, test::parts_of(r), {"probability"});
}

TYPED_TEST(ProbabilityStageTest, AFeatureThatMovedLastFrameStaysDynamicThroughItsTrack) {
  using T = TypeParam;
  const auto o = probability_on<T>();
  detail::PipelineWork<T> w;
  w.semantic = semantic_evidence<T>();
  TrackStateStore store;
  std::vector<std::int64_t> ids(20);
  for (std::size_t i = 0; i < ids.size(); ++i) ids[i] = static_cast<std::int64_t>(100 + i);
  for (bool moving : {true, false}) {
    auto f = frame_with_flows<T>(moving);
    f.track_ids = ids;
    w.regions.boxes = f.detections;
    PipelineResult<T> r = test::fresh_result(o, f.size());
    detail::score_probability(f.frame(), o, w.regions, w.semantic, w.geometric, &store, &w.probability, &r);
    ASSERT_TRUE(w.probability.ok) << r.probability.reason;
  }
  // Second frame, all still: the person's 13-15 moved last frame (K = 1): 0.4 + 0.2 = 0.6 -> dynamic;
  // the chair's 17 likewise gets 0.2 + 0.2 = 0.4 -> static.
  for (std::size_t i = 10; i < 19; ++i) {
    const bool dyn = i >= 13 && i <= 15;
    EXPECT_EQ(w.probability.labels[i], dyn ? L::Dynamic : L::Static) << i;
    EXPECT_EQ(w.probability.reasons[i], dyn ? R::Probability : R::None) << i;
  }
}

TYPED_TEST(ProbabilityStageTest, WithoutTracksItSaysSoAndDecidesNothing) {
  using T = TypeParam;
  auto f = frame_with_flows<T>(true);
  f.with_tracks = false;
  const auto o = probability_on<T>();
  detail::PipelineWork<T> w;
  w.regions.boxes = f.detections;
  w.semantic = semantic_evidence<T>();
  w.probability.ok = true;  // a previous frame's: not valid for this one
  PipelineResult<T> r = test::fresh_result(o, f.size());
  TrackStateStore store;
  detail::score_probability(f.frame(), o, w.regions, w.semantic, w.geometric, &store, &w.probability, &r);
  EXPECT_FALSE(w.probability.ok);
  test::expect_lacks_input(r.probability, "prev_keypoints");
}

TYPED_TEST(ProbabilityStageTest, DisabledLeavesItsEvidenceInvalid) {
  using T = TypeParam;
  const auto f = frame_with_flows<T>(true);
  const PipelineOptions<T> o;  // probability.enabled false
  detail::PipelineWork<T> w;
  w.regions.boxes = f.detections;
  w.semantic = semantic_evidence<T>();
  w.probability.ok = true;
  PipelineResult<T> r = test::fresh_result(o, f.size());
  TrackStateStore store;
  detail::score_probability(f.frame(), o, w.regions, w.semantic, w.geometric, &store, &w.probability, &r);
  EXPECT_FALSE(w.probability.ok);
  EXPECT_FALSE(r.probability.enabled);
  EXPECT_FALSE(r.probability.ran());
  // The later stages then read the semantic labels (PipelineWork::semantic_labels).
  EXPECT_EQ(&w.semantic_labels(), &w.semantic.labels);
}

}  // namespace
}  // namespace dyncull
