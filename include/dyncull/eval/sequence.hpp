/// @file sequence.hpp
/// Index of a TUM-format RGB-D sequence folder (Sturm et al. 2012; also the Bonn RGB-D Dynamic layout,
/// Palazzolo et al. 2019): rgb.txt and depth.txt associated by nearest timestamp as TUM's associate.py,
/// the intrinsics (camera.txt, a command-line list, or TUM's fr1/fr2/fr3 by name) and per-frame detector
/// boxes (a folder of per-frame JSON matched by timestamp, or YOLO text). No paper equation. Standard
/// library only: it indexes the folder, the caller loads the images.
///
/// API:
///   SequenceIndex s = read_sequence(dir);        // s.frames[i]: timestamp, image_path, depth_path ("" = none)
///   CameraResult c = camera_from_spec(spec);     // camera.txt path, "fx,fy,cx,cy[,k1,k2,p1,p2,k3]" or "fr3"
///   SequenceDetections d = read_sequence_detections(path, s, 640, 480);  // d.per_frame[i]
/// Problems that do not stop the reading (a listed file missing, a frame without a depth partner, a frame
/// without a detections file) are listed in `notes` as "file:line: what".
#pragma once

#include "dyncull/core/box.hpp"
#include "dyncull/core/camera_bounds.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/core/text.hpp"
#include "dyncull/core/text_file.hpp"
#include "dyncull/culling/detections.hpp"
#include "dyncull/eval/trajectory.hpp"
#include "dyncull/eval/yolo_json.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace dyncull::eval {

/// How a sequence folder is read.
struct SequenceOptions {
  /// rgb / depth pairs need |t_rgb - t_depth| < this (associate.py --max_difference).
  double max_difference_s = 0.02;
  /// A detections file pairs with the frame whose rgb stamp is within this (the JSON stamp is the rgb stamp).
  double detection_max_difference_s = 0.005;
  std::size_t max_line_chars = text::kMaxLineChars;  ///< longer data lines are a ParseError
  std::size_t max_frames = 1000000;                  ///< listed frames beyond this are a ParseError
  std::size_t max_notes = 32;                        ///< notes kept (the rest are only counted)
  bool check_files = true;                           ///< report listed images that do not exist
  DetectionOptions<float> detection_filter{};        ///< boxes of both formats go through filter_detections

  Status validate(std::string* reason = nullptr) const {
    auto bad = [&](const char* why) {
      if (reason) *reason = why;
      return Status::InvalidInput;
    };
    if (!(max_difference_s > 0.0) || !(max_difference_s <= AssociationOptions::kMaxDifferenceS))
      return bad("SequenceOptions: max_difference_s must be in (0, 10] seconds");
    if (!(detection_max_difference_s > 0.0) || !(detection_max_difference_s <= AssociationOptions::kMaxDifferenceS))
      return bad("SequenceOptions: detection_max_difference_s must be in (0, 10] seconds");
    if (max_line_chars < 16) return bad("SequenceOptions: max_line_chars must be at least 16");
    if (max_frames == 0) return bad("SequenceOptions: max_frames must be positive");
    if (reason) reason->clear();
    return Status::Ok;
  }
};

/// Problems that do not stop the reading: the first max_notes as "file:line: what", and their count.
struct SequenceNotes {
  std::vector<std::string> first;
  std::size_t count = 0;
  void add(std::string note, std::size_t max_notes) {
    ++count;
    if (first.size() < max_notes) first.push_back(std::move(note));
  }
};

/// One frame: an rgb.txt entry and the depth image associated with it.
struct SequenceFrame {
  double timestamp = 0;          ///< the rgb stamp, seconds
  std::string image_path;        ///< as listed, relative to the folder
  std::string depth_path;        ///< as listed; empty when the frame has no depth (the frame runs without)
  double depth_timestamp = std::numeric_limits<double>::quiet_NaN();
  std::size_t image_line = 0;    ///< line of rgb.txt
  bool has_depth() const { return !depth_path.empty(); }
};

struct SequenceIndex {
  Status status = Status::Ok;
  std::string reason;  ///< "file:line: why" on a ParseError, "path: why" on an IoError
  bool ok() const { return status == Status::Ok; }
  std::string dir;
  std::vector<SequenceFrame> frames;  ///< sorted by stamp; frames whose image is missing are left out
  std::size_t frames_without_depth = 0;
  std::size_t missing_images = 0;     ///< rgb.txt entries left out because the file does not exist
  std::size_t missing_depth = 0;      ///< depth.txt entries ignored because the file does not exist
  std::string groundtruth_path;       ///< dir/groundtruth.txt when it exists, else empty
  SequenceNotes notes;
};

/// Pinhole intrinsics, optional Brown-Conrady distortion (OpenCV order k1 k2 p1 p2 k3) and the depth scale.
struct SequenceCamera {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  std::array<double, 5> distortion{};  ///< k1 k2 p1 p2 k3
  double depth_units_per_metre = 5000;  ///< TUM and Bonn: 5000
  int width = 640, height = 480;
  std::string source;  ///< where it came from (file, "command line", TUM name)
  bool has_distortion() const {
    return std::any_of(distortion.begin(), distortion.end(), [](double d) { return d != 0.0; });
  }
  /// The camera check of core/camera_bounds.hpp (intrinsics for width x height, distortion, depth scale):
  /// Ok, or InvalidInput naming the value. Every reader here runs it; run it again after changing the
  /// image size (a caller that takes the size from the images).
  Status validate(std::string* reason = nullptr) const {
    return check_camera(fx, fy, cx, cy, width, height, distortion.data(), distortion.size(), depth_units_per_metre,
                        reason);
  }
};

struct CameraResult {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }
  SequenceCamera camera;
};

/// Per-frame boxes of a sequence, index-aligned with SequenceIndex::frames.
struct SequenceDetections {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }
  std::vector<std::vector<Detection<float>>> per_frame;
  std::vector<std::uint8_t> has_file;    ///< 1 when a detections file / line set was found for the frame
  std::size_t frames_with_file = 0;
  std::size_t files_unmatched = 0;       ///< JSON files whose stamp matches no frame
  std::size_t boxes_read = 0, boxes_dropped = 0;  ///< dropped by SequenceOptions::detection_filter
  SequenceNotes notes;
};

namespace detail {

/// Calls line(number, text) for each line of a regular file of at most max_bytes (text::LineReader:
/// streaming, bounded), '\r' stripped. IoError for a missing, non-regular or unreadable file; ParseError "path:line: ..." for
/// a data line over max_chars or past the line limit. `line` returns false to stop with its own reason.
template <class Fn>
Status for_each_line(const std::string& path, std::size_t max_chars, std::string* reason, Fn&& line,
                     std::uint64_t max_bytes = text::kMaxListFileBytes) {
  text::LineReaderOptions limits;
  limits.max_line_chars = max_chars;
  limits.max_bytes = max_bytes;
  text::LineReader in;
  if (!in.open(path, limits)) {
    *reason = in.error();
    return Status::IoError;
  }
  std::string_view text;
  for (text::LineStatus s; (s = in.next(&text)) != text::LineStatus::End;) {
    if (s == text::LineStatus::TooManyLines) {
      *reason = in.error();
      return Status::ParseError;
    }
    if (s == text::LineStatus::ReadError) {
      *reason = in.error();
      return Status::IoError;
    }
    if (!text.empty() && text.back() == '\r') text.remove_suffix(1);
    const std::size_t first = text.find_first_not_of(" \t");
    const bool comment = first == std::string_view::npos || text[first] == '#';
    if (s == text::LineStatus::TooLong && !comment) {
      *reason = text::line_location(in) + "line longer than " + std::to_string(max_chars) + " characters";
      return Status::ParseError;
    }
    if (!line(in.line_number(), text, reason)) return Status::ParseError;
  }
  return Status::Ok;
}

/// Whitespace-separated fields of a line (space, tab, comma as TUM's scripts accept).
inline std::vector<std::string_view> fields_of(std::string_view line) {
  std::vector<std::string_view> out;
  const auto sep = [](char c) { return c == ' ' || c == '\t' || c == ','; };
  std::size_t k = 0;
  while (k < line.size()) {
    while (k < line.size() && sep(line[k])) ++k;
    const std::size_t start = k;
    while (k < line.size() && !sep(line[k])) ++k;
    if (k > start) out.push_back(line.substr(start, k - start));
  }
  return out;
}

struct ListEntry {
  double timestamp = 0;
  std::string path;
  std::size_t line = 0;
};

/// A TUM list ("timestamp filename" per line, '#' comments); extra fields are ignored.
inline Status read_list(const std::string& path, const SequenceOptions& options, std::vector<ListEntry>* out,
                        std::string* reason) {
  return for_each_line(path, options.max_line_chars, reason,
                       [&](std::size_t number, std::string_view line, std::string* why) {
                         const std::size_t first = line.find_first_not_of(" \t");
                         if (first == std::string_view::npos || line[first] == '#') return true;
                         const std::string where = path + ":" + std::to_string(number) + ": ";
                         const std::vector<std::string_view> f = fields_of(line);
                         if (f.size() < 2) {
                           *why = where + "expected 'timestamp filename'";
                           return false;
                         }
                         ListEntry e;
                         e.line = number;
                         if (text::parse_python_float(f[0], &e.timestamp) != text::NumberStatus::Ok ||
                             !std::isfinite(e.timestamp)) {
                           *why = where + "timestamp " + text::quote_token(f[0]) + " is not a finite number";
                           return false;
                         }
                         if (out->size() >= options.max_frames) {
                           *why = where + "more than " + std::to_string(options.max_frames) + " entries";
                           return false;
                         }
                         e.path = std::string(f[1]);
                         out->push_back(std::move(e));
                         return true;
                       });
}

/// Sorted by stamp; of equal stamps the later line wins (associate.py's dict), the others are noted.
inline void sort_unique(std::vector<ListEntry>* list, const std::string& file, const SequenceOptions& options,
                        SequenceNotes* notes) {
  std::stable_sort(list->begin(), list->end(),
                   [](const ListEntry& a, const ListEntry& b) { return a.timestamp < b.timestamp; });
  std::vector<ListEntry> out;
  for (ListEntry& e : *list) {
    if (!out.empty() && out.back().timestamp == e.timestamp) {
      notes->add(file + ":" + std::to_string(out.back().line) + ": same stamp as line " + std::to_string(e.line) +
                     ", which is used instead",
                 options.max_notes);
      out.back() = std::move(e);
    } else {
      out.push_back(std::move(e));
    }
  }
  *list = std::move(out);
}

inline bool file_exists(const std::string& path) {
  std::error_code ec;
  return std::filesystem::is_regular_file(path, ec);
}

inline bool parse_number(std::string_view token, double* out) {
  return text::parse_python_float(token, out) == text::NumberStatus::Ok && std::isfinite(*out);
}

inline CameraResult camera_error(Status status, std::string reason) {
  CameraResult r;
  r.status = status;
  r.reason = std::move(reason);
  return r;
}

/// The camera check every entry shares (core/camera_bounds.hpp): intrinsics within the ranges a camera
/// has for its image size, distortion and depth scale within physical ranges. `where` names the source.
inline CameraResult checked_camera(SequenceCamera c, const std::string& where) {
  std::string why;
  if (c.validate(&why) != Status::Ok) return camera_error(Status::InvalidInput, where + why);
  CameraResult r;
  r.camera = std::move(c);
  return r;
}

}  // namespace detail

/// camera.txt: one "key value" per line ('#' comments): fx, fy, cx, cy (required), k1 k2 p1 p2 k3,
/// depth_units_per_metre, width, height (optional); at most text::kMaxCameraFileBytes. An unknown key, a
/// repeated key or a bad value is a ParseError naming file:line; a camera outside the physical ranges of
/// core/camera_bounds.hpp is InvalidInput naming the value. Keys and the path are quoted (text::quote_token,
/// text::quote_path) in reasons.
inline CameraResult read_camera_file(const std::string& path, const SequenceOptions& options = {}) {
  SequenceCamera c;
  c.source = text::quote_path(path);
  std::map<std::string, std::size_t> seen;
  std::string reason;
  const std::string shown = text::quote_path(path);
  const Status st = detail::for_each_line(
      path, options.max_line_chars, &reason,
      [&](std::size_t number, std::string_view line, std::string* why) {
        const std::size_t first = line.find_first_not_of(" \t");
        if (first == std::string_view::npos || line[first] == '#') return true;
        const std::string where = shown + ":" + std::to_string(number) + ": ";
        const std::vector<std::string_view> f = detail::fields_of(line);
        if (f.size() != 2) {
          *why = where + "expected 'key value'";
          return false;
        }
        static const std::array<const char*, 12> keys = {"fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3",
                                                          "depth_units_per_metre", "width", "height"};
        const auto k = std::find_if(keys.begin(), keys.end(), [&](const char* s) { return f[0] == s; });
        if (k == keys.end()) {
          *why = where + "unknown key " + text::quote_token(f[0]) +
                 " (fx fy cx cy k1 k2 p1 p2 k3 depth_units_per_metre width height)";
          return false;
        }
        const std::string key(*k);  // one of the names above: printable
        double v = 0;
        if (!detail::parse_number(f[1], &v)) {
          *why = where + key + ": " + text::quote_token(f[1]) + " is not a finite number";
          return false;
        }
        if (seen.count(key)) {
          *why = where + key + " repeats line " + std::to_string(seen[key]);
          return false;
        }
        seen[key] = number;
        const std::size_t i = static_cast<std::size_t>(k - keys.begin());
        double* const intrinsics[4] = {&c.fx, &c.fy, &c.cx, &c.cy};
        if (i < 4) *intrinsics[i] = v;
        else if (i < 9) c.distortion[i - 4] = v;
        else if (i == 9) c.depth_units_per_metre = v;
        else {
          if (!(v >= 1 && v <= 100000) || v != std::floor(v)) {
            *why = where + key + " must be a whole number of pixels in [1, 100000]";
            return false;
          }
          (i == 10 ? c.width : c.height) = static_cast<int>(v);  // checked: a whole number in [1, 100000]
        }
        return true;
      },
      text::kMaxCameraFileBytes);
  if (st != Status::Ok) return detail::camera_error(st, reason);
  for (const char* required : {"fx", "fy", "cx", "cy"})
    if (!seen.count(required)) return detail::camera_error(Status::ParseError, shown + ": no " + required);
  return detail::checked_camera(c, shown + ": ");
}

/// TUM's published intrinsics (ROS default calibration of the three Kinects): "fr1" / "freiburg1",
/// "fr2" / "freiburg2", "fr3" / "freiburg3"; the name may be a folder name containing one of them.
/// InvalidInput when none is named.
inline CameraResult tum_camera(const std::string& name) {
  SequenceCamera c;
  c.source = "TUM " + text::quote_path(name);
  auto has = [&](const char* s) { return name.find(s) != std::string::npos; };
  if (has("freiburg1") || has("fr1")) {
    c.fx = 517.3, c.fy = 516.5, c.cx = 318.6, c.cy = 255.3;
  } else if (has("freiburg2") || has("fr2")) {
    c.fx = 520.9, c.fy = 521.0, c.cx = 325.1, c.cy = 249.7;
  } else if (has("freiburg3") || has("fr3")) {
    c.fx = 535.4, c.fy = 539.2, c.cx = 320.1, c.cy = 247.6;
  } else {
    return detail::camera_error(Status::InvalidInput, text::quote_token(name) + " names none of TUM's cameras fr1, fr2, fr3");
  }
  CameraResult r;
  r.camera = c;
  return r;
}

/// A camera from the command line: an existing file is read as camera.txt; "fx,fy,cx,cy[,k1,k2,p1,p2,k3]"
/// (depth 5000 units per metre); else a TUM name (tum_camera).
inline CameraResult camera_from_spec(const std::string& spec, const SequenceOptions& options = {}) {
  std::error_code ec;
  // A NUL byte ends a file name early (".\0..." would name the current folder): such a spec is no path.
  if (spec.find('\0') == std::string::npos && std::filesystem::exists(spec, ec)) return read_camera_file(spec, options);
  const std::vector<std::string_view> f = detail::fields_of(spec);
  const std::string shown = "camera " + text::quote_token(spec);  // user text: escaped and cut to 32 characters
  double first = 0;
  if (!f.empty() && detail::parse_number(f[0], &first)) {
    if (f.size() != 4 && f.size() != 9)
      return detail::camera_error(Status::InvalidInput, shown + ": expected fx,fy,cx,cy or fx,fy,cx,cy,k1,k2,p1,p2,k3 (" +
                                                            std::to_string(f.size()) + " numbers given)");
    SequenceCamera c;
    c.source = "command line";
    double v[9] = {};
    for (std::size_t k = 0; k < f.size(); ++k)
      if (!detail::parse_number(f[k], &v[k]))
        return detail::camera_error(Status::InvalidInput, shown + ": value " + std::to_string(k + 1) + " " +
                                                              text::quote_token(f[k]) + " is not a finite number");
    c.fx = v[0], c.fy = v[1], c.cx = v[2], c.cy = v[3];
    for (std::size_t k = 4; k < f.size(); ++k) c.distortion[k - 4] = v[k];
    return detail::checked_camera(c, shown + ": ");
  }
  CameraResult r = tum_camera(spec);
  if (!r.ok()) r.reason = "camera: no file " + text::quote_token(spec) + ", not fx,fy,cx,cy, and " + r.reason;
  return r;
}

/// Reads dir/rgb.txt and dir/depth.txt and associates them as associate.py (every pair within
/// max_difference_s, greedy by |difference|, each stamp used once). An rgb entry whose image is missing
/// is left out; a depth entry whose file is missing is ignored, so its frame may run without depth;
/// a frame without a depth partner keeps depth_path empty. All three are noted. IoError / ParseError
/// when a list cannot be read or parsed, TooFewPoints when rgb.txt lists no existing image.
inline SequenceIndex read_sequence(const std::string& dir, const SequenceOptions& options = {}) {
  SequenceIndex s;
  s.dir = dir;
  if (options.validate(&s.reason) != Status::Ok) {
    s.status = Status::InvalidInput;
    return s;
  }
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) {
    s.status = Status::IoError;
    s.reason = dir + ": not a directory";
    return s;
  }
  const std::string rgb_file = dir + "/rgb.txt", depth_file = dir + "/depth.txt";
  std::vector<detail::ListEntry> rgb, depth;
  s.status = detail::read_list(rgb_file, options, &rgb, &s.reason);
  if (s.ok()) s.status = detail::read_list(depth_file, options, &depth, &s.reason);
  if (!s.ok()) return s;
  detail::sort_unique(&rgb, rgb_file, options, &s.notes);
  detail::sort_unique(&depth, depth_file, options, &s.notes);
  auto missing = [&](const std::vector<detail::ListEntry>& list, const std::string& file, std::size_t* count) {
    std::vector<detail::ListEntry> kept;
    for (const detail::ListEntry& e : list) {
      if (!options.check_files || detail::file_exists(dir + "/" + e.path)) {
        kept.push_back(e);
      } else {
        ++*count;
        s.notes.add(file + ":" + std::to_string(e.line) + ": " + text::quote_path(e.path) + " does not exist",
                    options.max_notes);
      }
    }
    return kept;
  };
  rgb = missing(rgb, rgb_file, &s.missing_images);
  depth = missing(depth, depth_file, &s.missing_depth);
  if (rgb.empty()) {
    s.status = Status::TooFewPoints;
    s.reason = rgb_file + ": lists no existing image";
    return s;
  }
  std::vector<double> rgb_t, depth_t;
  for (const auto& e : rgb) rgb_t.push_back(e.timestamp);
  for (const auto& e : depth) depth_t.push_back(e.timestamp);
  std::vector<int> partner(rgb.size(), -1);
  if (!depth.empty()) {
    AssociationOptions ao;
    ao.max_difference_s = options.max_difference_s;
    const AssociationResult m = associate(rgb_t, depth_t, ao);  // TooFewPoints: nothing pairs, all frames noted below
    for (std::size_t k = 0; k < m.size(); ++k) partner[m.first[k]] = static_cast<int>(m.second[k]);
  }
  for (std::size_t i = 0; i < rgb.size(); ++i) {
    SequenceFrame f;
    f.timestamp = rgb[i].timestamp;
    f.image_path = rgb[i].path;
    f.image_line = rgb[i].line;
    if (partner[i] >= 0) {
      f.depth_path = depth[static_cast<std::size_t>(partner[i])].path;
      f.depth_timestamp = depth[static_cast<std::size_t>(partner[i])].timestamp;
    } else {
      ++s.frames_without_depth;
      char dt[32];
      std::snprintf(dt, sizeof dt, "%g", options.max_difference_s);
      s.notes.add(rgb_file + ":" + std::to_string(rgb[i].line) + ": frame " + std::to_string(i) + " (" +
                      text::quote_path(rgb[i].path) + ") has no depth within " + dt + " s: it runs without depth",
                  options.max_notes);
    }
    s.frames.push_back(std::move(f));
  }
  if (detail::file_exists(dir + "/groundtruth.txt")) s.groundtruth_path = dir + "/groundtruth.txt";
  return s;
}

namespace detail {

inline void keep_filtered(const std::vector<Detection<float>>& boxes, int width, int height,
                          const SequenceOptions& options, SequenceDetections* d, std::vector<Detection<float>>* out) {
  const DetectionsResult<float> f = filter_detections(boxes, width, height, options.detection_filter);
  d->boxes_read += boxes.size();
  d->boxes_dropped += boxes.size() - f.detections.size();
  out->insert(out->end(), f.detections.begin(), f.detections.end());
}

/// A folder's *.json names (not starting with '_'), sorted; ParseError past max_frames of them (the
/// reader's frame limit: a folder with more files than a sequence may have frames is refused, never cut
/// in directory order), IoError when the folder cannot be listed.
inline Status list_json_files(const std::string& dir, const SequenceOptions& options, std::vector<std::string>* files,
                              std::string* reason) {
  std::error_code ec;
  for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::filesystem::path& p = it->path();
    if (p.extension() != ".json" || p.filename().string().front() == '_') continue;
    if (files->size() >= options.max_frames) {
      *reason = text::quote_path(dir) + ": more than " + std::to_string(options.max_frames) +
                " detection files (SequenceOptions::max_frames)";
      return Status::ParseError;
    }
    files->push_back(p.string());
  }
  if (ec) {
    *reason = text::quote_path(dir) + ": " + ec.message();
    return Status::IoError;
  }
  std::sort(files->begin(), files->end());
  return Status::Ok;
}

/// A folder of per-frame JSON (yolo_json.hpp) matched to the frames by stamp. Files are read in name
/// order, and reading stops once every frame has a file within detection_max_difference_s and the last
/// file read lies past the last frame: the files after it are not read, and a note says how many.
inline void read_json_folder(const std::string& dir, const SequenceIndex& s, int width, int height,
                             const SequenceOptions& options, SequenceDetections* d) {
  std::vector<std::string> files;
  d->status = list_json_files(dir, options, &files, &d->reason);
  if (!d->ok()) return;
  std::vector<double> frame_t, file_t;
  std::vector<YoloJsonFrame<float>> parsed;
  for (const SequenceFrame& f : s.frames) frame_t.push_back(f.timestamp);
  const double tolerance = options.detection_max_difference_s;
  const double last_frame = frame_t.empty() ? 0.0 : *std::max_element(frame_t.begin(), frame_t.end());
  std::vector<std::uint8_t> covered(frame_t.size(), 0);
  std::size_t frames_covered = 0;
  const bool can_stop = !frame_t.empty() && std::is_sorted(frame_t.begin(), frame_t.end());
  std::size_t read = 0;
  for (; read < files.size(); ++read) {
    if (can_stop && frames_covered == frame_t.size() && !file_t.empty() && file_t.back() > last_frame + tolerance)
      break;
    YoloJsonFrame<float> j = read_yolo_json<float>(files[read]);
    if (!j.ok()) {
      d->status = j.status;
      d->reason = j.reason;
      return;
    }
    // Frames within the window of this stamp (frame stamps sorted): a cover, not the final pairing.
    if (can_stop) {
      const auto lo = std::lower_bound(frame_t.begin(), frame_t.end(), j.timestamp - tolerance);
      for (auto it = lo; it != frame_t.end() && *it <= j.timestamp + tolerance; ++it) {
        const std::size_t i = static_cast<std::size_t>(it - frame_t.begin());
        frames_covered += covered[i] == 0;
        covered[i] = 1;
      }
    }
    file_t.push_back(j.timestamp);
    parsed.push_back(std::move(j));
  }
  if (read < files.size())
    d->notes.add(text::quote_path(dir) + ": " + std::to_string(files.size() - read) + " files after " +
                     text::quote_path(std::filesystem::path(files[read - 1]).filename().string()) +
                     " not read: every frame has its detections file",
                 options.max_notes);
  AssociationOptions ao;
  ao.max_difference_s = tolerance;
  const AssociationResult m = associate(frame_t, file_t, ao);
  std::vector<std::uint8_t> file_used(file_t.size(), 0);
  for (std::size_t k = 0; k < m.size(); ++k) {
    const std::size_t i = m.first[k], j = m.second[k];
    d->has_file[i] = 1;
    file_used[j] = 1;
    keep_filtered(parsed[j].detections, width, height, options, d, &d->per_frame[i]);
  }
  for (std::size_t j = 0; j < file_t.size(); ++j) {
    if (file_used[j]) continue;
    ++d->files_unmatched;
    d->notes.add(text::quote_path(files[j]) + ": timestamp matches no frame", options.max_notes);
  }
}

/// YOLO text: a folder of <image stem>.txt (no file: no boxes) or one file of "<stamp or stem> class cx cy w h [conf]".
inline void read_yolo_text(const std::string& path, const SequenceIndex& s, int width, int height,
                           const SequenceOptions& options, SequenceDetections* d) {
  auto stem = [](const std::string& p) { return std::filesystem::path(p).stem().string(); };
  auto add_line = [&](std::size_t i, std::string_view yolo, const std::string& file, std::size_t number,
                      std::string* why) {
    const YoloParseResult<float> r = parse_yolo_lines<float>(yolo);
    if (!r.ok() || r.boxes.size() != 1) {
      *why = file + ":" + std::to_string(number) + ": " +
             (r.errors.empty() ? std::string("expected 'class cx cy w h [conf]'") : r.errors.front().message);
      return false;
    }
    const DetectionsResult<float> c = convert_yolo_detections<float>(r.boxes, width, height, options.detection_filter);
    d->boxes_read += 1;
    d->boxes_dropped += 1 - c.detections.size();
    // Low confidence is the filter's ordinary work; a box it cannot use at all is worth naming.
    if (c.detections.empty() && !c.rejections.empty() && c.rejections.front() != BoxRejection::LowConfidence)
      d->notes.add(file + ":" + std::to_string(number) + ": box dropped (" + to_string(c.rejections.front()) + ")",
                   options.max_notes);
    d->per_frame[i].insert(d->per_frame[i].end(), c.detections.begin(), c.detections.end());
    d->has_file[i] = 1;
    return true;
  };
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    for (std::size_t i = 0; i < s.frames.size(); ++i) {
      const std::string file = path + "/" + stem(s.frames[i].image_path) + ".txt";
      if (!file_exists(file)) continue;
      d->has_file[i] = 1;
      d->status = for_each_line(file, options.max_line_chars, &d->reason,
                                [&](std::size_t number, std::string_view line, std::string* why) {
                                  const std::size_t first = line.find_first_not_of(" \t");
                                  if (first == std::string_view::npos || line[first] == '#') return true;
                                  return add_line(i, line, file, number, why);
                                });
      if (!d->ok()) return;
    }
    return;
  }
  std::map<std::string, std::size_t> by_stem;
  for (std::size_t i = 0; i < s.frames.size(); ++i) by_stem[stem(s.frames[i].image_path)] = i;
  d->status = for_each_line(path, options.max_line_chars, &d->reason,
                            [&](std::size_t number, std::string_view line, std::string* why) {
                              const std::size_t first = line.find_first_not_of(" \t");
                              if (first == std::string_view::npos || line[first] == '#') return true;
                              const std::size_t split = line.find_first_of(" \t", first);
                              const std::string key(line.substr(first, split == std::string_view::npos ? std::string_view::npos : split - first));
                              auto it = by_stem.find(key);
                              if (it == by_stem.end()) {
                                // A stamp: the frame whose rgb stamp is nearest, within the tolerance.
                                double t = 0;
                                std::size_t best = s.frames.size();
                                if (parse_number(key, &t)) {
                                  double best_dt = options.detection_max_difference_s;
                                  for (std::size_t i = 0; i < s.frames.size(); ++i) {
                                    const double dt = std::abs(s.frames[i].timestamp - t);
                                    if (dt < best_dt) best_dt = dt, best = i;
                                  }
                                }
                                if (best == s.frames.size()) {
                                  d->notes.add(path + ":" + std::to_string(number) + ": " + text::quote_token(key) +
                                                   " names no frame",
                                               options.max_notes);
                                  ++d->files_unmatched;
                                  return true;
                                }
                                return split != std::string_view::npos && add_line(best, line.substr(split), path, number, why);
                              }
                              if (split == std::string_view::npos) {
                                *why = path + ":" + std::to_string(number) + ": expected '<stamp or stem> class cx cy w h [conf]'";
                                return false;
                              }
                              return add_line(it->second, line.substr(split), path, number, why);
                            });
}

}  // namespace detail

/// Detector boxes per frame of `sequence` from `path`: a folder holding *.json (yolo_json.hpp; matched by
/// their timestamp within detection_max_difference_s; names starting with '_' are skipped), a folder of
/// YOLO `<image stem>.txt` files, or one YOLO text file keyed by rgb stamp or image stem. Boxes pass
/// SequenceOptions::detection_filter for a width x height image. A frame without a file has no boxes and
/// has_file 0 (noted once with the count). Any unreadable or malformed file fails the whole read: culling
/// with part of a detector's boxes would measure the wrong thing.
inline SequenceDetections read_sequence_detections(const std::string& path, const SequenceIndex& sequence, int width,
                                                   int height, const SequenceOptions& options = {}) {
  SequenceDetections d;
  d.per_frame.assign(sequence.frames.size(), {});
  d.has_file.assign(sequence.frames.size(), 0);
  if (options.validate(&d.reason) != Status::Ok || width <= 0 || height <= 0) {
    d.status = Status::InvalidInput;
    if (d.reason.empty()) d.reason = "read_sequence_detections: width and height must be positive";
    return d;
  }
  std::error_code ec;
  bool json = false;
  if (std::filesystem::is_directory(path, ec)) {
    for (std::filesystem::directory_iterator it(path, ec), end; !ec && it != end; it.increment(ec))
      if (it->path().extension() == ".json") {
        json = true;
        break;
      }
  } else if (!std::filesystem::exists(path, ec)) {
    d.status = Status::IoError;
    d.reason = path + ": does not exist";
    return d;
  }
  if (json) detail::read_json_folder(path, sequence, width, height, options, &d);
  else detail::read_yolo_text(path, sequence, width, height, options, &d);
  if (!d.ok()) return d;
  for (std::uint8_t h : d.has_file) d.frames_with_file += h;
  const std::size_t without = sequence.frames.size() - d.frames_with_file;
  if (without > 0)
    d.notes.add(path + ": " + std::to_string(without) + " of " + std::to_string(sequence.frames.size()) +
                    " frames have no detections file (they run without boxes)",
                options.max_notes);
  return d;
}

}  // namespace dyncull::eval
