/// @file frame.hpp
/// OpenCV adapter for a host front end's per-frame inputs (no paper equation): a validated PinholeCamera
/// from a K matrix with its distortion reported, TUM's uint16 depth (5000 per metre), and keypoint undistortion
/// to pixels through cv::undistortPoints (Brown-Conrady model, OpenCV's coefficient order).
///
/// API:
///   CameraFromK<float> cam = cv_adapter::camera_from_K<float>(K, cv::Size(640, 480), dist_coeffs);
///   DepthView<std::uint16_t> depth = cv_adapter::tum_depth_view(depth_png);
///   cv_adapter::undistort_keypoints(keypoints, K, dist_coeffs, &keypoints_un);
#pragma once

#include "dyncull/core/camera.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/opencv/views.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

namespace dyncull {
namespace cv_adapter {

// ------------------------------------------------------------------------------------------------
// Camera
// ------------------------------------------------------------------------------------------------

/// A camera built from K, with the distortion coefficients it came with.
template <class T>
struct CameraFromK {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }
  PinholeCamera<T> camera;          ///< meaningful only when ok()
  std::vector<double> distortion;   ///< OpenCV order (k1, k2, p1, p2[, k3[, k4, k5, k6[, s1..s4[, tx, ty]]]])
  bool has_distortion = false;      ///< a coefficient is non-zero: keypoints must be undistorted for geometry
};

namespace detail {
inline bool read_matrix(const cv::Mat& m, std::vector<double>* out) {
  if (m.empty() || m.channels() != 1 || (m.depth() != CV_32F && m.depth() != CV_64F)) return false;
  out->clear();
  for (int r = 0; r < m.rows; ++r)
    for (int c = 0; c < m.cols; ++c)
      out->push_back(m.depth() == CV_64F ? m.at<double>(r, c) : static_cast<double>(m.at<float>(r, c)));
  return true;
}
}  // namespace detail

/// PinholeCamera from a 3x3 K (CV_32F or CV_64F: fx 0 cx; 0 fy cy; 0 0 1) and the image size. K must be
/// finite with positive focal lengths, zero skew and the last row (0, 0, 1), the size positive, and its
/// intrinsics those of a camera that exists (PinholeCamera::validate: focal lengths 1e-3 to 1e4 times the
/// larger image side, the principal point within one image size of the image); the distortion
/// coefficients (optional) a CV_32F / CV_64F vector of 4, 5, 8, 12 or 14 finite values.
/// Anything else is InvalidInput (NonFinite for a NaN / Inf entry) with the reason naming K, image_size or
/// distortion. The camera itself has no distortion: with has_distortion, pass keypoints through
/// undistort_keypoints before geometry.
namespace detail {
/// K's nine entries (row-major) and the distortion coefficients, with the checks of camera_from_K that do
/// not need the image size. Ok, or the status with the reason (without the "camera_from_K: " prefix).
inline Status read_calibration(const cv::Mat& K, const cv::Mat& distortion, std::vector<double>* k,
                               std::vector<double>* coefficients, bool* has_distortion, std::string* why) {
  auto fail = [&](Status s, const std::string& reason) {
    *why = reason;
    return s;
  };
  *has_distortion = false;
  coefficients->clear();
  if (K.rows != 3 || K.cols != 3 || !read_matrix(K, k))
    return fail(Status::InvalidInput, "K must be a 3x3 single-channel CV_32F or CV_64F matrix");
  for (double v : *k)
    if (!std::isfinite(v)) return fail(Status::NonFinite, "K has a NaN or Inf entry");
  const std::vector<double>& m = *k;
  if (!(m[0] > 0.0) || !(m[4] > 0.0)) return fail(Status::InvalidInput, "K's focal lengths fx, fy must be positive");
  if (m[1] != 0.0) return fail(Status::InvalidInput, "K has a non-zero skew K(0, 1); the pinhole model has none");
  if (m[3] != 0.0 || m[6] != 0.0 || m[7] != 0.0 || m[8] != 1.0)
    return fail(Status::InvalidInput, "K's rows must be (fx 0 cx; 0 fy cy; 0 0 1)");
  if (!distortion.empty()) {
    if ((distortion.rows != 1 && distortion.cols != 1) || !read_matrix(distortion, coefficients))
      return fail(Status::InvalidInput, "distortion must be a single-channel CV_32F or CV_64F vector");
    const std::size_t nd = coefficients->size();
    if (nd != 4 && nd != 5 && nd != 8 && nd != 12 && nd != 14)
      return fail(Status::InvalidInput, "distortion has " + std::to_string(nd) +
                                            " coefficients; OpenCV takes 4, 5, 8, 12 or 14");
    for (double v : *coefficients) {
      if (!std::isfinite(v)) return fail(Status::NonFinite, "distortion has a NaN or Inf coefficient");
      *has_distortion = *has_distortion || v != 0.0;
    }
  }
  why->clear();
  return Status::Ok;
}
}  // namespace detail

template <class T>
CameraFromK<T> camera_from_K(const cv::Mat& K, cv::Size image_size, const cv::Mat& distortion = cv::Mat()) {
  CameraFromK<T> out;
  auto fail = [&](Status s, const std::string& why) {
    out.status = s;
    out.reason = "camera_from_K: " + why;
    out.distortion.clear();
    out.has_distortion = false;
    return out;
  };
  std::vector<double> k;
  std::string why;
  const Status read = detail::read_calibration(K, distortion, &k, &out.distortion, &out.has_distortion, &why);
  if (read != Status::Ok) return fail(read, why);
  if (image_size.width <= 0 || image_size.height <= 0)
    return fail(Status::InvalidInput, "image_size must be positive, got " + std::to_string(image_size.width) + "x" +
                                          std::to_string(image_size.height));
  // Checked in double before the conversion: the bounds keep every entry well inside float's range.
  const PinholeCamera<double> exact{k[0], k[4], k[2], k[5], image_size.width, image_size.height};
  if (exact.validate(&why) != Status::Ok) return fail(Status::InvalidInput, "K: " + why);
  out.camera = exact.template cast<T>();
  return out;
}

// ------------------------------------------------------------------------------------------------
// Depth
// ------------------------------------------------------------------------------------------------

/// Raw units per metre of the TUM RGB-D depth PNGs.
constexpr float kTumDepthUnitsPerMetre = 5000.f;

/// Depth view over a TUM depth PNG (CV_16UC1, 5000 per metre) read with cv::IMREAD_UNCHANGED; an empty
/// view on a wrong type (check_depth says why).
inline DepthView<std::uint16_t> tum_depth_view(const cv::Mat& depth, float min_m = 0.f, float max_m = 1e30f) {
  return depth_view_u16(depth, kTumDepthUnitsPerMetre, min_m, max_m);
}

/// Ok when `depth` can be read as a depth image of `image_size`: CV_16UC1 (raw units with a scale) or
/// CV_32FC1 (metres). Otherwise InvalidInput with the reason (empty, type, size); an image loaded without
/// cv::IMREAD_UNCHANGED is 8-bit and named as such.
inline Status check_depth(const cv::Mat& depth, cv::Size image_size, std::string* reason = nullptr) {
  auto bad = [&](const std::string& why) {
    if (reason) *reason = "depth: " + why;
    return Status::InvalidInput;
  };
  if (depth.empty()) return bad("the image is empty");
  if (depth.type() != CV_16UC1 && depth.type() != CV_32FC1) {
    if (depth.depth() == CV_8U) return bad("8-bit image: read the PNG with cv::IMREAD_UNCHANGED to keep 16 bits");
    return bad("type must be CV_16UC1 (raw units) or CV_32FC1 (metres)");
  }
  if (depth.cols != image_size.width || depth.rows != image_size.height)
    return bad(std::to_string(depth.cols) + "x" + std::to_string(depth.rows) + " for an image of " +
               std::to_string(image_size.width) + "x" + std::to_string(image_size.height));
  if (reason) reason->clear();
  return Status::Ok;
}

// ------------------------------------------------------------------------------------------------
// Undistortion
// ------------------------------------------------------------------------------------------------

/// Buffers of undistort_keypoints, reused across frames.
struct UndistortWorkspace {
  std::vector<cv::Point2f> src, dst;
  std::vector<std::size_t> index;
};

namespace detail {
inline cv::Point2f kp_position(const cv::KeyPoint& k) { return k.pt; }
template <class P> cv::Point2f kp_position(const cv::Point_<P>& p) {
  return cv::Point2f(static_cast<float>(p.x), static_cast<float>(p.y));
}
inline void kp_set_position(cv::KeyPoint& k, const cv::Point2f& p) { k.pt = p; }
template <class P> void kp_set_position(cv::Point_<P>& q, const cv::Point2f& p) {
  q.x = static_cast<P>(p.x);
  q.y = static_cast<P>(p.y);
}
}  // namespace detail

/// Undistorted pixel positions of `keypoints` (cv::KeyPoint: other fields copied; cv::Point2f / Point2d)
/// for the camera K with OpenCV distortion coefficients `distortion` (cv::undistortPoints with P = K, so
/// the output stays in pixels of the same K). Non-finite keypoints are copied unchanged (OpenCV's
/// iteration is not given them). No distortion (empty or all zero) copies the input. `out` may be
/// `&keypoints`. Status: InvalidInput / NonFinite from camera_from_K's checks of K and the coefficients
/// (out then holds a copy of the input), Ok otherwise.
template <class KP>
Status undistort_keypoints(const std::vector<KP>& keypoints, const cv::Mat& K, const cv::Mat& distortion,
                           std::vector<KP>* out, std::string* reason = nullptr,
                           UndistortWorkspace* workspace = nullptr) {
  static_assert(std::is_same<KP, cv::KeyPoint>::value || std::is_same<KP, cv::Point2f>::value ||
                    std::is_same<KP, cv::Point2d>::value,
                "undistort_keypoints: cv::KeyPoint, cv::Point2f or cv::Point2d");
  if (out != &keypoints) *out = keypoints;
  std::vector<double> k, coefficients;
  bool has_distortion = false;
  std::string why;
  const Status read = detail::read_calibration(K, distortion, &k, &coefficients, &has_distortion, &why);
  if (read != Status::Ok) {
    if (reason) *reason = "undistort_keypoints: camera_from_K: " + why;
    return read;
  }
  if (reason) reason->clear();
  if (!has_distortion || out->empty()) return Status::Ok;
  UndistortWorkspace local;
  UndistortWorkspace& ws = workspace ? *workspace : local;
  ws.src.clear();
  ws.index.clear();
  for (std::size_t i = 0; i < out->size(); ++i) {
    const cv::Point2f p = detail::kp_position((*out)[i]);
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) continue;
    ws.src.push_back(p);
    ws.index.push_back(i);
  }
  if (ws.src.empty()) return Status::Ok;
  // OpenCV's default of 5 fixed-point iterations leaves 0.06 px at the corners of TUM fr1 (k1 = 0.26)
  // and its strong k2, k3; iterate to convergence instead.
  cv::undistortPoints(ws.src, ws.dst, K, distortion, cv::noArray(), K,
                      cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 50, 1e-6));
  for (std::size_t j = 0; j < ws.index.size(); ++j) detail::kp_set_position((*out)[ws.index[j]], ws.dst[j]);
  return Status::Ok;
}

}  // namespace cv_adapter
}  // namespace dyncull
