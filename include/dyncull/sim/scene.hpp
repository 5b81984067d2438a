/// @file scene.hpp
/// Deterministic synthetic dynamic RGB-D sequence (TUM fr3 walking-like): CPU ray casting of the
/// room and actors of actors.hpp, with ground-truth pose, depth, instance ids, per-pixel "moving"
/// truth (and how far it moved) and noisy detections, so culling and SLAM claims are measured without
/// downloads. The Calibrated detector model imitates YOLOv8n (Jocher et al. 2023) on TUM fr3 (Sturm et
/// al. 2012): heavy-tailed box edges, one-frame dropouts, class-wise confidences, confused classes.
#pragma once

#include "dyncull/core/box.hpp"
#include "dyncull/core/camera.hpp"
#include "dyncull/core/random.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/core/types.hpp"
#include "dyncull/sim/actors.hpp"
#include "dyncull/sim/depth_noise.hpp"
#include "dyncull/sim/primitives.hpp"
#include "dyncull/sim/texture.hpp"
#include "dyncull/sim/trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace dyncull::sim {

/// Gaussian: each box edge gets N(0, box_jitter_px^2), confidences uniform in [0.55, 0.99], false
/// positives of person/chair/tv. Calibrated: the shape of the real YOLOv8n streams on TUM fr3 (see
/// DetectorModelOptions), with box_jitter_px, miss_rate and false_positive_rate keeping their meaning.
enum class DetectorModel { Gaussian, Calibrated };

/// Stable lower-case name ("gaussian", "calibrated").
constexpr const char* to_string(DetectorModel model) noexcept {
  switch (model) {
    case DetectorModel::Gaussian: return "gaussian";
    case DetectorModel::Calibrated: return "calibrated";
  }
  return "unknown";
}

/// Shape of the Calibrated detector model (ignored by the Gaussian one).
struct DetectorModelOptions {
  DetectorModel model = DetectorModel::Gaussian;
  /// Edge jitter: N(0, box_jitter_px^2) with probability 1 - tail_probability, else a Laplace of
  /// scale tail_scale * box_jitter_px: real box edges on still people move little most frames and
  /// far now and then (median 1.1 px, 90th percentile 6 px between frames).
  double tail_probability = 0.2;
  double tail_scale = 6.0;
  /// Extra miss probability of objects other than people and monitors (keyboard, mouse, bottle,
  /// chair...), which the real detector reports in only part of the frames.
  double object_miss_rate = 0.4;
  double confidence_sd = 0.06;          ///< spread of a detection's confidence around its class's median
  /// Confidence lost by a box cut by the image border. 0: on the real streams people cut by the
  /// border keep their confidence (median 0.87-0.90 against 0.84-0.90 inside the image).
  double border_confidence_drop = 0.0;
  double min_confidence = 0.45;         ///< detections below it are dropped (the real streams' threshold)
};

struct SceneOptions {
  int width = 640;                 ///< image size; intrinsics are TUM fr3's scaled to it
  int height = 480;
  double fps = 30;                 ///< frame rate (TUM: 30 Hz)
  int num_frames = 300;
  CameraMotion motion = CameraMotion::Xyz;
  std::uint64_t seed = 1;          ///< textures, trajectory phases, walker start, noise, detections
  bool depth_noise = true;         ///< Kinect-like noise, quantisation, holes (depth_model); false = exact depth
  double box_jitter_px = 2.0;      ///< std-dev of the Gaussian jitter of each box edge (Calibrated: of its core)
  double miss_rate = 0.05;         ///< probability that a visible instance gets no detection (i.i.d. per frame)
  double false_positive_rate = 0.02;  ///< probability per frame of one spurious detection
  int min_detection_pixels = 300;  ///< instances with fewer visible pixels are not detected
  double start_time_s = 1341846313.0;  ///< timestamp of frame 0 (TUM-like Unix seconds)
  double near_m = 0.05;            ///< surfaces closer than this are clipped
  DepthNoiseOptions depth_model;   ///< used when depth_noise
  TrajectoryOptions trajectory;
  ActorOptions actors;
  DetectorModelOptions detector;   ///< shape of the detector's noise (box_jitter_px etc. set its size)

  /// Ok, or InvalidInput with a reason naming the first bad field.
  Status validate(std::string* reason = nullptr) const {
    auto bad = [&](const char* why) {
      if (reason) *reason = why;
      return Status::InvalidInput;
    };
    if (width <= 0 || height <= 0 || width > 8192 || height > 8192) return bad("width and height must be in [1, 8192]");
    if (!(fps > 0) || !std::isfinite(fps)) return bad("fps must be positive and finite");
    if (num_frames < 0) return bad("num_frames must be >= 0");
    if (!(box_jitter_px >= 0) || !std::isfinite(box_jitter_px)) return bad("box_jitter_px must be >= 0 and finite");
    if (!(miss_rate >= 0 && miss_rate <= 1)) return bad("miss_rate must be in [0, 1]");
    if (!(false_positive_rate >= 0 && false_positive_rate <= 1)) return bad("false_positive_rate must be in [0, 1]");
    if (!(near_m > 0) || !std::isfinite(near_m)) return bad("near_m must be positive");
    if (!std::isfinite(start_time_s)) return bad("start_time_s must be finite");
    if (actors.walking_people < 0 || actors.walking_people > 4) return bad("actors.walking_people must be in [0, 4]");
    if (actors.desk_people < 0 || actors.desk_people > 2) return bad("actors.desk_people must be 0, 1 or 2");
    if (!(actors.desk_motion_scale >= 0 && actors.desk_motion_scale <= 10))
      return bad("actors.desk_motion_scale must be in [0, 10]");
    if (!(detector.tail_probability >= 0 && detector.tail_probability <= 1))
      return bad("detector.tail_probability must be in [0, 1]");
    if (!(detector.tail_scale >= 0 && detector.tail_scale <= 1000)) return bad("detector.tail_scale must be in [0, 1000]");
    if (!(detector.object_miss_rate >= 0 && detector.object_miss_rate <= 1))
      return bad("detector.object_miss_rate must be in [0, 1]");
    if (!(detector.confidence_sd >= 0 && detector.confidence_sd <= 1)) return bad("detector.confidence_sd must be in [0, 1]");
    if (!(detector.border_confidence_drop >= 0 && detector.border_confidence_drop <= 1))
      return bad("detector.border_confidence_drop must be in [0, 1]");
    if (!(detector.min_confidence >= 0 && detector.min_confidence < 1))
      return bad("detector.min_confidence must be in [0, 1)");
    if (detector.model != DetectorModel::Gaussian && detector.model != DetectorModel::Calibrated)
      return bad("detector.model is not a known model");
    if (motion != CameraMotion::Static && motion != CameraMotion::Xyz && motion != CameraMotion::Rpy &&
        motion != CameraMotion::Halfsphere && motion != CameraMotion::Recorded)
      return bad("motion is not a known camera motion");
    if (!trajectory.validate_recorded(motion == CameraMotion::Recorded, reason)) return Status::InvalidInput;
    if (!(actors.texture_scale > 0)) return bad("actors.texture_scale must be positive");
    if (!(actors.wall_contrast >= 0 && actors.wall_contrast <= 1)) return bad("actors.wall_contrast must be in [0, 1]");
    if (reason) reason->clear();
    return Status::Ok;
  }
};

/// Switches `o` to the detector calibrated on the real YOLOv8n streams of TUM fr3 walking_* and
/// sitting_*: the Calibrated model with the jitter, miss and false-positive sizes measured there.
inline void use_calibrated_detector(SceneOptions* o) {
  if (o == nullptr) return;
  o->detector = DetectorModelOptions{};
  o->detector.model = DetectorModel::Calibrated;
  o->box_jitter_px = 1.0;
  o->miss_rate = 0.004;
  o->false_positive_rate = 0.025;
}

/// One rendered frame. Buffers are row-major, width * height (rgb: * 3), and reused between renders.
struct FrameData {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }

  int index = -1;                         ///< frame index in the sequence
  double timestamp = 0;                   ///< seconds
  Rigid3<double> world_from_cam;          ///< TUM ground truth convention
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;          ///< width*height*3, RGB order
  std::vector<std::uint8_t> gray;         ///< width*height
  std::vector<float> depth_m;             ///< width*height, 0 = no measurement
  std::vector<std::uint16_t> instance;    ///< width*height, 0 = static background/furniture
  std::vector<std::uint8_t> moving;       ///< 1 where the visible surface moves in the world at this frame
  /// Metres the visible surface point moved in the world since the previous frame (frame 0: until the
  /// next one); 0 where moving is 0. It says how fast "moving" is: in the default scene a walker's
  /// surface moves a median 14 mm a frame, the seated person's swaying upper body 4.6 mm (a tenth of it
  /// under 1.6 mm), which is under a pixel a frame at its distance.
  std::vector<float> motion_m;
  std::vector<Detection<float>> detections;  ///< COCO class ids (CocoClass), noisy per options.detector
  std::vector<std::uint16_t> primitive;   ///< index of the primitive seen at each pixel (Scene::primitives order)
};

class Scene {
 public:
  explicit Scene(const SceneOptions& options) : options_(options) {
    status_ = options_.validate(&reason_);
    if (status_ != Status::Ok) return;
    camera_ = PinholeCamera<double>::tum_fr3();
    const double sx = options_.width / 640.0, sy = options_.height / 480.0;
    camera_.fx *= sx;
    camera_.cx = (camera_.cx + 0.5) * sx - 0.5;
    camera_.fy *= sy;
    camera_.cy = (camera_.cy + 0.5) * sy - 0.5;
    camera_.width = options_.width;
    camera_.height = options_.height;
    ray_x_.resize(static_cast<std::size_t>(options_.width));
    ray_y_.resize(static_cast<std::size_t>(options_.height));
    for (int u = 0; u < options_.width; ++u) ray_x_[static_cast<std::size_t>(u)] = (u - camera_.cx) / camera_.fx;
    for (int v = 0; v < options_.height; ++v) ray_y_[static_cast<std::size_t>(v)] = (v - camera_.cy) / camera_.fy;
  }

  bool ok() const { return status_ == Status::Ok; }
  Status status() const { return status_; }
  const std::string& reason() const { return reason_; }

  int num_frames() const { return ok() ? options_.num_frames : 0; }
  PinholeCamera<double> camera() const { return camera_; }
  const SceneOptions& options() const { return options_; }

  /// Seconds since frame 0, and the frame's timestamp.
  double time_s(int index) const { return static_cast<double>(index) / options_.fps; }
  double timestamp(int index) const { return options_.start_time_s + time_s(index); }
  /// Ground-truth world_from_cam of a frame.
  Rigid3<double> world_from_cam(int index) const {
    return camera_pose(options_.motion, time_s(index), options_.seed, options_.trajectory);
  }
  /// The scene's primitives at a frame, in a fixed order (same count and order for every frame).
  void primitives(int index, std::vector<Primitive>* out) const {
    build_scene(time_s(index), 1.0 / options_.fps, options_.seed, options_.actors, out);
  }

  /// Renders frame `index` into `out`, reusing its buffers. Deterministic for (options, index).
  /// An invalid scene or index gives status InvalidInput and empty buffers.
  void render(int index, FrameData* out) const;

  /// Casts the ray of sub-pixel (u, v) in frame `index` and reports the world point it hits, the
  /// same material point at frame `other_index` (where the primitive has moved it), and its instance.
  /// False when the scene or indices are invalid or (u, v) is outside the image.
  bool surface_point(int index, double u, double v, int other_index, Vec3<double>* world_at_index,
                     Vec3<double>* world_at_other, std::uint16_t* instance = nullptr) const;

 private:
  SceneOptions options_;
  Status status_ = Status::Ok;
  std::string reason_;
  PinholeCamera<double> camera_;
  std::vector<double> ray_x_, ray_y_;
};

// ---------------------------------------------------------------------------------------------
// Implementation
// ---------------------------------------------------------------------------------------------

namespace detail {

/// Seed of one frame's random streams (depth noise, detections), mixed so neighbouring frames
/// and seeds give unrelated streams.
inline std::uint64_t frame_seed(std::uint64_t seed, int index, std::uint64_t stream) {
  std::uint64_t x = seed * 0x9E3779B97F4A7C15ull + static_cast<std::uint64_t>(index) * 0xD6E8FEB86659FD93ull + stream;
  return splitmix(x);
}

/// Light direction (world, towards the light): from above and slightly in front of the camera.
inline Vec3<double> light_direction() { return Vec3<double>(0.3, -0.5, 0.8).normalized(); }

/// Face albedo for the room: floor darker and warmer, ceiling brighter than the walls.
inline Vec3<double> room_face_albedo(const Vec3<double>& albedo, int axis, double coord) {
  if (axis != 2) return albedo;
  return coord < 0 ? Vec3<double>(0.55, 0.48, 0.4) : Vec3<double>(0.95, 0.95, 0.95);
}

/// Median confidence of a class on the real streams (person 0.88, tv 0.84, chair 0.78, desk objects ~0.6).
inline double class_confidence(int class_id) {
  switch (class_id) {
    case CocoClass::kPerson: return 0.87;
    case CocoClass::kTv: return 0.84;
    case CocoClass::kChair: return 0.78;
    default: return 0.62;
  }
}

/// Calibrated detector: see DetectorModelOptions. Every instance draws the same count of random
/// numbers whatever happens to it, so one instance's fate does not change the others' noise.
inline void detect_calibrated(const SceneOptions& o, int index, int w, int h, const long long* count, const int* u0,
                              const int* v0, const int* u1, const int* v1, FrameData* out) {
  const DetectorModelOptions& m = o.detector;
  Random rng(frame_seed(o.seed, index, 0xCA11B7ull));
  out->detections.clear();
  const double xmax = w - 1.0, ymax = h - 1.0;
  auto edge_noise = [&]() {
    const double pick = rng.uniform();
    const double g = rng.normal();
    const double e = rng.uniform(1e-12, 1.0);  // Laplace magnitude by inversion
    const double sign = rng.uniform() < 0.5 ? -1.0 : 1.0;
    return pick < m.tail_probability ? sign * m.tail_scale * o.box_jitter_px * -std::log(e) : o.box_jitter_px * g;
  };
  for (int id = 1; id < SceneInstance::kCount; ++id) {
    if (count[id] < o.min_detection_pixels) continue;
    const double miss = rng.uniform();
    const double miss_object = rng.uniform();
    double e[8];
    for (int k = 0; k < 4; ++k) e[k] = edge_noise();
    for (int k = 4; k < 8; ++k) e[k] = rng.normal();
    const double conf_noise = rng.normal();
    const int cls = instance_class(static_cast<std::uint16_t>(id));
    if (miss < o.miss_rate) continue;
    if (cls != CocoClass::kPerson && cls != CocoClass::kTv && miss_object < m.object_miss_rate) continue;
    const bool cut = u0[id] <= 0 || v0[id] <= 0 || u1[id] >= w - 1 || v1[id] >= h - 1;
    const double conf = class_confidence(cls) + m.confidence_sd * conf_noise - (cut ? m.border_confidence_drop : 0.0);
    if (conf < m.min_confidence) continue;
    Detection<float> d;
    d.class_id = cls;
    // An edge on the image border stays within a pixel or two of it (the real boxes of people cut
    // by the border end 0-3 px inside it): its jitter is folded inwards and never takes the tail.
    const double fold = o.box_jitter_px;
    const double x0 = u0[id] <= 0 ? std::min(xmax, fold * std::abs(e[4])) : std::clamp(u0[id] + e[0], 0.0, xmax);
    const double y0 = v0[id] <= 0 ? std::min(ymax, fold * std::abs(e[5])) : std::clamp(v0[id] + e[1], 0.0, ymax);
    const double x1 = u1[id] >= w - 1 ? std::max(0.0, xmax - fold * std::abs(e[6])) : std::clamp(u1[id] + e[2], 0.0, xmax);
    const double y1 = v1[id] >= h - 1 ? std::max(0.0, ymax - fold * std::abs(e[7])) : std::clamp(v1[id] + e[3], 0.0, ymax);
    d.box = Box<float>{static_cast<float>(std::min(x0, x1)), static_cast<float>(std::min(y0, y1)),
                       static_cast<float>(std::max(x0, x1)), static_cast<float>(std::max(y0, y1))};
    d.confidence = static_cast<float>(std::min(0.99, conf));
    out->detections.push_back(d);
  }
  // False positives of the classes the real detector confuses on these scenes (by frequency there:
  // skateboard, refrigerator, laptop, chair, microwave, sink, remote, cell phone), low confidence.
  const double fp = rng.uniform();
  const double pick = rng.uniform(), bw = rng.uniform(0.05, 0.3) * w, bh = rng.uniform(0.05, 0.3) * h;
  const double x0 = rng.uniform(0.0, w - bw), y0 = rng.uniform(0.3 * h, h - bh), c = rng.uniform(0.45, 0.6);
  if (fp < o.false_positive_rate) {
    static constexpr int kClasses[8] = {36, 72, 63, 56, 68, 71, 65, 67};
    static constexpr double kCumulative[8] = {0.35, 0.5, 0.65, 0.8, 0.86, 0.91, 0.96, 1.0};
    int k = 0;
    while (k < 7 && pick > kCumulative[k]) ++k;
    Detection<float> d;
    d.class_id = kClasses[k];
    d.box = Box<float>{static_cast<float>(x0), static_cast<float>(y0), static_cast<float>(std::min(x0 + bw, xmax)),
                       static_cast<float>(std::min(y0 + bh, ymax))};
    d.confidence = static_cast<float>(c);
    out->detections.push_back(d);
  }
}

inline void detect_instances(const Scene& scene, int index, FrameData* out) {
  const SceneOptions& o = scene.options();
  constexpr int kN = SceneInstance::kCount;
  int u0[kN], v0[kN], u1[kN], v1[kN];
  long long count[kN] = {};
  for (int k = 0; k < kN; ++k) {
    u0[k] = v0[k] = 1 << 30;
    u1[k] = v1[k] = -1;
  }
  const int w = out->width, h = out->height;
  for (int v = 0; v < h; ++v) {
    const std::uint16_t* row = out->instance.data() + static_cast<std::ptrdiff_t>(v) * w;
    for (int u = 0; u < w; ++u) {
      const int id = row[u];
      if (id <= 0 || id >= kN) continue;
      ++count[id];
      u0[id] = std::min(u0[id], u);
      u1[id] = std::max(u1[id], u);
      v0[id] = std::min(v0[id], v);
      v1[id] = std::max(v1[id], v);
    }
  }
  if (o.detector.model == DetectorModel::Calibrated) {
    detect_calibrated(o, index, w, h, count, u0, v0, u1, v1, out);
    return;
  }
  Random rng(frame_seed(o.seed, index, 0xDE7EC7ull));
  out->detections.clear();
  const float xmax = static_cast<float>(w - 1), ymax = static_cast<float>(h - 1);
  auto clip = [](float x, float hi) { return std::clamp(x, 0.f, hi); };
  for (int id = 1; id < kN; ++id) {
    if (count[id] < o.min_detection_pixels) continue;
    // Draw every random number whether or not it is used, so one instance's fate does not change
    // the others' noise.
    const double miss = rng.uniform();
    const double j[4] = {rng.normal(), rng.normal(), rng.normal(), rng.normal()};
    const double conf = rng.uniform();
    if (miss < o.miss_rate) continue;
    Detection<float> d;
    d.class_id = instance_class(static_cast<std::uint16_t>(id));
    const auto s = static_cast<float>(o.box_jitter_px);
    d.box.x0 = clip(static_cast<float>(u0[id]) + s * static_cast<float>(j[0]), xmax);
    d.box.y0 = clip(static_cast<float>(v0[id]) + s * static_cast<float>(j[1]), ymax);
    d.box.x1 = clip(static_cast<float>(u1[id]) + s * static_cast<float>(j[2]), xmax);
    d.box.y1 = clip(static_cast<float>(v1[id]) + s * static_cast<float>(j[3]), ymax);
    if (d.box.x1 < d.box.x0) std::swap(d.box.x0, d.box.x1);
    if (d.box.y1 < d.box.y0) std::swap(d.box.y0, d.box.y1);
    d.confidence = static_cast<float>(0.55 + 0.44 * conf);
    out->detections.push_back(d);
  }
  if (rng.uniform() < o.false_positive_rate) {
    static constexpr int kClasses[3] = {CocoClass::kPerson, CocoClass::kChair, CocoClass::kTv};
    Detection<float> d;
    d.class_id = kClasses[rng.index(3)];
    const double bw = rng.uniform(0.06, 0.3) * w, bh = rng.uniform(0.1, 0.45) * h;
    const double x0 = rng.uniform(0.0, w - bw), y0 = rng.uniform(0.0, h - bh);
    d.box = Box<float>{static_cast<float>(x0), static_cast<float>(y0), static_cast<float>(std::min(x0 + bw, w - 1.0)),
                       static_cast<float>(std::min(y0 + bh, h - 1.0))};
    d.confidence = static_cast<float>(rng.uniform(0.3, 0.6));
    out->detections.push_back(d);
  }
}

/// An invalid frame: every buffer empty, size 0.
inline void clear_frame(FrameData* out) {
  out->width = out->height = 0;
  out->rgb.clear();
  out->gray.clear();
  out->depth_m.clear();
  out->instance.clear();
  out->moving.clear();
  out->motion_m.clear();
  out->primitive.clear();
}

/// Every per-pixel buffer sized for n pixels (rgb: 3 n).
inline void resize_frame(FrameData* out, std::size_t n) {
  out->rgb.resize(3 * n);
  out->gray.resize(n);
  out->depth_m.resize(n);
  out->instance.resize(n);
  out->moving.resize(n);
  out->motion_m.resize(n);
  out->primitive.resize(n);
}

/// Visibility: z-buffer over each primitive's screen bounds (the room covers every pixel first). zbuf
/// (initialised to kNoHit) gets the nearest ray parameter of each pixel, prim_id its primitive.
inline void zbuffer(const std::vector<Primitive>& prims, const std::vector<CameraPrimitive>& cps,
                    const std::vector<double>& ray_x, const std::vector<double>& ray_y, int w, double near_m,
                    std::vector<double>* zbuf, std::uint16_t* prim_id) {
  for (std::size_t k = 0; k < prims.size(); ++k) {
    const PixelRect& r = cps[k].bounds;
    const Mat3<double>& R = cps[k].local_from_cam_R;
    for (int v = r.r0; v < r.r1; ++v) {
      // Local ray direction is affine in x along a row: row_base + x * R.col(0).
      const Vec3<double> row_base = R.col(1) * ray_y[static_cast<std::size_t>(v)] + R.col(2);
      const std::size_t row = static_cast<std::size_t>(v) * static_cast<std::size_t>(w);
      for (int u = r.c0; u < r.c1; ++u) {
        const double lambda =
            intersect_local(prims[k], cps[k], row_base + ray_x[static_cast<std::size_t>(u)] * R.col(0), near_m);
        if (lambda < (*zbuf)[row + static_cast<std::size_t>(u)]) {
          (*zbuf)[row + static_cast<std::size_t>(u)] = lambda;
          prim_id[row + static_cast<std::size_t>(u)] = static_cast<std::uint16_t>(k);
        }
      }
    }
  }
}

/// Pixel i where no surface is seen (only possible with a camera outside the room): black, static.
inline void clear_pixel(FrameData* out, std::size_t i) {
  out->rgb[3 * i] = out->rgb[3 * i + 1] = out->rgb[3 * i + 2] = 0;
  out->gray[i] = 0;
  out->instance[i] = 0;
  out->moving[i] = 0;
  out->motion_m[i] = 0.f;
}

/// Colour and grey of pixel i seeing primitive p at `local` (its frame): albedo times texture times a
/// Lambertian shade towards `light`.
inline void shade_pixel(const Primitive& p, const Vec3<double>& local, const Vec3<double>& light, FrameData* out,
                        std::size_t i) {
  int axis = -1;
  const Vec3<double> n_local = local_normal(p, local, &axis);
  Vec3<double> tex_point = local;
  std::uint32_t tex_seed = p.texture_seed;
  Vec3<double> albedo = p.albedo;
  if (axis >= 0) {
    // Box faces: drop the constant coordinate (it sits on a cell boundary) and vary per face.
    const bool positive = local[axis] >= 0;
    tex_seed ^= static_cast<std::uint32_t>(2 * axis + (positive ? 1 : 0)) * 0x68E31DA4u;
    tex_point[axis] = 0;
    if (p.shape == PrimitiveShape::RoomInterior) albedo = room_face_albedo(albedo, axis, local[axis]);
  }
  const double texture = 0.55 + p.texture_contrast * (texture_value(tex_point, p.texture_cell_m, tex_seed) - 0.55);
  const double shade = 0.45 + 0.55 * std::max(0.0, (p.world_from_local.R * n_local).dot(light));
  const double g = 255.0 * texture * shade;
  const double r8 = std::min(255.0, albedo.x() * g), g8 = std::min(255.0, albedo.y() * g),
               b8 = std::min(255.0, albedo.z() * g);
  // checked: albedo, texture and shade are non-negative and each channel is capped at 255.
  out->rgb[3 * i] = static_cast<std::uint8_t>(r8 + 0.5);      // checked: above
  out->rgb[3 * i + 1] = static_cast<std::uint8_t>(g8 + 0.5);  // checked: above
  out->rgb[3 * i + 2] = static_cast<std::uint8_t>(b8 + 0.5);  // checked: above
  out->gray[i] = static_cast<std::uint8_t>(std::min(255.0, 0.299 * r8 + 0.587 * g8 + 0.114 * b8 + 0.5));  // checked: above
}

}  // namespace detail

inline void Scene::render(int index, FrameData* out) const {
  if (out == nullptr) return;
  out->index = index;
  out->detections.clear();
  if (!ok() || index < 0 || index >= options_.num_frames) {
    out->status = Status::InvalidInput;
    out->reason = !ok() ? "invalid scene options: " + reason_
                        : "frame index " + std::to_string(index) + " outside [0, " + std::to_string(options_.num_frames) + ")";
    detail::clear_frame(out);
    return;
  }
  out->status = Status::Ok;
  out->reason.clear();
  const int w = options_.width, h = options_.height;
  const auto n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  out->width = w;
  out->height = h;
  out->timestamp = timestamp(index);
  out->world_from_cam = world_from_cam(index);
  detail::resize_frame(out, n);

  std::vector<Primitive> prims, prims_other;
  primitives(index, &prims);
  // The frame motion_m measures against: the previous one, or for frame 0 the next (itself if alone).
  primitives(index > 0 ? index - 1 : std::min(1, options_.num_frames - 1), &prims_other);
  const Rigid3<double> cam_from_world = out->world_from_cam.inverse();
  std::vector<CameraPrimitive> cps(prims.size());
  for (std::size_t k = 0; k < prims.size(); ++k) cps[k] = prepare(prims[k], cam_from_world, camera_, options_.near_m);

  float* depth = out->depth_m.data();
  std::uint16_t* prim_id = out->primitive.data();
  std::fill(depth, depth + n, 0.f);
  std::fill(prim_id, prim_id + n, std::uint16_t(0));
  std::vector<double> zbuf(n, kNoHit);
  detail::zbuffer(prims, cps, ray_x_, ray_y_, w, options_.near_m, &zbuf, prim_id);

  // Shading, instance and moving truth.
  const Vec3<double> light = detail::light_direction();
  for (int v = 0; v < h; ++v) {
    const double y = ray_y_[static_cast<std::size_t>(v)];
    for (int u = 0; u < w; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * static_cast<std::size_t>(w) + static_cast<std::size_t>(u);
      const double lambda = zbuf[i];
      if (!(lambda < kNoHit)) {
        detail::clear_pixel(out, i);
        continue;
      }
      const Primitive& p = prims[prim_id[i]];
      const CameraPrimitive& cp = cps[prim_id[i]];
      const Vec3<double> local = cp.origin_local + lambda * (cp.local_from_cam_R * Vec3<double>(ray_x_[static_cast<std::size_t>(u)], y, 1.0));
      detail::shade_pixel(p, local, light, out, i);
      out->instance[i] = p.instance;
      out->moving[i] = p.moving;
      out->motion_m[i] =
          p.moving && prim_id[i] < prims_other.size()
              ? static_cast<float>((prims_other[prim_id[i]].world_from_local.apply(local) -
                                         p.world_from_local.apply(local)).norm())
              : 0.f;
      depth[i] = static_cast<float>(lambda);
    }
  }
  if (options_.depth_noise) {
    apply_depth_noise(depth, w, h, options_.depth_model, detail::frame_seed(options_.seed, index, 0xDE9700ull));
  }
  detail::detect_instances(*this, index, out);
}

inline bool Scene::surface_point(int index, double u, double v, int other_index, Vec3<double>* world_at_index,
                                 Vec3<double>* world_at_other, std::uint16_t* instance) const {
  if (!ok() || index < 0 || index >= options_.num_frames || other_index < 0 || other_index >= options_.num_frames)
    return false;
  if (!camera_.in_image(u, v) || !std::isfinite(u) || !std::isfinite(v)) return false;
  std::vector<Primitive> now, other;
  primitives(index, &now);
  primitives(other_index, &other);
  const Rigid3<double> cam_from_world = world_from_cam(index).inverse();
  const Vec3<double> ray = camera_.ray(Vec2<double>(u, v));
  double best = kNoHit;
  std::size_t best_k = 0;
  for (std::size_t k = 0; k < now.size(); ++k) {
    const CameraPrimitive cp = prepare(now[k], cam_from_world, camera_, options_.near_m);
    const double lambda = intersect(now[k], cp, ray, options_.near_m);
    if (lambda < best) {
      best = lambda;
      best_k = k;
    }
  }
  if (!(best < kNoHit) || now.size() != other.size()) return false;
  const Vec3<double> world = cam_from_world.inverse().apply(best * ray);
  const Vec3<double> local = now[best_k].world_from_local.inverse().apply(world);
  if (world_at_index) *world_at_index = world;
  if (world_at_other) *world_at_other = other[best_k].world_from_local.apply(local);
  if (instance) *instance = now[best_k].instance;
  return true;
}

}  // namespace dyncull::sim
