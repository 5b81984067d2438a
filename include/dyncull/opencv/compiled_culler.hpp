/// @file compiled_culler.hpp
/// Host-facing header of the compiled culler (library target dyncull::culler): the OpenCV culler of
/// opencv/culler.hpp (the recommended pipeline of Zhu et al. 2024, DLD-SLAM 2024 and DFD-SLAM 2024 against
/// a keyframe matched as in Mur-Artal, Montiel & Tardos 2015) compiled once, behind a C++11 interface that
/// includes only the standard library and opencv2/core.hpp, so C++11 / C++14 front ends (ORB-SLAM2/3)
/// include it without changing their standard and without compiling the templated pipeline.
///
/// API:
///   dyncull::cv_adapter::CompiledCuller culler(K, cv::Size(640, 480), dist_coeffs);  // check culler.ok()
///   const std::vector<std::uint8_t>& keep = culler.cull(keys, descriptors, depth, boxes, &Tcw);
///   dyncull::cv_adapter::CompiledCuller::compact(keep, descriptors, keys, keys_un);    // returns the new N
#pragma once

#include <opencv2/core.hpp>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

namespace dyncull {
namespace cv_adapter {

/// One detector box after NMS: corners in pixels, [x0, x1] x [y0, y1] inclusive with pixel centres at
/// integers (dyncull's Box), a class id (COCO-80 index by default) and a score.
struct DetectedBox {
  float x0, y0, x1, y1;
  int class_id;
  float confidence;

  DetectedBox() : x0(0.f), y0(0.f), x1(0.f), y1(0.f), class_id(-1), confidence(1.f) {}
  DetectedBox(float x0_, float y0_, float x1_, float y1_, int class_id_, float confidence_ = 1.f)
      : x0(x0_), y0(y0_), x1(x1_), y1(y1_), class_id(class_id_), confidence(confidence_) {}
  /// A detector's cv::Rect2f (x, y, width, height): x1 = x + width, y1 = y + height.
  DetectedBox(const cv::Rect2f& r, int class_id_, float confidence_ = 1.f)
      : x0(r.x), y0(r.y), x1(r.x + r.width), y1(r.y + r.height), class_id(class_id_), confidence(confidence_) {}
};

/// One camera stream's culler, compiled into dyncull::culler (float geometry). Not thread-safe; movable,
/// not copyable. Same per-frame behaviour as cv_adapter::FrameCuller (it runs one): the same input gives
/// the same keep mask, labels, status and reason.
class CompiledCuller {
 public:
  /// Same values and meanings as dyncull::Status.
  enum class Status : int {
    Ok = 0,
    TooFewPoints,
    Degenerate,
    NonFinite,
    NotConverged,
    InvalidInput,
    Skipped,
    IoError,
    ParseError,
    MissingInput,
  };
  /// Same values as dyncull::FeatureLabel.
  enum class Label : std::uint8_t { Static = 0, Candidate = 1, Dynamic = 2 };
  /// Same values and meanings as dyncull::CullReason: the stage that decided a feature's label.
  enum class Reason : std::uint8_t {
    None = 0,
    HighLevelBox,
    LowLevelOverride,
    MediumLevelBox,
    DepthMask,
    Probability,
    Epipolar,
    SubBox,
    MultiView,
    SurvivorGuardUndo,
    TrackedBox,
    Reprojection,
    CoherentMotion,
    InvalidInput,
  };

  /// What a host chooses; everything else is the preset's.
  struct Options {
    /// dld_slam, rtd_slam, zhu_2024, dfd_slam, zhang_2023, recommended or none (culling/presets.hpp).
    std::string preset;
    /// Raw scale of CV_16U depth images (TUM 5000 per metre, most sensors 1000).
    float depth_units_per_metre;
    /// A new reference keyframe when the predicted pose moved or turned past these from it, or when fewer
    /// than this share of the keypoints matched it.
    double keyframe_max_translation_m;
    double keyframe_max_rotation_deg;
    double keyframe_min_matched_ratio;

    Options()
        : preset("recommended"),
          depth_units_per_metre(5000.f),
          keyframe_max_translation_m(0.1),
          keyframe_max_rotation_deg(15.0),
          keyframe_min_matched_ratio(0.3) {}
  };

  /// Outcome of the last cull(); vectors parallel to its keypoints.
  struct Result {
    /// As dyncull::CullerResult::status. Ok: every enabled stage did its job. MissingInput: the labels are
    /// usable, but an input the configuration reads was missing, keypoints had a NaN or Inf coordinate
    /// (each culled), the descriptor width changed (this frame became the keyframe), or a stage could not
    /// run; the others culled. InvalidInput / NonFinite when an input could not be read, the arrays
    /// disagree in size or the predicted pose is not rigid (nothing culled: every keep is 1). `reason`
    /// names the argument.
    Status status;
    std::string reason;
    bool ok() const { return status == Status::Ok; }
    /// The frame was refused before culling: every keep is 1, no keyframe, no track ids (-1).
    bool refused;

    std::vector<std::uint8_t> keep;  ///< 1 = static: apply to every parallel array of the host
    std::vector<Label> labels;
    std::vector<Reason> reasons;
    std::vector<std::int64_t> track_ids;  ///< the keyframe point's id when matched, else a new id
    std::size_t num_features, num_kept, matched;
    int frames_since_keyframe;  ///< baseline of this frame's evidence (0: no keyframe yet)
    bool keyframe;              ///< this frame became the reference keyframe

    Result() : status(Status::Ok), refused(false), num_features(0), num_kept(0), matched(0), frames_since_keyframe(0), keyframe(false) {}
  };

  /// K: 3x3 CV_32F / CV_64F; distortion: OpenCV's 4, 5, 8, 12 or 14 coefficients, or empty. A bad K,
  /// size, distortion or option makes status() say why and every cull() refuse (keep all).
  CompiledCuller(const cv::Mat& K, cv::Size image_size, const cv::Mat& distortion = cv::Mat(),
                 const Options& options = Options());
  ~CompiledCuller();
  CompiledCuller(CompiledCuller&& other) noexcept;
  CompiledCuller& operator=(CompiledCuller&& other) noexcept;
  CompiledCuller(const CompiledCuller&) = delete;
  CompiledCuller& operator=(const CompiledCuller&) = delete;

  /// InvalidInput naming the argument when K, the size, the distortion or an option is bad (and after
  /// a move from this object: every cull() then keeps all, parallel to its keys).
  Status status() const;
  const std::string& reason() const;
  bool ok() const { return status() == Status::Ok; }

  /// Keep mask parallel to `keys` (1 = static); result() says why. `descriptors`: one CV_8U row per key
  /// (empty: none); `depth`: CV_32F metres or CV_16U raw at the image size (empty: monocular);
  /// `predicted_Tcw`: 4x4 cam_from_world (CV_32F / CV_64F), e.g. the motion model's, or null;
  /// `undistorted`: the host's undistorted copy of keys (ORB-SLAM's mvKeysUn), or null to undistort here
  /// when the camera has distortion.
  const std::vector<std::uint8_t>& cull(const std::vector<cv::KeyPoint>& keys, const cv::Mat& descriptors,
                                        const cv::Mat& depth, const std::vector<DetectedBox>& detections,
                                        const cv::Mat* predicted_Tcw = nullptr,
                                        const std::vector<cv::KeyPoint>* undistorted = nullptr);
  /// The same for cv::Point2f keypoints.
  const std::vector<std::uint8_t>& cull(const std::vector<cv::Point2f>& points, const cv::Mat& descriptors,
                                        const cv::Mat& depth, const std::vector<DetectedBox>& detections,
                                        const cv::Mat* predicted_Tcw = nullptr,
                                        const std::vector<cv::Point2f>* undistorted = nullptr);
  /// The same for `count` points as float pairs: point i's x at xy + i * stride_bytes (0: packed pairs),
  /// y right after it; e.g. a std::vector of Eigen::Vector2f through `&v[0].x()` and sizeof(Eigen::Vector2f).
  const std::vector<std::uint8_t>& cull(const float* xy, std::size_t count, std::size_t stride_bytes,
                                        const cv::Mat& descriptors, const cv::Mat& depth,
                                        const std::vector<DetectedBox>& detections,
                                        const cv::Mat* predicted_Tcw = nullptr);

  /// The last cull()'s result.
  const Result& result() const;
  /// Forgets the keyframe, the tracks and the pipeline's state, as if newly constructed (a new sequence,
  /// or a host that lost track); the camera and options stay.
  void reset();

  static const char* to_string(Status status);
  static const char* to_string(Label label);
  static const char* to_string(Reason reason);

  /// Removes, in place and stably, the features with keep[i] == 0 from the descriptor matrix (one row per
  /// feature) and from every parallel std::vector, then shrinks the matrix to the surviving rows (a
  /// bag-of-words lookup must never read a stale row). Returns the new count; when an array has another
  /// size than keep, or the matrix is not 2-D, nothing is touched and the result is -1.
  template <class... Vectors>
  static long compact(const std::vector<std::uint8_t>& keep, cv::Mat& descriptors, Vectors&... vectors) {
    const std::size_t n = keep.size();
    const std::size_t sizes[] = {n, vectors.size()...};
    for (std::size_t a = 0; a < sizeof(sizes) / sizeof(sizes[0]); ++a)
      if (sizes[a] != n) return -1;
    if (descriptors.dims > 2 || static_cast<std::size_t>(descriptors.rows) != n) return -1;
    std::size_t kept = 0;
    const std::size_t row_bytes = static_cast<std::size_t>(descriptors.cols) * descriptors.elemSize();
    for (std::size_t i = 0; i < n; ++i) {
      if (!keep[i]) continue;
      if (kept != i && row_bytes > 0)
        std::memmove(descriptors.ptr(static_cast<int>(kept)), descriptors.ptr(static_cast<int>(i)), row_bytes);
      ++kept;
    }
    const int expand[] = {0, (compact_vector(keep, vectors), 0)...};
    (void)expand;
    if (n > 0) descriptors = descriptors.rowRange(0, static_cast<int>(kept));
    return static_cast<long>(kept);
  }

 private:
  template <class V>
  static void compact_vector(const std::vector<std::uint8_t>& keep, V& v) {
    std::size_t kept = 0;
    for (std::size_t i = 0; i < keep.size(); ++i) {
      if (!keep[i]) continue;
      if (kept != i) v[kept] = v[i];
      ++kept;
    }
    v.erase(v.begin() + static_cast<std::ptrdiff_t>(kept), v.end());
  }

  struct Impl;
  Impl& impl();  // the moved-from object gets one that refuses every frame
  std::unique_ptr<Impl> impl_;
};

}  // namespace cv_adapter
}  // namespace dyncull
