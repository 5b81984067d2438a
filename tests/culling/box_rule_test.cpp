#include "dyncull/culling/box_rule.hpp"
#include "dyncull/core/random.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <vector>

#ifdef DYNCULL_HAS_OPENCV
#include <opencv2/core.hpp>
#endif

namespace {
using namespace dyncull;

template <class T>
class BoxRule : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(BoxRule, Scalars, );

constexpr int kPerson = 0, kChair = 56, kTv = 62;

template <class T>
std::vector<Vec2<T>> grid_in(const Box<T>& b, int nx, int ny) {
  std::vector<Vec2<T>> pts;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      pts.emplace_back(b.x0 + (b.x1 - b.x0) * (T(i) + T(0.5)) / T(nx), b.y0 + (b.y1 - b.y0) * (T(j) + T(0.5)) / T(ny));
  return pts;
}

TYPED_TEST(BoxRule, WalkingPersonDynamicTvOverrideChairCandidate) {
  using T = TypeParam;
  const Box<T> person{T(100), T(50), T(220), T(400)};
  const Box<T> tv{T(200), T(100), T(330), T(200)};  // overlaps the person's right edge
  const Box<T> chair{T(400), T(250), T(500), T(420)};
  const std::vector<Detection<T>> dets = {{person, kPerson, T(0.9)}, {tv, kTv, T(0.9)}, {chair, kChair, T(0.9)}};
  const std::vector<Vec2<T>> pts = {
      {T(150), T(300)},  // person only -> dynamic
      {T(210), T(150)},  // person and tv -> static (low-level override)
      {T(300), T(150)},  // tv only -> static
      {T(450), T(300)},  // chair -> candidate
      {T(600), T(20)},   // background -> static
      {T(100), T(50)},   // exactly on the person's corner: boxes are inclusive -> dynamic
  };
  const BoxRuleResult<T> r = apply_box_rule(pts, dets, MotionLevelTable::coco80(), BoxRuleOptions<T>{});
  ASSERT_TRUE(r.ok()) << r.reason;
  const std::vector<FeatureLabel> want = {FeatureLabel::Dynamic, FeatureLabel::Static,    FeatureLabel::Static,
                                          FeatureLabel::Candidate, FeatureLabel::Static, FeatureLabel::Dynamic};
  EXPECT_EQ(r.labels, want);
  EXPECT_EQ(r.reasons[0], CullReason::HighLevelBox);
  EXPECT_EQ(r.reasons[1], CullReason::LowLevelOverride);
  EXPECT_EQ(r.reasons[2], CullReason::None);
  EXPECT_EQ(r.reasons[3], CullReason::MediumLevelBox);
  EXPECT_EQ(r.box_index[0], 0);
  EXPECT_EQ(r.box_index[3], 2);
  EXPECT_EQ(r.box_index[4], -1);
  EXPECT_EQ(r.num_dynamic, 2u);
  EXPECT_EQ(r.num_candidate, 1u);
  EXPECT_EQ(r.num_static, 3u);
  EXPECT_EQ(r.num_low_override, 1u);
  EXPECT_EQ(r.num_high_boxes, 1u);
  EXPECT_EQ(r.num_medium_boxes, 1u);
  EXPECT_EQ(r.num_low_boxes, 1u);
}

// A result and scratch reused from a larger frame with an invalid box give what a fresh call gives.
TYPED_TEST(BoxRule, OutParameterFormMatchesAFreshResultWhenReused) {
  using T = TypeParam;
  const Box<T> person{T(100), T(50), T(220), T(400)};
  const Box<T> tv{T(200), T(100), T(330), T(200)};
  const T nan = std::numeric_limits<T>::quiet_NaN();
  const std::vector<Detection<T>> first = {{person, kPerson, T(0.9)}, {Box<T>{nan, T(0), T(1), T(1)}, kPerson, T(1)}};
  const std::vector<Detection<T>> second = {{person, kPerson, T(0.9)}, {tv, kTv, T(0.9)}};
  const std::vector<Vec2<T>> many = grid_in(Box<T>{T(0), T(0), T(640), T(480)}, 20, 15);
  const std::vector<Vec2<T>> few = {{T(150), T(300)}, {T(210), T(150)}, {T(600), T(20)}};
  BoxRuleResult<T> out;
  BoxRuleScratch<T> scratch;
  apply_box_rule(many, first, MotionLevelTable::coco80(), BoxRuleOptions<T>{}, &out, &scratch);
  ASSERT_FALSE(out.reason.empty());  // the invalid box is reported
  apply_box_rule(few, second, MotionLevelTable::coco80(), BoxRuleOptions<T>{}, &out, &scratch);
  const BoxRuleResult<T> fresh = apply_box_rule(few, second, MotionLevelTable::coco80(), BoxRuleOptions<T>{});
  EXPECT_EQ(out.status, fresh.status);
  EXPECT_EQ(out.reason, fresh.reason);
  EXPECT_EQ(out.labels, fresh.labels);
  EXPECT_EQ(out.reasons, fresh.reasons);
  EXPECT_EQ(out.box_index, fresh.box_index);
  EXPECT_EQ(out.num_dynamic, fresh.num_dynamic);
  EXPECT_EQ(out.num_static, fresh.num_static);
  EXPECT_EQ(out.num_low_override, fresh.num_low_override);
  EXPECT_EQ(out.num_high_boxes, fresh.num_high_boxes);
  EXPECT_EQ(out.num_low_boxes, fresh.num_low_boxes);
}

TYPED_TEST(BoxRule, OptionsChangeTheOutcomeAsDocumented) {
  using T = TypeParam;
  const std::vector<Detection<T>> dets = {{Box<T>{T(0), T(0), T(100), T(100)}, kPerson, T(1)},
                                          {Box<T>{T(90), T(0), T(200), T(100)}, kTv, T(1)},
                                          {Box<T>{T(300), T(0), T(400), T(100)}, kChair, T(1)}};
  const std::vector<Vec2<T>> pts = {{T(50), T(50)}, {T(93), T(50)}, {T(350), T(50)}};
  BoxRuleOptions<T> o;
  o.medium_as_candidate = false;
  const BoxRuleResult<T> r = apply_box_rule(pts, dets, MotionLevelTable::coco80(), o);
  EXPECT_EQ(r.labels[0], FeatureLabel::Dynamic);
  EXPECT_EQ(r.labels[1], FeatureLabel::Static);  // the tv box shelters x = 93
  EXPECT_EQ(r.reasons[1], CullReason::LowLevelOverride);
  EXPECT_EQ(r.labels[2], FeatureLabel::Static);  // the chair: no candidate
}

TYPED_TEST(BoxRule, EmptyInvalidAndIgnoredBoxes) {
  using T = TypeParam;
  const T nan = std::numeric_limits<T>::quiet_NaN();
  const std::vector<Vec2<T>> pts = {{T(10), T(10)}, {nan, T(5)}, {T(5), std::numeric_limits<T>::infinity()}};
  // No boxes at all: everything static except the non-finite points.
  const BoxRuleResult<T> none = apply_box_rule(pts, std::vector<Detection<T>>{}, MotionLevelTable::coco80());
  EXPECT_EQ(none.labels[0], FeatureLabel::Static);
  EXPECT_EQ(none.labels[1], FeatureLabel::Dynamic);
  EXPECT_EQ(none.reasons[1], CullReason::InvalidInput);
  EXPECT_EQ(none.num_non_finite, 2u);
  // NaN box skipped with a reason, inverted box skipped, unknown class ignored, zero-area box is a point.
  const std::vector<Detection<T>> dets = {{Box<T>{nan, T(0), T(20), T(20)}, kPerson, T(1)},
                                          {Box<T>{T(20), T(20), T(0), T(0)}, kPerson, T(1)},
                                          {Box<T>{T(0), T(0), T(20), T(20)}, 500, T(1)},
                                          {Box<T>{T(10), T(10), T(10), T(10)}, kPerson, T(1)}};
  const BoxRuleResult<T> r = apply_box_rule(pts, dets, MotionLevelTable::coco80());
  EXPECT_TRUE(r.ok());
  EXPECT_NE(r.reason.find("2 invalid"), std::string::npos) << r.reason;
  EXPECT_EQ(r.labels[0], FeatureLabel::Dynamic);  // on the degenerate box
  EXPECT_EQ(r.box_index[0], 3);
  // No points.
  const BoxRuleResult<T> empty = apply_box_rule(std::vector<Vec2<T>>{}, dets, MotionLevelTable::coco80());
  EXPECT_TRUE(empty.ok());
  EXPECT_TRUE(empty.labels.empty());
}

TYPED_TEST(BoxRule, AllDynamicFrame) {
  using T = TypeParam;
  const Box<T> full{T(0), T(0), T(639), T(479)};
  const std::vector<Vec2<T>> pts = grid_in(full, 40, 25);
  const BoxRuleResult<T> r = apply_box_rule(pts, std::vector<Detection<T>>{{full, kPerson, T(1)}},
                                            MotionLevelTable::coco80());
  EXPECT_EQ(r.num_dynamic, pts.size());
  EXPECT_EQ(r.num_static, 0u);
}

// Oracle: the branch-free SoA kernel against the plain per-point rule with Box::contains.
TYPED_TEST(BoxRule, MatchesScalarOracleOnRandomScenes) {
  using T = TypeParam;
  Random rng(7);
  const MotionLevelTable table = MotionLevelTable::coco80();
  const int classes[] = {kPerson, kChair, kTv, 16 /*dog*/, 73 /*book*/};
  for (int scene = 0; scene < 20; ++scene) {
    std::vector<Detection<T>> dets;
    for (int b = 0; b < 6; ++b) {
      const T x = T(rng.uniform(0, 560)), y = T(rng.uniform(0, 400));
      dets.push_back({Box<T>{x, y, x + T(rng.uniform(10, 200)), y + T(rng.uniform(10, 200))}, classes[rng.index(5)], T(1)});
    }
    std::vector<Vec2<T>> pts(1000);
    for (auto& p : pts) p = Vec2<T>(T(rng.uniform(0, 640)), T(rng.uniform(0, 480)));
    const BoxRuleResult<T> r = apply_box_rule(pts, dets, table);
    std::size_t agree = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      bool high = false, medium = false, low = false;
      for (const auto& d : dets) {
        if (!d.box.contains(pts[i].x(), pts[i].y())) continue;
        const MotionLevel l = table.level(d.class_id);
        high |= l == MotionLevel::High;
        medium |= l == MotionLevel::Medium;
        low |= l == MotionLevel::Low;
      }
      const FeatureLabel want = low ? FeatureLabel::Static
                                    : (high ? FeatureLabel::Dynamic : (medium ? FeatureLabel::Candidate : FeatureLabel::Static));
      agree += r.labels[i] == want;
    }
    // Precision and recall against the oracle must both be 1: any disagreement is a kernel bug.
    EXPECT_EQ(agree, pts.size()) << "scene " << scene;
  }
}

TYPED_TEST(BoxRule, OptionsAreValidatedWithTheFieldNamed) {
  using T = TypeParam;
  std::string why = "unchanged";
  EXPECT_EQ(BoxRuleOptions<T>{}.validate(&why), Status::Ok);
  EXPECT_TRUE(why.empty());
}

// Points and boxes with NaN, +-Inf and huge finite values mixed with ordinary ones.
template <class T>
T awkward_value(Random& rng) {
  const T inf = std::numeric_limits<T>::infinity(), big = std::numeric_limits<T>::max();
  switch (rng.index(8)) {
    case 0: return std::numeric_limits<T>::quiet_NaN();
    case 1: return rng.index(2) ? inf : -inf;
    case 2: return rng.index(2) ? big : -big;
    case 3: return T(4294967306.0);  // 2^32 + 10
    default: return T(rng.uniform(-20, 120));
  }
}

// Every vector path of the membership kernel against its scalar loop, at every size around the
// vector widths (4 and 16 floats), with flags already set (the kernel must only OR into them).
TYPED_TEST(BoxRule, VectorPathMatchesScalarPathOnAwkwardValues) {
  using T = TypeParam;
  Random rng(11);
  for (std::size_t n = 0; n <= 40; ++n) {
    for (int trial = 0; trial < 20; ++trial) {
      std::vector<T> xs(n), ys(n);
      std::vector<std::uint8_t> pre(n);
      for (std::size_t i = 0; i < n; ++i) {
        xs[i] = awkward_value<T>(rng);
        ys[i] = awkward_value<T>(rng);
        pre[i] = static_cast<std::uint8_t>(rng.index(16));
      }
      std::vector<Box<T>> boxes;
      std::vector<std::uint8_t> bits;
      const std::uint8_t kinds[] = {detail::kInHigh, detail::kInMedium, detail::kInLow};
      for (std::size_t b = 0, nb = rng.index(5); b < nb; ++b) {
        const T x = T(rng.uniform(-10, 100)), y = T(rng.uniform(-10, 100));
        boxes.push_back(rng.index(4) == 0 ? Box<T>{-std::numeric_limits<T>::max(), y, std::numeric_limits<T>::max(), y + T(40)}
                                          : Box<T>{x, y, x + T(rng.uniform(0, 60)), y + T(rng.uniform(0, 60))});
        bits.push_back(kinds[rng.index(3)]);
      }
      std::vector<std::uint8_t> fast = pre, slow = pre;
      detail::mark_points(xs.data(), ys.data(), n, boxes, bits, fast.data());
      for (std::size_t b = 0; b < boxes.size(); ++b)
        detail::mark_points_in_box(xs.data(), ys.data(), 0, n, boxes[b], bits[b], slow.data());
      ASSERT_EQ(fast, slow) << "n = " << n << ", trial " << trial;
    }
  }
}

TYPED_TEST(BoxRule, NanPointsStayNonFiniteOnTheVectorPath) {
  using T = TypeParam;
  Random rng(5);
  const MotionLevelTable table = MotionLevelTable::coco80();
  const int classes[] = {kPerson, kChair, kTv};
  for (std::size_t n = 0; n <= 40; ++n) {
    std::vector<Vec2<T>> pts(n);
    for (auto& p : pts) p = Vec2<T>(awkward_value<T>(rng), awkward_value<T>(rng));
    std::vector<Detection<T>> dets;
    for (int b = 0; b < 3; ++b) {
      const T x = T(rng.uniform(-10, 100)), y = T(rng.uniform(-10, 100));
      dets.push_back({Box<T>{x, y, x + T(rng.uniform(0, 60)), y + T(rng.uniform(0, 60))}, classes[b], T(1)});
    }
    dets.push_back({Box<T>{-std::numeric_limits<T>::max(), T(0), std::numeric_limits<T>::max(), T(50)}, kPerson, T(1)});
    const BoxRuleResult<T> r = apply_box_rule(pts, dets, table);
    ASSERT_TRUE(r.ok()) << r.reason;
    std::size_t bad = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const T x = pts[i].x(), y = pts[i].y();
      if (!std::isfinite(x) || !std::isfinite(y)) {
        ++bad;
        EXPECT_EQ(r.labels[i], FeatureLabel::Dynamic) << "n = " << n << ", point " << i;
        EXPECT_EQ(r.reasons[i], CullReason::InvalidInput) << "n = " << n << ", point " << i;
        continue;
      }
      bool high = false, medium = false, low = false;
      for (const auto& d : dets) {
        if (!d.box.contains(x, y)) continue;
        const MotionLevel l = table.level(d.class_id);
        high |= l == MotionLevel::High;
        medium |= l == MotionLevel::Medium;
        low |= l == MotionLevel::Low;
      }
      const FeatureLabel want = low ? FeatureLabel::Static
                                    : (high ? FeatureLabel::Dynamic : (medium ? FeatureLabel::Candidate : FeatureLabel::Static));
      EXPECT_EQ(r.labels[i], want) << "n = " << n << ", point " << i;
    }
    EXPECT_EQ(r.num_non_finite, bad) << "n = " << n;
  }
}

#ifdef DYNCULL_HAS_OPENCV
TEST(BoxRuleOpenCV, KeyPointsAndPoint2fWithoutCopies) {
  const std::vector<Detection<float>> dets = {{Box<float>{10, 10, 50, 50}, kPerson, 1.f}};
  std::vector<cv::KeyPoint> kps = {cv::KeyPoint(20.f, 20.f, 7.f), cv::KeyPoint(80.f, 20.f, 7.f)};
  const auto r = apply_box_rule(kps, dets, MotionLevelTable::coco80(), BoxRuleOptions<float>{});
  EXPECT_EQ(r.labels, (std::vector<FeatureLabel>{FeatureLabel::Dynamic, FeatureLabel::Static}));
  std::vector<cv::Point2f> p2 = {{20.f, 20.f}, {80.f, 20.f}};
  const auto r2 = apply_box_rule(p2, dets, MotionLevelTable::coco80(), BoxRuleOptions<float>{});
  EXPECT_EQ(r2.labels, r.labels);
}
#endif
}  // namespace
