// dyncull::Culler (culling/culler.hpp): CullerCore<float> behind the C++11 header. The public settings are
// laid over the named preset by bind_settings (culling/culler_core.hpp); boxes and the pose are converted
// into the core's types in reused buffers; keypoints of a distorted camera are undistorted here
// (cv::undistortPoints, Brown-Conrady) when the host gives no undistorted copy.
#include "dyncull/culling/culler.hpp"

#include "dyncull/core/text.hpp"
#include "dyncull/culling/culler_core.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

namespace dyncull {

namespace {

const char* const kPresetNames = "recommended, dld_slam, rtd_slam, zhu_2024, dfd_slam, zhang_2023, none";

/// Names the first setting outside its range.
struct RangeCheck {
  std::string* why;
  template <class P, class C>
  void operator()(const char* name, const P& value, const C&, double low, double high, bool low_open) const {
    const double v = static_cast<double>(value);
    if (!why->empty() || (std::isfinite(v) && v <= high && (low_open ? v > low : v >= low))) return;
    *why = std::string(name) + " is " + culler_checks::number(v) + ", outside " + (low_open ? "(" : "[") +
           culler_checks::number(low) + ", " + culler_checks::number(high) + "]";
  }
};

Status check_class_lists(const CullerOptions& o, std::string* why) {
  constexpr int kMaxClassId = 9999;
  std::vector<char> seen;
  const std::vector<int>* lists[] = {&o.high_level_classes, &o.medium_level_classes, &o.low_level_classes};
  const char* names[] = {"high_level_classes", "medium_level_classes", "low_level_classes"};
  for (int l = 0; l < 3; ++l)
    for (int id : *lists[l]) {
      if (id < 0 || id > kMaxClassId)
        return (*why = std::string(names[l]) + " holds " + std::to_string(id) + ", outside [0, 9999]",
                Status::InvalidInput);
      if (seen.size() <= static_cast<std::size_t>(id)) seen.resize(static_cast<std::size_t>(id) + 1, 0);
      if (seen[static_cast<std::size_t>(id)]++)
        return (*why = "class " + std::to_string(id) + " is in two level lists (" + names[l] + " and another)",
                Status::InvalidInput);
    }
  return Status::Ok;
}

PinholeCamera<float> pinhole_of(const CullerCamera& c) {
  return PinholeCamera<float>{static_cast<float>(c.fx), static_cast<float>(c.fy), static_cast<float>(c.cx),
                              static_cast<float>(c.cy), c.width, c.height};
}

// The camera check every entry shares (core/camera_bounds.hpp): distortion first, as before, then the intrinsics.
Status camera_problem(const CullerCamera& c, std::string* why) {
  std::string w;
  if (check_distortion(c.distortion.data(), c.distortion.size(), &w) != Status::Ok)
    return (*why = "camera: " + w, Status::InvalidInput);
  if (pinhole_of(c).validate(&w) != Status::Ok) return (*why = "camera: " + w + " (no default intrinsics)", Status::InvalidInput);
  return Status::Ok;
}

}  // namespace

CullerOptions::CullerOptions(const std::string& preset)
    : keyframe_policy(KeyframePolicy::Own), depth_units_per_metre(5000.0), preset_(preset) {
  // In double: a preset's decimal values then reach CullerCore<float> and <double> rounded once.
  CullerCoreOptions<double> core;
  preset_by_name(preset, &core.pipeline);
  settings_from_core(core, this);
}

Status CullerOptions::validate(std::string* reason) const {
  std::string why;
  PipelineOptions<float> probe;
  if (!preset_by_name(preset_, &probe))
    why = "preset " + text::quote_token(preset_) + " is not one of " + kPresetNames;
  CullerOptions pub = *this;
  CullerCoreOptions<float> unused;
  if (why.empty()) bind_settings<float>(pub, unused, RangeCheck{&why});
  if (why.empty() && static_cast<int>(keyframe_policy) > 1) why = "keyframe_policy must be Own or Host";
  if (why.empty() && !(depth_units_per_metre >= 1e-3 && depth_units_per_metre <= 1e6))
    why = "depth_units_per_metre is " + culler_checks::number(depth_units_per_metre) +
          ", outside [1e-3, 1e6] (metres: 1, millimetres: 1000, TUM: 5000)";
  if (why.empty() && !(max_depth_m > min_depth_m)) why = "max_depth_m must be above min_depth_m";
  if (why.empty()) check_class_lists(*this, &why);
  // The core's own checks (relations between its settings) back these up.
  if (why.empty() && core_options<float>(*this).validate(&why) != Status::Ok && why.empty()) why = "invalid";
  if (reason) *reason = why.empty() ? std::string() : "CullerOptions: " + why;
  return why.empty() ? Status::Ok : Status::InvalidInput;
}

struct Culler::Impl {
  Impl(const CullerCamera& camera_, const CullerOptions& options_)
      : camera(camera_), options(options_), core(pinhole_of(camera_), core_of(camera_, options_)) {
    if (camera_problem(camera, &reason) != Status::Ok) {
      status = Status::InvalidInput;
    } else if (options.validate(&reason) != Status::Ok) {
      status = Status::InvalidInput;
    } else {
      status = core.status();
      reason = core.reason();
    }
    if (camera.has_distortion() && status == Status::Ok) {
      K = (cv::Mat_<double>(3, 3) << camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1);
      distortion = cv::Mat(camera.distortion, true);
    }
  }

  static CullerCoreOptions<float> core_of(const CullerCamera& camera, const CullerOptions& options) {
    CullerCoreOptions<float> o = core_options<float>(options);
    o.camera_has_distortion = camera.has_distortion();
    return o;
  }

  const CullerResult& cull(const CullerFrame& f) {
    const std::size_t n = f.keypoints.given ? f.keypoints.count : 0;
    if (status != Status::Ok) return core.refuse_frame(status, reason, n);
    CullerCoreFrame<float> c;
    c.keypoints = f.keypoints;
    c.undistorted_keypoints = f.undistorted_keypoints;
    c.descriptors = f.descriptors;
    c.depth_m = f.depth_m;
    c.depth_raw = f.depth_raw;
    c.keyframe_match = f.keyframe_match;
    c.is_keyframe = f.is_keyframe;
    if (f.detections) {
      read_boxes(*f.detections);
      c.detections = &detections;
    }
    std::string why;
    if (f.cam_from_world) {
      const Status s = read_pose(f.cam_from_world, &why);
      if (s != Status::Ok) return core.refuse_frame(s, why, n);
      c.cam_from_world = &pose;
    }
    if (!f.undistorted_keypoints.given && camera.has_distortion() && f.keypoints.given) {
      const Status s = undistort(f.keypoints, &why);
      if (s != Status::Ok) return core.refuse_frame(s, why, n);
      c.undistorted_keypoints = PointsView::of(undistorted.data(), n);
    }
    return core.cull(c);
  }

  void read_boxes(const std::vector<DetectedBox>& boxes) {
    detections.resize(boxes.size());
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      const DetectedBox& b = boxes[i];
      detections[i].box = Box<float>{b.x0, b.y0, b.x1, b.y1};
      detections[i].class_id = b.class_id;
      detections[i].confidence = b.confidence;
    }
  }

  /// The pose checked in double (finite, in range, rigid) before its conversion to float.
  Status read_pose(const double* Rt, std::string* why) {
    const double R[9] = {Rt[0], Rt[1], Rt[2], Rt[4], Rt[5], Rt[6], Rt[8], Rt[9], Rt[10]};
    const double t[3] = {Rt[3], Rt[7], Rt[11]};
    const Status s = culler_checks::check_pose(R, t, "cam_from_world", why);
    if (s != Status::Ok) return s;
    for (int r = 0; r < 3; ++r) {
      for (int k = 0; k < 3; ++k) pose.R(r, k) = static_cast<float>(R[3 * r + k]);
      pose.t(r) = static_cast<float>(t[r]);
    }
    return Status::Ok;
  }

  /// Keypoints through the lens model into `undistorted` (pixels of the undistorted image); a NaN or Inf
  /// keypoint stays NaN there and the core culls it.
  Status undistort(const PointsView& keys, std::string* why) {
    const Status s = culler_checks::check_points(keys, "keypoints", why);
    if (s != Status::Ok) return s;
    const std::size_t n = keys.count;
    undistorted.resize(2 * n);
    for (std::size_t i = 0; i < n; ++i) {
      undistorted[2 * i] = static_cast<float>(keys.x(i));
      undistorted[2 * i + 1] = static_cast<float>(keys.y(i));
    }
    if (n == 0) return Status::Ok;
    cv::Mat points(static_cast<int>(n), 1, CV_32FC2, undistorted.data());
    cv::undistortPoints(points, undistorted_out, K, distortion, cv::noArray(), K);
    for (std::size_t i = 0; i < n; ++i) {
      const cv::Point2f p = undistorted_out.at<cv::Point2f>(static_cast<int>(i));
      const bool finite = std::isfinite(undistorted[2 * i]) && std::isfinite(undistorted[2 * i + 1]);
      undistorted[2 * i] = finite ? p.x : undistorted[2 * i];
      undistorted[2 * i + 1] = finite ? p.y : undistorted[2 * i + 1];
    }
    return Status::Ok;
  }

  CullerCamera camera;
  CullerOptions options;
  CullerCore<float> core;
  Status status = Status::Ok;
  std::string reason;
  std::vector<Detection<float>> detections;
  Rigid3<float> pose;
  cv::Mat K, distortion, undistorted_out;
  std::vector<float> undistorted;
};

Culler::Culler(const CullerCamera& camera, const CullerOptions& options) : impl_(new Impl(camera, options)) {}
Culler::~Culler() = default;
Culler::Culler(Culler&& other) noexcept = default;
Culler& Culler::operator=(Culler&& other) noexcept = default;

namespace {
const std::string& moved_from_reason() {
  static const std::string why = "Culler: used after being moved from";
  return why;
}
}  // namespace

Culler::Impl& Culler::impl() {
  if (!impl_) {
    // Moved from: a culler without a camera that refuses every frame, so the keep mask stays parallel
    // to the keypoints.
    impl_.reset(new Impl(CullerCamera(), CullerOptions()));
    impl_->status = Status::InvalidInput;
    impl_->reason = moved_from_reason();
  }
  return *impl_;
}

Status Culler::status() const { return impl_ ? impl_->status : Status::InvalidInput; }
const std::string& Culler::reason() const { return impl_ ? impl_->reason : moved_from_reason(); }
const CullerOptions& Culler::options() const { return const_cast<Culler*>(this)->impl().options; }
const CullerCamera& Culler::camera() const { return const_cast<Culler*>(this)->impl().camera; }
CullerInputs Culler::inputs() const { return impl_ ? impl_->core.inputs() : CullerInputs(); }
const CullerResult& Culler::cull(const CullerFrame& frame) { return impl().cull(frame); }
const CullerResult& Culler::refuse(Status status, const std::string& why, std::size_t n) {
  return impl().core.refuse_frame(status, why, n);
}
const CullerResult& Culler::result() const { return const_cast<Culler*>(this)->impl().core.result(); }
void Culler::reset() {
  if (impl_) impl_->core.reset();
}
std::size_t Culler::keyframe_size() const { return impl_ ? impl_->core.keyframe_keypoints().size() : 0; }

}  // namespace dyncull
