/// @file culler.hpp
/// OpenCV overloads of the culler (culling/culler.hpp): the camera from K, the image size and OpenCV's
/// distortion coefficients; a frame from an ORB-SLAM-like front end's cv::KeyPoint (or cv::Point2f)
/// vector, descriptor cv::Mat, depth cv::Mat (CV_32F metres or CV_16U raw units) and boxes; the keep mask
/// applied to a descriptor cv::Mat and parallel vectors. Thin: they build the culler's plain views.
/// C++11; includes the standard library and opencv2/core.hpp.
///
/// API:
/// @code
///   dyncull::Culler culler(dyncull::cv_adapter::culler_camera(K, cv::Size(640, 480), dist_coeffs));
///   const dyncull::CullerResult& r = dyncull::cv_adapter::cull(culler, keys, descriptors, depth, boxes, &Tcw);
///   dyncull::cv_adapter::compact(r.keep, descriptors, keys);   // returns the new count
/// @endcode
#pragma once

#include "dyncull/culling/culler.hpp"

#include <opencv2/core.hpp>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace dyncull {
namespace cv_adapter {

/// The culler's camera from a 3x3 K (CV_32F / CV_64F), the image size and OpenCV's distortion
/// coefficients (empty: none; any layout, also a view into a larger matrix). A K that is not 3x3 floating
/// point gives a camera without intrinsics, which the culler refuses with its reason.
inline CullerCamera culler_camera(const cv::Mat& K, cv::Size image_size, const cv::Mat& distortion = cv::Mat()) {
  CullerCamera c;
  c.width = image_size.width;
  c.height = image_size.height;
  if (K.rows == 3 && K.cols == 3 && K.channels() == 1 && (K.depth() == CV_32F || K.depth() == CV_64F)) {
    cv::Mat k;
    K.convertTo(k, CV_64F);
    c.fx = k.at<double>(0, 0);
    c.fy = k.at<double>(1, 1);
    c.cx = k.at<double>(0, 2);
    c.cy = k.at<double>(1, 2);
  }
  if (!distortion.empty() && distortion.dims == 2) {
    // convertTo writes a new continuous matrix, so a view (a column of a larger Mat) reads as well; every
    // value in row-major order, so a count the model does not have is refused by the culler, named.
    cv::Mat d;
    distortion.convertTo(d, CV_64F);
    const double* p = d.ptr<double>(0);
    c.distortion.assign(p, p + d.total() * static_cast<std::size_t>(d.channels()));
  } else if (!distortion.empty()) {
    c.distortion.assign(9, 0.0);  // not a 2-D matrix: a count no model has, refused with its reason
  }
  return c;
}

/// A detector's cv::Rect2f (x, y, width, height) as a box: x1 = x + width, y1 = y + height.
inline DetectedBox detected_box(const cv::Rect2f& r, int class_id, float confidence = 1.f) {
  return DetectedBox(r.x, r.y, r.x + r.width, r.y + r.height, class_id, confidence);
}

/// Culls one frame of OpenCV containers. `keys`: cv::KeyPoint or cv::Point2f as detected; `descriptors`:
/// one CV_8U row per key (empty: none); `depth`: CV_32F metres or CV_16U raw at the image size, scaled by
/// CullerOptions::depth_units_per_metre (empty: monocular); `predicted_Tcw`: 4x4 cam_from_world, CV_32F or
/// CV_64F, or null; `undistorted`: the host's undistorted copy of keys (ORB-SLAM's mvKeysUn) or null.
/// `keyframe_match`, `is_keyframe`: the host's correspondences and keyframe flag (CullerFrame). A container
/// of the wrong type or shape refuses the frame with the reason naming it.
template <class Point>
const CullerResult& cull(Culler& culler, const std::vector<Point>& keys, const cv::Mat& descriptors,
                         const cv::Mat& depth, const std::vector<DetectedBox>& detections,
                         const cv::Mat* predicted_Tcw = nullptr, const std::vector<Point>* undistorted = nullptr,
                         const int* keyframe_match = nullptr, bool is_keyframe = false) {
  const std::size_t n = keys.size();
  if (!culler.ok()) return culler.refuse(culler.status(), culler.reason(), n);
  CullerFrame f;
  f.keypoints = points_view(keys);
  if (undistorted) f.undistorted_keypoints = points_view(*undistorted);
  if (!descriptors.empty()) {
    if (descriptors.depth() != CV_8U || descriptors.dims != 2 || descriptors.channels() != 1)
      return culler.refuse(Status::InvalidInput, "descriptors must be a 2-D single-channel CV_8U matrix (binary descriptors)", n);
    f.descriptors = DescriptorRows(descriptors.ptr<std::uint8_t>(0), static_cast<std::size_t>(descriptors.rows),
                                   descriptors.step[0], static_cast<std::size_t>(descriptors.cols));
  }
  if (!depth.empty()) {
    if (depth.dims != 2 || (depth.type() != CV_32FC1 && depth.type() != CV_16UC1))
      return culler.refuse(Status::InvalidInput, "depth must be a CV_32FC1 (metres) or CV_16UC1 (raw units) image", n);
    if (depth.type() == CV_32FC1) {
      f.depth_m.data = depth.ptr<float>(0);
      f.depth_m.width = depth.cols;
      f.depth_m.height = depth.rows;
      f.depth_m.stride = static_cast<std::ptrdiff_t>(depth.step[0] / sizeof(float));
    } else {
      f.depth_raw.data = depth.ptr<std::uint16_t>(0);
      f.depth_raw.width = depth.cols;
      f.depth_raw.height = depth.rows;
      f.depth_raw.stride = static_cast<std::ptrdiff_t>(depth.step[0] / sizeof(std::uint16_t));
      f.depth_raw.units_per_metre = static_cast<float>(culler.options().depth_units_per_metre);
    }
    if (depth.step[0] % depth.elemSize() != 0)
      return culler.refuse(Status::InvalidInput, "depth rows must be aligned to its elements", n);
  }
  f.detections = &detections;
  f.keyframe_match = keyframe_match;
  f.is_keyframe = is_keyframe;
  double Rt[12];
  if (predicted_Tcw) {
    const cv::Mat& m = *predicted_Tcw;
    if (m.rows != 4 || m.cols != 4 || m.channels() != 1 || (m.depth() != CV_32F && m.depth() != CV_64F))
      return culler.refuse(Status::InvalidInput, "predicted_Tcw must be a 4x4 CV_32F or CV_64F matrix [R t; 0 0 0 1]", n);
    // Read in place (no conversion buffer: nothing allocated per frame).
    const bool dbl = m.depth() == CV_64F;
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) {
        const double v = dbl ? m.at<double>(r, c) : static_cast<double>(m.at<float>(r, c));
        if (r < 3) Rt[4 * r + c] = v;
        else if (v != (c == 3 ? 1.0 : 0.0))
          return culler.refuse(Status::InvalidInput, "predicted_Tcw must be a 4x4 CV_32F or CV_64F matrix [R t; 0 0 0 1]", n);
      }
    f.cam_from_world = Rt;
  }
  return culler.cull(f);
}

/// Removes, in place and stably, the features with keep[i] == 0 from the descriptor matrix (one row per
/// feature) and from every parallel std::vector, then shrinks the matrix to the surviving rows (a
/// bag-of-words lookup must never read a stale row). Returns the new count; -1 with nothing touched when
/// the matrix is not 2-D or an array has another size than keep (dyncull::compact, core/compact.hpp).
template <class... Vectors>
long compact(const std::vector<std::uint8_t>& keep, cv::Mat& descriptors, Vectors&... vectors) {
  if (descriptors.dims > 2) return -1;
  const std::size_t rows = static_cast<std::size_t>(descriptors.rows);
  const std::size_t row_bytes = static_cast<std::size_t>(descriptors.cols) * descriptors.elemSize();
  RowsView view(rows > 0 ? descriptors.ptr(0) : nullptr, row_bytes,
                rows > 0 ? static_cast<std::size_t>(descriptors.step[0]) : 0, rows);
  const long kept = dyncull::compact(keep, view, vectors...);
  if (kept >= 0 && rows > 0) descriptors = descriptors.rowRange(0, static_cast<int>(kept));
  return kept;
}

}  // namespace cv_adapter
}  // namespace dyncull
