#include "dyncull/eval/trajectory.hpp"

#include "eval/synthetic_trajectory.hpp"

#include <gtest/gtest.h>

#include "support/locale.hpp"
#include "support/special_files.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <tuple>
#include <unistd.h>
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

using dyncull::test::CommaDecimalLocale;

TYPED_TEST(TrajectoryIoTest, ParsingIgnoresTheCLocale) {
  using T = TypeParam;
  CommaDecimalLocale locale;
  if (!locale.active()) GTEST_SKIP() << "no comma-decimal locale installed (locale-gen de_DE.UTF-8)";
  const auto r = parse_tum_trajectory<T>("1.5 0.25 0 0 0 0 0 1\n", "f");
  ASSERT_TRUE(r.ok()) << r.reason;
  ASSERT_EQ(r.trajectory.size(), 1u);
  EXPECT_EQ(r.trajectory.poses[0].t.x(), T(0.25));
  std::string text;
  Trajectory<T> traj;
  traj.push_back(1.5, Rigid3<T>{});
  traj.poses[0].t.x() = T(0.25);
  ASSERT_TRUE(format_tum_trajectory(traj, &text).ok());
  EXPECT_EQ(text.find(','), std::string::npos) << text;
  EXPECT_EQ(text.rfind("1.500000 0.25 ", 0), 0u) << text;
}

TEST(TrajectoryIo, NumbersFollowPythonFloat) {
  // Accepted as Python's float() accepts them.
  const char* const good[] = {"1_000", "1_0.2_5", "1e1_0", "+5", "-.5", "5.", "1E3", "inf", "-Infinity",
                              "INF", "nAn", "+nan", "-0"};
  for (const char* tok : good) {
    const auto r = parse_tum_trajectory<double>(std::string("1 ") + tok + " 0 0 0 0 0 1\n", "f");
    EXPECT_TRUE(r.ok()) << tok << ": " << r.reason;
  }
  EXPECT_EQ(parse_tum_trajectory<double>("1 1_000 0 0 0 0 0 1\n").trajectory.poses.at(0).t.x(), 1000.0);
  EXPECT_EQ(parse_tum_trajectory<double>("1 1_0.2_5 0 0 0 0 0 1\n").trajectory.poses.at(0).t.x(), 10.25);
  // Rejected as Python rejects them.
  const char* const bad[] = {"+-5", "-+5", "--5", "1__0", "_1", "1_", "1_.5", "1._5", "1e", "1e+", ".", ".e5",
                             "e5", "0x10", "infinit", "nana", "1,5e", "1.5.2", "1e5.0", "i"};
  for (const char* tok : bad) {
    const auto r = parse_tum_trajectory<double>(std::string("1 ") + tok + " 0 0 0 0 0 1\n", "f");
    EXPECT_EQ(r.status, Status::ParseError) << tok;
  }
}

TEST(TrajectoryIo, OverflowIsInfinityAndSkipsTheLineUnderflowIsZero) {
  const auto r = parse_tum_trajectory<double>("1 1e400 0 0 0 0 0 1\n2 -1e99999999999999999999 0 0 0 0 0 1\n"
                                              "3 1e-400 0 0 0 0 0 1\n4 0 0 0 0 0 0 1\n", "f");
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.num_skipped, 2u);
  EXPECT_EQ(r.first_skipped, "f:1: non-finite value");
  ASSERT_EQ(r.trajectory.size(), 2u);
  EXPECT_EQ(r.trajectory.poses[0].t.x(), 0.0);
  EXPECT_EQ(r.trajectory.stamps[1], 4.0);
}

TEST(TrajectoryIo, FloatTranslationOutOfRangeIsAReasonNotInfinity) {
  const std::string text = "1 1e39 0 0 0 0 0 1\n2 0 0 0 0 0 0 1\n";
  const auto f = parse_tum_trajectory<float>(text, "f");
  ASSERT_TRUE(f.ok()) << f.reason;
  ASSERT_EQ(f.trajectory.size(), 1u);
  EXPECT_EQ(f.num_skipped, 1u);
  EXPECT_NE(f.first_skipped.find("f:1: tx"), std::string::npos) << f.first_skipped;
  EXPECT_NE(f.first_skipped.find("out of range for float"), std::string::npos) << f.first_skipped;
  for (const auto& p : f.trajectory.poses) EXPECT_TRUE(p.t.allFinite());
  TrajectoryReadOptions strict;
  strict.skip_invalid_poses = false;
  EXPECT_EQ(parse_tum_trajectory<float>(text, "f", strict).status, Status::ParseError);
  const auto d = parse_tum_trajectory<double>(text, "f");
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d.trajectory.size(), 2u);  // 1e39 is a finite double
}

TEST(TrajectoryIo, ReasonQuotesABoundedEscapedPrefixOfTheToken) {
  std::string huge(600, '7');
  huge += 'x';
  auto r = parse_tum_trajectory<double>("1 " + huge + " 0 0 0 0 0 1\n", "f");
  EXPECT_EQ(r.status, Status::ParseError);
  EXPECT_LT(r.reason.size(), 200u) << r.reason.substr(0, 300);
  EXPECT_EQ(r.reason.rfind("f:1: tx '7777", 0), 0u) << r.reason.substr(0, 300);
  EXPECT_NE(r.reason.find("(601 bytes)"), std::string::npos) << r.reason.substr(0, 300);
  r = parse_tum_trajectory<double>("1 0 0 0 0 0 0 " + std::string(1u << 20, '1') + "\n", "f");
  EXPECT_EQ(r.status, Status::ParseError);
  EXPECT_LT(r.reason.size(), 200u) << r.reason.substr(0, 300);

  const std::string nul_token = std::string("1") + '\0' + "5";
  r = parse_tum_trajectory<double>("1 " + nul_token + " 0 0 0 0 0 1 \n", "f");
  EXPECT_EQ(r.status, Status::ParseError);
  EXPECT_EQ(r.reason.find('\0'), std::string::npos);
  EXPECT_NE(r.reason.find("1\\x005"), std::string::npos) << r.reason;
  EXPECT_NE(r.reason.find("is not a number"), std::string::npos) << r.reason;  // the message goes on past the NUL
}

TEST(TrajectoryIo, OverlongDataLineIsAnErrorAndLongCommentsAreSkipped) {
  const std::string spaces(100000, ' ');
  auto r = parse_tum_trajectory<double>("1 0 0 0" + spaces + "0 0 0 1\n", "f");
  EXPECT_EQ(r.status, Status::ParseError);
  EXPECT_NE(r.reason.find("f:1: line"), std::string::npos) << r.reason.substr(0, 200);
  EXPECT_LT(r.reason.size(), 200u);
  r = parse_tum_trajectory<double>("#" + spaces + "\n1 0 0 0 0 0 0 1\n", "f");
  ASSERT_TRUE(r.ok()) << r.reason.substr(0, 200);
  EXPECT_EQ(r.trajectory.size(), 1u);
}

TEST(TrajectoryIo, DirectoryIsIoError) {
  const std::string dir = ::testing::TempDir() + "/dyncull_traj_dir_" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  const auto r = read_tum_trajectory<double>(dir);
  EXPECT_EQ(r.status, Status::IoError) << r.reason;
  EXPECT_NE(r.reason.find(dir), std::string::npos) << r.reason;
  const WriteResult w = write_tum_trajectory(dir, synthetic::make_loop<double>(3));
  EXPECT_EQ(w.status, Status::IoError) << w.reason;
  std::filesystem::remove_all(dir);
}

TEST(TrajectoryIo, FifoAndDeviceAreRefusedPromptlyNamingThePath) {
  test::ScratchDir dir;
  const std::string fifo = dir / "est.txt";
  if (!test::make_fifo(fifo)) return;
  TrajectoryReadResult<double> r;
  EXPECT_TRUE(test::returns_promptly([&] { r = read_tum_trajectory<double>(fifo); }, fifo)) << "blocked on a FIFO";
  EXPECT_EQ(r.status, Status::IoError);
  EXPECT_EQ(r.reason, fifo + ": is a FIFO (named pipe), not a regular file");
  // /dev/zero has no newline and no end: refused before reading, not read until memory runs out.
  r = read_tum_trajectory<double>("/dev/zero");
  EXPECT_EQ(r.status, Status::IoError);
  EXPECT_EQ(r.reason, "/dev/zero: is a character device, not a regular file");
}

TEST(TrajectoryIo, LinesBeyondMaxLinesAreAParseErrorInFileAndText) {
  test::ScratchDir dir;
  std::ofstream(dir / "t.txt") << "# header\n1 0 0 0 0 0 0 1\n2 0 0 0 0 0 0 1\n3 0 0 0 0 0 0 1\n";
  TrajectoryReadOptions o;
  o.max_lines = 3;
  const auto r = read_tum_trajectory<double>(dir / "t.txt", o);
  EXPECT_EQ(r.status, Status::ParseError);
  EXPECT_EQ(r.reason, dir / "t.txt" + ": more than 3 lines");
  EXPECT_TRUE(r.trajectory.empty());
  const auto p = parse_tum_trajectory<double>("# header\n1 0 0 0 0 0 0 1\n2 0 0 0 0 0 0 1\n3 0 0 0 0 0 0 1\n", "t", o);
  EXPECT_EQ(p.status, Status::ParseError);
  EXPECT_EQ(p.reason, "t: more than 3 lines");
  o.max_lines = 4;
  EXPECT_EQ(read_tum_trajectory<double>(dir / "t.txt", o).trajectory.size(), 3u);
}

TEST(TrajectoryIo, FileAndTextGiveTheSameResultLineForLine) {
  test::ScratchDir dir;
  const std::string text = "# c\r\n1 0 0 0 0 0 0 1\r\n\n  \t\n2,0,0,0,0,0,0,1\n3 0 0 0 0 0 0 0\n#" + std::string(20000, 'x') +
                           "\n4 nan 0 0 0 0 0 1\n5 1 2 3 0 0 0 1";
  std::ofstream(dir / "t.txt", std::ios::binary) << text;
  const auto f = read_tum_trajectory<double>(dir / "t.txt");
  const auto p = parse_tum_trajectory<double>(text, dir / "t.txt");
  ASSERT_TRUE(f.ok()) << f.reason;
  ASSERT_TRUE(p.ok()) << p.reason;
  EXPECT_EQ(f.trajectory.stamps, p.trajectory.stamps);
  EXPECT_EQ(f.num_skipped, 2u);
  EXPECT_EQ(f.first_skipped, p.first_skipped);
  EXPECT_EQ(f.first_skipped, dir / "t.txt" + ":6: zero quaternion");
  std::ofstream(dir / "t.txt", std::ios::binary) << "1 0 0 0 0 0 0 1\n" << std::string(9000, '1') << "\n";
  const auto g = read_tum_trajectory<double>(dir / "t.txt");
  EXPECT_EQ(g.status, Status::ParseError);
  EXPECT_EQ(g.reason, dir / "t.txt" + ":2: line is 9000 bytes long (limit 8192)");
}

TEST(TrajectoryIo, PathsInReasonsAreEscaped) {
  const auto r = read_tum_trajectory<double>("/nonexistent/\x1b]0;title\x07.txt");
  EXPECT_EQ(r.status, Status::IoError);
  EXPECT_EQ(r.reason, "/nonexistent/\\x1b]0;title\\x07.txt: no such file");
}

TEST(TrajectoryIo, UnreadableFileIsIoError) {
  if (::geteuid() == 0) GTEST_SKIP() << "running as root: every file is readable";
  const std::string file = ::testing::TempDir() + "/dyncull_traj_noread_" + std::to_string(::getpid()) + ".txt";
  std::ofstream(file) << "1 0 0 0 0 0 0 1\n";
  std::filesystem::permissions(file, std::filesystem::perms::none);
  const auto u = read_tum_trajectory<double>(file);
  EXPECT_EQ(u.status, Status::IoError) << u.reason;
  std::filesystem::remove(file);
}

TYPED_TEST(TrajectoryIoTest, LongValuesAreNeverCutAndDigitsAreValidated) {
  using T = TypeParam;
  Trajectory<T> traj;
  for (int i = 0; i < 2; ++i) {
    Rigid3<T> p;
    p.t = Vec3<T>(T(1) / T(3), T(-2) / T(7), std::numeric_limits<T>::max());
    traj.push_back(i == 0 ? 1e300 : -std::numeric_limits<double>::max(), p);  // 301 and 309 digits with %f
  }
  std::string text;
  TrajectoryWriteOptions options;
  options.stamp_decimals = 9;
  options.value_digits = 17;
  const WriteResult w = format_tum_trajectory(traj, &text, options);
  ASSERT_TRUE(w.ok()) << w.reason;
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 2);
  const auto r = parse_tum_trajectory<T>(text, "f");
  ASSERT_TRUE(r.ok()) << r.reason.substr(0, 200);
  ASSERT_EQ(r.trajectory.size(), 2u);
  EXPECT_EQ(r.trajectory.poses[1].t, traj.poses[1].t);

  for (int bad_digits : {-1, 18, 120}) {
    TrajectoryWriteOptions o;
    o.value_digits = bad_digits;
    const WriteResult b = format_tum_trajectory(traj, &text, o);
    EXPECT_EQ(b.status, Status::InvalidInput) << bad_digits;
    EXPECT_NE(b.reason.find("value_digits"), std::string::npos) << b.reason;
  }
  for (int bad_decimals : {-1, 10}) {
    TrajectoryWriteOptions o;
    o.stamp_decimals = bad_decimals;
    const WriteResult b = format_tum_trajectory(traj, &text, o);
    EXPECT_EQ(b.status, Status::InvalidInput) << bad_decimals;
    EXPECT_NE(b.reason.find("stamp_decimals"), std::string::npos) << b.reason;
  }
}

TYPED_TEST(TrajectoryIoTest, NonFinitePoseIsAnErrorAndNothingIsWritten) {
  using T = TypeParam;
  const std::string path = ::testing::TempDir() + "/dyncull_traj_nan_" + std::to_string(sizeof(T)) + ".txt";
  std::filesystem::remove(path);
  for (int which = 0; which < 3; ++which) {
    Trajectory<T> traj = synthetic::make_loop<T>(4);
    if (which == 0) traj.poses[2].t.y() = std::numeric_limits<T>::quiet_NaN();
    if (which == 1) traj.poses[2].R(0, 0) = std::numeric_limits<T>::infinity();
    if (which == 2) traj.stamps[2] = std::numeric_limits<double>::quiet_NaN();
    const WriteResult w = write_tum_trajectory(path, traj);
    EXPECT_EQ(w.status, Status::NonFinite) << which;
    EXPECT_NE(w.reason.find("pose 2"), std::string::npos) << w.reason;
    EXPECT_FALSE(std::filesystem::exists(path)) << which;
    std::string text;
    EXPECT_EQ(format_tum_trajectory(traj, &text).status, Status::NonFinite);
  }
  Trajectory<T> zero = synthetic::make_loop<T>(2);
  zero.poses[1].R.setZero();  // no rotation: its quaternion is meaningless
  std::string text;
  const WriteResult z = format_tum_trajectory(zero, &text);
  EXPECT_EQ(z.status, Status::InvalidInput);
  EXPECT_EQ(z.reason, "pose 1: rotation is not orthonormal");
  EXPECT_TRUE(text.empty());
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

// Exact ties (stamps on a grid of 1/64 s), windows holding many stamps, and an offset so large that
// distinct stamps round to the same shifted value: the order (difference, a, b) decides every pair.
TEST(Associate, MatchesAssociatePyWithTiesDenseWindowsAndRoundingOffsets) {
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> tick(0, 200);
  for (int trial = 0; trial < 60; ++trial) {
    const bool huge_offset = trial % 3 == 2;
    const double base = huge_offset ? 0.0 : 1000.0;
    std::vector<double> first, second;
    const int n = 1 + trial % 40, m = 1 + (trial * 7) % 45;
    for (int k = 0; k < n; ++k) first.push_back(base + tick(rng) / 64.0);
    for (int k = 0; k < m; ++k) second.push_back(base + tick(rng) / 64.0 + (trial % 2 ? 1e-13 * tick(rng) : 0.0));
    AssociationOptions options;
    options.max_difference_s = trial % 4 == 0 ? 0.5 : 0.04;
    options.offset_s = huge_offset ? 4.0e15 : (trial % 5) / 64.0;
    if (huge_offset) {  // the shifted stamps land on a grid of 0.5 s: many round together
      for (double& t : first) t += 4.0e15;
    }
    const AssociationResult r = associate(first, second, options);
    const auto expected = associate_py(first, second, options.offset_s, options.max_difference_s);
    ASSERT_EQ(r.size(), expected.size()) << "trial " << trial;
    for (std::size_t i = 0; i < r.size(); ++i) {
      EXPECT_EQ(first[r.first[i]], expected[i].first) << "trial " << trial << " pair " << i;
      EXPECT_EQ(second[r.second[i]], expected[i].second) << "trial " << trial << " pair " << i;
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
  EXPECT_EQ(nan_only.status, Status::NonFinite);
  AssociationOptions bad;
  bad.max_difference_s = 0.0;
  EXPECT_EQ(associate(std::vector<double>{1.0}, std::vector<double>{1.0}, bad).status, Status::InvalidInput);
}


// A frame rate of 5e-324 Hz stamps every frame inf: the association refuses the stamps and names
// them, instead of pairing nothing (or the finite rest) without a word.
TEST(Associate, NonFiniteStampsAreRefusedNamingListIndexAndCount) {
  const double inf = std::numeric_limits<double>::infinity();
  const AssociationResult r = associate(std::vector<double>{1.0, 2.0, 3.0}, std::vector<double>{1.0, inf, inf});
  EXPECT_EQ(r.status, Status::NonFinite);
  EXPECT_EQ(r.reason, "associate: second list's stamp 1 is inf (2 of 3 stamps are not finite)");
  EXPECT_EQ(r.size(), 0u);
  const AssociationResult g = associate(std::vector<double>{std::nan(""), 2.0}, std::vector<double>{2.0});
  EXPECT_EQ(g.status, Status::NonFinite);
  EXPECT_NE(g.reason.find("first list's stamp 0 is nan (1 of 2"), std::string::npos) << g.reason;
}

TEST(Associate, OptionsValidateNamesTheField) {
  std::string why;
  EXPECT_EQ(AssociationOptions{}.validate(&why), Status::Ok);
  EXPECT_TRUE(why.empty());
  const std::vector<double> a{1.0, 2.0, 3.0}, b{1.001, 2.001, 3.001};
  for (double bad : {0.0, -1.0, std::nan(""), HUGE_VAL, 1e9}) {
    AssociationOptions o;
    o.max_difference_s = bad;
    EXPECT_EQ(o.validate(&why), Status::InvalidInput) << bad;
    EXPECT_NE(why.find("max_difference_s"), std::string::npos) << why;
    // A window of seconds or more pairs unrelated poses and makes every pair a candidate.
    const AssociationResult r = associate(a, b, o);
    EXPECT_EQ(r.status, Status::InvalidInput) << bad;
    EXPECT_NE(r.reason.find("max_difference_s"), std::string::npos) << r.reason;
    EXPECT_EQ(r.size(), 0u);
  }
  for (double bad : {std::nan(""), -HUGE_VAL}) {
    AssociationOptions o;
    o.offset_s = bad;
    EXPECT_EQ(o.validate(&why), Status::InvalidInput);
    const AssociationResult r = associate(a, b, o);
    EXPECT_EQ(r.status, Status::InvalidInput);
    EXPECT_NE(r.reason.find("offset_s"), std::string::npos) << r.reason;
    EXPECT_EQ(r.reason.find("max_difference_s"), std::string::npos) << r.reason;
  }
  AssociationOptions widest;
  widest.max_difference_s = AssociationOptions::kMaxDifferenceS;
  EXPECT_EQ(associate(a, b, widest).size(), 3u);
}

}  // namespace
