// Test helper: the public culler's inputs from the core's types (detections as DetectedBox, an OpenCV
// descriptor matrix as DescriptorRows), shared by the tests of the compiled culler and its OpenCV overloads.
// Not a paper equation.
#pragma once

#include "dyncull/core/box.hpp"
#include "dyncull/core/views.hpp"
#include "dyncull/culling/culler.hpp"

#include <opencv2/core.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace dyncull::test {

inline std::vector<DetectedBox> boxes_of(const std::vector<Detection<float>>& detections) {
  std::vector<DetectedBox> out;
  for (const Detection<float>& d : detections)
    out.emplace_back(d.box.x0, d.box.y0, d.box.x1, d.box.y1, d.class_id, d.confidence);
  return out;
}

inline DescriptorRows rows_of(const cv::Mat& d) {
  return DescriptorRows(d.ptr<std::uint8_t>(0), static_cast<std::size_t>(d.rows), d.step[0],
                        static_cast<std::size_t>(d.cols));
}

}  // namespace dyncull::test
