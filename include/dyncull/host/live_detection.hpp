/// @file live_detection.hpp
/// A detector beside the tracking thread: frames are handed to a detector on its own thread (at the
/// lowest priority on Linux, so that it takes the CPU tracking leaves) and the tracker, never waiting,
/// gets the newest finished boxes carried to its frame (shifted by each box's
/// velocity between the last two detections, grown with their age), with that age in frames; or, in the
/// synchronous form, each frame's own boxes. C++11 header (standard library and opencv2/core.hpp);
/// compiled into dyncull::host. (Not culling/box_tracker.hpp's tracker: it takes an update's boxes as the
/// current frame's, so boxes that finish k frames late would stay k frames behind.)
///
/// API:
///   dyncull::host::LiveDetection live(dyncull::host::open_yolo_detector(spec, &reason), options);
///   const dyncull::host::LiveBoxes& b = live.frame(frame_index, bgr);  // b.boxes, b.age_frames, b.reason
#pragma once

#include "dyncull/culling/culler.hpp"

#include <opencv2/core.hpp>

#include <condition_variable>
#include <cstddef>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace dyncull {
namespace host {

/// A detector the host runs on frames: the YOLO detector (open_yolo_detector) or a host's own.
class FrameDetector {
 public:
  virtual ~FrameDetector() {}
  /// Boxes on one BGR (or grey) frame in its pixels; false with a reason when it could not detect.
  /// Called from the detector's thread only. An exception counts as a failure with its message.
  virtual bool detect(const cv::Mat& frame, std::vector<DetectedBox>* boxes, std::string* reason) = 0;
};

/// The YOLO detector of opencv/yolo_detector.hpp (plain resize to a Darknet cfg's own input size, which
/// is Yolo-Fastest's 320 x 320, else 416 x 416; confidence >= 0.25, NMS per class at IoU 0.45) for `spec` "CFG,WEIGHTS" or "MODEL.onnx", opened and run once on a blank frame. Null
/// with `*reason` naming the file and why when the spec, the files or the network cannot be used, or
/// when dyncull was built without OpenCV's dnn module.
std::unique_ptr<FrameDetector> open_yolo_detector(const std::string& spec, std::string* reason);

struct LiveDetectionOptions {
  bool synchronous;           ///< run the detector on each frame and wait for it (the YOLO forks' way)
  bool frames_rgb;            ///< frames arrive in RGB order: swapped to BGR for the detector
  double grow_px_per_frame;   ///< a carried box grows by this much on every side per frame of age
  double max_speed_px;        ///< a box velocity above this (pixels per frame) is not trusted: no shift
  /// The first frame waits up to this long for its own boxes (0: not at all), once: the host's map starts
  /// from that frame, and a map started on unculled people keeps their points.
  double first_frame_wait_ms;
  LiveDetectionOptions()
      : synchronous(false), frames_rgb(false), grow_px_per_frame(4.0), max_speed_px(40.0), first_frame_wait_ms(2000) {}
};

/// The boxes the culler gets at one frame.
struct LiveBoxes {
  std::vector<DetectedBox> boxes;  ///< carried to this frame
  long age_frames;                 ///< this frame's index minus the detected frame's; -1: none finished yet
  bool failed;                     ///< the detection these boxes would come from failed (reason says why)
  std::string reason;              ///< empty when boxes are from a finished detection
  double detector_ms;              ///< the detection's own time (0 when none)
  LiveBoxes() : age_frames(-1), failed(false), detector_ms(0) {}
};

/// The hand-over. The tracking thread calls frame() once per frame, in order; the detector thread takes
/// the newest frame offered while it was busy (older ones are skipped). Destruction stops the thread
/// after its current detection.
class LiveDetection {
 public:
  LiveDetection(std::unique_ptr<FrameDetector> detector, const LiveDetectionOptions& options);
  ~LiveDetection();
  LiveDetection(const LiveDetection&) = delete;
  LiveDetection& operator=(const LiveDetection&) = delete;

  /// Offers frame `index` (indices increase) and returns the newest finished boxes carried to it. An
  /// empty or unreadable frame is not offered (the reason says so). Never throws. In the asynchronous form
  /// it waits only once, on the first frame offered, for that frame's boxes (at most first_frame_wait_ms);
  /// after that only for the detector thread's hand-over of a finished result (microseconds).
  const LiveBoxes& frame(long index, const cv::Mat& image) noexcept;

  /// Detections finished so far, and how many failed.
  std::size_t finished() const;
  std::size_t failures() const;

 private:
  struct Detected {
    long index;
    bool ok;
    std::string reason;
    std::vector<DetectedBox> boxes;
    double ms;
    Detected() : index(-1), ok(false), ms(0) {}
  };
  void run();
  void wait_for_first_result(std::unique_lock<std::mutex>* lock);
  void detect_into(const cv::Mat& image, long index, Detected* out);
  void adopt(const Detected& d);
  void carry_to(long index);

  std::unique_ptr<FrameDetector> detector_;
  LiveDetectionOptions options_;
  mutable std::mutex mutex_;
  std::condition_variable wake_, result_ready_;
  bool stop_, has_pending_, has_result_, first_offered_;
  long pending_index_;
  cv::Mat pending_frame_, working_, spare_, converted_;  // the newest offered frame, the one being detected
  Detected result_;                 // finished by the thread, not yet adopted
  Detected sync_;                   // the synchronous form's detection
  std::size_t finished_, failures_;
  Detected newest_, previous_;      // adopted: the newest successful detection and the one before
  bool newest_failed_;
  std::string newest_failure_;
  long failed_index_;
  double failed_ms_;
  LiveBoxes out_;
  std::thread thread_;
};

}  // namespace host
}  // namespace dyncull
