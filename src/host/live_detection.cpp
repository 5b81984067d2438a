// The live detector's hand-over (host/live_detection.hpp): one pending frame (the newest offered), one
// finished result, both under one mutex; the tracking thread copies its frame outside the lock and only
// swaps buffers inside it, so it never waits for a detection.
#include "dyncull/host/live_detection.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <utility>

#ifdef __linux__
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

namespace dyncull {
namespace host {

namespace {

double iou(const DetectedBox& a, const DetectedBox& b) {
  const double w = std::min(a.x1, b.x1) - std::max(a.x0, b.x0);
  const double h = std::min(a.y1, b.y1) - std::max(a.y0, b.y0);
  if (!(w > 0) || !(h > 0)) return 0;
  const double inter = w * h;
  const double area_a = double(a.x1 - a.x0) * double(a.y1 - a.y0);
  const double area_b = double(b.x1 - b.x0) * double(b.y1 - b.y0);
  const double uni = area_a + area_b - inter;
  return uni > 0 ? inter / uni : 0;
}

// The box of `previous` that continues `box` (same class, IoU at least 0.3, the box tracker's threshold),
// or null.
const DetectedBox* continued_from(const DetectedBox& box, const std::vector<DetectedBox>& previous) {
  const DetectedBox* best = nullptr;
  double best_iou = 0.3;
  for (const DetectedBox& p : previous) {
    if (p.class_id != box.class_id) continue;
    const double o = iou(box, p);
    if (o >= best_iou) {
      best_iou = o;
      best = &p;
    }
  }
  return best;
}

// The calling thread at the lowest scheduling priority (Linux: a thread's own nice value), so that on a
// machine of few cores the detector takes only the CPU time that tracking and mapping leave.
void yield_cpu_to_tracking() {
#ifdef __linux__
  setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), 19);
#endif
}

}  // namespace

LiveDetection::LiveDetection(std::unique_ptr<FrameDetector> detector, const LiveDetectionOptions& options)
    : detector_(std::move(detector)), options_(options), stop_(false), has_pending_(false), has_result_(false),
      first_offered_(false), pending_index_(-1), finished_(0), failures_(0), newest_failed_(false),
      failed_index_(-1), failed_ms_(0) {
  if (detector_ && !options_.synchronous) thread_ = std::thread(&LiveDetection::run, this);
}

LiveDetection::~LiveDetection() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

std::size_t LiveDetection::finished() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return finished_;
}

std::size_t LiveDetection::failures() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return failures_;
}

void LiveDetection::detect_into(const cv::Mat& image, long index, Detected* out) {
  out->index = index;
  out->boxes.clear();
  out->reason.clear();
  const auto start = std::chrono::steady_clock::now();
  try {
    const cv::Mat* frame = &image;
    if (options_.frames_rgb && image.type() == CV_8UC3) {
      cv::cvtColor(image, converted_, cv::COLOR_RGB2BGR);
      frame = &converted_;
    }
    out->ok = detector_->detect(*frame, &out->boxes, &out->reason);
  } catch (const std::exception& e) {
    out->ok = false;
    out->reason = std::string("the detector threw: ") + e.what();
  } catch (...) {
    out->ok = false;
    out->reason = "the detector threw an unknown exception";
  }
  if (!out->ok) out->boxes.clear();
  if (!out->ok && out->reason.empty()) out->reason = "the detector failed without a reason";
  out->ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

void LiveDetection::run() {
  yield_cpu_to_tracking();
  Detected d;
  for (;;) {
    long index = -1;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return stop_ || has_pending_; });
      if (stop_) return;
      std::swap(working_, pending_frame_);
      index = pending_index_;
      has_pending_ = false;
    }
    detect_into(working_, index, &d);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      std::swap(result_, d);
      has_result_ = true;
      ++finished_;
      if (!result_.ok) ++failures_;
    }
    result_ready_.notify_all();
  }
}

// The first frame offered waits for its own boxes (bounded): the host builds its first map from it.
void LiveDetection::wait_for_first_result(std::unique_lock<std::mutex>* lock) {
  first_offered_ = true;
  const double ms = options_.first_frame_wait_ms > 0 ? std::min(options_.first_frame_wait_ms, 60000.0) : 0;  // NaN: 0
  const std::chrono::milliseconds limit(static_cast<long>(ms));  // checked: ms in [0, 60000]
  result_ready_.wait_for(*lock, limit, [this] { return has_result_; });
}

void LiveDetection::adopt(const Detected& d) {
  if (!d.ok) {
    newest_failed_ = true;
    newest_failure_ = "detector failed on frame " + std::to_string(d.index) + ": " + d.reason;
    failed_index_ = d.index;
    failed_ms_ = d.ms;
    return;
  }
  newest_failed_ = false;
  if (newest_.index >= 0) std::swap(previous_, newest_);
  newest_ = d;
}

void LiveDetection::carry_to(long index) {
  out_.boxes.clear();
  out_.failed = false;
  out_.reason.clear();
  out_.detector_ms = 0;
  if (newest_failed_) {
    out_.failed = true;
    out_.age_frames = index - failed_index_;
    out_.reason = newest_failure_ + "; culled without boxes";
    out_.detector_ms = failed_ms_;
    return;
  }
  if (newest_.index < 0) {
    out_.age_frames = -1;
    out_.reason = "no detection finished yet; culled without boxes";
    return;
  }
  const long age = index - newest_.index;
  out_.age_frames = age;
  out_.detector_ms = newest_.ms;
  const long since_previous = previous_.index >= 0 ? newest_.index - previous_.index : 0;
  const double grow = options_.grow_px_per_frame * static_cast<double>(age > 0 ? age : 0);
  for (const DetectedBox& b : newest_.boxes) {
    double vx = 0, vy = 0;
    const DetectedBox* p = since_previous > 0 && age > 0 ? continued_from(b, previous_.boxes) : nullptr;
    if (p) {
      vx = (0.5 * (double(b.x0) + b.x1) - 0.5 * (double(p->x0) + p->x1)) / static_cast<double>(since_previous);
      vy = (0.5 * (double(b.y0) + b.y1) - 0.5 * (double(p->y0) + p->y1)) / static_cast<double>(since_previous);
      if (!(std::hypot(vx, vy) <= options_.max_speed_px)) vx = vy = 0;  // an unlikely jump: not extrapolated
    }
    const double dx = vx * static_cast<double>(age), dy = vy * static_cast<double>(age);
    out_.boxes.push_back(DetectedBox(static_cast<float>(b.x0 + dx - grow), static_cast<float>(b.y0 + dy - grow),
                                     static_cast<float>(b.x1 + dx + grow), static_cast<float>(b.y1 + dy + grow),
                                     b.class_id, b.confidence));
  }
}

const LiveBoxes& LiveDetection::frame(long index, const cv::Mat& image) noexcept {
  try {
    const bool usable = !image.empty() && image.dims == 2 && (image.type() == CV_8UC3 || image.type() == CV_8UC1);
    if (!detector_) {
      out_ = LiveBoxes();
      out_.failed = true;
      out_.reason = "no detector";
      return out_;
    }
    if (options_.synchronous) {
      if (usable) {
        detect_into(image, index, &sync_);
        ++finished_;
        if (!sync_.ok) ++failures_;
        adopt(sync_);
      }
    } else {
      if (usable) image.copyTo(spare_);  // outside the lock: the detector thread may be reading working_
      std::unique_lock<std::mutex> lock(mutex_);
      if (usable) {
        std::swap(pending_frame_, spare_);
        pending_index_ = index;
        has_pending_ = true;
        wake_.notify_one();
        if (!first_offered_) wait_for_first_result(&lock);
      }
      if (has_result_) {
        adopt(result_);
        has_result_ = false;
      }
    }
    carry_to(index);
    if (!usable) {
      out_.reason = (out_.reason.empty() ? std::string() : out_.reason + "; ") +
                    "the frame was not given to the detector (empty, or not CV_8UC3 / CV_8UC1)";
    }
  } catch (const std::exception& e) {
    out_ = LiveBoxes();
    out_.failed = true;
    out_.reason = std::string("live detection failed: ") + e.what();
  } catch (...) {
    out_ = LiveBoxes();
    out_.failed = true;
    out_.reason = "live detection failed";
  }
  return out_;
}

}  // namespace host
}  // namespace dyncull
