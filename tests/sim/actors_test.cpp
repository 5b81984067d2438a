// The scene's actors: COCO classes of the instances, which primitives move (walkers yes, the sitting
// person's upper body only, the pushed chair only while pushed, the room never), the walkers' speed
// on the floor, and the actor options.
#include "dyncull/sim/actors.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <vector>

namespace dyncull::sim {
namespace {

constexpr double kDt = 1.0 / 30.0;

TEST(SimActors, InstancesMapToTheirCocoClasses) {
  EXPECT_EQ(instance_class(SceneInstance::kBackground), -1);
  EXPECT_EQ(instance_class(SceneInstance::kWalkerA), CocoClass::kPerson);
  EXPECT_EQ(instance_class(SceneInstance::kWalkerB), CocoClass::kPerson);
  EXPECT_EQ(instance_class(SceneInstance::kSittingPerson), CocoClass::kPerson);
  EXPECT_EQ(instance_class(SceneInstance::kPushedChair), CocoClass::kChair);
  EXPECT_EQ(instance_class(SceneInstance::kSittingChair), CocoClass::kChair);
  EXPECT_EQ(instance_class(SceneInstance::kTv), CocoClass::kTv);
  EXPECT_EQ(instance_class(SceneInstance::kCount), -1);
}

struct Motion {
  std::size_t moving = 0, still = 0;
};

std::vector<Motion> motion_by_instance(double t, const ActorOptions& options) {
  std::vector<Primitive> prims;
  build_scene(t, kDt, 1, options, &prims);
  std::vector<Motion> m(SceneInstance::kCount);
  for (const Primitive& p : prims) {
    EXPECT_LT(p.instance, SceneInstance::kCount);
    if (p.instance >= SceneInstance::kCount) continue;
    (p.moving ? m[p.instance].moving : m[p.instance].still) += 1;
  }
  return m;
}

TEST(SimActors, MovingFlagsFollowWhatMoves) {
  const ActorOptions o;
  const double before = 0.5 * o.push_start_s, during = 0.5 * (o.push_start_s + o.push_end_s), after = o.push_end_s + 1.0;
  for (double t : {before, during, after}) {
    const auto m = motion_by_instance(t, o);
    EXPECT_EQ(m[SceneInstance::kBackground].moving, 0u) << "t " << t;
    EXPECT_GT(m[SceneInstance::kBackground].still, 0u);
    EXPECT_EQ(m[SceneInstance::kTv].moving, 0u);
    EXPECT_EQ(m[SceneInstance::kSittingChair].moving, 0u);
    for (int w = 0; w < o.walking_people; ++w) {
      const auto id = static_cast<std::uint16_t>(SceneInstance::kWalkerA + w);
      EXPECT_GT(m[id].moving, 0u) << "walker " << w << " t " << t;
    }
    // The case of DFD-SLAM's Figure 8 (Qian et al. 2024): the seated person's legs stay, the upper body moves.
    EXPECT_GT(m[SceneInstance::kSittingPerson].moving, 0u);
    EXPECT_GT(m[SceneInstance::kSittingPerson].still, 0u);
  }
  EXPECT_EQ(motion_by_instance(before, o)[SceneInstance::kPushedChair].moving, 0u);
  EXPECT_GT(motion_by_instance(during, o)[SceneInstance::kPushedChair].moving, 0u);
  EXPECT_EQ(motion_by_instance(after, o)[SceneInstance::kPushedChair].moving, 0u);
}

TEST(SimActors, PushedChairMovesOnlyWhilePushed) {
  const ActorOptions o;
  const auto p0 = pushed_chair_pose(o.push_start_s - 1.0, o), p1 = pushed_chair_pose(o.push_start_s - 0.5, o);
  const auto q0 = pushed_chair_pose(o.push_end_s + 0.5, o), q1 = pushed_chair_pose(o.push_end_s + 1.0, o);
  EXPECT_EQ(p0.t, p1.t);
  EXPECT_EQ(q0.t, q1.t);
  EXPECT_GT((q0.t - p0.t).norm(), 0.1);  // it went somewhere
  EXPECT_FALSE(chair_moving_near(o.push_start_s - 1.0, kDt, o));
  EXPECT_TRUE(chair_moving_near(0.5 * (o.push_start_s + o.push_end_s), kDt, o));
  EXPECT_FALSE(chair_moving_near(o.push_end_s + 1.0, kDt, o));
}

TEST(SimActors, WalkersStayOnTheFloorAtTheirWalkingSpeed) {
  const ActorOptions o;
  for (int w = 0; w < o.walking_people; ++w) {
    double path = 0;
    Rigid3<double> previous = walker_pose(0.0, w, o, 1, nullptr);
    for (int i = 1; i <= 600; ++i) {
      const Rigid3<double> pose = walker_pose(i * kDt, w, o, 1, nullptr);
      EXPECT_NEAR(pose.t.z(), 0.0, 1e-12);
      EXPECT_NEAR(pose.R.col(2).z(), 1.0, 1e-12);  // upright
      path += (pose.t - previous.t).norm();
      previous = pose;
    }
    EXPECT_NEAR(path / (600 * kDt), o.walking_speed_mps, 0.15 * o.walking_speed_mps) << "walker " << w;
  }
}

TEST(SimActors, OptionsChooseTheActors) {
  ActorOptions o;
  o.walking_people = 1;
  o.sitting_person = false;
  o.pushed_chair = false;
  std::vector<Primitive> prims;
  build_scene(1.0, kDt, 1, o, &prims);
  std::set<std::uint16_t> present;
  for (const Primitive& p : prims) present.insert(p.instance);
  EXPECT_TRUE(present.count(SceneInstance::kWalkerA));
  EXPECT_FALSE(present.count(SceneInstance::kWalkerB));
  EXPECT_FALSE(present.count(SceneInstance::kSittingPerson));
  EXPECT_FALSE(present.count(SceneInstance::kPushedChair));
  EXPECT_TRUE(present.count(SceneInstance::kTv));
}

}  // namespace
}  // namespace dyncull::sim
