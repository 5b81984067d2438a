// Bad input to the culling stages (depth mask, sub-box vote and mask, multi-view, moving consistency,
// reprojection, coherent motion, dynamic probability, static history, sub-box memory): mismatched sizes,
// options out of range, and property tests over random inputs with NaN / Inf / huge / negative values.
// For any input a stage either returns a non-Ok status with a reason, or finite outputs and defined labels.
#include "dyncull/core/random.hpp"
#include "dyncull/culling/coherent_motion.hpp"
#include "dyncull/culling/depth_mask.hpp"
#include "dyncull/culling/dynamic_probability.hpp"
#include "dyncull/culling/moving_consistency.hpp"
#include "dyncull/culling/multiview_check.hpp"
#include "dyncull/culling/reprojection_check.hpp"
#include "dyncull/culling/static_history.hpp"
#include "dyncull/culling/subbox_memory.hpp"
#include "dyncull/culling/subbox_refine.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <climits>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace dyncull {
namespace {

template <class T>
class StageInputsTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(StageInputsTest, Scalars, );  // trailing comma: clang -Wpedantic rejects an empty variadic

bool defined(FeatureLabel l) {
  return l == FeatureLabel::Static || l == FeatureLabel::Candidate || l == FeatureLabel::Dynamic;
}
bool defined(CullReason r) { return static_cast<int>(r) <= static_cast<int>(CullReason::ListedStage); }

/// A value for property tests: mostly ordinary, sometimes NaN, +-Inf, huge, negative or tiny.
template <class T>
T wild_or_tiny(Random& rng, double lo, double hi) {
  switch (rng.index(16)) {
    case 0: return std::numeric_limits<T>::quiet_NaN();
    case 1: return std::numeric_limits<T>::infinity();
    case 2: return -std::numeric_limits<T>::infinity();
    case 3: return std::numeric_limits<T>::max() * T(rng.uniform(-1, 1));
    case 4: return T(rng.uniform(-1e9, 1e9));
    case 5: return T(-rng.uniform(0, 10));
    case 6: return std::numeric_limits<T>::denorm_min();
    default: return T(rng.uniform(lo, hi));
  }
}

/// An option value: usually the default, now and then something absurd (one in 40: most trials keep
/// every option valid and exercise the kernel itself).
template <class X>
X maybe_wild(Random& rng, X normal) {
  if (rng.index(40) != 0) return normal;
  return wild_or_tiny<X>(rng, -10, 10);
}
int maybe_wild_int(Random& rng, int normal) {
  switch (rng.index(60)) {
    case 0: return INT_MAX;
    case 1: return INT_MIN;
    case 2: return -1;
    case 3: return static_cast<int>(rng.index(100));
    default: return normal;
  }
}

/// A box with a wild corner in [x_lo, x_hi] x [y_lo, y_hi] and wild extents up to w_hi, h_hi (may be
/// inverted, empty or non-finite).
template <class T>
Box<T> wild_box(Random& rng, double x_lo, double x_hi, double y_lo, double y_hi, double w_hi, double h_hi) {
  const T x0 = wild_or_tiny<T>(rng, x_lo, x_hi), y0 = wild_or_tiny<T>(rng, y_lo, y_hi);
  return Box<T>{x0, y0, x0 + wild_or_tiny<T>(rng, 0, w_hi), y0 + wild_or_tiny<T>(rng, 0, h_hi)};
}

/// The options fail validate() with InvalidInput and a reason that names the field.
template <class Options>
void expect_names_field(const Options& o, const char* field) {
  std::string why;
  EXPECT_EQ(o.validate(&why), Status::InvalidInput) << field;
  EXPECT_NE(why.find(field), std::string::npos) << why;
}

// ---- multi-view check ----

TYPED_TEST(StageInputsTest, MultiViewRejectsFewerDepthsThanPoints) {
  using T = TypeParam;
  std::vector<Vec2<T>> points(100, Vec2<T>(T(320), T(240)));
  std::vector<T> depths(10, T(2));
  std::vector<float> depth(640 * 480, 2.f);
  const DepthView<float> view{depth.data(), 640, 480, 0, 1.f, 0.f, 1e30f};
  const auto r = check_multiview(points, depths, Rigid3<T>{}, Rigid3<T>{}, view, PinholeCamera<T>{},
                                 MultiViewOptions<T>{});
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.reason.find("ref_depths_m"), std::string::npos) << r.reason;
}

TYPED_TEST(StageInputsTest, KeyframeRingStoresNothingWhenDepthsDoNotMatchPoints) {
  using T = TypeParam;
  KeyframeRing<T> ring(4);
  const std::vector<Vec2<T>> points(50, Vec2<T>(T(10), T(10)));
  const std::vector<T> depths(5, T(1));
  EXPECT_EQ(ring.push(Rigid3<T>{}, points, depths), Status::InvalidInput);
  EXPECT_TRUE(ring.empty());
}

TYPED_TEST(StageInputsTest, MultiViewOptionsNameTheBadField) {
  using T = TypeParam;
  std::string why;
  MultiViewOptions<T> o;
  EXPECT_EQ(o.validate(&why), Status::Ok) << why;
  o.search_radius_px = INT_MAX;
  expect_names_field(o, "search_radius_px");
  o = MultiViewOptions<T>{};
  o.max_parallax_deg = std::numeric_limits<T>::quiet_NaN();
  expect_names_field(o, "max_parallax_deg");
}

TYPED_TEST(StageInputsTest, MultiViewPropertyStatusOrFiniteOutputs) {
  using T = TypeParam;
  Random rng(11);
  std::size_t checked = 0;  // trials whose outputs were checked (not rejected)
  for (int trial = 0; trial < 300; ++trial) {
    const int w = 1 + static_cast<int>(rng.index(40)), h = 1 + static_cast<int>(rng.index(30));
    std::vector<float> depth(static_cast<std::size_t>(w * h));
    for (float& d : depth) d = wild_or_tiny<float>(rng, 0, 8);
    DepthView<float> view{depth.data(), w, h, 0, 1.f, 0.f, 1e30f};
    if (rng.index(8) == 0) view.units_per_metre = wild_or_tiny<float>(rng, -2, 2);
    PinholeCamera<T> camera;
    camera.width = w;
    camera.height = h;
    camera.cx = T(w) / 2;
    camera.cy = T(h) / 2;
    camera.fx = camera.fy = T(rng.uniform(5, 60));
    const std::size_t n = rng.index(60);
    std::vector<Vec2<T>> points(n);
    std::vector<T> depths(rng.index(10) == 0 ? rng.index(60) : n);
    for (auto& p : points) p = Vec2<T>(wild_or_tiny<T>(rng, 0, w), wild_or_tiny<T>(rng, 0, h));
    for (T& d : depths) d = wild_or_tiny<T>(rng, 0, 8);
    Rigid3<T> ref, cur;
    cur.t = Vec3<T>(wild_or_tiny<T>(rng, -0.2, 0.2), T(rng.uniform(-0.2, 0.2)), T(rng.uniform(-0.2, 0.2)));
    MultiViewOptions<T> o;
    o.search_radius_px = maybe_wild_int(rng, 2);
    o.depth_threshold_m = maybe_wild(rng, T(0.4));
    o.max_parallax_deg = maybe_wild(rng, T(30));
    o.border_px = maybe_wild(rng, T(0));
    MultiViewResult<T> r;
    check_multiview(points, depths, ref, cur, view, camera, o, &r);
    if (r.status != Status::Ok && r.status != Status::TooFewPoints) {
      EXPECT_FALSE(r.reason.empty()) << trial;
      continue;
    }
    ++checked;
    ASSERT_EQ(r.labels.size(), n);
    for (std::size_t i = 0; i < n; ++i) {
      EXPECT_TRUE(defined(r.labels[i])) << trial;
      EXPECT_TRUE(std::isfinite(r.projected_depth_m[i]) && std::isfinite(r.measured_depth_m[i])) << trial;
    }
    Mask mask;
    std::vector<std::uint32_t> stack;
    const std::size_t set = grow_multiview_regions(r, view, &mask, &stack);
    EXPECT_LE(set, static_cast<std::size_t>(w * h)) << trial;
  }
  EXPECT_GT(checked, 30u) << "trials that reached the output checks";
}

// ---- sub-box vote and mask ----

/// Ten features in each cell of a 3 x 3 split of (0, 0)-(90, 90); cell (1, 1) flagged.
template <class T>
void centre_cell_scene(std::vector<Vec2<T>>* points, std::vector<FeatureLabel>* labels) {
  for (int cy = 0; cy < 3; ++cy)
    for (int cx = 0; cx < 3; ++cx)
      for (int k = 0; k < 10; ++k) {
        points->emplace_back(T(cx * 30 + 5 + 2 * k), T(cy * 30 + 15));
        labels->push_back(cx == 1 && cy == 1 ? FeatureLabel::Dynamic : FeatureLabel::Static);
      }
}

TYPED_TEST(StageInputsTest, SubBoxMaskUsesTheGridOfTheVote) {
  using T = TypeParam;
  std::vector<Vec2<T>> points;
  std::vector<FeatureLabel> labels;
  centre_cell_scene(&points, &labels);
  const std::vector<Box<T>> boxes{Box<T>{T(0), T(0), T(90), T(90)}};
  SubBoxOptions<T> vote;
  vote.grid = 3;
  vote.dilation_radius_px = 0;
  const SubBoxResult<T> r = refine_subboxes(points, labels, boxes, vote);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.grid, 3);
  Mask expected(100, 100), mask(100, 100);
  std::vector<std::uint16_t> scratch;
  const std::size_t want = subbox_mask(r, boxes, vote, ConstMaskView{}, expected.view(), &scratch);
  EXPECT_GT(want, 0u);
  SubBoxOptions<T> other = vote;
  other.grid = 8;  // not the vote's grid: its 64 cells would be read from 9
  EXPECT_EQ(subbox_mask(r, boxes, other, ConstMaskView{}, mask.view(), &scratch), want);
  EXPECT_EQ(mask.pixels, expected.pixels);
}

TYPED_TEST(StageInputsTest, SubBoxMaskOfAnInconsistentResultSetsNothing) {
  using T = TypeParam;
  std::vector<Vec2<T>> points;
  std::vector<FeatureLabel> labels;
  centre_cell_scene(&points, &labels);
  const std::vector<Box<T>> boxes{Box<T>{T(0), T(0), T(90), T(90)}};
  SubBoxResult<T> r = refine_subboxes(points, labels, boxes, SubBoxOptions<T>{});
  ASSERT_TRUE(r.ok()) << r.reason;
  r.cells.resize(2);  // not grid * grid per box
  Mask mask(100, 100, 7);
  std::vector<std::uint16_t> scratch;
  EXPECT_EQ(subbox_mask(r, boxes, SubBoxOptions<T>{}, ConstMaskView{}, mask.view(), &scratch), 0u);
  for (std::uint8_t m : mask.pixels) ASSERT_EQ(m, 0);
}

TYPED_TEST(StageInputsTest, SubBoxOptionsNameTheBadField) {
  using T = TypeParam;
  std::string why;
  SubBoxOptions<T> o;
  EXPECT_EQ(o.validate(&why), Status::Ok) << why;
  o.dilation_radius_px = INT_MAX;
  expect_names_field(o, "dilation_radius_px");
  o = SubBoxOptions<T>{};
  o.sigma1 = std::numeric_limits<T>::quiet_NaN();
  expect_names_field(o, "sigma1");
  std::vector<Vec2<T>> points(3, Vec2<T>(T(1), T(1)));
  std::vector<FeatureLabel> labels(3, FeatureLabel::Dynamic);
  const auto r = refine_subboxes(points, labels, std::vector<Box<T>>{}, o);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.reason.find("sigma1"), std::string::npos) << r.reason;
}

TYPED_TEST(StageInputsTest, SubBoxCellsOfAHugeFiniteBox) {
  using T = TypeParam;
  const T big = std::numeric_limits<T>::max() * T(0.9);
  const std::vector<Box<T>> boxes{Box<T>{-big, -big, big, big}};
  // The box spans more than the largest T: cells still split it evenly.
  const std::vector<Vec2<T>> points{Vec2<T>(-big, -big), Vec2<T>(T(0), T(0)), Vec2<T>(big, big),
                                    Vec2<T>(big * T(0.5), -big * T(0.5))};
  EXPECT_EQ(detail::subbox_cell(boxes[0], 3, points[0].x(), points[0].y()), 0);
  EXPECT_EQ(detail::subbox_cell(boxes[0], 3, points[1].x(), points[1].y()), 4);
  EXPECT_EQ(detail::subbox_cell(boxes[0], 3, points[2].x(), points[2].y()), 8);
  EXPECT_EQ(detail::subbox_cell(boxes[0], 3, points[3].x(), points[3].y()), 2);
  const std::vector<FeatureLabel> labels(points.size(), FeatureLabel::Dynamic);
  SubBoxOptions<T> o;
  o.min_points = 1;
  const SubBoxResult<T> r = refine_subboxes(points, labels, boxes, o);
  ASSERT_TRUE(r.ok()) << r.reason;
  Mask mask(64, 48);
  std::vector<std::uint16_t> scratch;
  const std::size_t set = subbox_mask(r, boxes, o, ConstMaskView{}, mask.view(), &scratch);
  EXPECT_EQ(set, 64u * 48u);  // the centre cell covers the whole image
}

TEST(DilateSquare, RadiusBeyondTheImageFillsTheRoiQuickly) {
  Mask mask(50, 40);
  mask.pixels[20 * 50 + 25] = 255;
  std::vector<std::uint16_t> scratch;
  dilate_square(mask.view(), PixelRect{0, 0, 50, 40}, INT_MAX, &scratch);
  for (std::uint8_t m : mask.pixels) ASSERT_EQ(m, 255);
  EXPECT_LT(scratch.size(), 50u * 41u + 1000u);
}

TYPED_TEST(StageInputsTest, SubBoxPropertyStatusOrDefinedLabels) {
  using T = TypeParam;
  Random rng(12);
  std::size_t checked = 0;  // trials whose outputs were checked (not rejected)
  for (int trial = 0; trial < 300; ++trial) {
    const std::size_t n = rng.index(80), nb = rng.index(5);
    std::vector<Vec2<T>> points(n);
    std::vector<FeatureLabel> geo(n);
    for (std::size_t i = 0; i < n; ++i) {
      points[i] = Vec2<T>(wild_or_tiny<T>(rng, -10, 110), wild_or_tiny<T>(rng, -10, 90));
      geo[i] = static_cast<FeatureLabel>(rng.index(3));
    }
    std::vector<Box<T>> boxes(nb);
    for (auto& b : boxes) b = wild_box<T>(rng, -20, 100, -20, 80, 60, 60);
    SubBoxOptions<T> o;
    o.grid = rng.index(4) == 0 ? maybe_wild_int(rng, 3) : 1 + static_cast<int>(rng.index(8));
    o.sigma1 = maybe_wild(rng, T(0.5));
    o.merge_ratio = maybe_wild(rng, T(0.35));
    o.sigma2 = maybe_wild_int(rng, 4);
    o.static_needs_evidence = rng.index(2) == 0;
    o.static_max_dynamic_ratio = maybe_wild(rng, T(0.3));
    o.dilation_radius_px = maybe_wild_int(rng, 3);
    std::vector<std::uint8_t> in_object(n);
    for (auto& f : in_object) f = static_cast<std::uint8_t>(rng.index(2));
    const SubBoxResult<T> r = refine_subboxes(points, geo, boxes, o, in_object);
    if (!r.ok()) {
      EXPECT_FALSE(r.reason.empty()) << trial;
      continue;
    }
    ++checked;
    ASSERT_EQ(r.labels.size(), n);
    for (std::size_t i = 0; i < n; ++i) {
      EXPECT_TRUE(r.labels[i] == FeatureLabel::Static || r.labels[i] == FeatureLabel::Dynamic) << trial;
      EXPECT_TRUE(defined(r.reasons[i])) << trial;
      if (!std::isfinite(points[i].x()) || !std::isfinite(points[i].y())) {
        EXPECT_EQ(r.labels[i], FeatureLabel::Dynamic);
      }
    }
    Mask mask(100, 80);
    std::vector<std::uint16_t> scratch;
    EXPECT_LE(subbox_mask(r, boxes, o, ConstMaskView{}, mask.view(), &scratch), 100u * 80u) << trial;
    std::vector<std::uint8_t> states(r.cells.size(), 2);
    SubBoxResult<T> applied;
    apply_subbox_states(points, geo, boxes, states, o, &applied);
    EXPECT_TRUE(applied.ok()) << applied.reason;
  }
  EXPECT_GT(checked, 30u) << "trials that reached the output checks";
}

// ---- depth mask ----

TEST(DepthMaskInputs, HugeFloatDepthInTheHistogramFallback) {
  // Float metres, default max_m 1e30: a finite 1e20 m depth is a valid measurement. The centre is far,
  // the corners near: the rule does not apply and the histogram fallback bins every pixel.
  const int w = 40, h = 30;
  std::vector<float> depth(static_cast<std::size_t>(w * h), 1e20f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if ((x + y) % 3 == 0) depth[static_cast<std::size_t>(y * w + x)] = 2.f;
  const DepthView<float> view{depth.data(), w, h, 0, 1.f, 0.f, 1e30f};
  const std::vector<Box<float>> boxes{Box<float>{0.f, 0.f, 39.f, 29.f}};
  const std::vector<Vec2<float>> points{Vec2<float>(3.f, 3.f), Vec2<float>(20.f, 15.f)};
  Mask mask(w, h);
  const DepthMaskResult r = depth_mask(view, boxes, points, DepthMaskOptions{}, mask.view());
  ASSERT_TRUE(r.ok()) << r.reason;
  ASSERT_EQ(r.boxes.size(), 1u);
  EXPECT_EQ(r.boxes[0].outcome, DepthMaskOutcome::HistogramFallback);
  EXPECT_TRUE(std::isfinite(r.boxes[0].threshold_m));
  // The near surface (2 m) is the box's object: its pixels are in the mask, the far ones are not.
  EXPECT_EQ(r.labels[0], FeatureLabel::Dynamic);
  EXPECT_EQ(r.labels[1], FeatureLabel::Static);
}

TEST(DepthMaskInputs, OptionsNameTheBadField) {
  std::string why;
  DepthMaskOptions o;
  EXPECT_EQ(o.validate(&why), Status::Ok) << why;
  o.max_object_depth_extent_m = 1e12;
  expect_names_field(o, "max_object_depth_extent_m");
  o = DepthMaskOptions{};
  o.eps_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(o.validate(&why), Status::InvalidInput);
  EXPECT_EQ(why, "eps_m must be finite and in [0, 1e4] m");
  const std::vector<std::uint16_t> raw(64, 5000);
  const auto view = tum_depth_view(raw.data(), 8, 8);
  const DepthMaskResult r =
      depth_mask(view, std::vector<Box<float>>{Box<float>{0.f, 0.f, 7.f, 7.f}}, std::vector<Vec2<float>>(3), o);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.reason.find("eps_m"), std::string::npos) << r.reason;
  EXPECT_EQ(r.labels.size(), 3u);
}

TEST(DepthMaskInputs, NegativeUnitsPerMetreIsInvalidInput) {
  std::vector<std::uint16_t> raw(64, 5000);
  raw[27] = 9000;
  DepthView<std::uint16_t> view = tum_depth_view(raw.data(), 8, 8);
  view.units_per_metre = -5000.f;
  const std::vector<Box<float>> boxes{Box<float>{0.f, 0.f, 7.f, 7.f}};
  const DepthMaskResult r = depth_mask(view, boxes, std::vector<Vec2<float>>{Vec2<float>(3.f, 3.f)}, DepthMaskOptions{});
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.reason.find("units_per_metre"), std::string::npos) << r.reason;
  const DepthMaskBoxInfo info = depth_mask_box(view, boxes[0], DepthMaskOptions{});
  EXPECT_EQ(info.status, Status::InvalidInput);
}

TEST(DepthMaskInputs, RangeWithoutARawValueIsInvalidInput) {
  // uint16 at 5000 units per metre reaches 13.1 m: a valid range from 20 m (or from 1e30 m) holds no raw value.
  const std::vector<std::uint16_t> raw(64, 60000);
  for (float min_m : {20.f, 1e30f}) {
    const auto view = tum_depth_view(raw.data(), 8, 8, min_m, 1e30f);
    const DepthMaskResult r = depth_mask(view, std::vector<Box<float>>{Box<float>{0.f, 0.f, 7.f, 7.f}},
                                         std::vector<Vec2<float>>{Vec2<float>(3.f, 3.f)}, DepthMaskOptions{});
    EXPECT_EQ(r.status, Status::InvalidInput) << min_m;
    EXPECT_NE(r.reason.find("min_m"), std::string::npos) << r.reason;
  }
}

template <class Raw>
void depth_mask_property(std::uint64_t seed) {
  Random rng(seed);
  std::size_t checked = 0;  // trials whose outputs were checked (not rejected)
  for (int trial = 0; trial < 300; ++trial) {
    const int w = 1 + static_cast<int>(rng.index(48)), h = 1 + static_cast<int>(rng.index(36));
    std::vector<Raw> depth(static_cast<std::size_t>(w * h));
    for (Raw& d : depth) {
      if constexpr (std::is_integral<Raw>::value)
        d = rng.index(4) == 0 ? Raw(0) : static_cast<Raw>(rng.index(65536));
      else
        d = wild_or_tiny<Raw>(rng, 0, 6);
    }
    DepthView<Raw> view{depth.data(), w, h, 0, std::is_integral<Raw>::value ? 5000.f : 1.f, 0.f, 1e30f};
    if (rng.index(6) == 0) view.units_per_metre = wild_or_tiny<float>(rng, -10, 10);
    if (rng.index(6) == 0) view.min_m = wild_or_tiny<float>(rng, 0, 2);
    if (rng.index(6) == 0) view.max_m = wild_or_tiny<float>(rng, 0, 10);
    const std::size_t nb = rng.index(4), n = rng.index(40);
    std::vector<Box<double>> boxes(nb);
    for (auto& b : boxes) b = wild_box<double>(rng, -10, w, -10, h, w, h);
    std::vector<Vec2<double>> points(n);
    for (auto& p : points) p = Vec2<double>(wild_or_tiny<double>(rng, 0, w), wild_or_tiny<double>(rng, 0, h));
    DepthMaskOptions o;
    o.mode = rng.index(2) ? DepthMaskMode::Robust : DepthMaskMode::Plain;
    o.missing_depth = static_cast<MissingDepth>(rng.index(3));
    o.occluded_centre_search = rng.index(2) == 0;
    o.eps_m = maybe_wild(rng, 0.3);
    o.max_object_depth_extent_m = maybe_wild(rng, 1.5);
    o.min_valid_fraction = maybe_wild(rng, 0.05);
    Mask mask(w, h);
    const DepthMaskResult r = depth_mask(view, boxes, points, o, mask.view());
    ASSERT_EQ(r.labels.size(), n);
    if (!r.ok()) {
      EXPECT_FALSE(r.reason.empty()) << trial;
      continue;
    }
    ++checked;
    for (std::size_t i = 0; i < n; ++i) {
      EXPECT_TRUE(defined(r.labels[i]) && defined(r.reasons[i])) << trial;
      if (!std::isfinite(points[i].x()) || !std::isfinite(points[i].y())) {
        EXPECT_EQ(r.labels[i], FeatureLabel::Dynamic);
      }
    }
    for (const DepthMaskBoxInfo& info : r.boxes) {
      if (!info.ok()) {
        EXPECT_FALSE(info.reason.empty()) << trial;
        continue;
      }
      EXPECT_TRUE(std::isfinite(info.d_max_m) && std::isfinite(info.d_c_m) && std::isfinite(info.threshold_m)) << trial;
      EXPECT_LE(info.num_mask_pixels, static_cast<std::size_t>(w * h)) << trial;
    }
  }
  EXPECT_GT(checked, 30u) << "trials that reached the output checks";
}

TEST(DepthMaskInputs, PropertyUint16StatusOrDefinedLabels) { depth_mask_property<std::uint16_t>(21); }
TEST(DepthMaskInputs, PropertyFloatStatusOrDefinedLabels) { depth_mask_property<float>(22); }
TEST(DepthMaskInputs, PropertyDoubleStatusOrDefinedLabels) { depth_mask_property<double>(23); }

// ---- moving consistency and reprojection ----

TYPED_TEST(StageInputsTest, MovingConsistencyBoundsRefitIterations) {
  using T = TypeParam;
  std::string why;
  MovingConsistencyOptions<T> o;
  EXPECT_EQ(o.validate(&why), Status::Ok) << why;
  o.refit_iterations = 1000000;
  expect_names_field(o, "refit_iterations");
  std::vector<Vec2<T>> a(40), b(40);
  Random rng(3);
  for (std::size_t i = 0; i < a.size(); ++i) {
    a[i] = Vec2<T>(T(rng.uniform(0, 640)), T(rng.uniform(0, 480)));
    b[i] = a[i] + Vec2<T>(T(2), T(0));
  }
  const auto r = check_moving_consistency(a, b, o);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.reason.find("refit_iterations"), std::string::npos) << r.reason;
}

TYPED_TEST(StageInputsTest, MovingConsistencyPropertyStatusOrDefinedLabels) {
  using T = TypeParam;
  Random rng(31);
  std::size_t checked = 0;  // trials whose outputs were checked (not rejected)
  for (int trial = 0; trial < 200; ++trial) {
    // Mostly a camera translation seen by tracks at random depths (F well determined), plus wild tracks.
    const std::size_t n = 8 + rng.index(60);
    std::vector<Vec2<T>> prev(n), cur(rng.index(12) == 0 ? rng.index(60) : n);
    for (auto& p : prev) p = Vec2<T>(T(rng.uniform(0, 640)), T(rng.uniform(0, 480)));
    for (std::size_t i = 0; i < cur.size(); ++i) {
      const T inv_depth = T(rng.uniform(0.2, 1));
      cur[i] = i < n ? prev[i] + Vec2<T>(T(4) * inv_depth, T(1) * inv_depth) : Vec2<T>(T(1), T(1));
      if (rng.index(8) == 0) cur[i] = Vec2<T>(wild_or_tiny<T>(rng, 0, 640), wild_or_tiny<T>(rng, 0, 480));
      if (i < n && rng.index(12) == 0) prev[i] = Vec2<T>(wild_or_tiny<T>(rng, 0, 640), wild_or_tiny<T>(rng, 0, 480));
    }
    MovingConsistencyOptions<T> o;
    o.max_ransac_iterations = 100;
    o.max_epipolar_distance_px = maybe_wild(rng, T(1));
    o.max_epipolar_distance_in_boxes_px = maybe_wild(rng, T(0.5));
    o.refit_iterations = rng.index(5) == 0 ? maybe_wild_int(rng, 2) : 2;
    o.min_tracks = rng.index(20);
    std::vector<std::uint8_t> valid(cur.size()), in_box(cur.size());
    for (std::size_t i = 0; i < cur.size(); ++i) {
      valid[i] = static_cast<std::uint8_t>(rng.index(8) != 0);
      in_box[i] = static_cast<std::uint8_t>(rng.index(3) == 0);
    }
    const auto r = check_moving_consistency(prev, cur, o, valid, in_box);
    ASSERT_EQ(r.labels.size(), cur.size());
    if (!r.ok()) {
      EXPECT_FALSE(r.reason.empty()) << trial;
      continue;
    }
    ++checked;
    for (std::size_t i = 0; i < cur.size(); ++i) {
      EXPECT_TRUE(defined(r.labels[i])) << trial;
      if (r.labels[i] != FeatureLabel::Candidate) {
        EXPECT_TRUE(std::isfinite(r.distance_px[i])) << trial;
      }
    }
  }
  EXPECT_GT(checked, 30u) << "trials that reached the output checks";
}

TYPED_TEST(StageInputsTest, ReprojectionPropertyStatusOrDefinedLabels) {
  using T = TypeParam;
  Random rng(32);
  const PinholeCamera<T> camera;
  std::size_t checked = 0;  // trials whose outputs were checked (not rejected)
  for (int trial = 0; trial < 200; ++trial) {
    const std::size_t n = rng.index(60);
    std::vector<Vec3<T>> points(n);
    std::vector<Vec2<T>> pixels(rng.index(12) == 0 ? rng.index(60) : n);
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3<T> X(T(rng.uniform(-2, 2)), T(rng.uniform(-1.5, 1.5)), T(rng.uniform(1, 5)));
      points[i] = rng.index(8) == 0 ? Vec3<T>(wild_or_tiny<T>(rng, -2, 2), wild_or_tiny<T>(rng, -2, 2), wild_or_tiny<T>(rng, -1, 5)) : X;
    }
    for (std::size_t i = 0; i < pixels.size(); ++i) {
      const bool exact = i < n && rng.index(3) != 0 && points[i].z() > T(0) && points[i].allFinite();
      pixels[i] = exact ? camera.project(points[i]) : Vec2<T>(wild_or_tiny<T>(rng, 0, 640), wild_or_tiny<T>(rng, 0, 480));
    }
    std::vector<float> depth(640 * 480, 0.f);
    for (int k = 0; k < 200; ++k) depth[rng.index(640 * 480)] = wild_or_tiny<float>(rng, 0, 5);
    DepthView<float> view{depth.data(), 640, 480, 0, 1.f, 0.f, 1e30f};
    if (rng.index(10) == 0) view.units_per_metre = wild_or_tiny<float>(rng, -1, 1);
    ReprojectionCheckOptions<T> o;
    o.max_ransac_iterations = 50;
    o.max_residual_px = maybe_wild(rng, T(3));
    o.max_residual_in_boxes_px = maybe_wild(rng, T(1.5));
    o.max_depth_residual_sigmas = rng.index(3) == 0 ? T(3) : maybe_wild(rng, T(0));
    o.min_tracks = rng.index(20);
    const auto r = check_reprojection(points, pixels, camera, o, nullptr, nullptr, view);
    ASSERT_EQ(r.labels.size(), pixels.size());
    if (!r.ok()) {
      EXPECT_FALSE(r.reason.empty()) << trial;
      continue;
    }
    ++checked;
    for (std::size_t i = 0; i < pixels.size(); ++i) EXPECT_TRUE(defined(r.labels[i])) << trial;
    EXPECT_TRUE(r.cam_from_world.all_finite()) << trial;
  }
  EXPECT_GT(checked, 30u) << "trials that reached the output checks";
}

TYPED_TEST(StageInputsTest, ReprojectionOptionsNameTheBadField) {
  using T = TypeParam;
  std::string why;
  ReprojectionCheckOptions<T> o;
  EXPECT_EQ(o.validate(&why), Status::Ok) << why;
  o.max_ransac_iterations = 0;
  expect_names_field(o, "max_ransac_iterations");
}

// ---- coherent motion, dynamic probability, static history, sub-box memory ----

TYPED_TEST(StageInputsTest, CoherentMotionPropertyStatusOrDefinedLabels) {
  using T = TypeParam;
  Random rng(41);
  std::size_t checked = 0;  // trials whose outputs were checked (not rejected)
  for (int trial = 0; trial < 300; ++trial) {
    const std::size_t n = rng.index(80), nb = rng.index(4);
    std::vector<Vec2<T>> points(n), residuals(n);
    std::vector<FeatureLabel> labels(n);
    for (std::size_t i = 0; i < n; ++i) {
      points[i] = Vec2<T>(wild_or_tiny<T>(rng, 0, 100), wild_or_tiny<T>(rng, 0, 100));
      residuals[i] = Vec2<T>(wild_or_tiny<T>(rng, -3, 3), wild_or_tiny<T>(rng, -3, 3));
      labels[i] = static_cast<FeatureLabel>(rng.index(3));
    }
    std::vector<Box<T>> boxes(nb);
    for (auto& b : boxes) b = wild_box<T>(rng, -10, 90, -10, 90, 80, 80);
    CoherentMotionOptions<T> o;
    const int grid = rng.index(4) == 0 ? maybe_wild_int(rng, 3) : 1 + static_cast<int>(rng.index(8));
    o.min_points = rng.index(6);
    o.sigmas = maybe_wild(rng, T(10));
    o.min_median_px = maybe_wild(rng, T(0.5));
    CoherentMotionResult<T> r;
    flag_coherent_cells(points, residuals, boxes, grid, wild_or_tiny<T>(rng, 0, 2), o, labels.data(), &r);
    if (r.status != Status::Ok && r.status != Status::Skipped) {
      EXPECT_FALSE(r.reason.empty()) << trial;
      continue;
    }
    ++checked;
    for (FeatureLabel l : labels) EXPECT_TRUE(defined(l)) << trial;
    EXPECT_TRUE(std::isfinite(r.noise_px)) << trial;
  }
  EXPECT_GT(checked, 30u) << "trials that reached the output checks";
}

TYPED_TEST(StageInputsTest, DynamicProbabilityPropertyStatusOrFiniteOutputs) {
  using T = TypeParam;
  Random rng(42);
  std::size_t checked = 0;  // trials whose outputs were checked (not rejected)
  for (int trial = 0; trial < 300; ++trial) {
    const std::size_t n = rng.index(60);
    std::vector<Vec2<T>> prev(n), cur(n);
    std::vector<MotionLevel> levels(rng.index(12) == 0 ? rng.index(60) : n);
    for (std::size_t i = 0; i < n; ++i) {
      prev[i] = Vec2<T>(wild_or_tiny<T>(rng, 0, 640), wild_or_tiny<T>(rng, 0, 480));
      cur[i] = Vec2<T>(wild_or_tiny<T>(rng, 0, 640), wild_or_tiny<T>(rng, 0, 480));
    }
    for (auto& l : levels) l = static_cast<MotionLevel>(rng.index(4));
    DynamicProbabilityOptions<T> o;
    o.weight_semantic = maybe_wild(rng, T(0.4));
    o.threshold = maybe_wild(rng, T(0.55));
    EgoMotion<T> ego;
    ego.model = static_cast<FlowModel>(rng.index(3));
    if (ego.model != FlowModel::MeanFlow)
      for (int k = 0; k < 9; ++k) ego.matrix(k / 3, k % 3) = rng.index(20) == 0 ? wild_or_tiny<T>(rng, -1, 1) : T(rng.uniform(-1, 1));
    const auto r = dynamic_probability(prev, cur, levels, o, ego);
    ASSERT_EQ(r.labels.size(), n);
    if (!r.ok()) {
      EXPECT_FALSE(r.reason.empty()) << trial;
      continue;
    }
    ++checked;
    for (std::size_t i = 0; i < n; ++i) {
      EXPECT_TRUE(defined(r.labels[i]) && defined(r.reasons[i])) << trial;
      EXPECT_TRUE(std::isfinite(r.probability[i])) << trial;
    }
    EXPECT_TRUE(std::isfinite(r.motion_threshold_px)) << trial;
  }
  EXPECT_GT(checked, 30u) << "trials that reached the output checks";
}

TYPED_TEST(StageInputsTest, StaticHistoryOptionsNameTheBadField) {
  using T = TypeParam;
  std::string why;
  StaticHistoryOptions<T> o;
  EXPECT_EQ(o.validate(&why), Status::Ok) << why;
  o.min_frames = 70000;
  expect_names_field(o, "min_frames");
  o = StaticHistoryOptions<T>{};
  o.max_residual_px = std::numeric_limits<T>::quiet_NaN();
  expect_names_field(o, "max_residual_px");
}

TEST(SubBoxMemoryInputs, GridOutsideItsRangeRecallsNothing) {
  SubBoxMemory memory;
  std::vector<std::uint8_t> cells(5, 1);
  const std::vector<std::int64_t> ids{1, 2};
  for (int grid : {-3, 0, 9, INT_MAX}) {
    cells.assign(5, 1);
    EXPECT_EQ(memory.recall_states(ids, grid, 10, 5, &cells), 0u) << grid;
    EXPECT_TRUE(cells.empty()) << grid;
  }
}

}  // namespace
}  // namespace dyncull
