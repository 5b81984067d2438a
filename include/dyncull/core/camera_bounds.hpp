/// @file camera_bounds.hpp
/// The one check of a camera where it enters dyncull (the culler, the sequence reader's camera.txt and
/// `--camera`, a host's settings): intrinsics, OpenCV distortion coefficients and the depth scale within
/// the ranges a physical camera has. Refusing fx = 1e-300 or k1 = 1e300 up front is what keeps such a
/// camera from running to the end with a wrong answer. No paper equation. C++11, standard library only, so
/// a C++11 host (ORB-SLAM2/3) can call it on its own settings.
///
/// API:
///   std::string why;
///   if (dyncull::check_camera(fx, fy, cx, cy, width, height, dist.data(), dist.size(), 5000.0, &why) != Ok) ...
///   // why: "fx = 1e-300 px is outside [0.64, 6.4e+06] for a 640x480 image (1e-3 to 1e4 times its larger side)"
#pragma once

#include "dyncull/core/status.hpp"

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <string>

namespace dyncull {

/// Ranges of a camera that exists. Focal lengths are relative to the larger image side s: in
/// [kMinFocalPerSide, kMaxFocalPerSide] * s, a field of view across s between about 0.006 and 179.8
/// degrees. The principal point lies within one image size of the image (cx in [-width, 2 width], cy in
/// [-height, 2 height]). Distortion in OpenCV's order (k1 k2 p1 p2 [k3 [k4 k5 k6 [s1 s2 s3 s4 [tx ty]]]]):
/// radial k at most kMaxRadialDistortion in magnitude (strong fisheye calibrations under the rational
/// model stay below a few hundred), tangential p and thin-prism s at most kMaxTangentialDistortion (a
/// lens decentred by its whole focal length), tilt tx, ty at most kMaxTiltRad (a sensor tilted by 57
/// degrees). Depth: [kMinDepthUnitsPerMetre, kMaxDepthUnitsPerMetre] raw units per metre (metres 1,
/// millimetres 1000, TUM 5000). Images up to kMaxImageSide pixels a side.
struct CameraBounds {
  static constexpr double kMinFocalPerSide = 1e-3;
  static constexpr double kMaxFocalPerSide = 1e4;
  static constexpr double kMaxRadialDistortion = 1e3;
  static constexpr double kMaxTangentialDistortion = 1.0;
  static constexpr double kMaxTiltRad = 1.0;
  static constexpr double kMinDepthUnitsPerMetre = 1e-3;
  static constexpr double kMaxDepthUnitsPerMetre = 1e6;
  static constexpr int kMaxImageSide = 100000;
};

namespace detail {
inline std::string camera_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return std::string(buf);
}
inline Status camera_refused(std::string* reason, const std::string& why) {
  if (reason) *reason = why;
  return Status::InvalidInput;
}
}  // namespace detail

/// Ok, or InvalidInput naming the first intrinsic no camera has: an image size outside [1, 100000], a
/// non-finite or non-positive focal length, a focal length or principal point outside CameraBounds.
inline Status check_intrinsics(double fx, double fy, double cx, double cy, int width, int height,
                               std::string* reason = nullptr) {
  using detail::camera_number;
  if (width <= 0 || height <= 0 || width > CameraBounds::kMaxImageSide || height > CameraBounds::kMaxImageSide)
    return detail::camera_refused(reason, "image size must be positive, got " + std::to_string(width) + "x" +
                                              std::to_string(height));
  if (!(fx > 0) || !(fy > 0) || !std::isfinite(fx) || !std::isfinite(fy))
    return detail::camera_refused(reason, "focal lengths fx, fy must be finite and positive");
  if (!std::isfinite(cx) || !std::isfinite(cy))
    return detail::camera_refused(reason, "principal point cx, cy must be finite");
  const double side = static_cast<double>(width > height ? width : height);
  const double lo = CameraBounds::kMinFocalPerSide * side, hi = CameraBounds::kMaxFocalPerSide * side;
  const double f[2] = {fx, fy};
  for (int k = 0; k < 2; ++k)
    if (!(f[k] >= lo && f[k] <= hi))
      return detail::camera_refused(reason, std::string(k == 0 ? "fx" : "fy") + " = " + camera_number(f[k]) +
                                                " px is outside [" + camera_number(lo) + ", " + camera_number(hi) +
                                                "] for a " + std::to_string(width) + "x" + std::to_string(height) +
                                                " image (1e-3 to 1e4 times its larger side)");
  const double c[2] = {cx, cy};
  const int size[2] = {width, height};
  for (int k = 0; k < 2; ++k)
    if (!(c[k] >= -double(size[k]) && c[k] <= 2.0 * double(size[k])))
      return detail::camera_refused(reason, std::string(k == 0 ? "cx" : "cy") + " = " + camera_number(c[k]) +
                                                " px is more than one image " + (k == 0 ? "width" : "height") + " (" +
                                                std::to_string(size[k]) + " px) outside the image");
  if (reason) reason->clear();
  return Status::Ok;
}

/// Name of OpenCV's distortion coefficient i (k1 k2 p1 p2 k3 k4 k5 k6 s1 s2 s3 s4 tx ty).
inline const char* distortion_name(std::size_t i) {
  static const char* const names[14] = {"k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6",
                                        "s1", "s2", "s3", "s4", "tx", "ty"};
  return i < 14 ? names[i] : "?";
}

/// Ok, or InvalidInput naming the first bad coefficient: a count other than 0, 4, 5, 8, 12 or 14, a value
/// that is not finite or outside CameraBounds for its kind.
inline Status check_distortion(const double* coefficients, std::size_t count, std::string* reason = nullptr) {
  if (count != 0 && count != 4 && count != 5 && count != 8 && count != 12 && count != 14)
    return detail::camera_refused(reason, std::to_string(count) +
                                              " distortion coefficients; OpenCV's model has 4, 5, 8, 12 or 14");
  for (std::size_t i = 0; i < count; ++i) {
    const double v = coefficients[i];
    const bool tangential = i == 2 || i == 3 || (i >= 8 && i < 12);
    const bool tilt = i >= 12;
    // Assigned, not chosen by ?: (an lvalue there would odr-use the constants, which C++11 must define).
    double bound = CameraBounds::kMaxRadialDistortion;
    if (tangential) bound = CameraBounds::kMaxTangentialDistortion;
    if (tilt) bound = CameraBounds::kMaxTiltRad;
    if (!std::isfinite(v))
      return detail::camera_refused(reason, std::string("distortion ") + distortion_name(i) + " is NaN or Inf");
    if (!(std::abs(v) <= bound))
      return detail::camera_refused(reason, std::string("distortion ") + distortion_name(i) + " = " +
                                                detail::camera_number(v) + " is outside [-" +
                                                detail::camera_number(bound) + ", " + detail::camera_number(bound) +
                                                "] (no lens has it)");
  }
  if (reason) reason->clear();
  return Status::Ok;
}

/// Ok, or InvalidInput when raw depth units per metre are not in CameraBounds' range.
inline Status check_depth_units(double units_per_metre, std::string* reason = nullptr) {
  if (!(units_per_metre >= CameraBounds::kMinDepthUnitsPerMetre && units_per_metre <= CameraBounds::kMaxDepthUnitsPerMetre))
    return detail::camera_refused(reason, "depth units per metre = " + detail::camera_number(units_per_metre) +
                                              " is outside [1e-3, 1e6] (metres: 1, millimetres: 1000, TUM: 5000)");
  if (reason) reason->clear();
  return Status::Ok;
}

/// All three checks in order: intrinsics, distortion, depth scale (pass a depth scale of 1 for a
/// camera without depth). Ok, or InvalidInput with the first reason.
inline Status check_camera(double fx, double fy, double cx, double cy, int width, int height, const double* distortion,
                           std::size_t distortion_count, double depth_units_per_metre, std::string* reason = nullptr) {
  Status s = check_intrinsics(fx, fy, cx, cy, width, height, reason);
  if (s == Status::Ok) s = check_distortion(distortion, distortion_count, reason);
  if (s == Status::Ok) s = check_depth_units(depth_units_per_metre, reason);
  return s;
}

}  // namespace dyncull
