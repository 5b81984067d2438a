// dyncull_eval's logic (argument parsing, evaluation, text and JSON output), run in-process on the
// real TUM data, without executing the binary.
#include "dyncull/eval/report.hpp"

#include <gtest/gtest.h>

#include "support/real_data.hpp"

#include <algorithm>
#include <clocale>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace dyncull;
using namespace dyncull::eval;

ParseArgsResult parse(std::vector<const char*> args) {
  args.insert(args.begin(), "dyncull_eval");
  return parse_eval_args(static_cast<int>(args.size()), args.data());
}

TEST(EvalArgs, DefaultsAndEveryOption) {
  const ParseArgsResult d = parse({"gt.txt", "est.txt"});
  ASSERT_TRUE(d.ok()) << d.reason;
  EXPECT_EQ(d.args.groundtruth_path, "gt.txt");
  EXPECT_EQ(d.args.estimate_path, "est.txt");
  EXPECT_FALSE(d.args.rpe);
  EXPECT_EQ(d.args.delta_unit, DeltaUnit::Seconds);
  EXPECT_EQ(d.args.max_difference_s, 0.02);

  const ParseArgsResult all = parse({"--rpe", "gt.txt", "--delta", "5", "--delta-unit", "frames", "--scale",
                                     "--max-difference", "0.03", "--offset", "-0.01", "--json", "est.txt"});
  ASSERT_TRUE(all.ok()) << all.reason;
  EXPECT_TRUE(all.args.rpe && all.args.estimate_scale && all.args.json);
  EXPECT_EQ(all.args.delta, 5.0);
  EXPECT_EQ(all.args.delta_unit, DeltaUnit::Frames);
  EXPECT_EQ(all.args.max_difference_s, 0.03);
  EXPECT_EQ(all.args.offset_s, -0.01);
  EXPECT_EQ(all.args.estimate_path, "est.txt");
  EXPECT_TRUE(parse({"--help"}).args.help);
}

TEST(EvalArgs, BadArgumentsAreReported) {
  EXPECT_NE(parse({"gt.txt"}).reason.find("expected 2 files"), std::string::npos);
  EXPECT_NE(parse({"a", "b", "c"}).reason.find("got 3"), std::string::npos);
  EXPECT_NE(parse({"a", "b", "--frobnicate"}).reason.find("unknown option '--frobnicate'"), std::string::npos);
  EXPECT_EQ(parse({"a", "b", "--delta"}).status, Status::InvalidInput);
  EXPECT_EQ(parse({"a", "b", "--delta", "-1"}).status, Status::InvalidInput);
  EXPECT_EQ(parse({"a", "b", "--delta", "1x"}).status, Status::InvalidInput);
  EXPECT_EQ(parse({"a", "b", "--delta-unit", "furlongs"}).status, Status::InvalidInput);
  EXPECT_EQ(parse({"a", "b", "--max-difference", "0"}).status, Status::InvalidInput);
  EXPECT_NE(eval_usage().find("FIXED factor"), std::string::npos);  // --scale differs from TUM's
}

TEST(EvalArgs, NumbersAreReadTheSameInACommaDecimalLocale) {
  const std::string previous = std::setlocale(LC_NUMERIC, nullptr);
  bool switched = false;
  for (const char* l : {"de_DE.UTF-8", "de_DE.utf8", "fr_FR.UTF-8"}) {
    switched = switched || std::setlocale(LC_NUMERIC, l) != nullptr;
  }
  if (!switched) GTEST_SKIP() << "no comma-decimal locale installed";
  const auto ok = parse({"a", "b", "--delta", "0.5", "--offset", "-1.25"});
  const auto comma = parse({"a", "b", "--delta", "0,5"});
  std::setlocale(LC_NUMERIC, previous.c_str());
  ASSERT_TRUE(ok.ok()) << ok.reason;
  EXPECT_EQ(ok.args.delta, 0.5);
  EXPECT_EQ(ok.args.offset_s, -1.25);
  EXPECT_EQ(comma.status, Status::InvalidInput);
}

TEST(EvalRun, MalformedFileGivesFileAndLine) {
  const std::string dir = ::testing::TempDir();
  const std::string good = dir + "/dyncull_eval_good.txt";
  const std::string bad = dir + "/dyncull_eval_bad.txt";
  std::ofstream(good) << "1 0 0 0 0 0 0 1\n2 1 0 0 0 0 0 1\n3 1 1 0 0 0 0 1\n4 0 1 1 0 0 0 1\n";
  std::ofstream(bad) << "# header\n1 0 0 0 0 0 0 1\n2 0 0 0 0 0 1\n";
  EvalCommandLine args;
  args.groundtruth_path = good;
  args.estimate_path = bad;
  const EvalReport r = run_eval(args);
  EXPECT_EQ(r.status, Status::ParseError);
  EXPECT_EQ(r.reason.rfind(bad + ":3: ", 0), 0u) << r.reason;
  args.estimate_path = dir + "/does_not_exist.txt";
  EXPECT_EQ(run_eval(args).status, Status::IoError);
  EXPECT_NE(format_report_json(run_eval(args)).find("\"status\": \"i/o error\""), std::string::npos);
}

// --poses-csv: one row per pair in stamp order; an estimate that is the truth moved rigidly comes back
// onto the truth after the alignment, with zero error.
TEST(EvalRun, PosesCsvHoldsEachPairAligned) {
  const std::string dir = ::testing::TempDir();
  const std::string truth = dir + "/dyncull_eval_poses_truth.txt";
  const std::string moved = dir + "/dyncull_eval_poses_moved.txt";
  std::ofstream(truth) << "1 0 0 0 0 0 0 1\n2 1 0 0 0 0 0 1\n3 1 1 0 0 0 0 1\n4 0 1 1 0 0 0 1\n";
  std::ofstream(moved) << "1 5 0 0 0 0 0 1\n2 5 1 0 0 0 0 1\n3 4 1 0 0 0 0 1\n4 4 0 1 0 0 0 1\n";  // turned 90 deg, shifted
  const ParseArgsResult parsed = parse({truth.c_str(), moved.c_str(), "--poses-csv", "poses.csv"});
  ASSERT_TRUE(parsed.ok()) << parsed.reason;
  EXPECT_EQ(parsed.args.poses_csv, "poses.csv");
  EXPECT_FALSE(parse({truth.c_str(), moved.c_str(), "--poses-csv"}).ok());
  const std::string csv = format_poses_csv(run_eval(parsed.args));
  EXPECT_EQ(csv.substr(0, csv.find('\n')), "stamp,gt_x,gt_y,gt_z,x,y,z,error_m");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 5);
  std::istringstream rows(csv.substr(csv.find('\n') + 1));
  std::string row;
  double expected_stamp = 1.0;
  while (std::getline(rows, row)) {
    std::vector<double> v;
    std::istringstream fields(row);
    for (std::string f; std::getline(fields, f, ',');) v.push_back(std::stod(f));
    ASSERT_EQ(v.size(), 8u) << row;
    EXPECT_DOUBLE_EQ(v[0], expected_stamp++);
    for (int k = 1; k <= 3; ++k) EXPECT_NEAR(v[k + 3], v[k], 1e-6) << row;
    EXPECT_NEAR(v[7], 0.0, 1e-6) << row;
  }
}

// --associate: rgb.txt and depth.txt pairs as associate.py makes them: depth 1.052 is within the window of rgb
// 1.033 (0.019 s) and rgb 1.067 (0.015 s), the closer one gets it; rgb 1.100 has no depth within 0.02 s.
TEST(EvalRun, AssociateListsPairsClosestFirstEachStampOnce) {
  const std::string dir = ::testing::TempDir();
  const std::string rgb = dir + "/dyncull_eval_rgb.txt", depth = dir + "/dyncull_eval_depth.txt";
  std::ofstream(rgb) << "# color images\n1.000000 rgb/1.png\n1.033333 rgb/2.png\n1.066667 rgb/3.png\n1.100000 rgb/4.png\n";
  std::ofstream(depth) << "# depth maps\n1.010000 depth/a.png\n1.052000 depth/b.png\n1.130000 depth/c.png\n";
  const ParseArgsResult parsed = parse({"--associate", rgb.c_str(), depth.c_str()});
  ASSERT_TRUE(parsed.ok()) << parsed.reason;
  const ListAssociation pairs = associate_lists(parsed.args);
  ASSERT_TRUE(pairs.ok()) << pairs.reason;
  EXPECT_EQ(pairs.text, "1.000000 rgb/1.png 1.010000 depth/a.png\n1.066667 rgb/3.png 1.052000 depth/b.png\n");
  std::ofstream(depth) << "1.000000\n";  // a line without its file
  const ListAssociation bad = associate_lists(parsed.args);
  EXPECT_EQ(bad.status, Status::ParseError);
  EXPECT_EQ(bad.reason.rfind(depth + ":1: ", 0), 0u) << bad.reason;
}

TEST(EvalRun, RealDataPrintsTheTumScriptsLines) {
  std::string why_not;
  const std::string root = dyncull::test::real_data_dir(&why_not);
  if (root.empty()) GTEST_SKIP() << why_not;
  const std::string dir = root + "/tum/fr3_sitting_static";
  if (!std::ifstream(dir + "/groundtruth.txt")) GTEST_SKIP() << dir << "/groundtruth.txt is missing";
  const std::string gt = dir + "/groundtruth.txt";
  const std::string est = dir + "/estimate_dynaslam.txt";
  const ParseArgsResult parsed = parse({gt.c_str(), est.c_str(), "--rpe", "--delta", "1", "--delta-unit", "seconds"});
  ASSERT_TRUE(parsed.ok()) << parsed.reason;
  const EvalReport report = run_eval(parsed.args);
  ASSERT_TRUE(report.ok()) << report.reason;
  EXPECT_EQ(report.estimate_poses, 557u);
  const std::string text = format_report_text(report);
  // What evaluate_ate.py --verbose and evaluate_rpe.py --fixed_delta --verbose print on these files
  // (the %f-rounded values of expected_tum_scripts.json).
  for (const char* line : {"compared_pose_pairs 557 pairs\n", "absolute_translational_error.rmse 0.006368 m\n",
                           "absolute_translational_error.mean 0.005611 m\n",
                           "absolute_translational_error.median 0.005116 m\n",
                           "absolute_translational_error.std 0.003010 m\n",
                           "absolute_translational_error.min 0.000682 m\n",
                           "absolute_translational_error.max 0.022002 m\n", "compared_pose_pairs 530 pairs\n",
                           "translational_error.rmse 0.008219 m\n", "translational_error.median 0.006322 m\n",
                           "rotational_error.rmse 0.280728 deg\n", "rotational_error.max 0.843676 deg\n"}) {
    EXPECT_NE(text.find(line), std::string::npos) << "missing: " << line << "in:\n" << text;
  }
  const std::string json = format_report_json(report);
  EXPECT_NE(json.find("\"pairs\": 530"), std::string::npos) << json;
  EXPECT_NE(json.find("\"rmse\": 0.0063675374980"), std::string::npos) << json;

  // --scale: Sim(3) can only lower the error, and RPE is computed with the fitted scale.
  const ParseArgsResult scaled = parse({gt.c_str(), est.c_str(), "--scale", "--rpe"});
  const EvalReport sim3 = run_eval(scaled.args);
  ASSERT_TRUE(sim3.ok()) << sim3.reason;
  EXPECT_LE(sim3.ate.error_m.rmse, report.ate.error_m.rmse);
  EXPECT_EQ(sim3.rpe_scale, sim3.ate.groundtruth_from_estimate.scale);
  EXPECT_NE(format_report_text(sim3).find("alignment_scale"), std::string::npos);
}

}  // namespace
