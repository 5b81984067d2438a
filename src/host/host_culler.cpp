// The host harness (host/host_culler.hpp): settings read and checked at start, the detections folder read
// once by frame index and looked up by timestamp, or a live detector; box-only culling; the per-frame CSV
// log and the summary line. Nothing here throws out of a function the tracking thread calls: a failure
// becomes the frame's status and logged reason, and the frame passes uncut.
#include "dyncull/host/host_culler.hpp"

#include "dyncull/core/text.hpp"
#include "dyncull/eval/yolo_json.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <utility>

namespace dyncull {
namespace host {

namespace {

struct StampedBoxes {
  double stamp = 0;
  std::vector<DetectedBox> boxes;
};

// A detections folder holds at most this many NNNNNN.json files (a 30 Hz sequence of over 9 hours).
constexpr std::size_t kMaxDetectionFiles = 1000000;

std::string environment(const char* name) {
  const char* value = std::getenv(name);
  return value ? std::string(value) : std::string();
}

std::string bad_variable(const char* name, const std::string& value, const char* expected) {
  return std::string(name) + "=" + text::quote_token(value) + ": expected " + expected;
}

bool mode_from_text(const std::string& value, bool has_boxes, Mode* mode) {
  if (value.empty()) *mode = has_boxes ? Mode::Culler : Mode::Stock;
  else if (value == "stock") *mode = Mode::Stock;
  else if (value == "box_only") *mode = Mode::BoxOnly;
  else if (value == "culler") *mode = Mode::Culler;
  else return false;
  return true;
}

bool flag_from_text(const std::string& value, bool* flag) {
  if (value.empty() || value == "0") *flag = false;
  else if (value == "1") *flag = true;
  else return false;
  return true;
}

bool threads_from_text(const std::string& value, int* out) {
  if (value.empty()) return true;
  double n = 0;
  long long whole = 0;
  if (text::parse_python_float(value, &n) != text::NumberStatus::Ok || !text::integer_in_range(n, 1, 64, &whole))
    return false;
  *out = static_cast<int>(whole);
  return true;
}

bool seconds_from_text(const std::string& value, double* out) {
  if (value.empty()) return true;
  double s = 0;
  if (text::parse_python_float(value, &s) != text::NumberStatus::Ok || !(s >= 0 && s <= 1)) return false;
  *out = s;
  return true;
}

bool classes_from_text(const std::string& value, std::vector<int>* out) {
  if (value.empty()) return true;
  std::vector<int> classes;
  std::size_t start = 0;
  while (start <= value.size()) {
    const std::size_t comma = std::min(value.find(',', start), value.size());
    double id = 0;
    long long whole = 0;
    if (text::parse_python_float(value.substr(start, comma - start), &id) != text::NumberStatus::Ok ||
        !text::integer_in_range(id, 0, 1000000, &whole))
      return false;
    classes.push_back(static_cast<int>(whole));
    start = comma + 1;
  }
  *out = classes;
  return true;
}

bool inside_any(const cv::KeyPoint& key, const std::vector<DetectedBox>& boxes, const std::vector<int>& classes) {
  for (const DetectedBox& b : boxes) {
    if (std::find(classes.begin(), classes.end(), b.class_id) == classes.end()) continue;
    if (key.pt.x >= b.x0 && key.pt.x <= b.x1 && key.pt.y >= b.y0 && key.pt.y <= b.y1) return true;
  }
  return false;
}

// The file's frame number when its name is six or more digits then ".json", else -1.
long long frame_number(const std::string& name) {
  const std::size_t dot = name.size() >= 5 ? name.size() - 5 : 0;
  if (name.size() < 11 || name.size() > 24 || name.compare(dot, 5, ".json") != 0) return -1;
  long long n = 0;
  for (std::size_t k = 0; k < dot; ++k) {
    if (name[k] < '0' || name[k] > '9') return -1;
    n = n * 10 + (name[k] - '0');
  }
  return n;
}

// Every NNNNNN.json of `dir`, by frame number (gaps allowed: a frame without a file has no boxes), sorted
// by stamp. False with the folder or file and why.
bool read_detections(const std::string& dir, std::vector<StampedBoxes>* out, std::string* reason) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    *reason = "DYNCULL_DETECTIONS " + text::quote_path(dir) + ": no such directory";
    return false;
  }
  std::vector<std::pair<long long, std::string>> files;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const long long n = frame_number(it->path().filename().string());
    if (n < 0) continue;
    if (files.size() == kMaxDetectionFiles) {
      *reason = "DYNCULL_DETECTIONS " + text::quote_path(dir) + ": more than " + std::to_string(kMaxDetectionFiles) +
                " NNNNNN.json files";
      return false;
    }
    files.emplace_back(n, it->path().string());
  }
  if (ec) {
    *reason = "DYNCULL_DETECTIONS " + text::quote_path(dir) + ": cannot list the folder (" + ec.message() + ")";
    return false;
  }
  if (files.empty()) {
    *reason = "DYNCULL_DETECTIONS " + text::quote_path(dir) + ": no NNNNNN.json file";
    return false;
  }
  std::sort(files.begin(), files.end());
  out->clear();
  out->reserve(files.size());
  for (const auto& file : files) {
    const eval::YoloJsonFrame<float> f = eval::read_yolo_json<float>(file.second);
    if (!f.ok()) {
      *reason = "DYNCULL_DETECTIONS: " + f.reason;
      return false;
    }
    if (f.frame_id != file.first) {
      *reason = "DYNCULL_DETECTIONS: " + text::quote_path(file.second) + ": frame_id " + std::to_string(f.frame_id) +
                " differs from the file's number " + std::to_string(file.first);
      return false;
    }
    StampedBoxes s;
    s.stamp = f.timestamp;
    for (const Detection<float>& d : f.detections)
      s.boxes.push_back(DetectedBox(d.box.x0, d.box.y0, d.box.x1, d.box.y1, d.class_id, d.confidence));
    out->push_back(std::move(s));
  }
  std::stable_sort(out->begin(), out->end(),
                   [](const StampedBoxes& a, const StampedBoxes& b) { return a.stamp < b.stamp; });
  return true;
}

// The boxes of the file nearest `stamp` within `tolerance` seconds (detections sorted by stamp).
bool find_boxes(const std::vector<StampedBoxes>& d, double tolerance, double stamp, std::vector<DetectedBox>* boxes) {
  if (!std::isfinite(stamp)) return false;
  auto it = std::lower_bound(d.begin(), d.end(), stamp - tolerance,
                             [](const StampedBoxes& s, double t) { return s.stamp < t; });
  const StampedBoxes* best = nullptr;
  for (; it != d.end() && it->stamp <= stamp + tolerance; ++it)
    if (!best || std::fabs(it->stamp - stamp) < std::fabs(best->stamp - stamp)) best = &*it;
  if (!best) return false;
  *boxes = best->boxes;
  return true;
}

// A stamp as one CSV field whatever its value: fixed with microseconds in the range of real clocks,
// otherwise the shortest exact form (1e300 stays one short field).
std::string stamp_field(double stamp) {
  char buf[48];
  if (std::isfinite(stamp) && std::fabs(stamp) < 1e12) std::snprintf(buf, sizeof buf, "%.6f", stamp);
  else std::snprintf(buf, sizeof buf, "%.17g", stamp);
  return buf;
}

// A reason as one CSV field: commas become semicolons, control bytes spaces, at most 600 characters.
std::string reason_field(const std::string& reason) {
  std::string out = reason.substr(0, 600);
  for (char& c : out) {
    if (c == ',') c = ';';
    else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = ' ';
  }
  return out;
}

// The CSV log: a regular file, locked for one host (two hosts on one file would interleave their lines),
// written one whole line per write().
class LogFile {
 public:
  ~LogFile() {
    if (fd_ >= 0) ::close(fd_);
  }
  bool open(const std::string& path, std::string* reason) {
    path_ = path;
    const std::string name = "DYNCULL_LOG " + text::quote_path(path) + ": ";
    // O_NONBLOCK: a FIFO without a reader is refused at once instead of waited on.
    fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_NOCTTY | O_NONBLOCK | O_CLOEXEC, 0644);
    if (fd_ < 0) return fail(name + "cannot open for writing (" + std::strerror(errno) + ")", reason);
    struct stat st;
    if (::fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode))
      return fail(name + "not a regular file (a device, FIFO or directory cannot hold the log)", reason);
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0)
      return fail(name + "in use by another dyncull host: give each host its own log", reason);
    if (::ftruncate(fd_, 0) != 0) return fail(name + "cannot truncate (" + std::strerror(errno) + ")", reason);
    if (!write("stamp,mode,status,reason,features,kept,boxes,box_age,ms\n"))
      return fail(name + "cannot write (" + error_ + ")", reason);
    return true;
  }
  bool is_open() const { return fd_ >= 0; }
  /// Writes one line; on the first failure reports it on standard error and stops logging.
  void line(const std::string& text) {
    if (fd_ < 0 || write(text)) return;
    std::fprintf(stderr, "dyncull: DYNCULL_LOG %s: write failed (%s): logging stopped, the summary counts the frames\n",
                 text::quote_path(path_).c_str(), error_.c_str());
    ::close(fd_);
    fd_ = -1;
    failed_ = true;
  }
  bool failed() const { return failed_; }

 private:
  bool fail(const std::string& why, std::string* reason) {
    *reason = why;
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    return false;
  }
  bool write(const std::string& text) {
    std::size_t done = 0;
    while (done < text.size()) {
      const ssize_t n = ::write(fd_, text.data() + done, text.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0 && errno == EAGAIN) continue;  // a regular file does not block; kept for completeness
      if (n <= 0) {
        error_ = n < 0 ? std::strerror(errno) : "nothing written";
        return false;
      }
      done += static_cast<std::size_t>(n);
    }
    return true;
  }
  int fd_ = -1;
  bool failed_ = false;
  std::string path_, error_;
};

}  // namespace

const char* to_string(Mode mode) {
  switch (mode) {
    case Mode::Stock: return "stock";
    case Mode::BoxOnly: return "box_only";
    case Mode::Culler: return "culler";
  }
  return "?";
}

HostSettings HostSettings::from_environment() {
  HostSettings s;
  const auto bad = [&s](const std::string& why) {
    if (s.ok()) {
      s.status = Status::InvalidInput;
      s.reason = why;
    }
  };
  s.detections_dir = environment("DYNCULL_DETECTIONS");
  s.detector = environment("DYNCULL_DETECTOR");
  const std::string mode = environment("DYNCULL_MODE");
  if (!mode_from_text(mode, !s.detections_dir.empty() || !s.detector.empty(), &s.mode))
    bad(bad_variable("DYNCULL_MODE", mode, "stock, box_only or culler"));
  const std::string sync = environment("DYNCULL_DETECTOR_SYNC");
  if (!flag_from_text(sync, &s.detector_sync)) bad(bad_variable("DYNCULL_DETECTOR_SYNC", sync, "0 or 1"));
  const std::string rgb = environment("DYNCULL_FRAMES_RGB");
  if (!flag_from_text(rgb, &s.frames_rgb)) bad(bad_variable("DYNCULL_FRAMES_RGB", rgb, "0 or 1"));
  const std::string threads = environment("DYNCULL_OPENCV_THREADS");
  if (!threads_from_text(threads, &s.opencv_threads))
    bad(bad_variable("DYNCULL_OPENCV_THREADS", threads, "a number of threads from 1 to 64"));
  const std::string preset = environment("DYNCULL_PRESET");
  if (!preset.empty()) s.preset = preset;
  const std::string tolerance = environment("DYNCULL_STAMP_TOLERANCE");
  if (!seconds_from_text(tolerance, &s.stamp_tolerance_s))
    bad(bad_variable("DYNCULL_STAMP_TOLERANCE", tolerance, "a number of seconds in [0, 1]"));
  s.log_path = environment("DYNCULL_LOG");
  const std::string classes = environment("DYNCULL_BOX_CLASSES");
  if (!classes_from_text(classes, &s.box_only_classes))
    bad(bad_variable("DYNCULL_BOX_CLASSES", classes, "comma-separated class ids such as 0,2"));
  return s;
}

struct HostCuller::Impl {
  HostSettings settings;
  Status status = Status::Ok;
  std::string reason;
  std::vector<StampedBoxes> detections;
  std::unique_ptr<LiveDetection> live;
  std::unique_ptr<Culler> culler;
  std::vector<std::uint8_t> keep;
  std::vector<DetectedBox> boxes;
  LogFile log;
  Stats stats;
  bool has_frame = false;
  unsigned long last_frame_id = 0;
  std::atomic<bool> reset_requested{false};  // HostCuller::reset, from any thread
  bool warned_missing = false, warned_not_ok = false;

  bool refuse(const std::string& why) {
    status = Status::InvalidInput;
    reason = why;
    return false;
  }
  bool open(std::unique_ptr<FrameDetector> detector);
  void log_frame(double stamp, const char* status_name, const std::string& why, std::size_t features,
                 std::size_t kept, const std::string& boxes_field, const std::string& age_field, double ms);
  void warn_once(bool* warned, const char* what, const std::string& why);
  bool boxes_for(const HostFrame& f, std::string* why, std::string* boxes_field, std::string* age_field);
  void note_frame_id(unsigned long frame_id);
  void keep_outside_boxes(const std::vector<cv::KeyPoint>& keys);
  bool run_culler(const HostFrame& f, const std::vector<cv::KeyPoint>& keys, std::string* why, const char** status_name,
                  Status* refusal);
  const std::vector<std::uint8_t>* cull(const HostFrame& f);
  void pass(double stamp, std::size_t n, Status s, const std::string& why, double ms);
};

bool HostCuller::Impl::open(std::unique_ptr<FrameDetector> detector) {
  const HostSettings& s = settings;
  if (!s.ok()) return refuse(s.reason);
  std::string why;
  if (CullerOptions(s.preset).validate(&why) != Status::Ok)
    return refuse("DYNCULL_PRESET=" + text::quote_token(s.preset) + ": " + why);
  if (!(s.stamp_tolerance_s >= 0 && s.stamp_tolerance_s <= 1))
    return refuse("DYNCULL_STAMP_TOLERANCE: must be in [0, 1] seconds");
  if (s.mode != Mode::Stock) {
    const bool live = detector || !s.detector.empty();
    if (live && !s.detections_dir.empty())
      return refuse("DYNCULL_DETECTIONS and DYNCULL_DETECTOR are both set: choose one source of boxes");
    if (!live && s.detections_dir.empty())
      return refuse(std::string("DYNCULL_MODE=") + to_string(s.mode) +
                    " needs boxes: set DYNCULL_DETECTIONS (a folder of NNNNNN.json) or DYNCULL_DETECTOR (a model)");
    if (!live && !read_detections(s.detections_dir, &detections, &why)) return refuse(why);
    if (live && !detector) {
      detector = open_yolo_detector(s.detector, &why);
      if (!detector) return refuse("DYNCULL_DETECTOR=" + text::quote_token(s.detector, 200) + ": " + why);
    }
    if (live) {
      LiveDetectionOptions o;
      o.synchronous = s.detector_sync;
      o.frames_rgb = s.frames_rgb;
      this->live.reset(new LiveDetection(std::move(detector), o));
    }
  }
  if (!s.log_path.empty() && !log.open(s.log_path, &why)) return refuse(why);
  if (s.opencv_threads < 0 || s.opencv_threads > 64) return refuse("DYNCULL_OPENCV_THREADS: must be 1 to 64 (0: unchanged)");
  // OpenCV's thread pool serves the whole process (the detector's network and the host's own OpenCV
  // calls): on a machine of few cores, a smaller pool leaves cores to the tracking thread.
  if (s.opencv_threads > 0) cv::setNumThreads(s.opencv_threads);
  return true;
}

void HostCuller::Impl::log_frame(double stamp, const char* status_name, const std::string& why, std::size_t features,
                                 std::size_t kept, const std::string& boxes_field, const std::string& age_field,
                                 double ms) {
  if (!log.is_open()) return;
  char tail[64];
  std::snprintf(tail, sizeof tail, ",%.3f\n", ms);
  log.line(stamp_field(stamp) + "," + to_string(settings.mode) + "," + status_name + "," + reason_field(why) + "," +
           std::to_string(features) + "," + std::to_string(kept) + "," + boxes_field + "," + age_field + tail);
}

void HostCuller::Impl::warn_once(bool* warned, const char* what, const std::string& why) {
  if (*warned) return;
  *warned = true;
  std::fprintf(stderr, "dyncull: %s: %s (further such frames are counted in the summary)\n", what,
               reason_field(why).c_str());
}

void HostCuller::Impl::pass(double stamp, std::size_t n, Status s, const std::string& why, double ms) {
  stats.features_kept += static_cast<double>(n);
  ++stats.frames_not_ok;
  warn_once(&warned_not_ok, "a frame passes uncut", why);
  log_frame(stamp, dyncull::to_string(s), why, n, n, "", "", ms);
}

// This frame's boxes from the folder or the live detector; false when there are none (why says so).
bool HostCuller::Impl::boxes_for(const HostFrame& f, std::string* why, std::string* boxes_field,
                                 std::string* age_field) {
  boxes.clear();
  if (live) {
    static const cv::Mat kNoImage;
    const LiveBoxes& b = live->frame(static_cast<long>(stats.frames), f.image ? *f.image : kNoImage);
    boxes = b.boxes;
    *why = b.reason;
    *age_field = b.age_frames >= 0 ? std::to_string(b.age_frames) : std::string("none");
    if (b.failed) ++stats.detector_failures;
    if (b.age_frames >= 0 && !b.failed) {
      ++stats.frames_with_age;
      stats.box_age_frames += static_cast<double>(b.age_frames);
      stats.detector_ms += b.detector_ms;
    }
    const bool found = b.age_frames >= 0 && !b.failed;
    *boxes_field = found ? std::to_string(boxes.size()) : std::string("none");
    return found;
  }
  const bool found = find_boxes(detections, settings.stamp_tolerance_s, f.stamp, &boxes);
  if (!found) *why = "no detections file for this stamp";
  *boxes_field = found ? std::to_string(boxes.size()) : std::string("none");
  return found;
}

// A frame id not above the last one, or a reset the host asked for: the host restarted its map, and the
// keyframe belongs to the old one.
void HostCuller::Impl::note_frame_id(unsigned long frame_id) {
  if (reset_requested.exchange(false)) {
    if (has_frame && culler) {
      culler->reset();
      ++stats.restarts;
    }
    has_frame = false;
  }
  if (has_frame && frame_id <= last_frame_id && culler) {
    culler->reset();
    ++stats.restarts;
  }
  has_frame = true;
  last_frame_id = frame_id;
}

void HostCuller::Impl::keep_outside_boxes(const std::vector<cv::KeyPoint>& keys) {
  keep.assign(keys.size(), 1);
  for (std::size_t i = 0; i < keys.size(); ++i)
    if (inside_any(keys[i], boxes, settings.box_only_classes)) keep[i] = 0;
}

// The culler's keep mask into `keep` (the culler made at the first frame from its K, image size and
// distortion). False when the culler refused the frame: `refusal` and `why` then say why; nothing is culled.
bool HostCuller::Impl::run_culler(const HostFrame& f, const std::vector<cv::KeyPoint>& keys, std::string* why,
                                  const char** status_name, Status* refusal) {
  static const cv::Mat kNoMat;
  if (!culler) {
    const cv::Size size = f.image ? f.image->size() : cv::Size();
    culler.reset(new Culler(cv_adapter::culler_camera(f.K ? *f.K : kNoMat, size, f.distortion ? *f.distortion : kNoMat),
                            CullerOptions(settings.preset)));
  }
  const cv::Mat* pose = f.predicted_Tcw && !f.predicted_Tcw->empty() ? f.predicted_Tcw : nullptr;
  const std::vector<cv::KeyPoint>* undistorted = f.keys_un && !f.keys_un->empty() ? f.keys_un : nullptr;
  const CullerResult& r = cv_adapter::cull(*culler, keys, f.descriptors ? *f.descriptors : kNoMat,
                                           f.depth ? *f.depth : kNoMat, boxes, pose, undistorted);
  if (!r.ok()) *why = why->empty() ? r.reason : *why + "; " + r.reason;
  if (r.refused || r.keep.size() != keys.size()) {
    *refusal = r.refused ? r.status : Status::InvalidInput;
    return false;
  }
  keep = r.keep;
  *status_name = dyncull::to_string(r.status);
  if (!r.ok()) ++stats.frames_not_ok;
  return true;
}

const std::vector<std::uint8_t>* HostCuller::Impl::cull(const HostFrame& f) {
  const auto start = std::chrono::steady_clock::now();
  const auto elapsed_ms = [&start] {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  };
  ++stats.frames;
  static const std::vector<cv::KeyPoint> kNoKeys;
  const std::vector<cv::KeyPoint>& keys = f.keys ? *f.keys : kNoKeys;
  const std::size_t n = keys.size();
  stats.features_in += static_cast<double>(n);
  if (status != Status::Ok) {
    pass(f.stamp, n, status, "the host did not start: " + reason, elapsed_ms());
    return nullptr;
  }
  if (settings.mode == Mode::Stock) {
    stats.features_kept += static_cast<double>(n);
    log_frame(f.stamp, dyncull::to_string(Status::Ok), "", n, n, "", "", elapsed_ms());
    return nullptr;
  }
  note_frame_id(f.frame_id);
  std::string why, boxes_field, age_field;
  if (!boxes_for(f, &why, &boxes_field, &age_field)) {
    ++stats.frames_without_detections;
    warn_once(&warned_missing, "a frame without boxes is culled without them", why);
  }
  const char* status_name = dyncull::to_string(Status::Ok);
  Status refusal = Status::Ok;
  if (settings.mode == Mode::BoxOnly) {
    keep_outside_boxes(keys);
  } else if (!run_culler(f, keys, &why, &status_name, &refusal)) {
    pass(f.stamp, n, refusal, why, elapsed_ms());  // nothing culled: the frame passes as it came
    return nullptr;
  }
  const double ms = elapsed_ms();
  stats.cull_ms += ms;
  const std::size_t kept = static_cast<std::size_t>(std::count(keep.begin(), keep.end(), std::uint8_t(1)));
  stats.features_kept += static_cast<double>(kept);
  log_frame(f.stamp, status_name, why, n, kept, boxes_field, age_field, ms);
  return &keep;
}

HostCuller::HostCuller(const HostSettings& settings) : HostCuller(settings, nullptr) {}

HostCuller::HostCuller(const HostSettings& settings, std::unique_ptr<FrameDetector> detector) : impl_(new Impl) {
  impl_->settings = settings;
  try {
    impl_->open(std::move(detector));
  } catch (const std::exception& e) {
    impl_->refuse(std::string("start-up failed: ") + e.what());
  }
  if (!ok()) return;
  std::string boxes = "no boxes";
  if (impl_->live) boxes = std::string(settings.detector_sync ? "a live detector, waited for" : "a live detector, asynchronous");
  else if (settings.mode != Mode::Stock) boxes = std::to_string(impl_->detections.size()) + " detection frames";
  std::fprintf(stderr, "dyncull: mode %s%s%s (%s)\n", to_string(settings.mode),
               settings.mode == Mode::Culler ? ", preset " : "",
               settings.mode == Mode::Culler ? settings.preset.c_str() : "", boxes.c_str());
}

HostCuller::~HostCuller() {
  if (impl_ && impl_->stats.frames > 0) std::fprintf(stderr, "%s\n", summary().c_str());
}

Status HostCuller::status() const { return impl_->status; }
const std::string& HostCuller::reason() const { return impl_->reason; }
const HostSettings& HostCuller::settings() const { return impl_->settings; }
const HostCuller::Stats& HostCuller::stats() const { return impl_->stats; }

bool HostCuller::detections_for(double stamp, std::vector<DetectedBox>* boxes) const {
  return find_boxes(impl_->detections, impl_->settings.stamp_tolerance_s, stamp, boxes);
}

const std::vector<std::uint8_t>* HostCuller::cull(const HostFrame& frame) noexcept {
  try {
    return impl_->cull(frame);
  } catch (const std::exception& e) {
    try {
      impl_->pass(frame.stamp, frame.keys ? frame.keys->size() : 0, Status::InvalidInput,
                  std::string("the host failed on this frame: ") + e.what(), 0.0);
    } catch (...) {
    }
  } catch (...) {
  }
  return nullptr;
}

void HostCuller::reset() noexcept { impl_->reset_requested.store(true); }

void HostCuller::pass_uncut(double stamp, std::size_t features, const std::string& why) noexcept {
  try {
    ++impl_->stats.frames;
    impl_->stats.features_in += static_cast<double>(features);
    impl_->pass(stamp, features, Status::InvalidInput, why, 0.0);
  } catch (...) {
  }
}

std::string HostCuller::summary() const {
  const Stats& s = impl_->stats;
  const double n = s.frames > 0 ? static_cast<double>(s.frames) : 1.0;
  char line[512];
  std::snprintf(line, sizeof line,
                "dyncull: mode %s, %zu frames (%zu without boxes, %zu not Ok, %zu restarts), features "
                "%.1f -> %.1f per frame, %.3f ms per frame culling",
                to_string(impl_->settings.mode), s.frames, s.frames_without_detections, s.frames_not_ok, s.restarts,
                s.features_in / n, s.features_kept / n, s.cull_ms / n);
  std::string out = line;
  if (impl_->live) {
    const double m = s.frames_with_age > 0 ? static_cast<double>(s.frames_with_age) : 1.0;
    std::snprintf(line, sizeof line, "; live detector%s: %.1f ms per detection, box age %.2f frames, %zu failed frames",
                  impl_->settings.detector_sync ? " (waited for)" : "", s.detector_ms / m, s.box_age_frames / m,
                  s.detector_failures);
    out += line;
  }
  if (impl_->log.failed()) out += "; the log stopped at a write error";
  return out;
}

HostCuller& environment_culler() {
  static HostCuller culler(HostSettings::from_environment());
  static const bool started = [] {
    if (!culler.ok()) {
      std::fprintf(stderr, "dyncull: %s\n", culler.reason().c_str());
      std::exit(1);
    }
    return true;
  }();
  (void)started;
  return culler;
}

}  // namespace host
}  // namespace dyncull
