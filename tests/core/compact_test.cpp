// Tests of core/compact.hpp: every parallel array of a host (vectors of anything, strided descriptor
// rows) compacted together and stably by one keep mask; a size mismatch, an unusable row view or two
// arguments sharing memory touch nothing and return -1.
#include "dyncull/core/compact.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace {
using dyncull::compact;
using dyncull::RowsView;

const std::vector<std::uint8_t> kKeep = {1, 0, 1, 1, 0};

struct Key {  // an ORB-SLAM-like keypoint
  float x, y;
  int octave;
};

TEST(Compact, EveryParallelArrayTogetherInOrder) {
  std::vector<Key> keys;
  std::vector<float> depth, right_u;
  std::vector<std::string> names;
  // Descriptor rows of 4 used bytes in a buffer with an 8-byte stride (like a cv::Mat ROI).
  std::vector<std::uint8_t> desc(5 * 8, 0xEE);
  for (int i = 0; i < 5; ++i) {
    keys.push_back({float(i), float(10 * i), i % 3});
    depth.push_back(1.f + float(i));
    right_u.push_back(-1.f * float(i));
    names.push_back("kp" + std::to_string(i));
    for (int b = 0; b < 4; ++b) desc[std::size_t(i * 8 + b)] = std::uint8_t(i * 16 + b);
  }
  RowsView rows(desc.data(), 4, 8, 5);
  ASSERT_EQ(compact(kKeep, keys, rows, depth, right_u, names), 3);
  const int kept[] = {0, 2, 3};
  ASSERT_EQ(keys.size(), 3u);
  ASSERT_EQ(names.size(), 3u);
  EXPECT_EQ(rows.rows, 3u);
  for (int j = 0; j < 3; ++j) {
    const int i = kept[j];
    EXPECT_EQ(keys[std::size_t(j)].x, float(i));
    EXPECT_EQ(depth[std::size_t(j)], 1.f + float(i));
    EXPECT_EQ(right_u[std::size_t(j)], -1.f * float(i));
    EXPECT_EQ(names[std::size_t(j)], "kp" + std::to_string(i));
    for (int b = 0; b < 4; ++b) EXPECT_EQ(desc[std::size_t(j * 8 + b)], std::uint8_t(i * 16 + b));
    EXPECT_EQ(desc[std::size_t(j * 8 + 5)], 0xEE);  // padding bytes untouched
  }
}

TEST(Compact, MismatchedSizesTouchNothing) {
  std::vector<int> a = {1, 2, 3, 4, 5};
  std::vector<int> b = {1, 2, 3};  // an array left unshrunk, like ORB-SLAM3's N in forks
  EXPECT_EQ(compact(kKeep, a, b), -1);
  EXPECT_EQ(a.size(), 5u);
  EXPECT_EQ(b.size(), 3u);
  EXPECT_EQ(compact(kKeep), 3);  // no arrays at all: the count
  std::vector<int> c = {1, 2};   // an all-dynamic frame
  EXPECT_EQ(compact(std::vector<std::uint8_t>{0, 0}, c), 0);
  EXPECT_TRUE(c.empty());
}

TEST(Compact, UnusableRowViewsAndSharedMemoryAreRefusedAndTouchNothing) {
  std::vector<int> ids = {0, 1, 2, 3, 4};
  EXPECT_EQ(compact(kKeep, ids, RowsView(nullptr, 32, 32, 5)), -1);  // rows without data
  std::vector<std::uint8_t> desc(5 * 8, 7);
  EXPECT_EQ(compact(kKeep, ids, RowsView(desc.data(), 16, 8, 5)), -1);  // rows longer than the stride
  EXPECT_EQ(compact(kKeep, RowsView(desc.data(), 8, std::numeric_limits<std::size_t>::max() / 2, 5)), -1);
  // Two views of the same rows, and the same vector twice: the second pass would read moved slots.
  EXPECT_EQ(compact(kKeep, RowsView(desc.data(), 8, 8, 5), RowsView(desc.data() + 4, 4, 8, 5)), -1);
  EXPECT_EQ(compact(kKeep, ids, ids), -1);
  std::vector<std::uint8_t> two(5 * 16, 1);  // interleaved rows share one span of memory
  EXPECT_EQ(compact(kKeep, RowsView(two.data(), 8, 16, 5), RowsView(two.data() + 8, 8, 16, 5)), -1);
  EXPECT_EQ(ids, (std::vector<int>{0, 1, 2, 3, 4}));
  EXPECT_EQ(desc, std::vector<std::uint8_t>(5 * 8, 7));
  // Null data is fine with no rows; separate buffers side by side are fine.
  EXPECT_EQ(compact(std::vector<std::uint8_t>{}, RowsView(nullptr, 32, 32, 0)), 0);
  std::vector<std::uint8_t> a(5 * 8, 1), b(5 * 8, 2);
  EXPECT_EQ(compact(kKeep, RowsView(a.data(), 8, 8, 5), RowsView(b.data(), 8, 8, 5), ids), 3);
}

// keep passed as an array, a view over keep's bytes, a view over a vector's own elements passed with that
// vector, and a vector that is an element of another: each would move bytes a later pass reads.
TEST(Compact, AliasingThroughKeepOrAVectorsOwnElementsIsRefusedAndTouchesNothing) {
  std::vector<std::uint8_t> keep = kKeep;
  std::vector<int> a = {0, 1, 2, 3, 4};
  EXPECT_EQ(compact(keep, keep, a), -1);
  EXPECT_EQ(compact(keep, a, RowsView(keep.data(), 1, 1, 5)), -1);
  std::vector<std::uint8_t> desc(5 * 4, 9);
  EXPECT_EQ(compact(keep, desc, RowsView(desc.data(), 4, 4, 5)), -1);  // sizes differ too; below they agree
  std::vector<std::uint8_t> bytes = {10, 11, 12, 13, 14};
  EXPECT_EQ(compact(keep, bytes, RowsView(bytes.data(), 1, 1, 5)), -1);
  std::vector<std::vector<int>> nested(5, std::vector<int>(5, 3));
  EXPECT_EQ(compact(keep, nested, nested[1]), -1);
  EXPECT_EQ(keep, kKeep);
  EXPECT_EQ(a, (std::vector<int>{0, 1, 2, 3, 4}));
  EXPECT_EQ(bytes, (std::vector<std::uint8_t>{10, 11, 12, 13, 14}));
  EXPECT_EQ(desc, std::vector<std::uint8_t>(5 * 4, 9));
  EXPECT_EQ(nested, std::vector<std::vector<int>>(5, std::vector<int>(5, 3)));
  // A copy of the keep mask and vectors of bool (no element address) still work.
  std::vector<std::uint8_t> mask_copy = kKeep;
  std::vector<bool> flags = {true, false, true, false, true};
  EXPECT_EQ(compact(kKeep, mask_copy, flags, a), 3);
  EXPECT_EQ(flags, (std::vector<bool>{true, true, false}));
}

}  // namespace
