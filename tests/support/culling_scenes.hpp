/// @file culling_scenes.hpp
/// Ray-cast test scenes with known truth for the culling strategies: a static room, a walking
/// person, a sitting person moving only the upper body, a pushed chair and a TV, seen by a moving camera.
#pragma once

#include "dyncull/core/box.hpp"
#include "dyncull/core/camera.hpp"
#include "dyncull/core/depth.hpp"
#include "dyncull/core/random.hpp"
#include "dyncull/core/types.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace dyncull {
namespace test {

/// What a feature lies on. The sitting person is one object (one detection) with two parts.
enum class SceneKind : std::uint8_t { Room = 0, WalkingPerson, SittingUpper, SittingLower, Chair, Tv };

/// An axis-aligned solid cuboid in world coordinates at time 0, moving `velocity_m` per frame.
struct ScenePart {
  Vec3<double> lo, hi;
  Vec3<double> velocity_m = Vec3<double>::Zero();
  SceneKind kind = SceneKind::Room;
  int object = -1;  ///< index into SceneConfig objects (detections); parts of one object share it
  Vec3<double> lo_at(double tau) const { return lo + tau * velocity_m; }
  Vec3<double> hi_at(double tau) const { return hi + tau * velocity_m; }
  bool moving() const { return velocity_m.squaredNorm() > 0; }
};

struct SceneConfig {
  bool walking = true;  ///< person walking across in front of the TV
  bool sitting = true;  ///< person sitting still, leaning the upper body
  bool chair = true;    ///< chair being pushed (a medium-level object that moves)
  bool tv = true;       ///< static TV on the back wall, its box overlapping the walking person's
  bool all_dynamic = false;  ///< the walking person fills the view: every feature is on it
  int num_uniform = 700;     ///< features sampled uniformly over the image
  int num_per_object = 90;   ///< extra features sampled inside each object's box
  int frames_between = 1;    ///< previous frame = this many frames earlier (tracks)
  double pixel_noise = 0.25; ///< Gaussian pixel noise (std, px) on both ends of a track
  double walk_speed_m = 0.04;  ///< walking speed per frame (1.2 m/s at 30 fps)
  double sway_scale = 1.0;     ///< scales the seated person's upper-body motion (1: about 4 px a frame)
  bool static_camera = false;  ///< camera does not move (F undetermined)
  std::uint64_t seed = 7;
  PinholeCamera<double> camera = PinholeCamera<double>::tum_fr3();
};

/// The seated person's scene: no walker, 200 extra features in each object's box (its cells well filled).
inline SceneConfig seated_person_config() {
  SceneConfig config;
  config.walking = false;
  config.num_per_object = 200;
  return config;
}

/// One frame pair with truth. All per-feature vectors are parallel.
template <class T>
struct CullingScene {
  PinholeCamera<T> camera;
  Rigid3<T> cam_from_world_prev, cam_from_world;  ///< previous and current camera
  std::vector<Vec2<T>> keypoints;       ///< current-frame positions (noisy)
  std::vector<Vec2<T>> prev_keypoints;  ///< previous-frame positions (noisy); see track_valid
  std::vector<std::uint8_t> track_valid;
  /// Exact 3-D point (world) of each track's surface at the previous frame, as the previous frame's depth
  /// would measure it (NaN where the track is invalid): the reprojection check's points_3d.
  std::vector<Vec3<T>> prev_points_world;
  std::vector<T> depth_m;               ///< current depth of each feature (metres)
  std::vector<std::uint8_t> truth_dynamic;  ///< 1 when the surface moves in the world
  std::vector<SceneKind> kind;
  std::vector<Detection<float>> detections;  ///< current-frame boxes: person 0, chair 56, tv 62
  std::vector<SceneKind> detection_kind;
  std::vector<float> depth;  ///< current depth image, float metres, 0 = none
  int width = 0, height = 0;

  DepthView<float> depth_view() const { return DepthView<float>{depth.data(), width, height, 0, 1.f, 0.f, 1e30f}; }
  /// TUM-style uint16 copy (5000 per metre) of the depth image.
  std::vector<std::uint16_t> depth_tum() const {
    std::vector<std::uint16_t> out(depth.size());
    for (std::size_t i = 0; i < depth.size(); ++i)
      out[i] = static_cast<std::uint16_t>(std::min(65535.0, std::round(double(depth[i]) * 5000.0)));
    return out;
  }
  std::size_t size() const { return keypoints.size(); }
  std::size_t count(SceneKind k) const { return static_cast<std::size_t>(std::count(kind.begin(), kind.end(), k)); }
};

/// Features of an earlier keyframe (for the multi-view check): positions and depths in that frame.
template <class T>
struct SceneKeyframe {
  Rigid3<T> cam_from_world;
  std::vector<Vec2<T>> keypoints;
  std::vector<T> depth_m;
  std::vector<SceneKind> kind;
};

/// The world: room interior plus solid parts, and a camera moving at constant velocity.
class SceneWorld {
 public:
  explicit SceneWorld(const SceneConfig& config) : config_(config) {
    // Room interior (y points down, floor at y = 1.3, camera at the origin at time 0).
    room_lo_ = Vec3<double>(-3.0, -1.6, -1.0);
    room_hi_ = Vec3<double>(3.0, 1.3, 4.5);
    if (config.all_dynamic) {
      // A person close to the camera, filling the view, walking sideways.
      add({-3.0, -2.5, 0.9}, {3.0, 2.5, 1.2}, {config.walk_speed_m, 0.0, 0.0}, SceneKind::WalkingPerson, 0);
      return;
    }
    // Static furniture at 1.4-3.5 m: the depth spread that makes F well determined at small baselines.
    add({-0.6, 0.55, 1.4}, {0.3, 1.3, 1.9}, {0.0, 0.0, 0.0}, SceneKind::Room, -1);     // desk
    add({-3.0, -1.6, 0.8}, {-2.3, 1.3, 3.5}, {0.0, 0.0, 0.0}, SceneKind::Room, -1);    // bookcase, left
    add({2.2, -0.2, 1.2}, {3.0, 1.3, 2.2}, {0.0, 0.0, 0.0}, SceneKind::Room, -1);      // cabinet, right
    if (config.walking)
      add({-1.35, -0.5, 2.3}, {-0.85, 1.3, 2.6}, {config.walk_speed_m, 0.0, -0.01}, SceneKind::WalkingPerson, 0);
    if (config.sitting) {
      // The upper body (head and shoulders, the top 28 % of the person) sways sideways; hips and legs stay.
      add({0.35, -0.30, 3.0}, {0.85, 0.15, 3.3}, config.sway_scale * Vec3<double>(0.02, -0.01, 0.0),
          SceneKind::SittingUpper, 1);
      add({0.35, 0.15, 3.0}, {0.85, 1.3, 3.3}, {0.0, 0.0, 0.0}, SceneKind::SittingLower, 1);
    }
    if (config.chair) add({1.3, 0.6, 2.6}, {1.8, 1.3, 3.0}, {0.03, 0.0, 0.02}, SceneKind::Chair, 2);
    if (config.tv) add({-1.1, -0.8, 4.35}, {-0.2, -0.25, 4.45}, {0.0, 0.0, 0.0}, SceneKind::Tv, 3);
  }

  /// Camera pose at time tau (frames): translation and a slow yaw, so F is well determined
  /// (the room has depth variation) and epipolar lines are slanted, not parallel to the walk.
  Rigid3<double> cam_from_world(double tau) const {
    Rigid3<double> world_from_cam;
    if (config_.static_camera) return world_from_cam;
    world_from_cam.R = Eigen::AngleAxisd(0.004 * tau, Vec3<double>::UnitY()).toRotationMatrix() *
                       Eigen::AngleAxisd(0.002 * tau, Vec3<double>::UnitX()).toRotationMatrix();
    world_from_cam.t = Vec3<double>(0.010, 0.014, 0.004) * tau;
    return world_from_cam.inverse();
  }

  /// The world frozen at time tau: the camera's centre and orientation and every part's box, computed
  /// once for the many rays of one image (a dense depth image casts one per pixel).
  struct View {
    Vec3<double> origin;
    Mat3<double> world_from_cam;
    std::vector<Vec3<double>> lo, hi;  // per part
  };

  View view_at(double tau) const {
    const Rigid3<double> wc = cam_from_world(tau).inverse();
    View view{wc.t, wc.R, {}, {}};
    for (const ScenePart& p : parts_) {
      view.lo.push_back(p.lo_at(tau));
      view.hi.push_back(p.hi_at(tau));
    }
    return view;
  }

  /// First surface hit by the ray through pixel (u, v) at time tau: world point, depth, part index
  /// (-1 for the room). Returns false when nothing is hit (never inside the room).
  bool raycast(double tau, double u, double v, Vec3<double>* world, double* depth, int* part) const {
    return raycast(view_at(tau), u, v, world, depth, part);
  }

  bool raycast(const View& view, double u, double v, Vec3<double>* world, double* depth, int* part) const {
    const Vec3<double>& origin = view.origin;
    const Vec3<double> dir_cam = config_.camera.ray(Vec2<double>(u, v));
    const Vec3<double> dir = view.world_from_cam * dir_cam;  // t along dir == depth along the optical axis
    double best = std::numeric_limits<double>::infinity();
    int best_part = -1;
    // Room: exit distance of the interior box.
    for (int a = 0; a < 3; ++a) {
      if (dir[a] > 0) best = std::min(best, (room_hi_[a] - origin[a]) / dir[a]);
      if (dir[a] < 0) best = std::min(best, (room_lo_[a] - origin[a]) / dir[a]);
    }
    for (std::size_t i = 0; i < parts_.size(); ++i) {
      const Vec3<double>& lo = view.lo[i];
      const Vec3<double>& hi = view.hi[i];
      double t0 = 0, t1 = std::numeric_limits<double>::infinity();
      bool hit = true;
      for (int a = 0; a < 3 && hit; ++a) {
        if (dir[a] == 0) {
          hit = origin[a] >= lo[a] && origin[a] <= hi[a];
          continue;
        }
        double ta = (lo[a] - origin[a]) / dir[a], tb = (hi[a] - origin[a]) / dir[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
        hit = t0 <= t1;
      }
      if (hit && t0 > 1e-6 && t0 < best) {
        best = t0;
        best_part = static_cast<int>(i);
      }
    }
    if (!std::isfinite(best)) return false;
    *world = origin + best * dir;
    *depth = best;
    *part = best_part;
    return true;
  }

  SceneKind kind_of(int part) const { return part < 0 ? SceneKind::Room : parts_[static_cast<std::size_t>(part)].kind; }
  const std::vector<ScenePart>& parts() const { return parts_; }
  const SceneConfig& config() const { return config_; }

  /// Tight pixel box of an object (all its parts) at time tau, clipped; false when not visible.
  bool object_box(int object, double tau, Box<float>* box) const {
    const Rigid3<double> cw = cam_from_world(tau);
    double x0 = 1e30, y0 = 1e30, x1 = -1e30, y1 = -1e30;
    bool any = false;
    for (const ScenePart& p : parts_) {
      if (p.object != object) continue;
      const Vec3<double> lo = p.lo_at(tau), hi = p.hi_at(tau);
      for (int c = 0; c < 8; ++c) {
        const Vec3<double> corner((c & 1) ? hi.x() : lo.x(), (c & 2) ? hi.y() : lo.y(), (c & 4) ? hi.z() : lo.z());
        const Vec3<double> pc = cw.apply(corner);
        if (pc.z() <= 0.05) continue;
        const Vec2<double> px = config_.camera.project(pc);
        x0 = std::min(x0, px.x());
        y0 = std::min(y0, px.y());
        x1 = std::max(x1, px.x());
        y1 = std::max(y1, px.y());
        any = true;
      }
    }
    if (!any) return false;
    *box = Box<float>{float(x0), float(y0), float(x1), float(y1)}.clipped(config_.camera.width, config_.camera.height);
    return box->width() > 2 && box->height() > 2;
  }

 private:
  void add(Vec3<double> lo, Vec3<double> hi, Vec3<double> v, SceneKind kind, int object) {
    ScenePart p;
    p.lo = lo;
    p.hi = hi;
    p.velocity_m = v;
    p.kind = kind;
    p.object = object;
    parts_.push_back(p);
  }

  SceneConfig config_;
  Vec3<double> room_lo_, room_hi_;
  std::vector<ScenePart> parts_;
};

inline int coco_class_of(SceneKind kind) {
  switch (kind) {
    case SceneKind::WalkingPerson:
    case SceneKind::SittingUpper:
    case SceneKind::SittingLower: return 0;
    case SceneKind::Chair: return 56;
    case SceneKind::Tv: return 62;
    case SceneKind::Room: break;
  }
  return -1;
}

/// Builds the current frame (time 0) and its tracks from `frames_between` frames earlier.
template <class T>
CullingScene<T> make_culling_scene(const SceneConfig& config = {}) {
  SceneWorld world(config);
  const PinholeCamera<double>& cam = config.camera;
  const double tau_prev = -double(config.frames_between);
  const Rigid3<double> cw_prev = world.cam_from_world(tau_prev), cw_cur = world.cam_from_world(0.0);
  CullingScene<T> s;
  s.camera = cam.cast<T>();
  s.cam_from_world_prev = cw_prev.cast<T>();
  s.cam_from_world = cw_cur.cast<T>();
  s.width = cam.width;
  s.height = cam.height;

  // Depth image of the current frame.
  const SceneWorld::View now = world.view_at(0.0);
  s.depth.assign(static_cast<std::size_t>(cam.width) * static_cast<std::size_t>(cam.height), 0.f);
  for (int v = 0; v < cam.height; ++v)
    for (int u = 0; u < cam.width; ++u) {
      Vec3<double> X;
      double d = 0;
      int part = -1;
      if (world.raycast(now, u, v, &X, &d, &part)) s.depth[static_cast<std::size_t>(v) * cam.width + u] = float(d);
    }

  // Detections: one box per object, in the order of the objects.
  for (int object = 0; object < 4; ++object) {
    Box<float> box;
    if (!world.object_box(object, 0.0, &box)) continue;
    SceneKind kind = SceneKind::Room;
    for (const ScenePart& p : world.parts())
      if (p.object == object) kind = p.kind == SceneKind::SittingLower ? SceneKind::SittingUpper : p.kind;
    Detection<float> det;
    det.box = box;
    det.class_id = coco_class_of(kind);
    det.confidence = 0.9f;
    s.detections.push_back(det);
    s.detection_kind.push_back(kind);
  }

  Random rng(config.seed);
  auto add_feature = [&](double u, double v, int want_object) {
    Vec3<double> X;
    double d = 0;
    int part = -1;
    if (!world.raycast(now, u, v, &X, &d, &part)) return;
    if (want_object >= 0 && (part < 0 || world.parts()[static_cast<std::size_t>(part)].object != want_object)) return;
    const Vec3<double> vel = part < 0 ? Vec3<double>::Zero() : world.parts()[static_cast<std::size_t>(part)].velocity_m;
    const Vec3<double> X_prev = X + tau_prev * vel;
    const Vec3<double> pc = cw_prev.apply(X_prev);
    bool valid = pc.z() > 0.1;
    Vec2<double> prev = valid ? cam.project(pc) : Vec2<double>(-1, -1);
    valid = valid && cam.in_image(prev.x(), prev.y());
    const double n = config.pixel_noise;
    s.keypoints.push_back(Vec2<T>(T(u + n * rng.normal()), T(v + n * rng.normal())));
    s.prev_keypoints.push_back(Vec2<T>(T(prev.x() + n * rng.normal()), T(prev.y() + n * rng.normal())));
    s.track_valid.push_back(valid ? 1 : 0);
    s.prev_points_world.push_back(valid ? Vec3<T>(X_prev.cast<T>()) : Vec3<T>::Constant(std::numeric_limits<T>::quiet_NaN()));
    s.depth_m.push_back(T(d));
    s.truth_dynamic.push_back(vel.squaredNorm() > 0 ? 1 : 0);
    s.kind.push_back(world.kind_of(part));
  };
  const double border = 8;
  for (int i = 0; i < config.num_uniform; ++i)
    add_feature(rng.uniform(border, cam.width - 1 - border), rng.uniform(border, cam.height - 1 - border), -1);
  for (int object = 0; object < 4; ++object) {
    Box<float> box;
    if (!world.object_box(object, 0.0, &box)) continue;
    for (int i = 0; i < config.num_per_object; ++i)
      add_feature(rng.uniform(box.x0, box.x1), rng.uniform(box.y0, box.y1), object);
  }
  return s;
}

/// Features of a keyframe `frames_back` frames before the current one, sampled in that frame.
template <class T>
SceneKeyframe<T> make_scene_keyframe(const SceneConfig& config, int frames_back, int num_features = 800,
                                     std::uint64_t seed = 11) {
  SceneWorld world(config);
  const double tau = -double(frames_back);
  SceneKeyframe<T> kf;
  kf.cam_from_world = world.cam_from_world(tau).cast<T>();
  Random rng(seed);
  const PinholeCamera<double>& cam = config.camera;
  const SceneWorld::View then = world.view_at(tau);
  for (int i = 0; i < num_features; ++i) {
    const double u = rng.uniform(4, cam.width - 5), v = rng.uniform(4, cam.height - 5);
    Vec3<double> X;
    double d = 0;
    int part = -1;
    if (!world.raycast(then, u, v, &X, &d, &part)) continue;
    kf.keypoints.push_back(Vec2<T>(T(u), T(v)));
    kf.depth_m.push_back(T(d));
    kf.kind.push_back(world.kind_of(part));
  }
  return kf;
}

/// Precision and recall of predicted dynamic flags against truth.
struct PrecisionRecall {
  double precision = 1, recall = 1;
  std::size_t tp = 0, fp = 0, fn = 0;
};

template <class Pred, class Truth>
PrecisionRecall precision_recall(const Pred& predicted_dynamic, const Truth& truth_dynamic, std::size_t n) {
  PrecisionRecall pr;
  for (std::size_t i = 0; i < n; ++i) {
    const bool p = static_cast<bool>(predicted_dynamic[i]), t = static_cast<bool>(truth_dynamic[i]);
    pr.tp += p && t;
    pr.fp += p && !t;
    pr.fn += !p && t;
  }
  pr.precision = pr.tp + pr.fp > 0 ? double(pr.tp) / double(pr.tp + pr.fp) : 1.0;
  pr.recall = pr.tp + pr.fn > 0 ? double(pr.tp) / double(pr.tp + pr.fn) : 1.0;
  return pr;
}

}  // namespace test
}  // namespace dyncull
