/// @file culler.hpp
/// The culler: one object per camera stream that takes a frame's keypoints, descriptors, depth, detector
/// boxes and predicted pose and returns which keypoints lie on moving objects. It matches each frame to
/// a reference keyframe (Mur-Artal, Montiel & Tardos 2015, ORB-SLAM §V-B) and runs a preset of the
/// culling pipeline against it (culling/pipeline.hpp: Zhang et al. 2023 box levels, Zhu et al. 2024 depth
/// masks, DLD-SLAM 2024 probability, DFD-SLAM 2024 sub-boxes, RTD-SLAM multi-view). Compiled once into
/// dyncull::culler; this header is C++11 and includes the standard library only.
///
/// API:
/// @code
///   dyncull::CullerCamera camera(fx, fy, cx, cy, 640, 480);        // plus distortion when the lens has it
///   dyncull::check_camera(camera, 5000.0, &why);                     // at start-up: the culler's camera check
///   dyncull::Culler culler(camera, dyncull::CullerOptions("recommended"));   // culler.ok(), culler.reason()
///   dyncull::CullerFrame f;
///   f.keypoints = dyncull::points_view(keys);  f.descriptors = ...;  f.depth_m = ...;  // each optional:
///   f.detections = &boxes;  f.cam_from_world = Tcw;                  // culler.inputs() says what it reads
///   const dyncull::CullerResult& r = culler.cull(f);                 // r.keep[i]: 1 = static
///   dyncull::compact(r.keep, keys, depths);                          // the host's parallel arrays
/// @endcode
/// OpenCV containers: opencv/culler.hpp. The expert entry for hosts that feed their own tracks, 3-D points
/// and ids is cull_frame (culling/pipeline.hpp).
#pragma once

#include "dyncull/core/camera_bounds.hpp"
#include "dyncull/core/compact.hpp"
#include "dyncull/core/depth.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/core/views.hpp"
#include "dyncull/culling/labels.hpp"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace dyncull {

/// Pinhole intrinsics of the image the keypoints were detected in, in pixels, and the lens distortion in
/// OpenCV's order (k1, k2, p1, p2[, k3[, k4, k5, k6[, s1..s4[, tx, ty]]]]): 4, 5, 8, 12 or 14 values, or
/// none. There are no default intrinsics: a zero focal length is refused.
struct CullerCamera {
  double fx, fy, cx, cy;
  int width, height;
  std::vector<double> distortion;

  CullerCamera() : fx(0), fy(0), cx(0), cy(0), width(0), height(0) {}
  CullerCamera(double fx_, double fy_, double cx_, double cy_, int width_, int height_,
               std::vector<double> distortion_ = std::vector<double>())
      : fx(fx_), fy(fy_), cx(cx_), cy(cy_), width(width_), height(height_), distortion(distortion_) {}
  /// A coefficient is non-zero: the geometry needs undistorted keypoints.
  bool has_distortion() const {
    for (std::size_t i = 0; i < distortion.size(); ++i)
      if (distortion[i] != 0.0) return true;
    return false;
  }
};

/// The camera check of core/camera_bounds.hpp on a CullerCamera and a depth scale (raw units per metre;
/// 1 when the host has no depth): what the culler refuses a camera for, for a host to check its settings
/// once at start-up. Ok, or InvalidInput with the first reason.
inline Status check_camera(const CullerCamera& camera, double depth_units_per_metre, std::string* reason = nullptr) {
  return check_camera(camera.fx, camera.fy, camera.cx, camera.cy, camera.width, camera.height,
                      camera.distortion.empty() ? nullptr : &camera.distortion[0],
                      camera.distortion.size(), depth_units_per_metre, reason);
}

/// Who decides when the current frame becomes the reference keyframe.
enum class KeyframePolicy : std::uint8_t {
  Own = 0,  ///< the culler: pose moved or turned far, too few keypoints matched the keyframe, or it has none
  Host,     ///< the host sets CullerFrame::is_keyframe (its own keyframes); the first frame always is one
};

/// What the culler does, as a preset plus the settings a host tunes. `CullerOptions(name)` fills every
/// setting with the preset's value; change the ones you need. Everything else is fixed by the preset
/// (docs/algorithms.md lists the presets and the evidence for their constants). Distances are in pixels
/// of the undistorted image or metres; each setting says its range.
class CullerOptions {
 public:
  /// recommended, dld_slam, rtd_slam, zhu_2024, dfd_slam, zhang_2023 or none. An unknown name keeps the
  /// recommended values and validate() says so.
  explicit CullerOptions(const std::string& preset = "recommended");
  const std::string& preset() const { return preset_; }

  // --- keyframe: the baseline the evidence is measured over ---
  KeyframePolicy keyframe_policy;
  /// Own policy: a new keyframe when the predicted pose moved more than this from the keyframe's, in
  /// (0, 1e4] m. Longer baselines show slow movers, shorter ones keep more keypoints matched.
  double keyframe_max_translation_m;
  double keyframe_max_rotation_deg;  ///< ... or turned more than this, in (0, 180]
  /// ... or fewer than this share of the keypoints matched the keyframe's, in [0, 1]. A detector that
  /// re-detects every frame matches about half of them a frame later; a host that keeps tracks between
  /// its own keyframes matches fewer of the culler's keyframe: about 0.6 suits it.
  double keyframe_min_matched_ratio;

  // --- depth ---
  /// Raw units per metre of 16-bit depth images the OpenCV overload reads (TUM 5000, most sensors 1000),
  /// in [1e-3, 1e6]. A plain DepthView carries its own.
  double depth_units_per_metre;
  /// The depth sensor's reliable range for the keyframe's 3-D points, in metres (min >= 0, max above it).
  double min_depth_m, max_depth_m;

  // --- matching to the keyframe (binary descriptors) ---
  /// Search radius around a keypoint's predicted position, in (0, 4096] px: the prediction's error plus
  /// keypoint noise (ORB-SLAM2 searches 15 px).
  double match_radius_px;
  /// Largest Hamming distance of a match, in bits, in [0, 2048] (at most the descriptor's bits).
  int match_max_hamming;

  // --- detector boxes ---
  double box_padding_px;         ///< grown on each side: detectors cut limbs; in [0, 1e4] px
  double min_box_confidence;     ///< boxes scoring lower are dropped, in [0, 1]
  double min_person_confidence;  ///< the same for class 0 (people are the movers that matter), in [0, 1]
  /// Class ids (COCO-80 by default) by how they move (Zhang et al. 2023): high-level boxes are culled,
  /// medium-level ones only on evidence of their own motion, low-level ones shelter their features from
  /// the other boxes. A class in no list is ignored.
  std::vector<int> high_level_classes, medium_level_classes, low_level_classes;
  /// Frames a box the detector missed is carried forward at its velocity, in [0, 1000].
  int box_memory_frames;

  // --- geometric evidence ---
  /// Epipolar distance above which a track is moving (DS-SLAM's 1 px), outside boxes and inside them,
  /// in (0, 1e4] px.
  double max_epipolar_distance_px, max_epipolar_distance_in_boxes_px;
  /// Reprojection residual of a keyframe point at the PnP pose above which it moved, outside boxes and
  /// inside them, in (0, 1e4] px.
  double max_reprojection_px, max_reprojection_in_boxes_px;
  /// Depth residual, in multiples of the sensor's axial noise at that depth, above which a point moved
  /// along the ray; 0 turns the depth test off; in [0, 1e4].
  double max_depth_residual_sigmas;
  /// Depth band of an object behind its box's nearest surface (Zhu et al. 2024's epsilon), in [0, 1e4] m.
  double object_depth_band_m;
  /// A sub-box is dynamic when at least this share of its evidence is (DFD-SLAM's sigma1), in [0, 1].
  double subbox_dynamic_ratio;
  /// More dynamic sub-boxes than this make the whole box dynamic (DFD-SLAM's sigma2), in [0, 64].
  int whole_box_min_dynamic_cells;
  /// A track static this many frames, with a residual below max_residual, is kept against a region's
  /// cull; frames in [1, 1e6], residual in [0, 1e4] px.
  int static_history_min_frames;
  double static_history_max_residual_px;
  /// RTD-SLAM's multi-view check: depth difference that marks a point dynamic, in (0, 1e4] m, and the
  /// largest viewing-angle difference checked, in (0, 180] degrees.
  double multiview_depth_threshold_m, multiview_max_parallax_deg;
  /// DLD-SLAM's dynamic probability above which a feature is culled, in [0, 1].
  double probability_threshold;

  // --- survivor guard: never leave the tracker too little ---
  /// When culling would leave fewer than max(min_survivors, min_survivor_fraction * n) features, the
  /// softest culls are undone (ORB-SLAM loses tracking below about 30 inliers).
  std::size_t min_survivors;
  double min_survivor_fraction;  ///< in [0, 1]

  /// Ok, or InvalidInput with the reason naming the setting.
  Status validate(std::string* reason = nullptr) const;

 private:
  std::string preset_;
};

/// One detector box after NMS: corners in pixels of the image as detected, [x0, x1] x [y0, y1] with pixel
/// centres at integers, a class id (COCO-80 by default) and a score in [0, 1].
struct DetectedBox {
  float x0, y0, x1, y1;
  int class_id;
  float confidence;

  DetectedBox() : x0(0.f), y0(0.f), x1(0.f), y1(0.f), class_id(-1), confidence(1.f) {}
  DetectedBox(float x0_, float y0_, float x1_, float y1_, int class_id_, float confidence_ = 1.f)
      : x0(x0_), y0(y0_), x1(x1_), y1(y1_), class_id(class_id_), confidence(confidence_) {}
};

/// One frame as the host has it: views it keeps valid during Culler::cull. Per-keypoint inputs are
/// parallel to `keypoints`; every input but the keypoints is optional (Culler::inputs says which the
/// options read; a frame lacking one is culled by the stages that can run, and the status says so).
struct CullerFrame {
  PointsView keypoints;              ///< pixels as detected (where the boxes are)
  PointsView undistorted_keypoints;  ///< the host's undistorted copy (ORB-SLAM's mvKeysUn); absent: undistorted here
  DescriptorRows descriptors;        ///< one binary row per keypoint (data null: not given)
  DepthView<float> depth_m;          ///< depth in metres, or ...
  DepthView<std::uint16_t> depth_raw;  ///< ... raw 16-bit with its units_per_metre; neither: monocular
  const std::vector<DetectedBox>* detections;  ///< boxes after NMS (empty: none seen; null: no detector)
  /// Predicted cam_from_world as 12 doubles, row-major [R | t] (a motion model is enough); null: none.
  const double* cam_from_world;
  /// The host's correspondences: per keypoint the index of its match among the keypoints of the culler's
  /// keyframe (the frame CullerResult::keyframe last reported), -1 for none. Given: no own matching.
  const int* keyframe_match;
  bool is_keyframe;  ///< KeyframePolicy::Host: this frame becomes the reference after culling

  CullerFrame() : detections(nullptr), cam_from_world(nullptr), keyframe_match(nullptr), is_keyframe(false) {}
};

/// Which inputs the options read (Culler::inputs) or a frame lacked (CullerResult::missing).
struct CullerInputs {
  bool keypoints, descriptors, depth, detections, pose;

  CullerInputs() : keypoints(false), descriptors(false), depth(false), detections(false), pose(false) {}
  bool any() const { return keypoints || descriptors || depth || detections || pose; }
  /// Comma-separated names, e.g. "keypoints, descriptors, depth".
  std::string names() const {
    std::string s;
    const bool on[] = {keypoints, descriptors, depth, detections, pose};
    const char* name[] = {"keypoints", "descriptors", "depth", "detections", "pose"};
    for (int k = 0; k < 5; ++k) {
      if (!on[k]) continue;
      if (!s.empty()) s += ", ";
      s += name[k];
    }
    return s;
  }
};

/// Outcome of one frame; vectors parallel to the frame's keypoints.
struct CullerResult {
  /// Ok: every stage the options enable did its job. MissingInput: the labels are usable, but part of
  /// the input was missing or unusable, named in `reason`: an input the options read (`missing`),
  /// keypoints with a NaN or Inf coordinate (each culled, reason InvalidInput), a descriptor width other
  /// than the keyframe's (this frame becomes the keyframe), or a stage that could not run (the first
  /// frame has no keyframe); the stages that could run culled. Another status from the pipeline (a stage
  /// that could not do its job) is passed on with the labels of the stages that ran.
  /// refused: InvalidInput or NonFinite before culling (an input cannot be read, arrays disagree in size,
  /// the pose is not rigid, the camera or options are bad); nothing culled, every keep is 1.
  Status status;
  std::string reason;
  bool ok() const { return status == Status::Ok; }
  bool refused;  ///< the frame was refused before culling: every keep 1, no keyframe, track ids -1

  std::vector<std::uint8_t> keep;       ///< 1 = static: apply to every parallel array of the host (compact)
  std::vector<FeatureLabel> labels;     ///< Static or Dynamic
  std::vector<CullReason> reasons;      ///< deciding stage (None for untouched statics)
  std::vector<std::int64_t> track_ids;  ///< the keyframe point's id when matched, else a new id
  std::size_t num_features, num_kept;
  std::size_t matched;        ///< keypoints matched to the keyframe
  int frames_since_keyframe;  ///< baseline of this frame's evidence (0: no keyframe yet)
  bool keyframe;              ///< this frame became the reference keyframe
  CullerInputs missing;       ///< inputs the options read that this frame lacked

  CullerResult()
      : status(Status::Ok), refused(false), num_features(0), num_kept(0), matched(0), frames_since_keyframe(0),
        keyframe(false) {}
};

/// One camera stream's culler. Not thread-safe; movable, not copyable. A bad camera or bad options make
/// status() say why at once and every cull() refuse (keep all).
class Culler {
 public:
  explicit Culler(const CullerCamera& camera, const CullerOptions& options = CullerOptions());
  ~Culler();
  Culler(Culler&& other) noexcept;
  Culler& operator=(Culler&& other) noexcept;
  Culler(const Culler&) = delete;
  Culler& operator=(const Culler&) = delete;

  Status status() const;
  const std::string& reason() const;
  bool ok() const { return status() == Status::Ok; }
  const CullerOptions& options() const;
  const CullerCamera& camera() const;
  /// The inputs the options read; a frame lacking one gets MissingInput naming it.
  CullerInputs inputs() const;

  /// Culls one frame and, when the keyframe policy says so, makes it the reference keyframe. The result
  /// is valid until the next call.
  const CullerResult& cull(const CullerFrame& frame);
  /// Reports a frame of `n` keypoints as refused with `status` and `why` (every keep 1, nothing culled,
  /// no keyframe), as cull() does for an input it cannot read: for adapters that read their own
  /// containers first (opencv/culler.hpp), so their refusals match cull()'s field for field.
  const CullerResult& refuse(Status status, const std::string& why, std::size_t n);
  /// The last cull()'s result.
  const CullerResult& result() const;
  /// Forgets the keyframe, the tracks and the pipeline's state, as if newly constructed (a new sequence,
  /// or a host that lost track or restarted its map); the camera and options stay.
  void reset();
  /// Keypoints in the reference keyframe, the range CullerFrame::keyframe_match indexes (0: none yet).
  std::size_t keyframe_size() const;

 private:
  struct Impl;
  Impl& impl();  // a moved-from culler gets one that refuses every frame
  std::unique_ptr<Impl> impl_;
};

}  // namespace dyncull
