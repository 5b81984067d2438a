// dynamic_vo --dataset (apps/vo/dataset.hpp): the frame source over a TUM-format folder (frames without
// depth run with an empty depth map, never a crash), the summary CSV, and a run on the first 80 frames of
// the real Bonn crowd sequence (through DYNCULL_DATA_DIR; skipped loudly without it).
#include <gtest/gtest.h>

#include "support/real_data.hpp"

#ifdef DYNCULL_HAS_OPENCV

#include "../../apps/vo/dataset.hpp"

#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace {

using namespace dyncull;
namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("dyncull_dataset_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// A three-frame folder: frame 0 with depth, frame 1 whose depth file is not a PNG, frame 2 without a
// depth partner within 0.02 s.
/// The real sequence under DYNCULL_DATA_DIR; false with why the real-data test cannot run.
bool bonn_crowd_dir(std::string* dir, std::string* why_not) {
  const std::string root = dyncull::test::real_data_dir(why_not);
  if (root.empty()) return false;
  *dir = root + "/bonn/crowd_part1";
  if (!fs::is_directory(*dir)) {
    *why_not = *dir + " does not exist: the real-sequence run did not happen";
    return false;
  }
  return true;
}

fs::path write_small_folder(const std::string& name) {
  const fs::path dir = fresh_dir(name);
  fs::create_directories(dir / "rgb");
  fs::create_directories(dir / "depth");
  cv::Mat grey(48, 64, CV_8UC1, cv::Scalar(90)), depth(48, 64, CV_16UC1, cv::Scalar(10000));
  std::ofstream rgb(dir / "rgb.txt"), dep(dir / "depth.txt");
  for (int i = 0; i < 3; ++i) {
    const std::string t = std::to_string(100 + i) + ".0";
    cv::imwrite((dir / "rgb" / (t + ".png")).string(), grey);
    rgb << t << " rgb/" << t << ".png\n";
  }
  cv::imwrite((dir / "depth/100.001.png").string(), depth);
  std::ofstream(dir / "depth/101.001.png") << "not a png";
  dep << "100.001 depth/100.001.png\n101.001 depth/101.001.png\n102.5 depth/100.001.png\n";
  std::ofstream(dir / "camera.txt") << "fx 50\nfy 50\ncx 32\ncy 24\ndepth_units_per_metre 1000\n";
  return dir;
}

TEST(DatasetSource, FramesWithoutDepthRunWithAnEmptyDepthMap) {
  const fs::path dir = write_small_folder("no_depth");
  vo::DatasetOptions o;
  o.dir = dir.string();
  vo::DatasetSource source;
  std::string error;
  ASSERT_TRUE(source.open(o, &error)) << error;
  ASSERT_EQ(source.size(), 3);
  EXPECT_EQ(source.camera().width, 64);  // from the image, not camera.txt's default
  EXPECT_EQ(source.camera().height, 48);
  EXPECT_DOUBLE_EQ(source.camera().fx, 50);
  EXPECT_FALSE(source.has_detections());
  vo::SequenceFrame f;
  ASSERT_TRUE(source.load(0, &f, &error)) << error;
  EXPECT_FLOAT_EQ(f.depth_m.at<float>(10, 10), 10.0f);  // 10000 units at 1000 per metre
  ASSERT_TRUE(source.load(1, &f, &error)) << error;
  EXPECT_EQ(cv::countNonZero(f.depth_m), 0);
  ASSERT_TRUE(source.load(2, &f, &error)) << error;
  EXPECT_EQ(cv::countNonZero(f.depth_m), 0);
  EXPECT_EQ(source.frames_without_depth(), 2u);
  std::string notes;
  for (const std::string& n : source.notes()) notes += n + "\n";
  EXPECT_NE(notes.find("frame 2 (rgb/102.0.png) has no depth"), std::string::npos) << notes;
  EXPECT_NE(notes.find("101.001.png: not a 16-bit depth image"), std::string::npos) << notes;
  fs::remove_all(dir);
}

// With distortion in camera.txt the source hands the front end undistorted images (so the pinhole model
// holds) and moves the boxes with them: pincushion distortion (k1 > 0) pushes the image's rim outwards, so
// the undistorted corners have no source pixel (0) and a box near the rim moves inwards.
TEST(DatasetSource, DistortedCameraUndistortsImagesDepthAndBoxes) {
  const fs::path dir = write_small_folder("distorted");
  std::ofstream(dir / "camera.txt") << "fx 50\nfy 50\ncx 32\ncy 24\nk1 0.3\ndepth_units_per_metre 1000\n";
  std::ofstream(dir / "yolo.txt") << "100.0 0 0.8 0.5 0.2 0.2 0.9\n";
  vo::DatasetOptions o;
  o.dir = dir.string();
  o.detections = (dir / "yolo.txt").string();
  vo::DatasetSource source;
  std::string error;
  ASSERT_TRUE(source.open(o, &error)) << error;
  vo::SequenceFrame f;
  ASSERT_TRUE(source.load(0, &f, &error)) << error;
  EXPECT_EQ(f.gray.at<std::uint8_t>(24, 32), 90);
  EXPECT_EQ(f.gray.at<std::uint8_t>(0, 0), 0);
  EXPECT_FLOAT_EQ(f.depth_m.at<float>(24, 32), 10.0f);
  EXPECT_EQ(f.depth_m.at<float>(0, 0), 0.0f);
  ASSERT_EQ(f.detections.size(), 1u);
  // Distorted box: x 44.8..57.6 plus 5 px padding = 39.8..62.6; undistorted its right edge moves in.
  EXPECT_LT(f.detections[0].box.x1, 61.0f);
  EXPECT_GT(f.detections[0].box.x1, f.detections[0].box.x0);
  fs::remove_all(dir);
}

TEST(DatasetSource, BadCameraOrDetectionsStopTheOpenWithTheirReason) {
  const fs::path dir = write_small_folder("bad_inputs");
  vo::DatasetOptions o;
  o.dir = dir.string();
  o.camera = "50,50,32";
  vo::DatasetSource source;
  std::string error;
  EXPECT_FALSE(source.open(o, &error));
  EXPECT_NE(error.find("3 numbers given"), std::string::npos) << error;
  o.camera.clear();
  std::ofstream(dir / "yolo.txt") << "100.0 0 0.5 0.5 nan\n";
  o.detections = (dir / "yolo.txt").string();
  vo::DatasetSource again;
  EXPECT_FALSE(again.open(o, &error));
  EXPECT_NE(error.find("yolo.txt:1:"), std::string::npos) << error;
  fs::remove_all(dir);
}

// A camera no lens has (on the command line or in camera.txt, or one that fits camera.txt's default size
// but not the images) stops the open with a reason naming the value: it never runs to the end.
TEST(DatasetSource, AbsurdCamerasStopTheOpenWithTheirReason) {
  const fs::path dir = write_small_folder("absurd_camera");
  vo::DatasetOptions o;
  o.dir = dir.string();
  const std::pair<const char*, const char*> specs[] = {{"1e-300,50,32,24", "fx = 1e-300"},
                                                       {"50,50,-1e300,24", "cx = -1e+300"},
                                                       {"50,50,32,24,1e300,0,0,0,0", "distortion k1 = 1e+300"}};
  for (const auto& spec : specs) {
    o.camera = spec.first;
    vo::DatasetSource source;
    std::string error;
    EXPECT_FALSE(source.open(o, &error)) << spec.first;
    EXPECT_NE(error.find(spec.second), std::string::npos) << error;
  }
  o.camera.clear();
  std::ofstream(dir / "camera.txt") << "fx 50\nfy 50\ncx 32\ncy 24\ndepth_units_per_metre 1e-300\n";
  vo::DatasetSource units;
  std::string error;
  EXPECT_FALSE(units.open(o, &error));
  EXPECT_NE(error.find("depth units per metre = 1e-300"), std::string::npos) << error;
  std::ofstream(dir / "camera.txt") << "fx 50\nfy 50\ncx 500\ncy 24\n";  // fine for 640x480, not for 64x48
  vo::DatasetSource small;
  EXPECT_FALSE(small.open(o, &error));
  EXPECT_NE(error.find("cx = 500 px is more than one image width (64 px)"), std::string::npos) << error;
  fs::remove_all(dir);
}

TEST(DatasetSummary, CsvHasOneRowPerStrategyAndTheNamedColumns) {
  vo::DatasetRow none, rec;
  none.strategy = "none";
  none.frames = 10;
  none.ate_rmse_m = 0.02;
  none.front_end_ms = 30;
  rec.strategy = "recommended";
  rec.culls = true;
  rec.frames = 10;
  rec.lost_frames = 1;
  rec.ate_rmse_m = 0.01;
  rec.culled_in_person_boxes = 0.5;
  rec.culled_in_other_boxes = 0.2;
  rec.culled_outside_boxes = 0.01;
  rec.cull_ms = 1.5;
  rec.front_end_ms = 30;
  std::istringstream csv(vo::dataset_summary_csv({none, rec}));
  std::string header, a, b, extra;
  std::getline(csv, header);
  std::getline(csv, a);
  std::getline(csv, b);
  EXPECT_FALSE(std::getline(csv, extra));
  EXPECT_EQ(header.rfind("strategy,frames,lost_frames,", 0), 0u) << header;
  EXPECT_EQ(a.rfind("none,10,0,", 0), 0u) << a;
  EXPECT_NE(b.find(",0.5000,0.2000,0.0100,1.5000,30.000,0.0500"), std::string::npos) << b;
}

// A feature counts in the person box when it is in one, else in the other classes' boxes when it is in
// one of them, else outside every box.
TEST(DatasetSummary, CullsAreCountedInPersonBoxesOtherBoxesAndOutside) {
  Detection<float> person, chair;
  person.box = {0.f, 0.f, 10.f, 10.f};
  person.class_id = 0;
  chair.box = {5.f, 5.f, 20.f, 20.f};
  chair.class_id = 56;
  const std::vector<cv::Point2f> px = {{2, 2}, {7, 7}, {15, 15}, {16, 16}, {30, 30}, {31, 31}};
  const std::vector<std::uint8_t> keep = {0, 1, 0, 1, 1, 0};
  vo::BoxCullCounts counts;
  counts.add(px, keep, {person, chair});
  EXPECT_EQ(counts.in_person, 2u);  // (7,7) is in both: the person's
  EXPECT_DOUBLE_EQ(counts.culled_in_person_boxes(), 0.5);
  EXPECT_EQ(counts.in_other, 2u);
  EXPECT_DOUBLE_EQ(counts.culled_in_other_boxes(), 0.5);
  EXPECT_EQ(counts.outside, 2u);
  EXPECT_DOUBLE_EQ(counts.culled_outside_boxes(), 0.5);
}

std::map<std::string, std::string> csv_row(const std::string& header, const std::string& line) {
  std::map<std::string, std::string> out;
  std::istringstream h(header), l(line);
  std::string key, value;
  while (std::getline(h, key, ',')) {
    std::getline(l, value, ',');
    out[key] = value;
    value.clear();
  }
  return out;
}

// The ATE before the first person takes only the poses stamped before it: an estimate exact up to then and
// off afterwards has a zero ATE there and a non-zero one over the whole run.
TEST(DatasetSummary, AteBeforePeopleUsesOnlyThePosesBeforeTheFirstPerson) {
  eval::Trajectory<double> truth, estimate;
  for (int i = 0; i < 40; ++i) {
    Rigid3<double> pose = Rigid3<double>::identity();
    pose.t = Vec3<double>(0.01 * i, 0.002 * i * i / 10.0, 0.0);
    truth.push_back(i * 0.1, pose);
    if (i >= 20) pose.t.z() += 0.05 * (i - 19);
    estimate.push_back(i * 0.1, pose);
  }
  EXPECT_NEAR(vo::detail::ate_before(truth, estimate, 2.0), 0.0, 1e-9);
  const eval::AteResult<double> whole = eval::evaluate_ate(truth, estimate);
  ASSERT_TRUE(whole.ok()) << whole.reason;
  EXPECT_GT(whole.error_m.rmse, 0.05);
  EXPECT_TRUE(std::isnan(vo::detail::ate_before(truth, estimate, -1.0))) << "no poses before the first person";

  vo::DatasetRun run;
  run.first_person_frame = 20;
  vo::DatasetRow a, b;
  a.strategy = "none";
  a.ate_before_people_m = 0.012;
  a.rpe_trans_m = 0.05;
  b.strategy = "culler";
  b.ate_before_people_m = 0.011;
  b.rpe_trans_m = 0.03;
  run.rows = {a, b};
  EXPECT_EQ(vo::noise_floor_line(run),
            "Noise floor of the front end: over frames 0-19, before the first person box, the ATE is 1.10 cm at best "
            "(ATE before people); the lowest RPE over 1 s is 3.00 cm (culler).\n");
  std::istringstream csv(vo::dataset_summary_csv(run.rows));
  std::string header, line;
  std::getline(csv, header);
  std::getline(csv, line);
  EXPECT_EQ(csv_row(header, line)["ate_before_people_m"], "0.012000");
}

// The first 80 frames of Bonn crowd (Palazzolo et al. 2019; a person enters at frame 57) with no culling
// and the box-only zhu_2024 preset: the CSV has the columns and finite, plausible values. Bounds are loose
// (the camera moves about 0.3 m over these frames): they catch a broken evaluation, not a tuned figure.
TEST(DatasetRun, BonnCrowdFirstFramesWriteTheSummary) {
  std::string dir, why_not;
  if (!bonn_crowd_dir(&dir, &why_not)) GTEST_SKIP() << why_not;
  const fs::path out = fresh_dir("bonn_run");
  vo::DatasetOptions o;
  o.dir = dir;
  for (const vo::StrategySpec& s : vo::all_strategies())
    if (s.name == "none" || s.name == "zhu_2024") o.strategies.push_back(s);
  ASSERT_EQ(o.strategies.size(), 2u);
  o.runner.out_dir = out.string();
  o.runner.max_frames = 80;
  o.runner.print_progress = false;
  vo::DatasetRun run;
  std::string error;
  ASSERT_TRUE(vo::run_dataset(o, &run, &error)) << error;
  EXPECT_EQ(run.camera_source, dir + "/camera.txt");
  EXPECT_EQ(run.detections_path, dir + "/detections");
  EXPECT_EQ(run.first_person_frame, 57) << "the stored boxes show the first person on frame 57";
  for (const vo::DatasetRow& r : run.rows) {
    EXPECT_GT(r.ate_before_people_m, 0.0) << r.strategy;
    EXPECT_LT(r.ate_before_people_m, 0.05) << r.strategy;
  }

  std::ifstream csv(out / "dataset_summary.csv");
  ASSERT_TRUE(csv.good());
  std::string header, line;
  std::getline(csv, header);
  for (const char* column : {"strategy", "frames", "lost_frames", "ate_rmse_m", "rpe_trans_m", "culled_in_person_boxes",
                             "culled_outside_boxes", "cull_ms", "front_end_ms"})
    EXPECT_NE(("," + header + ",").find(std::string(",") + column + ","), std::string::npos) << column;
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(csv, line))
    if (!line.empty()) rows.push_back(csv_row(header, line));
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0]["strategy"], "none");
  EXPECT_EQ(rows[1]["strategy"], "zhu_2024");
  for (auto& r : rows) {
    EXPECT_EQ(r["frames"], "80");
    EXPECT_LE(std::stoi(r["lost_frames"]), 8) << r["strategy"];
    const double ate = std::stod(r["ate_rmse_m"]), rpe = std::stod(r["rpe_trans_m"]);
    EXPECT_GT(ate, 0.0) << r["strategy"];
    EXPECT_LT(ate, 0.15) << r["strategy"];
    EXPECT_GT(rpe, 0.0) << r["strategy"];
    EXPECT_LT(rpe, 0.3) << r["strategy"];
    EXPECT_GT(std::stod(r["front_end_ms"]), 0.0);
  }
  // No culling culls nothing; the box preset culls inside person boxes (frames 57-79 have people).
  EXPECT_EQ(std::stod(rows[0]["culled_in_person_boxes"]), 0.0);
  EXPECT_GT(std::stod(rows[1]["culled_in_person_boxes"]), 0.5);
  EXPECT_LT(std::stod(rows[1]["culled_outside_boxes"]), 0.05);
  EXPECT_GT(std::stod(rows[1]["cull_ms"]), 0.0);
  for (const char* f : {"crowd_part1_none.txt", "crowd_part1_zhu_2024.txt", "crowd_part1_poses.csv", "crowd_part1_frames.csv",
                        "crowd_part1_frame_strip.png"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  fs::remove_all(out);
}

// Several PnP seeds: one run each, ATE and RPE the median, the ATE's range beside it, and the CSV says how
// many runs; the seeds really change the runs (a single seed gives a zero-width range).
TEST(DatasetRun, SeveralPnpSeedsGiveTheMedianAndTheRange) {
  EXPECT_DOUBLE_EQ(vo::detail::median_of({3.0, 1.0, std::numeric_limits<double>::quiet_NaN(), 2.0}), 2.0);
  EXPECT_DOUBLE_EQ(vo::detail::median_of({4.0, 1.0}), 2.5);
  EXPECT_TRUE(std::isnan(vo::detail::median_of({})));
  std::string dir, why_not;
  if (!bonn_crowd_dir(&dir, &why_not)) GTEST_SKIP() << why_not;
  const fs::path out = fresh_dir("bonn_seeds");
  vo::DatasetOptions o;
  o.dir = dir;
  for (const vo::StrategySpec& s : vo::all_strategies())
    if (s.name == "none") o.strategies.push_back(s);
  o.runner.out_dir = out.string();
  o.runner.max_frames = 40;
  o.runner.print_progress = false;
  o.pnp_seeds = {7, 8, 9};
  vo::DatasetRun run;
  std::string error;
  ASSERT_TRUE(vo::run_dataset(o, &run, &error)) << error;
  ASSERT_EQ(run.rows.size(), 1u);
  const vo::DatasetRow& r = run.rows[0];
  EXPECT_EQ(r.runs, 3u);
  EXPECT_LE(r.ate_min_m, r.ate_rmse_m);
  EXPECT_LE(r.ate_rmse_m, r.ate_max_m);
  EXPECT_LT(r.ate_min_m, r.ate_max_m) << "three seeds gave the same ATE: the seed did not reach the front end";
  std::ifstream csv(out / "dataset_summary.csv");
  std::string header, line;
  std::getline(csv, header);
  std::getline(csv, line);
  EXPECT_EQ(csv_row(header, line)["runs"], "3");
  fs::remove_all(out);
}

}  // namespace

#else

TEST(DatasetRun, NeedsOpenCv) { GTEST_SKIP() << "dynamic_vo needs the OpenCV adapter (OpenCV 4 not found)"; }

#endif
