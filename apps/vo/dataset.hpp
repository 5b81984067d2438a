/// @file dataset.hpp
/// dynamic_vo --dataset: a real RGB-D sequence in TUM format (Sturm et al. 2012; the Bonn RGB-D Dynamic
/// layout, Palazzolo et al. 2019) indexed by eval/sequence.hpp, run with each culling strategy and
/// evaluated as the TUM benchmark does: ATE RMSE after rigid alignment (0.02 s association) and RPE over
/// 1 s (evaluate_rpe.py --fixed_delta), plus lost frames, where the culls fall relative to the boxes and
/// culling time against the front end's. Writes dataset_summary.csv / .md, the trajectories (TUM format),
/// the plots' data (CSV for scripts/figures.py) and a strip of annotated frames.
#pragma once

#include "dyncull/eval/rpe.hpp"
#include "dyncull/eval/sequence.hpp"

#include "figures.hpp"
#include "live_detector.hpp"
#include "runner.hpp"
#include "sources.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace dyncull {
namespace vo {

/// What to run. Empty detections / camera take the folder's own (DIR/detections, DIR/camera.txt) when
/// present; detections "none" runs without boxes; camera falls back to TUM's by the folder's name.
struct DatasetOptions {
  std::string dir;
  std::string detections;
  std::string camera;
  std::vector<StrategySpec> strategies;
  RunnerOptions runner;  ///< out_dir, max_frames, front end
  eval::SequenceOptions sequence;
  int strip_frames = 4;  ///< annotated frames in the strip (evenly spaced, drawn with the recommended preset)
  LiveDetector* live_detector = nullptr;  ///< when set (and open), boxes come from it instead of files
  /// A dyncull_motion_truth folder (index.txt, NNNNNN.png): per-pixel motion truth that scores every
  /// strategy (precision, recall) and lets the oracle run. Empty: none.
  std::string truth_dir;
  /// PnP-RANSAC seeds of the front end, one run of every strategy each (empty: runner.front_end.seed).
  /// A single run's ATE moves by centimetres with the seed alone, so rows report the median and range.
  std::vector<std::uint64_t> pnp_seeds;
};

/// A TUM-format folder as a frame source of the runner: images loaded with OpenCV, depth scaled by the
/// camera's depth_units_per_metre, undistorted when the camera has distortion. A frame without depth (no
/// partner, or an unreadable depth file) runs with an empty depth map (0 = no measurement).
class DatasetSource {
 public:
  bool open(const DatasetOptions& options, std::string* error) {
    index_ = eval::read_sequence(options.dir, options.sequence);
    if (!index_.ok()) {
      *error = index_.reason;
      return false;
    }
    for (const std::string& n : index_.notes.first) notes_.push_back(n);
    if (index_.notes.count > index_.notes.first.size())
      notes_.push_back("... and " + std::to_string(index_.notes.count - index_.notes.first.size()) + " more");
    if (!open_camera(options, error)) return false;
    std::string det = options.detections;
    std::error_code ec;
    if (det.empty() && std::filesystem::exists(options.dir + "/detections", ec)) det = options.dir + "/detections";
    if (options.live_detector != nullptr && options.live_detector->enabled()) {
      live_ = options.live_detector;
      has_detections_ = true;
      detections_path_ = "the live detector";
    } else if (!det.empty() && det != "none") {
      detections_ = eval::read_sequence_detections(det, index_, camera_.width, camera_.height, options.sequence);
      if (!detections_.ok()) {
        *error = "detections: " + detections_.reason;
        return false;
      }
      has_detections_ = true;
      detections_path_ = det;
      for (const std::string& n : detections_.notes.first) notes_.push_back(n);
    }
    return options.truth_dir.empty() || open_truth(options.truth_dir, error);
  }

  int size() const { return static_cast<int>(index_.frames.size()); }
  PinholeCamera<double> camera() const { return camera_; }
  const eval::SequenceCamera& sequence_camera() const { return seq_camera_; }
  const eval::SequenceIndex& index() const { return index_; }
  bool has_detections() const { return has_detections_; }
  const std::string& detections_path() const { return detections_path_; }
  bool has_truth_labels() const { return !truth_files_.empty(); }
  /// What the reading noted (missing files, frames without depth or boxes), and what load() found.
  const std::vector<std::string>& notes() const { return notes_; }
  std::size_t frames_without_depth() const { return index_.frames_without_depth + unreadable_depth_; }

  bool load(int index, SequenceFrame* out, std::string* error) {
    const eval::SequenceFrame& f = index_.frames[static_cast<std::size_t>(index)];
    const std::string image_path = index_.dir + "/" + f.image_path;
    const cv::Mat image = cv::imread(image_path, cv::IMREAD_UNCHANGED);
    if (image.empty() || image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3) ||
        image.cols != camera_.width || image.rows != camera_.height) {
      *error = image_path + ": cannot read an 8-bit grey or colour image of " + std::to_string(camera_.width) + "x" +
               std::to_string(camera_.height);
      return false;
    }
    if (image.channels() == 3) {
      bgr_ = image;
      cv::cvtColor(image, gray_, cv::COLOR_BGR2GRAY);
    } else {
      gray_ = image;
      bgr_.release();
    }
    // The detector sees the image as recorded; its boxes are undistorted below as file boxes are.
    if (live_ != nullptr && !live_->detect(bgr_.empty() ? gray_ : bgr_, &live_boxes_, error)) return false;
    depth_.create(gray_.size(), CV_32FC1);
    depth_.setTo(0);
    if (f.has_depth()) {
      const std::string depth_path = index_.dir + "/" + f.depth_path;
      const cv::Mat raw = cv::imread(depth_path, cv::IMREAD_ANYDEPTH);
      if (raw.empty() || raw.type() != CV_16UC1 || raw.size() != gray_.size()) {
        ++unreadable_depth_;
        notes_.push_back(depth_path + ": not a 16-bit depth image of the grey image's size: frame " +
                         std::to_string(index) + " runs without depth");
      } else {
        raw.convertTo(depth_, CV_32FC1, 1.0 / seq_camera_.depth_units_per_metre);
      }
    }
    if (!map_x_.empty()) {
      cv::remap(gray_.clone(), gray_, map_x_, map_y_, cv::INTER_LINEAR, cv::BORDER_CONSTANT, 0);
      cv::remap(depth_.clone(), depth_, map_x_, map_y_, cv::INTER_NEAREST, cv::BORDER_CONSTANT, 0);  // no mixed depths
      if (!bgr_.empty()) cv::remap(bgr_.clone(), bgr_, map_x_, map_y_, cv::INTER_LINEAR);
    }
    out->timestamp = f.timestamp;
    out->gray = gray_;
    out->depth_m = depth_;
    out->moving.release();
    if (!truth_files_.empty() && !load_truth(index, &out->moving, error)) return false;
    out->instance.release();
    out->motion_m.release();
    out->detections.clear();
    if (live_ != nullptr) out->detections = undistorted(live_boxes_);
    else if (has_detections_) out->detections = undistorted(detections_.per_frame[static_cast<std::size_t>(index)]);
    out->has_truth_pose = false;
    out->bgr.release();
    return true;
  }
  /// The first frame whose stored boxes hold a person (COCO-80 class 0, any confidence), or -1: none, or
  /// the boxes come from the live detector and are not known before the run.
  int first_person_frame() const {
    if (live_ != nullptr || !has_detections_) return -1;
    for (std::size_t i = 0; i < detections_.per_frame.size(); ++i)
      for (const Detection<float>& d : detections_.per_frame[i])
        if (d.class_id == BoxCullCounts::kPersonClass) return static_cast<int>(i);
    return -1;
  }
  void load_colour(SequenceFrame* out) const {
    if (!bgr_.empty()) out->bgr = bgr_;
    else cv::cvtColor(gray_, out->bgr, cv::COLOR_GRAY2BGR);
  }

 private:
  bool open_camera(const DatasetOptions& options, std::string* error) {
    std::error_code ec;
    eval::CameraResult c;
    if (!options.camera.empty()) {
      c = eval::camera_from_spec(options.camera, options.sequence);
    } else if (std::filesystem::exists(options.dir + "/camera.txt", ec)) {
      c = eval::read_camera_file(options.dir + "/camera.txt", options.sequence);
    } else {
      c = eval::tum_camera(std::filesystem::absolute(options.dir, ec).lexically_normal().string());
      if (!c.ok()) c = eval::tum_camera("fr3");
      notes_.push_back("no --camera and no camera.txt: " + c.camera.source + " intrinsics assumed");
    }
    if (!c.ok()) {
      *error = c.reason;
      return false;
    }
    seq_camera_ = c.camera;
    // The image size is the first image's, whatever camera.txt says.
    const std::string first = index_.dir + "/" + index_.frames.front().image_path;
    const cv::Mat image = cv::imread(first, cv::IMREAD_UNCHANGED);
    if (image.empty()) {
      *error = first + ": cannot read the first image";
      return false;
    }
    seq_camera_.width = image.cols;
    seq_camera_.height = image.rows;
    if (seq_camera_.validate(error) != Status::Ok) {  // again, for the image's size
      *error = seq_camera_.source + ": " + *error;
      return false;
    }
    camera_ = PinholeCamera<double>{seq_camera_.fx, seq_camera_.fy, seq_camera_.cx, seq_camera_.cy, image.cols, image.rows};
    if (seq_camera_.has_distortion()) {
      K_ = (cv::Mat_<double>(3, 3) << camera_.fx, 0, camera_.cx, 0, camera_.fy, camera_.cy, 0, 0, 1);
      dist_ = cv::Mat(1, 5, CV_64F);
      for (int k = 0; k < 5; ++k) dist_.at<double>(0, k) = seq_camera_.distortion[static_cast<std::size_t>(k)];
      cv::initUndistortRectifyMap(K_, dist_, cv::Mat(), K_, image.size(), CV_32FC1, map_x_, map_y_);
    }
    return true;
  }

  /// Reads TRUTH_DIR/index.txt ("stamp file" lines) and pairs each frame with the label image of its
  /// stamp (within 1 ms); frames without one are scored on no feature.
  bool open_truth(const std::string& dir, std::string* error) {
    std::vector<std::pair<double, std::string>> listed;
    const std::string path = dir + "/index.txt";
    std::string reason;
    const Status st = eval::detail::for_each_line(path, 4096, &reason, [&](std::size_t number, std::string_view line,
                                                                           std::string* why) {
      const std::vector<std::string_view> f = eval::detail::fields_of(line);
      if (f.empty() || f.front().front() == '#') return true;
      double stamp = 0;
      if (f.size() != 2 || !eval::detail::parse_number(f[0], &stamp) || f[1].find('/') != std::string_view::npos) {
        *why = text::quote_path(path) + ":" + std::to_string(number) + ": expected 'stamp file'";
        return false;
      }
      listed.emplace_back(stamp, std::string(f[1]));
      return true;
    });
    if (st != Status::Ok) {
      *error = "--truth: " + reason;
      return false;
    }
    std::sort(listed.begin(), listed.end());
    truth_files_.assign(index_.frames.size(), std::string());
    std::size_t matched = 0;
    for (std::size_t i = 0; i < index_.frames.size(); ++i) {
      const double t = index_.frames[i].timestamp;
      const auto it = std::lower_bound(listed.begin(), listed.end(), std::make_pair(t - 1e-3, std::string()));
      if (it == listed.end() || std::abs(it->first - t) > 1e-3) continue;
      truth_files_[i] = dir + "/" + it->second;
      ++matched;
    }
    if (matched == 0) {
      *error = "--truth: " + dir + "/index.txt lists no stamp of the sequence's frames";
      return false;
    }
    if (matched < index_.frames.size())
      notes_.push_back("--truth: " + std::to_string(index_.frames.size() - matched) + " frames have no truth image");
    return true;
  }

  /// The frame's label image (0 static, 255 moving, 128 unknown) as SequenceFrame::moving.
  bool load_truth(int index, cv::Mat* moving, std::string* error) const {
    const std::string& path = truth_files_[static_cast<std::size_t>(index)];
    if (path.empty()) return true;
    const cv::Mat labels = cv::imread(path, cv::IMREAD_UNCHANGED);
    if (labels.type() != CV_8UC1 || labels.cols != camera_.width || labels.rows != camera_.height) {
      *error = path + ": not an 8-bit label image of " + std::to_string(camera_.width) + "x" + std::to_string(camera_.height);
      return false;
    }
    moving->create(labels.size(), CV_8UC1);
    moving->setTo(kTruthUnknown);
    moving->setTo(0, labels == 0);
    moving->setTo(1, labels == 255);
    return true;
  }

  /// Boxes of the distorted image moved to the undistorted one: the box around the undistorted corners
  /// and edge midpoints (a detector box is coarse; its shape is kept only approximately).
  std::vector<Detection<float>> undistorted(const std::vector<Detection<float>>& boxes) const {
    if (map_x_.empty()) return boxes;
    std::vector<Detection<float>> out = boxes;
    for (Detection<float>& d : out) {
      const float xm = 0.5f * (d.box.x0 + d.box.x1), ym = 0.5f * (d.box.y0 + d.box.y1);
      std::vector<cv::Point2f> p = {{d.box.x0, d.box.y0}, {d.box.x1, d.box.y0}, {d.box.x0, d.box.y1},
                                    {d.box.x1, d.box.y1}, {xm, d.box.y0},       {xm, d.box.y1},
                                    {d.box.x0, ym},       {d.box.x1, ym}},
                              q;
      cv::undistortPoints(p, q, K_, dist_, cv::noArray(), K_);
      const cv::Rect2f r = cv::boundingRect(q);
      const float w = static_cast<float>(camera_.width - 1), h = static_cast<float>(camera_.height - 1);
      d.box.x0 = std::clamp(r.x, 0.f, w);
      d.box.y0 = std::clamp(r.y, 0.f, h);
      d.box.x1 = std::clamp(r.x + r.width, 0.f, w);
      d.box.y1 = std::clamp(r.y + r.height, 0.f, h);
    }
    return out;
  }

  eval::SequenceIndex index_;
  eval::SequenceDetections detections_;
  LiveDetector* live_ = nullptr;
  std::vector<Detection<float>> live_boxes_;
  eval::SequenceCamera seq_camera_;
  PinholeCamera<double> camera_;
  bool has_detections_ = false;
  std::string detections_path_;
  std::vector<std::string> notes_;
  std::size_t unreadable_depth_ = 0;
  std::vector<std::string> truth_files_;  ///< per frame, empty without truth
  cv::Mat K_, dist_, map_x_, map_y_;
  cv::Mat gray_, depth_, bgr_;
};

/// One row of dataset_summary.csv.
struct DatasetRow {
  std::string strategy;
  bool culls = false, recommended = false;
  std::size_t frames = 0, lost_frames = 0, keyframes = 0;
  double ate_rmse_m = std::numeric_limits<double>::quiet_NaN();
  std::size_t ate_pairs = 0;
  double rpe_trans_m = std::numeric_limits<double>::quiet_NaN();  ///< RMSE over 1 s
  double rpe_rot_deg = std::numeric_limits<double>::quiet_NaN();
  std::size_t rpe_pairs = 0;
  double culled_in_person_boxes = std::numeric_limits<double>::quiet_NaN();
  double culled_in_other_boxes = std::numeric_limits<double>::quiet_NaN();  ///< boxes of other classes only
  double culled_outside_boxes = std::numeric_limits<double>::quiet_NaN();
  double cull_ms = 0, front_end_ms = 0;  ///< per frame
  /// Of culling the features on moving pixels, over the features on pixels the truth knows (--truth).
  double precision = std::numeric_limits<double>::quiet_NaN(), recall = std::numeric_limits<double>::quiet_NaN();
  /// ATE RMSE over the frames before the first person box: the front end's own error, which culling
  /// cannot lower (NaN when the sequence opens with a person or has no stored boxes).
  double ate_before_people_m = std::numeric_limits<double>::quiet_NaN();
  // Over the PnP seeds (DatasetOptions::pnp_seeds): ATE and RPE above are medians, lost_frames the most.
  std::size_t runs = 1;
  double ate_min_m = std::numeric_limits<double>::quiet_NaN(), ate_max_m = std::numeric_limits<double>::quiet_NaN();
};

struct DatasetRun {
  SequenceReport report;
  std::vector<DatasetRow> rows;
  std::vector<std::string> notes;    ///< from the reader and the run
  std::vector<std::string> skipped;  ///< strategies that could not run here, with why
  std::size_t frames_without_depth = 0;
  int first_person_frame = -1;       ///< see DatasetSource::first_person_frame()
  std::string camera_source, detections_path;
  std::vector<std::string> files;    ///< everything written
};

/// dataset_summary.csv: one row per strategy.
inline std::string dataset_summary_csv(const std::vector<DatasetRow>& rows) {
  std::ostringstream o;
  o << "strategy,frames,lost_frames,keyframes,ate_rmse_m,ate_pairs,rpe_trans_m,rpe_rot_deg,rpe_pairs,"
       "culled_in_person_boxes,culled_in_other_boxes,culled_outside_boxes,cull_ms,front_end_ms,cull_over_front_end,runs,ate_min_m,"
       "ate_max_m,ate_before_people_m,precision,recall\n";
  auto num = [](double v, const char* f) { return std::isfinite(v) ? fmt(v, f) : std::string(); };
  for (const DatasetRow& r : rows) {
    o << r.strategy << "," << r.frames << "," << r.lost_frames << "," << r.keyframes << "," << num(r.ate_rmse_m, "%.6f")
      << "," << r.ate_pairs << "," << num(r.rpe_trans_m, "%.6f") << "," << num(r.rpe_rot_deg, "%.4f") << ","
      << r.rpe_pairs << "," << (r.culls ? num(r.culled_in_person_boxes, "%.4f") : "0") << ","
      << (r.culls ? num(r.culled_in_other_boxes, "%.4f") : "0") << ","
      << (r.culls ? num(r.culled_outside_boxes, "%.4f") : "0") << "," << num(r.cull_ms, "%.4f") << ","
      << num(r.front_end_ms, "%.3f") << ","
      << (r.culls && r.front_end_ms > 0 ? num(r.cull_ms / r.front_end_ms, "%.4f") : "") << "," << r.runs << ","
      << num(r.ate_min_m, "%.6f") << "," << num(r.ate_max_m, "%.6f") << "," << num(r.ate_before_people_m, "%.6f")
      << "," << num(r.precision, "%.4f") << "," << num(r.recall, "%.4f") << "\n";
  }
  return o.str();
}

/// The front end's noise floor in words: the ATE before the first person (no mover to cull, so every
/// strategy's error there is the front end's) and the lowest RPE of any strategy.
inline std::string noise_floor_line(const DatasetRun& run) {
  double before = std::numeric_limits<double>::infinity(), rpe = before;
  std::string best;
  for (const DatasetRow& r : run.rows) {
    if (std::isfinite(r.ate_before_people_m)) before = std::min(before, r.ate_before_people_m);
    if (std::isfinite(r.rpe_trans_m) && r.rpe_trans_m < rpe) {
      rpe = r.rpe_trans_m;
      best = r.strategy;
    }
  }
  std::ostringstream o;
  if (run.first_person_frame > 0 && std::isfinite(before))
    o << "Noise floor of the front end: over frames 0-" << run.first_person_frame - 1
      << ", before the first person box, the ATE is " << fmt(100 * before, "%.2f")
      << " cm at best (ATE before people); ";
  else
    o << "Noise floor of the front end: no frames before the first person box to measure the ATE on; ";
  if (!best.empty()) o << "the lowest RPE over 1 s is " << fmt(100 * rpe, "%.2f") << " cm (" << best << ").\n";
  else o << "no RPE.\n";
  return o.str();
}

/// The same as a Markdown table (ATE and RPE in cm).
inline std::string dataset_summary_md(const DatasetRun& run, const std::string& command, double seconds) {
  std::ostringstream o;
  o << "| strategy | ATE RMSE (cm) | RPE 1 s (cm) | RPE 1 s (deg) | lost frames | keyframes | culled in person boxes "
       "| culled in other boxes | culled outside boxes | cull ms/frame | front end ms/frame | cull / front end | ATE before people (cm) | precision | recall |\n"
       "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const DatasetRow& r : run.rows) {
    const std::string range = r.runs > 1 ? " (" + fmt(100 * r.ate_min_m, "%.2f") + "-" + fmt(100 * r.ate_max_m, "%.2f") + ")" : "";
    o << "| " << r.strategy << (r.recommended ? " (default)" : "") << " | " << fmt(100 * r.ate_rmse_m, "%.2f") << range << " | "
      << fmt(100 * r.rpe_trans_m, "%.2f") << " | " << fmt(r.rpe_rot_deg, "%.2f") << " | " << r.lost_frames << " of "
      << r.frames << " | " << r.keyframes << " | "
      << (r.culls ? fmt(100 * r.culled_in_person_boxes, "%.1f %%") : "-") << " | "
      << (r.culls ? fmt(100 * r.culled_in_other_boxes, "%.1f %%") : "-") << " | "
      << (r.culls ? fmt(100 * r.culled_outside_boxes, "%.1f %%") : "-") << " | " << fmt(r.cull_ms, "%.2f") << " | "
      << fmt(r.front_end_ms, "%.1f") << " | " << (r.culls ? fmt(r.cull_ms / r.front_end_ms, "%.3f") : "-") << " | "
      << (std::isfinite(r.ate_before_people_m) ? fmt(100 * r.ate_before_people_m, "%.2f") : "-") << " | "
      << (std::isfinite(r.precision) ? fmt(r.precision) : "-") << " | " << (std::isfinite(r.recall) ? fmt(r.recall) : "-")
      << " |\n";
  }
  o << "\nATE: TUM evaluate_ate.py (0.02 s association, rigid SE(3) alignment, RMSE). RPE: evaluate_rpe.py "
       "--fixed_delta --delta 1 --delta_unit s, RMSE over every pair. Lost frames: PnP failed and the pose came from "
       "the constant-velocity prior. Culled in person boxes / in other boxes / outside boxes: share of the tracked "
       "features inside a person box / inside boxes of other classes only / outside every box that the strategy culled. Times: wall clock per frame on this machine; the "
       "culler's ORB descriptors at the tracks count as front-end time (an ORB-based host has them).\n";
  if (!run.rows.empty() && run.rows.front().runs > 1)
    o << "Over " << run.rows.front().runs << " runs with different PnP-RANSAC seeds: ATE and RPE are medians, the ATE's "
      << "range in brackets; lost frames the most of any run; the other columns from the first run.\n";
  o << noise_floor_line(run);
  if (run.frames_without_depth > 0) o << "Frames without depth: " << run.frames_without_depth << ".\n";
  for (const std::string& s : run.skipped) o << "Not run: " << s << ".\n";
  o << "\nCommand: `" << command << "` (" << fmt(seconds, "%.0f") << " s)\n";
  return o.str();
}

namespace detail {
/// The annotated frames the runner wrote (name_frameNNNN.png), in frame order.
inline std::vector<StripFrame> dataset_strip(const SequenceReport& report, const std::string& strategy) {
  std::vector<StripFrame> out;
  for (const std::string& f : report.files) {
    const std::size_t at = f.rfind("_frame");
    if (at == std::string::npos || f.size() < 4 || f.compare(f.size() - 4, 4, ".png") != 0) continue;
    const int frame = std::atoi(f.c_str() + at + 6);
    out.push_back({f, "frame " + std::to_string(frame) + ", " + strategy + ": green kept, red culled" +
                          (report.has_label_truth ? "; x culled static, ring kept moving" : "")});
  }
  return out;
}
}  // namespace detail

namespace detail {

/// ATE RMSE of the estimate's poses stamped before `end_stamp`; NaN when there are none or the
/// evaluation fails (too few pairs, no motion to align on).
inline double ate_before(const eval::Trajectory<double>& truth, const eval::Trajectory<double>& estimate,
                         double end_stamp) {
  eval::Trajectory<double> head;
  for (std::size_t i = 0; i < estimate.size() && estimate.stamps[i] < end_stamp; ++i)
    head.push_back(estimate.stamps[i], estimate.poses[i]);
  const eval::AteResult<double> ate = eval::evaluate_ate(truth, head);
  return ate.ok() ? ate.error_m.rmse : std::numeric_limits<double>::quiet_NaN();
}

/// The timestamp of the first person frame, or NaN without one.
inline double first_person_stamp(const DatasetSource& source) {
  const int k = source.first_person_frame();
  return k > 0 ? source.index().frames[static_cast<std::size_t>(k)].timestamp : std::numeric_limits<double>::quiet_NaN();
}

/// Runs the strategies again with the other PnP seeds (no files written) and turns the first run's rows
/// into medians and ranges over all seeds.
inline bool rerun_with_seeds(const DatasetOptions& options, DatasetSource& source, const std::vector<StrategySpec>& run,
                             const RunnerOptions& first, const std::string& name, DatasetRun* out, std::string* error) {
  std::vector<std::vector<double>> ate(out->rows.size()), rpe(out->rows.size()), before(out->rows.size());
  for (std::size_t k = 0; k < out->rows.size(); ++k) {
    ate[k].push_back(out->rows[k].ate_rmse_m);
    rpe[k].push_back(out->rows[k].rpe_trans_m);
    before[k].push_back(out->rows[k].ate_before_people_m);
  }
  const double people_stamp = first_person_stamp(source);
  for (std::size_t i = 1; i < options.pnp_seeds.size(); ++i) {
    RunnerOptions ro = first;
    ro.front_end.seed = options.pnp_seeds[i];
    ro.write_outputs = false;
    ro.frames_to_draw = 0;
    SequenceReport report;
    if (!run_sequence(name, source, run, ro, &report, error)) return false;
    const bool evaluated = !source.index().groundtruth_path.empty() &&
                           evaluate_against_file(source.index().groundtruth_path, &report, ro);
    for (std::size_t k = 0; k < report.runs.size() && k < out->rows.size(); ++k) {
      const StrategyRun& r = report.runs[k];
      ate[k].push_back(evaluated && r.has_ate ? r.ate_rmse_m : std::numeric_limits<double>::quiet_NaN());
      const eval::RpeResult<double> e = evaluated ? eval::evaluate_rpe(report.truth, r.estimate) : eval::RpeResult<double>{};
      rpe[k].push_back(e.ok() ? e.translation_m.rmse : std::numeric_limits<double>::quiet_NaN());
      before[k].push_back(evaluated && std::isfinite(people_stamp) ? ate_before(report.truth, r.estimate, people_stamp)
                                                                   : std::numeric_limits<double>::quiet_NaN());
      out->rows[k].lost_frames = std::max(out->rows[k].lost_frames, r.fallbacks);
    }
  }
  for (std::size_t k = 0; k < out->rows.size(); ++k) {
    DatasetRow& row = out->rows[k];
    row.runs = options.pnp_seeds.size();
    row.ate_rmse_m = median_of(ate[k]);
    row.rpe_trans_m = median_of(rpe[k]);
    row.ate_before_people_m = median_of(before[k]);
    std::vector<double> a = ate[k];
    a.erase(std::remove_if(a.begin(), a.end(), [](double x) { return !std::isfinite(x); }), a.end());
    if (!a.empty()) {
      row.ate_min_m = *std::min_element(a.begin(), a.end());
      row.ate_max_m = *std::max_element(a.begin(), a.end());
    }
  }
  return true;
}

}  // namespace detail

/// Runs every strategy over the folder (RunnerOptions::max_frames frames at most), evaluates it against
/// DIR/groundtruth.txt and writes the summary, trajectories, plots' data and strip into runner.out_dir (when
/// runner.write_outputs). False with `error` when the folder, camera or detections cannot be read, a frame
/// cannot be loaded, or no strategy can run.
inline bool run_dataset(const DatasetOptions& options, DatasetRun* out, std::string* error) {
  DatasetSource source;
  if (!source.open(options, error)) return false;
  out->camera_source = source.sequence_camera().source;
  out->first_person_frame = source.first_person_frame();
  const double people_stamp = detail::first_person_stamp(source);
  out->detections_path = source.has_detections() ? source.detections_path() : std::string();
  std::vector<StrategySpec> run;
  for (const StrategySpec& s : options.strategies) {
    if (s.needs_truth() && !source.has_truth_labels())
      out->skipped.push_back(s.name + " (needs per-pixel motion truth: --truth)");
    else if (s.needs_detections && !source.has_detections()) out->skipped.push_back(s.name + " (needs detections)");
    else run.push_back(s);
  }
  if (run.empty()) {
    *error = options.dir + ": none of the strategies can run here";
    return false;
  }
  RunnerOptions ro = options.runner;
  ro.frames_to_draw = options.strip_frames;
  if (!options.pnp_seeds.empty()) ro.front_end.seed = options.pnp_seeds.front();
  std::string name = std::filesystem::path(options.dir).filename().string();
  if (name.empty()) name = std::filesystem::path(options.dir).parent_path().filename().string();
  if (!run_sequence(name, source, run, ro, &out->report, error)) return false;
  out->notes = source.notes();
  out->frames_without_depth = 0;
  const int n = std::min(source.size(), ro.max_frames);
  for (int i = 0; i < n; ++i) out->frames_without_depth += source.index().frames[static_cast<std::size_t>(i)].has_depth() ? 0 : 1;
  if (source.index().groundtruth_path.empty() ||
      !evaluate_against_file(source.index().groundtruth_path, &out->report, ro))
    out->notes.push_back(options.dir + ": no usable groundtruth.txt, ATE and RPE not computed" +
                         (out->report.truth_note.empty() ? std::string() : " (" + out->report.truth_note + ")"));
  for (const StrategyRun& r : out->report.runs) {
    DatasetRow row;
    row.strategy = r.spec.name;
    row.culls = r.spec.culls;
    row.recommended = r.spec.recommended;
    row.frames = r.frames;
    row.lost_frames = r.fallbacks;
    row.keyframes = r.keyframes;
    row.ate_rmse_m = r.has_ate ? r.ate_rmse_m : std::numeric_limits<double>::quiet_NaN();
    row.ate_pairs = r.ate_pairs;
    if (!out->report.truth.empty()) {
      const eval::RpeResult<double> rpe = eval::evaluate_rpe(out->report.truth, r.estimate);
      if (rpe.ok()) {
        row.rpe_trans_m = rpe.translation_m.rmse;
        row.rpe_rot_deg = rpe.rotation_deg.rmse;
        row.rpe_pairs = rpe.num_pairs;
        if (std::isfinite(people_stamp)) row.ate_before_people_m = detail::ate_before(out->report.truth, r.estimate, people_stamp);
      } else {
        out->notes.push_back(r.spec.name + ": RPE not computed (" + rpe.reason + ")");
      }
    }
    row.culled_in_person_boxes = r.box_culls.culled_in_person_boxes();
    row.culled_in_other_boxes = r.box_culls.culled_in_other_boxes();
    row.culled_outside_boxes = r.box_culls.culled_outside_boxes();
    if (out->report.has_label_truth && r.spec.culls) {
      row.precision = r.labels.precision();
      row.recall = r.labels.recall();
    }
    row.cull_ms = r.cull_ms_per_frame();
    row.front_end_ms = r.front_end_ms_per_frame();
    out->rows.push_back(row);
  }
  if (options.pnp_seeds.size() > 1 && !detail::rerun_with_seeds(options, source, run, ro, name, out, error)) return false;
  if (!ro.write_outputs) return true;
  const std::string csv = ro.out_dir + "/dataset_summary.csv";
  std::ofstream(csv) << dataset_summary_csv(out->rows);
  out->files.push_back(csv);
  std::string drawn = run.back().name;
  for (const StrategySpec& s : run)
    if (s.recommended) drawn = s.name;
  const std::string strip = ro.out_dir + "/" + name + "_frame_strip.png";
  if (write_frame_strip(strip, detail::dataset_strip(out->report, drawn), 320, 4, 16)) out->files.push_back(strip);
  for (const std::string& f : out->report.files) out->files.push_back(f);
  return true;
}

}  // namespace vo
}  // namespace dyncull
