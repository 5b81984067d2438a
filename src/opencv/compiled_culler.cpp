// The compiled culler (opencv/compiled_culler.hpp): cv_adapter::FrameCuller instantiated once for float,
// behind the C++11 interface. cv::Point2f and float-pair keypoints are copied into a reused cv::KeyPoint
// buffer (the culler reads positions only), so all three overloads run the same compiled code.
#include "dyncull/opencv/compiled_culler.hpp"

#include "dyncull/core/text.hpp"
#include "dyncull/culling/presets.hpp"
#include "dyncull/opencv/culler.hpp"

#include <cmath>
#include <cstring>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace dyncull {
namespace cv_adapter {

namespace {

using Compiled = CompiledCuller;

// The mirrored enums must stay those of the templated culler: results are converted by value.
static_assert(static_cast<int>(Compiled::Status::MissingInput) == static_cast<int>(Status::MissingInput) &&
                  static_cast<int>(Compiled::Status::InvalidInput) == static_cast<int>(Status::InvalidInput) &&
                  static_cast<int>(Compiled::Status::NonFinite) == static_cast<int>(Status::NonFinite),
              "CompiledCuller::Status must mirror dyncull::Status");
static_assert(static_cast<int>(Compiled::Label::Dynamic) == static_cast<int>(FeatureLabel::Dynamic) &&
                  static_cast<int>(Compiled::Label::Candidate) == static_cast<int>(FeatureLabel::Candidate),
              "CompiledCuller::Label must mirror dyncull::FeatureLabel");
static_assert(static_cast<int>(Compiled::Reason::InvalidInput) == static_cast<int>(CullReason::InvalidInput) &&
                  static_cast<int>(Compiled::Reason::CoherentMotion) == static_cast<int>(CullReason::CoherentMotion) &&
                  static_cast<int>(Compiled::Reason::TrackedBox) == static_cast<int>(CullReason::TrackedBox),
              "CompiledCuller::Reason must mirror dyncull::CullReason");
static_assert(sizeof(Compiled::Label) == sizeof(FeatureLabel) && sizeof(Compiled::Reason) == sizeof(CullReason),
              "label and reason enums must have the templated culler's size");

bool preset_by_name(const std::string& name, PipelineOptions<float>* out) {
  if (name == "recommended") *out = presets::recommended<float>();
  else if (name == "none") *out = presets::none<float>();
  else if (name == "dld_slam") *out = presets::dld_slam<float>();
  else if (name == "rtd_slam") *out = presets::rtd_slam<float>();
  else if (name == "zhu_2024") *out = presets::zhu_2024<float>();
  else if (name == "dfd_slam") *out = presets::dfd_slam<float>();
  else if (name == "zhang_2023") *out = presets::zhang_2023<float>();
  else return false;
  return true;
}

CullerOptions<float> culler_options(const Compiled::Options& o, bool* preset_known) {
  CullerOptions<float> c;
  *preset_known = preset_by_name(o.preset, &c.pipeline);
  c.keyframe_max_translation_m = o.keyframe_max_translation_m;
  c.keyframe_max_rotation_deg = o.keyframe_max_rotation_deg;
  c.keyframe_min_matched_ratio = o.keyframe_min_matched_ratio;
  return c;
}

template <class To, class From>
void convert_all(const std::vector<From>& in, std::vector<To>* out) {
  out->resize(in.size());
  for (std::size_t i = 0; i < in.size(); ++i) (*out)[i] = static_cast<To>(in[i]);
}

}  // namespace

struct CompiledCuller::Impl {
  Impl(const cv::Mat& K, cv::Size size, const cv::Mat& distortion, const Options& options, bool* preset_known)
      : culler(K, size, distortion, culler_options(options, preset_known), options.depth_units_per_metre) {}

  FrameCuller culler;
  Status status = Status::Ok;
  std::string reason;
  Result result;
  std::vector<Detection<float>> detections;
  std::vector<cv::KeyPoint> keys, undistorted;

  // Every refusal goes through the templated culler's, so that all forms fill the result alike.
  const std::vector<std::uint8_t>& refuse(Status s, const std::string& why, std::size_t n) {
    culler.culler().refuse_frame(static_cast<dyncull::Status>(static_cast<int>(s)), why, n);
    return take_result();
  }

  const std::vector<std::uint8_t>& take_result() {
    const CullerResult& r = culler.result();
    result.status = static_cast<Status>(static_cast<int>(r.status));
    result.reason = r.reason;
    result.refused = r.refused;
    result.keep = r.keep;
    convert_all(r.labels, &result.labels);
    convert_all(r.reasons, &result.reasons);
    result.track_ids = r.track_ids;
    result.num_features = r.num_features;
    result.num_kept = r.num_kept;
    result.matched = r.matched;
    result.frames_since_keyframe = r.frames_since_keyframe;
    result.keyframe = r.keyframe;
    return result.keep;
  }

  const std::vector<std::uint8_t>& cull(const std::vector<cv::KeyPoint>& k, const cv::Mat& descriptors,
                                        const cv::Mat& depth, const std::vector<DetectedBox>& boxes,
                                        const cv::Mat* Tcw, const std::vector<cv::KeyPoint>* und) {
    if (status != Status::Ok) return refuse(status, reason, k.size());
    detections.resize(boxes.size());
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      const DetectedBox& b = boxes[i];
      detections[i].box = Box<float>{b.x0, b.y0, b.x1, b.y1};
      detections[i].class_id = b.class_id;
      detections[i].confidence = b.confidence;
    }
    culler.cull(k, descriptors, depth, detections, Tcw, und);
    return take_result();
  }
};

CompiledCuller::CompiledCuller(const cv::Mat& K, cv::Size image_size, const cv::Mat& distortion,
                               const Options& options) {
  bool preset_known = true;
  impl_.reset(new Impl(K, image_size, distortion, options, &preset_known));
  if (!impl_->culler.ok()) {
    impl_->status = static_cast<Status>(static_cast<int>(impl_->culler.status()));
    impl_->reason = impl_->culler.reason();
  } else if (!preset_known) {
    impl_->status = Status::InvalidInput;
    impl_->reason = "Options::preset " + text::quote_token(options.preset) +
                    " is not one of none, dld_slam, rtd_slam, zhu_2024, dfd_slam, zhang_2023, recommended";
  }
}

CompiledCuller::~CompiledCuller() = default;
CompiledCuller::CompiledCuller(CompiledCuller&& other) noexcept = default;
CompiledCuller& CompiledCuller::operator=(CompiledCuller&& other) noexcept = default;

namespace {
const std::string& moved_from_reason() {
  static const std::string why = "CompiledCuller: used after being moved from";
  return why;
}
const CompiledCuller::Result& moved_from_result() {
  static const CompiledCuller::Result r = [] {
    CompiledCuller::Result x;
    x.status = CompiledCuller::Status::InvalidInput;
    x.reason = moved_from_reason();
    x.refused = true;
    return x;
  }();
  return r;
}
}  // namespace

CompiledCuller::Status CompiledCuller::status() const { return impl_ ? impl_->status : Status::InvalidInput; }
const std::string& CompiledCuller::reason() const { return impl_ ? impl_->reason : moved_from_reason(); }
const CompiledCuller::Result& CompiledCuller::result() const { return impl_ ? impl_->result : moved_from_result(); }

void CompiledCuller::reset() {
  if (impl_) impl_->culler.reset();
}

CompiledCuller::Impl& CompiledCuller::impl() {
  if (!impl_) {
    // Moved from: a culler without a camera that refuses every frame, so that the keep mask stays
    // parallel to the keys.
    bool preset_known = true;
    impl_.reset(new Impl(cv::Mat(), cv::Size(), cv::Mat(), Options(), &preset_known));
    impl_->status = Status::InvalidInput;
    impl_->reason = moved_from_reason();
  }
  return *impl_;
}

const std::vector<std::uint8_t>& CompiledCuller::cull(const std::vector<cv::KeyPoint>& keys, const cv::Mat& descriptors,
                                                      const cv::Mat& depth, const std::vector<DetectedBox>& detections,
                                                      const cv::Mat* predicted_Tcw,
                                                      const std::vector<cv::KeyPoint>* undistorted) {
  return impl().cull(keys, descriptors, depth, detections, predicted_Tcw, undistorted);
}

const std::vector<std::uint8_t>& CompiledCuller::cull(const std::vector<cv::Point2f>& points,
                                                      const cv::Mat& descriptors, const cv::Mat& depth,
                                                      const std::vector<DetectedBox>& detections,
                                                      const cv::Mat* predicted_Tcw,
                                                      const std::vector<cv::Point2f>* undistorted) {
  Impl& m = impl();
  m.keys.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) m.keys[i].pt = points[i];
  if (undistorted) {
    m.undistorted.resize(undistorted->size());
    for (std::size_t i = 0; i < undistorted->size(); ++i) m.undistorted[i].pt = (*undistorted)[i];
  }
  return m.cull(m.keys, descriptors, depth, detections, predicted_Tcw, undistorted ? &m.undistorted : nullptr);
}

const std::vector<std::uint8_t>& CompiledCuller::cull(const float* xy, std::size_t count, std::size_t stride_bytes,
                                                      const cv::Mat& descriptors, const cv::Mat& depth,
                                                      const std::vector<DetectedBox>& detections,
                                                      const cv::Mat* predicted_Tcw) {
  Impl& m = impl();
  if (m.status != Status::Ok) return m.refuse(m.status, m.reason, count);
  const PointsView view = PointsView::of(xy, count, stride_bytes);
  std::string why;
  const dyncull::Status s = culler_checks::check_points(view, "keypoints", &why);
  if (s != dyncull::Status::Ok) return m.refuse(static_cast<Status>(static_cast<int>(s)), why, count);
  m.keys.resize(count);
  for (std::size_t i = 0; i < count; ++i)
    m.keys[i].pt = cv::Point2f(static_cast<float>(view.x(i)), static_cast<float>(view.y(i)));
  return m.cull(m.keys, descriptors, depth, detections, predicted_Tcw, nullptr);
}

const char* CompiledCuller::to_string(Status status) {
  return dyncull::to_string(static_cast<dyncull::Status>(static_cast<int>(status)));
}
const char* CompiledCuller::to_string(Label label) {
  return dyncull::to_string(static_cast<FeatureLabel>(static_cast<int>(label)));
}
const char* CompiledCuller::to_string(Reason reason) {
  return dyncull::to_string(static_cast<CullReason>(static_cast<int>(reason)));
}

}  // namespace cv_adapter
}  // namespace dyncull
