/// @file views.hpp
/// OpenCV adapter: zero-copy dyncull views over cv::Mat depth images and masks. cv::Point2f,
/// cv::Point3f and cv::KeyPoint need no adapter: dyncull::PointTraits reads their x/y and .pt members.
#pragma once

#include "dyncull/core/depth.hpp"
#include "dyncull/core/mask.hpp"
#include "dyncull/core/traits.hpp"

#include <opencv2/core.hpp>

#include <cstdint>

namespace dyncull {
namespace cv_adapter {

/// Depth view over a CV_16UC1 image (raw units, e.g. TUM 5000 per metre). Empty view on a wrong type.
inline DepthView<std::uint16_t> depth_view_u16(const cv::Mat& depth, float units_per_metre, float min_m = 0.f,
                                               float max_m = 1e30f) {
  if (depth.empty() || depth.type() != CV_16UC1) return {};
  return DepthView<std::uint16_t>{depth.ptr<std::uint16_t>(0), depth.cols, depth.rows,
                                  static_cast<std::ptrdiff_t>(depth.step1()), units_per_metre, min_m, max_m};
}

/// Depth view over a CV_32FC1 image in metres. Empty view on a wrong type.
inline DepthView<float> depth_view_f32(const cv::Mat& depth, float min_m = 0.f, float max_m = 1e30f) {
  if (depth.empty() || depth.type() != CV_32FC1) return {};
  return DepthView<float>{depth.ptr<float>(0), depth.cols, depth.rows, static_cast<std::ptrdiff_t>(depth.step1()),
                          1.f, min_m, max_m};
}

/// Mutable mask view over a CV_8UC1 image. Empty view on a wrong type.
inline MaskView mask_view(cv::Mat& mask) {
  if (mask.empty() || mask.type() != CV_8UC1) return {};
  return MaskView{mask.ptr<std::uint8_t>(0), mask.cols, mask.rows, static_cast<std::ptrdiff_t>(mask.step1())};
}

/// Read-only mask view over a CV_8UC1 image. Empty view on a wrong type.
inline ConstMaskView const_mask_view(const cv::Mat& mask) {
  if (mask.empty() || mask.type() != CV_8UC1) return {};
  return ConstMaskView{mask.ptr<std::uint8_t>(0), mask.cols, mask.rows, static_cast<std::ptrdiff_t>(mask.step1())};
}

/// cv::Mat header over a dyncull mask (no copy; the Mask must outlive it).
inline cv::Mat to_mat(Mask& mask) {
  return cv::Mat(mask.height, mask.width, CV_8UC1, mask.pixels.data());
}

static_assert(is_point_v<cv::Point2f>, "cv::Point2f must be readable by PointTraits");
static_assert(is_point_v<cv::KeyPoint>, "cv::KeyPoint must be readable by PointTraits");
static_assert(is_point_v<cv::Point3d> && PointTraits<cv::Point3d>::dim == 3, "cv::Point3d has a z");

}  // namespace cv_adapter
}  // namespace dyncull
