// Memory of the rgb / depth association (eval/trajectory.hpp associate, through eval/sequence.hpp
// read_sequence) is linear in the lists, whatever the association window holds: 100,000-line lists whose
// stamps are 10 us apart put 2,000 depth stamps in each rgb stamp's 20 ms window (200 million candidate
// pairs if they were listed, 3.2 GB), and the read stays under a heap cap of 64 MiB.
#include "dyncull/eval/sequence.hpp"

#include "support/allocation_cap.hpp"
#include "support/special_files.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <new>
#include <string>

namespace dyncull::eval {
namespace {

constexpr int kLines = 100000;

void write_list(const std::string& path, const char* folder, double shift_s) {
  std::ofstream out(path);
  char line[96];
  for (int k = 0; k < kLines; ++k) {
    std::snprintf(line, sizeof line, "%.6f %s/%d.png\n", 1000.0 + k * 1e-5 + shift_s, folder, k);
    out << line;
  }
}

TEST(AssociationMemory, HundredThousandLineListsWithCrowdedWindowsStayLinear) {
  test::ScratchDir dir;
  write_list(dir / "rgb.txt", "rgb", 0.0);
  write_list(dir / "depth.txt", "depth", 3e-6);
  SequenceOptions options;
  options.check_files = false;
  SequenceIndex s;
  std::size_t peak = 0;
  {
    const test::HeapCap cap(std::size_t(64) << 20);
    EXPECT_NO_THROW(s = read_sequence(dir.str(), options));
    peak = cap.peak();
  }
  ASSERT_TRUE(s.ok()) << s.reason;
  ASSERT_EQ(s.frames.size(), std::size_t(kLines));
  EXPECT_EQ(s.frames_without_depth, 0u);
  // Each rgb stamp's nearest depth stamp is its own line's, 3 us later.
  for (std::size_t k = 0; k < s.frames.size(); k += 997)
    EXPECT_EQ(s.frames[k].depth_path, "depth/" + std::to_string(k) + ".png");
  EXPECT_LT(peak, std::size_t(64) << 20);
  std::printf("peak heap of read_sequence on two %d-line lists: %.1f MiB\n", kLines, double(peak) / (1 << 20));
}

// The worst case for associate() itself: every stamp of both lists inside one window.
TEST(AssociationMemory, EveryPairInsideTheWindowStaysLinear) {
  std::vector<double> first, second;
  for (int k = 0; k < kLines; ++k) {
    first.push_back(1.0 + k * 1e-7);
    second.push_back(1.0 + k * 1e-7 + 3e-8);
  }
  AssociationOptions options;
  options.max_difference_s = 1.0;
  AssociationResult r;
  {
    const test::HeapCap cap(std::size_t(32) << 20);
    EXPECT_NO_THROW(r = associate(first, second, options));
  }
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.size(), std::size_t(kLines));
  for (std::size_t k = 0; k < r.size(); k += 991) EXPECT_EQ(r.second[k], r.first[k]);
}

}  // namespace
}  // namespace dyncull::eval
