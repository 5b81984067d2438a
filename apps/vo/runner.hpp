/// @file runner.hpp
/// Runs the dynamic_vo front end over one sequence with several culling strategies in lockstep (each
/// frame is loaded once and fed to one front end per strategy), then evaluates ATE (000 eq. 6-7,
/// TUM evaluate_ate.py through dyncull::eval) and the improvement (m - n) / m (002 eq. 7).
#pragma once

#include "dyncull/eval/ate.hpp"
#include "dyncull/eval/statistics.hpp"
#include "dyncull/eval/trajectory.hpp"

#include "box_culls.hpp"
#include "culling.hpp"
#include "frontend.hpp"
#include "report.hpp"
#include "sources.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace dyncull {
namespace vo {

struct RunnerOptions {
  std::string out_dir = "dynamic_vo_out";
  int max_frames = 300;
  int progress_every = 50;       ///< progress line every this many frames
  int frames_to_draw = 3;        ///< frames with kept/culled features written as PNG (0: none)
  bool write_outputs = true;     ///< PNGs and TUM trajectory files (tests turn this off)
  bool print_progress = true;
  bool diagnose = false;         ///< per-instance / per-reason label breakdown (needs sim truth)
  FrontEndOptions front_end;
};

/// Everything measured for one strategy on one sequence.
/// One pose of a run beside its ground truth: the estimate as the ATE aligned it, and their distance.
struct PosePair {
  double stamp = 0;
  Vec3<double> truth = Vec3<double>::Zero(), estimate = Vec3<double>::Zero();
  double error_m = 0;
};

struct StrategyRun {
  StrategySpec spec;
  eval::Trajectory<double> estimate;
  LabelCounts labels;
  BoxCullCounts box_culls;  ///< culls inside person boxes / outside every box (needs no truth)
  LabelBreakdown breakdown;  ///< filled when RunnerOptions::diagnose
  RecallBySpeed recall_by_speed;  ///< filled when RunnerOptions::diagnose (sim only)
  double cull_ms = 0, front_end_ms = 0;  ///< totals over the frames
  std::size_t frames = 0, fallbacks = 0, keyframes = 0, tracks = 0, kept = 0, inliers = 0;
  // Evaluation.
  bool has_ate = false;
  double ate_rmse_m = std::numeric_limits<double>::quiet_NaN();
  std::size_t ate_pairs = 0;
  std::string ate_note;                  ///< how the ATE was computed when not the standard way
  std::vector<PosePair> pose_pairs;      ///< the ATE's pairs (aligned estimate), for the figures

  double cull_ms_per_frame() const { return frames ? cull_ms / static_cast<double>(frames) : 0.0; }
  double front_end_ms_per_frame() const { return frames ? front_end_ms / static_cast<double>(frames) : 0.0; }
};

struct SequenceReport {
  std::string name;
  std::string family;      ///< sim: the scene family (sim/families.hpp)
  std::string sequence;    ///< sim: the camera motion (name adds the seed when several run)
  std::uint64_t seed = 0;  ///< sim: SceneOptions::seed
  bool has_label_truth = false;
  eval::Trajectory<double> truth;  ///< per frame when the source has it (sim)
  std::string truth_note;
  std::vector<StrategyRun> runs;
  std::vector<double> frame_stamps;     ///< per frame run
  std::vector<int> person_boxes;        ///< per frame: the detector's person boxes (people in view)
  std::vector<std::string> files;  ///< PNG / trajectory files written
};

namespace detail {
inline double ms_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

/// Scores one frame's keep mask on the tracks the culling saw (before PnP drops outliers): labels against
/// the moving truth when the source has it, box culls, and with options.diagnose the culler's reasons.
inline void score_culling(const FrontEnd& fe, const Culler& culler, const std::vector<std::uint8_t>& keep,
                          const SequenceFrame& frame, bool has_label_truth, const RunnerOptions& options,
                          StrategyRun* run) {
  if (has_label_truth) count_labels(fe.tracks().cur_px, keep, frame.moving, frame.detections, &run->labels);
  run->box_culls.add(fe.tracks().cur_px, keep, frame.detections);
  if (options.diagnose) {
    run->breakdown.add(fe.tracks().cur_px, keep, culler.reasons(), culler.kept_why(), frame.moving, frame.instance);
    run->recall_by_speed.add(fe.tracks().cur_px, keep, frame.moving, frame.motion_m, frame.instance);
  }
}

/// Draws frame i's tracks, green kept and red culled, with its caption into <out_dir>/<name>_frameNNNN.png
/// (loading the colour image first), and lists the file in the report.
template <class Source>
void draw_culled_frame(Source& source, SequenceFrame* frame, const std::string& name, int i,
                       const std::string& strategy, std::size_t kept, const FrontEnd& fe,
                       const std::vector<std::uint8_t>& keep, const RunnerOptions& options, SequenceReport* report) {
  source.load_colour(frame);
  char file[64];
  std::snprintf(file, sizeof file, "/%s_frame%04d.png", name.c_str(), i);
  std::ostringstream cap;
  cap << name << " frame " << i << ", " << strategy << ": " << kept << " kept of " << fe.tracks().size()
      << (frame->moving.empty() ? " (green kept, red culled)" : " (green kept, red culled, x culled static, ring kept moving)");
  if (draw_features(options.out_dir + file, frame->bgr, cap.str(), fe.tracks().cur_px, keep, frame->detections,
                    frame->moving))
    report->files.push_back(options.out_dir + file);
}

/// Adds frame i's pose and front-end counts to the run.
inline void add_frame_stats(const FrameStats& st, int i, double stamp, const Rigid3<double>& world_from_cam,
                            StrategyRun* run) {
  run->estimate.push_back(stamp, world_from_cam);
  ++run->frames;
  run->fallbacks += (st.fallback && i > 0) ? 1 : 0;
  run->keyframes += st.keyframe ? 1 : 0;
  run->tracks += st.tracks;
  run->kept += st.kept;
  run->inliers += st.inliers;
}
}  // namespace detail

/// Runs every strategy over the first max_frames frames of `source`. Returns false (with `error`)
/// only when a frame cannot be loaded.
template <class Source>
bool run_sequence(const std::string& name, Source& source, const std::vector<StrategySpec>& specs,
                  const RunnerOptions& options, SequenceReport* report, std::string* error) {
  report->name = name;
  report->has_label_truth = source.has_truth_labels();
  const int n = std::min(source.size(), options.max_frames);
  if (n < 2) {
    *error = name + ": fewer than 2 frames";
    return false;
  }
  const PinholeCamera<double> camera = source.camera();
  std::vector<FrontEnd> front_ends;
  std::vector<Culler> cullers;
  report->runs.clear();
  report->frame_stamps.clear();
  report->person_boxes.clear();
  for (const StrategySpec& s : specs) {
    front_ends.emplace_back(camera, options.front_end);
    cullers.emplace_back(s, camera);
    report->runs.emplace_back();
    report->runs.back().spec = s;
    report->runs.back().estimate.reserve(static_cast<std::size_t>(n));
  }
  // Frames drawn with the recommended strategy (or the last one given) at 1/4, 1/2, 3/4 of the run.
  std::size_t draw_strategy = specs.size() - 1;
  for (std::size_t k = 0; k < specs.size(); ++k)
    if (specs[k].recommended) draw_strategy = k;
  std::vector<int> draw_at;
  for (int k = 1; k <= options.frames_to_draw; ++k) draw_at.push_back(n * k / (options.frames_to_draw + 1));

  SequenceFrame frame;
  FrameInput input;
  std::vector<std::uint8_t> keep;
  if (options.print_progress) std::printf("[%s] %d frames, %zu strategies\n", name.c_str(), n, specs.size());
  for (int i = 0; i < n; ++i) {
    if (!source.load(i, &frame, error)) return false;
    if (frame.has_truth_pose) report->truth.push_back(frame.timestamp, frame.truth_world_from_cam);
    report->frame_stamps.push_back(frame.timestamp);
    report->person_boxes.push_back(static_cast<int>(std::count_if(
        frame.detections.begin(), frame.detections.end(),
        [](const Detection<float>& d) { return d.class_id == BoxCullCounts::kPersonClass; })));
    input.timestamp = frame.timestamp;
    input.gray = frame.gray;
    input.depth_m = frame.depth_m;
    const bool draw = options.write_outputs && std::find(draw_at.begin(), draw_at.end(), i) != draw_at.end();
    for (std::size_t k = 0; k < specs.size(); ++k) {
      FrontEnd& fe = front_ends[k];
      StrategyRun& run = report->runs[k];
      // The sim's truth fixes the start so trajectories and truth share a frame before alignment.
      if (i == 0 && frame.has_truth_pose) fe.set_initial_pose(frame.truth_world_from_cam);
      const auto t0 = std::chrono::steady_clock::now();
      fe.track(input);
      const double track_ms = detail::ms_since(t0);
      const auto t1 = std::chrono::steady_clock::now();
      cullers[k].cull(frame, fe.tracks(), fe.predicted_world_from_cam(), fe.frames_since_keyframe(), &keep);
      // ORB descriptors at the tracks are the front end's work in a host with ORB features (ORB-SLAM).
      run.cull_ms += detail::ms_since(t1) - cullers[k].descriptor_ms();
      run.front_end_ms += cullers[k].descriptor_ms();
      // Labels are counted (and drawn) on the tracks the culling saw, before PnP drops outliers.
      const std::size_t kept = static_cast<std::size_t>(std::count_if(keep.begin(), keep.end(), [](std::uint8_t k) { return k != 0; }));
      detail::score_culling(fe, cullers[k], keep, frame, report->has_label_truth, options, &run);
      if (draw && k == draw_strategy && fe.tracks().size() > 0)
        detail::draw_culled_frame(source, &frame, name, i, specs[k].name, kept, fe, keep, options, report);
      const auto t2 = std::chrono::steady_clock::now();
      const FrameStats st = fe.estimate(keep);
      run.front_end_ms += track_ms + detail::ms_since(t2);
      detail::add_frame_stats(st, i, frame.timestamp, fe.world_from_cam(), &run);
      if (options.print_progress && ((i + 1) % options.progress_every == 0 || i + 1 == n)) {
        std::printf("[%s] frame %4d/%d  %-20s tracks %4zu kept %4zu inliers %4zu%s\n", name.c_str(), i + 1, n,
                    specs[k].name.c_str(), st.tracks, st.kept, st.inliers, st.fallback ? "  (constant-velocity fallback)" : "");
      }
    }
    if (options.print_progress && ((i + 1) % options.progress_every == 0 || i + 1 == n)) std::fflush(stdout);
  }
  return true;
}

inline PosePair pose_pair(const eval::Trajectory<double>& truth, std::size_t truth_index, const Vec3<double>& estimate) {
  PosePair p;
  p.stamp = truth.stamps[truth_index];
  p.truth = truth.poses[truth_index].t;
  p.estimate = estimate;
  p.error_m = (estimate - p.truth).norm();
  return p;
}

/// Every run's pose pairs, `strategy,stamp,gt_x,gt_y,gt_z,x,y,z,error_m` (dyncull_eval --poses-csv's
/// columns after the strategy), metres.
inline std::string poses_csv(const SequenceReport& report) {
  std::string out = "strategy,stamp,gt_x,gt_y,gt_z,x,y,z,error_m\n";
  char line[256];
  for (const StrategyRun& run : report.runs) {
    for (const PosePair& p : run.pose_pairs) {
      std::snprintf(line, sizeof line, ",%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f\n", p.stamp, p.truth.x(), p.truth.y(),
                    p.truth.z(), p.estimate.x(), p.estimate.y(), p.estimate.z(), p.error_m);
      out += run.spec.name + line;
    }
  }
  return out;
}

/// Per frame run: `frame,stamp,person_boxes` (the detector's person boxes: the frames with people in view).
inline std::string frames_csv(const SequenceReport& report) {
  std::string out = "frame,stamp,person_boxes\n";
  char line[96];
  for (std::size_t i = 0; i < report.frame_stamps.size(); ++i) {
    std::snprintf(line, sizeof line, "%zu,%.6f,%d\n", i, report.frame_stamps[i], report.person_boxes[i]);
    out += line;
  }
  return out;
}

/// ATE of every run against `truth`. The standard TUM way (associate, SE(3) alignment, RMSE); when
/// the truth does not move (static camera: the alignment is undefined) the estimate is compared
/// unaligned, in the truth frame it was started in, and the run's ate_note says so.
inline void evaluate(const eval::Trajectory<double>& truth, SequenceReport* report, const RunnerOptions& options) {
  for (StrategyRun& run : report->runs) {
    const eval::AteResult<double> ate = eval::evaluate_ate(truth, run.estimate);
    run.pose_pairs.clear();
    if (ate.ok()) {
      run.has_ate = true;
      run.ate_rmse_m = ate.error_m.rmse;
      run.ate_pairs = ate.num_pairs;
      for (std::size_t j = 0; j < ate.groundtruth_index.size(); ++j)
        run.pose_pairs.push_back(pose_pair(truth, ate.groundtruth_index[j], ate.groundtruth_from_estimate.apply(
                                                                               run.estimate.poses[ate.estimate_index[j]].t)));
    } else if (ate.status == Status::Degenerate) {
      const eval::AssociationResult m = eval::associate(truth.stamps, run.estimate.stamps);
      std::vector<double> err;
      for (std::size_t j = 0; j < m.size(); ++j) {
        run.pose_pairs.push_back(pose_pair(truth, m.first[j], run.estimate.poses[m.second[j]].t));
        err.push_back(run.pose_pairs.back().error_m);
      }
      const eval::ErrorStatistics<double> s = eval::compute_statistics(err.data(), err.size());
      if (s.ok()) {
        run.has_ate = true;
        run.ate_rmse_m = s.rmse;
        run.ate_pairs = s.count;
        run.ate_note = "unaligned (truth does not move: " + ate.reason + ")";
      } else {
        run.pose_pairs.clear();
        run.ate_note = s.reason;
      }
    } else {
      run.ate_note = ate.reason;
    }
    if (options.write_outputs) {
      const std::string file = options.out_dir + "/" + report->name + "_" + run.spec.name + ".txt";
      if (eval::write_tum_trajectory(file, run.estimate).ok()) report->files.push_back(file);
    }
  }
  if (!options.write_outputs) return;
  const std::string truth_file = options.out_dir + "/" + report->name + "_groundtruth.txt";
  if (eval::write_tum_trajectory(truth_file, truth).ok()) report->files.push_back(truth_file);
  // The figures' data: scripts/figures.py draws the trajectories and the error over time from these.
  const std::string poses = options.out_dir + "/" + report->name + "_poses.csv";
  if (std::ofstream(poses) << poses_csv(*report)) report->files.push_back(poses);
  const std::string frames = options.out_dir + "/" + report->name + "_frames.csv";
  if (std::ofstream(frames) << frames_csv(*report)) report->files.push_back(frames);
}

/// Sim: the truth recorded frame by frame.
inline void evaluate_against_recorded_truth(SequenceReport* report, const RunnerOptions& options) {
  const eval::Trajectory<double> truth = report->truth;
  evaluate(truth, report, options);
}

/// TUM: groundtruth.txt beside the images. Returns false when it is missing or unreadable.
inline bool evaluate_against_file(const std::string& path, SequenceReport* report, const RunnerOptions& options) {
  const eval::TrajectoryReadResult<double> gt = eval::read_tum_trajectory<double>(path);
  if (!gt.ok()) {
    report->truth_note = gt.reason;
    for (StrategyRun& run : report->runs) {
      if (!options.write_outputs) continue;
      const std::string file = options.out_dir + "/" + report->name + "_" + run.spec.name + ".txt";
      if (eval::write_tum_trajectory(file, run.estimate).ok()) report->files.push_back(file);
    }
    return false;
  }
  report->truth = gt.trajectory;
  evaluate(gt.trajectory, report, options);
  return true;
}

inline std::string fmt(double v, const char* f = "%.3f") {
  if (!std::isfinite(v)) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

/// The papers' table: ATE RMSE per sequence and strategy, improvement over no culling, labels, time.
inline std::string format_table(const std::vector<SequenceReport>& reports, const std::string& command, double seconds) {
  std::ostringstream o;
  o << "| sequence | strategy | ATE RMSE (m) | improvement (m-n)/m | dyn. precision | dyn. recall | static in boxes kept "
       "| culling ms/frame | front end ms/frame | cull / front end | fallbacks | keyframes |\n";
  o << "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const SequenceReport& r : reports) {
    double reference = std::numeric_limits<double>::quiet_NaN();
    for (const StrategyRun& run : r.runs)
      if (!run.spec.culls && run.has_ate) reference = run.ate_rmse_m;
    for (const StrategyRun& run : r.runs) {
      const double improvement =
          run.spec.culls && run.has_ate && reference > 0 ? (reference - run.ate_rmse_m) / reference
                                                         : std::numeric_limits<double>::quiet_NaN();
      const bool labels = r.has_label_truth && run.spec.culls;
      o << "| " << r.name << " | " << run.spec.name << (run.spec.recommended ? " (default)" : "") << " | "
        << (run.has_ate ? fmt(run.ate_rmse_m, "%.4f") : "-") << " | " << fmt(improvement * 100.0, "%.1f %%") << " | "
        << (labels ? fmt(run.labels.precision()) : "-") << " | " << (labels ? fmt(run.labels.recall()) : "-") << " | "
        << (labels ? fmt(run.labels.static_in_box_kept_ratio()) : "-") << " | " << fmt(run.cull_ms_per_frame(), "%.3f")
        << " | " << fmt(run.front_end_ms_per_frame(), "%.2f") << " | "
        << (run.spec.culls ? fmt(run.cull_ms_per_frame() / run.front_end_ms_per_frame(), "%.3f") : "-") << " | "
        << run.fallbacks << " | " << run.keyframes << " |\n";
    }
  }
  o << "\nATE: TUM evaluate_ate.py semantics (association 0.02 s, SE(3) alignment, RMSE of position errors).";
  for (const SequenceReport& r : reports) {
    for (const StrategyRun& run : r.runs) {
      if (!run.ate_note.empty()) {
        o << "\n- " << r.name << " / " << run.spec.name << ": " << run.ate_note;
        break;
      }
    }
    if (!r.truth_note.empty()) o << "\n- " << r.name << ": " << r.truth_note;
  }
  o << "\nPrecision/recall: culled features against the per-pixel 'moving' truth at each tracked feature, all frames;"
       " 'static in boxes kept': share of truly static features inside detection boxes that were kept.\n";
  o << "Times: wall clock per frame on this machine (culling = the preset's pipeline call; front end = LK tracking,"
       " PnP-RANSAC with refinement, keyframe ORB detection).\n";
  o << "\nCommand: `" << command << "` (" << fmt(seconds, "%.0f") << " s)\n";
  return o.str();
}

/// Several scene seeds per sequence: single runs of this VO vary a lot with the scene (no-culling ATE
/// on xyz 1.8-14 cm over seeds 1-3), so the summary gives per sequence and strategy the median ATE,
/// the median of the per-seed improvements, and precision / recall / static-in-boxes pooled over seeds.
inline std::string format_seed_summary(const std::vector<SequenceReport>& reports) {
  auto median = [](std::vector<double> v) {
    v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
    if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
    std::sort(v.begin(), v.end());
    const std::size_t h = v.size() / 2;
    return v.size() % 2 ? v[h] : 0.5 * (v[h - 1] + v[h]);
  };
  std::ostringstream o;
  o << "| sequence | strategy | seeds | median ATE RMSE (m) | ATE per seed (m) | median improvement | dyn. precision "
       "| dyn. recall | static in boxes kept |\n";
  o << "|---|---|---|---|---|---|---|---|---|\n";
  std::vector<std::string> sequences;
  for (const SequenceReport& r : reports)
    if (std::find(sequences.begin(), sequences.end(), r.sequence) == sequences.end()) sequences.push_back(r.sequence);
  for (const std::string& seq : sequences) {
    std::vector<const SequenceReport*> runs_of_seq;
    for (const SequenceReport& r : reports)
      if (r.sequence == seq) runs_of_seq.push_back(&r);
    const SequenceReport& first = *runs_of_seq.front();
    for (std::size_t k = 0; k < first.runs.size(); ++k) {
      std::vector<double> ate, improvement;
      std::ostringstream per_seed;
      LabelCounts labels;
      for (const SequenceReport* r : runs_of_seq) {
        if (k >= r->runs.size()) continue;
        const StrategyRun& run = r->runs[k];
        double reference = std::numeric_limits<double>::quiet_NaN();
        for (const StrategyRun& x : r->runs)
          if (!x.spec.culls && x.has_ate) reference = x.ate_rmse_m;
        const double a = run.has_ate ? run.ate_rmse_m : std::numeric_limits<double>::quiet_NaN();
        ate.push_back(a);
        if (run.spec.culls && reference > 0) improvement.push_back((reference - a) / reference);
        per_seed << (per_seed.tellp() > 0 ? " / " : "") << fmt(a, "%.4f");
        labels += run.labels;
      }
      const StrategyRun& run = first.runs[k];
      const bool has_labels = first.has_label_truth && run.spec.culls;
      o << "| " << seq << " | " << run.spec.name << (run.spec.recommended ? " (default)" : "") << " | "
        << runs_of_seq.size() << " | " << fmt(median(ate), "%.4f") << " | " << per_seed.str() << " | "
        << fmt(median(improvement) * 100.0, "%.1f %%") << " | " << (has_labels ? fmt(labels.precision()) : "-")
        << " | " << (has_labels ? fmt(labels.recall()) : "-") << " | "
        << (has_labels ? fmt(labels.static_in_box_kept_ratio()) : "-") << " |\n";
    }
  }
  o << "\nMedian over the seeds of each sequence; improvement = median of the per-seed (m-n)/m; labels pooled over"
       " the seeds' frames.\n";
  return o.str();
}

namespace detail {
/// Median of the finite values, NaN when there are none.
inline double median_of(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const std::size_t h = v.size() / 2;
  return v.size() % 2 ? v[h] : 0.5 * (v[h - 1] + v[h]);
}
}  // namespace detail

/// One strategy over a family's runs (all motions, or one motion): median ATE over its sequences
/// (motions x seeds), labels and times pooled.
struct FamilyStrategySummary {
  std::string family;
  std::string motion;  ///< "all", or the camera motion
  std::string strategy;
  bool culls = false, recommended = false, oracle = false;  ///< as the strategy's StrategySpec
  std::size_t runs = 0;
  double median_ate_m = std::numeric_limits<double>::quiet_NaN();
  double median_improvement = std::numeric_limits<double>::quiet_NaN();  ///< of the per-run (m - n) / m
  LabelCounts labels;
  double cull_ms = 0, front_end_ms = 0;
  std::size_t frames = 0;
  double cull_over_front_end() const { return front_end_ms > 0 ? cull_ms / front_end_ms : std::numeric_limits<double>::quiet_NaN(); }
};

/// Per family (in order of appearance), per motion ("all" first) and per strategy (in run order).
inline std::vector<FamilyStrategySummary> summarise_families(const std::vector<SequenceReport>& reports) {
  std::vector<std::string> families, motions;
  auto add_unique = [](std::vector<std::string>& v, const std::string& x) {
    if (std::find(v.begin(), v.end(), x) == v.end()) v.push_back(x);
  };
  std::vector<const StrategySpec*> specs;
  for (const SequenceReport& r : reports) {
    add_unique(families, r.family);
    add_unique(motions, r.sequence);
    for (const StrategyRun& run : r.runs)
      if (std::none_of(specs.begin(), specs.end(), [&](const StrategySpec* s) { return s->name == run.spec.name; }))
        specs.push_back(&run.spec);
  }
  motions.insert(motions.begin(), "all");
  std::vector<FamilyStrategySummary> out;
  for (const std::string& family : families) {
    for (const std::string& motion : motions) {
      for (const StrategySpec* spec_ptr : specs) {
        const StrategySpec& spec = *spec_ptr;
        FamilyStrategySummary s;
        s.family = family;
        s.motion = motion;
        s.strategy = spec.name;
        s.culls = spec.culls;
        s.recommended = spec.recommended;
        s.oracle = spec.oracle;
        std::vector<double> ate, improvement;
        for (const SequenceReport& r : reports) {
          if (r.family != family || (motion != "all" && r.sequence != motion)) continue;
          double reference = std::numeric_limits<double>::quiet_NaN();
          for (const StrategyRun& x : r.runs)
            if (!x.spec.culls && x.has_ate) reference = x.ate_rmse_m;
          for (const StrategyRun& run : r.runs) {
            if (run.spec.name != spec.name) continue;
            ++s.runs;
            const double a = run.has_ate ? run.ate_rmse_m : std::numeric_limits<double>::quiet_NaN();
            ate.push_back(a);
            if (run.spec.culls && reference > 0) improvement.push_back((reference - a) / reference);
            if (r.has_label_truth) s.labels += run.labels;
            s.cull_ms += run.cull_ms;
            s.front_end_ms += run.front_end_ms;
            s.frames += run.frames;
          }
        }
        if (s.runs == 0) continue;
        s.median_ate_m = detail::median_of(ate);
        s.median_improvement = detail::median_of(improvement);
        out.push_back(s);
      }
    }
  }
  return out;
}

/// Per family: the median ATE (cm, over motions x seeds) of every strategy that ran, the recommended
/// preset's ATE over the oracle's and over no culling's (ratios of the medians; "worst motion": the
/// largest recommended / oracle ratio of one motion's medians over its seeds), its label precision and
/// recall (pooled over the family's runs) and its culling time over the front end's.
inline std::string format_family_summary(const std::vector<FamilyStrategySummary>& rows) {
  std::vector<std::string> families, strategies;
  for (const FamilyStrategySummary& r : rows) {
    if (r.motion != "all") continue;
    if (std::find(families.begin(), families.end(), r.family) == families.end()) families.push_back(r.family);
    if (std::find(strategies.begin(), strategies.end(), r.strategy) == strategies.end())
      strategies.push_back(r.strategy);
  }
  auto find = [&](const std::string& family, const std::string& motion, auto pred) -> const FamilyStrategySummary* {
    for (const FamilyStrategySummary& r : rows)
      if (r.family == family && r.motion == motion && pred(r)) return &r;
    return nullptr;
  };
  auto is_rec = [](const FamilyStrategySummary& s) { return s.recommended; };
  auto is_oracle = [](const FamilyStrategySummary& s) { return s.oracle; };
  auto is_none = [](const FamilyStrategySummary& s) { return !s.culls; };
  auto ratio = [](const FamilyStrategySummary* a, const FamilyStrategySummary* b) {
    return a && b && b->median_ate_m > 0 ? a->median_ate_m / b->median_ate_m : std::numeric_limits<double>::quiet_NaN();
  };
  std::ostringstream o;
  o << "| family | runs |";
  for (const std::string& name : strategies) o << " " << name << " |";
  o << " rec / oracle | worst motion | rec / none | dyn. precision | dyn. recall | cull / front end |\n|---|---|";
  for (std::size_t k = 0; k < strategies.size(); ++k) o << "---|";
  o << "---|---|---|---|---|---|\n";
  for (const std::string& family : families) {
    const FamilyStrategySummary* rec = find(family, "all", is_rec);
    const FamilyStrategySummary* oracle = find(family, "all", is_oracle);
    const FamilyStrategySummary* none = find(family, "all", is_none);
    std::size_t runs = 0;
    for (const FamilyStrategySummary& r : rows)
      if (r.family == family && r.motion == "all") runs = std::max(runs, r.runs);
    o << "| " << family << " | " << runs << " |";
    for (const std::string& name : strategies) {
      const FamilyStrategySummary* r = find(family, "all", [&](const FamilyStrategySummary& x) { return x.strategy == name; });
      o << " " << (r ? fmt(r->median_ate_m * 100.0, "%.2f") : "-") << " |";
    }
    double worst = std::numeric_limits<double>::quiet_NaN();
    std::string worst_motion;
    for (const FamilyStrategySummary& r : rows) {
      if (r.family != family || r.motion == "all" || !r.recommended) continue;
      const double q = ratio(&r, find(family, r.motion, is_oracle));
      if (std::isfinite(q) && !(q <= worst)) {
        worst = q;
        worst_motion = r.motion;
      }
    }
    o << " " << fmt(ratio(rec, oracle), "%.2f") << " | "
      << (worst_motion.empty() ? "-" : fmt(worst, "%.2f") + " (" + worst_motion + ")") << " | "
      << fmt(ratio(rec, none), "%.2f") << " | " << (rec ? fmt(rec->labels.precision()) : "-") << " | "
      << (rec ? fmt(rec->labels.recall()) : "-") << " | " << (rec ? fmt(rec->cull_over_front_end()) : "-") << " |\n";
  }
  o << "\nATE columns: median ATE RMSE in cm over the family's runs (motions x seeds). rec / oracle and rec / none:"
       " the recommended preset's median over the oracle's and no culling's; worst motion: the largest recommended /"
       " oracle ratio of one motion's medians over its seeds. Precision / recall: the recommended preset's dynamic"
       " labels pooled over the family's runs. cull / front end: its culling time over the front end's.\n";
  return o.str();
}

/// The summary, long format, one row per family x motion ("all" = every motion) x strategy, for tools.
inline std::string family_summary_csv(const std::vector<FamilyStrategySummary>& rows) {
  std::ostringstream o;
  o << "family,motion,strategy,recommended,oracle,runs,median_ate_m,median_improvement,precision,recall,"
       "static_in_boxes_kept,true_positive,false_positive,false_negative,true_negative,cull_ms_per_frame,"
       "front_end_ms_per_frame,cull_over_front_end\n";
  auto num = [](double v, const char* f) { return std::isfinite(v) ? fmt(v, f) : std::string(); };
  for (const FamilyStrategySummary& r : rows) {
    const bool labels = r.culls && r.labels.true_positive + r.labels.false_positive + r.labels.false_negative +
                                            r.labels.true_negative > 0;
    const double frames = r.frames ? static_cast<double>(r.frames) : std::numeric_limits<double>::quiet_NaN();
    o << r.family << "," << r.motion << "," << r.strategy << "," << (r.recommended ? 1 : 0) << ","
      << (r.oracle ? 1 : 0) << "," << r.runs << "," << num(r.median_ate_m, "%.6f") << ","
      << num(r.median_improvement, "%.4f") << "," << (labels ? num(r.labels.precision(), "%.4f") : "") << ","
      << (labels ? num(r.labels.recall(), "%.4f") : "") << ","
      << (labels ? num(r.labels.static_in_box_kept_ratio(), "%.4f") : "") << "," << r.labels.true_positive << ","
      << r.labels.false_positive << "," << r.labels.false_negative << "," << r.labels.true_negative << ","
      << num(r.cull_ms / frames, "%.4f") << "," << num(r.front_end_ms / frames, "%.3f") << ","
      << (r.culls ? num(r.cull_over_front_end(), "%.4f") : "") << "\n";
  }
  return o.str();
}

}  // namespace vo
}  // namespace dyncull
