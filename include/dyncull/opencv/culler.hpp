/// @file culler.hpp
/// OpenCV face of the stateful culler (culling/culler.hpp): an ORB-SLAM-like front end's cv::KeyPoint
/// vector, descriptor cv::Mat, depth cv::Mat (CV_32F metres or CV_16U raw units) and detector boxes in, a
/// keep mask out. The camera comes from K, the image size and optional distortion (camera_from_K); with
/// distortion the keypoints are undistorted here (cv::undistortPoints, Brown-Conrady model) for the
/// geometry, or the host passes its own undistorted copy (ORB-SLAM's mvKeysUn).
///
/// API:
///   cv_adapter::FrameCuller culler(K, cv::Size(640, 480), dist_coeffs);   // check culler.ok()
///   const std::vector<std::uint8_t>& keep = culler.cull(keys, descriptors, depth, boxes, &Tcw);
///   cv_adapter::compact_frame(keep, descriptors, keys);                     // opencv/frame.hpp
#pragma once

#include "dyncull/culling/culler.hpp"
#include "dyncull/opencv/frame.hpp"

#include <opencv2/core.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace dyncull {
namespace cv_adapter {

/// One camera stream's culler over OpenCV containers (float geometry). Not thread-safe.
class FrameCuller {
 public:
  /// K: 3x3 CV_32F / CV_64F; distortion: OpenCV's 4, 5, 8, 12 or 14 coefficients, or empty;
  /// depth_units_per_metre: the raw scale of CV_16U depth images (TUM 5000, most sensors 1000).
  /// A bad K, size, distortion or option makes status() say why and every cull() refuse (keep all).
  FrameCuller(const cv::Mat& K, cv::Size image_size, const cv::Mat& distortion = cv::Mat(),
              const CullerOptions<float>& options = CullerOptions<float>(), float depth_units_per_metre = 5000.f)
      : camera_(camera_from_K<float>(K, image_size, distortion)),
        culler_(camera_.ok() ? camera_.camera : invalid_camera(), with_distortion(options, camera_.has_distortion)),
        depth_units_per_metre_(depth_units_per_metre) {
    K.copyTo(K_);
    distortion.copyTo(distortion_);
    if (!camera_.ok()) {
      status_ = camera_.status;
      reason_ = camera_.reason;
    } else if (!(depth_units_per_metre >= DepthView<std::uint16_t>::kMinUnitsPerMetre &&
                 depth_units_per_metre <= DepthView<std::uint16_t>::kMaxUnitsPerMetre)) {
      status_ = Status::InvalidInput;
      reason_ = "depth_units_per_metre must be in [1e-3, 1e6] (metres: 1, millimetres: 1000, TUM: 5000)";
    } else {
      status_ = culler_.status();
      reason_ = culler_.reason();
    }
  }

  Status status() const { return status_; }
  const std::string& reason() const { return reason_; }
  bool ok() const { return status_ == Status::Ok; }

  /// Keep mask parallel to `keys` (1 = static); result() says why. `descriptors`: one CV_8U row per key
  /// (empty: none); `depth`: the frame's depth at the image size (empty: monocular); `predicted_Tcw`: 4x4
  /// cam_from_world (CV_32F / CV_64F), e.g. the motion model's, or null. `undistorted`: the host's
  /// undistorted copy of keys, or null to undistort here when the camera has distortion. The checks and
  /// statuses are Culler::cull's (a rigid pose, NaN / Inf keypoints culled, descriptor widths): the same
  /// frame gets the same result as from Culler<float> and CompiledCuller.
  const std::vector<std::uint8_t>& cull(const std::vector<cv::KeyPoint>& keys, const cv::Mat& descriptors,
                                        const cv::Mat& depth, const std::vector<Detection<float>>& detections,
                                        const cv::Mat* predicted_Tcw = nullptr,
                                        const std::vector<cv::KeyPoint>* undistorted = nullptr) {
    CullerFrame<float> f;
    f.keypoints = points_view(keys);
    std::string why;
    if (!ok()) return refuse(status_, reason_, keys.size());
    if (!descriptors.empty()) {
      if (descriptors.depth() != CV_8U || descriptors.dims != 2)
        return refuse(Status::InvalidInput, "descriptors must be a 2-D CV_8U matrix (binary descriptors)", keys.size());
      f.descriptors = DescriptorRows(descriptors.ptr<std::uint8_t>(0), static_cast<std::size_t>(descriptors.rows),
                                     descriptors.step[0], descriptors.cols * descriptors.elemSize());
    }
    if (!depth.empty()) {
      if (check_depth(depth, cv::Size(camera_.camera.width, camera_.camera.height), &why) != Status::Ok)
        return refuse(Status::InvalidInput, why, keys.size());
      if (depth.type() == CV_32FC1)
        f.depth_m = depth_view_f32(depth);
      else
        f.depth_raw = depth_view_u16(depth, depth_units_per_metre_);
    }
    f.detections = &detections;
    if (predicted_Tcw) {
      const Status s = read_pose(*predicted_Tcw, &pose_, &why);
      if (s != Status::Ok) return refuse(s, why, keys.size());
      f.cam_from_world = &pose_;
    }
    if (undistorted) {
      f.undistorted_keypoints = points_view(*undistorted);
    } else if (camera_.has_distortion) {
      if (undistort_keypoints(keys, K_, distortion_, &undistorted_, &why, &undistort_ws_) != Status::Ok)
        return refuse(Status::InvalidInput, why, keys.size());
      f.undistorted_keypoints = points_view(undistorted_);
    }
    return culler_.cull(f).keep;
  }

  /// Labels, reasons, status and what was missing, of the last cull().
  const CullerResult& result() const { return culler_.result(); }
  /// Forgets the keyframe, the tracks and the pipeline's state (Culler::reset); the camera and options stay.
  void reset() { culler_.reset(); }
  /// The camera read from K (with its distortion flag).
  const CameraFromK<float>& camera() const { return camera_; }
  Culler<float>& culler() { return culler_; }

 private:
  static PinholeCamera<float> invalid_camera() { return PinholeCamera<float>{0.f, 0.f, 0.f, 0.f, 0, 0}; }
  static CullerOptions<float> with_distortion(CullerOptions<float> o, bool distorted) {
    o.camera_has_distortion = o.camera_has_distortion || distorted;
    return o;
  }

  // Refused here or in Culler::cull: the same result either way.
  const std::vector<std::uint8_t>& refuse(Status s, const std::string& why, std::size_t n) {
    return culler_.refuse_frame(s, why, n).keep;
  }

  /// The 4x4 cam_from_world, checked in double before the conversion to float (culler_checks::check_pose:
  /// finite, in range, rigid), then its last row.
  static Status read_pose(const cv::Mat& m, Rigid3<float>* out, std::string* why) {
    if (m.rows != 4 || m.cols != 4 || m.channels() != 1 || (m.depth() != CV_32F && m.depth() != CV_64F))
      return (*why = "predicted_Tcw must be a 4x4 CV_32F or CV_64F matrix [R t; 0 0 0 1]", Status::InvalidInput);
    auto at = [&](int r, int c) {
      return m.depth() == CV_64F ? m.at<double>(r, c) : static_cast<double>(m.at<float>(r, c));
    };
    double R[9], t[3];
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) R[3 * r + c] = at(r, c);
      t[r] = at(r, 3);
    }
    const Status s = culler_checks::check_pose(R, t, "predicted_Tcw", why);
    if (s != Status::Ok) return s;
    if (!(at(3, 0) == 0.0 && at(3, 1) == 0.0 && at(3, 2) == 0.0 && at(3, 3) == 1.0))
      return (*why = "predicted_Tcw must be a 4x4 CV_32F or CV_64F matrix [R t; 0 0 0 1]", Status::InvalidInput);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) out->R(r, c) = static_cast<float>(R[3 * r + c]);
      out->t(r) = static_cast<float>(t[r]);
    }
    return Status::Ok;
  }

  CameraFromK<float> camera_;
  Culler<float> culler_;
  float depth_units_per_metre_;
  Status status_ = Status::Ok;
  std::string reason_;
  cv::Mat K_, distortion_;
  Rigid3<float> pose_;
  std::vector<cv::KeyPoint> undistorted_;
  UndistortWorkspace undistort_ws_;
};

}  // namespace cv_adapter
}  // namespace dyncull
