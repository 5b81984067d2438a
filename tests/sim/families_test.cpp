// Tests of the named scene families: each validates and renders with every camera motion, is the
// text of its keys (so --scene can rebuild it), and differs from the default scene the way its name says.
#include "dyncull/sim/families.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <set>
#include <string>
#include <vector>

namespace {

using dyncull::Status;
using namespace dyncull::sim;

SceneFamily family(const std::string& name) {
  SceneFamily f;
  std::string reason;
  EXPECT_TRUE(find_scene_family(name, &f, &reason)) << reason;
  return f;
}

bool is_walker(std::uint16_t id) {
  for (int w = 0; w < 4; ++w)
    if (id == SceneInstance::walker(w)) return true;
  return false;
}

/// Visible pixels of walkers (the instances of walking people) in one frame.
std::size_t walker_pixels(const FrameData& f, std::vector<float>* depths = nullptr) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < f.instance.size(); ++i) {
    const std::uint16_t id = f.instance[i];
    if (!is_walker(id)) continue;
    ++n;
    if (depths && f.depth_m[i] > 0) depths->push_back(f.depth_m[i]);
  }
  return n;
}

TEST(SceneFamilies, TheSuiteNamesItsFamiliesOnce) {
  const std::vector<SceneFamily> all = scene_families();
  ASSERT_FALSE(all.empty());
  EXPECT_EQ(all.front().name, "walking");
  EXPECT_EQ(scene_difference(all.front().options), "") << "walking is the default scene";
  std::set<std::string> names;
  for (const SceneFamily& f : all) {
    EXPECT_TRUE(names.insert(f.name).second) << "duplicate family " << f.name;
    EXPECT_FALSE(f.description.empty()) << f.name;
    EXPECT_EQ(f.name.find_first_of(", ="), std::string::npos) << f.name << ": must fit in a comma-separated list";
  }
  for (const char* name : {"walking", "sitting", "crowd", "far_walker", "brisk", "low_texture", "noisy_detector"})
    EXPECT_TRUE(names.count(name)) << name;
}

TEST(SceneFamilies, UnknownFamilyIsNamedWithTheKnownOnes) {
  SceneFamily f;
  std::string reason;
  EXPECT_FALSE(find_scene_family("Walking", &f, &reason));
  EXPECT_NE(reason.find("'Walking'"), std::string::npos) << reason;
  EXPECT_NE(reason.find("walking, sitting, crowd"), std::string::npos) << reason;
  EXPECT_TRUE(find_scene_family("brisk", nullptr));
}

// A family's options are exactly its --scene text applied to the default scene.
TEST(SceneFamilies, EachFamilyIsItsSceneKeys) {
  for (const SceneFamily& f : scene_families()) {
    SceneOptions rebuilt;
    std::string reason;
    ASSERT_EQ(apply_scene_assignments(&rebuilt, scene_difference(f.options), &reason), Status::Ok)
        << f.name << ": " << reason;
    EXPECT_EQ(scene_difference(rebuilt, f.options), "") << f.name;
    // Motion, seed and length are the caller's: every family runs with every motion and seed.
    EXPECT_EQ(f.options.motion, SceneOptions{}.motion) << f.name;
    EXPECT_EQ(f.options.seed, SceneOptions{}.seed) << f.name;
    EXPECT_EQ(f.options.num_frames, SceneOptions{}.num_frames) << f.name;
  }
  const std::string help = format_scene_families();
  for (const SceneFamily& f : scene_families()) EXPECT_NE(help.find("  " + f.name + " "), std::string::npos) << help;
  EXPECT_NE(help.find("--scene actors.walking_speed_mps=1.2"), std::string::npos) << help;
}

TEST(SceneFamilies, EveryFamilyRendersWithEveryMotion) {
  FrameData frame;
  for (const SceneFamily& f : scene_families()) {
    for (const CameraMotion m : camera_motions()) {
      SceneOptions o = f.options;
      o.motion = m;
      o.num_frames = 40;
      o.seed = 2;
      o.width = 320;  // the scene is the same at any size; small renders fast
      o.height = 240;
      std::string reason;
      ASSERT_EQ(o.validate(&reason), Status::Ok) << f.name << " / " << to_string(m) << ": " << reason;
      const Scene scene(o);
      ASSERT_TRUE(scene.ok()) << scene.reason();
      scene.render(39, &frame);
      ASSERT_TRUE(frame.ok()) << f.name << " / " << to_string(m) << ": " << frame.reason;
      std::size_t measured = 0;
      for (float d : frame.depth_m) measured += d > 0 ? 1 : 0;
      EXPECT_GT(measured, frame.depth_m.size() / 2) << f.name << " / " << to_string(m);
      const auto [lo, hi] = std::minmax_element(frame.gray.begin(), frame.gray.end());
      EXPECT_GT(*hi - *lo, 50) << f.name << " / " << to_string(m) << ": a flat image";
    }
  }
}

// The recorded camera motion (a real trajectory given as data) runs with every family too.
TEST(SceneFamilies, EveryFamilyRendersWithARecordedMotion) {
  // A 2 s recording: 10 cm sideways and a 5 degree turn, sampled at 100 Hz as TUM's ground truth.
  std::vector<double> stamps;
  std::vector<dyncull::Rigid3<double>> poses;
  for (int k = 0; k <= 200; ++k) {
    const double s = k / 200.0;
    dyncull::Rigid3<double> p;
    p.R = Eigen::AngleAxisd(0.087 * s, dyncull::Vec3<double>::UnitZ()).toRotationMatrix();
    p.t = dyncull::Vec3<double>(0.1 * s, 0, 1.5);
    stamps.push_back(100.0 + 0.01 * k);
    poses.push_back(p);
  }
  FrameData frame;
  for (const SceneFamily& f : scene_families()) {
    SceneOptions o = f.options;
    o.motion = CameraMotion::Recorded;
    o.trajectory.recorded_stamps_s = stamps;
    o.trajectory.recorded_poses = poses;
    o.num_frames = 40;
    o.width = 160;
    o.height = 120;
    std::string reason;
    ASSERT_EQ(o.validate(&reason), Status::Ok) << f.name << ": " << reason;
    const Scene scene(o);
    scene.render(39, &frame);
    ASSERT_TRUE(frame.ok()) << f.name << ": " << frame.reason;
    // Frame 0 is the rest pose; the camera then moves as the recording does.
    const double moved = (scene.world_from_cam(39).t - scene.world_from_cam(0).t).norm();
    EXPECT_GT(moved, 0.03) << f.name;
    EXPECT_LT(moved, 0.1) << f.name;
  }
}

// sitting: nobody walks; two desk people move, are detected, and their boxes cover a large part of the
// image (fr3/sitting_static: a mean person-box area of 0.55 of the image).
TEST(SceneFamilies, SittingHasTwoDeskPeopleAndNoWalkers) {
  SceneOptions o = family("sitting").options;
  o.motion = CameraMotion::Static;
  o.num_frames = 30;
  const Scene scene(o);
  FrameData frame;
  for (int i : {0, 15, 29}) {
    scene.render(i, &frame);
    ASSERT_TRUE(frame.ok()) << frame.reason;
    EXPECT_EQ(walker_pixels(frame), 0u) << "frame " << i;
    std::size_t moving[2] = {0, 0};
    for (std::size_t p = 0; p < frame.instance.size(); ++p)
      for (int k = 0; k < 2; ++k)
        moving[k] += frame.instance[p] == SceneInstance::kDeskPersonA + k && frame.moving[p] ? 1 : 0;
    EXPECT_GT(moving[0], 500u) << "frame " << i;
    EXPECT_GT(moving[1], 500u) << "frame " << i;
    double person_box_area = 0;
    for (const auto& d : frame.detections)
      if (d.class_id == CocoClass::kPerson)
        person_box_area += (d.box.x1 - d.box.x0) * (d.box.y1 - d.box.y0) / (frame.width * frame.height);
    EXPECT_GT(person_box_area, 0.3) << "frame " << i;
  }
  EXPECT_EQ(o.detector.model, DetectorModel::Calibrated);
}

// crowd: four walkers, at least three of them in view at some frame.
TEST(SceneFamilies, CrowdHasFourWalkersSeveralInView) {
  SceneOptions o = family("crowd").options;
  o.motion = CameraMotion::Static;
  o.num_frames = 300;
  o.width = 160;
  o.height = 120;
  const Scene scene(o);
  FrameData frame;
  std::set<std::uint16_t> seen;
  std::size_t most_in_view = 0;
  for (int i = 0; i < 300; i += 20) {
    scene.render(i, &frame);
    ASSERT_TRUE(frame.ok()) << frame.reason;
    std::set<std::uint16_t> now;
    for (std::uint16_t id : frame.instance)
      if (is_walker(id)) now.insert(id);
    most_in_view = std::max(most_in_view, now.size());
    seen.insert(now.begin(), now.end());
  }
  EXPECT_EQ(seen.size(), 4u);
  EXPECT_GE(most_in_view, 3u);
}

// far_walker: one walker, and wherever it is seen it is more than 2 m away (walking: within 2 m).
TEST(SceneFamilies, FarWalkerIsOneWalkerBeyondTwoMetres) {
  for (const char* name : {"far_walker", "walking"}) {
    SceneOptions o = family(name).options;
    o.motion = CameraMotion::Static;
    o.num_frames = 300;
    o.depth_noise = false;
    o.width = 320;
    o.height = 240;
    const Scene scene(o);
    FrameData frame;
    std::vector<float> depths;
    std::set<std::uint16_t> walkers;
    for (int i = 0; i < 300; i += 30) {
      scene.render(i, &frame);
      ASSERT_TRUE(frame.ok()) << frame.reason;
      walker_pixels(frame, &depths);
      for (std::uint16_t id : frame.instance)
        if (is_walker(id)) walkers.insert(id);
    }
    ASSERT_GT(depths.size(), 250u) << name << ": the walker is never seen";
    std::sort(depths.begin(), depths.end());
    const float median = depths[depths.size() / 2];
    if (std::string(name) == "far_walker") {
      EXPECT_EQ(walkers.size(), 1u);
      EXPECT_GT(depths[depths.size() / 20], 2.0f) << "5th percentile of the walker's depth";
      EXPECT_GT(median, 2.4f);
    } else {
      EXPECT_EQ(walkers.size(), 2u);
      EXPECT_LT(median, 2.0f);
    }
  }
}

// brisk: the walkers' surfaces move about three times as far a frame as in the walking scene.
TEST(SceneFamilies, BriskWalkersMoveFasterThanWalking) {
  auto median_walker_motion_mm = [](const SceneOptions& base) {
    SceneOptions o = base;
    o.motion = CameraMotion::Static;
    o.num_frames = 60;
    o.width = 320;
    o.height = 240;
    const Scene scene(o);
    FrameData frame;
    std::vector<float> mm;
    for (int i = 10; i < 60; i += 10) {
      scene.render(i, &frame);
      for (std::size_t p = 0; p < frame.instance.size(); ++p)
        if (is_walker(frame.instance[p]) && frame.moving[p])
          mm.push_back(1000.f * frame.motion_m[p]);
    }
    if (mm.empty()) return 0.f;
    std::nth_element(mm.begin(), mm.begin() + static_cast<std::ptrdiff_t>(mm.size() / 2), mm.end());
    return mm[mm.size() / 2];
  };
  const float walking = median_walker_motion_mm(family("walking").options);
  const float brisk = median_walker_motion_mm(family("brisk").options);
  EXPECT_GT(walking, 5.f);
  EXPECT_GT(brisk, 2.f * walking) << "walking " << walking << " mm, brisk " << brisk << " mm a frame";
}

// low_texture: fewer strong image gradients than the walking scene, from the same pose.
TEST(SceneFamilies, LowTextureRoomHasFewerStrongGradients) {
  auto strong_gradients = [](const SceneOptions& base) {
    SceneOptions o = base;
    o.motion = CameraMotion::Static;
    o.num_frames = 1;
    o.actors.walking_people = 0;  // the same static view in both scenes
    const Scene scene(o);
    FrameData f;
    scene.render(0, &f);
    std::size_t n = 0;
    for (int v = 1; v + 1 < f.height; ++v)
      for (int u = 1; u + 1 < f.width; ++u) {
        const auto at = [&](int x, int y) { return static_cast<int>(f.gray[static_cast<std::size_t>(y * f.width + x)]); };
        n += std::abs(at(u + 1, v) - at(u - 1, v)) + std::abs(at(u, v + 1) - at(u, v - 1)) > 40 ? 1 : 0;
      }
    return n;
  };
  const std::size_t walking = strong_gradients(family("walking").options);
  const std::size_t low = strong_gradients(family("low_texture").options);
  EXPECT_LT(static_cast<double>(low), 0.7 * static_cast<double>(walking)) << low << " vs " << walking;
  EXPECT_GT(low, 1000u) << "the room must stay trackable";
}

// noisy_detector: more misses and spurious boxes than the walking scene over the same frames.
TEST(SceneFamilies, NoisyDetectorMissesMoreAndInventsMore) {
  auto count = [](const SceneOptions& base, std::size_t* boxes, std::size_t* spurious) {
    SceneOptions o = base;
    o.motion = CameraMotion::Static;
    o.num_frames = 60;
    o.width = 160;  // detections follow the instance masks at any size; small is fast
    o.height = 120;
    o.min_detection_pixels = 20;
    const Scene scene(o);
    FrameData f;
    *boxes = *spurious = 0;
    for (int i = 0; i < 60; ++i) {
      scene.render(i, &f);
      std::set<std::uint16_t> visible;
      for (std::uint16_t id : f.instance)
        if (id != SceneInstance::kBackground) visible.insert(id);
      *boxes += f.detections.size();
      // More boxes than visible instances: a spurious one.
      *spurious += f.detections.size() > visible.size() ? 1 : 0;
    }
  };
  std::size_t walking_boxes = 0, walking_spurious = 0, noisy_boxes = 0, noisy_spurious = 0;
  count(family("walking").options, &walking_boxes, &walking_spurious);
  count(family("noisy_detector").options, &noisy_boxes, &noisy_spurious);
  EXPECT_LT(noisy_boxes - noisy_spurious, walking_boxes - walking_spurious);
  EXPECT_GT(noisy_spurious, walking_spurious);
}

}  // namespace
