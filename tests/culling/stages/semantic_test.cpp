// The semantic stage (stages/semantic.hpp) on its own: the box rule's labels per motion level, limited to
// each object's depth band by the depth mask (in_object flags), and what it reports without depth.
#include "dyncull/culling/stages/semantic.hpp"

#include "support/stage_context.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <vector>

namespace dyncull {
namespace {

template <class T>
class SemanticStageTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(SemanticStageTest, Scalars, );  // trailing comma: clang -Wpedantic rejects an empty variadic

/// 64 x 48 depth, background 3 m. A person (box (16, 6)-(44, 44)) stands at 1 m over columns 20-39, rows
/// 10-39; a chair (box (46, 30)-(62, 46)) at 2 m over columns 48-59, rows 32-45; a TV box (36, 6)-(50, 20)
/// overlaps the person's. Features:
///   0 (30, 20) on the person            1 (18, 8) person box, background   2 (55, 10) outside every box
///   3 (54, 38) on the chair             4 (38, 12) person and TV boxes     5 NaN
template <class T>
test::StageFrame<T> scene() {
  test::StageFrame<T> f(64, 48);
  f.fill_depth(3.f);
  f.paint_depth(20, 10, 40, 40, 1.f);
  f.paint_depth(48, 32, 60, 46, 2.f);
  f.detect(0, T(16), T(6), T(44), T(44));
  f.detect(62, T(36), T(6), T(50), T(20));
  f.detect(56, T(46), T(30), T(62), T(46));
  f.add(T(30), T(20));
  f.add(T(18), T(8));
  f.add(T(55), T(10));
  f.add(T(54), T(38));
  f.add(T(38), T(12));
  const T nan = std::numeric_limits<T>::quiet_NaN();
  f.add(nan, nan);
  return f;
}

/// The regions the boxes stage would give for these boxes (no filter, no tracker).
template <class T>
detail::BoxRegions<T> regions_of(const test::StageFrame<T>& f) {
  detail::BoxRegions<T> g;
  g.boxes = f.detections;
  g.dyn_boxes = {f.detections[0], f.detections[2]};
  g.dyn_box_source = {0, 2};
  g.box_track_id.assign(3, -1);
  g.dyn_box_track_id.assign(2, -1);
  return g;
}

template <class T>
PipelineOptions<T> box_rule_with_depth_mask() {
  PipelineOptions<T> o;
  o.depth_mask.enabled = true;  // robust mode: d_c from the centre patch, eps 0.3 m
  return o;
}

using L = FeatureLabel;
using R = CullReason;

TYPED_TEST(SemanticStageTest, DepthMaskLimitsTheBoxRuleToTheObject) {
  using T = TypeParam;
  const auto f = scene<T>();
  const auto o = box_rule_with_depth_mask<T>();
  detail::PipelineWork<T> w;
  w.regions = regions_of(f);
  PipelineResult<T> r = test::fresh_result(o, f.size());
  const auto work_before = test::parts_of(w);
  const auto result_before = test::parts_of(r);
  detail::classify_by_boxes(f.frame(), o, w.regions, &w.semantic, &r);

  ASSERT_TRUE(r.box_rule.ran()) << r.box_rule.reason;
  ASSERT_TRUE(r.depth_mask.ran()) << r.depth_mask.reason;
  const auto& s = w.semantic;
  EXPECT_TRUE(s.rule_ok);
  EXPECT_TRUE(s.masks);
  // The box rule alone: person box high (0, 1), chair medium (3), the TV shelters 4, NaN never trusted.
  EXPECT_EQ(s.rule.labels, (std::vector<L>{L::Dynamic, L::Dynamic, L::Static, L::Candidate, L::Static, L::Dynamic}));
  EXPECT_EQ(s.rule.reasons, (std::vector<R>{R::HighLevelBox, R::HighLevelBox, R::None, R::MediumLevelBox,
                                            R::LowLevelOverride, R::InvalidInput}));
  // Person box: corners 3 m, centre 1 m, so its mask is the depths below 1.3 m. Feature 1 (3 m) is the
  // box's background and becomes static; feature 0 stays dynamic, now for the mask. The chair's mask
  // (centre 2 m) holds feature 3, which stays a candidate. Feature 4 lies on the person (1 m) but the TV
  // box shelters it.
  EXPECT_EQ(s.labels, (std::vector<L>{L::Dynamic, L::Static, L::Static, L::Candidate, L::Static, L::Dynamic}));
  EXPECT_EQ(s.reasons, (std::vector<R>{R::DepthMask, R::None, R::None, R::MediumLevelBox, R::LowLevelOverride,
                                       R::InvalidInput}));
  EXPECT_EQ(s.in_dyn_box, (std::vector<std::uint8_t>{1, 1, 0, 1, 0, 0}));
  EXPECT_EQ(s.in_object, (std::vector<std::uint8_t>{1, 0, 0, 1, 1, 1}));
  // Mask bits per feature: bit 0 the person's mask, bit 1 the chair's.
  ASSERT_EQ(s.object_box_bits.size(), f.size());
  EXPECT_EQ(s.object_box_bits[0], 1u);
  EXPECT_EQ(s.object_box_bits[1], 0u);
  EXPECT_EQ(s.object_box_bits[3], 2u);
  EXPECT_EQ(s.object_box_bits[4], 1u);

  test::expect_only_changed(work_before, test::parts_of(w), {"semantic"});
  test::expect_only_changed(result_before, test::parts_of(r), {"box_rule", "depth_mask", "unsheltered"});
}

TYPED_TEST(SemanticStageTest, WithoutTheDepthMaskEveryBoxedFeatureKeepsTheBoxRuleLabel) {
  using T = TypeParam;
  const auto f = scene<T>();
  const PipelineOptions<T> o;  // box rule only
  detail::PipelineWork<T> w;
  w.regions = regions_of(f);
  PipelineResult<T> r = test::fresh_result(o, f.size());
  detail::classify_by_boxes(f.frame(), o, w.regions, &w.semantic, &r);
  EXPECT_FALSE(r.depth_mask.enabled);
  EXPECT_FALSE(w.semantic.masks);
  EXPECT_EQ(w.semantic.labels, w.semantic.rule.labels);
  EXPECT_EQ(w.semantic.reasons, w.semantic.rule.reasons);
  // Without a mask every feature counts as on its object.
  EXPECT_EQ(w.semantic.in_object, (std::vector<std::uint8_t>(f.size(), 1)));
  EXPECT_EQ(w.semantic.in_dyn_box, (std::vector<std::uint8_t>{1, 1, 0, 1, 0, 0}));
}

TYPED_TEST(SemanticStageTest, WithoutDepthTheMaskSaysSoAndTheBoxRuleStands) {
  using T = TypeParam;
  auto f = scene<T>();
  f.depth.clear();
  const auto o = box_rule_with_depth_mask<T>();
  detail::PipelineWork<T> w;
  w.regions = regions_of(f);
  PipelineResult<T> r = test::fresh_result(o, f.size());
  detail::classify_by_boxes(f.frame(), o, w.regions, &w.semantic, &r);
  test::expect_lacks_input(r.depth_mask, "depth");
  EXPECT_FALSE(w.semantic.masks);
  EXPECT_EQ(w.semantic.labels, (std::vector<L>{L::Dynamic, L::Dynamic, L::Static, L::Candidate, L::Static, L::Dynamic}));
}

TYPED_TEST(SemanticStageTest, DisabledBoxRuleLeavesTheMaskAlone) {
  using T = TypeParam;
  const auto f = scene<T>();
  auto o = box_rule_with_depth_mask<T>();
  o.box_rule.enabled = false;
  detail::PipelineWork<T> w;
  w.regions = regions_of(f);
  PipelineResult<T> r = test::fresh_result(o, f.size());
  detail::classify_by_boxes(f.frame(), o, w.regions, &w.semantic, &r);
  EXPECT_FALSE(r.box_rule.enabled);
  EXPECT_FALSE(r.box_rule.ran());
  EXPECT_FALSE(w.semantic.rule_ok);
  ASSERT_TRUE(r.depth_mask.ran()) << r.depth_mask.reason;
  // Only the masks decide: the person's and the chair's objects (4 included: no shelter without the rule).
  EXPECT_EQ(w.semantic.labels[0], L::Dynamic);
  EXPECT_EQ(w.semantic.labels[1], L::Static);
  EXPECT_EQ(w.semantic.labels[2], L::Static);
  EXPECT_EQ(w.semantic.labels[3], L::Dynamic);
  EXPECT_EQ(w.semantic.labels[4], L::Dynamic);
  EXPECT_EQ(w.semantic.reasons[0], R::DepthMask);
  EXPECT_EQ(w.semantic.reasons[5], R::InvalidInput);
}


/// A walker whose box the detector cut below the head: the person (1 m) reaches rows 2-9 above the box top
/// (row 10); background 3 m. Features: 0 (30, 6) on the head, 1 (18, 6) above the box on the background,
/// 2 (30, 20) on the body, 3 (54, 6) on the head's row beside the box.
template <class T>
test::StageFrame<T> cut_head_scene() {
  test::StageFrame<T> f(64, 48);
  f.fill_depth(3.f);
  f.paint_depth(20, 2, 40, 40, 1.f);
  f.paint_depth(50, 2, 58, 10, 1.f);  // something at the walker's depth beside the box
  f.detect(0, T(16), T(10), T(44), T(44));
  f.add(T(30), T(6));
  f.add(T(18), T(6));
  f.add(T(30), T(20));
  f.add(T(54), T(6));
  return f;
}

TYPED_TEST(SemanticStageTest, HeadBandClaimsOnlyFeaturesAtThePersonsDepthAboveItsBox) {
  using T = TypeParam;
  const auto f = cut_head_scene<T>();
  auto o = box_rule_with_depth_mask<T>();
  detail::PipelineWork<T> w;
  w.regions.boxes = f.detections;
  w.regions.dyn_boxes = f.detections;
  w.regions.dyn_box_source = {0};
  w.regions.box_track_id = {-1};
  w.regions.dyn_box_track_id = {-1};
  PipelineResult<T> r = test::fresh_result(o, f.size());
  detail::classify_by_boxes(f.frame(), o, w.regions, &w.semantic, &r);
  ASSERT_TRUE(r.depth_mask.ran()) << r.depth_mask.reason;
  EXPECT_EQ(w.semantic.labels, (std::vector<L>{L::Static, L::Static, L::Dynamic, L::Static})) << "no band: the box alone";

  o.depth_mask.head_band_fraction = 0.25;  // 8.5 px above the 34 px box: rows 1.5-10
  r = test::fresh_result(o, f.size());
  detail::classify_by_boxes(f.frame(), o, w.regions, &w.semantic, &r);
  const auto& s = w.semantic;
  // The head (1 m, the box's d_c) joins the person; the background above the box (2 m further) and the
  // surface at the walker's depth outside the box's columns stay static.
  EXPECT_EQ(s.labels, (std::vector<L>{L::Dynamic, L::Static, L::Dynamic, L::Static}));
  EXPECT_EQ(s.reasons, (std::vector<R>{R::DepthMask, R::None, R::DepthMask, R::None}));
  EXPECT_EQ(s.in_dyn_box, (std::vector<std::uint8_t>{1, 0, 1, 0}));
  EXPECT_EQ(s.in_object[0], 1u);
  EXPECT_EQ(s.object_box_bits[0], 1u);
  EXPECT_EQ(s.head_band_box, (std::vector<std::int32_t>{0, -1, -1, -1}));

  o.depth_mask.head_band_depth_tolerance_m = 0.0;  // the head's depth must equal d_c: still 1 m
  r = test::fresh_result(o, f.size());
  detail::classify_by_boxes(f.frame(), o, w.regions, &w.semantic, &r);
  EXPECT_EQ(w.semantic.labels[0], L::Dynamic);
  o.depth_mask.head_band_fraction = 0.1;  // 3.4 px: rows 6.6-10 miss the head feature at row 6
  r = test::fresh_result(o, f.size());
  detail::classify_by_boxes(f.frame(), o, w.regions, &w.semantic, &r);
  EXPECT_EQ(w.semantic.labels[0], L::Static);
}

}  // namespace
}  // namespace dyncull
