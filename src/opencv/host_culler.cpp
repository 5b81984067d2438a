// The host glue (opencv/host_culler.hpp): settings from the environment, the detections folder read once
// and looked up by timestamp, box-only culling, the per-frame CSV log and the summary line.
#include "dyncull/opencv/host_culler.hpp"

#include "dyncull/core/text.hpp"
#include "dyncull/eval/yolo_json.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <utility>

namespace dyncull {
namespace cv_adapter {

namespace {

using Mode = HostCuller::Mode;

struct StampedBoxes {
  double stamp = 0;
  std::vector<DetectedBox> boxes;
};

[[noreturn]] void fail(const std::string& message) {
  std::fprintf(stderr, "dyncull: %s\n", message.c_str());
  throw std::invalid_argument("dyncull: " + message);
}

std::string environment(const char* name) {
  const char* value = std::getenv(name);
  return value ? std::string(value) : std::string();
}

std::string bad_variable(const char* name, const std::string& value, const char* expected) {
  return std::string(name) + "=" + text::quote_token(value) + ": expected " + expected;
}

Mode mode_from_text(const std::string& value, bool has_detections) {
  if (value.empty()) return has_detections ? Mode::Culler : Mode::Stock;
  if (value == "stock") return Mode::Stock;
  if (value == "box_only") return Mode::BoxOnly;
  if (value == "culler") return Mode::Culler;
  fail(bad_variable("DYNCULL_MODE", value, "stock, box_only or culler"));
}

double number_from_text(const char* name, const std::string& value, double fallback) {
  if (value.empty()) return fallback;
  double out = 0;
  if (text::parse_python_float(value, &out) != text::NumberStatus::Ok || !(out >= 0) || !std::isfinite(out))
    fail(bad_variable(name, value, "a number of seconds, 0 or more"));
  return out;
}

std::vector<int> classes_from_text(const std::string& value, std::vector<int> fallback) {
  if (value.empty()) return fallback;
  std::vector<int> out;
  std::size_t start = 0;
  while (start <= value.size()) {
    const std::size_t comma = std::min(value.find(',', start), value.size());
    const std::string token = value.substr(start, comma - start);
    double id = 0;
    long long whole = 0;
    if (text::parse_python_float(token, &id) != text::NumberStatus::Ok || !text::integer_in_range(id, 0, 1000000, &whole))
      fail(bad_variable("DYNCULL_BOX_CLASSES", value, "comma-separated class ids such as 0,2"));
    out.push_back(static_cast<int>(whole));
    start = comma + 1;
  }
  return out;
}

DetectedBox to_detected_box(const Detection<float>& d) {
  return DetectedBox(d.box.x0, d.box.y0, d.box.x1, d.box.y1, d.class_id, d.confidence);
}

std::vector<StampedBoxes> read_detections(const std::string& dir) {
  std::error_code ec;
  if (dir.empty()) fail("DYNCULL_DETECTIONS is not set: box_only and culler need a folder of NNNNNN.json detections");
  if (!std::filesystem::is_directory(dir, ec)) fail("detections folder " + text::quote_path(dir) + ": no such directory");
  const eval::YoloJsonSequence<float> seq = eval::read_yolo_json_sequence<float>(dir);
  if (!seq.ok()) fail("detections folder: " + seq.reason);
  std::vector<StampedBoxes> out;
  out.reserve(seq.frames.size());
  for (const eval::YoloJsonFrame<float>& f : seq.frames) {
    StampedBoxes s;
    s.stamp = f.timestamp;
    for (const Detection<float>& d : f.detections) s.boxes.push_back(to_detected_box(d));
    out.push_back(std::move(s));
  }
  std::sort(out.begin(), out.end(), [](const StampedBoxes& a, const StampedBoxes& b) { return a.stamp < b.stamp; });
  return out;
}

bool inside_any(const cv::KeyPoint& key, const std::vector<DetectedBox>& boxes, const std::vector<int>& classes) {
  for (const DetectedBox& b : boxes) {
    if (std::find(classes.begin(), classes.end(), b.class_id) == classes.end()) continue;
    if (key.pt.x >= b.x0 && key.pt.x <= b.x1 && key.pt.y >= b.y0 && key.pt.y <= b.y1) return true;
  }
  return false;
}

}  // namespace

struct HostCuller::Impl {
  Settings settings;
  std::vector<StampedBoxes> detections;
  std::unique_ptr<Culler> culler;
  std::vector<std::uint8_t> keep;
  std::ofstream log;
  Stats stats;
  bool has_frame = false;
  unsigned long last_frame_id = 0;
  bool warned_missing = false;

  void write_log(double stamp, const char* status, const std::string& reason, std::size_t boxes, bool found,
                 double ms) {
    if (!log.is_open()) return;
    char line[160];
    std::snprintf(line, sizeof line, "%.6f,%s,%s,", stamp, to_string(settings.mode), status);
    std::string quoted = reason;
    std::replace(quoted.begin(), quoted.end(), ',', ';');
    log << line << quoted << ',' << keep.size() << ',' << std::count(keep.begin(), keep.end(), std::uint8_t(1))
        << ',' << (found ? std::to_string(boxes) : std::string("none")) << ',' << ms << '\n';
  }

  void note_missing(double stamp) {
    ++stats.frames_without_detections;
    if (warned_missing) return;
    warned_missing = true;
    std::fprintf(stderr, "dyncull: no detections file within %g s of stamp %.6f in %s: this frame is culled without boxes "
                 "(further such frames are counted in the summary)\n", settings.stamp_tolerance_s, stamp,
                 text::quote_path(settings.detections_dir).c_str());
  }
};

HostCuller::Settings HostCuller::environment_settings() {
  Settings s;
  s.detections_dir = environment("DYNCULL_DETECTIONS");
  s.mode = mode_from_text(environment("DYNCULL_MODE"), !s.detections_dir.empty());
  const std::string preset = environment("DYNCULL_PRESET");
  if (!preset.empty()) s.preset = preset;
  s.stamp_tolerance_s = number_from_text("DYNCULL_STAMP_TOLERANCE", environment("DYNCULL_STAMP_TOLERANCE"), s.stamp_tolerance_s);
  s.log_path = environment("DYNCULL_LOG");
  s.box_only_classes = classes_from_text(environment("DYNCULL_BOX_CLASSES"), s.box_only_classes);
  return s;
}

HostCuller::HostCuller(const Settings& settings) : impl_(new Impl) {
  impl_->settings = settings;
  if (settings.mode != Mode::Stock) impl_->detections = read_detections(settings.detections_dir);
  if (!settings.log_path.empty()) {
    impl_->log.open(settings.log_path);
    if (!impl_->log) fail("DYNCULL_LOG " + text::quote_path(settings.log_path) + ": cannot open for writing");
    impl_->log << "stamp,mode,status,reason,features,kept,boxes,ms\n";
  }
  std::fprintf(stderr, "dyncull: mode %s%s%s (%zu detection frames)\n", to_string(settings.mode),
               settings.mode == Mode::Culler ? ", preset " : "", settings.mode == Mode::Culler ? settings.preset.c_str() : "",
               impl_->detections.size());
}

HostCuller::~HostCuller() {
  if (impl_ && impl_->stats.frames > 0) std::fprintf(stderr, "%s\n", summary().c_str());
}

const HostCuller::Settings& HostCuller::settings() const { return impl_->settings; }
const HostCuller::Stats& HostCuller::stats() const { return impl_->stats; }

const char* HostCuller::to_string(Mode mode) {
  switch (mode) {
    case Mode::Stock: return "stock";
    case Mode::BoxOnly: return "box_only";
    case Mode::Culler: return "culler";
  }
  return "?";
}

bool HostCuller::detections_for(double stamp, std::vector<DetectedBox>* boxes) const {
  const std::vector<StampedBoxes>& d = impl_->detections;
  auto it = std::lower_bound(d.begin(), d.end(), stamp - impl_->settings.stamp_tolerance_s,
                             [](const StampedBoxes& s, double t) { return s.stamp < t; });
  const StampedBoxes* best = nullptr;
  for (; it != d.end() && it->stamp <= stamp + impl_->settings.stamp_tolerance_s; ++it)
    if (!best || std::fabs(it->stamp - stamp) < std::fabs(best->stamp - stamp)) best = &*it;
  if (!best) return false;
  *boxes = best->boxes;
  return true;
}

const std::vector<std::uint8_t>* HostCuller::cull(double stamp, unsigned long frame_id, const cv::Mat& K,
                                                  const cv::Mat& distortion, cv::Size image_size,
                                                  const std::vector<cv::KeyPoint>& keys,
                                                  const std::vector<cv::KeyPoint>& keys_un, const cv::Mat& descriptors,
                                                  const cv::Mat& depth, const cv::Mat& predicted_Tcw) {
  Impl& m = *impl_;
  const auto start = std::chrono::steady_clock::now();
  ++m.stats.frames;
  m.stats.features_in += static_cast<double>(keys.size());
  if (m.settings.mode == Mode::Stock) {
    m.stats.features_kept += static_cast<double>(keys.size());
    return nullptr;
  }
  if (m.has_frame && frame_id <= m.last_frame_id && m.culler) {
    m.culler->reset();  // the host restarted its map: the keyframe belongs to the old one
    ++m.stats.restarts;
  }
  m.has_frame = true;
  m.last_frame_id = frame_id;

  std::vector<DetectedBox> boxes;
  const bool found = detections_for(stamp, &boxes);
  if (!found) m.note_missing(stamp);
  const char* status = "Ok";
  std::string reason = found ? std::string() : std::string("no detections file for this stamp");
  if (m.settings.mode == Mode::BoxOnly) {
    m.keep.assign(keys.size(), 1);
    for (std::size_t i = 0; i < keys.size(); ++i)
      if (inside_any(keys[i], boxes, m.settings.box_only_classes)) m.keep[i] = 0;
  } else {
    if (!m.culler) {
      m.culler.reset(new Culler(culler_camera(K, image_size, distortion), CullerOptions(m.settings.preset)));
      if (!m.culler->ok()) fail("culler: " + m.culler->reason());
    }
    const cv::Mat* pose = predicted_Tcw.empty() ? nullptr : &predicted_Tcw;
    const std::vector<cv::KeyPoint>* undistorted = keys_un.size() == keys.size() ? &keys_un : nullptr;
    const CullerResult& r = cv_adapter::cull(*m.culler, keys, descriptors, depth, boxes, pose, undistorted);
    m.keep = r.keep;
    status = dyncull::to_string(r.status);
    if (!r.ok()) {
      ++m.stats.frames_not_ok;
      reason = reason.empty() ? r.reason : reason + "; " + r.reason;
    }
  }
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  m.stats.cull_ms += ms;
  m.stats.features_kept += static_cast<double>(std::count(m.keep.begin(), m.keep.end(), std::uint8_t(1)));
  m.write_log(stamp, status, reason, boxes.size(), found, ms);
  return &m.keep;
}

std::string HostCuller::summary() const {
  const Stats& s = impl_->stats;
  const double n = s.frames > 0 ? static_cast<double>(s.frames) : 1.0;
  char line[320];
  std::snprintf(line, sizeof line,
                "dyncull: mode %s, %zu frames (%zu without a detections file, %zu not Ok, %zu restarts), features "
                "%.1f -> %.1f per frame, %.3f ms per frame culling",
                to_string(impl_->settings.mode), s.frames, s.frames_without_detections, s.frames_not_ok, s.restarts,
                s.features_in / n, s.features_kept / n, s.cull_ms / n);
  return line;
}

}  // namespace cv_adapter
}  // namespace dyncull
