/// @file box_culls.hpp
/// Where a strategy's culls fall relative to the detector's boxes, for sequences without per-pixel
/// truth: the share of tracked features culled inside person boxes (what box-based culling is for), inside
/// the boxes of other classes only (chairs, screens: in an office mostly static, so mostly lost) and outside
/// every box (static background lost, unless a geometric check caught a mover the detector missed). No
/// paper equation.
#pragma once

#include "dyncull/core/box.hpp"

#include <opencv2/core.hpp>

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace dyncull {
namespace vo {

struct BoxCullCounts {
  static constexpr int kPersonClass = 0;  ///< COCO-80 person
  std::size_t in_person = 0, in_person_culled = 0;
  std::size_t in_other = 0, in_other_culled = 0;  ///< in some box, in no person box
  std::size_t outside = 0, outside_culled = 0;

  /// Adds one frame: px the tracked features, keep[i] == 0 culled, boxes the frame's detections.
  void add(const std::vector<cv::Point2f>& px, const std::vector<std::uint8_t>& keep,
           const std::vector<Detection<float>>& boxes) {
    for (std::size_t i = 0; i < px.size(); ++i) {
      bool person = false, any = false;
      for (const Detection<float>& d : boxes) {
        if (px[i].x < d.box.x0 || px[i].x > d.box.x1 || px[i].y < d.box.y0 || px[i].y > d.box.y1) continue;
        any = true;
        person = person || d.class_id == kPersonClass;
      }
      const bool culled = i < keep.size() && keep[i] == 0;
      if (person) {
        ++in_person;
        in_person_culled += culled ? 1 : 0;
      } else if (any) {
        ++in_other;
        in_other_culled += culled ? 1 : 0;
      } else {
        ++outside;
        outside_culled += culled ? 1 : 0;
      }
    }
  }
  static double share(std::size_t part, std::size_t whole) {
    return whole ? static_cast<double>(part) / static_cast<double>(whole) : std::numeric_limits<double>::quiet_NaN();
  }
  double culled_in_person_boxes() const { return share(in_person_culled, in_person); }
  double culled_in_other_boxes() const { return share(in_other_culled, in_other); }
  double culled_outside_boxes() const { return share(outside_culled, outside); }
};

}  // namespace vo
}  // namespace dyncull
