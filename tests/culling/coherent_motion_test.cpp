// Tests of the cell-level coherent-motion evidence: a shared sub-threshold residual flags its sub-box.
#include "dyncull/culling/coherent_motion.hpp"

#include "dyncull/core/random.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace dyncull {
namespace {

template <class T>
class CoherentMotionTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(CoherentMotionTest, Scalars, );  // trailing comma: clang -Wpedantic rejects an empty variadic

/// One 210 x 300 px box at (100, 60), `per_cell` features in each of its 3 x 3 cells, residuals of
/// Gaussian noise `noise_px` per component plus `shift` in the cells of the top row.
template <class T>
struct CellScene {
  std::vector<Box<T>> boxes;
  std::vector<Vec2<T>> points, residuals;
  std::vector<int> cell;
  std::vector<FeatureLabel> labels;
};

template <class T>
CellScene<T> make_cell_scene(int per_cell, double noise_px, const Vec2<double>& shift, std::uint64_t seed = 5) {
  CellScene<T> s;
  s.boxes.push_back(Box<T>{T(100), T(60), T(310), T(360)});
  Random rng(seed);
  for (int c = 0; c < 9; ++c) {
    const int row = c / 3, col = c % 3;
    for (int k = 0; k < per_cell; ++k) {
      s.points.emplace_back(T(100 + 70 * col + rng.uniform(1.0, 69.0)), T(60 + 100 * row + rng.uniform(1.0, 99.0)));
      const Vec2<double> e = (row == 0 ? shift : Vec2<double>::Zero()) +
                             Vec2<double>(noise_px * rng.normal(), noise_px * rng.normal());
      s.residuals.push_back(e.cast<T>());
      s.cell.push_back(c);
      // What a per-feature threshold of 1.5 px (the in-box reprojection threshold) says.
      s.labels.push_back(e.norm() > 1.5 ? FeatureLabel::Dynamic : FeatureLabel::Static);
    }
  }
  return s;
}

// A seated person's upper body sways 0.8 px between the frames, below the 1.5 px per-feature threshold:
// only the noise tail is flagged there. The shared median flags the three top cells and only them.
TYPED_TEST(CoherentMotionTest, SharedSubThresholdMotionFlagsItsCellsOnly) {
  using T = TypeParam;
  auto s = make_cell_scene<T>(20, 0.25, Vec2<double>(0.7, 0.4));
  std::size_t top_flagged_before = 0;
  for (std::size_t i = 0; i < s.points.size(); ++i)
    top_flagged_before += s.cell[i] < 3 && s.labels[i] == FeatureLabel::Dynamic;
  EXPECT_LT(top_flagged_before, 10u);  // of 60: the per-feature test misses the motion

  const auto before = s.labels;
  CoherentMotionResult<T> r;
  flag_coherent_cells(s.points, s.residuals, s.boxes, 3, T(0.25), CoherentMotionOptions<T>{}, s.labels.data(), &r);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.num_cells_tested, 9u);
  EXPECT_EQ(r.num_cells_flagged, 3u);
  for (int c = 0; c < 9; ++c) EXPECT_EQ(r.cells[static_cast<std::size_t>(c)], c < 3 ? 1 : 0) << "cell " << c;
  std::size_t turned = 0;
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    if (s.cell[i] < 3) {
      EXPECT_EQ(s.labels[i], FeatureLabel::Dynamic) << i;
    } else {
      EXPECT_EQ(s.labels[i], before[i]) << i;  // untouched
    }
    turned += before[i] == FeatureLabel::Static && s.labels[i] == FeatureLabel::Dynamic;
  }
  EXPECT_EQ(r.num_flagged, turned);
  EXPECT_NEAR(double(r.noise_px), 0.25, 1e-6);
}

// The limits: a shared offset below min_median_px is never motion, however many features carry it; a
// large spread hides a small shift (the standard error grows with the noise); a cell with fewer than
// min_points features is not tested; the noise has a floor.
TYPED_TEST(CoherentMotionTest, SmallOffsetsNoiseAndSparseCellsAreNotMotion) {
  using T = TypeParam;
  const CoherentMotionOptions<T> o;
  {
    auto s = make_cell_scene<T>(200, 0.2, Vec2<double>(0.4, 0.0));  // 0.4 px < min_median_px 0.5
    CoherentMotionResult<T> r;
    flag_coherent_cells(s.points, s.residuals, s.boxes, 3, T(0.2), o, s.labels.data(), &r);
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(r.num_cells_flagged, 0u);
    auto lower = o;
    lower.min_median_px = T(0.3);
    flag_coherent_cells(s.points, s.residuals, s.boxes, 3, T(0.2), lower, s.labels.data(), &r);
    EXPECT_EQ(r.num_cells_flagged, 3u);
  }
  {
    // 1 px shared shift under 1.5 px noise with 9 features a cell: standard error 0.63 px, z about 1.6.
    auto s = make_cell_scene<T>(9, 1.5, Vec2<double>(1.0, 0.0));
    CoherentMotionResult<T> r;
    flag_coherent_cells(s.points, s.residuals, s.boxes, 3, T(1.5), o, s.labels.data(), &r);
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(r.num_cells_flagged, 0u);
  }
  {
    auto s = make_cell_scene<T>(3, 0.1, Vec2<double>(3.0, 0.0));  // 3 features a cell, min_points 4
    CoherentMotionResult<T> r;
    flag_coherent_cells(s.points, s.residuals, s.boxes, 3, T(0.1), o, s.labels.data(), &r);
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(r.num_cells_tested, 0u);
    EXPECT_EQ(r.num_cells_flagged, 0u);
  }
  {
    // A noise estimate of 0 (or NaN: no fit) falls back to the floor kMinNoisePx.
    auto s = make_cell_scene<T>(20, 0.25, Vec2<double>(0.7, 0.4));
    CoherentMotionResult<T> r;
    flag_coherent_cells(s.points, s.residuals, s.boxes, 3, T(0), o, s.labels.data(), &r);
    EXPECT_NEAR(double(r.noise_px), double(T(CoherentMotionOptions<T>::kMinNoisePx)), 1e-6);
    flag_coherent_cells(s.points, s.residuals, s.boxes, 3, std::numeric_limits<T>::quiet_NaN(), o, s.labels.data(), &r);
    EXPECT_NEAR(double(r.noise_px), double(T(CoherentMotionOptions<T>::kMinNoisePx)), 1e-6);
  }
}

// Only the box's object takes part (the depth mask's bits, as the sub-box vote), only eligible features,
// and Candidate (no evidence) and Dynamic labels are left as they are.
TYPED_TEST(CoherentMotionTest, OnlyTheObjectsEligibleStaticFeaturesChange) {
  using T = TypeParam;
  auto s = make_cell_scene<T>(20, 0.25, Vec2<double>(0.7, 0.4));
  const std::size_t n = s.points.size();
  std::vector<std::uint32_t> bits(n, 1u);
  std::vector<std::uint8_t> eligible(n, 1);
  for (std::size_t i = 0; i < n; ++i) {
    if (s.cell[i] == 0) bits[i] = 0;       // cell 0: the wall behind the person, not its object
    if (s.cell[i] == 1) eligible[i] = 0;   // cell 1: e.g. features a chair's box holds (candidates)
  }
  s.labels[40] = FeatureLabel::Candidate;  // cell 2
  CoherentMotionResult<T> r;
  flag_coherent_cells(s.points, s.residuals, s.boxes, 3, T(0.25), CoherentMotionOptions<T>{}, s.labels.data(), &r,
                      nullptr, bits, eligible);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.num_cells_tested, 7u);
  EXPECT_EQ(r.num_cells_flagged, 1u);
  EXPECT_EQ(r.cells[2], 1);
  for (std::size_t i = 0; i < n; ++i) {
    if (s.cell[i] == 0 || s.cell[i] == 1) {
      EXPECT_NE(s.labels[i], FeatureLabel::Dynamic) << i;
    }
  }
  EXPECT_EQ(s.labels[40], FeatureLabel::Candidate);
}

TYPED_TEST(CoherentMotionTest, BadInputGetsAReason) {
  using T = TypeParam;
  auto s = make_cell_scene<T>(20, 0.25, Vec2<double>(0.7, 0.4));
  const auto before = s.labels;
  CoherentMotionResult<T> r;
  CoherentMotionOptions<T> bad;
  bad.sigmas = T(0);
  flag_coherent_cells(s.points, s.residuals, s.boxes, 3, T(0.25), bad, s.labels.data(), &r);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_FALSE(r.reason.empty());
  bad = CoherentMotionOptions<T>{};
  bad.min_median_px = std::numeric_limits<T>::quiet_NaN();
  flag_coherent_cells(s.points, s.residuals, s.boxes, 3, T(0.25), bad, s.labels.data(), &r);
  EXPECT_EQ(r.status, Status::InvalidInput);
  flag_coherent_cells(s.points, s.residuals, s.boxes, 9, T(0.25), CoherentMotionOptions<T>{}, s.labels.data(), &r);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_EQ(s.labels, before);

  const CoherentMotionOptions<T> o;
  flag_coherent_cells(s.points, s.residuals, std::vector<Box<T>>{}, 3, T(0.25), o, s.labels.data(), &r);
  EXPECT_EQ(r.status, Status::Skipped);
  EXPECT_FALSE(r.reason.empty());
  flag_coherent_cells(s.points, nullptr, s.boxes, 3, T(0.25), o, s.labels.data(), &r);
  EXPECT_EQ(r.status, Status::InvalidInput);

  // Non-finite residuals (no 3-D point) take no part, an invalid box is passed over, a NaN point lies in
  // no cell: the remaining cells are still decided.
  const T nan = std::numeric_limits<T>::quiet_NaN();
  for (std::size_t i = 0; i < s.points.size(); ++i)
    if (s.cell[i] == 0) s.residuals[i] = Vec2<T>(nan, nan);
  s.points[25] = Vec2<T>(nan, nan);
  std::vector<Box<T>> boxes = s.boxes;
  boxes.push_back(Box<T>{T(50), T(50), T(10), T(10)});  // x1 < x0
  flag_coherent_cells(s.points, s.residuals, boxes, 3, T(0.25), o, s.labels.data(), &r);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.num_cells_tested, 8u);
  EXPECT_EQ(r.num_cells_flagged, 2u);
  EXPECT_EQ(r.cells.size(), 18u);
  for (int i = 0; i < 20; ++i) EXPECT_EQ(s.labels[static_cast<std::size_t>(i)], before[static_cast<std::size_t>(i)]);
}

TEST(CoherentMotion, BuffersAreReusedAcrossFrames) {
  auto s = make_cell_scene<double>(20, 0.25, Vec2<double>(0.7, 0.4));
  CoherentMotionResult<double> r;
  flag_coherent_cells(s.points, s.residuals, s.boxes, 3, 0.25, CoherentMotionOptions<double>{}, s.labels.data(), &r);
  ASSERT_TRUE(r.ok());
  const auto* order = r.scratch_order.data();
  const auto* u = r.scratch_u.data();
  flag_coherent_cells(s.points, s.residuals, s.boxes, 3, 0.25, CoherentMotionOptions<double>{}, s.labels.data(), &r);
  EXPECT_EQ(r.scratch_order.data(), order);
  EXPECT_EQ(r.scratch_u.data(), u);
  EXPECT_EQ(r.num_cells_flagged, 3u);
}

// Per-feature views shorter than the points: InvalidInput naming the view and both sizes, no label changed,
// nothing read past the end (AddressSanitizer).
TYPED_TEST(CoherentMotionTest, ViewsOfAnotherLengthAreInvalidInputAndNotRead) {
  using T = TypeParam;
  auto s = make_cell_scene<T>(20, 0.25, Vec2<double>(0.7, 0.4));
  const std::size_t n = s.points.size();
  const auto before = s.labels;
  const CoherentMotionOptions<T> o;
  const std::vector<std::uint8_t> few(10, 1), all(n, 1);
  const std::vector<std::uint32_t> few_bits(10, 1u), bits(n, 1u);
  const std::string tail = " has 10 entries for " + std::to_string(n) + " points";
  CoherentMotionResult<T> r;
  flag_coherent_cells(s.points, s.residuals, s.boxes, 3, T(0.25), o, s.labels.data(), &r, few);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_EQ(r.reason, "in_object_mask" + tail);
  flag_coherent_cells(s.points, s.residuals, s.boxes, 3, T(0.25), o, s.labels.data(), &r, all, few_bits);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_EQ(r.reason, "object_box_bits" + tail);
  flag_coherent_cells(s.points, s.residuals, s.boxes, 3, T(0.25), o, s.labels.data(), &r, all, bits, few);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_EQ(r.reason, "eligible" + tail);
  EXPECT_EQ(s.labels, before);
  flag_coherent_cells(s.points, s.residuals, s.boxes, 3, T(0.25), o, s.labels.data(), &r, all, bits, all);
  EXPECT_TRUE(r.ok()) << r.reason;
}

// Residuals are required, one per point: a short array is named with both sizes before any is read.
TYPED_TEST(CoherentMotionTest, ShortOrMissingResidualsAreInvalidInputAndNotRead) {
  using T = TypeParam;
  auto s = make_cell_scene<T>(20, 0.25, Vec2<double>(0.7, 0.4));
  const std::size_t n = s.points.size();
  const auto before = s.labels;
  const std::vector<Vec2<T>> short_residuals(s.residuals.begin(), s.residuals.begin() + 10);
  CoherentMotionResult<T> r;
  flag_coherent_cells(s.points, short_residuals, s.boxes, 3, T(0.25), CoherentMotionOptions<T>{}, s.labels.data(), &r);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_EQ(r.reason, "residuals has 10 entries for " + std::to_string(n) + " points");
  EXPECT_EQ(r.num_flagged, 0u);
  EXPECT_EQ(s.labels, before);
  flag_coherent_cells(s.points, nullptr, s.boxes, 3, T(0.25), CoherentMotionOptions<T>{}, s.labels.data(), &r);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_EQ(r.reason, "residuals is required (" + std::to_string(n) + " points)");
  EXPECT_EQ(s.labels, before);
}

}  // namespace
}  // namespace dyncull
