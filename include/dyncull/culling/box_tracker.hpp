/// @file box_tracker.hpp
/// Missed-detection compensation (Dynamic-VINS compensateMissedDetection): a box the detector
/// misses is carried forward by its averaged centre velocity, grown by 10 px, and dropped after 2
/// frames without a detection. All state lives in the BoxTracker object the caller owns.
///
/// API:
///   BoxTracker<float> tracker(BoxTrackerOptions<float>{});
///   BoxTrackerResult<float> r = tracker.update(detections, width, height);  // once per frame
///   r.boxes: this frame's detections followed by the carried-forward boxes (r.carried[i] = 1).
#pragma once

#include "dyncull/core/box.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/core/types.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace dyncull {

template <class T>
struct BoxTrackerOptions {
  /// A detection continues a track when its IoU with the track's predicted box reaches this: at 30 Hz the
  /// same walker's boxes overlap far more, two people side by side far less.
  static constexpr double kMinIou = 0.3;
  /// Growth of a carried box per missed frame, on every side (Dynamic-VINS: 10 px).
  T grow_px_per_frame = T(10);
  /// A track is dropped after more than this many consecutive frames without a detection.
  int max_missed_frames = 2;
  /// Velocity average: v = (1 - a) v_old + a v_new, with a = 0.5: a detector's box jitters by a few pixels.
  static constexpr double kVelocitySmoothing = 0.5;

  /// Ok, or InvalidInput naming the first bad field: grow_px_per_frame finite and >= 0, max_missed_frames
  /// in [0, 1000].
  Status validate(std::string* reason = nullptr) const {
    auto bad = [&](const char* why) {
      if (reason) *reason = why;
      return Status::InvalidInput;
    };
    if (!(grow_px_per_frame >= T(0)) || !std::isfinite(grow_px_per_frame))
      return bad("grow_px_per_frame must be finite and >= 0");
    if (max_missed_frames < 0 || max_missed_frames > 1000) return bad("max_missed_frames must be in [0, 1000]");
    if (reason) reason->clear();
    return Status::Ok;
  }
};

template <class T>
struct TrackedBox {
  std::int64_t id = -1;
  Detection<T> detection;   ///< last detected box (or last prediction while missed)
  Vec2<T> velocity = Vec2<T>::Zero();  ///< centre pixels per frame
  Vec2<T> last_centre = Vec2<T>::Zero();  ///< centre of the last detected (not predicted) box
  int missed = 0;           ///< consecutive frames without a detection
  int hits = 0;             ///< frames with a detection
};

template <class T>
struct BoxTrackerResult {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }
  std::vector<Detection<T>> boxes;      ///< detections (input order), then carried boxes
  std::vector<std::uint8_t> carried;    ///< 1 for boxes carried forward (CullReason::TrackedBox)
  std::vector<std::int64_t> track_id;   ///< track of each box
  std::size_t num_matched = 0, num_new = 0, num_carried = 0, num_dropped = 0;
};

template <class T>
class BoxTracker {
 public:
  explicit BoxTracker(const BoxTrackerOptions<T>& options = {}) : options_(options) {}
  /// Options of the next update() (the tracks are kept).
  void set_options(const BoxTrackerOptions<T>& options) { options_ = options; }

  /// Feeds one frame's detections (already filtered, pixel boxes). Invalid boxes are ignored
  /// (counted in `reason`); a bad image size or options failing BoxTrackerOptions::validate fail
  /// with InvalidInput and leave the state as is. Writes into `*out`, reusing its buffers and the
  /// tracker's own scratch (no allocation once warm).
  void update(const std::vector<Detection<T>>& detections, int width, int height, BoxTrackerResult<T>* out) {
    BoxTrackerResult<T>& r = *out;
    r.status = Status::Ok;
    r.reason.clear();
    r.boxes.clear();
    r.carried.clear();
    r.track_id.clear();
    r.num_matched = r.num_new = r.num_carried = r.num_dropped = 0;
    if (width <= 0 || height <= 0) {
      r.status = Status::InvalidInput;
      r.reason.assign("image size must be positive");
      return;
    }
    if (options_.validate(&r.reason) != Status::Ok) {
      r.status = Status::InvalidInput;
      return;
    }
    predict();
    const std::size_t invalid = associate(detections);
    next_.clear();
    next_.reserve(tracks_.size() + detections.size());
    take_detections(detections, &r);
    carry_missed_tracks(width, height, &r);
    tracks_.swap(next_);
    if (invalid) {
      r.reason.assign(std::to_string(invalid));
      r.reason += " invalid detection(s) ignored";
    }
  }

  /// The same update returning a fresh result (allocates; the out-parameter form reuses buffers).
  BoxTrackerResult<T> update(const std::vector<Detection<T>>& detections, int width, int height) {
    BoxTrackerResult<T> r;
    update(detections, width, height, &r);
    return r;
  }

  const std::vector<TrackedBox<T>>& tracks() const { return tracks_; }
  void reset() {
    tracks_.clear();
    next_id_ = 0;
  }

 private:
  /// Each track's box moved by its velocity.
  void predict() {
    predicted_.resize(tracks_.size());
    for (std::size_t t = 0; t < tracks_.size(); ++t) {
      const Box<T>& b = tracks_[t].detection.box;
      const Vec2<T>& v = tracks_[t].velocity;
      predicted_[t] = Box<T>{b.x0 + v.x(), b.y0 + v.y(), b.x1 + v.x(), b.y1 + v.y()};
    }
  }

  /// Greedy association by IoU with the predicted boxes, best pairs first (a handful of boxes: O(n^2 log n)
  /// is nothing): det_track_[d] is detection d's track or -1. Returns the invalid detections skipped.
  std::size_t associate(const std::vector<Detection<T>>& detections) {
    pairs_.clear();
    std::size_t invalid = 0;
    for (std::size_t d = 0; d < detections.size(); ++d) {
      if (!detections[d].box.valid()) {
        ++invalid;
        continue;
      }
      for (std::size_t t = 0; t < tracks_.size(); ++t) {
        if (detections[d].class_id != tracks_[t].detection.class_id) continue;  // only the track's class continues it
        const T o = iou(detections[d].box, predicted_[t]);
        if (o >= T(BoxTrackerOptions<T>::kMinIou)) pairs_.push_back(Pair{o, d, t});
      }
    }
    std::sort(pairs_.begin(), pairs_.end(), [](const Pair& a, const Pair& b) {
      return a.iou > b.iou || (a.iou == b.iou && (a.det < b.det || (a.det == b.det && a.track < b.track)));
    });
    det_track_.assign(detections.size(), -1);
    track_used_.assign(tracks_.size(), 0);
    for (const Pair& p : pairs_) {
      if (det_track_[p.det] >= 0 || track_used_[p.track]) continue;
      det_track_[p.det] = static_cast<std::int64_t>(p.track);
      track_used_[p.track] = 1;
    }
    return invalid;
  }

  /// Every valid detection continues its track (velocity smoothed from the last real detection) or
  /// starts a new one.
  void take_detections(const std::vector<Detection<T>>& detections, BoxTrackerResult<T>* r) {
    for (std::size_t d = 0; d < detections.size(); ++d) {
      if (!detections[d].box.valid()) continue;
      TrackedBox<T> tb;
      if (det_track_[d] >= 0) {
        const TrackedBox<T>& old = tracks_[static_cast<std::size_t>(det_track_[d])];
        // Velocity from the last real detection, spread over the frames it was missed.
        const Vec2<T> shift = (detections[d].box.centre() - old.last_centre) / T(old.missed + 1);
        tb = old;
        const T a = T(BoxTrackerOptions<T>::kVelocitySmoothing);
        tb.velocity = (T(1) - a) * old.velocity + a * shift;
        ++tb.hits;
        ++r->num_matched;
      } else {
        tb.id = next_id_++;
        tb.hits = 1;
        ++r->num_new;
      }
      tb.detection = detections[d];
      tb.last_centre = detections[d].box.centre();
      tb.missed = 0;
      r->boxes.push_back(detections[d]);
      r->carried.push_back(0);
      r->track_id.push_back(tb.id);
      next_.push_back(tb);
    }
  }

  /// An unmatched track is carried at its predicted box, grown by grow_px_per_frame, until it has been
  /// missed max_missed_frames times or leaves the image.
  void carry_missed_tracks(int width, int height, BoxTrackerResult<T>* r) {
    for (std::size_t t = 0; t < tracks_.size(); ++t) {
      if (track_used_[t]) continue;
      TrackedBox<T> tb = tracks_[t];
      ++tb.missed;
      const Box<T> moved = predicted_[t].padded(options_.grow_px_per_frame);
      const bool outside = moved.x1 < T(0) || moved.y1 < T(0) || moved.x0 > T(width - 1) || moved.y0 > T(height - 1);
      if (tb.missed > options_.max_missed_frames || outside || !moved.valid()) {
        ++r->num_dropped;
        continue;
      }
      // The unclipped box is kept for the next prediction; the output is clipped to the image.
      tb.detection.box = moved;
      Detection<T> out = tb.detection;
      out.box = moved.clipped(width, height);
      r->boxes.push_back(out);
      r->carried.push_back(1);
      r->track_id.push_back(tb.id);
      ++r->num_carried;
      next_.push_back(tb);
    }
  }

  struct Pair {
    T iou;
    std::size_t det, track;
  };
  BoxTrackerOptions<T> options_;
  std::vector<TrackedBox<T>> tracks_;
  std::int64_t next_id_ = 0;
  // Scratch of update(), kept so a tracker run every frame does not allocate once warm.
  std::vector<Box<T>> predicted_;
  std::vector<Pair> pairs_;
  std::vector<std::int64_t> det_track_;
  std::vector<std::uint8_t> track_used_;
  std::vector<TrackedBox<T>> next_;
};

}  // namespace dyncull
