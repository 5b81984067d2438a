#include "dyncull/eval/trajectory.hpp"

#include "eval/synthetic_trajectory.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <tuple>
#include <vector>

namespace {

using namespace dyncull;
using namespace dyncull::eval;

template <class T>
class TrajectoryIoTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(TrajectoryIoTest, Scalars, );

TYPED_TEST(TrajectoryIoTest, ParsesCommentsBlankLinesCommasTabsAndCrlf) {
  using T = TypeParam;
  const std::string text =
      "# ground truth trajectory\n"
      "\n"
      "   # indented comment\n"
      "1.5 1 2 3 0 0 0 1\r\n"
      "1.6,1,2,3,0,0,0.7071067811865476,0.7071067811865476\n"
      "\t1.7\t-1e-3\t+2\t3.5 0 0 0 2\n"  // quaternion not unit: normalised as TUM's transform44
      "   \n";
  const auto r = parse_tum_trajectory<T>(text, "mem");
  ASSERT_TRUE(r.ok()) << r.reason;
  ASSERT_EQ(r.trajectory.size(), 3u);
  EXPECT_EQ(r.trajectory.stamps[0], 1.5);
  EXPECT_EQ(r.trajectory.stamps[2], 1.7);
  const T tol = Constants<T>::small();
  EXPECT_TRUE(r.trajectory.poses[0].R.isIdentity(tol));
  EXPECT_NEAR(r.trajectory.poses[2].t.x(), T(-1e-3), tol);
  EXPECT_NEAR(r.trajectory.poses[2].t.y(), T(2), tol);
  EXPECT_TRUE(r.trajectory.poses[2].R.isIdentity(tol));
  // qz = qw = 1/sqrt(2): 90 degrees about z, so R * x = y.
  const Vec3<T> rx = r.trajectory.poses[1].R * Vec3<T>::UnitX();
  EXPECT_TRUE(rx.isApprox(Vec3<T>::UnitY(), tol)) << rx.transpose();
}

TEST(TrajectoryIo, ParseErrorsGiveSourceAndLine) {
  const std::string good = "# c\n1 0 0 0 0 0 0 1\n\n";
  auto r = parse_tum_trajectory<double>(good + "2 0 0 0 0 0 1\n", "traj.txt");
  EXPECT_EQ(r.status, Status::ParseError);
  EXPECT_EQ(r.reason.rfind("traj.txt:4: ", 0), 0u) << r.reason;
  EXPECT_NE(r.reason.find("found 7"), std::string::npos) << r.reason;
  EXPECT_TRUE(r.trajectory.empty());

  r = parse_tum_trajectory<double>(good + "2 0 0 0 0 0 0 1 9\n", "traj.txt");
  EXPECT_EQ(r.status, Status::ParseError);
  EXPECT_NE(r.reason.find("found 9"), std::string::npos) << r.reason;

  r = parse_tum_trajectory<double>(good + "2 0 0 0 0 0 0 1\n3 0 0 zero 0 0 0 1\n", "traj.txt");
  EXPECT_EQ(r.status, Status::ParseError);
  EXPECT_EQ(r.reason.rfind("traj.txt:5: tz 'zero' is not a number", 0), 0u) << r.reason;

  r = parse_tum_trajectory<double>("1 0 0 0 0 0 0 1x", "f");  // last line without newline
  EXPECT_EQ(r.status, Status::ParseError);
  EXPECT_EQ(r.reason.rfind("f:1: qw '1x'", 0), 0u) << r.reason;
}

TEST(TrajectoryIo, InvalidPosesAreSkippedAndCountedOrRejected) {
  const std::string text = "1 0 0 0 0 0 0 1\n2 nan 0 0 0 0 0 1\n3 0 0 0 0 0 0 0\n4 0 0 0 0 0 0 1\n";
  const auto r = parse_tum_trajectory<double>(text, "f");
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.trajectory.size(), 2u);
  EXPECT_EQ(r.num_skipped, 2u);
  EXPECT_EQ(r.first_skipped, "f:2: non-finite value");
  TrajectoryReadOptions strict;
  strict.skip_invalid_poses = false;
  const auto s = parse_tum_trajectory<double>(text, "f", strict);
  EXPECT_EQ(s.status, Status::ParseError);
  EXPECT_EQ(s.reason, "f:2: non-finite value");
}

TEST(TrajectoryIo, MissingFileIsIoError) {
  const auto r = read_tum_trajectory<double>("/nonexistent/dir/traj.txt");
  EXPECT_EQ(r.status, Status::IoError);
  EXPECT_NE(r.reason.find("/nonexistent/dir/traj.txt"), std::string::npos);
  const WriteResult w = write_tum_trajectory("/nonexistent/dir/out.txt", synthetic::make_loop<double>(5));
  EXPECT_EQ(w.status, Status::IoError);
}

TYPED_TEST(TrajectoryIoTest, WriteReadRoundTripIsLossless) {
  using T = TypeParam;
  const Trajectory<T> traj = synthetic::make_loop<T>(50);
  // One file per scalar type: ctest may run the typed instances in parallel.
  const std::string path = ::testing::TempDir() + "/dyncull_eval_roundtrip_" + std::to_string(sizeof(T)) + ".txt";
  const WriteResult w = write_tum_trajectory(path, traj);
  ASSERT_TRUE(w.ok()) << w.reason;
  const auto r = read_tum_trajectory<T>(path);
  ASSERT_TRUE(r.ok()) << r.reason;
  ASSERT_EQ(r.trajectory.size(), traj.size());
  // Stamps are written with 6 decimals (microseconds, TUM), positions with max_digits10.
  const T rot_tol = T(10) * Constants<T>::epsilon();
  for (std::size_t i = 0; i < traj.size(); ++i) {
    EXPECT_NEAR(r.trajectory.stamps[i], traj.stamps[i], 5e-7);
    EXPECT_EQ(r.trajectory.poses[i].t, traj.poses[i].t);
    EXPECT_TRUE(r.trajectory.poses[i].R.isApprox(traj.poses[i].R, rot_tol)) << i;
  }
}

// associate.py, literally: O(n m) candidate list, sort by (diff, a, b) tuples, greedy, sort by a.
std::vector<std::pair<double, double>> associate_py(std::vector<double> first, std::vector<double> second,
                                                    double offset, double max_difference) {
  std::sort(first.begin(), first.end());
  first.erase(std::unique(first.begin(), first.end()), first.end());
  std::sort(second.begin(), second.end());
  second.erase(std::unique(second.begin(), second.end()), second.end());
  std::vector<std::tuple<double, double, double>> potential;
  for (double a : first) {
    for (double b : second) {
      if (std::abs(a - (b + offset)) < max_difference) potential.emplace_back(std::abs(a - (b + offset)), a, b);
    }
  }
  std::sort(potential.begin(), potential.end());
  std::vector<std::pair<double, double>> matches;
  for (const auto& [d, a, b] : potential) {
    (void)d;
    auto ia = std::find(first.begin(), first.end(), a);
    auto ib = std::find(second.begin(), second.end(), b);
    if (ia != first.end() && ib != second.end()) {
      first.erase(ia);
      second.erase(ib);
      matches.emplace_back(a, b);
    }
  }
  std::sort(matches.begin(), matches.end());
  return matches;
}

TEST(Associate, MatchesAssociatePyOnJitteredStreams) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> jitter(-0.004, 0.004);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<double> gt;
    std::vector<double> est;
    for (int k = 0; k < 300; ++k) gt.push_back(1341845688.7 + k * 0.01 + jitter(rng));   // 100 Hz
    for (int k = 0; k < 90; ++k) est.push_back(1341845688.7 + k / 30.0 + jitter(rng));  // 30 Hz
    std::shuffle(est.begin(), est.end(), rng);  // order must not matter
    const double offset = trial % 2 ? 0.003 : 0.0;
    AssociationOptions options;
    options.offset_s = offset;
    const AssociationResult r = associate(gt, est, options);
    ASSERT_TRUE(r.ok()) << r.reason;
    const auto expected = associate_py(gt, est, offset, 0.02);
    ASSERT_EQ(r.size(), expected.size());
    for (std::size_t i = 0; i < r.size(); ++i) {
      EXPECT_EQ(gt[r.first[i]], expected[i].first);
      EXPECT_EQ(est[r.second[i]], expected[i].second);
    }
  }
}

TEST(Associate, GreedyBySmallestDifferenceEachStampOnce) {
  // 1.012 is closer to 1.010 than 1.000 is, so it takes it; 1.000 stays unmatched.
  const AssociationResult r = associate(std::vector<double>{1.000, 1.012}, std::vector<double>{1.010});
  ASSERT_TRUE(r.ok());
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r.first[0], 1u);
  EXPECT_EQ(r.second[0], 0u);
}

TEST(Associate, TiesGoToTheEarlierFirstStamp) {
  AssociationOptions options;
  options.max_difference_s = 1.0;
  const AssociationResult r = associate(std::vector<double>{2.0, 1.0}, std::vector<double>{1.5}, options);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r.first[0], 1u);  // stamp 1.0 (index 1): Python's tuple sort breaks the tie on a
}

TEST(Associate, WindowIsStrictAndOffsetShiftsTheSecondList) {
  AssociationOptions options;
  options.max_difference_s = 0.5;
  EXPECT_EQ(associate(std::vector<double>{1.0}, std::vector<double>{1.5}, options).status, Status::TooFewPoints);
  options.offset_s = -0.25;
  const AssociationResult r = associate(std::vector<double>{1.0}, std::vector<double>{1.5}, options);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.size(), 1u);
}

TEST(Associate, DuplicateStampsCountOnceLastEntryWins) {
  const AssociationResult r =
      associate(std::vector<double>{1.0, 1.0, 2.0}, std::vector<double>{2.001, 1.001, 1.001});
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.num_duplicates_first, 1u);
  EXPECT_EQ(r.num_duplicates_second, 1u);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r.first[0], 1u);   // the later of the two 1.0 entries
  EXPECT_EQ(r.second[0], 2u);  // the later of the two 1.001 entries
  EXPECT_EQ(r.first[1], 2u);
  EXPECT_EQ(r.second[1], 0u);
}

TEST(Associate, NoOverlapEmptyAndBadOptionsAreStatuses) {
  const AssociationResult none = associate(std::vector<double>{1.0, 2.0}, std::vector<double>{10.0, 11.0});
  EXPECT_EQ(none.status, Status::TooFewPoints);
  EXPECT_NE(none.reason.find("no stamp pairs"), std::string::npos) << none.reason;
  EXPECT_EQ(none.size(), 0u);
  EXPECT_EQ(associate(std::vector<double>{}, std::vector<double>{1.0}).status, Status::TooFewPoints);
  const AssociationResult nan_only =
      associate(std::vector<double>{std::nan("")}, std::vector<double>{std::nan("")});
  EXPECT_EQ(nan_only.status, Status::TooFewPoints);
  AssociationOptions bad;
  bad.max_difference_s = 0.0;
  EXPECT_EQ(associate(std::vector<double>{1.0}, std::vector<double>{1.0}, bad).status, Status::InvalidInput);
}

}  // namespace
