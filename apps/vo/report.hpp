/// @file report.hpp
/// Outputs of the dynamic_vo demo: per-feature label counts against the sim's per-pixel motion truth
/// (precision / recall of the dynamic labels, DLD-SLAM eq. 6-7 style tables) and frames with kept / culled
/// features drawn (PNG through OpenCV).
#pragma once

#include "dyncull/core/pixel.hpp"
#include "dyncull/core/box.hpp"
#include "dyncull/core/types.hpp"
#include "dyncull/culling/labels.hpp"
#include "dyncull/sim/actors.hpp"

#include "sources.hpp"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace dyncull {
namespace vo {

/// Confusion counts of "culled" against "moving" truth, plus the static features inside boxes.
struct LabelCounts {
  std::size_t true_positive = 0;   ///< culled and moving
  std::size_t false_positive = 0;  ///< culled but static
  std::size_t false_negative = 0;  ///< kept but moving
  std::size_t true_negative = 0;   ///< kept and static
  std::size_t static_in_box = 0;       ///< static features inside any detection box ...
  std::size_t static_in_box_kept = 0;  ///< ... and how many of them were kept

  double precision() const {
    const std::size_t d = true_positive + false_positive;
    return d ? static_cast<double>(true_positive) / static_cast<double>(d) : std::numeric_limits<double>::quiet_NaN();
  }
  double recall() const {
    const std::size_t d = true_positive + false_negative;
    return d ? static_cast<double>(true_positive) / static_cast<double>(d) : std::numeric_limits<double>::quiet_NaN();
  }
  double static_in_box_kept_ratio() const {
    return static_in_box ? static_cast<double>(static_in_box_kept) / static_cast<double>(static_in_box)
                         : std::numeric_limits<double>::quiet_NaN();
  }
  LabelCounts& operator+=(const LabelCounts& o) {
    true_positive += o.true_positive;
    false_positive += o.false_positive;
    false_negative += o.false_negative;
    true_negative += o.true_negative;
    static_in_box += o.static_in_box;
    static_in_box_kept += o.static_in_box_kept;
    return *this;
  }
};

/// Adds one frame's features: `moving` is the per-pixel truth (SequenceFrame::moving), keep[i] == 0
/// means culled. Features outside the image or on pixels the truth cannot tell are not counted.
inline void count_labels(const std::vector<cv::Point2f>& px, const std::vector<std::uint8_t>& keep,
                         const cv::Mat& moving, const std::vector<Detection<float>>& detections, LabelCounts* out) {
  if (moving.empty() || moving.type() != CV_8UC1) return;
  for (std::size_t i = 0; i < px.size(); ++i) {
    const int truth = truth_at(moving, px[i]);
    if (truth < 0) continue;
    const bool is_moving = truth == 1;
    const bool culled = i < keep.size() && keep[i] == 0;
    if (culled && is_moving) ++out->true_positive;
    if (culled && !is_moving) ++out->false_positive;
    if (!culled && is_moving) ++out->false_negative;
    if (!culled && !is_moving) ++out->true_negative;
    if (is_moving) continue;
    bool in_box = false;
    for (const Detection<float>& d : detections) in_box = in_box || d.box.contains(px[i].x, px[i].y);
    if (in_box) {
      ++out->static_in_box;
      if (!culled) ++out->static_in_box_kept;
    }
  }
}

/// Where a kept feature (final reason None) stayed static, for dynamic_vo --diagnose.
enum class KeptWhy : std::uint8_t {
  NotExplained = 0,       ///< no culling ran, or the oracle
  OutsideBoxes,           ///< in no high- or medium-level box (detector miss, box too small)
  OutsideObjectBand,      ///< in a box but outside its object's depth band (DLD-SLAM mask)
  CandidateNotFlagged,    ///< medium-level candidate its own evidence did not flag
  NoGeometricEvidence,    ///< in the object, without a geometric label (no track / point, depth edge)
  NotFlagged,             ///< in the object, the geometric check said static, and so did its sub-box
  FlaggedInStaticSubBox,  ///< in the object, flagged by the geometric check, but its sub-box voted static
  StaticHistory,          ///< its region was culled, but its own residual stayed small over its last frames
};

constexpr const char* to_string(KeptWhy w) noexcept {
  switch (w) {
    case KeptWhy::NotExplained: return "";
    case KeptWhy::OutsideBoxes: return "(outside boxes)";
    case KeptWhy::OutsideObjectBand: return "(outside object band)";
    case KeptWhy::CandidateNotFlagged: return "(candidate not flagged)";
    case KeptWhy::NoGeometricEvidence: return "(no geometric evidence)";
    case KeptWhy::NotFlagged: return "(not flagged)";
    case KeptWhy::FlaggedInStaticSubBox: return "(flagged, static sub-box)";
    case KeptWhy::StaticHistory: return "(static history)";
  }
  return "";
}

/// Where the labels of one strategy come from: counts per (sim instance, truth, decision, reason), so a
/// low precision or recall can be traced to the actor and the stage (dynamic_vo --diagnose). A kept
/// feature's reason is None; `kept_why` (optional) then says at which stage it stayed static.
struct LabelBreakdown {
  /// Every sim instance id (sim::SceneInstance), then "other".
  static constexpr int kInstances = sim::SceneInstance::kCount + 1, kReasons = 14, kKeptWhy = 8;
  static constexpr int kCells = kReasons + kKeptWhy;  ///< reasons, then None split by KeptWhy
  std::array<std::size_t, kInstances * 2 * 2 * kCells> counts{};

  std::size_t& at(int instance, bool moving, bool culled, int cell) {
    const int inst = instance < 0 || instance >= kInstances ? kInstances - 1 : instance;
    return counts[static_cast<std::size_t>(((inst * 2 + moving) * 2 + culled) * kCells + cell)];
  }
  void add(const std::vector<cv::Point2f>& px, const std::vector<std::uint8_t>& keep,
           const std::vector<CullReason>& reasons, const std::vector<KeptWhy>& kept_why, const cv::Mat& moving,
           const cv::Mat& instance) {
    // A real sequence's truth has no instances: its features count as "other".
    if (moving.empty() || (!instance.empty() && instance.type() != CV_16UC1)) return;
    for (std::size_t i = 0; i < px.size(); ++i) {
      const int truth = truth_at(moving, px[i]);
      int u = 0, v = 0;
      if (truth < 0 || !pixel_of(px[i].x, px[i].y, moving.cols, moving.rows, &u, &v)) continue;
      const CullReason why = i < reasons.size() ? reasons[i] : CullReason::None;
      int cell = std::min(static_cast<int>(why), kReasons - 1);
      if (why == CullReason::None && i < kept_why.size() && kept_why[i] != KeptWhy::NotExplained)
        cell = kReasons + static_cast<int>(kept_why[i]);
      ++at(instance.empty() ? -1 : instance.at<std::uint16_t>(v, u), truth == 1, i < keep.size() && keep[i] == 0, cell);
    }
  }
  /// Name of a sim instance id (sim::SceneInstance order; ids past the table are "other").
  static const char* instance_name(int instance) {
    static const char* names[kInstances] = {
        "background",    "walker_a",      "walker_b",    "sitting_person", "pushed_chair", "sitting_chair",
        "tv",            "walker_c",      "walker_d",    "desk_person_a",  "desk_person_b", "desk_chair_a",
        "desk_chair_b",  "monitor_a",     "monitor_b",   "keyboard_a",     "keyboard_b",    "mouse_a",
        "mouse_b",       "bottle",        "cup",         "book",           "laptop",        "other"};
    static_assert(sim::SceneInstance::kCount == 23, "name the sim's new instances here");
    return names[instance < 0 || instance >= kInstances ? kInstances - 1 : instance];
  }
  /// One line per non-empty cell: "instance truth decision reason count".
  std::string format() const {
    std::ostringstream o;
    for (int inst = 0; inst < kInstances; ++inst)
      for (int mv = 0; mv < 2; ++mv)
        for (int cu = 0; cu < 2; ++cu)
          for (int cell = 0; cell < kCells; ++cell) {
            const std::size_t c = counts[static_cast<std::size_t>(((inst * 2 + mv) * 2 + cu) * kCells + cell)];
            if (c == 0) continue;
            o << "    " << instance_name(inst) << (mv ? " moving " : " static ") << (cu ? "culled " : "kept   ");
            if (cell < kReasons) o << to_string(static_cast<CullReason>(cell));
            else o << "none " << to_string(static_cast<KeptWhy>(cell - kReasons));
            o << " " << c << "\n";
          }
    return o.str();
  }
};

/// Recall of the moving features by how far their surface moved since the previous frame (sim truth,
/// FrameData::motion_m), overall and per sim instance, for dynamic_vo --diagnose: it tells slow movers,
/// which no geometric check sees within a few frames, from fast ones the culling missed for other reasons.
struct RecallBySpeed {
  static constexpr int kBands = 4, kInstances = LabelBreakdown::kInstances;
  static constexpr float kUpperMm[kBands - 1] = {2.f, 5.f, 10.f};  ///< band edges, mm per frame
  std::array<std::size_t, kInstances * kBands> moving{}, culled{};

  void add(const std::vector<cv::Point2f>& px, const std::vector<std::uint8_t>& keep, const cv::Mat& is_moving,
           const cv::Mat& motion_m, const cv::Mat& instance) {
    if (is_moving.empty() || motion_m.empty() || motion_m.type() != CV_32FC1 || instance.type() != CV_16UC1) return;
    for (std::size_t i = 0; i < px.size(); ++i) {
      int u = 0, v = 0;
      if (!pixel_of(px[i].x, px[i].y, is_moving.cols, is_moving.rows, &u, &v) || !is_moving.at<std::uint8_t>(v, u)) continue;
      const float mm = 1000.f * motion_m.at<float>(v, u);
      int band = 0;
      while (band < kBands - 1 && !(mm < kUpperMm[band])) ++band;
      const int inst = std::min<int>(instance.at<std::uint16_t>(v, u), kInstances - 1);
      const auto cell = static_cast<std::size_t>(inst * kBands + band);
      ++moving[cell];
      culled[cell] += i < keep.size() && keep[i] == 0;
    }
  }
  /// One line for all moving features and one per instance: "band culled/moving (recall)".
  std::string format() const {
    static const char* bands[kBands] = {"< 2 mm", "2-5 mm", "5-10 mm", ">= 10 mm"};
    std::ostringstream o;
    auto line = [&](const char* name, int first, int last) {
      std::size_t total = 0;
      std::ostringstream l;
      l << "    recall by surface motion per frame, " << name << ":";
      for (int b = 0; b < kBands; ++b) {
        std::size_t m = 0, c = 0;
        for (int k = first; k <= last; ++k) {
          m += moving[static_cast<std::size_t>(k * kBands + b)];
          c += culled[static_cast<std::size_t>(k * kBands + b)];
        }
        total += m;
        l << "  " << bands[b] << " " << c << "/" << m;
        if (m > 0) {
          char buf[16];
          std::snprintf(buf, sizeof buf, " (%.2f)", static_cast<double>(c) / static_cast<double>(m));
          l << buf;
        }
      }
      if (total > 0) o << l.str() << "\n";
    };
    line("all", 0, kInstances - 1);
    for (int k = 0; k < kInstances; ++k) line(LabelBreakdown::instance_name(k), k, k);
    return o.str();
  }
};

/// Draws detection boxes, kept features (green) and culled features (red) on a copy of `bgr`.
/// With truth, culled static features are drawn as red crosses and kept moving ones as yellow rings.
inline bool draw_features(const std::string& path, const cv::Mat& bgr, const std::string& caption,
                          const std::vector<cv::Point2f>& px, const std::vector<std::uint8_t>& keep,
                          const std::vector<Detection<float>>& detections, const cv::Mat& moving) {
  cv::Mat img = bgr.clone();
  for (const Detection<float>& d : detections) {
    cv::rectangle(img, cv::Point(cvRound(d.box.x0), cvRound(d.box.y0)), cv::Point(cvRound(d.box.x1), cvRound(d.box.y1)),
                  cv::Scalar(255, 160, 0), 2);
    cv::putText(img, "class " + std::to_string(d.class_id), cv::Point(cvRound(d.box.x0) + 3, cvRound(d.box.y0) + 14),
                cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(255, 160, 0), 1, cv::LINE_AA);
  }
  for (std::size_t i = 0; i < px.size(); ++i) {
    const bool culled = i < keep.size() && keep[i] == 0;
    const int truth = truth_at(moving, px[i]);
    const cv::Point c(cvRound(px[i].x), cvRound(px[i].y));
    if (!culled && truth == 1) {
      cv::circle(img, c, 5, cv::Scalar(0, 230, 255), 2, cv::LINE_AA);
    } else if (culled && truth == 0) {
      cv::drawMarker(img, c, cv::Scalar(0, 0, 255), cv::MARKER_CROSS, 8, 2);
    } else {
      cv::circle(img, c, 3, culled ? cv::Scalar(0, 0, 255) : cv::Scalar(0, 200, 0), -1, cv::LINE_AA);
    }
  }
  cv::rectangle(img, cv::Point(0, 0), cv::Point(img.cols, 22), cv::Scalar(0, 0, 0), -1);
  cv::putText(img, caption, cv::Point(6, 16), cv::FONT_HERSHEY_SIMPLEX, 0.48, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  return cv::imwrite(path, img);
}

}  // namespace vo
}  // namespace dyncull
