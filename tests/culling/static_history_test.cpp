// Static history: what counts as a still frame, what restarts the count, what leaves it alone, and which
// tracks are forgotten.
#include "dyncull/culling/static_history.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <vector>

namespace dyncull {
namespace {

template <class T>
class StaticHistoryTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(StaticHistoryTest, Scalars, );  // trailing comma: clang -Wpedantic rejects an empty variadic

constexpr FeatureLabel S = FeatureLabel::Static, D = FeatureLabel::Dynamic, C = FeatureLabel::Candidate;

TYPED_TEST(StaticHistoryTest, CountsStillFramesAndRestartsOnAFlagOrALargeResidual) {
  using T = TypeParam;
  StaticHistory history;
  const std::vector<std::int64_t> ids = {10, 20, 30, 40};
  std::vector<std::uint16_t> counts;
  // Track 10 still; 20 still but at the residual limit (not below it); 30 flagged; 40 without evidence.
  const std::vector<FeatureLabel> labels = {S, S, D, C};
  const std::vector<T> residuals = {T(0.2), T(0.8), T(0.1), T(0.1)};
  for (int f = 1; f <= 3; ++f) {
    history.update(ids, labels, residuals, true, T(0.8), &counts);
    EXPECT_EQ(counts, (std::vector<std::uint16_t>{static_cast<std::uint16_t>(f), 0, 0, 0})) << "frame " << f;
  }
  EXPECT_EQ(history.count(10), 3);
  EXPECT_EQ(history.num_tracks(), 4u);

  // Frames that are no evidence (too short a baseline, or no labels) carry the counts over.
  history.update(ids, labels, residuals, false, T(0.8), &counts);
  EXPECT_EQ(counts[0], 3);
  history.update<T>(ids, nullptr, nullptr, true, T(0.8), &counts);
  EXPECT_EQ(counts[0], 3);

  // A Candidate label (no point this frame) leaves the count; a flag, or a residual above the limit, restarts it.
  const std::vector<T> small(4, T(0.1));
  history.update(ids, std::vector<FeatureLabel>{C, S, S, S}, small, true, T(0.8), &counts);
  EXPECT_EQ(counts, (std::vector<std::uint16_t>{3, 1, 1, 1}));
  history.update(ids, std::vector<FeatureLabel>{D, S, S, S}, small, true, T(0.8), &counts);
  EXPECT_EQ(counts, (std::vector<std::uint16_t>{0, 2, 2, 2}));
  history.update(ids, std::vector<FeatureLabel>{S, S, S, S}, std::vector<T>{T(0.1), T(0.9), T(0.1), T(0.1)},
                 true, T(0.8), &counts);
  EXPECT_EQ(counts, (std::vector<std::uint16_t>{1, 0, 3, 3}));
  // A non-finite residual is no proof of stillness.
  history.update(ids, std::vector<FeatureLabel>{S, S, S, S},
                 std::vector<T>{std::numeric_limits<T>::quiet_NaN(), T(0.1), std::numeric_limits<T>::infinity(), T(0.1)},
                 true, T(0.8), &counts);
  EXPECT_EQ(counts, (std::vector<std::uint16_t>{0, 1, 0, 4}));
}

TYPED_TEST(StaticHistoryTest, TracksMissingFromAFrameAreForgottenAndOrderDoesNotMatter) {
  using T = TypeParam;
  StaticHistory history;
  std::vector<std::uint16_t> counts;
  const std::vector<T> small(3, T(0.1));
  const std::vector<FeatureLabel> still(3, S);
  history.update(std::vector<std::int64_t>{5, 3, 9}, still, small, true, T(0.8), &counts);
  history.update(std::vector<std::int64_t>{9, 5, 3}, still, small, true, T(0.8), &counts);
  EXPECT_EQ(counts, (std::vector<std::uint16_t>{2, 2, 2})) << "ids are matched, not positions";
  // Track 3 is lost; 11 is new.
  history.update(std::vector<std::int64_t>{11, 9, 5}, still, small, true, T(0.8), &counts);
  EXPECT_EQ(counts, (std::vector<std::uint16_t>{1, 3, 3}));
  EXPECT_EQ(history.count(3), 0) << "forgotten";
  EXPECT_EQ(history.num_tracks(), 3u);
  // An id given twice in one frame gets a defined count (each from the same history).
  history.update(std::vector<std::int64_t>{9, 9, 5}, still, small, true, T(0.8), &counts);
  EXPECT_EQ(counts, (std::vector<std::uint16_t>{4, 4, 4}));
  EXPECT_EQ(history.count(9), 4);
  // No tracks: everything forgotten.
  history.update<T>({}, nullptr, nullptr, true, T(0.8), &counts);
  EXPECT_TRUE(counts.empty());
  EXPECT_EQ(history.num_tracks(), 0u);
  history.update(std::vector<std::int64_t>{9}, std::vector<FeatureLabel>{S}, std::vector<T>{T(0.1)}, true, T(0.8),
                 &counts);
  EXPECT_EQ(counts[0], 1);
  history.clear();
  EXPECT_EQ(history.num_tracks(), 0u);
  EXPECT_EQ(history.count(9), 0);
}

// The counts do not depend on the order the tracks come in (creation order, or a keyframe's order).
TYPED_TEST(StaticHistoryTest, AscendingAndShuffledIdsGiveTheSameCounts) {
  using T = TypeParam;
  const std::vector<std::vector<std::int64_t>> frames = {{1, 2, 4, 7}, {1, 4, 7, 8}, {4, 4, 8, 9}, {2, 8, 9, 12}};
  const std::vector<std::vector<FeatureLabel>> labels = {{S, S, D, S}, {S, S, C, S}, {S, S, S, D}, {S, S, S, S}};
  const std::vector<T> residuals = {T(0.1), T(0.2), T(0.3), T(0.4)};
  StaticHistory ascending, reversed;
  std::vector<std::uint16_t> a, r;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    ascending.update(frames[f], labels[f], residuals, true, T(0.8), &a);
    const std::vector<std::int64_t> rev_ids(frames[f].rbegin(), frames[f].rend());
    const std::vector<FeatureLabel> rev_labels(labels[f].rbegin(), labels[f].rend());
    const std::vector<T> rev_res(residuals.rbegin(), residuals.rend());
    reversed.update(rev_ids, rev_labels, rev_res, true, T(0.8), &r);
    for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i], r[a.size() - 1 - i]) << "frame " << f << " track " << i;
  }
  // Last frame ({2, 8, 9, 12}): 2 is new again (lost in the second), 8 still in all three frames it was in,
  // 9 flagged in the third and still in this one, 12 new.
  EXPECT_EQ(a, (std::vector<std::uint16_t>{1, 3, 1, 1}));
}

// Labels or residuals of another length than the ids: InvalidInput naming them and both sizes, the counts
// and the history unchanged, nothing read past the end (AddressSanitizer).
TYPED_TEST(StaticHistoryTest, ViewsOfAnotherLengthAreInvalidInputAndNotRead) {
  using T = TypeParam;
  StaticHistory history;
  const std::vector<std::int64_t> ids{1, 2, 3, 4};
  const std::vector<FeatureLabel> still(4, FeatureLabel::Static), few_labels(1, FeatureLabel::Static);
  const std::vector<T> small(4, T(0.1)), few_residuals(1, T(0.1));
  std::vector<std::uint16_t> counts;
  ASSERT_EQ(history.update(ids, still, small, true, T(0.8), &counts), Status::Ok);
  std::string why;
  EXPECT_EQ(history.update(ids, few_labels, small, true, T(0.8), &counts, &why), Status::InvalidInput);
  EXPECT_EQ(why, "labels has 1 entries for 4 track ids");
  EXPECT_EQ(history.update(ids, still, few_residuals, true, T(0.8), &counts, &why), Status::InvalidInput);
  EXPECT_EQ(why, "residual_px has 1 entries for 4 track ids");
  EXPECT_EQ(counts, (std::vector<std::uint16_t>{1, 1, 1, 1}));
  EXPECT_EQ(history.count(4), 1);
  // Not given: no evidence this frame, the counts carry over.
  EXPECT_EQ(history.update(ids, nullptr, nullptr, true, T(0.8), &counts, &why), Status::Ok);
  EXPECT_EQ(counts, (std::vector<std::uint16_t>{1, 1, 1, 1}));
}

// Against a plain map over many frames of random ids: track counts from 0 to a few thousand (the tables grow
// and are reused), negative ids, ids given twice, frames without evidence, and counts read back by id.
TYPED_TEST(StaticHistoryTest, CountsMatchAMapOverManyFramesOfRandomIds) {
  using T = TypeParam;
  std::mt19937 rng(7);
  auto uniform = [&rng](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  StaticHistory history;
  std::map<std::int64_t, std::uint16_t> reference;
  std::vector<std::uint16_t> counts;
  for (int frame = 0; frame < 300; ++frame) {
    const int n = frame % 50 == 49 ? 0 : uniform(0, frame < 150 ? 3000 : 40);
    std::vector<std::int64_t> ids(static_cast<std::size_t>(n));
    std::vector<FeatureLabel> labels(ids.size());
    std::vector<T> residuals(ids.size());
    for (std::size_t i = 0; i < ids.size(); ++i) {
      ids[i] = uniform(-100, 4000);
      const int l = uniform(0, 9);
      labels[i] = l == 0 ? D : l == 1 ? C : S;
      residuals[i] = static_cast<T>(uniform(0, 16)) / T(10);
    }
    const bool evaluated = frame % 7 != 3;
    ASSERT_EQ(history.update(ids, labels, residuals, evaluated, T(0.8), &counts), Status::Ok);
    std::map<std::int64_t, std::uint16_t> next;
    for (std::size_t i = 0; i < ids.size(); ++i) {
      const auto it = reference.find(ids[i]);
      int count = it == reference.end() ? 0 : it->second;
      if (evaluated && labels[i] != C) count = labels[i] == S && residuals[i] < T(0.8) ? count + 1 : 0;
      next.emplace(ids[i], static_cast<std::uint16_t>(count));  // an id given twice keeps its first count
      ASSERT_EQ(counts[i], count) << "frame " << frame << " track " << i << " id " << ids[i];
    }
    reference.swap(next);
    ASSERT_EQ(history.num_tracks(), ids.size());
    for (std::int64_t id = -100; id <= 4000; id += 37) {
      const auto it = reference.find(id);
      ASSERT_EQ(history.count(id), it == reference.end() ? 0 : it->second) << "frame " << frame << " id " << id;
    }
  }
}

}  // namespace
}  // namespace dyncull
