// Smoke and unit tests of the dynamic_vo demo's pieces (apps/vo/*.hpp): the VO with and without
// culling on a short synthetic walking sequence, the label counting, and the TUM directory reader.
#include <gtest/gtest.h>

#ifdef DYNCULL_HAS_OPENCV

#include "../../apps/vo/ablation.hpp"
#include "../../apps/vo/runner.hpp"
#include "dyncull/sim/families.hpp"

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace dyncull;

const vo::StrategySpec* find_spec(const std::vector<vo::StrategySpec>& all, bool recommended) {
  for (const auto& s : all)
    if (recommended ? s.recommended : !s.culls) return &s;
  return nullptr;
}

// Runs the strategies on the first `frames` frames of the sim's xyz walking sequence (no files, no progress).
bool run_short_xyz(int frames, const std::vector<vo::StrategySpec>& strategies, vo::SequenceReport* report,
                   std::string* error) {
  sim::SceneOptions so;
  so.motion = sim::CameraMotion::Xyz;
  so.num_frames = frames;
  vo::SimSource source(so);
  vo::RunnerOptions ro;
  ro.max_frames = frames;
  ro.write_outputs = false;
  ro.print_progress = false;
  if (!vo::run_sequence("xyz", source, strategies, ro, report, error)) return false;
  vo::evaluate_against_recorded_truth(report, ro);
  return true;
}

// 45 frames of the sim's xyz walking sequence, where the two slow walkers crossing close to the
// camera pull the un-culled front end off (measured: 106 mm ATE after 1.5 s, `dynamic_vo --sequences xyz
// --frames 45 --seeds 1`): the recommended preset must cut that ATE by a clear margin
// (measured 4.1 mm, -96 %) and label most moving features (measured precision 0.97, recall 0.97; over
// 300 frames recall and, but for rpy, precision are below the 0.9 target, see docs/results.md; the
// bounds here guard against regressions, not the target).
TEST(DynamicVo, RecommendedPresetBeatsNoCullingOnShortXyz) {
  const auto all = vo::all_strategies();
  const vo::StrategySpec* none = find_spec(all, false);
  const vo::StrategySpec* preset = find_spec(all, true);
  ASSERT_NE(none, nullptr);
  ASSERT_NE(preset, nullptr) << "no recommended preset in vo::all_strategies()";

  vo::SequenceReport report;
  std::string error;
  ASSERT_TRUE(run_short_xyz(45, {*none, *preset}, &report, &error)) << error;
  ASSERT_EQ(report.runs.size(), 2u);
  const vo::StrategyRun& a = report.runs[0];
  const vo::StrategyRun& b = report.runs[1];
  ASSERT_TRUE(a.has_ate) << a.ate_note;
  ASSERT_TRUE(b.has_ate) << b.ate_note;
  EXPECT_EQ(a.ate_pairs, 45u);
  // The scene is hard: without culling the walkers visibly pull the pose off.
  EXPECT_GT(a.ate_rmse_m, 0.03) << "none " << a.ate_rmse_m << " m: the walkers no longer pull the front end off";
  // Culling beats no culling by a clear margin, not by run-to-run noise.
  EXPECT_LT(b.ate_rmse_m, 0.5 * a.ate_rmse_m) << "culled " << b.ate_rmse_m << " m vs none " << a.ate_rmse_m << " m";
  EXPECT_GT(b.labels.precision(), 0.6);
  EXPECT_GT(b.labels.recall(), 0.8);
  // No culling never culls: its counts have no positives at all.
  EXPECT_EQ(a.labels.true_positive + a.labels.false_positive, 0u);
}

// The diagnostic copies of the recommended preset undo one kind of error by the truth: no false culls leaves
// no static feature culled, no misses leaves no moving feature kept. They are not in the default run and
// need the sim's truth.
TEST(DynamicVo, TruthRepairedStrategiesUndoOneKindOfError) {
  const auto all = vo::all_strategies();
  const vo::StrategySpec* preset = find_spec(all, true);
  ASSERT_NE(preset, nullptr);
  std::vector<vo::StrategySpec> run{*preset};
  for (const char* name : {"recommended_no_false_culls", "recommended_no_misses"}) {
    const auto it = std::find_if(all.begin(), all.end(), [&](const vo::StrategySpec& s) { return s.name == name; });
    ASSERT_NE(it, all.end()) << name;
    EXPECT_FALSE(it->in_default) << name;
    EXPECT_TRUE(it->needs_truth()) << name;
    EXPECT_FALSE(it->recommended) << name << ": only the preset itself is the table's default row";
    EXPECT_TRUE(it->tracks_from_keyframe) << name << ": must see the tracks the preset sees";
    run.push_back(*it);
  }
  EXPECT_FALSE(preset->needs_truth());

  vo::SequenceReport report;
  std::string error;
  ASSERT_TRUE(run_short_xyz(30, run, &report, &error)) << error;
  ASSERT_EQ(report.runs.size(), 3u);
  const vo::LabelCounts& plain = report.runs[0].labels;
  const vo::LabelCounts& no_false_culls = report.runs[1].labels;
  const vo::LabelCounts& no_misses = report.runs[2].labels;
  // The preset itself makes both kinds of error here, so the repairs have something to undo.
  EXPECT_GT(plain.false_positive, 0u);
  EXPECT_GT(plain.false_negative, 0u);
  EXPECT_EQ(no_false_culls.false_positive, 0u);
  EXPECT_GT(no_false_culls.false_negative, 0u) << "its misses must stay";
  EXPECT_GT(no_false_culls.true_positive, 0u);
  EXPECT_EQ(no_misses.false_negative, 0u);
  EXPECT_GT(no_misses.false_positive, 0u) << "its false culls must stay";
}

// A static camera must stay put: every frame's estimate within a few centimetres of the truth.
TEST(DynamicVo, StaticCameraStaysStillWithCulling) {
  const auto all = vo::all_strategies();
  const vo::StrategySpec* preset = find_spec(all, true);
  ASSERT_NE(preset, nullptr);
  sim::SceneOptions so;
  so.motion = sim::CameraMotion::Static;
  so.num_frames = 20;
  vo::SimSource source(so);
  vo::RunnerOptions ro;
  ro.max_frames = 20;
  ro.write_outputs = false;
  ro.print_progress = false;
  vo::SequenceReport report;
  std::string error;
  ASSERT_TRUE(vo::run_sequence("static", source, {*preset}, ro, &report, &error)) << error;
  ASSERT_EQ(report.runs[0].estimate.size(), 20u);
  for (std::size_t i = 0; i < 20; ++i) {
    const double d = (report.runs[0].estimate.poses[i].t - report.truth.poses[i].t).norm();
    EXPECT_LT(d, 0.05) << "frame " << i;
  }
}

// The "culler" strategy runs the recommended preset through the stateful culler as a host would (ORB
// descriptors at the tracked keypoints, the culler's own keyframe matching and keyframes): on the short xyz
// walking sequence it must cut no culling's ATE by a clear margin and label most moving features, like the
// hand-fed preset above (measured over 45 frames: 3.4 mm against 3.5 mm hand-fed, precision 0.98, recall 0.99).
TEST(DynamicVo, CullerStrategyBeatsNoCullingOnShortXyz) {
  const auto all = vo::all_strategies();
  const vo::StrategySpec* none = find_spec(all, false);
  const auto culler = std::find_if(all.begin(), all.end(), [](const vo::StrategySpec& s) { return s.name == "culler"; });
  ASSERT_NE(none, nullptr);
  ASSERT_NE(culler, all.end()) << "no 'culler' strategy in vo::all_strategies()";
  EXPECT_TRUE(culler->through_culler);
  EXPECT_FALSE(culler->recommended) << "only the hand-fed preset is the table's default row";
  EXPECT_FALSE(culler->needs_truth());

  vo::SequenceReport report;
  std::string error;
  ASSERT_TRUE(run_short_xyz(45, {*none, *culler}, &report, &error)) << error;
  ASSERT_EQ(report.runs.size(), 2u);
  const vo::StrategyRun& a = report.runs[0];
  const vo::StrategyRun& b = report.runs[1];
  ASSERT_TRUE(a.has_ate) << a.ate_note;
  ASSERT_TRUE(b.has_ate) << b.ate_note;
  EXPECT_LT(b.ate_rmse_m, 0.5 * a.ate_rmse_m) << "culler " << b.ate_rmse_m << " m vs none " << a.ate_rmse_m << " m";
  EXPECT_GT(b.labels.precision(), 0.6);
  EXPECT_GT(b.labels.recall(), 0.8);
}

// Frame by frame through the culler strategy: after the first frame (no keyframe yet) the culler's status is
// Ok, so no input was missing or malformed and the keep mask is its decision, not its refusal; ORB gives
// every tracked keypoint a descriptor (the front end keeps tracks at least its border_px / 2 from the edge,
// which is ORB's edge threshold here), so no track is kept unasked.
TEST(DynamicVo, CullerStrategyGetsEveryInputAndADescriptorPerTrack) {
  const auto all = vo::all_strategies();
  const auto spec = std::find_if(all.begin(), all.end(), [](const vo::StrategySpec& s) { return s.through_culler; });
  ASSERT_NE(spec, all.end());
  sim::SceneOptions so;
  so.motion = sim::CameraMotion::Xyz;
  so.num_frames = 20;
  vo::SimSource source(so);
  vo::FrontEndOptions fo;
  ASSERT_EQ(fo.border_px / 2, vo::Culler::kOrbEdgePx);
  vo::FrontEnd front_end(source.camera(), fo);
  vo::Culler culler(*spec, source.camera());
  vo::SequenceFrame frame;
  std::vector<std::uint8_t> keep;
  std::size_t culled = 0, keyframes = 0, matched = 0, features = 0;
  for (int i = 0; i < so.num_frames; ++i) {
    std::string error;
    ASSERT_TRUE(source.load(i, &frame, &error)) << error;
    front_end.track(vo::FrameInput{frame.timestamp, frame.gray, frame.depth_m});
    culler.cull(frame, front_end.tracks(), front_end.predicted_world_from_cam(), front_end.frames_since_keyframe(),
                &keep);
    ASSERT_EQ(keep.size(), front_end.tracks().size());
    ASSERT_NE(culler.culler_result(), nullptr);
    const CullerResult& r = *culler.culler_result();
    if (i > 0) {
      EXPECT_EQ(r.status, Status::Ok) << "frame " << i << ": " << r.reason;
      EXPECT_EQ(culler.without_descriptor(), 0u) << "frame " << i;
      EXPECT_EQ(r.num_features, keep.size()) << "frame " << i;
    }
    // Frame 0 has no tracks (the front end detects after it) and frame 1 replaces that empty keyframe.
    if (i > 1) {
      matched += r.matched;
      features += r.num_features;
    }
    keyframes += r.keyframe ? 1 : 0;
    culled += static_cast<std::size_t>(std::count(keep.begin(), keep.end(), 0));
    front_end.estimate(keep);
  }
  std::printf("culler strategy: %zu of %zu keypoints matched the culler's keyframe, %zu keyframes, %zu culled\n",
              matched, features, keyframes, culled);
  EXPECT_GT(culled, 0u);
  EXPECT_GE(keyframes, 2u) << "the culler's own policy made no keyframe after the first";
  // Measured 0.55: the front end adds corners at its own keyframes, which the culler's keyframe lacks until
  // its next one.
  EXPECT_GT(matched, features * 45 / 100) << "few keypoints matched the culler's keyframe";
}

TEST(DynamicVo, LabelCountsAgainstTruth) {
  cv::Mat moving(10, 10, CV_8UC1, cv::Scalar(0));
  moving(cv::Rect(0, 0, 5, 10)).setTo(1);  // left half moves
  std::vector<cv::Point2f> px = {{1, 1}, {2, 2}, {7, 7}, {8, 8}, {1, 8}, {50, 50}};
  std::vector<std::uint8_t> keep = {0, 0, 0, 1, 1, 0};  // last one is outside: not counted
  std::vector<Detection<float>> boxes = {Detection<float>{Box<float>{6, 6, 9, 9}, 0, 1.f}};
  vo::LabelCounts c;
  vo::count_labels(px, keep, moving, boxes, &c);
  EXPECT_EQ(c.true_positive, 2u);
  EXPECT_EQ(c.false_positive, 1u);
  EXPECT_EQ(c.false_negative, 1u);
  EXPECT_EQ(c.true_negative, 1u);
  EXPECT_EQ(c.static_in_box, 2u);
  EXPECT_EQ(c.static_in_box_kept, 1u);
  EXPECT_DOUBLE_EQ(c.precision(), 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(c.recall(), 2.0 / 3.0);
  vo::LabelCounts empty;
  EXPECT_TRUE(std::isnan(empty.precision()));
}

// --diagnose: recall of the moving features split by their truth speed (mm a frame) and instance; static
// features and points outside the image are not counted, a band edge belongs to the faster band.
TEST(DynamicVo, RecallBySpeedBandsAndInstances) {
  cv::Mat moving(10, 10, CV_8UC1, cv::Scalar(0));
  moving(cv::Rect(0, 0, 5, 10)).setTo(1);  // left half moves
  cv::Mat motion(10, 10, CV_32FC1, cv::Scalar(0));
  motion.at<float>(1, 1) = 0.001f;   // < 2 mm
  motion.at<float>(2, 2) = 0.002f;   // 2-5 mm (edge)
  motion.at<float>(3, 3) = 0.012f;   // >= 10 mm
  motion.at<float>(4, 4) = 0.012f;   // >= 10 mm
  cv::Mat instance(10, 10, CV_16UC1, cv::Scalar(1));
  instance.at<std::uint16_t>(4, 4) = 3;
  const std::vector<cv::Point2f> px = {{1, 1}, {2, 2}, {3, 3}, {4, 4}, {7, 7}, {50, 50}};
  const std::vector<std::uint8_t> keep = {0, 1, 0, 1, 0, 0};
  vo::RecallBySpeed r;
  r.add(px, keep, moving, motion, instance);
  const auto at = [](const std::array<std::size_t, vo::RecallBySpeed::kInstances * vo::RecallBySpeed::kBands>& a,
                     int inst, int band) { return a[static_cast<std::size_t>(inst * vo::RecallBySpeed::kBands + band)]; };
  EXPECT_EQ(at(r.moving, 1, 0), 1u);
  EXPECT_EQ(at(r.culled, 1, 0), 1u);
  EXPECT_EQ(at(r.moving, 1, 1), 1u);
  EXPECT_EQ(at(r.culled, 1, 1), 0u);
  EXPECT_EQ(at(r.moving, 1, 3), 1u);
  EXPECT_EQ(at(r.culled, 1, 3), 1u);
  EXPECT_EQ(at(r.moving, 3, 3), 1u);
  EXPECT_EQ(at(r.culled, 3, 3), 0u);
  std::size_t total = 0;
  for (std::size_t m : r.moving) total += m;
  EXPECT_EQ(total, 4u);
  const std::string text = r.format();
  EXPECT_NE(text.find("all:  < 2 mm 1/1 (1.00)  2-5 mm 0/1 (0.00)  5-10 mm 0/0  >= 10 mm 1/2 (0.50)"), std::string::npos)
      << text;
  EXPECT_NE(text.find("sitting_person:"), std::string::npos) << text;
  EXPECT_EQ(text.find("background:"), std::string::npos) << text;  // no moving features there
  vo::RecallBySpeed none;
  none.add(px, keep, moving, cv::Mat(), instance);  // no truth (TUM): nothing counted
  EXPECT_EQ(none.format().find("all:"), std::string::npos);
}

// rgb.txt / depth.txt association (nearest within 0.02 s), depth scale 5000 and YOLO detections.
// --seeds: per sequence and strategy the median ATE over the seeds, the median of the per-seed
// improvements, and labels pooled over the seeds (not averaged per seed).
TEST(DynamicVo, SeedSummaryGivesMediansAndPooledLabels) {
  const auto all = vo::all_strategies();
  const vo::StrategySpec* none = find_spec(all, false);
  const vo::StrategySpec* preset = find_spec(all, true);
  ASSERT_NE(none, nullptr);
  ASSERT_NE(preset, nullptr);
  const double none_ate[3] = {0.10, 0.02, 0.20}, culled_ate[3] = {0.01, 0.01, 0.05};
  const std::size_t tp[3] = {9, 1, 0}, fp[3] = {1, 1, 0}, fn[3] = {0, 0, 9};
  std::vector<vo::SequenceReport> reports(3);
  for (int k = 0; k < 3; ++k) {
    vo::SequenceReport& r = reports[static_cast<std::size_t>(k)];
    r.sequence = "xyz";
    r.seed = static_cast<std::uint64_t>(k + 1);
    r.has_label_truth = true;
    r.runs.resize(2);
    r.runs[0].spec = *none;
    r.runs[1].spec = *preset;
    r.runs[0].has_ate = r.runs[1].has_ate = true;
    r.runs[0].ate_rmse_m = none_ate[k];
    r.runs[1].ate_rmse_m = culled_ate[k];
    r.runs[1].labels.true_positive = tp[k];
    r.runs[1].labels.false_positive = fp[k];
    r.runs[1].labels.false_negative = fn[k];
  }
  const std::string table = vo::format_seed_summary(reports);
  // none: median of 0.10 / 0.02 / 0.20 is 0.10. Preset: median 0.01; improvements 90 / 50 / 75 % -> 75 %.
  EXPECT_NE(table.find("| xyz | none | 3 | 0.1000 | 0.1000 / 0.0200 / 0.2000 |"), std::string::npos) << table;
  EXPECT_NE(table.find("| 3 | 0.0100 | 0.0100 / 0.0100 / 0.0500 | 75.0 % |"), std::string::npos) << table;
  // Pooled: precision 10 / 12, recall 10 / 19 (per-seed averages would give 0.61 and 0.67).
  EXPECT_NE(table.find("| 0.833 | 0.526 |"), std::string::npos) << table;
}

// Random grey rectangles: corners for ORB, texture for LK.
cv::Mat rectangle_texture(int size) {
  cv::Mat canvas(size, size, CV_8UC1, cv::Scalar(128));
  cv::RNG rng(12345);
  for (int i = 0; i < size * size / 480; ++i) {
    const int x = rng.uniform(0, size - 10), y = rng.uniform(0, size - 10);
    cv::rectangle(canvas, cv::Rect(x, y, rng.uniform(4, 30), rng.uniform(4, 30)), cv::Scalar(rng.uniform(0, 256)), -1);
  }
  cv::GaussianBlur(canvas, canvas, cv::Size(3, 3), 0.8);
  return canvas;
}

// The front end's refinement against the keyframe when the camera rolls 1 deg a frame over a textured
// plane 2 m away (pure rotation: every pixel's truth is the homography K R K^-1 of its keyframe position).
// Returns the tracks' RMS error against that truth after `frames` frames, or -1 when a keyframe was made.
double rolled_track_rms_px(bool rotation_compensated, int frames) {
  const PinholeCamera<double> cam{525, 525, 319.5, 239.5, 640, 480};
  const cv::Mat canvas = rectangle_texture(1200);  // larger than the image: no empty border when turned
  const double ox = 600 - cam.cx, oy = 600 - cam.cy;  // frame 0's pixel (0, 0) on the canvas
  const Mat3<double> K = cam.K();
  auto frame0_from_frame = [&](int k) {  // pixel of frame k -> pixel of frame 0 (roll about the optical axis)
    const double a = k * Constants<double>::deg_to_rad();
    Mat3<double> R;
    R << std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1;
    return Mat3<double>(K * R * K.inverse());
  };

  vo::FrontEndOptions options;
  options.refine_rotation_compensated = rotation_compensated;
  options.keyframe_max_rotation_deg = 90;  // keep frame 0 as the keyframe throughout
  options.keyframe_min_inliers = 0;
  options.keyframe_min_tracked_ratio = 0;
  vo::FrontEnd front_end(cam, options);
  const cv::Mat depth(480, 640, CV_32FC1, cv::Scalar(2.f));  // a roll keeps a fronto-parallel plane's depth
  cv::Mat gray;
  for (int k = 0; k <= frames; ++k) {
    Mat3<double> h = frame0_from_frame(k);
    h.row(0) += ox * h.row(2);
    h.row(1) += oy * h.row(2);
    const cv::Matx33d canvas_from_frame(h(0, 0), h(0, 1), h(0, 2), h(1, 0), h(1, 1), h(1, 2), h(2, 0), h(2, 1), h(2, 2));
    cv::warpPerspective(canvas, gray, canvas_from_frame, cv::Size(640, 480), cv::INTER_LINEAR | cv::WARP_INVERSE_MAP);
    front_end.track(vo::FrameInput{k / 30.0, gray, depth});
    const vo::FrameStats stats = front_end.estimate(std::vector<std::uint8_t>(front_end.tracks().size(), 1));
    if (k > 0 && stats.keyframe) return -1;
  }
  const vo::Tracks& t = front_end.tracks();
  const Mat3<double> frame_from_frame0 = frame0_from_frame(frames).inverse();
  double sum_sq = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    const Vec3<double> q = frame_from_frame0 * Vec3<double>(t.kf_px[i].x, t.kf_px[i].y, 1.0);
    const double du = q.x() / q.z() - t.cur_px[i].x, dv = q.y() / q.z() - t.cur_px[i].y;
    sum_sq += du * du + dv * dv;
  }
  return t.size() > 100 ? std::sqrt(sum_sq / static_cast<double>(t.size())) : -1;
}

// Beyond 5 deg from the keyframe the keyframe patch is turned by the predicted rotation before the
// refinement; without that the tracks are frame-to-frame LK only from there on and their error adds up.
TEST(DynamicVo, RefinementAgainstTurnedKeyframeKeepsRolledTracksAccurate) {
  const double compensated = rolled_track_rms_px(true, 15), frame_to_frame = rolled_track_rms_px(false, 15);
  ASSERT_GT(compensated, 0) << "a keyframe was made or too few tracks survived";
  ASSERT_GT(frame_to_frame, 0) << "a keyframe was made or too few tracks survived";
  std::printf("RMS track error after a 15 deg roll: %.3f px compensated, %.3f px frame to frame\n", compensated,
              frame_to_frame);
  EXPECT_LT(compensated, 0.5 * frame_to_frame);
  EXPECT_LT(compensated, 0.1);  // measured 0.017 px (frame to frame 1.19 px)
}

// At a keyframe the budget freed by the tracks the culling removed is not spent on new corners next to
// them (they would be on the same mover, seen with a one-frame baseline); without the option it is.
TEST(DynamicVo, NewCornersKeepAwayFromCulledTracks) {
  const PinholeCamera<double> cam{525, 525, 319.5, 239.5, 640, 480};
  const cv::Mat texture = rectangle_texture(640)(cv::Rect(0, 0, 640, 480)).clone();
  const cv::Mat depth(480, 640, CV_32FC1, cv::Scalar(2.f));
  auto new_corners_near_culled = [&](bool away, std::size_t* culled) {
    vo::FrontEndOptions options;
    options.detect_away_from_culled = away;
    options.keyframe_min_inliers = 100000;  // every frame becomes a keyframe
    vo::FrontEnd front_end(cam, options);
    front_end.track(vo::FrameInput{0.0, texture, depth});
    front_end.estimate({});
    front_end.track(vo::FrameInput{1 / 30.0, texture, depth});
    // Cull every track in the left half of the image (a "mover" there).
    const vo::Tracks& before = front_end.tracks();
    std::vector<std::uint8_t> keep(before.size(), 1);
    std::vector<cv::Point2f> culled_px;
    for (std::size_t i = 0; i < before.size(); ++i)
      if (before.cur_px[i].x < 320) {
        keep[i] = 0;
        culled_px.push_back(before.cur_px[i]);
      }
    std::set<std::uint32_t> old_ids(before.ids.begin(), before.ids.end());
    EXPECT_TRUE(front_end.estimate(keep).keyframe);
    *culled = culled_px.size();
    std::size_t near = 0;
    const vo::Tracks& after = front_end.tracks();
    const double r = options.min_feature_distance_px;
    for (std::size_t i = 0; i < after.size(); ++i) {
      if (old_ids.count(after.ids[i])) continue;  // a track carried over, not a new corner
      for (const cv::Point2f& c : culled_px)
        if (std::hypot(after.cur_px[i].x - c.x, after.cur_px[i].y - c.y) < r - 1) {
          ++near;
          break;
        }
    }
    return near;
  };
  std::size_t culled_away = 0, culled_plain = 0;
  const std::size_t near_away = new_corners_near_culled(true, &culled_away);
  const std::size_t near_plain = new_corners_near_culled(false, &culled_plain);
  ASSERT_GT(culled_away, 100u) << "too few tracks in the culled half";
  std::printf("new corners near culled tracks: %zu with the option, %zu without (%zu culled)\n", near_away, near_plain, culled_away);
  EXPECT_EQ(near_away, 0u);
  EXPECT_GT(near_plain, 50u) << "without the option the freed budget goes back to the culled half";
}

// A keyframe every keyframe_max_translation_m of travel (default 0.1 m): the camera slides sideways
// 3 cm a frame in front of a textured plane 2 m away, so the other keyframe rules (inliers, tracked
// share, turn) stay quiet and the first keyframe after frame 0 is the one past 0.1 m, frame 4 (0.12 m).
// frames_since_keyframe() counts the frames in between.
TEST(DynamicVo, KeyframeAfterTenCentimetresOfTravel) {
  const PinholeCamera<double> cam{525, 525, 319.5, 239.5, 640, 480};
  const cv::Mat canvas = rectangle_texture(1200);
  const cv::Mat depth(480, 640, CV_32FC1, cv::Scalar(2.f));
  const vo::FrontEndOptions options;
  EXPECT_DOUBLE_EQ(options.keyframe_max_translation_m, 0.1);
  vo::FrontEnd front_end(cam, options);
  constexpr double kStepM = 0.03, kDepthM = 2.0;
  int first_keyframe = -1;
  for (int k = 0; k <= 8 && first_keyframe < 0; ++k) {
    // Camera at x = k * step: the plane's texture moves left by f * x / Z pixels.
    const double shift_px = cam.fx * kStepM * k / kDepthM;
    const cv::Matx23d canvas_from_frame(1, 0, 300 + shift_px, 0, 1, 300);
    cv::Mat gray;
    cv::warpAffine(canvas, gray, canvas_from_frame, cv::Size(640, 480), cv::INTER_LINEAR | cv::WARP_INVERSE_MAP);
    front_end.track(vo::FrameInput{k / 30.0, gray, depth});
    const int since_keyframe = front_end.frames_since_keyframe();  // the culling's baseline (evidence_frames)
    const vo::FrameStats stats = front_end.estimate(std::vector<std::uint8_t>(front_end.tracks().size(), 1));
    if (k > 0) {
      EXPECT_EQ(since_keyframe, k);
      ASSERT_FALSE(stats.fallback) << "frame " << k << ": " << stats.reason;
      const double error_m = (front_end.world_from_cam().t - Vec3<double>(kStepM * k, 0, 0)).norm();
      EXPECT_LT(error_m, 0.005) << "frame " << k << ": pose off the truth";
    }
    if (k > 0 && stats.keyframe) first_keyframe = k;
  }
  EXPECT_EQ(first_keyframe, 4);
  EXPECT_EQ(front_end.frames_since_keyframe(), 0);
}

// Per family: median ATE over its motions x seeds for each strategy, the recommended / oracle and
// recommended / none ratios of those medians, the worst motion's ratio, and labels pooled over the runs.
TEST(DynamicVo, FamilySummaryGivesMediansRatiosAndPooledLabels) {
  const auto all = vo::all_strategies();
  const vo::StrategySpec* none = find_spec(all, false);
  const vo::StrategySpec* preset = find_spec(all, true);
  const auto oracle = std::find_if(all.begin(), all.end(), [](const vo::StrategySpec& s) { return s.oracle; });
  ASSERT_NE(none, nullptr);
  ASSERT_NE(preset, nullptr);
  ASSERT_NE(oracle, all.end());
  struct Run {
    const char* family;
    const char* motion;
    double none_m, rec_m, oracle_m;
    std::size_t tp, fp, fn;
  };
  const Run runs[] = {
      {"walking", "xyz", 0.10, 0.020, 0.010, 9, 1, 0},  {"walking", "xyz", 0.20, 0.030, 0.030, 1, 1, 0},
      {"walking", "rpy", 0.30, 0.040, 0.020, 0, 0, 9},  {"walking", "rpy", 0.05, 0.060, 0.040, 0, 0, 0},
      {"sitting", "xyz", 0.01, 0.012, 0.010, 5, 5, 0},
  };
  std::vector<vo::SequenceReport> reports;
  for (const Run& r : runs) {
    vo::SequenceReport rep;
    rep.family = r.family;
    rep.sequence = r.motion;
    rep.has_label_truth = true;
    rep.runs.resize(3);
    rep.runs[0].spec = *none;
    rep.runs[1].spec = *preset;
    rep.runs[2].spec = *oracle;
    const double ate[3] = {r.none_m, r.rec_m, r.oracle_m};
    for (int k = 0; k < 3; ++k) {
      rep.runs[static_cast<std::size_t>(k)].has_ate = true;
      rep.runs[static_cast<std::size_t>(k)].ate_rmse_m = ate[k];
      rep.runs[static_cast<std::size_t>(k)].frames = 10;
      rep.runs[static_cast<std::size_t>(k)].front_end_ms = 100;
    }
    rep.runs[1].labels.true_positive = r.tp;
    rep.runs[1].labels.false_positive = r.fp;
    rep.runs[1].labels.false_negative = r.fn;
    rep.runs[1].cull_ms = 5;
    reports.push_back(rep);
  }
  const std::vector<vo::FamilyStrategySummary> rows = vo::summarise_families(reports);
  // walking: all + xyz + rpy, sitting: all + xyz; three strategies each.
  ASSERT_EQ(rows.size(), (3u + 2u) * 3u);
  const std::string table = vo::format_family_summary(rows);
  // walking medians: none 0.075 / 0.20 / 0.30 / 0.05 -> 0.15 m; recommended 0.035 m; oracle 0.025 m.
  // Ratios 1.40 and 0.23; worst motion rpy: median 0.05 over 0.03 = 1.67 (xyz: 0.025 / 0.02 = 1.25).
  // Pooled labels: precision 10 / 12, recall 10 / 19.
  EXPECT_NE(table.find("| walking | 4 | 15.00 | 3.50 | 2.50 | 1.40 | 1.67 (rpy) | 0.23 | 0.833 | 0.526 | 0.050 |"),
            std::string::npos)
      << table;
  EXPECT_NE(table.find("| sitting | 1 | 1.00 | 1.20 | 1.00 | 1.20 | 1.20 (xyz) | 1.20 | 0.500 | 1.000 |"), std::string::npos)
      << table;
  const std::string csv = vo::family_summary_csv(rows);
  EXPECT_EQ(csv.rfind("family,motion,strategy,", 0), 0u) << csv;
  EXPECT_NE(csv.find("\nwalking,all,recommended,1,0,4,0.035000,"), std::string::npos) << csv;
  EXPECT_NE(csv.find("\nwalking,rpy,oracle,0,1,2,0.030000,"), std::string::npos) << csv;
  EXPECT_NE(csv.find("\nsitting,all,none,0,0,1,0.010000,,"), std::string::npos) << csv;
  std::size_t lines = 0;
  for (char c : csv) lines += c == '\n' ? 1 : 0;
  EXPECT_EQ(lines, rows.size() + 1);
}

// The fields the ablation switches touch, as text: each switch must change it (a switch that changes
// nothing, because the preset came to use the library default, is dead and should go).
std::string ablated_fields(const vo::StrategySpec& s) {
  const PipelineOptions<float>& o = s.pipeline;
  std::ostringstream t;
  t << o.detections.enabled << o.tracker.enabled << o.box_rule.enabled << o.depth_mask.enabled
    << o.moving_consistency.enabled << o.reprojection.enabled << o.edge_evidence.enabled << o.coherent_motion.enabled
    << o.subbox.enabled << o.static_history.enabled << o.guard.enabled << s.tracks_from_keyframe
    << static_cast<int>(o.depth_mask.missing_depth) << " " << o.depth_mask.eps_m << " "
    << o.moving_consistency.max_epipolar_distance_in_boxes_px << " " << o.reprojection.max_depth_residual_sigmas << " "
    << o.depth_mask.assign_overlaps_by_depth << " " << o.depth_mask.overlap_high_level_margin_m << " "
    << o.depth_mask.low_override_by_depth << " " << o.depth_mask.head_band_fraction << " " << o.subbox.object_mask_votes_only << o.subbox.static_needs_evidence
    << o.subbox.verifies_candidates << " " << o.subbox.min_evidence_frames << o.subbox.short_baseline_keeps_last_vote;
  return t.str();
}

TEST(DynamicVo, AblationStrategiesEachUndoOneThingOfTheRecommendedPreset) {
  const auto all = vo::all_strategies();
  const vo::StrategySpec* preset = find_spec(all, true);
  ASSERT_NE(preset, nullptr);
  const std::vector<vo::StrategySpec> ablations = vo::ablation_strategies();
  ASSERT_EQ(ablations.size(), vo::ablation_switches().size());
  std::set<std::string> names;
  for (const vo::StrategySpec& s : all) names.insert(s.name);
  std::set<std::string> changed;
  for (const vo::StrategySpec& s : ablations) {
    EXPECT_EQ(s.name.rfind("recommended-no_", 0), 0u) << s.name;
    EXPECT_TRUE(names.insert(s.name).second) << "duplicate strategy " << s.name;
    EXPECT_FALSE(s.in_default) << s.name;
    EXPECT_FALSE(s.recommended) << s.name;
    EXPECT_TRUE(s.culls) << s.name;
    EXPECT_FALSE(s.needs_truth()) << s.name;
    std::string reason;
    EXPECT_EQ(s.pipeline.validate(&reason), Status::Ok) << s.name << ": " << reason << " (the pipeline would refuse it)";
    const std::string fields = ablated_fields(s);
    EXPECT_NE(fields, ablated_fields(*preset)) << s.name << " changes nothing";
    EXPECT_TRUE(changed.insert(fields).second) << s.name << " repeats another switch";
  }
  for (const char* stage : {"recommended-no_depth_mask", "recommended-no_subbox", "recommended-no_static_history",
                            "recommended-no_reprojection", "recommended-no_keyframe_tracks"})
    EXPECT_TRUE(names.count(stage)) << stage;
}

// A family's scene runs through the demo unchanged: the sitting family, 12 frames, no culling and the preset.
TEST(DynamicVo, FamilySceneRunsThroughTheFrontEnd) {
  sim::SceneFamily family;
  ASSERT_TRUE(sim::find_scene_family("sitting", &family));
  sim::SceneOptions so = family.options;
  ASSERT_EQ(sim::apply_scene_assignments(&so, "motion=rpy,num_frames=12,seed=4"), Status::Ok);
  const auto all = vo::all_strategies();
  vo::SimSource source(so);
  vo::RunnerOptions ro;
  ro.max_frames = 12;
  ro.write_outputs = false;
  ro.print_progress = false;
  vo::SequenceReport report;
  report.family = family.name;
  std::string error;
  ASSERT_TRUE(vo::run_sequence("sitting-rpy", source, {*find_spec(all, false), *find_spec(all, true)}, ro, &report,
                               &error))
      << error;
  vo::evaluate_against_recorded_truth(&report, ro);
  ASSERT_EQ(report.runs.size(), 2u);
  for (const vo::StrategyRun& run : report.runs) {
    EXPECT_TRUE(run.has_ate) << run.spec.name << ": " << run.ate_note;
    EXPECT_LT(run.ate_rmse_m, 0.05) << run.spec.name;
  }
  EXPECT_GT(report.runs[1].labels.true_positive, 0u) << "the seated person's moving parts are culled";
}

// The scene keys allow images from 1 x 1 px: the front end must run on any of them (no room for a
// feature inside its 12 px border is no features, not an exception from the detection mask).
TEST(DynamicVo, ImagesSmallerThanTheBorderRunWithoutFeatures) {
  const auto all = vo::all_strategies();
  for (const char* size : {"width=8,height=8", "width=1,height=1", "width=8192,height=8", "width=24,height=25"}) {
    sim::SceneOptions so;
    ASSERT_EQ(sim::apply_scene_assignments(&so, std::string(size) + ",motion=xyz,num_frames=3"), Status::Ok) << size;
    vo::SimSource source(so);
    vo::RunnerOptions ro;
    ro.max_frames = 3;
    ro.write_outputs = false;
    ro.print_progress = false;
    vo::SequenceReport report;
    std::string error;
    bool ran = false;
    EXPECT_NO_THROW(ran = vo::run_sequence("tiny", source, {*find_spec(all, false), *find_spec(all, true)}, ro,
                                           &report, &error))
        << size;
    EXPECT_TRUE(ran) << size << ": " << error;
  }
}

// --diagnose names every instance the sim can render (the crowd's third and fourth walkers, the desk people
// and clutter), so their labels are not lumped into "other".
TEST(DynamicVo, DiagnoseNamesEverySimInstance) {
  std::set<std::string> names;
  for (int id = 0; id < sim::SceneInstance::kCount; ++id) {
    const std::string name = vo::LabelBreakdown::instance_name(id);
    EXPECT_NE(name, "other") << "instance " << id;
    EXPECT_TRUE(names.insert(name).second) << "instance " << id << " shares the name " << name;
  }
  EXPECT_STREQ(vo::LabelBreakdown::instance_name(sim::SceneInstance::kWalkerC), "walker_c");
  EXPECT_STREQ(vo::LabelBreakdown::instance_name(sim::SceneInstance::kDeskPersonB), "desk_person_b");
  EXPECT_STREQ(vo::LabelBreakdown::instance_name(sim::SceneInstance::kCount), "other");
  EXPECT_STREQ(vo::LabelBreakdown::instance_name(-1), "other");
  vo::LabelBreakdown b;
  ++b.at(sim::SceneInstance::kWalkerD, true, true, 0);
  EXPECT_NE(b.format().find("walker_d moving culled"), std::string::npos) << b.format();
}

}  // namespace

#else
TEST(DynamicVo, NeedsOpenCv) { GTEST_SKIP() << "dynamic_vo needs the OpenCV adapter (OpenCV 4 not found)"; }
#endif
