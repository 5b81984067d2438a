/// @file actors.hpp
/// The synthetic room and its actors as primitives at time t: static textured room and furniture,
/// walking people (COCO 0), a pushed chair (56), a sitting person moving only the upper body, a TV (62);
/// optionally two people seated at a desk with its clutter, as in TUM fr3/sitting_* (Sturm et al. 2012).
/// Layout and gait are modelled on the TUM fr3 walking and sitting sequences (no paper equation).
#pragma once

#include "dyncull/core/types.hpp"
#include "dyncull/sim/primitives.hpp"

#include <cmath>
#include <cstdint>
#include <vector>

namespace dyncull::sim {

/// COCO-80 class indices used by the scene.
struct CocoClass {
  static constexpr int kPerson = 0;
  static constexpr int kBottle = 39;
  static constexpr int kCup = 41;
  static constexpr int kChair = 56;
  static constexpr int kTv = 62;
  static constexpr int kLaptop = 63;
  static constexpr int kMouse = 64;
  static constexpr int kKeyboard = 66;
  static constexpr int kBook = 73;
};

/// Instance ids of the scene (0 = static background and furniture without a detector class).
struct SceneInstance {
  static constexpr std::uint16_t kBackground = 0;
  static constexpr std::uint16_t kWalkerA = 1;
  static constexpr std::uint16_t kWalkerB = 2;
  static constexpr std::uint16_t kSittingPerson = 3;
  static constexpr std::uint16_t kPushedChair = 4;
  static constexpr std::uint16_t kSittingChair = 5;
  static constexpr std::uint16_t kTv = 6;
  static constexpr std::uint16_t kWalkerC = 7;       ///< third and fourth walkers (a crowd)
  static constexpr std::uint16_t kWalkerD = 8;
  static constexpr std::uint16_t kDeskPersonA = 9;   ///< people seated at the desk (fr3/sitting_*)
  static constexpr std::uint16_t kDeskPersonB = 10;
  static constexpr std::uint16_t kDeskChairA = 11;   ///< their swivel chairs
  static constexpr std::uint16_t kDeskChairB = 12;
  static constexpr std::uint16_t kMonitorA = 13;     ///< desk clutter: monitors (tv), then medium-level objects
  static constexpr std::uint16_t kMonitorB = 14;
  static constexpr std::uint16_t kKeyboardA = 15;
  static constexpr std::uint16_t kKeyboardB = 16;
  static constexpr std::uint16_t kMouseA = 17;
  static constexpr std::uint16_t kMouseB = 18;
  static constexpr std::uint16_t kBottle = 19;
  static constexpr std::uint16_t kCup = 20;
  static constexpr std::uint16_t kBook = 21;
  static constexpr std::uint16_t kLaptop = 22;
  static constexpr int kCount = 23;  ///< ids are < kCount

  /// Walker w's id (w in 0..3).
  static constexpr std::uint16_t walker(int w) noexcept {
    return w <= 1 ? static_cast<std::uint16_t>(kWalkerA + w) : static_cast<std::uint16_t>(kWalkerC + (w - 2));
  }
};

/// COCO class of an instance id, -1 for the background.
constexpr int instance_class(std::uint16_t instance) noexcept {
  switch (instance) {
    case SceneInstance::kWalkerA:
    case SceneInstance::kWalkerB:
    case SceneInstance::kWalkerC:
    case SceneInstance::kWalkerD:
    case SceneInstance::kDeskPersonA:
    case SceneInstance::kDeskPersonB:
    case SceneInstance::kSittingPerson: return CocoClass::kPerson;
    case SceneInstance::kPushedChair:
    case SceneInstance::kDeskChairA:
    case SceneInstance::kDeskChairB:
    case SceneInstance::kSittingChair: return CocoClass::kChair;
    case SceneInstance::kMonitorA:
    case SceneInstance::kMonitorB:
    case SceneInstance::kTv: return CocoClass::kTv;
    case SceneInstance::kKeyboardA:
    case SceneInstance::kKeyboardB: return CocoClass::kKeyboard;
    case SceneInstance::kMouseA:
    case SceneInstance::kMouseB: return CocoClass::kMouse;
    case SceneInstance::kBottle: return CocoClass::kBottle;
    case SceneInstance::kCup: return CocoClass::kCup;
    case SceneInstance::kBook: return CocoClass::kBook;
    case SceneInstance::kLaptop: return CocoClass::kLaptop;
    default: return -1;
  }
}

/// Which actors are present and how they move.
struct ActorOptions {
  int walking_people = 2;              ///< 0 to 4 people walking an elliptic loop, walker_gap_rad apart
  bool sitting_person = true;          ///< person on a chair moving head, torso and arms only
  bool pushed_chair = true;            ///< chair that slides once, pushed between push_start_s and push_end_s
  double walking_speed_mps = 0.4;      ///< mean walking speed along the loop (slow, like TUM fr3/walking_*)
  Vec2<double> loop_centre_m{0.0, 1.05};  ///< centre of the walking loop on the floor (world x, y)
  Vec2<double> loop_semi_axes_m{0.8, 0.35};  ///< semi-axes of the loop; camera rests at y = -0.3
  double walker_start_phase_rad = -2.4;  ///< walker A's loop phase at t = 0 (-pi/2 = nearest the camera)
  double walker_gap_rad = 0.8;         ///< phase of walker B behind walker A on the loop (close: coherent motion)
  double push_start_s = 3.5;           ///< chair starts moving (seconds from the first frame)
  double push_end_s = 5.0;             ///< chair stops moving
  double wall_contrast = 0.4;          ///< texture contrast of walls, floor, ceiling in [0, 1]; lower = plainer, harder
  double texture_scale = 1.0;          ///< multiplies every texture cell size (smaller = more corners)
  /// People seated at a desk in front of the camera rest pose (fr3/sitting_*): 0, 1 or 2. They sway,
  /// turn their heads, gesture with their arms and now and then swivel their chairs; with 2 the
  /// person boxes cover about half of the image from the rest pose.
  int desk_people = 0;
  double desk_motion_scale = 1.0;      ///< scales the desk people's sway, head turn, gesture and swivel (0 = still)
  /// Desk clutter, static: two monitors (tv, low level) and keyboards, mice, a bottle, a cup, a book
  /// and a laptop (medium level) on the desk. The desk itself is there when desk_people > 0 or this.
  bool desk_clutter = false;
};

namespace detail {

inline Mat3<double> rot_z(double a) { return Eigen::AngleAxisd(a, Vec3<double>::UnitZ()).toRotationMatrix(); }
inline Mat3<double> rot_y(double a) { return Eigen::AngleAxisd(a, Vec3<double>::UnitY()).toRotationMatrix(); }
inline Mat3<double> rot_x(double a) { return Eigen::AngleAxisd(a, Vec3<double>::UnitX()).toRotationMatrix(); }

inline Rigid3<double> make_pose(const Mat3<double>& R, const Vec3<double>& t) {
  Rigid3<double> p;
  p.R = R;
  p.t = t;
  return p;
}

/// Appends one primitive given in an actor frame (world_from_actor) at actor_from_part.
struct PrimitiveSink {
  std::vector<Primitive>* out;
  double texture_scale;
  void add(PrimitiveShape shape, const Rigid3<double>& world_from_part, const Vec3<double>& half,
           std::uint16_t instance, bool moving, std::uint32_t texture_seed, double cell_m, const Vec3<double>& albedo) {
    Primitive p;
    p.shape = shape;
    p.half_extents = half;
    p.world_from_local = world_from_part;
    p.instance = instance;
    p.moving = moving ? 1 : 0;
    p.texture_seed = texture_seed;
    p.texture_cell_m = cell_m * texture_scale;
    p.albedo = albedo;
    out->push_back(p);
  }
};

/// A limb hanging from a joint: ellipsoid of length `length` rotated by R about the joint.
inline Rigid3<double> limb(const Vec3<double>& joint, const Mat3<double>& R, double length) {
  return make_pose(R, joint + R * Vec3<double>(0, 0, -0.5 * length));
}

struct Clothes {
  Vec3<double> shirt, trousers, skin;
  std::uint32_t seed;
};

/// Walking person in a frame with x forward, y left, z up, origin on the floor under the pelvis.
inline void add_walker(PrimitiveSink& sink, const Rigid3<double>& world_from_person, double gait_phase,
                       std::uint16_t instance, const Clothes& c) {
  const double swing_leg = 0.45 * std::sin(gait_phase);  // about 26 degrees
  const double swing_arm = -0.35 * std::sin(gait_phase);
  const double bob = 0.02 * std::cos(2.0 * gait_phase);
  auto W = [&](const Rigid3<double>& person_from_part) { return world_from_person * person_from_part; };
  const Mat3<double> I = Mat3<double>::Identity();
  constexpr double kCloth = 0.04, kSkin = 0.04;
  sink.add(PrimitiveShape::Ellipsoid, W(make_pose(I, {0, 0, 0.95 + bob})), {0.11, 0.17, 0.12}, instance, true,
           c.seed + 1, kCloth, c.trousers);
  sink.add(PrimitiveShape::Ellipsoid, W(make_pose(I, {0, 0, 1.27 + bob})), {0.13, 0.21, 0.29}, instance, true,
           c.seed + 2, kCloth, c.shirt);
  sink.add(PrimitiveShape::Ellipsoid, W(make_pose(I, {0, 0, 1.67 + bob})), {0.10, 0.085, 0.12}, instance, true,
           c.seed + 3, kSkin, c.skin);
  for (int side = -1; side <= 1; side += 2) {
    const double s = static_cast<double>(side);
    sink.add(PrimitiveShape::Ellipsoid, W(limb({0, 0.095 * s, 0.92 + bob}, rot_y(s * swing_leg), 0.92)),
             {0.08, 0.08, 0.46}, instance, true, c.seed + 4, kCloth, c.trousers);
    sink.add(PrimitiveShape::Ellipsoid, W(limb({0, 0.25 * s, 1.48 + bob}, rot_y(s * swing_arm), 0.64)),
             {0.055, 0.055, 0.32}, instance, true, c.seed + 5, kCloth, c.shirt);
  }
}

/// Seated person facing x: legs (static) on the seat, upper body swaying and gesturing about the hips.
inline void add_sitting_person(PrimitiveSink& sink, const Rigid3<double>& world_from_person, double t,
                               std::uint16_t instance, const Clothes& c) {
  constexpr double kTwoPi = 6.283185307179586;
  constexpr double kCloth = 0.04, kSkin = 0.04;
  const Mat3<double> I = Mat3<double>::Identity();
  auto W = [&](const Rigid3<double>& person_from_part) { return world_from_person * person_from_part; };
  // Legs and pelvis: static.
  sink.add(PrimitiveShape::Ellipsoid, W(make_pose(I, {0, 0, 0.58})), {0.13, 0.17, 0.10}, instance, false, c.seed + 1,
           kCloth, c.trousers);
  for (int side = -1; side <= 1; side += 2) {
    const double s = static_cast<double>(side);
    sink.add(PrimitiveShape::Ellipsoid, W(make_pose(I, {0.22, 0.1 * s, 0.56})), {0.24, 0.075, 0.075}, instance,
             false, c.seed + 4, kCloth, c.trousers);
    sink.add(PrimitiveShape::Ellipsoid, W(make_pose(I, {0.46, 0.1 * s, 0.27})), {0.06, 0.06, 0.27}, instance, false,
             c.seed + 6, kCloth, c.trousers);
  }
  // Upper body pivots about the hips: continuous sway, so it moves at every frame.
  const double yaw = 0.26 * std::sin(kTwoPi * t / 4.1);
  const double pitch = 0.17 * std::sin(kTwoPi * t / 2.9) + 0.08;
  const Rigid3<double> person_from_upper = make_pose(rot_z(yaw) * rot_y(pitch), {0, 0, 0.62});
  auto U = [&](const Rigid3<double>& upper_from_part) { return world_from_person * person_from_upper * upper_from_part; };
  sink.add(PrimitiveShape::Ellipsoid, U(make_pose(I, {0, 0, 0.31})), {0.13, 0.21, 0.29}, instance, true, c.seed + 2,
           kCloth, c.shirt);
  sink.add(PrimitiveShape::Ellipsoid, U(make_pose(I, {0, 0, 0.72})), {0.10, 0.085, 0.12}, instance, true, c.seed + 3,
           kSkin, c.skin);
  for (int side = -1; side <= 1; side += 2) {
    const double s = static_cast<double>(side);
    const double gesture = -0.6 - 0.45 * std::sin(kTwoPi * t / 1.7 + (s > 0 ? 0.0 : 2.0));
    sink.add(PrimitiveShape::Ellipsoid, U(limb({0, 0.25 * s, 0.52}, rot_y(gesture), 0.64)), {0.055, 0.055, 0.32},
             instance, true, c.seed + 5, kCloth, c.shirt);
  }
}

/// Chair facing x (the sitter looks along x), origin on the floor under the seat centre.
inline void add_chair(PrimitiveSink& sink, const Rigid3<double>& world_from_chair, std::uint16_t instance, bool moving,
                      std::uint32_t seed) {
  const Mat3<double> I = Mat3<double>::Identity();
  const Vec3<double> wood(0.75, 0.55, 0.35);
  constexpr double kCell = 0.05;
  auto W = [&](const Vec3<double>& centre) { return world_from_chair * make_pose(I, centre); };
  sink.add(PrimitiveShape::Box, W({0, 0, 0.45}), {0.22, 0.22, 0.03}, instance, moving, seed + 1, kCell, wood);
  sink.add(PrimitiveShape::Box, W({-0.2, 0, 0.75}), {0.03, 0.22, 0.27}, instance, moving, seed + 2, kCell, wood);
  for (int k = 0; k < 4; ++k) {
    const double x = (k & 1) ? 0.18 : -0.18, y = (k & 2) ? 0.18 : -0.18;
    sink.add(PrimitiveShape::Box, W({x, y, 0.21}), {0.02, 0.02, 0.21}, instance, moving, seed + 3, kCell, wood);
  }
}

/// Motion of one desk person at time t: angles in radians, all scaled by `scale`. `phase` (seconds)
/// offsets the person's clocks so two people do not move in step.
struct DeskMotion {
  double sway_yaw = 0, sway_pitch = 0;  ///< upper body about the hips
  double head_yaw = 0;                  ///< head about the neck, relative to the upper body
  double arm[2] = {0, 0};               ///< shoulder pitch of the right (0) and left (1) arm, added to the rest pose
  double swivel = 0;                    ///< chair (and whole person) about the vertical through the seat
  bool swivel_moving = false;           ///< the swivel changes somewhere in (t - dt, t + dt)
  bool upper_moving = false;            ///< upper body, head and arms move (scale != 0)
};

/// Swivel profile over one 9 s cycle: out over 1.2 s, hold, back over 1.2 s, rest. Episodic, so
/// legs and chair are still most of the time as in the real sequences.
inline double desk_swivel_profile(double t) {
  constexpr double kPeriod = 9.0;
  double c = std::fmod(t, kPeriod);
  if (c < 0) c += kPeriod;
  auto ramp = [](double x) {
    x = x < 0 ? 0 : (x > 1 ? 1 : x);
    return x * x * (3.0 - 2.0 * x);
  };
  return ramp(c / 1.2) - ramp((c - 4.5) / 1.2);
}

inline DeskMotion desk_motion(double t, double dt, double phase, double scale) {
  constexpr double kTwoPi = 6.283185307179586;
  const double u = t + phase;
  DeskMotion m;
  m.sway_yaw = scale * 0.08 * std::sin(kTwoPi * u / 5.3);
  m.sway_pitch = scale * (0.05 * std::sin(kTwoPi * u / 3.7) + 0.02 * std::sin(kTwoPi * u / 1.3));
  m.head_yaw = scale * 0.45 * std::sin(kTwoPi * u / 6.1) * std::sin(kTwoPi * u / 6.1);  // looks aside, returns
  // Gestures come in bursts: the envelope is zero a third of each cycle.
  const double envelope = std::max(0.0, std::sin(kTwoPi * u / 4.7));
  m.arm[0] = scale * -0.9 * envelope * (0.6 + 0.4 * std::sin(kTwoPi * u / 1.1));
  m.arm[1] = scale * -0.35 * std::max(0.0, std::sin(kTwoPi * u / 7.9 + 1.0));
  m.swivel = scale * 0.3 * (desk_swivel_profile(u) - 0.5);
  m.upper_moving = scale != 0;
  if (scale != 0) {
    // Moving when the profile differs at either end of the window (sampled finely: ramps are 1.2 s).
    const double p0 = desk_swivel_profile(u);
    for (int k = -4; k <= 4 && !m.swivel_moving; ++k)
      m.swivel_moving = desk_swivel_profile(u + dt * k / 4.0) != p0;
  }
  return m;
}

/// Person seated at the desk, facing x, on a swivel chair (origin on the floor under the seat).
/// Legs and pelvis move only with the swivel; upper body, head and arms move all the time.
inline void add_desk_person(PrimitiveSink& sink, const Rigid3<double>& world_from_seat, const DeskMotion& m,
                            std::uint16_t instance, std::uint16_t chair_instance, const Clothes& c,
                            std::uint32_t chair_seed) {
  constexpr double kCloth = 0.04, kSkin = 0.04;
  const Mat3<double> I = Mat3<double>::Identity();
  const Rigid3<double> world_from_person = world_from_seat * make_pose(rot_z(m.swivel), Vec3<double>::Zero());
  add_chair(sink, world_from_person, chair_instance, m.swivel_moving, chair_seed);
  auto W = [&](const Rigid3<double>& person_from_part) { return world_from_person * person_from_part; };
  const bool legs_move = m.swivel_moving;
  sink.add(PrimitiveShape::Ellipsoid, W(make_pose(I, {0, 0, 0.58})), {0.13, 0.17, 0.10}, instance, legs_move,
           c.seed + 1, kCloth, c.trousers);
  for (int side = -1; side <= 1; side += 2) {
    const double s = static_cast<double>(side);
    sink.add(PrimitiveShape::Ellipsoid, W(make_pose(I, {0.22, 0.1 * s, 0.56})), {0.24, 0.075, 0.075}, instance,
             legs_move, c.seed + 4, kCloth, c.trousers);
    sink.add(PrimitiveShape::Ellipsoid, W(make_pose(I, {0.46, 0.1 * s, 0.27})), {0.06, 0.06, 0.27}, instance,
             legs_move, c.seed + 6, kCloth, c.trousers);
  }
  const Rigid3<double> person_from_upper = make_pose(rot_z(m.sway_yaw) * rot_y(m.sway_pitch + 0.05), {0, 0, 0.62});
  auto U = [&](const Rigid3<double>& upper_from_part) { return world_from_person * person_from_upper * upper_from_part; };
  sink.add(PrimitiveShape::Ellipsoid, U(make_pose(I, {0, 0, 0.31})), {0.13, 0.21, 0.29}, instance, m.upper_moving, c.seed + 2,
           kCloth, c.shirt);
  sink.add(PrimitiveShape::Ellipsoid, U(make_pose(rot_z(m.head_yaw), {0, 0, 0.72})), {0.10, 0.085, 0.12}, instance,
           m.upper_moving, c.seed + 3, kSkin, c.skin);
  for (int side = -1; side <= 1; side += 2) {
    const double s = static_cast<double>(side);
    const double pitch = -0.35 + m.arm[side > 0 ? 1 : 0];  // arms rest forward on the lap
    sink.add(PrimitiveShape::Ellipsoid, U(limb({0, 0.25 * s, 0.52}, rot_y(pitch) * rot_x(-0.12 * s), 0.64)),
             {0.055, 0.055, 0.32}, instance, m.upper_moving, c.seed + 5, kCloth, c.shirt);
  }
}

/// Static desk clutter on a desk whose top is at height `top` (world frame of the desk: x along the
/// desk, y away from the camera, origin on the floor under the desk centre).
inline void add_desk_clutter(PrimitiveSink& sink, const Rigid3<double>& world_from_desk, double top,
                             std::uint32_t seed) {
  const Mat3<double> I = Mat3<double>::Identity();
  auto W = [&](const Mat3<double>& R, const Vec3<double>& centre) { return world_from_desk * make_pose(R, centre); };
  auto box = [&](const Mat3<double>& R, const Vec3<double>& centre, const Vec3<double>& half, std::uint16_t id,
                 std::uint32_t k, double cell, const Vec3<double>& albedo) {
    sink.add(PrimitiveShape::Box, W(R, centre), half, id, false, seed + k, cell, albedo);
  };
  const Vec3<double> dark(0.25, 0.25, 0.28), screen(0.45, 0.55, 0.75), grey(0.6, 0.6, 0.62);
  for (int k = 0; k < 2; ++k) {
    const double x = k == 0 ? -0.55 : 0.55;
    const Mat3<double> R = rot_z(k == 0 ? 0.25 : -0.25);  // turned towards the desk's middle
    const auto id = static_cast<std::uint16_t>(SceneInstance::kMonitorA + k);
    box(R, {x, 0.22, top + 0.38}, {0.28, 0.025, 0.19}, id, 10u + k, 0.05, screen);  // screen
    box(I, {x, 0.24, top + 0.1}, {0.04, 0.03, 0.1}, id, 12u + k, 0.05, dark);      // stand
    box(I, {x, 0.22, top + 0.01}, {0.12, 0.09, 0.01}, id, 14u + k, 0.05, dark);    // foot
    box(R, {x, -0.12, top + 0.016}, {0.23, 0.08, 0.016}, static_cast<std::uint16_t>(SceneInstance::kKeyboardA + k),
        16u + k, 0.02, grey);
    box(I, {k == 0 ? x + 0.32 : x - 0.36, k == 0 ? -0.27 : -0.12, top + 0.022}, {0.04, 0.06, 0.022},
        static_cast<std::uint16_t>(SceneInstance::kMouseA + k), 18u + k, 0.02, dark);
  }
  box(I, {0.3, 0.06, top + 0.13}, {0.04, 0.04, 0.13}, SceneInstance::kBottle, 20u, 0.03, {0.4, 0.7, 0.5});
  box(I, {0.1, 0.0, top + 0.055}, {0.045, 0.045, 0.055}, SceneInstance::kCup, 21u, 0.02, {0.9, 0.9, 0.85});
  box(rot_z(0.4), {0.0, -0.2, top + 0.025}, {0.1, 0.13, 0.025}, SceneInstance::kBook, 22u, 0.03, {0.8, 0.3, 0.3});
  // Laptop: base on the desk, lid open at 110 degrees.
  box(I, {-0.05, 0.12, top + 0.01}, {0.17, 0.12, 0.01}, SceneInstance::kLaptop, 23u, 0.03, grey);
  box(rot_x(-0.35), {-0.05, 0.27, top + 0.12}, {0.17, 0.01, 0.115}, SceneInstance::kLaptop, 24u, 0.03, dark);
}

inline double smoothstep(double x) {
  x = x < 0 ? 0 : (x > 1 ? 1 : x);
  return x * x * (3.0 - 2.0 * x);
}

}  // namespace detail

/// Pose of the pushed chair at time t (world_from_chair): rests, slides 0.5 m while turning, rests.
inline Rigid3<double> pushed_chair_pose(double t, const ActorOptions& options) {
  const double span = options.push_end_s - options.push_start_s;
  const double s = span > 0 ? detail::smoothstep((t - options.push_start_s) / span) : (t >= options.push_end_s ? 1 : 0);
  const Vec3<double> p0(0.95, 2.0, 0.0), p1(1.25, 2.4, 0.0);
  return detail::make_pose(detail::rot_z(3.6 + 0.6 * s), p0 + s * (p1 - p0));
}

/// Walking person's world_from_person and gait phase at time t on the elliptic loop.
inline Rigid3<double> walker_pose(double t, int walker, const ActorOptions& options, std::uint64_t seed,
                                  double* gait_phase) {
  const double a = options.loop_semi_axes_m.x(), b = options.loop_semi_axes_m.y();
  const double mean_radius = std::sqrt(0.5 * (a * a + b * b));
  const double omega = options.walking_speed_mps / mean_radius;
  // Walker B follows walker A by walker_gap_rad on the loop; the seed shifts the start by up to ~0.3 rad.
  const double phase0 = options.walker_start_phase_rad - options.walker_gap_rad * walker +
                        0.3 * static_cast<double>(seed % 97) / 97.0;
  const double phi = phase0 + omega * t;
  const Vec3<double> pos(options.loop_centre_m.x() + a * std::cos(phi), options.loop_centre_m.y() + b * std::sin(phi),
                         0.0);
  const double heading = std::atan2(b * std::cos(phi), -a * std::sin(phi));
  constexpr double kStrideM = 1.4;  // one gait cycle (two steps)
  if (gait_phase) *gait_phase = 6.283185307179586 * omega * mean_radius * t / kStrideM + phase0;
  return detail::make_pose(detail::rot_z(heading), pos);
}

/// True when the pushed chair moves at some instant of the open interval (t - dt, t + dt).
inline bool chair_moving_near(double t, double dt, const ActorOptions& options) {
  return options.push_end_s > options.push_start_s && t + dt > options.push_start_s && t - dt < options.push_end_s;
}

/// All primitives of the scene at time t (seconds from the first frame); `frame_dt` is the frame
/// period, used to flag the chair as moving in the frames next to its motion.
inline void build_scene(double t, double frame_dt, std::uint64_t seed, const ActorOptions& options,
                        std::vector<Primitive>* out) {
  out->clear();
  detail::PrimitiveSink sink{out, options.texture_scale};
  const auto tex = static_cast<std::uint32_t>(seed * 0x9E3779B1u);
  const Mat3<double> I = Mat3<double>::Identity();
  using detail::make_pose;
  constexpr std::uint16_t kBg = SceneInstance::kBackground;
  // Room: x in [-3, 3], y in [-1.5, 4.6], z in [0, 2.8].
  sink.add(PrimitiveShape::RoomInterior, make_pose(I, {0, 1.55, 1.4}), {3.0, 3.05, 1.4}, kBg, false, tex + 100, 0.2,
           {0.85, 0.82, 0.75});
  out->back().texture_contrast = options.wall_contrast;
  // Furniture: cabinet under the TV, desk, shelf, two posters.
  sink.add(PrimitiveShape::Box, make_pose(I, {0, 4.3, 0.35}), {0.8, 0.25, 0.35}, kBg, false, tex + 110, 0.08,
           {0.6, 0.45, 0.35});
  sink.add(PrimitiveShape::Box, make_pose(detail::rot_z(0.3), {1.9, 3.5, 0.37}), {0.7, 0.4, 0.37}, kBg, false,
           tex + 120, 0.08, {0.8, 0.8, 0.7});
  sink.add(PrimitiveShape::Box, make_pose(I, {-2.6, 3.6, 0.95}), {0.3, 0.6, 0.95}, kBg, false, tex + 130, 0.07,
           {0.7, 0.6, 0.5});
  sink.add(PrimitiveShape::Box, make_pose(I, {-1.3, 4.57, 1.6}), {0.5, 0.02, 0.35}, kBg, false, tex + 140, 0.05,
           {0.9, 0.7, 0.5});
  sink.add(PrimitiveShape::Box, make_pose(I, {2.97, 2.0, 1.5}), {0.02, 0.6, 0.4}, kBg, false, tex + 150, 0.05,
           {0.5, 0.7, 0.9});
  // TV (low-level dynamic class, static here) on the cabinet.
  sink.add(PrimitiveShape::Box, make_pose(I, {0, 4.35, 1.03}), {0.55, 0.04, 0.33}, SceneInstance::kTv, false,
           tex + 160, 0.06, {0.6, 0.7, 0.9});
  // Sitting person on a chair, facing the walking loop at an angle.
  if (options.sitting_person) {
    const Rigid3<double> seat = make_pose(detail::rot_z(-0.9), {-1.35, 2.7, 0});
    detail::add_chair(sink, seat, SceneInstance::kSittingChair, false, tex + 200);
    detail::add_sitting_person(sink, seat, t, SceneInstance::kSittingPerson,
                               {{0.55, 0.75, 0.9}, {0.45, 0.45, 0.5}, {0.9, 0.75, 0.6}, tex + 300});
  }
  if (options.pushed_chair) {
    detail::add_chair(sink, pushed_chair_pose(t, options), SceneInstance::kPushedChair,
                      chair_moving_near(t, frame_dt, options), tex + 400);
  }
  const detail::Clothes clothes[4] = {{{0.9, 0.4, 0.35}, {0.35, 0.4, 0.75}, {0.9, 0.75, 0.6}, tex + 500},
                                      {{0.4, 0.8, 0.45}, {0.55, 0.5, 0.45}, {0.8, 0.65, 0.5}, tex + 600},
                                      {{0.85, 0.8, 0.35}, {0.3, 0.3, 0.35}, {0.7, 0.55, 0.45}, tex + 700},
                                      {{0.6, 0.45, 0.8}, {0.5, 0.35, 0.3}, {0.95, 0.8, 0.7}, tex + 800}};
  for (int w = 0; w < options.walking_people && w < 4; ++w) {
    double gait = 0;
    const Rigid3<double> pose = walker_pose(t, w, options, seed, &gait);
    detail::add_walker(sink, pose, gait, SceneInstance::walker(w), clothes[w]);
  }
  if (options.desk_people > 0 || options.desk_clutter) {
    // Desk across the view 2.1 m in front of the rest pose, top at 0.73 m; its people sit in front
    // of it, turned towards each other and the desk.
    const Rigid3<double> world_from_desk = make_pose(I, {0.05, 2.05, 0.0});
    constexpr double kTop = 0.73;
    sink.add(PrimitiveShape::Box, world_from_desk * make_pose(I, {0, 0, 0.5 * kTop}), {1.3, 0.35, 0.5 * kTop}, kBg,
             false, tex + 900, 0.07, {0.75, 0.7, 0.6});
    if (options.desk_clutter) detail::add_desk_clutter(sink, world_from_desk, kTop, tex + 1000);
    const detail::Clothes desk_clothes[2] = {{{0.3, 0.35, 0.6}, {0.25, 0.25, 0.3}, {0.85, 0.7, 0.55}, tex + 1100},
                                             {{0.8, 0.75, 0.7}, {0.35, 0.3, 0.25}, {0.75, 0.6, 0.5}, tex + 1200}};
    const Rigid3<double> seats[2] = {make_pose(detail::rot_z(0.55), {-0.7, 0.92, 0.0}),
                                     make_pose(detail::rot_z(3.141592653589793 - 0.75), {0.55, 1.02, 0.0})};
    for (int k = 0; k < options.desk_people && k < 2; ++k) {
      const double phase = 2.3 * k + 0.37 * static_cast<double>(seed % 13);
      const detail::DeskMotion m = detail::desk_motion(t, frame_dt, phase, options.desk_motion_scale);
      detail::add_desk_person(sink, seats[k], m, static_cast<std::uint16_t>(SceneInstance::kDeskPersonA + k),
                              static_cast<std::uint16_t>(SceneInstance::kDeskChairA + k), desk_clothes[k],
                              tex + 1300 + 100 * static_cast<std::uint32_t>(k));
    }
  }
}

}  // namespace dyncull::sim
