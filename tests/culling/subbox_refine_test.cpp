// Tests of the 3x3 sub-box refinement (DFD-SLAM Algorithm 1) with geometric labels of known error rates.
#include "dyncull/culling/subbox_refine.hpp"

#include "support/culling_scenes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace dyncull {
namespace {

using test::SceneConfig;
using test::SceneKind;

template <class T>
class SubBoxTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(SubBoxTest, Scalars, );  // trailing comma: clang -Wpedantic rejects an empty variadic

// Geometric labels as an epipolar check would give them: truth with 8 % of static features flagged
// (noise, epipolar-line errors) and 15 % of moving ones missed (motion along the epipolar line).
template <class T>
std::vector<FeatureLabel> noisy_geometric_labels(const test::CullingScene<T>& s, std::uint64_t seed = 3) {
  Random rng(seed);
  std::vector<FeatureLabel> g(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    const bool flip = rng.uniform() < (s.truth_dynamic[i] ? 0.15 : 0.08);
    g[i] = (s.truth_dynamic[i] != 0) != flip ? FeatureLabel::Dynamic : FeatureLabel::Static;
  }
  return g;
}

// Appends n_static then n_dynamic labelled features on a short diagonal from (x, y) (one sub-box).
template <class T>
void add_votes(std::vector<Vec2<T>>* pts, std::vector<FeatureLabel>* geo, T x, T y, int n_static, int n_dynamic) {
  for (int k = 0; k < n_static + n_dynamic; ++k) {
    pts->emplace_back(x + T(2 * k), y + T(k));
    geo->push_back(k < n_static ? FeatureLabel::Static : FeatureLabel::Dynamic);
  }
}

template <class T>
std::vector<Detection<T>> person_boxes(const test::CullingScene<T>& s) {
  std::vector<Detection<T>> out;
  for (std::size_t b = 0; b < s.detections.size(); ++b)
    if (s.detections[b].class_id == 0)
      out.push_back(Detection<T>{s.detections[b].box.template cast<T>(), 0, T(s.detections[b].confidence)});
  return out;
}

TYPED_TEST(SubBoxTest, SittingPersonKeepsStaticLegsAndCullsTheMovingUpperBody) {
  using T = TypeParam;
  const auto s = test::make_culling_scene<T>(test::seated_person_config());
  const auto geo = noisy_geometric_labels(s);
  const auto boxes = person_boxes(s);
  ASSERT_EQ(boxes.size(), 1u);
  const auto r = refine_subboxes(s.keypoints, geo, boxes, SubBoxOptions<T>{});
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_FALSE(r.votes[0].whole_box);
  // Top row dynamic, bottom two rows static (DFD-SLAM Figure 8: a seated person moving the upper body).
  for (int c = 0; c < 9; ++c) EXPECT_EQ(r.cells[static_cast<std::size_t>(c)], c < 3 ? 1 : 0) << "cell " << c;
  std::size_t legs = 0, legs_static = 0, upper = 0, upper_dyn = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] == SceneKind::SittingLower) {
      ++legs;
      legs_static += r.labels[i] == FeatureLabel::Static;
    } else if (s.kind[i] == SceneKind::SittingUpper) {
      ++upper;
      upper_dyn += r.labels[i] == FeatureLabel::Dynamic;
    }
  }
  ASSERT_GT(legs, 50u);
  ASSERT_GT(upper, 20u);
  // The top cell row reaches 5 % of the person height below the moving part: those leg features are
  // culled with it, the rest (>= 90 %) must survive; every upper-body feature lies in the top row.
  EXPECT_GE(double(legs_static), 0.9 * double(legs)) << legs_static << " of " << legs;
  EXPECT_EQ(upper_dyn, upper);
  EXPECT_GT(r.num_rescued, 0u);  // false epipolar flags on the legs were undone
}

TYPED_TEST(SubBoxTest, PaperMergeRuleCullsTheWholeSittingPerson) {
  // Documents why merge_ratio defaults to 0.35: merging every static neighbour (the paper's literal
  // rule) turns the middle row dynamic, 6 > sigma2 = 4 cells, and the whole person is culled.
  using T = TypeParam;
  const auto s = test::make_culling_scene<T>(test::seated_person_config());
  const auto geo = noisy_geometric_labels(s);
  SubBoxOptions<T> paper;
  paper.merge_ratio = T(0);
  const auto r = refine_subboxes(s.keypoints, geo, person_boxes(s), paper);
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r.votes[0].whole_box);
  EXPECT_EQ(r.votes[0].num_merged_cells, 3);
}

TYPED_TEST(SubBoxTest, WalkingPersonBecomesAWholeDynamicBox) {
  using T = TypeParam;
  SceneConfig config;
  config.sitting = false;
  config.tv = false;
  const auto s = test::make_culling_scene<T>(config);
  const auto geo = noisy_geometric_labels(s);
  const auto r = refine_subboxes(s.keypoints, geo, person_boxes(s), SubBoxOptions<T>{});
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r.votes[0].whole_box);
  EXPECT_EQ(r.num_whole_boxes, 1u);
  std::size_t person = 0, person_dyn = 0;
  for (std::size_t i = 0; i < s.size(); ++i)
    if (s.kind[i] == SceneKind::WalkingPerson) {
      ++person;
      person_dyn += r.labels[i] == FeatureLabel::Dynamic;
    }
  EXPECT_EQ(person_dyn, person);  // the 15 % missed by geometry are recovered
  EXPECT_GT(r.num_added, 0u);
}

TYPED_TEST(SubBoxTest, EmptyAndInvalidBoxesAndObjectMask) {
  using T = TypeParam;
  const std::vector<Vec2<T>> pts{Vec2<T>(3, 3), Vec2<T>(5, 4), Vec2<T>(300, 300), Vec2<T>(305, 302),
                                 Vec2<T>(Constants<T>::nan(), T(1))};
  const std::vector<FeatureLabel> geo{FeatureLabel::Dynamic, FeatureLabel::Dynamic, FeatureLabel::Dynamic,
                                      FeatureLabel::Static, FeatureLabel::Static};
  std::vector<Box<T>> boxes{Box<T>{T(100), T(100), T(200), T(200)},                 // empty: no features
                            Box<T>{T(0), T(0), T(29), T(29)},                       // both in cell 0
                            Box<T>{Constants<T>::nan(), T(0), T(1), T(1)}};          // invalid
  const auto r = refine_subboxes(pts, geo, boxes, SubBoxOptions<T>{});
  EXPECT_TRUE(r.ok());
  EXPECT_EQ(r.num_invalid_boxes, 1u);
  EXPECT_FALSE(r.reason.empty());
  EXPECT_EQ(r.votes[0].num_dynamic_cells, 0);  // no evidence and no dynamic neighbour: static
  // Box 1: cell 0 dynamic; its 4-neighbours 1 and 3 are empty and merged; 3 <= sigma2.
  EXPECT_EQ(r.votes[1].num_dynamic_cells, 3);
  EXPECT_EQ(r.votes[1].num_merged_cells, 2);
  EXPECT_EQ(r.labels[0], FeatureLabel::Dynamic);
  EXPECT_EQ(r.reasons[0], CullReason::SubBox);
  EXPECT_EQ(r.labels[2], FeatureLabel::Dynamic);  // outside boxes: geometric label kept
  EXPECT_EQ(r.reasons[2], CullReason::Epipolar);
  EXPECT_EQ(r.labels[3], FeatureLabel::Static);
  EXPECT_EQ(r.labels[4], FeatureLabel::Dynamic);  // non-finite: never trusted
  // Object-mask flags: a feature in a dynamic cell but outside the object mask stays static.
  const std::vector<std::uint8_t> in_mask{0, 1, 1, 1, 1};
  const auto m = refine_subboxes(pts, geo, boxes, SubBoxOptions<T>{}, in_mask);
  EXPECT_EQ(m.labels[0], FeatureLabel::Static);
  EXPECT_EQ(m.labels[1], FeatureLabel::Dynamic);
  // Invalid options.
  SubBoxOptions<T> bad;
  bad.grid = 0;
  EXPECT_EQ(refine_subboxes(pts, geo, boxes, bad).status, Status::InvalidInput);
}

// With static_needs_evidence a cell stays static only on a clear static vote: empty cells and split
// static votes keep the box rule's "dynamic"; such cells neither merge nor make the whole box dynamic.
TYPED_TEST(SubBoxTest, StaticNeedsEvidenceCullsEmptyAndSplitCells) {
  using T = TypeParam;
  std::vector<Vec2<T>> pts;
  std::vector<FeatureLabel> geo;
  auto add = [&](T x, T y, int n_static, int n_dynamic) { add_votes(&pts, &geo, x, y, n_static, n_dynamic); };
  add(T(5), T(5), 5, 0);    // cell 0: unanimous static
  add(T(65), T(5), 4, 1);   // cell 2: 1 of 5 flagged (ratio 0.2)
  add(T(5), T(65), 3, 2);   // cell 6: 2 of 5 flagged (0.4, under sigma1 0.5)
  add(T(65), T(65), 1, 0);  // cell 8: one labelled feature, no evidence
  const std::vector<Box<T>> boxes{Box<T>{T(0), T(0), T(90), T(90)}};
  SubBoxOptions<T> o;
  const auto plain = refine_subboxes(pts, geo, boxes, o);
  ASSERT_TRUE(plain.ok());
  for (std::size_t i = 0; i < pts.size(); ++i) EXPECT_EQ(plain.labels[i], FeatureLabel::Static) << i;
  o.static_needs_evidence = true;
  o.static_max_dynamic_ratio = T(0.2);
  const auto r = refine_subboxes(pts, geo, boxes, o);
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(r.votes[0].whole_box) << "7 assumed cells do not count towards sigma2";
  EXPECT_EQ(r.votes[0].num_merged_cells, 0);
  for (std::size_t i = 0; i < 10; ++i) EXPECT_EQ(r.labels[i], FeatureLabel::Static) << i << ": cells 0 and 2";
  for (std::size_t i = 10; i < 16; ++i) {
    EXPECT_EQ(r.labels[i], FeatureLabel::Dynamic) << i << ": cells 6 and 8";
    EXPECT_EQ(r.reasons[i], CullReason::SubBox) << i;
  }
  EXPECT_EQ(r.cells[0], 0);
  EXPECT_EQ(r.cells[2], 0);
  EXPECT_EQ(r.cells[4], 1) << "no features at all: the box rule stands";
  // Unanimity required: cell 2's single flag now makes it dynamic too.
  o.static_max_dynamic_ratio = T(0);
  const auto strict = refine_subboxes(pts, geo, boxes, o);
  for (std::size_t i = 5; i < 10; ++i) EXPECT_EQ(strict.labels[i], FeatureLabel::Dynamic) << i;
  for (std::size_t i = 0; i < 5; ++i) EXPECT_EQ(strict.labels[i], FeatureLabel::Static) << i;
  o.static_max_dynamic_ratio = Constants<T>::nan();
  const auto bad = refine_subboxes(pts, geo, boxes, o);
  EXPECT_EQ(bad.status, Status::InvalidInput);
  EXPECT_NE(bad.reason.find("static_max_dynamic_ratio"), std::string::npos) << bad.reason;
}

// static_needs_evidence_boxes limits the burden of proof to the boxes it flags: the same cells in an
// unflagged box (a chair's) are dynamic only on their own vote. A view of the wrong size is refused.
TYPED_TEST(SubBoxTest, StaticNeedsEvidenceAppliesToTheFlaggedBoxesOnly) {
  using T = TypeParam;
  std::vector<Vec2<T>> pts;
  std::vector<FeatureLabel> geo;
  // The same votes in two boxes: cell 0 unanimous static, cell 6 split (2 of 5 flagged), cell 8 one feature.
  for (T dx : {T(0), T(200)}) {
    add_votes(&pts, &geo, dx + T(5), T(5), 5, 0);
    add_votes(&pts, &geo, dx + T(5), T(65), 3, 2);
    add_votes(&pts, &geo, dx + T(65), T(65), 1, 0);
  }
  const std::vector<Box<T>> boxes{Box<T>{T(0), T(0), T(90), T(90)}, Box<T>{T(200), T(0), T(290), T(90)}};
  SubBoxOptions<T> o;
  o.static_needs_evidence = true;
  const std::vector<std::uint8_t> person_then_chair{1, 0};
  const auto r = refine_subboxes(pts, geo, boxes, o, nullptr, nullptr, FlagView(person_then_chair));
  ASSERT_TRUE(r.ok()) << r.reason;
  const std::size_t per_box = 11;
  for (std::size_t i = 0; i < 5; ++i) EXPECT_EQ(r.labels[i], FeatureLabel::Static) << i;
  for (std::size_t i = 5; i < per_box; ++i) EXPECT_EQ(r.labels[i], FeatureLabel::Dynamic) << i << ": burden on static";
  for (std::size_t i = per_box; i < 2 * per_box; ++i)
    EXPECT_EQ(r.labels[i], FeatureLabel::Static) << i << ": no cell of the second box voted dynamic";
  EXPECT_EQ(r.votes[1].num_dynamic_cells, 0);
  // Not given: every box carries the burden, as before.
  const auto all = refine_subboxes(pts, geo, boxes, o);
  for (std::size_t i = per_box + 5; i < 2 * per_box; ++i) EXPECT_EQ(all.labels[i], FeatureLabel::Dynamic) << i;
  const std::vector<std::uint8_t> one_flag{1};
  const auto bad = refine_subboxes(pts, geo, boxes, o, nullptr, nullptr, FlagView(one_flag));
  EXPECT_EQ(bad.status, Status::InvalidInput);
  EXPECT_NE(bad.reason.find("static_needs_evidence_boxes has 1 entries for 2 boxes"), std::string::npos) << bad.reason;
  for (FeatureLabel l : bad.labels) EXPECT_EQ(l, FeatureLabel::Static);
}

// A walker's box overlapping a still chair's box: with per-box object bits the walker's dynamic
// sub-boxes act only on the walker's own features, and only they vote.
TYPED_TEST(SubBoxTest, OverlappingBoxesActOnTheirOwnObjectsOnly) {
  using T = TypeParam;
  std::vector<Vec2<T>> pts;
  std::vector<FeatureLabel> geo;
  std::vector<std::uint32_t> bits;
  // Walker: two epipolar-dynamic features in each of the nine 30-px cells of box 0.
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 2; ++k) {
        pts.emplace_back(T(30 * c + 5 + 10 * k), T(30 * r + 5 + 10 * k));
        geo.push_back(FeatureLabel::Dynamic);
        bits.push_back(1u);
      }
  // Chair: static features, two in the walker's last cell (the overlap) and two beyond it.
  const std::size_t chair0 = pts.size();
  for (const T v : {T(78), T(85), T(120), T(130)}) {
    pts.emplace_back(v, v);
    geo.push_back(FeatureLabel::Static);
    bits.push_back(2u);
  }
  const std::vector<Box<T>> boxes{Box<T>{T(0), T(0), T(89), T(89)}, Box<T>{T(70), T(70), T(150), T(150)}};
  const std::vector<std::uint8_t> in_any(pts.size(), 1);

  // One object flag for all boxes (the chair is in its own box's mask): the overlap is culled.
  SubBoxOptions<T> o;
  const auto flat = refine_subboxes(pts, geo, boxes, o, in_any);
  ASSERT_TRUE(flat.ok());
  EXPECT_EQ(flat.labels[chair0], FeatureLabel::Dynamic);
  EXPECT_EQ(flat.static_count[8], 2u);  // the chair votes in the walker's cell

  // Per-box bits: the chair keeps its features; the walker is still dynamic everywhere.
  o.object_mask_votes_only = true;
  const auto own = refine_subboxes(pts, geo, boxes, o, in_any, bits);
  ASSERT_TRUE(own.ok());
  for (std::size_t i = 0; i < pts.size(); ++i)
    EXPECT_EQ(own.labels[i], i < chair0 ? FeatureLabel::Dynamic : FeatureLabel::Static) << "feature " << i;
  EXPECT_EQ(own.dyn_count[8], 2u);
  EXPECT_EQ(own.static_count[8], 0u);  // only the walker's own features vote in its box
  EXPECT_EQ(own.votes[1].num_dynamic_cells, 0);
}

TYPED_TEST(SubBoxTest, RasterMaskIsObjectMaskInDynamicCellsDilated) {
  using T = TypeParam;
  const int W = 120, H = 90;
  // Two dynamic features in cell 0, static evidence in its 4-neighbours 1 and 3 and in cell 8.
  const std::vector<Vec2<T>> pts{Vec2<T>(35, 35), Vec2<T>(36, 36), Vec2<T>(55, 35), Vec2<T>(56, 36),
                                 Vec2<T>(35, 55), Vec2<T>(36, 56), Vec2<T>(85, 75), Vec2<T>(86, 76)};
  const std::vector<FeatureLabel> geo{FeatureLabel::Dynamic, FeatureLabel::Dynamic, FeatureLabel::Static,
                                      FeatureLabel::Static,  FeatureLabel::Static,  FeatureLabel::Static,
                                      FeatureLabel::Static,  FeatureLabel::Static};
  const std::vector<Box<T>> boxes{Box<T>{T(30), T(30), T(89.999), T(89)}};  // 3x3 cells of 20 px
  SubBoxOptions<T> opt;
  opt.merge_ratio = T(2);  // static neighbours with evidence are never merged: one dynamic cell
  opt.dilation_radius_px = 3;
  const auto r = refine_subboxes(pts, geo, boxes, opt);
  ASSERT_EQ(r.votes[0].num_dynamic_cells, 1);
  Mask out(W, H);
  std::vector<std::uint16_t> scratch;
  // Whole cell: pixels 30..49 x 30..49 (20 x 20), dilated by 3 -> 26 x 26.
  EXPECT_EQ(subbox_mask(r, boxes, opt, ConstMaskView{}, out.view(), &scratch), 26u * 26u);
  EXPECT_TRUE(out.test(27, 27));
  EXPECT_FALSE(out.test(26, 27));
  EXPECT_FALSE(out.test(53, 40));
  // Object mask: one pixel inside the cell -> a 7 x 7 square; pixels outside dynamic cells are dropped.
  Mask object(W, H);
  object.pixels[static_cast<std::size_t>(40 * W + 40)] = 1;
  object.pixels[static_cast<std::size_t>(80 * W + 80)] = 1;
  EXPECT_EQ(subbox_mask(r, boxes, opt, object.view(), out.view(), &scratch), 49u);
}

TEST(SubBoxDilation, MatchesBruteForce) {
  const int W = 64, H = 48, R = 4;
  Random rng(5);
  Mask m(W, H);
  for (auto& p : m.pixels) p = rng.uniform() < 0.01 ? 1 : 0;
  Mask ref(W, H);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      bool any = false;
      for (int dy = -R; dy <= R; ++dy)
        for (int dx = -R; dx <= R; ++dx) any = any || m.test(x + dx, y + dy);
      ref.pixels[static_cast<std::size_t>(y * W + x)] = any ? 255 : 0;
    }
  std::vector<std::uint16_t> scratch;
  dilate_square(m.view(), PixelRect{0, 0, W, H}, R, &scratch);
  EXPECT_EQ(m.pixels, ref.pixels);
}

// Sub-rectangles, radii larger than the rectangle, and one scratch buffer reused across sizes: inside
// the ROI the result is the dilation of the ROI's own pixels; outside it nothing changes.
TEST(SubBoxDilation, RoiAndLargeRadiiMatchBruteForce) {
  const int W = 80, H = 60;
  Random rng(11);
  std::vector<std::uint16_t> scratch;
  for (const PixelRect roi : {PixelRect{0, 0, W, H}, PixelRect{10, 7, 53, 41}, PixelRect{70, 50, 80, 60}}) {
    for (const int R : {1, 4, 15, 40}) {
      Mask m(W, H);
      for (auto& p : m.pixels) p = rng.uniform() < 0.02 ? 1 : 0;
      Mask ref = m;
      for (int y = roi.r0; y < roi.r1; ++y)
        for (int x = roi.c0; x < roi.c1; ++x) {
          bool any = false;
          for (int yy = std::max(roi.r0, y - R); yy < std::min(roi.r1, y + R + 1); ++yy)
            for (int xx = std::max(roi.c0, x - R); xx < std::min(roi.c1, x + R + 1); ++xx) any = any || m.test(xx, yy);
          ref.pixels[static_cast<std::size_t>(y * W + x)] = any ? 255 : 0;
        }
      dilate_square(m.view(), roi, R, &scratch);
      EXPECT_EQ(m.pixels, ref.pixels) << "roi " << roi.c0 << "," << roi.r0 << " radius " << R;
    }
  }
}

// Per-feature views shorter than the points, or per-cell flags shorter than the boxes' cells: InvalidInput
// naming the view and both sizes, every feature Static, nothing read past the end (AddressSanitizer).
TYPED_TEST(SubBoxTest, ViewsOfAnotherLengthAreInvalidInputAndNotRead) {
  using T = TypeParam;
  // Features 0 and 1 share cell 0 of box 1 (flagged: a dynamic cell), feature 2 lies in box 0's cell 0.
  const std::vector<Vec2<T>> pts{Vec2<T>(3, 3), Vec2<T>(5, 4), Vec2<T>(105, 105)};
  const std::vector<FeatureLabel> geo{FeatureLabel::Dynamic, FeatureLabel::Dynamic, FeatureLabel::Static};
  const std::vector<Box<T>> boxes{Box<T>{T(100), T(100), T(200), T(200)}, Box<T>{T(0), T(0), T(29), T(29)}};
  const SubBoxOptions<T> o;
  const std::vector<std::uint8_t> one(1, 1), flags(3, 1), cells(18, 0), few_cells(9, 1);
  const std::vector<std::uint32_t> one_bits(1, 3u), bits(3, 3u);
  auto expect_invalid = [&](const SubBoxResult<T>& r, const std::string& reason) {
    EXPECT_EQ(r.status, Status::InvalidInput);
    EXPECT_EQ(r.reason, reason);
    ASSERT_EQ(r.labels.size(), pts.size());
    for (FeatureLabel l : r.labels) EXPECT_EQ(l, FeatureLabel::Static);
  };
  SubBoxResult<T> r;
  refine_subboxes(pts, geo, boxes, o, &r, one, bits);
  expect_invalid(r, "in_object_mask has 1 entries for 3 points");
  refine_subboxes(pts, geo, boxes, o, &r, flags, one_bits);
  expect_invalid(r, "object_box_bits has 1 entries for 3 points");
  refine_subboxes(pts, geo, boxes, o, &r, flags, bits);
  EXPECT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.labels[1], FeatureLabel::Dynamic);

  apply_subbox_states(pts, geo, boxes, few_cells, o, &r);
  expect_invalid(r, "states has 9 entries for 18 cells (boxes x grid x grid)");
  apply_subbox_states(pts, geo, boxes, nullptr, o, &r);
  expect_invalid(r, "states has 0 entries for 18 cells (boxes x grid x grid)");
  apply_subbox_states(pts, geo, boxes, cells, o, &r, one);
  expect_invalid(r, "in_object_mask has 1 entries for 3 points");
  apply_subbox_states(pts, geo, boxes, cells, o, &r, flags, bits);
  EXPECT_TRUE(r.ok()) << r.reason;
}

// The geometric labels are required, one per point, by every entry point: a short array is named with
// both sizes and no label is read (every feature Static).
TYPED_TEST(SubBoxTest, ShortGeometricLabelsAreInvalidInputAndNotRead) {
  using T = TypeParam;
  const std::vector<Vec2<T>> pts{Vec2<T>(3, 3), Vec2<T>(5, 4), Vec2<T>(105, 105)};
  const std::vector<FeatureLabel> short_geo{FeatureLabel::Dynamic};
  const std::vector<Box<T>> boxes{Box<T>{T(100), T(100), T(200), T(200)}, Box<T>{T(0), T(0), T(29), T(29)}};
  const SubBoxOptions<T> o;
  const std::vector<std::uint8_t> cells(18, 1);
  auto expect_invalid = [&](const SubBoxResult<T>& r, const std::string& reason) {
    EXPECT_EQ(r.status, Status::InvalidInput);
    EXPECT_EQ(r.reason, reason);
    ASSERT_EQ(r.labels.size(), pts.size());
    for (FeatureLabel l : r.labels) EXPECT_EQ(l, FeatureLabel::Static);
    EXPECT_TRUE(r.cells.empty());
  };
  const std::string reason = "geometric has 1 entries for 3 points";
  SubBoxResult<T> r;
  refine_subboxes(pts, short_geo, boxes, o, &r);
  expect_invalid(r, reason);
  expect_invalid(refine_subboxes(pts, short_geo, boxes, o), reason);
  apply_subbox_states(pts, short_geo, boxes, cells, o, &r);
  expect_invalid(r, reason);
  refine_subboxes(pts, nullptr, boxes, o, &r);
  expect_invalid(r, "geometric is required (3 points)");
  apply_subbox_states(pts, nullptr, boxes, cells, o, &r);
  expect_invalid(r, "geometric is required (3 points)");
}

}  // namespace
}  // namespace dyncull
