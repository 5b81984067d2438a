// Synthetic depth scenes with known truth: a person (near) in front of a wall (far) inside a box.
#include "dyncull/culling/depth_mask.hpp"
#include "dyncull/core/random.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace {
using namespace dyncull;

constexpr int W = 160, H = 120;

// Raw uint16 (5000 per metre) or float metres, one template for both.
template <class Raw>
struct Scene {
  std::vector<Raw> depth = std::vector<Raw>(W * H);
  std::vector<std::uint8_t> truth = std::vector<std::uint8_t>(W * H, 0);
  static Raw raw(double m) {
    if constexpr (std::is_integral<Raw>::value) return static_cast<Raw>(std::lround(m * 5000.0));
    else return static_cast<Raw>(m);
  }
  DepthView<Raw> view(float min_m = 0.f, float max_m = 1e30f) const {
    return DepthView<Raw>{depth.data(), W, H, 0, std::is_integral<Raw>::value ? 5000.f : 1.f, min_m, max_m};
  }
  void fill(double m) {
    for (auto& d : depth) d = raw(m);
  }
  // An upright ellipse "person" at depth m.
  void person(double cx, double cy, double rx, double ry, double m) {
    for (int v = 0; v < H; ++v)
      for (int u = 0; u < W; ++u) {
        const double a = (u - cx) / rx, b = (v - cy) / ry;
        if (a * a + b * b <= 1.0) {
          depth[v * W + u] = raw(m);
          truth[v * W + u] = 1;
        }
      }
  }
  void hole(int u0, int v0, int u1, int v1) {
    for (int v = v0; v <= v1; ++v)
      for (int u = u0; u <= u1; ++u) depth[v * W + u] = Raw(0);
  }
};

template <class Raw>
class DepthMask : public ::testing::Test {};
using Raws = ::testing::Types<std::uint16_t, float>;
TYPED_TEST_SUITE(DepthMask, Raws, );

// Pixel agreement with the truth inside the box.
template <class Raw>
double box_iou(const Scene<Raw>& s, const Mask& m, const Box<double>& b) {
  const PixelRect r = pixel_rect(b, W, H);
  long tp = 0, fp = 0, fn = 0;
  for (int v = r.r0; v < r.r1; ++v)
    for (int u = r.c0; u < r.c1; ++u) {
      const bool gt = s.truth[v * W + u] != 0, p = m.test(u, v);
      tp += gt && p;
      fp += !gt && p;
      fn += gt && !p;
    }
  return double(tp) / double(tp + fp + fn);
}

TYPED_TEST(DepthMask, PlainRuleSeparatesPersonFromWall) {
  using Raw = TypeParam;
  Scene<Raw> s;
  s.fill(4.0);
  s.person(80, 60, 20, 40, 1.5);
  const Box<double> box{55, 15, 105, 105};
  DepthMaskOptions o;
  o.mode = DepthMaskMode::Plain;
  Mask m(W, H);
  const DepthMaskBoxInfo info = depth_mask_box(s.view(), box, o, m.view());
  ASSERT_TRUE(info.ok()) << info.reason;
  EXPECT_TRUE(info.rule_applies);
  EXPECT_NEAR(info.d_max_m, 4.0, 1e-6);
  EXPECT_NEAR(info.d_c_m, 1.5, 1e-6);
  EXPECT_NEAR(info.threshold_m, 1.8, 1e-6);
  EXPECT_DOUBLE_EQ(box_iou(s, m, box), 1.0);
  // Nothing outside the box is touched.
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u)
      if (!box.contains(u, v)) {
        ASSERT_FALSE(m.test(u, v)) << u << "," << v;
      }
}

// A chair 0.9 m in front of a person, inside the person's box: DLD-SLAM's one-sided band (everything nearer
// than d_c + eps) takes the chair in, in the robust and the plain rule.
TYPED_TEST(DepthMask, OneSidedBandTakesInWhatStandsInFrontOfTheObject) {
  using Raw = TypeParam;
  Scene<Raw> s;
  s.fill(4.0);
  s.person(80, 60, 20, 40, 2.5);
  for (int v = 80; v <= 100; ++v)  // the chair, over the person's legs (not person truth)
    for (int u = 60; u <= 100; ++u) {
      s.depth[v * W + u] = Scene<Raw>::raw(1.6);
      s.truth[v * W + u] = 0;
    }
  s.hole(70, 30, 72, 32);  // a Kinect hole on the person: still masked (mask_missing_depth)
  const Box<double> box{55, 15, 105, 105};
  DepthMaskOptions o;  // robust, one-sided (paper) band
  Mask one_sided(W, H);
  const DepthMaskBoxInfo a = depth_mask_box(s.view(), box, o, one_sided.view());
  ASSERT_TRUE(a.ok()) << a.reason;
  EXPECT_TRUE(a.rule_applies);
  EXPECT_NEAR(a.d_c_m, 2.5, 1e-6);
  EXPECT_TRUE(one_sided.test(80, 90));   // chair pixel taken in by the one-sided band
  EXPECT_TRUE(one_sided.test(80, 50));   // person
  EXPECT_TRUE(one_sided.test(71, 31));   // hole
  EXPECT_FALSE(one_sided.test(56, 16));  // wall left out
  EXPECT_LT(box_iou(s, one_sided, box), 0.8);
  // Point labels follow the raster.
  const std::vector<Box<double>> boxes{box};
  const std::vector<Vec2<float>> pts{{80.f, 90.f}, {80.f, 50.f}};
  const DepthMaskResult r = depth_mask(s.view(), boxes, pts, o);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.labels[0], FeatureLabel::Dynamic);
  EXPECT_EQ(r.labels[1], FeatureLabel::Dynamic);
  o.mode = DepthMaskMode::Plain;
  Mask plain(W, H);
  depth_mask_box(s.view(), box, o, plain.view());
  EXPECT_TRUE(plain.test(80, 90));
}

// A seated person (3.3 m) half hidden by a walker (1.5 m) standing over its box centre: DLD-SLAM's centre
// sample measures the walker, and the seated person's band ("closer than d_c + eps") leaves the seated
// person out. occluded_centre_search re-estimates that box's d_c from its pixels outside the walker's box.
TYPED_TEST(DepthMask, OccludedCentreIsReestimatedOutsideTheOccludersBox) {
  using Raw = TypeParam;
  Scene<Raw> s;
  s.fill(4.5);
  s.person(60, 62, 30, 40, 3.3);             // seated person
  for (int v = 10; v <= 115; ++v)            // walker, covering the seated person's centre
    for (int u = 52; u <= 76; ++u) s.depth[v * W + u] = Scene<Raw>::raw(1.5);
  const std::vector<Box<double>> boxes{Box<double>{28, 20, 92, 104},   // seated person
                                       Box<double>{50, 8, 78, 117}};   // walker
  const std::vector<Vec2<float>> pts{{40.f, 62.f},    // seated person, left of the walker
                                     {85.f, 70.f},    // seated person, right of the walker
                                     {31.f, 24.f},    // wall in the seated person's box
                                     {64.f, 60.f}};   // walker
  DepthMaskOptions o;
  const DepthMaskResult paper = depth_mask(s.view(), boxes, pts, o);
  ASSERT_TRUE(paper.ok()) << paper.reason;
  EXPECT_NEAR(paper.boxes[0].d_c_m, 1.5, 1e-6) << "premise: the centre sample is on the walker";
  EXPECT_EQ(paper.labels[0], FeatureLabel::Static);
  EXPECT_EQ(paper.labels[1], FeatureLabel::Static);

  o.occluded_centre_search = true;
  Mask raster(W, H);
  const DepthMaskResult r = depth_mask(s.view(), boxes, pts, o, raster.view());
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_NEAR(r.boxes[0].d_c_m, 3.3, 0.15);
  EXPECT_FALSE(r.boxes[0].reason.empty());
  EXPECT_NEAR(r.boxes[1].d_c_m, 1.5, 1e-6);  // the walker's own box is left alone
  EXPECT_EQ(r.labels[0], FeatureLabel::Dynamic);
  EXPECT_EQ(r.labels[1], FeatureLabel::Dynamic);
  EXPECT_EQ(r.box_bits[0], 1u);
  EXPECT_EQ(r.labels[2], FeatureLabel::Static);  // wall behind stays out
  EXPECT_EQ(r.labels[3], FeatureLabel::Dynamic);
  EXPECT_TRUE(raster.test(40, 62));
  EXPECT_FALSE(raster.test(31, 24));

  // A box whose centre depth is its own object's (most of its unshared pixels) is not moved.
  const std::vector<Box<double>> alone{Box<double>{28, 20, 92, 104}};
  Scene<Raw> plain;
  plain.fill(4.5);
  plain.person(60, 62, 30, 40, 3.3);
  const DepthMaskResult q = depth_mask(plain.view(), alone, pts, o);
  ASSERT_TRUE(q.ok()) << q.reason;
  EXPECT_NEAR(q.boxes[0].d_c_m, 3.3, 1e-6);
  EXPECT_TRUE(q.boxes[0].reason.empty());
}

TYPED_TEST(DepthMask, PointLabelsAgreeWithTheRaster) {
  using Raw = TypeParam;
  Scene<Raw> s;
  s.fill(4.0);
  s.person(80, 60, 20, 40, 1.5);
  const std::vector<Box<double>> boxes = {{55, 15, 105, 105}};
  std::vector<Vec2<float>> pts;
  for (int v = 0; v < H; v += 3)
    for (int u = 0; u < W; u += 3) pts.emplace_back(float(u) + 0.3f, float(v) - 0.2f);
  pts.emplace_back(std::numeric_limits<float>::quiet_NaN(), 1.f);
  for (DepthMaskMode mode : {DepthMaskMode::Plain, DepthMaskMode::Robust}) {
    DepthMaskOptions o;
    o.mode = mode;
    Mask m(W, H);
    const DepthMaskResult r = depth_mask(s.view(), boxes, pts, o, m.view());
    ASSERT_TRUE(r.ok()) << r.reason;
    std::size_t dynamic = 0, truth_dynamic = 0;
    for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
      const int u = int(std::lround(pts[i].x())), v = int(std::lround(pts[i].y()));
      const bool in_mask = m.test(u, v);
      EXPECT_EQ(r.labels[i] == FeatureLabel::Dynamic, in_mask) << u << "," << v;
      dynamic += r.labels[i] == FeatureLabel::Dynamic;
      truth_dynamic += s.truth[v * W + u] != 0;
      if (in_mask) {
        EXPECT_EQ(r.reasons[i], CullReason::DepthMask);
      }
    }
    // Exact scene: the labels equal the truth (precision = recall = 1).
    EXPECT_EQ(dynamic, truth_dynamic);
    EXPECT_EQ(r.labels.back(), FeatureLabel::Dynamic);
    EXPECT_EQ(r.reasons.back(), CullReason::InvalidInput);
    EXPECT_EQ(r.num_dynamic, truth_dynamic + 1);
    EXPECT_EQ(r.num_mask_pixels, m.count());
  }
  // Labels need no raster: same labels with an empty MaskView.
  const DepthMaskResult a = depth_mask(s.view(), boxes, pts, DepthMaskOptions{});
  Mask m(W, H);
  const DepthMaskResult b = depth_mask(s.view(), boxes, pts, DepthMaskOptions{}, m.view());
  EXPECT_EQ(a.labels, b.labels);
}

// A result and scratch reused from a larger frame with a bad box give what a fresh call gives.
TYPED_TEST(DepthMask, OutParameterFormMatchesAFreshResultWhenReused) {
  using Raw = TypeParam;
  Scene<Raw> s;
  s.fill(4.0);
  s.person(60, 60, 18, 40, 2.5);
  s.person(95, 60, 18, 40, 1.2);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<Box<double>> first = {{38, 15, 82, 105}, {73, 15, 117, 105}, {nan, 0, 1, 1}};
  const std::vector<Box<double>> second = {{73, 15, 117, 105}};
  std::vector<Vec2<float>> many;
  for (int v = 0; v < H; v += 4)
    for (int u = 0; u < W; u += 4) many.emplace_back(float(u), float(v));
  const std::vector<Vec2<float>> few = {Vec2<float>(60, 60), Vec2<float>(100, 60), Vec2<float>(40, 17)};
  DepthMaskResult out;
  DepthMaskScratch scratch;
  depth_mask(s.view(), first, many, DepthMaskOptions{}, &out, &scratch);
  ASSERT_FALSE(out.reason.empty());  // the bad box is reported
  depth_mask(s.view(), second, few, DepthMaskOptions{}, &out, &scratch);
  const DepthMaskResult fresh = depth_mask(s.view(), second, few, DepthMaskOptions{});
  EXPECT_EQ(out.status, fresh.status);
  EXPECT_EQ(out.reason, fresh.reason);
  ASSERT_EQ(out.boxes.size(), fresh.boxes.size());
  EXPECT_EQ(out.boxes[0].d_c_m, fresh.boxes[0].d_c_m);
  EXPECT_EQ(out.labels, fresh.labels);
  EXPECT_EQ(out.reasons, fresh.reasons);
  EXPECT_EQ(out.box_index, fresh.box_index);
  EXPECT_EQ(out.box_bits, fresh.box_bits);
  EXPECT_EQ(out.num_dynamic, fresh.num_dynamic);
  EXPECT_EQ(out.num_static, fresh.num_static);
  EXPECT_EQ(out.num_in_boxes, fresh.num_in_boxes);
  EXPECT_EQ(out.num_mask_pixels, fresh.num_mask_pixels);
}

// Two people, the near one's box overlapping the far one's: box_bits names every box whose own mask
// holds a point, box_index the first.
TYPED_TEST(DepthMask, OverlappingBoxesReportEveryMaskHoldingAPoint) {
  using Raw = TypeParam;
  Scene<Raw> s;
  s.fill(4.0);
  s.person(60, 60, 18, 40, 2.5);   // far person
  s.person(95, 60, 18, 40, 1.2);   // near person, in front of the far one's right side
  const std::vector<Box<double>> boxes = {{38, 15, 82, 105}, {73, 15, 117, 105}};
  const std::vector<Vec2<float>> pts = {Vec2<float>(60, 60),    // far person only
                                        Vec2<float>(80, 60),    // near person, in both boxes
                                        Vec2<float>(100, 60),   // near person only
                                        Vec2<float>(40, 17)};   // wall in the far box
  DepthMaskOptions o;
  o.mode = DepthMaskMode::Plain;
  const DepthMaskResult r = depth_mask(s.view(), boxes, pts, o);
  ASSERT_TRUE(r.ok()) << r.reason;
  ASSERT_EQ(r.box_bits.size(), pts.size());
  EXPECT_EQ(r.box_bits[0], 1u);
  // The near person is closer than the far box's threshold too: both masks hold it.
  EXPECT_EQ(r.box_bits[1], 3u);
  EXPECT_EQ(r.box_index[1], 0);
  EXPECT_EQ(r.box_bits[2], 2u);
  EXPECT_EQ(r.box_bits[3], 0u);
  EXPECT_EQ(r.labels[3], FeatureLabel::Static);
}

TYPED_TEST(DepthMask, RuleNotApplicablePlainGivesCandidatesRobustFallsBackToHistogram) {
  using Raw = TypeParam;
  // The box is tight on the person: all four corners are on the person too (d_max - d_c = 0).
  Scene<Raw> s;
  s.fill(4.0);
  for (int v = 20; v <= 100; ++v)
    for (int u = 60; u <= 100; ++u) {
      s.depth[v * W + u] = Scene<Raw>::raw(1.5 + 0.002 * (v - 20));  // a slightly tilted body
      s.truth[v * W + u] = 1;
    }
  for (int v = 40; v <= 80; ++v)  // wall visible between the arms
    for (int u = 62; u <= 66; ++u) {
      s.depth[v * W + u] = Scene<Raw>::raw(4.0);
      s.truth[v * W + u] = 0;
    }
  const Box<double> box{60, 20, 100, 100};
  DepthMaskOptions o;
  o.mode = DepthMaskMode::Plain;
  Mask m(W, H);
  const std::vector<Vec2<double>> pts = {{80, 60}, {64, 60}, {130, 60}};
  const DepthMaskResult plain = depth_mask(s.view(), std::vector<Box<double>>{box}, pts, o, m.view());
  ASSERT_EQ(plain.boxes.size(), 1u);
  EXPECT_EQ(plain.boxes[0].outcome, DepthMaskOutcome::NotApplied);
  EXPECT_FALSE(plain.boxes[0].reason.empty());
  EXPECT_EQ(m.count(), 0u);
  EXPECT_EQ(plain.labels[0], FeatureLabel::Candidate);
  EXPECT_EQ(plain.labels[1], FeatureLabel::Candidate);
  EXPECT_EQ(plain.labels[2], FeatureLabel::Static);

  o.mode = DepthMaskMode::Robust;
  m.reset(W, H);
  const DepthMaskResult robust = depth_mask(s.view(), std::vector<Box<double>>{box}, pts, o, m.view());
  EXPECT_EQ(robust.boxes[0].outcome, DepthMaskOutcome::HistogramFallback);
  EXPECT_GT(robust.boxes[0].threshold_m, 1.66);  // the whole body (1.5 .. 1.66 m) ...
  EXPECT_LT(robust.boxes[0].threshold_m, 3.0);   // ... but not the wall
  EXPECT_DOUBLE_EQ(box_iou(s, m, box), 1.0);
  EXPECT_EQ(robust.labels[0], FeatureLabel::Dynamic);
  EXPECT_EQ(robust.labels[1], FeatureLabel::Static);
}

TYPED_TEST(DepthMask, HolesAtCentreAndCornersAreBridgedByTheRobustMode) {
  using Raw = TypeParam;
  Scene<Raw> s;
  s.fill(4.0);
  s.person(139, 59, 15, 40, 1.5);      // a person at the right image edge
  s.hole(138, 58, 140, 60);            // Kinect hole on the centre pixel
  s.hole(0, 0, W - 1, 3);              // band without depth along the top edge
  s.hole(W - 4, 0, W - 1, H - 1);      // ... and the right edge
  const Box<double> box{W - 41, 0, W - 1, H - 1};  // integer centre (139, 59)
  DepthMaskOptions o;
  o.mode = DepthMaskMode::Plain;
  const DepthMaskBoxInfo plain = depth_mask_box(s.view(), box, o);
  EXPECT_FALSE(plain.rule_applies);  // centre pixel has no depth
  o.mode = DepthMaskMode::Robust;
  o.missing_depth = MissingDepth::InMask;
  Mask m(W, H);
  const DepthMaskBoxInfo robust = depth_mask_box(s.view(), box, o, m.view());
  EXPECT_TRUE(robust.rule_applies);
  EXPECT_NEAR(robust.d_c_m, 1.5, 1e-6);
  EXPECT_NEAR(robust.d_max_m, 4.0, 1e-6);
  EXPECT_TRUE(robust.masks_missing);
  // Person pixels all masked; wall pixels with depth never; missing pixels masked (InMask).
  const PixelRect r = pixel_rect(box, W, H);
  for (int v = r.r0; v < r.r1; ++v)
    for (int u = r.c0; u < r.c1; ++u) {
      const Raw d = s.depth[v * W + u];
      if (d == Raw(0)) {
        EXPECT_TRUE(m.test(u, v));
      } else {
        EXPECT_EQ(m.test(u, v), s.truth[v * W + u] != 0) << u << "," << v;
      }
    }
  o.missing_depth = MissingDepth::OutOfMask;
  m.reset(W, H);
  EXPECT_FALSE(depth_mask_box(s.view(), box, o, m.view()).masks_missing);
  EXPECT_FALSE(m.test(139, 59));
  EXPECT_TRUE(m.test(139, 70));
  // Nearest (default): the hole on the person is the person's; the border bands are the wall's, also
  // beside the person's widest row (x = 154), where the wall column x = 155 is nearer.
  o.missing_depth = MissingDepth::Nearest;
  m.reset(W, H);
  const DepthMaskBoxInfo nearest = depth_mask_box(s.view(), box, o, m.view());
  EXPECT_FALSE(nearest.masks_missing);
  EXPECT_TRUE(m.test(139, 59));
  EXPECT_FALSE(m.test(130, 1));
  EXPECT_FALSE(m.test(W - 2, 10));
  EXPECT_FALSE(m.test(W - 4, 59));
}

// MissingDepth::Nearest: a pixel without depth is in the mask when its nearest pixel with depth (exact
// Euclidean distance, within the box) is in the band; ties go to the mask. The raster (two exact distance
// transforms) and the point labels (ring search) must both equal a brute-force evaluation of that rule,
// on random scenes of people with holes of every size.
TYPED_TEST(DepthMask, MissingDepthTakesTheNearestMeasuredPixelsDecision) {
  using Raw = TypeParam;
  Random rng(12345);
  auto next = [&](int n) { return static_cast<int>(rng.index(static_cast<std::uint32_t>(n))); };
  std::size_t total_in = 0, total_out = 0;
  for (int trial = 0; trial < 20; ++trial) {
    Scene<Raw> s;
    s.fill(4.0);
    // One draw per statement: the order of evaluation of function arguments is unspecified (g++ and
    // clang differ), and the scenes must not depend on the compiler.
    const int cx = 40 + next(80), cy = 30 + next(60), rx = 8 + next(20), ry = 15 + next(30);
    s.person(cx, cy, rx, ry, 1.5);
    for (int k = 0, holes = 5 + next(30); k < holes; ++k) {
      const int u0 = next(W), v0 = next(H), size = next(k < 3 ? 25 : 4);
      s.hole(u0, v0, std::min(W - 1, u0 + size), std::min(H - 1, v0 + size));
    }
    // Every other scene also gets a wide hole (a border band, a window): rows with long runs without
    // depth take the raster's parabola envelopes instead of the row scan.
    if (trial % 2 == 1) {
      const int u0 = next(W / 2), v0 = next(H / 2), v1 = next(H / 2) + H / 3;
      s.hole(u0, v0, W - 1, v1);
    }
    const Box<double> box{double(next(40)), double(next(30)), double(100 + next(60)), double(80 + next(40))};
    DepthMaskOptions o;  // robust, Nearest
    Mask m(W, H);
    std::vector<Vec2<double>> pts;
    for (int v = 0; v < H; ++v)
      for (int u = 0; u < W; ++u) pts.emplace_back(u, v);
    const DepthMaskResult r = depth_mask(s.view(), std::vector<Box<double>>{box}, pts, o, m.view());
    ASSERT_TRUE(r.ok()) << r.reason;
    const DepthMaskOutcome outcome = r.boxes[0].outcome;
    ASSERT_TRUE(outcome == DepthMaskOutcome::RuleApplied || outcome == DepthMaskOutcome::HistogramFallback)
        << "trial " << trial << ": " << to_string(outcome);
    const double thr = r.boxes[0].threshold_raw;
    const PixelRect rc = pixel_rect(box, W, H);
    auto depth_raw = [&](int u, int v) { return double(s.depth[v * W + u]); };
    std::size_t holes_in = 0, holes_out = 0;
    for (int v = 0; v < H; ++v)
      for (int u = 0; u < W; ++u) {
        bool expected = false;
        if (u >= rc.c0 && u < rc.c1 && v >= rc.r0 && v < rc.r1) {
          if (s.depth[v * W + u] != Raw(0)) {
            expected = depth_raw(u, v) < thr;
          } else {
            long best_in = -1, best_out = -1;
            for (int y = rc.r0; y < rc.r1; ++y)
              for (int x = rc.c0; x < rc.c1; ++x) {
                if (s.depth[y * W + x] == Raw(0)) continue;
                const long d2 = long(x - u) * (x - u) + long(y - v) * (y - v);
                long& best = depth_raw(x, y) < thr ? best_in : best_out;
                if (best < 0 || d2 < best) best = d2;
              }
            expected = best_in >= 0 && (best_out < 0 || best_in <= best_out);
            (expected ? holes_in : holes_out) += 1;
          }
        }
        ASSERT_EQ(m.test(u, v), expected) << "raster, trial " << trial << " at " << u << "," << v;
        ASSERT_EQ(r.labels[std::size_t(v * W + u)] == FeatureLabel::Dynamic, expected)
            << "label, trial " << trial << " at " << u << "," << v;
      }
    EXPECT_EQ(r.num_mask_pixels, m.count());
    total_in += holes_in;
    total_out += holes_out;
  }
  // Both decisions were exercised.
  EXPECT_GT(total_in, 1000u);
  EXPECT_GT(total_out, 1000u);
}

// Kinect shadows: the pixels without depth on the background side of a silhouette belong to the wall,
// those on the person side to the person, and a feature there is labelled accordingly.
TYPED_TEST(DepthMask, HolesBesideASilhouetteGoWithTheSurfaceTheyLieOn) {
  using Raw = TypeParam;
  Scene<Raw> s;
  s.fill(4.0);
  s.person(80, 60, 20, 40, 1.5);
  // An 8 px hole across the left outline at rows 50-70: columns 54-59 are wall (the outline is at x = 60
  // on row 60), 60-61 person. Nearest measured pixels on row 60: the wall at x = 53, the person at x = 62.
  s.hole(54, 50, 61, 70);
  const std::vector<Box<double>> boxes = {{50, 15, 110, 105}};
  const std::vector<Vec2<float>> pts = {{55.f, 60.f}, {61.f, 60.f}, {57.f, 60.f}};
  for (MissingDepth policy : {MissingDepth::Nearest, MissingDepth::InMask, MissingDepth::OutOfMask}) {
    DepthMaskOptions o;
    o.missing_depth = policy;
    const DepthMaskResult r = depth_mask(s.view(), boxes, pts, o);
    ASSERT_TRUE(r.ok()) << r.reason;
    const bool nearest = policy == MissingDepth::Nearest, in = policy == MissingDepth::InMask;
    EXPECT_EQ(r.labels[0] == FeatureLabel::Dynamic, in) << "wall side, far from the person";
    EXPECT_EQ(r.labels[1] == FeatureLabel::Dynamic, in || nearest) << "person side";
    EXPECT_EQ(r.labels[2] == FeatureLabel::Dynamic, in) << "wall side, 4 px from the wall, 5 px from the person";
  }
}

TYPED_TEST(DepthMask, BoxWithoutDepthAndBoxesOutsideTheImage) {
  using Raw = TypeParam;
  Scene<Raw> s;
  s.fill(4.0);
  s.hole(20, 20, 60, 60);
  const std::vector<Box<double>> boxes = {{20, 20, 60, 60},       // no depth at all
                                          {200, 10, 300, 50},     // outside the image
                                          {std::nan(""), 0, 5, 5}};  // non-finite
  const std::vector<Vec2<double>> pts = {{40, 40}, {100, 100}};
  Mask m(W, H);
  const DepthMaskResult r = depth_mask(s.view(), boxes, pts, DepthMaskOptions{}, m.view());
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_NE(r.reason.find("2 of 3"), std::string::npos) << r.reason;
  EXPECT_EQ(r.boxes[0].outcome, DepthMaskOutcome::WholeBox);
  EXPECT_EQ(r.boxes[0].num_mask_pixels, 41u * 41u);
  EXPECT_EQ(r.boxes[1].status, Status::Skipped);
  EXPECT_EQ(r.boxes[2].status, Status::InvalidInput);
  EXPECT_EQ(r.labels[0], FeatureLabel::Dynamic);
  EXPECT_EQ(r.labels[1], FeatureLabel::Static);
  EXPECT_EQ(m.count(), 41u * 41u);

  // Missing depth image and mismatched mask.
  const DepthMaskResult none = depth_mask(DepthView<Raw>{}, boxes, pts, DepthMaskOptions{});
  EXPECT_EQ(none.status, Status::Skipped);
  EXPECT_EQ(none.labels.size(), 2u);
  Mask wrong(W - 1, H);
  EXPECT_EQ(depth_mask(s.view(), boxes, pts, DepthMaskOptions{}, wrong.view()).status, Status::InvalidInput);
}

TYPED_TEST(DepthMask, ValidRangeIsAParameter) {
  using Raw = TypeParam;
  Scene<Raw> s;
  s.fill(4.0);
  s.person(80, 60, 20, 40, 1.5);
  s.person(80, 30, 4, 4, 0.2);  // sensor noise nearer than the valid range
  const Box<double> box{55, 15, 105, 105};
  DepthMaskOptions o;
  o.mode = DepthMaskMode::Plain;
  Mask m(W, H);
  depth_mask_box(s.view(0.4f, 10.f), box, o, m.view());
  EXPECT_FALSE(m.test(80, 30));  // 0.2 m is "no measurement" with min 0.4 m
  EXPECT_TRUE(m.test(80, 60));
  // Everything beyond 3 m invalid: the corners have no depth and the plain rule cannot apply.
  EXPECT_FALSE(depth_mask_box(s.view(0.f, 3.f), box, o).rule_applies);
}

TEST(DepthMaskRaw, ThresholdIsComparedInRawUnits) {
  // DLD-SLAM in TUM raw units: eps 0.3 m = 1500, strict "<": the pixel at exactly d_c + eps is out.
  std::vector<std::uint16_t> d(W * H, 20000);
  for (int v = 40; v <= 80; ++v)
    for (int u = 60; u <= 100; ++u) d[v * W + u] = 10000;
  d[50 * W + 70] = 11500;
  d[50 * W + 71] = 11499;
  DepthMaskOptions o;
  o.mode = DepthMaskMode::Plain;
  Mask m(W, H);
  const DepthMaskBoxInfo info = depth_mask_box(tum_depth_view(d.data(), W, H), Box<float>{50, 30, 110, 90}, o, m.view());
  EXPECT_EQ(info.threshold_raw, 11500.0);
  EXPECT_FALSE(m.test(70, 50));
  EXPECT_TRUE(m.test(71, 50));
  EXPECT_EQ(m.view().at(71, 50), 255);
}
}  // namespace
