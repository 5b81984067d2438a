// The region-votes stage (stages/region_votes.hpp) on its own: the sub-box vote of DFD-SLAM Algorithm 1 on
// hand-placed evidence, a coherent cell flagged before the vote, and each reason it gives for not voting.
#include "dyncull/culling/stages/region_votes.hpp"

#include "support/stage_context.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace dyncull {
namespace {

template <class T>
class RegionVotesStageTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(RegionVotesStageTest, Scalars, );  // trailing comma: clang -Wpedantic rejects an empty variadic

using L = FeatureLabel;
using R = CullReason;

constexpr std::size_t kInBox = 90;  // features 0-89 in the person's box, 90 and 91 outside it

/// A person's box (0, 0)-(90, 90) in a 100 x 100 image, split 3 x 3: ten features per cell, cell by
/// cell row-major (features 10c .. 10c + 9 in cell c); the centre cell's (40-49) flagged by the geometric
/// check. Outside the box: 90 at (95, 50) flagged, 91 at (95, 60) static.
template <class T>
struct VoteScene {
  test::StageFrame<T> f{100, 100};
  detail::PipelineWork<T> w;
  VoteScene() {
    f.detect(0, T(0), T(0), T(90), T(90));
    for (int cy = 0; cy < 3; ++cy)
      for (int cx = 0; cx < 3; ++cx)
        for (int k = 0; k < 10; ++k) f.add(T(cx * 30 + 5 + 2 * k), T(cy * 30 + 15));
    f.add(T(95), T(50));
    f.add(T(95), T(60));
    const std::size_t n = f.size();
    w.regions.boxes = f.detections;
    w.regions.dyn_boxes = f.detections;
    w.regions.dyn_box_source = {0};
    w.regions.box_track_id = {-1};
    w.regions.dyn_box_track_id = {-1};
    w.semantic.rule_ok = true;
    w.semantic.labels.assign(n, L::Static);
    w.semantic.reasons.assign(n, R::None);
    w.semantic.in_dyn_box.assign(n, 0);
    w.semantic.in_object.assign(n, 1);
    for (std::size_t i = 0; i < kInBox; ++i) {
      w.semantic.labels[i] = L::Dynamic;
      w.semantic.reasons[i] = R::HighLevelBox;
      w.semantic.in_dyn_box[i] = 1;
    }
    w.geometric.ok = true;
    w.geometric.fit_outside_boxes = true;
    w.geometric.labels.assign(n, L::Static);
    w.geometric.source.assign(n, R::Epipolar);
    for (std::size_t i = 40; i < 50; ++i) w.geometric.labels[i] = L::Dynamic;
    w.geometric.labels[90] = L::Dynamic;
  }
  void vote(const PipelineOptions<T>& o, PipelineResult<T>* r, SubBoxMemory* memory, std::uint64_t frame_index = 1) {
    detail::vote_regions(f.frame(), o, frame_index, w.regions, w.semantic, w.semantic.labels, w.geometric, memory,
                         &w.votes, r);
  }
};

TYPED_TEST(RegionVotesStageTest, OnlyTheFlaggedCellIsVotedDynamic) {
  using T = TypeParam;
  VoteScene<T> s;
  const PipelineOptions<T> o;  // grid 3, sigma1 0.5, merge_ratio 0.35, sigma2 4
  PipelineResult<T> r = test::fresh_result(o, s.f.size());
  SubBoxMemory memory;
  const auto work_before = test::parts_of(s.w);
  const auto result_before = test::parts_of(r);
  s.vote(o, &r, &memory);

  ASSERT_TRUE(r.subbox.ran()) << r.subbox.reason;
  ASSERT_TRUE(s.w.votes.ok);
  EXPECT_FALSE(s.w.votes.coherent_ran);
  // Centre cell: 10 of 10 flagged, ratio 1 >= 0.5: dynamic. Its four neighbours have ratio 0 < 0.35 and
  // are not merged; one dynamic cell is not more than sigma2, so the box is not taken whole.
  EXPECT_EQ(s.w.votes.subbox.cells, (std::vector<std::uint8_t>{0, 0, 0, 0, 1, 0, 0, 0, 0}));
  std::vector<L> want_labels(s.f.size(), L::Static);
  std::vector<R> want_reasons(s.f.size(), R::None);
  for (std::size_t i = 40; i < 50; ++i) {
    want_labels[i] = L::Dynamic;
    want_reasons[i] = R::SubBox;
  }
  want_labels[90] = L::Dynamic;  // outside every box the geometric label stands
  want_reasons[90] = R::Epipolar;
  EXPECT_EQ(s.w.votes.subbox.labels, want_labels);
  EXPECT_EQ(s.w.votes.subbox.reasons, want_reasons);
  EXPECT_EQ(r.subbox.num_dynamic, 11u);

  test::expect_only_changed(work_before, test::parts_of(s.w), {"votes"});
  test::expect_only_changed(result_before, test::parts_of(r), {"subbox", "coherent_motion"});
}

TYPED_TEST(RegionVotesStageTest, ACoherentCellIsFlaggedBeforeTheVote) {
  using T = TypeParam;
  VoteScene<T> s;
  PipelineOptions<T> o;
  o.reprojection.enabled = true;
  o.coherent_motion.enabled = true;  // sigmas 10, noise floor 0.2 px, min_median 0.5 px, min_points 4
  PipelineResult<T> r = test::fresh_result(o, s.f.size());
  r.reprojection.status = Status::Ok;  // the geometric stage ran the reprojection check
  // Top-left cell (features 0-9): every residual (1, 0) px, none flagged on its own. Standard error of
  // the median: 1.2533 * 0.2 / sqrt(10) = 0.079 px; 10 of them, 0.79 px, is below the median 1 px.
  auto& rv = s.w.geometric.reprojection.residual_vec;
  rv.assign(s.f.size(), Vec2<T>(T(0), T(0)));
  for (std::size_t i = 0; i < 10; ++i) rv[i] = Vec2<T>(T(1), T(0));
  s.w.geometric.reprojection.inlier_noise_px = T(0.2);
  SubBoxMemory memory;
  const auto work_before = test::parts_of(s.w);
  s.vote(o, &r, &memory);

  ASSERT_TRUE(r.coherent_motion.ran()) << r.coherent_motion.reason;
  ASSERT_TRUE(s.w.votes.coherent_ran);
  EXPECT_EQ(r.coherent_motion.num_dynamic, 10u);
  for (std::size_t i = 0; i < s.f.size(); ++i) {
    const bool flagged = i < 10 || (i >= 40 && i < 50) || i == 90;
    EXPECT_EQ(s.w.votes.evidence[i], flagged ? L::Dynamic : L::Static) << i;
  }
  ASSERT_TRUE(r.subbox.ran()) << r.subbox.reason;
  EXPECT_EQ(s.w.votes.subbox.cells, (std::vector<std::uint8_t>{1, 0, 0, 0, 1, 0, 0, 0, 0}));
  // The coherent flags are the vote's evidence; the geometric stage's own labels are left as they were.
  test::expect_only_changed(work_before, test::parts_of(s.w), {"votes"});
  EXPECT_EQ(s.w.evidence_source(3), R::CoherentMotion);
  EXPECT_EQ(s.w.evidence_source(45), R::Epipolar);
}

TYPED_TEST(RegionVotesStageTest, CoherentMotionWithoutResidualsSaysSoAndTheVoteRuns) {
  using T = TypeParam;
  VoteScene<T> s;
  PipelineOptions<T> o;
  o.coherent_motion.enabled = true;
  PipelineResult<T> r = test::fresh_result(o, s.f.size());
  SubBoxMemory memory;
  s.vote(o, &r, &memory);
  EXPECT_FALSE(r.coherent_motion.ran());
  EXPECT_EQ(r.coherent_motion.reason, "needs the reprojection check's residuals (reprojection.enabled, points_3d)");
  EXPECT_FALSE(s.w.votes.coherent_ran);
  ASSERT_TRUE(r.subbox.ran()) << r.subbox.reason;
  EXPECT_EQ(s.w.votes.subbox.cells, (std::vector<std::uint8_t>{0, 0, 0, 0, 1, 0, 0, 0, 0}));
}

TYPED_TEST(RegionVotesStageTest, EachMissingInputIsNamedAndNothingIsVoted) {
  using T = TypeParam;
  const PipelineOptions<T> o;
  SubBoxMemory memory;
  {
    VoteScene<T> s;
    s.w.geometric.ok = false;
    PipelineResult<T> r = test::fresh_result(o, s.f.size());
    s.vote(o, &r, &memory);
    EXPECT_FALSE(s.w.votes.ok);
    EXPECT_FALSE(r.subbox.ran());
    EXPECT_EQ(r.subbox.reason, "needs geometric labels (moving consistency or reprojection), unavailable this frame");
  }
  {
    VoteScene<T> s;
    s.w.regions.dyn_boxes.clear();
    PipelineResult<T> r = test::fresh_result(o, s.f.size());
    s.vote(o, &r, &memory);
    EXPECT_FALSE(s.w.votes.ok);
    EXPECT_EQ(r.subbox.reason, "no dynamic-class boxes");
  }
  {
    VoteScene<T> s;
    s.w.geometric.fit_outside_boxes = false;  // F fitted through the person
    PipelineResult<T> r = test::fresh_result(o, s.f.size());
    s.vote(o, &r, &memory);
    EXPECT_FALSE(s.w.votes.ok);
    EXPECT_EQ(r.subbox.reason.rfind("F or the pose was fitted through the dynamic-class boxes", 0), 0u)
        << r.subbox.reason;
  }
  {
    VoteScene<T> s;
    s.f.evidence_frames = 1;
    PipelineOptions<T> short_baseline = o;
    short_baseline.subbox.min_evidence_frames = 3;
    PipelineResult<T> r = test::fresh_result(short_baseline, s.f.size());
    s.vote(short_baseline, &r, &memory);
    EXPECT_FALSE(s.w.votes.ok);
    EXPECT_EQ(r.subbox.reason,
              "baseline of 1 frame(s) too short for static evidence (subbox.min_evidence_frames): the box rule decides");
  }
}

TYPED_TEST(RegionVotesStageTest, DisabledVotesNothing) {
  using T = TypeParam;
  VoteScene<T> s;
  PipelineOptions<T> o;
  o.subbox.enabled = false;
  s.w.votes.ok = true;  // a previous frame's
  PipelineResult<T> r = test::fresh_result(o, s.f.size());
  SubBoxMemory memory;
  s.vote(o, &r, &memory);
  EXPECT_FALSE(r.subbox.enabled);
  EXPECT_FALSE(r.subbox.ran());
  EXPECT_FALSE(s.w.votes.ok);
}


// A feature in a box's head band (the semantic stage's head_band_box) follows the top-row cell of its
// column: culled above a dynamic cell, left to the box's static verdict above a static one.
TYPED_TEST(RegionVotesStageTest, HeadBandFeaturesFollowTheTopRowOfTheirColumn) {
  using T = TypeParam;
  VoteScene<T> s;
  for (std::size_t i = 0; i < 10; ++i) s.w.geometric.labels[i] = L::Dynamic;  // top-left cell flagged too
  // The box's top moves to row 10 (its cells keep their features) and two features sit above it on row 2,
  // at x 10 (column 0) and 50 (column 1), marked as the semantic stage marks a head band's.
  s.w.regions.dyn_boxes[0].box.y0 = T(10);
  s.w.regions.boxes[0].box.y0 = T(10);
  s.f.add(T(10), T(2));
  s.f.add(T(50), T(2));
  const std::size_t n = s.f.size();
  for (auto* v : {&s.w.semantic.in_dyn_box, &s.w.semantic.in_object}) v->resize(n, 1);
  s.w.semantic.labels.resize(n, L::Dynamic);
  s.w.semantic.reasons.resize(n, R::DepthMask);
  s.w.geometric.labels.resize(n, L::Static);
  s.w.geometric.source.resize(n, R::Epipolar);
  s.w.semantic.head_band_box.assign(n, -1);
  s.w.semantic.head_band_box[n - 2] = 0;
  s.w.semantic.head_band_box[n - 1] = 0;
  const PipelineOptions<T> o;
  PipelineResult<T> r = test::fresh_result(o, n);
  SubBoxMemory memory;
  s.vote(o, &r, &memory);
  ASSERT_TRUE(s.w.votes.ok) << r.subbox.reason;
  ASSERT_EQ(s.w.votes.subbox.cells[0], 1u) << "premise: the top-left cell is dynamic";
  ASSERT_EQ(s.w.votes.subbox.cells[1], 0u) << "premise: the top-middle cell is static";
  EXPECT_EQ(s.w.votes.subbox.labels[n - 2], L::Dynamic);
  EXPECT_EQ(s.w.votes.subbox.reasons[n - 2], R::SubBox);
  EXPECT_EQ(s.w.votes.subbox.labels[n - 1], L::Static);
  EXPECT_EQ(s.w.votes.subbox.reasons[n - 1], R::None);
}

}  // namespace
}  // namespace dyncull
