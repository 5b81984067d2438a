/// @file sources.hpp
/// Frame sources of the dynamic_vo demo: the synthetic dynamic scene rendered in memory
/// (dyncull::sim::Scene, with per-pixel "moving" truth) and TUM RGB-D directories (rgb.txt,
/// depth.txt, depth x 5000, optional groundtruth.txt, optional YOLO detections per frame).
#pragma once

#include "dyncull/core/box.hpp"
#include "dyncull/core/camera.hpp"
#include "dyncull/core/text.hpp"
#include "dyncull/core/text_file.hpp"
#include "dyncull/core/types.hpp"
#include "dyncull/culling/detections.hpp"
#include "dyncull/sim/scene.hpp"

#include "live_detector.hpp"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace dyncull {
namespace vo {

/// One frame as the demo consumes it. Mats may be headers over the source's buffers: valid until
/// the next load() on the same source.
struct SequenceFrame {
  double timestamp = 0;
  cv::Mat gray;     ///< CV_8UC1
  cv::Mat depth_m;  ///< CV_32FC1 metres, 0 = no measurement
  cv::Mat moving;   ///< CV_8UC1, 1 where the surface moves; empty when there is no truth
  cv::Mat instance; ///< CV_16UC1 sim instance ids (sim::SceneInstance); empty when there is no truth
  cv::Mat motion_m; ///< CV_32FC1 sim: metres the surface moved since the previous frame (sim::FrameData)
  std::vector<Detection<float>> detections;
  bool has_truth_pose = false;
  Rigid3<double> truth_world_from_cam;
  /// BGR image for drawing (only filled by load_colour()).
  cv::Mat bgr;
};

/// Synthetic walking sequence rendered on demand (deterministic for its options).
class SimSource {
 public:
  explicit SimSource(const sim::SceneOptions& options) : scene_(options) {}
  int size() const { return scene_.num_frames(); }
  PinholeCamera<double> camera() const { return scene_.camera(); }
  bool has_detections() const { return true; }
  bool has_truth_labels() const { return true; }

  bool load(int index, SequenceFrame* out, std::string* error) {
    scene_.render(index, &data_);
    if (!data_.ok()) {
      if (error) *error = "sim frame " + std::to_string(index) + ": " + data_.reason;
      return false;
    }
    const int w = data_.width, h = data_.height;
    if (w <= 0 || h <= 0 || data_.gray.size() != static_cast<std::size_t>(w) * h ||
        data_.depth_m.size() != static_cast<std::size_t>(w) * h) {
      if (error) *error = "sim frame " + std::to_string(index) + " has inconsistent buffers";
      return false;
    }
    out->timestamp = data_.timestamp;
    out->gray = cv::Mat(h, w, CV_8UC1, data_.gray.data());
    out->depth_m = cv::Mat(h, w, CV_32FC1, data_.depth_m.data());
    out->moving = data_.moving.size() == data_.gray.size() ? cv::Mat(h, w, CV_8UC1, data_.moving.data()) : cv::Mat();
    out->instance = data_.instance.size() == data_.gray.size() ? cv::Mat(h, w, CV_16UC1, data_.instance.data()) : cv::Mat();
    out->motion_m = data_.motion_m.size() == data_.gray.size() ? cv::Mat(h, w, CV_32FC1, data_.motion_m.data()) : cv::Mat();
    out->detections = data_.detections;
    out->has_truth_pose = true;
    out->truth_world_from_cam = data_.world_from_cam;
    out->bgr.release();
    return true;
  }
  void load_colour(SequenceFrame* out) const {
    if (data_.rgb.size() != static_cast<std::size_t>(data_.width) * data_.height * 3) {
      cv::cvtColor(out->gray, out->bgr, cv::COLOR_GRAY2BGR);
      return;
    }
    cv::Mat rgb(data_.height, data_.width, CV_8UC3, const_cast<std::uint8_t*>(data_.rgb.data()));
    cv::cvtColor(rgb, out->bgr, cv::COLOR_RGB2BGR);
  }

 private:
  sim::Scene scene_;
  sim::FrameData data_;
};

namespace detail {

struct StampedFile {
  double timestamp = 0;
  std::string path;
};

/// Lines of the demo's list and detection files: at most this many per file (a TUM sequence lists
/// a few thousand images; a detections file a few per image).
constexpr std::size_t kMaxListLines = 1000000;

/// TUM list file: "timestamp filename" per line (more fields ignored), '#' comments, read line by line
/// (text::LineReader: regular files only, bounded lines). The stamp is a number as Python's float()
/// reads it, whatever the locale; errors name file:line.
inline bool read_tum_list(const std::string& file, std::vector<StampedFile>* out, std::string* error) {
  text::LineReaderOptions limits;
  limits.max_lines = kMaxListLines;
  text::LineReader in;
  if (!in.open(file, limits)) {
    *error = in.error();
    return false;
  }
  const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  std::string_view line;
  for (text::LineStatus s; (s = in.next(&line)) != text::LineStatus::End;) {
    if (s == text::LineStatus::TooManyLines || s == text::LineStatus::ReadError) {
      *error = in.error();
      return false;
    }
    std::size_t k = 0;
    while (k < line.size() && space(line[k])) ++k;
    if (k < line.size() && line[k] == '#') continue;
    if (k == line.size() && s == text::LineStatus::Line) continue;
    const std::string where = text::line_location(in);
    if (s == text::LineStatus::TooLong) {
      *error = where + "line is " + std::to_string(in.line_chars()) + " bytes long (limit " +
               std::to_string(text::kMaxLineChars) + ")";
      return false;
    }
    std::string_view fields[2];
    int n = 0;
    while (k < line.size() && n < 2) {
      const std::size_t start = k;
      while (k < line.size() && !space(line[k])) ++k;
      fields[n++] = line.substr(start, k - start);
      while (k < line.size() && space(line[k])) ++k;
    }
    if (n < 2) {
      *error = where + "expected 'timestamp filename'";
      return false;
    }
    StampedFile f;
    if (text::parse_python_float(fields[0], &f.timestamp) != text::NumberStatus::Ok) {
      *error = where + "timestamp " + text::quote_token(fields[0]) + " is not a number";
      return false;
    }
    if (!std::isfinite(f.timestamp)) {
      *error = where + "timestamp " + text::quote_token(fields[0]) + " is not finite";
      return false;
    }
    f.path = std::string(fields[1]);
    out->push_back(std::move(f));
  }
  return true;
}

/// File name without directory and extension: rgb/1341846313.592026.png -> 1341846313.592026.
inline std::string stem(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  const std::size_t dot = name.find_last_of('.');
  return dot == std::string::npos ? name : name.substr(0, dot);
}

/// Malformed detection lines: the count and the first few as "file:line: reason".
struct DetectionLineErrors {
  static constexpr std::size_t kListed = 5;
  std::size_t count = 0;
  std::vector<std::string> first;
  void add(const std::string& file, int line, const std::string& why) {
    ++count;
    if (first.size() < kListed) first.push_back(file + ":" + std::to_string(line) + ": " + why);
  }
  std::string format() const {
    std::string out = std::to_string(count) + (count == 1 ? " malformed detection line" : " malformed detection lines");
    for (const std::string& e : first) out += "\n  " + e;
    if (count > first.size()) out += "\n  ...";
    return out;
  }
};

/// Boxes that parsed but the detection filter dropped (non-finite, zero size, outside the image, low
/// confidence): the count by reason and the first few as "file:line: why", so none is dropped unseen.
struct DroppedBoxes {
  static constexpr std::size_t kListed = 5;
  std::size_t count = 0, total = 0;
  std::size_t by_reason[6] = {0, 0, 0, 0, 0, 0};  ///< indexed by BoxRejection
  std::vector<std::string> first;
  std::string format() const {
    if (count == 0) return {};
    std::string out = std::to_string(count) + " of " + std::to_string(total) + " boxes dropped by the detection filter (";
    bool comma = false;
    for (std::size_t r = 1; r < 6; ++r) {
      if (by_reason[r] == 0) continue;
      out += (comma ? ", " : "") + std::to_string(by_reason[r]) + " " + to_string(static_cast<BoxRejection>(r));
      comma = true;
    }
    out += ")";
    for (const std::string& e : first) out += "\n  " + e;
    if (count > first.size()) out += "\n  ...";
    return out;
  }
};

/// Parsed YOLO lines -> pixel detections through dyncull's conversion (RTD-SLAM eq. 1-2) and filter;
/// malformed lines go to `errors`, boxes the filter drops to `dropped`, both as `file`:line.
inline void yolo_lines_to_detections(const YoloParseResult<float>& parsed, int width, int height,
                                     const std::string& file, std::vector<Detection<float>>* out,
                                     DetectionLineErrors* errors, DroppedBoxes* dropped) {
  const std::string shown = text::quote_path(file);
  for (const YoloParseError& e : parsed.errors) errors->add(shown, e.line, e.message);
  // Bad lines beyond the listed ones are counted only.
  errors->count += parsed.num_bad_lines - parsed.errors.size();
  const DetectionsResult<float> boxes = convert_yolo_detections<float>(parsed.boxes, width, height);
  out->insert(out->end(), boxes.detections.begin(), boxes.detections.end());
  dropped->total += boxes.rejections.size();
  for (std::size_t i = 0; i < boxes.rejections.size() && i < parsed.line_of_box.size(); ++i) {
    const BoxRejection why = boxes.rejections[i];
    if (why == BoxRejection::None) continue;
    ++dropped->count;
    ++dropped->by_reason[static_cast<std::size_t>(why) < 6 ? static_cast<std::size_t>(why) : 0];
    if (dropped->first.size() < DroppedBoxes::kListed)
      dropped->first.push_back(shown + ":" + std::to_string(parsed.line_of_box[i]) + ": " + to_string(why));
  }
}

}  // namespace detail

/// A TUM RGB-D sequence directory. Depth is associated to each RGB image by nearest timestamp
/// (max 0.02 s, as the TUM associate.py); RGB images without a depth partner are dropped.
class TumSource {
 public:
  /// `detections` is empty (none), a directory of YOLO label files named after the RGB image
  /// (<stem>.txt, "class cx cy w h [conf]" normalised per line; no file: no detections), or one text
  /// file whose lines are "<rgb timestamp or stem> class cx cy w h [conf]". Every file is read here:
  /// a malformed line fails the open, the error giving the count and the first few as
  /// "file:line: reason" (culling with part of a detector's boxes would measure the wrong thing).
  bool open(const std::string& dir, const std::string& detections, const PinholeCamera<double>& camera,
            std::string* error) {
    dir_ = dir;
    camera_ = camera;
    frames_.clear();
    detections_.clear();
    bad_detection_lines_ = 0;
    dropped_boxes_ = 0;
    detection_note_.clear();
    std::vector<detail::StampedFile> rgb, depth;
    if (!detail::read_tum_list(dir + "/rgb.txt", &rgb, error)) return false;
    if (!detail::read_tum_list(dir + "/depth.txt", &depth, error)) return false;
    if (rgb.empty() || depth.empty()) {
      *error = text::quote_path(dir) + ": rgb.txt or depth.txt lists no images";
      return false;
    }
    std::sort(depth.begin(), depth.end(), [](const auto& a, const auto& b) { return a.timestamp < b.timestamp; });
    for (const auto& r : rgb) {
      auto it = std::lower_bound(depth.begin(), depth.end(), r.timestamp,
                                 [](const detail::StampedFile& d, double t) { return d.timestamp < t; });
      const detail::StampedFile* best = nullptr;
      double best_dt = 0.02;
      for (auto c : {it, it == depth.begin() ? it : it - 1}) {
        if (c == depth.end()) continue;
        const double dt = std::abs(c->timestamp - r.timestamp);
        if (dt <= best_dt) {
          best_dt = dt;
          best = &*c;
        }
      }
      if (best) frames_.push_back({r, *best});
    }
    if (frames_.empty()) {
      *error = text::quote_path(dir) + ": no RGB image has a depth image within 0.02 s";
      return false;
    }
    has_detections_ = false;
    if (!detections.empty()) {
      if (!load_detections(detections, error)) return false;
      has_detections_ = true;
    }
    return true;
  }

  int size() const { return static_cast<int>(frames_.size()); }
  PinholeCamera<double> camera() const { return camera_; }
  bool has_detections() const { return has_detections_ || live_ != nullptr; }
  bool has_truth_labels() const { return false; }
  /// Boxes from this detector, run on each loaded frame, instead of any read from files (null: none).
  void use_live_detector(LiveDetector* detector) { live_ = detector; }
  /// Malformed detection lines found by the last open() (which then failed).
  std::size_t bad_detection_lines() const { return bad_detection_lines_; }
  /// Boxes that parsed but the detection filter dropped at the last open() (non-finite such as 1e400,
  /// zero size, outside the image, low confidence), and what to tell the user about them ("" if none).
  std::size_t dropped_boxes() const { return dropped_boxes_; }
  const std::string& detection_note() const { return detection_note_; }

  bool load(int index, SequenceFrame* out, std::string* error) {
    const Pair& p = frames_[static_cast<std::size_t>(index)];
    // imread would block on a FIFO and read a device without end: regular files only.
    for (const std::string* image : {&p.rgb.path, &p.depth.path}) {
      const std::string problem = text::regular_file_problem(dir_ + "/" + *image);
      if (!problem.empty()) {
        *error = problem;
        return false;
      }
    }
    bgr_ = cv::imread(dir_ + "/" + p.rgb.path, cv::IMREAD_COLOR);
    const cv::Mat raw = cv::imread(dir_ + "/" + p.depth.path, cv::IMREAD_ANYDEPTH);
    if (bgr_.empty() || raw.empty() || raw.type() != CV_16UC1 || raw.size() != bgr_.size()) {
      *error = "cannot read " + text::quote_path(p.rgb.path) + " / " + text::quote_path(p.depth.path) +
               " (need 8-bit colour and 16-bit depth of equal size)";
      return false;
    }
    cv::cvtColor(bgr_, gray_, cv::COLOR_BGR2GRAY);
    raw.convertTo(depth_, CV_32FC1, 1.0 / 5000.0);  // TUM: 5000 units per metre, 0 stays 0
    out->timestamp = p.rgb.timestamp;
    out->gray = gray_;
    out->depth_m = depth_;
    out->moving.release();
    out->instance.release();
    out->motion_m.release();
    out->detections.clear();
    if (live_ != nullptr) {
      if (!live_->detect(bgr_, &out->detections, error)) return false;
    } else if (has_detections_) {
      auto it = detections_.find(detail::stem(p.rgb.path));
      if (it != detections_.end()) out->detections = it->second;
    }
    out->has_truth_pose = false;
    out->bgr.release();
    return true;
  }
  void load_colour(SequenceFrame* out) const { out->bgr = bgr_; }

 private:
  struct Pair {
    detail::StampedFile rgb, depth;
  };

  bool load_detections(const std::string& path, std::string* error) {
    detail::DetectionLineErrors bad;
    detail::DroppedBoxes dropped;
    std::error_code ec;
    text::LineReaderOptions limits;
    limits.max_lines = detail::kMaxListLines;
    text::LineReader in;
    std::string_view line;
    const auto read_error = [&](text::LineStatus s) {
      if (s != text::LineStatus::TooManyLines && s != text::LineStatus::ReadError) return false;
      *error = "detections " + in.error();
      return true;
    };
    if (std::filesystem::is_directory(path, ec)) {
      // One label file per RGB image; YOLO writes none for an image without detections.
      for (const Pair& p : frames_) {
        const std::string key = detail::stem(p.rgb.path);
        const std::string file = path + "/" + key + ".txt";
        if (!std::filesystem::exists(file, ec)) continue;
        if (!in.open(file, limits)) {
          *error = "detections " + in.error();
          return false;
        }
        YoloParseResult<float> parsed;
        for (text::LineStatus s; (s = in.next(&line)) != text::LineStatus::End;) {
          if (read_error(s)) return false;
          add_yolo_line(line, in.line_chars(), static_cast<int>(in.line_number()), file, &parsed);
        }
        detail::yolo_lines_to_detections(parsed, camera_.width, camera_.height, file, &detections_[key], &bad, &dropped);
      }
    } else {
      // One file for the sequence: the first field keys the RGB image, the rest is a YOLO line.
      if (!in.open(path, limits)) {
        *error = "detections " + in.error();
        return false;
      }
      const std::string shown = text::quote_path(path);
      YoloParseResult<float> parsed;
      for (text::LineStatus s; (s = in.next(&line)) != text::LineStatus::End;) {
        if (read_error(s)) return false;
        const int line_no = static_cast<int>(in.line_number());
        const std::size_t first = line.find_first_not_of(" \t\r");
        if (first != std::string_view::npos && line[first] == '#') continue;
        if (first == std::string_view::npos && s == text::LineStatus::Line) continue;
        if (s == text::LineStatus::TooLong) {
          bad.add(shown, line_no, "line is " + std::to_string(in.line_chars()) + " bytes long (limit " +
                                      std::to_string(text::kMaxLineChars) + ")");
          continue;
        }
        const std::size_t split = line.find_first_of(" \t", first);
        const std::size_t rest = split == std::string_view::npos ? line.size() : line.find_first_not_of(" \t\r", split);
        if (rest == std::string_view::npos || rest >= line.size()) {
          bad.add(shown, line_no, "expected '<rgb timestamp or stem> class cx cy w h [conf]'");
          continue;
        }
        const std::string key(line.substr(first, std::min<std::size_t>(split, line.size()) - first));
        parsed = YoloParseResult<float>();
        const std::string_view yolo = line.substr(split);
        add_yolo_line(yolo, yolo.size(), line_no, path, &parsed);
        detail::yolo_lines_to_detections(parsed, camera_.width, camera_.height, path, &detections_[key], &bad, &dropped);
      }
    }
    bad_detection_lines_ = bad.count;
    if (bad.count > 0) {
      *error = "detections " + text::quote_path(path) + ": " + bad.format();
      return false;
    }
    dropped_boxes_ = dropped.count;
    if (dropped.count > 0) detection_note_ = "detections " + text::quote_path(path) + ": " + dropped.format();
    return true;
  }

  std::string dir_;
  PinholeCamera<double> camera_;
  std::vector<Pair> frames_;
  std::map<std::string, std::vector<Detection<float>>> detections_;
  bool has_detections_ = false;
  std::size_t bad_detection_lines_ = 0;
  LiveDetector* live_ = nullptr;
  std::size_t dropped_boxes_ = 0;
  std::string detection_note_;
  cv::Mat bgr_, gray_, depth_;
};

/// TUM intrinsics by sequence name (freiburg1/2/3), fr3 otherwise (TUM's published values).
inline PinholeCamera<double> tum_camera_for(const std::string& dir) {
  if (dir.find("freiburg1") != std::string::npos || dir.find("fr1") != std::string::npos)
    return PinholeCamera<double>{517.3, 516.5, 318.6, 255.3, 640, 480};
  if (dir.find("freiburg2") != std::string::npos || dir.find("fr2") != std::string::npos)
    return PinholeCamera<double>{520.9, 521.0, 325.1, 249.7, 640, 480};
  return PinholeCamera<double>::tum_fr3();
}

}  // namespace vo
}  // namespace dyncull
