// Tests of the public culler (culling/culler.hpp, compiled into dyncull::culler): its settings count and
// ranges, every preset carried through CullerOptions unchanged, the same labels as the templated core frame
// by frame, refusals of a bad camera and of a moved-from culler, its own undistortion, compact(), and no
// heap allocation per frame after warm-up (a counting global operator new in this executable).
#include "dyncull/culling/culler.hpp"

#include "dyncull/core/views.hpp"
#include "dyncull/culling/culler_core.hpp"
#include "support/counting_allocator.hpp"
#include "support/culler_wall.hpp"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>

#include <string>
#include <vector>

namespace dyncull {
namespace {

using test::WallView;
using test::wall_view;

const char* const kPresets[] = {"recommended", "dld_slam", "rtd_slam", "zhu_2024", "dfd_slam", "zhang_2023", "none"};

struct CountSettings {
  int* count;
  template <class P, class C>
  void operator()(const char*, P&, C&, double, double, bool) const {
    ++*count;
  }
};

struct CollectCore {
  std::vector<double>* values;
  template <class P, class C>
  void operator()(const char*, P&, C& core, double, double, bool) const {
    values->push_back(static_cast<double>(core));
  }
};

TEST(CullerOptions, PublicSettingsAreAtMostForty) {
  CullerOptions o;
  CullerCoreOptions<float> core;
  int numeric = 0;
  bind_settings<float>(o, core, CountSettings{&numeric});
  const int other = 1 /* preset */ + 1 /* keyframe_policy */ + 3 /* class lists */ + 1 /* depth_units_per_metre */;
  const int camera = 7;  // fx, fy, cx, cy, width, height, distortion
  EXPECT_EQ(numeric, 26);
  EXPECT_LE(numeric + other + camera, 40);
}

template <class T>
std::vector<double> core_values(CullerCoreOptions<T> core) {
  CullerOptions unused;
  std::vector<double> v;
  bind_settings<T>(unused, core, CollectCore{&v});
  return v;
}

TEST(CullerOptions, EveryPresetIsCarriedUnchanged) {
  for (const char* name : kPresets) {
    SCOPED_TRACE(name);
    CullerCoreOptions<double> preset;
    ASSERT_TRUE(preset_by_name(name, &preset.pipeline));
    const CullerOptions o(name);
    EXPECT_EQ(o.preset(), name);
    std::string why;
    EXPECT_EQ(o.validate(&why), Status::Ok) << why;
    const CullerCoreOptions<double> carried = core_options<double>(o);
    EXPECT_EQ(core_values(carried), core_values(preset));
    EXPECT_EQ(carried.keyframe_policy, preset.keyframe_policy);
    ASSERT_EQ(carried.pipeline.levels.size(), preset.pipeline.levels.size());
    for (int id = 0; id < static_cast<int>(preset.pipeline.levels.size()); ++id)
      EXPECT_EQ(carried.pipeline.levels.level(id), preset.pipeline.levels.level(id)) << "class " << id;
  }
}

TEST(CullerOptions, DefaultIsRecommended) {
  const CullerOptions d, r("recommended");
  EXPECT_EQ(d.preset(), "recommended");
  EXPECT_EQ(core_values(core_options<float>(d)), core_values(core_options<float>(r)));
  EXPECT_EQ(d.high_level_classes, r.high_level_classes);
  EXPECT_EQ(d.depth_units_per_metre, 5000.0);
}

TEST(CullerOptions, ValidateNamesTheSetting) {
  struct Case {
    const char* expect;
    void (*spoil)(CullerOptions*);
  };
  const Case cases[] = {
      {"max_epipolar_distance_px", [](CullerOptions* o) { o->max_epipolar_distance_px = -1; }},
      {"keyframe_min_matched_ratio", [](CullerOptions* o) { o->keyframe_min_matched_ratio = 1.5; }},
      {"box_padding_px", [](CullerOptions* o) { o->box_padding_px = std::nan(""); }},
      {"match_max_hamming", [](CullerOptions* o) { o->match_max_hamming = 5000; }},
      {"depth_units_per_metre", [](CullerOptions* o) { o->depth_units_per_metre = 0; }},
      {"max_depth_m", [](CullerOptions* o) { o->max_depth_m = o->min_depth_m; }},
      {"two level lists", [](CullerOptions* o) { o->low_level_classes.push_back(o->high_level_classes.front()); }},
      {"high_level_classes", [](CullerOptions* o) { o->high_level_classes.push_back(-3); }},
  };
  for (const Case& c : cases) {
    CullerOptions o;
    c.spoil(&o);
    std::string why;
    EXPECT_EQ(o.validate(&why), Status::InvalidInput) << c.expect;
    EXPECT_NE(why.find(c.expect), std::string::npos) << why;
  }
  std::string why;
  EXPECT_EQ(CullerOptions("walking").validate(&why), Status::InvalidInput);
  EXPECT_NE(why.find("preset"), std::string::npos) << why;
}

CullerCamera tum_camera() {
  const PinholeCamera<float> c = PinholeCamera<float>::tum_fr3();
  return CullerCamera(c.fx, c.fy, c.cx, c.cy, c.width, c.height);
}

/// The wall view as the public culler's frame: the same views, boxes as DetectedBox, the pose as 12 doubles.
struct PublicFrame {
  std::vector<DetectedBox> boxes;
  double Rt[12];
  CullerFrame frame;

  explicit PublicFrame(const WallView<float>& v) {
    const CullerCoreFrame<float> c = v.frame();
    for (const Detection<float>& d : v.detections)
      boxes.push_back(DetectedBox(d.box.x0, d.box.y0, d.box.x1, d.box.y1, d.class_id, d.confidence));
    for (int r = 0; r < 3; ++r) {
      for (int k = 0; k < 3; ++k) Rt[4 * r + k] = v.cam_from_world.R(r, k);
      Rt[4 * r + 3] = v.cam_from_world.t(r);
    }
    frame.keypoints = c.keypoints;
    frame.descriptors = c.descriptors;
    frame.depth_m = c.depth_m;
    frame.detections = &boxes;
    frame.cam_from_world = Rt;
  }
};

WallView<float> wall_with_person(double x) {
  WallView<float> v = wall_view<float>(x);
  Detection<float> person;
  person.box = Box<float>{200.f, 100.f, 380.f, 400.f};
  person.class_id = 0;
  person.confidence = 0.9f;
  v.detections.push_back(person);
  return v;
}

TEST(Culler, SameLabelsAsTheCoreFrameByFrameForEveryPreset) {
  for (const char* name : kPresets) {
    SCOPED_TRACE(name);
    Culler culler(tum_camera(), CullerOptions(name));
    ASSERT_TRUE(culler.ok()) << culler.reason();
    CullerCoreOptions<float> o;
    preset_by_name(name, &o.pipeline);
    CullerCore<float> core(PinholeCamera<float>::tum_fr3(), o);
    for (int k = 0; k < 6; ++k) {
      const WallView<float> v = wall_with_person(0.03 * k);
      const PublicFrame pf(v);
      const CullerResult& a = culler.cull(pf.frame);
      const CullerResult& b = core.cull(v.frame());
      EXPECT_EQ(a.status, b.status) << "frame " << k;
      EXPECT_EQ(a.reason, b.reason);
      EXPECT_EQ(a.keep, b.keep);
      EXPECT_EQ(a.labels, b.labels);
      EXPECT_EQ(a.reasons, b.reasons);
      EXPECT_EQ(a.track_ids, b.track_ids);
      EXPECT_EQ(a.keyframe, b.keyframe);
      EXPECT_GT(a.num_features, 0u);
    }
  }
}

TEST(Culler, BadCameraRefusesEveryFrameNamingIt) {
  CullerCamera camera = tum_camera();
  camera.distortion = {0.1, 0.0, 0.0};
  Culler culler(camera);
  EXPECT_EQ(culler.status(), Status::InvalidInput);
  EXPECT_NE(culler.reason().find("distortion"), std::string::npos) << culler.reason();
  const PublicFrame pf(wall_view<float>(0));
  const CullerResult& r = culler.cull(pf.frame);
  EXPECT_TRUE(r.refused);
  EXPECT_EQ(r.keep, std::vector<std::uint8_t>(pf.frame.keypoints.count, 1));

  Culler no_focal(CullerCamera(0, 0, 320, 240, 640, 480));
  EXPECT_EQ(no_focal.status(), Status::InvalidInput);
  EXPECT_NE(no_focal.reason().find("camera"), std::string::npos) << no_focal.reason();
}

// The camera check a host can run on its own settings at start-up is the one the culler refuses by.
TEST(Culler, AbsurdCamerasAreRefusedByTheCheckAHostCanCallToo) {
  struct Case {
    CullerCamera camera;
    double depth_units;
    const char* named;
  };
  const Case cases[] = {
      {CullerCamera(1e-300, 525, 320, 240, 640, 480), 5000, "fx = 1e-300"},
      {CullerCamera(525, 525, -1e300, 240, 640, 480), 5000, "cx = -1e+300"},
      {CullerCamera(525, 525, 320, 240, 640, 480, {1e300, 0, 0, 0, 0}), 5000, "distortion k1 = 1e+300"},
      {CullerCamera(525, 525, 320, 240, 640, 480, {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2}), 5000, "distortion ty = 2"},
      {tum_camera(), 1e-300, "depth units per metre = 1e-300"},
  };
  for (const Case& c : cases) {
    std::string why;
    EXPECT_EQ(check_camera(c.camera, c.depth_units, &why), Status::InvalidInput) << c.named;
    EXPECT_NE(why.find(c.named), std::string::npos) << why;
    CullerOptions o;
    o.depth_units_per_metre = c.depth_units;
    const Culler culler(c.camera, o);
    EXPECT_EQ(culler.status(), Status::InvalidInput) << c.named;
  }
  EXPECT_EQ(check_camera(tum_camera(), 5000), Status::Ok);
  EXPECT_EQ(check_camera(CullerCamera(525, 525, 320, 240, 640, 480, {0.26, -0.95, -0.005, 0.002, 1.16}), 1000),
            Status::Ok);
}

TEST(Culler, BadOptionsRefuseNamingTheSetting) {
  CullerOptions o;
  o.min_survivor_fraction = 2;
  Culler culler(tum_camera(), o);
  EXPECT_EQ(culler.status(), Status::InvalidInput);
  EXPECT_NE(culler.reason().find("min_survivor_fraction"), std::string::npos) << culler.reason();
}

TEST(Culler, MovedFromRefusesKeepingEveryKeypoint) {
  Culler a(tum_camera());
  Culler b(std::move(a));
  EXPECT_TRUE(b.ok());
  const PublicFrame pf(wall_view<float>(0));
  const CullerResult& r = a.cull(pf.frame);  // NOLINT(bugprone-use-after-move): defined on purpose
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.reason.find("moved from"), std::string::npos) << r.reason;
  EXPECT_EQ(r.keep.size(), pf.frame.keypoints.count);
}

TEST(Culler, RejectsANonRigidPose) {
  Culler culler(tum_camera());
  PublicFrame pf(wall_view<float>(0));
  pf.Rt[0] = 2.0;  // a scaled rotation
  const CullerResult& r = culler.cull(pf.frame);
  EXPECT_TRUE(r.refused);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.reason.find("cam_from_world"), std::string::npos) << r.reason;
}

TEST(Culler, UndistortsKeypointsWhenTheHostGivesNone) {
  CullerCamera camera = tum_camera();
  camera.distortion = {0.05, -0.1, 0.0, 0.0};
  Culler own(camera), given(camera);
  for (int k = 0; k < 4; ++k) {
    const WallView<float> v = wall_with_person(0.03 * k);
    PublicFrame pf(v);
    // The host's undistorted copy, as ORB-SLAM's mvKeysUn.
    std::vector<cv::Point2f> raw, und;
    for (const Vec2<float>& p : v.keypoints) raw.push_back(cv::Point2f(p.x(), p.y()));
    const cv::Matx33d K(camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1);
    cv::undistortPoints(raw, und, K, camera.distortion, cv::noArray(), K);
    const CullerResult a = own.cull(pf.frame);
    pf.frame.undistorted_keypoints = points_view(und);
    const CullerResult& b = given.cull(pf.frame);
    EXPECT_FALSE(a.refused) << a.reason;
    EXPECT_EQ(a.keep, b.keep) << "frame " << k;
    EXPECT_EQ(a.reasons, b.reasons);
  }
}

TEST(Culler, RecommendedAllocatesNothingPerFrameAfterWarmUp) {
  std::vector<WallView<float>> views;
  for (int k = 0; k < 8; ++k) views.push_back(wall_with_person(0.03 * k));
  std::vector<PublicFrame> frames;
  frames.reserve(views.size());  // each frame points into itself: built in place, never moved
  for (const WallView<float>& v : views) frames.emplace_back(v);
  Culler culler(tum_camera());
  for (int round = 0; round < 3; ++round)
    for (const PublicFrame& f : frames) culler.cull(f.frame);
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const std::size_t before = test::allocations();
    const CullerResult& r = culler.cull(frames[k].frame);
    EXPECT_EQ(test::allocations() - before, 0u) << "frame " << k << ": " << r.reason;
  }
}

TEST(Culler, CompactRemovesCulledElementsFromEveryVector) {
  const std::vector<std::uint8_t> keep = {1, 0, 1, 0, 1};
  std::vector<int> a = {0, 1, 2, 3, 4};
  std::vector<float> b = {0.f, 1.f, 2.f, 3.f, 4.f};
  EXPECT_EQ(compact(keep, a, b), 3);
  EXPECT_EQ(a, (std::vector<int>{0, 2, 4}));
  EXPECT_EQ(b, (std::vector<float>{0.f, 2.f, 4.f}));
  std::vector<int> short_one = {1, 2};
  EXPECT_EQ(compact(keep, short_one), -1);
  EXPECT_EQ(short_one.size(), 2u);
}

}  // namespace
}  // namespace dyncull
