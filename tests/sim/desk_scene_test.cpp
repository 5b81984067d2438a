// The scene modelled on TUM fr3/sitting_*: two people seated at a desk (sway, head turns, gestures,
// a chair swivel now and then) with monitors, keyboards, mice, a bottle, a cup, a book and a laptop;
// and a crowd of up to four walkers. Ids, classes, moving truth against the actual motion, instance
// masks and detections, the people's share of the image, determinism and option checks.
#include "dyncull/sim/scene.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <vector>

namespace dyncull::sim {
namespace {

constexpr double kDeskFrameDt = 1.0 / 30.0;

ActorOptions desk_actors() {
  ActorOptions a;
  a.walking_people = 0;
  a.sitting_person = false;
  a.pushed_chair = false;
  a.desk_people = 2;
  a.desk_clutter = true;
  return a;
}

SceneOptions desk_scene(int width, int height, int frames) {
  SceneOptions o;
  o.width = width;
  o.height = height;
  o.num_frames = frames;
  o.motion = CameraMotion::Static;
  o.actors = desk_actors();
  o.box_jitter_px = 0;
  o.miss_rate = 0;
  o.false_positive_rate = 0;
  o.min_detection_pixels = 300 * width * height / (640 * 480);
  return o;
}

const std::uint16_t kClutter[] = {SceneInstance::kMonitorA,  SceneInstance::kMonitorB, SceneInstance::kKeyboardA,
                                  SceneInstance::kKeyboardB, SceneInstance::kMouseA,   SceneInstance::kMouseB,
                                  SceneInstance::kBottle,    SceneInstance::kCup,      SceneInstance::kBook,
                                  SceneInstance::kLaptop};

TEST(SimDeskScene, DeskAndWalkerInstancesMapToTheirCocoClasses) {
  EXPECT_EQ(instance_class(SceneInstance::kDeskPersonA), CocoClass::kPerson);
  EXPECT_EQ(instance_class(SceneInstance::kDeskPersonB), CocoClass::kPerson);
  EXPECT_EQ(instance_class(SceneInstance::kDeskChairA), CocoClass::kChair);
  EXPECT_EQ(instance_class(SceneInstance::kDeskChairB), CocoClass::kChair);
  EXPECT_EQ(instance_class(SceneInstance::kMonitorA), CocoClass::kTv);
  EXPECT_EQ(instance_class(SceneInstance::kMonitorB), CocoClass::kTv);
  EXPECT_EQ(instance_class(SceneInstance::kKeyboardA), 66);  // COCO-80 0-based, as motion_levels.hpp
  EXPECT_EQ(instance_class(SceneInstance::kMouseB), 64);
  EXPECT_EQ(instance_class(SceneInstance::kBottle), 39);
  EXPECT_EQ(instance_class(SceneInstance::kCup), 41);
  EXPECT_EQ(instance_class(SceneInstance::kBook), 73);
  EXPECT_EQ(instance_class(SceneInstance::kLaptop), 63);
  for (int w = 0; w < 4; ++w) EXPECT_EQ(instance_class(SceneInstance::walker(w)), CocoClass::kPerson);
  EXPECT_EQ(SceneInstance::walker(0), SceneInstance::kWalkerA);
  EXPECT_EQ(SceneInstance::walker(1), SceneInstance::kWalkerB);
  EXPECT_EQ(SceneInstance::walker(3), SceneInstance::kWalkerD);
  for (int id = 1; id < SceneInstance::kCount; ++id) EXPECT_GE(instance_class(static_cast<std::uint16_t>(id)), 0) << id;
}

TEST(SimDeskScene, DefaultSceneHasNoDeskActorsOrExtraWalkers) {
  std::vector<Primitive> prims;
  build_scene(2.0, kDeskFrameDt, 1, ActorOptions{}, &prims);
  for (const Primitive& p : prims) EXPECT_LE(p.instance, SceneInstance::kTv);
}

// The moving flag of every desk primitive says whether it moved within a frame of t: flagged
// primitives moved against a neighbouring frame, unflagged ones did not.
TEST(SimDeskScene, MovingTruthFollowsTheActualMotionAndTheSwivelIsEpisodic) {
  const ActorOptions o = desk_actors();
  std::size_t legs_moving = 0, legs_still = 0, chair_moving = 0, samples = 0;
  for (int i = 1; i < 600; ++i) {  // 20 s: two swivel cycles of each person
    std::vector<Primitive> before, now, after;
    build_scene((i - 1) * kDeskFrameDt, kDeskFrameDt, 7, o, &before);
    build_scene(i * kDeskFrameDt, kDeskFrameDt, 7, o, &now);
    build_scene((i + 1) * kDeskFrameDt, kDeskFrameDt, 7, o, &after);
    ASSERT_EQ(before.size(), now.size());
    ASSERT_EQ(after.size(), now.size());
    for (std::size_t k = 0; k < now.size(); ++k) {
      const Primitive& p = now[k];
      auto moved = [&](const Primitive& q) {
        return (q.world_from_local.t - p.world_from_local.t).norm() + (q.world_from_local.R - p.world_from_local.R).norm() >
               1e-12;
      };
      const bool actually = moved(before[k]) || moved(after[k]);
      if (p.moving) {
        EXPECT_TRUE(actually) << "primitive " << k << " of instance " << p.instance << " flagged but still at frame " << i;
      } else {
        EXPECT_FALSE(actually) << "primitive " << k << " of instance " << p.instance << " moved unflagged at frame " << i;
      }
      const bool clutter = std::find(std::begin(kClutter), std::end(kClutter), p.instance) != std::end(kClutter);
      if (clutter || p.instance == SceneInstance::kBackground) {
        EXPECT_EQ(p.moving, 0) << "instance " << p.instance;
      }
    }
    for (const Primitive& p : now) {
      if (p.instance == SceneInstance::kDeskChairA) {
        chair_moving += p.moving;
        ++samples;
      }
    }
    // Pelvis of person A (its first primitive): still unless swivelling.
    for (std::size_t k = 0; k < now.size(); ++k) {
      if (now[k].instance == SceneInstance::kDeskPersonA) {
        (now[k].moving ? legs_moving : legs_still) += 1;
        break;
      }
    }
  }
  // Two 1.2 s turns per 9 s cycle (plus a frame each side): the legs move in a quarter to a third of
  // the frames, with the chair.
  const double share = static_cast<double>(legs_moving) / static_cast<double>(legs_moving + legs_still);
  EXPECT_GT(share, 0.2);
  EXPECT_LT(share, 0.4);
  EXPECT_EQ(samples, 6u * 599u);                 // the chair's six boxes in every frame
  EXPECT_EQ(chair_moving, 6u * legs_moving);     // ... moving exactly when the legs do
}

TEST(SimDeskScene, StillOptionFreezesThePeople) {
  ActorOptions o = desk_actors();
  o.desk_motion_scale = 0;
  std::vector<Primitive> a, b;
  build_scene(1.0, kDeskFrameDt, 3, o, &a);
  build_scene(4.0, kDeskFrameDt, 3, o, &b);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].moving, 0);
    EXPECT_EQ(a[k].world_from_local.t, b[k].world_from_local.t);
  }
}

TEST(SimDeskScene, MasksAndDetectionsCoverThePeopleAndTheClutter) {
  const SceneOptions o = desk_scene(320, 240, 90);
  const Scene scene(o);
  ASSERT_TRUE(scene.ok()) << scene.reason();
  FrameData f;
  std::vector<int> frames_detected(SceneInstance::kCount, 0), frames_visible(SceneInstance::kCount, 0);
  std::vector<int> still_legs(SceneInstance::kCount, 0);
  int frames = 0;
  double area = 0;
  for (int i = 0; i < o.num_frames; i += 6, ++frames) {
    scene.render(i, &f);
    ASSERT_TRUE(f.ok()) << f.reason;
    std::vector<long long> count(SceneInstance::kCount, 0);
    std::vector<int> moving(SceneInstance::kCount, 0);
    for (std::size_t p = 0; p < f.instance.size(); ++p) {
      ++count[f.instance[p]];
      moving[f.instance[p]] += f.moving[p];
    }
    for (std::uint16_t id : kClutter) EXPECT_EQ(moving[id], 0) << "instance " << id;
    for (std::uint16_t id : {SceneInstance::kDeskPersonA, SceneInstance::kDeskPersonB}) {
      EXPECT_GT(moving[id], 0) << "upper body of " << id << " at frame " << i;
      still_legs[id] += moving[id] < count[id] ? 1 : 0;
    }
    // With no jitter and no misses, each visible instance gives one detection of its class whose box
    // is the tight box of its mask.
    std::multiset<int> classes;
    for (const auto& d : f.detections) classes.insert(d.class_id);
    for (int id = 1; id < SceneInstance::kCount; ++id) {
      if (count[static_cast<std::size_t>(id)] < o.min_detection_pixels) continue;
      ++frames_visible[static_cast<std::size_t>(id)];
      if (classes.count(instance_class(static_cast<std::uint16_t>(id)))) ++frames_detected[static_cast<std::size_t>(id)];
    }
    for (const auto& d : f.detections) {
      if (d.class_id == CocoClass::kPerson) area += static_cast<double>((d.box.x1 - d.box.x0 + 1) * (d.box.y1 - d.box.y0 + 1));
    }
  }
  area /= static_cast<double>(frames) * o.width * o.height;
  // Two seated people cover about half of the image, as on fr3/sitting_static (mean 0.546).
  EXPECT_GT(area, 0.49);
  EXPECT_LT(area, 0.6);
  // Every clutter object and both people are visible in (almost) every frame and detected there.
  for (std::uint16_t id : kClutter) EXPECT_GE(frames_visible[id], frames - 1) << "instance " << id;
  for (std::uint16_t id : {SceneInstance::kDeskPersonA, SceneInstance::kDeskPersonB}) {
    EXPECT_EQ(frames_visible[id], frames);
    // Legs still (not flagged moving) outside the swivels: in most of these 3 s.
    EXPECT_GT(2 * still_legs[id], frames) << "instance " << id;
  }
  for (int id = 1; id < SceneInstance::kCount; ++id) EXPECT_EQ(frames_detected[id], frames_visible[id]) << id;
}

TEST(SimDeskScene, DeterministicForASeedAndDifferentAcrossSeeds) {
  SceneOptions o = desk_scene(96, 72, 40);
  FrameData a, b, c;
  Scene(o).render(33, &a);
  Scene(o).render(33, &b);
  o.seed = 2;
  Scene(o).render(33, &c);
  EXPECT_EQ(a.rgb, b.rgb);
  EXPECT_EQ(a.instance, b.instance);
  EXPECT_NE(a.instance, c.instance);  // the people's clocks depend on the seed
}

TEST(SimDeskScene, CrowdOfFourWalkersHasFourPeople) {
  ActorOptions o;
  o.walking_people = 4;
  o.walker_gap_rad = 1.5;
  std::vector<Primitive> prims;
  std::set<std::uint16_t> present;
  build_scene(1.0, kDeskFrameDt, 1, o, &prims);
  for (const Primitive& p : prims) present.insert(p.instance);
  for (int w = 0; w < 4; ++w) EXPECT_TRUE(present.count(SceneInstance::walker(w))) << "walker " << w;
  // Each walker is its own body on the loop (walker_gap_rad apart in phase; a crowd wants a gap
  // near 2 pi / 4 so that bodies do not touch at the loop's narrow ends).
  std::vector<Vec3<double>> pelvis;
  for (int w = 0; w < 4; ++w) pelvis.push_back(walker_pose(1.0, w, o, 1, nullptr).t);
  for (int a = 0; a < 4; ++a)
    for (int b = a + 1; b < 4; ++b) EXPECT_GT((pelvis[static_cast<std::size_t>(a)] - pelvis[static_cast<std::size_t>(b)]).norm(), 0.3);
  SceneOptions so;
  so.actors = o;
  so.width = 64;
  so.height = 48;
  EXPECT_TRUE(Scene(so).ok()) << Scene(so).reason();
}

TEST(SimDeskScene, BadActorOptionsAreNamed) {
  const std::pair<void (*)(SceneOptions*), const char*> cases[] = {
      {[](SceneOptions* o) { o->actors.walking_people = 5; }, "actors.walking_people"},
      {[](SceneOptions* o) { o->actors.walking_people = -1; }, "actors.walking_people"},
      {[](SceneOptions* o) { o->actors.desk_people = 3; }, "actors.desk_people"},
      {[](SceneOptions* o) { o->actors.desk_motion_scale = std::nan(""); }, "actors.desk_motion_scale"},
      {[](SceneOptions* o) { o->actors.desk_motion_scale = -1; }, "actors.desk_motion_scale"},
      {[](SceneOptions* o) { o->motion = static_cast<CameraMotion>(17); }, "motion"},
  };
  for (const auto& [set, field] : cases) {
    SceneOptions o;
    set(&o);
    std::string why;
    EXPECT_EQ(o.validate(&why), Status::InvalidInput) << field;
    EXPECT_EQ(why.rfind(field, 0), 0u) << why;
  }
}

}  // namespace
}  // namespace dyncull::sim
