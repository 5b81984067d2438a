// Tests of culling/culler_core.hpp on a synthetic textured wall with known camera motion: the keyframe policy
// (own: by motion and by matched share; host-decided), stable track ids, the host's matches, the inputs a
// configuration lists, missing inputs and mismatched sizes named in the status, monocular and distortion
// statuses, and no default intrinsics.
#include "dyncull/culling/culler_core.hpp"

#include "dyncull/core/random.hpp"
#include "support/culler_wall.hpp"
#include "dyncull/culling/presets.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace dyncull {
namespace {

using test::WallView;
using test::wall_view;
using test::kWallPoints;

template <class T>
CullerCoreOptions<T> host_keyframes() {
  CullerCoreOptions<T> o;
  o.keyframe_policy = KeyframePolicy::Host;
  return o;
}

template <class T>
class CullerTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(CullerTest, Scalars, );

TYPED_TEST(CullerTest, InvalidCameraFailsWithItsReason) {
  using T = TypeParam;
  PinholeCamera<T> camera = PinholeCamera<T>::tum_fr3();
  camera.fx = T(0);
  CullerCore<T> culler(camera);
  EXPECT_EQ(culler.status(), Status::InvalidInput);
  EXPECT_NE(culler.reason().find("camera"), std::string::npos) << culler.reason();
  const WallView<T> v = wall_view<T>(0);
  const CullerResult& r = culler.cull(v.frame());
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.reason.find("no default intrinsics"), std::string::npos) << r.reason;
  ASSERT_EQ(r.keep.size(), v.keypoints.size());
  for (std::uint8_t k : r.keep) EXPECT_EQ(k, 1);
}

// Depth given but unusable (all 0, all NaN, all beyond the sensor's range): the keyframe has no 3-D
// point, so the reprojection check cannot run. The frame says so, as it does for depth not given, and
// is not Ok; with valid depth the same frames are Ok.
TYPED_TEST(CullerTest, UnusableDepthIsAMissingInputNotAnOkFrame) {
  using T = TypeParam;
  const float fills[] = {0.f, std::numeric_limits<float>::quiet_NaN(), 1e6f};
  for (const float fill : fills) {
    CullerCore<T> culler(PinholeCamera<T>::tum_fr3());
    for (int k = 0; k < 3; ++k) {
      WallView<T> v = wall_view<T>(0.01 * k);
      std::fill(v.depth.begin(), v.depth.end(), fill);
      const CullerResult& r = culler.cull(v.frame());
      if (k == 0) continue;  // the first frame has no keyframe yet
      EXPECT_EQ(r.status, Status::MissingInput) << "depth " << fill << ", frame " << k << ": " << r.reason;
      EXPECT_NE(r.reason.find("reprojection: points_3d: none of the"), std::string::npos) << r.reason;
    }
  }
  CullerCore<T> valid(PinholeCamera<T>::tum_fr3());
  for (int k = 0; k < 3; ++k) {
    const CullerResult& r = valid.cull(wall_view<T>(0.01 * k).frame());
    if (k > 0) {
      EXPECT_TRUE(r.ok()) << r.reason;
    }
  }
}

TYPED_TEST(CullerTest, InvalidOptionsNameTheField) {
  using T = TypeParam;
  CullerCoreOptions<T> o;
  o.keyframe_min_matched_ratio = 2;
  CullerCore<T> culler(PinholeCamera<T>::tum_fr3(), o);
  EXPECT_EQ(culler.status(), Status::InvalidInput);
  EXPECT_NE(culler.reason().find("keyframe_min_matched_ratio"), std::string::npos) << culler.reason();
}

TYPED_TEST(CullerTest, TrackIdsFollowTheKeyframePointsAcrossFrames) {
  using T = TypeParam;
  CullerCore<T> culler(PinholeCamera<T>::tum_fr3(), host_keyframes<T>());
  const WallView<T> v0 = wall_view<T>(0);
  const CullerResult& r0 = culler.cull(v0.frame());
  EXPECT_TRUE(r0.keyframe);
  std::vector<std::int64_t> id_of_point(kWallPoints, -1);
  for (std::size_t i = 0; i < v0.keypoints.size(); ++i) id_of_point[v0.point_index[i]] = r0.track_ids[i];

  for (int k = 1; k <= 4; ++k) {
    const WallView<T> v = wall_view<T>(0.01 * k, 3, k % 2 == 1);
    const CullerResult& r = culler.cull(v.frame());
    EXPECT_TRUE(r.ok()) << r.reason;
    EXPECT_FALSE(r.keyframe);
    EXPECT_EQ(r.frames_since_keyframe, k);
    std::size_t same = 0, seen = 0;
    for (std::size_t i = 0; i < v.keypoints.size(); ++i) {
      const std::int64_t expected = id_of_point[v.point_index[i]];
      if (expected < 0) continue;
      ++seen;
      same += r.track_ids[i] == expected;
    }
    EXPECT_GT(seen, 200u);
    EXPECT_GE(static_cast<double>(same), 0.95 * static_cast<double>(seen)) << "frame " << k;
    EXPECT_GE(static_cast<double>(r.matched), 0.95 * static_cast<double>(seen));
  }
}

TYPED_TEST(CullerTest, UnmatchedKeypointsGetNewIds) {
  using T = TypeParam;
  CullerCore<T> culler(PinholeCamera<T>::tum_fr3(), host_keyframes<T>());
  const WallView<T> v0 = wall_view<T>(0);
  const CullerResult r0 = culler.cull(v0.frame());
  const WallView<T> v1 = wall_view<T>(0.01, 99);  // other texture: nothing matches
  const CullerResult& r1 = culler.cull(v1.frame());
  EXPECT_EQ(r1.matched, 0u);
  std::int64_t max0 = -1;
  for (std::int64_t id : r0.track_ids) max0 = std::max(max0, id);
  for (std::int64_t id : r1.track_ids) EXPECT_GT(id, max0);
}

TYPED_TEST(CullerTest, OwnPolicyMakesAKeyframeWhenThePoseMovedFar) {
  using T = TypeParam;
  CullerCore<T> culler(PinholeCamera<T>::tum_fr3());
  EXPECT_TRUE(culler.cull(wall_view<T>(0).frame()).keyframe);  // the first frame
  EXPECT_FALSE(culler.cull(wall_view<T>(0.05).frame()).keyframe);
  EXPECT_FALSE(culler.cull(wall_view<T>(0.09).frame()).keyframe);
  const CullerResult& r = culler.cull(wall_view<T>(0.12).frame());  // 0.12 m > 0.1 m from the keyframe
  EXPECT_TRUE(r.keyframe);
  EXPECT_EQ(r.frames_since_keyframe, 3);
  const CullerResult& next = culler.cull(wall_view<T>(0.14).frame());
  EXPECT_FALSE(next.keyframe);
  EXPECT_EQ(next.frames_since_keyframe, 1);
}

TYPED_TEST(CullerTest, OwnPolicyMakesAKeyframeWhenFewKeypointsMatch) {
  using T = TypeParam;
  CullerCore<T> culler(PinholeCamera<T>::tum_fr3());
  culler.cull(wall_view<T>(0).frame());
  EXPECT_FALSE(culler.cull(wall_view<T>(0.01).frame()).keyframe);
  const CullerResult& r = culler.cull(wall_view<T>(0.02, 99).frame());
  EXPECT_EQ(r.matched, 0u);
  EXPECT_TRUE(r.keyframe);
}

// A front end that has no features yet on its first frame (it detects after tracking) gives the culler an
// empty first keyframe: the next frame with keypoints must replace it, or a still camera would never get
// one and every later frame would run on box evidence alone.
TYPED_TEST(CullerTest, OwnPolicyReplacesAnEmptyKeyframe) {
  using T = TypeParam;
  CullerCore<T> culler(PinholeCamera<T>::tum_fr3());
  WallView<T> empty = wall_view<T>(0);
  empty.keypoints.clear();
  empty.descriptors.clear();
  EXPECT_TRUE(culler.cull(empty.frame()).keyframe);
  EXPECT_TRUE(culler.cull(wall_view<T>(0).frame()).keyframe) << "the keyframe without keypoints stayed";
  const CullerResult& r = culler.cull(wall_view<T>(0.01).frame());
  EXPECT_FALSE(r.keyframe);
  EXPECT_GT(r.matched, wall_view<T>(0.01).keypoints.size() / 2);
}

TYPED_TEST(CullerTest, HostPolicyFollowsIsKeyframe) {
  using T = TypeParam;
  CullerCore<T> culler(PinholeCamera<T>::tum_fr3(), host_keyframes<T>());
  EXPECT_TRUE(culler.cull(wall_view<T>(0).frame()).keyframe);  // the first frame always is one
  const WallView<T> far = wall_view<T>(0.3);
  EXPECT_FALSE(culler.cull(far.frame()).keyframe);  // the own policy would take it
  CullerCoreFrame<T> f = wall_view<T>(0.01).frame();
  const WallView<T> v = wall_view<T>(0.01);
  f = v.frame();
  f.is_keyframe = true;
  EXPECT_TRUE(culler.cull(f).keyframe);
}

TYPED_TEST(CullerTest, HostMatchesReplaceOwnMatching) {
  using T = TypeParam;
  CullerCore<T> culler(PinholeCamera<T>::tum_fr3(), host_keyframes<T>());
  const WallView<T> v0 = wall_view<T>(0);
  const CullerResult r0 = culler.cull(v0.frame());
  const WallView<T> v1 = wall_view<T>(0.02, 3, true);
  std::vector<int> match(v1.keypoints.size(), -1);
  for (std::size_t i = 0; i < v1.keypoints.size(); ++i)
    for (std::size_t k = 0; k < v0.keypoints.size(); ++k)
      if (v0.point_index[k] == v1.point_index[i]) match[i] = static_cast<int>(k);
  CullerCoreFrame<T> f = v1.frame();
  f.descriptors = DescriptorRows();  // not needed with the host's matches
  f.keyframe_match = match.data();
  const CullerResult& r = culler.cull(f);
  EXPECT_TRUE(r.ok()) << r.reason;
  for (std::size_t i = 0; i < match.size(); ++i)
    EXPECT_EQ(r.track_ids[i], match[i] >= 0 ? r0.track_ids[static_cast<std::size_t>(match[i])] : r.track_ids[i]);

  match[0] = static_cast<int>(v0.keypoints.size());  // one past the keyframe's keypoints
  const CullerResult& bad = culler.cull(f);
  EXPECT_EQ(bad.status, Status::InvalidInput);
  EXPECT_NE(bad.reason.find("keyframe_match[0]"), std::string::npos) << bad.reason;
}

TYPED_TEST(CullerTest, InputsListWhatTheConfigurationReads) {
  using T = TypeParam;
  CullerCore<T> recommended(PinholeCamera<T>::tum_fr3());
  EXPECT_EQ(recommended.inputs().names(), "keypoints, descriptors, depth, detections, pose");
  CullerCoreOptions<T> o;
  o.pipeline = presets::zhu_2024<T>();
  CullerCore<T> boxes_only(PinholeCamera<T>::tum_fr3(), o);
  EXPECT_EQ(boxes_only.inputs().names(), "keypoints, detections");
  o.pipeline = presets::dfd_slam<T>();
  o.keyframe_policy = KeyframePolicy::Host;
  CullerCore<T> epipolar(PinholeCamera<T>::tum_fr3(), o);
  EXPECT_EQ(epipolar.inputs().names(), "keypoints, descriptors, detections");
}

TYPED_TEST(CullerTest, MissingInputsAreNamed) {
  using T = TypeParam;
  struct Case {
    const char* name;
    void (*drop)(CullerCoreFrame<T>*);
  };
  const Case cases[] = {
      {"descriptors", [](CullerCoreFrame<T>* f) { f->descriptors = DescriptorRows(); }},
      {"detections", [](CullerCoreFrame<T>* f) { f->detections = nullptr; }},
      {"pose", [](CullerCoreFrame<T>* f) { f->cam_from_world = nullptr; }},
      {"depth", [](CullerCoreFrame<T>* f) { f->depth_m = DepthView<float>{}; }},
  };
  for (const Case& c : cases) {
    CullerCore<T> culler(PinholeCamera<T>::tum_fr3());
    culler.cull(wall_view<T>(0).frame());
    const WallView<T> v = wall_view<T>(0.01);
    CullerCoreFrame<T> f = v.frame();
    c.drop(&f);
    const CullerResult& r = culler.cull(f);
    EXPECT_EQ(r.status, Status::MissingInput) << c.name;
    EXPECT_EQ(r.missing.names(), c.name);
    EXPECT_NE(r.reason.find(std::string("missing input: ") + c.name), std::string::npos) << r.reason;
    EXPECT_EQ(r.keep.size(), v.keypoints.size());
  }
  CullerCore<T> culler(PinholeCamera<T>::tum_fr3());
  CullerCoreFrame<T> none;
  const CullerResult& r = culler.cull(none);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.reason.find("keypoints"), std::string::npos) << r.reason;
}

TYPED_TEST(CullerTest, MonocularRunsAndSaysDepthStagesDidNotRun) {
  using T = TypeParam;
  CullerCore<T> culler(PinholeCamera<T>::tum_fr3());
  for (int k = 0; k < 3; ++k) {
    const WallView<T> v = wall_view<T>(0.01 * k);
    CullerCoreFrame<T> f = v.frame();
    f.depth_m = DepthView<float>{};
    const CullerResult& r = culler.cull(f);
    EXPECT_EQ(r.status, Status::MissingInput);
    EXPECT_TRUE(r.missing.depth);
    EXPECT_NE(r.reason.find("monocular"), std::string::npos) << r.reason;
    EXPECT_NE(r.reason.find("epipolar evidence only"), std::string::npos) << r.reason;
    if (k > 0) {
      EXPECT_GT(r.matched, 200u);  // matched without depth, around the rotated ray
      EXPECT_EQ(culler.pipeline_result().moving_consistency.status, Status::Ok)
          << culler.pipeline_result().moving_consistency.reason;
    }
  }
}

TYPED_TEST(CullerTest, MismatchedSizesAreNamed) {
  using T = TypeParam;
  const WallView<T> v = wall_view<T>(0);
  const std::size_t n = v.keypoints.size();
  {
    CullerCore<T> culler(PinholeCamera<T>::tum_fr3());
    CullerCoreFrame<T> f = v.frame();
    f.descriptors.rows = n - 1;
    const CullerResult& r = culler.cull(f);
    EXPECT_EQ(r.status, Status::InvalidInput);
    EXPECT_NE(r.reason.find("descriptors has " + std::to_string(n - 1) + " rows"), std::string::npos) << r.reason;
    EXPECT_EQ(r.keep, std::vector<std::uint8_t>(n, 1));
    EXPECT_FALSE(culler.has_keyframe());  // a refused frame changes no state
  }
  {
    CullerCore<T> culler(PinholeCamera<T>::tum_fr3());
    CullerCoreFrame<T> f = v.frame();
    f.undistorted_keypoints = PointsView::of(static_cast<const T*>(v.keypoints[0].data()), n - 2, sizeof(Vec2<T>));
    const CullerResult& r = culler.cull(f);
    EXPECT_EQ(r.status, Status::InvalidInput);
    EXPECT_NE(r.reason.find("undistorted_keypoints has"), std::string::npos) << r.reason;
  }
  {
    CullerCore<T> culler(PinholeCamera<T>::tum_fr3());
    CullerCoreFrame<T> f = v.frame();
    f.depth_m.width = 320;
    const CullerResult& r = culler.cull(f);
    EXPECT_EQ(r.status, Status::InvalidInput);
    EXPECT_NE(r.reason.find("depth: 320x480 for an image of 640x480"), std::string::npos) << r.reason;
  }
  {
    CullerCore<T> culler(PinholeCamera<T>::tum_fr3());
    CullerCoreFrame<T> f = v.frame();
    const std::vector<std::uint16_t> raw(v.depth.size(), 15000);
    f.depth_raw = DepthView<std::uint16_t>{raw.data(), 640, 480, 0, 5000.f, 0.f, 1e30f};
    const CullerResult& r = culler.cull(f);
    EXPECT_EQ(r.status, Status::InvalidInput);
    EXPECT_NE(r.reason.find("not both"), std::string::npos) << r.reason;
  }
  {
    CullerCore<T> culler(PinholeCamera<T>::tum_fr3());
    CullerCoreFrame<T> f = v.frame();
    Rigid3<T> bad = v.cam_from_world;
    bad.t.x() = std::numeric_limits<T>::quiet_NaN();
    f.cam_from_world = &bad;
    const CullerResult& r = culler.cull(f);
    EXPECT_EQ(r.status, Status::NonFinite);
    EXPECT_NE(r.reason.find("cam_from_world"), std::string::npos) << r.reason;
  }
}

TYPED_TEST(CullerTest, DistortedCameraNeedsUndistortedKeypoints) {
  using T = TypeParam;
  CullerCoreOptions<T> o;
  o.camera_has_distortion = true;
  CullerCore<T> culler(PinholeCamera<T>::tum_fr3(), o);
  const WallView<T> v = wall_view<T>(0);
  CullerCoreFrame<T> f = v.frame();
  const CullerResult& r = culler.cull(f);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.reason.find("undistorted_keypoints"), std::string::npos) << r.reason;
  EXPECT_NE(r.reason.find("distortion"), std::string::npos) << r.reason;
  f.undistorted_keypoints = points_view(v.keypoints);
  const CullerResult& first = culler.cull(f);
  EXPECT_EQ(first.status, Status::MissingInput);  // no keyframe to track against yet
  EXPECT_NE(first.reason.find("first frame"), std::string::npos) << first.reason;
  const WallView<T> v1 = wall_view<T>(0.01);
  CullerCoreFrame<T> f1 = v1.frame();
  f1.undistorted_keypoints = points_view(v1.keypoints);
  const CullerResult& second = culler.cull(f1);
  EXPECT_TRUE(second.ok()) << second.reason;
}

TYPED_TEST(CullerTest, Uint16DepthGivesTheSameResultAsMetres) {
  using T = TypeParam;
  CullerCore<T> metres(PinholeCamera<T>::tum_fr3()), raw(PinholeCamera<T>::tum_fr3());
  for (int k = 0; k < 3; ++k) {
    const WallView<T> v = wall_view<T>(0.01 * k);
    std::vector<std::uint16_t> depth(v.depth.size());  // 5000 per metre, as TUM's PNGs
    for (std::size_t i = 0; i < depth.size(); ++i) depth[i] = static_cast<std::uint16_t>(std::lround(v.depth[i] * 5000.f));
    CullerCoreFrame<T> f = v.frame();
    const CullerResult a = metres.cull(f);
    f.depth_m = DepthView<float>{};
    f.depth_raw = DepthView<std::uint16_t>{depth.data(), 640, 480, 0, 5000.f, 0.f, 1e30f};
    const CullerResult& b = raw.cull(f);
    EXPECT_EQ(a.status, b.status) << b.reason;
    EXPECT_EQ(a.keep, b.keep);
    EXPECT_EQ(a.track_ids, b.track_ids);
    EXPECT_EQ(metres.pipeline_result().reprojection.status, raw.pipeline_result().reprojection.status);
  }
}

TYPED_TEST(CullerTest, PointsViewReadsPackedAndStridedPoints) {
  using T = TypeParam;
  const std::vector<Vec2<T>> pts = {Vec2<T>(1, 2), Vec2<T>(3, 4)};
  const PointsView v = points_view(pts);
  EXPECT_TRUE(v.given);
  EXPECT_EQ(v.count, 2u);
  EXPECT_EQ(v.x(1), 3.0);
  EXPECT_EQ(v.y(1), 4.0);
  struct Key { float x, y, size, angle; };
  const std::vector<Key> keys = {{5.f, 6.f, 31.f, 0.f}, {7.f, 8.f, 31.f, 0.f}};
  const PointsView k = points_view(keys);
  EXPECT_EQ(k.x(1), 7.0);
  EXPECT_EQ(k.y(1), 8.0);
  const std::vector<Key> empty;
  EXPECT_TRUE(points_view(empty).given);
  EXPECT_EQ(points_view(empty).count, 0u);
}

// --- The frame contract under bad input -------------------------------------------------------------

template <class T>
CullerCoreOptions<T> none_preset() {
  CullerCoreOptions<T> o;
  o.pipeline = presets::none<T>();
  return o;
}

TYPED_TEST(CullerTest, NonFiniteKeypointIsCulledAndNamedWhileTheFrameStaysUsable) {
  using T = TypeParam;
  for (const bool none : {false, true}) {
    SCOPED_TRACE(none ? "preset none" : "preset recommended");
    CullerCore<T> culler(PinholeCamera<T>::tum_fr3(), none ? none_preset<T>() : CullerCoreOptions<T>());
    culler.cull(wall_view<T>(0).frame());
    WallView<T> v = wall_view<T>(0.01);
    v.keypoints[5].x() = std::numeric_limits<T>::quiet_NaN();
    v.keypoints[9].y() = std::numeric_limits<T>::infinity();
    const CullerResult& r = culler.cull(v.frame());
    EXPECT_EQ(r.status, Status::MissingInput) << r.reason;
    EXPECT_NE(r.reason.find("keypoints[5] and 1 other have a NaN or Inf coordinate: culled"), std::string::npos)
        << r.reason;
    ASSERT_EQ(r.keep.size(), v.keypoints.size());
    for (std::size_t i : {std::size_t(5), std::size_t(9)}) {
      EXPECT_EQ(r.keep[i], 0) << i;
      EXPECT_EQ(r.labels[i], FeatureLabel::Dynamic) << i;
      EXPECT_EQ(r.reasons[i], CullReason::InvalidInput) << i;
    }
    EXPECT_GT(r.matched, v.keypoints.size() / 2);  // the other keypoints were matched and judged
    std::size_t kept = 0;
    for (std::uint8_t k : r.keep) kept += k;
    EXPECT_EQ(r.num_kept, kept);
    const CullerResult& next = culler.cull(wall_view<T>(0.02).frame());
    EXPECT_TRUE(next.ok()) << next.reason;
  }
}

TYPED_TEST(CullerTest, NonFiniteUndistortedKeypointIsCulledAndNamedByItsArgument) {
  using T = TypeParam;
  CullerCore<T> culler(PinholeCamera<T>::tum_fr3(), none_preset<T>());
  culler.cull(wall_view<T>(0).frame());
  const WallView<T> v = wall_view<T>(0.01);
  std::vector<Vec2<T>> undistorted = v.keypoints;
  undistorted[7].y() = std::numeric_limits<T>::quiet_NaN();
  CullerCoreFrame<T> f = v.frame();
  f.undistorted_keypoints = points_view(undistorted);
  const CullerResult& r = culler.cull(f);
  EXPECT_EQ(r.status, Status::MissingInput) << r.reason;
  EXPECT_NE(r.reason.find("undistorted_keypoints[7] has a NaN or Inf coordinate: culled"), std::string::npos)
      << r.reason;
  ASSERT_EQ(r.keep.size(), v.keypoints.size());
  EXPECT_EQ(r.keep[7], 0);
  EXPECT_EQ(r.num_kept, v.keypoints.size() - 1);  // preset none culls nothing else
}

TYPED_TEST(CullerTest, DescriptorWidthChangeStartsANewKeyframeNamingTheDescriptors) {
  using T = TypeParam;
  CullerCore<T> culler(PinholeCamera<T>::tum_fr3(), host_keyframes<T>());
  culler.cull(wall_view<T>(0).frame());
  for (const std::size_t width : {std::size_t(64), std::size_t(33)}) {
    SCOPED_TRACE("rows of " + std::to_string(width) + " bytes");
    const WallView<T> v = wall_view<T>(0.01);
    std::vector<std::uint8_t> wide(v.keypoints.size() * width);
    for (std::size_t i = 0; i < v.keypoints.size(); ++i)
      for (std::size_t b = 0; b < width; ++b) wide[i * width + b] = v.descriptors[i * 32 + b % 32];
    CullerCoreFrame<T> f = v.frame();
    f.descriptors = DescriptorRows(wide.data(), v.keypoints.size(), 0, width);
    const CullerResult& r = culler.cull(f);
    EXPECT_EQ(r.status, Status::MissingInput) << r.reason;
    EXPECT_NE(r.reason.find("descriptors: rows of " + std::to_string(width) + " bytes where the keyframe's have"),
              std::string::npos)
        << r.reason;
    EXPECT_EQ(r.reason.find("kf_desc"), std::string::npos) << r.reason;
    EXPECT_TRUE(r.keyframe);
    EXPECT_EQ(r.keep.size(), v.keypoints.size());
    // The next frame of the same width matches the new keyframe.
    const WallView<T> v2 = wall_view<T>(0.02);
    CullerCoreFrame<T> f2 = v2.frame();
    std::vector<std::uint8_t> wide2(v2.keypoints.size() * width);
    for (std::size_t i = 0; i < v2.keypoints.size(); ++i)
      for (std::size_t b = 0; b < width; ++b) wide2[i * width + b] = v2.descriptors[i * 32 + b % 32];
    f2.descriptors = DescriptorRows(wide2.data(), v2.keypoints.size(), 0, width);
    const CullerResult& r2 = culler.cull(f2);
    EXPECT_TRUE(r2.ok()) << r2.reason;
    EXPECT_GT(r2.matched, v2.keypoints.size() / 2);
  }
}

TYPED_TEST(CullerTest, DescriptorRowsWiderThanTheMatcherTakesAreRefusedWithoutPoisoningLaterFrames) {
  using T = TypeParam;
  CullerCore<T> culler(PinholeCamera<T>::tum_fr3(), host_keyframes<T>());
  const WallView<T> v = wall_view<T>(0);
  std::vector<std::uint8_t> wide(v.keypoints.size() * 300, 7);
  CullerCoreFrame<T> f = v.frame();
  f.descriptors = DescriptorRows(wide.data(), v.keypoints.size(), 0, 300);
  const CullerResult& r = culler.cull(f);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.reason.find("descriptors: rows of 300 bytes"), std::string::npos) << r.reason;
  EXPECT_EQ(r.keep, std::vector<std::uint8_t>(v.keypoints.size(), 1));
  culler.cull(wall_view<T>(0.01).frame());
  const CullerResult& later = culler.cull(wall_view<T>(0.02).frame());
  EXPECT_TRUE(later.ok()) << later.reason;
  EXPECT_GT(later.matched, v.keypoints.size() / 2);
}

TYPED_TEST(CullerTest, ResetForgetsTheKeyframeAndTheTracks) {
  using T = TypeParam;
  CullerCore<T> culler(PinholeCamera<T>::tum_fr3(), host_keyframes<T>());
  culler.cull(wall_view<T>(0).frame());
  culler.cull(wall_view<T>(0.01).frame());
  ASSERT_TRUE(culler.has_keyframe());
  culler.reset();
  EXPECT_FALSE(culler.has_keyframe());
  const CullerResult& r = culler.cull(wall_view<T>(0.02).frame());
  EXPECT_TRUE(r.keyframe);
  EXPECT_EQ(r.frames_since_keyframe, 0);
  EXPECT_EQ(r.matched, 0u);
  EXPECT_EQ(r.track_ids.front(), 0);  // ids start again
  EXPECT_NE(r.reason.find("first frame"), std::string::npos) << r.reason;
}

TYPED_TEST(CullerTest, PredictedPoseThatIsNotRigidIsRefusedNamingThePose) {
  using T = TypeParam;
  const WallView<T> v = wall_view<T>(0);
  Mat3<T> reflection = Mat3<T>::Identity();
  reflection(2, 2) = T(-1);
  Mat3<T> shear = Mat3<T>::Identity();
  shear(0, 1) = T(0.5);
  const std::pair<const char*, Mat3<T>> bad[] = {{"zero", Mat3<T>::Zero()},
                                                 {"doubled", T(2) * Mat3<T>::Identity()},
                                                 {"reflection", reflection},
                                                 {"shear", shear}};
  for (const auto& b : bad) {
    SCOPED_TRACE(b.first);
    CullerCore<T> culler(PinholeCamera<T>::tum_fr3());
    Rigid3<T> pose = v.cam_from_world;
    pose.R = b.second;
    CullerCoreFrame<T> f = v.frame();
    f.cam_from_world = &pose;
    const CullerResult& r = culler.cull(f);
    EXPECT_EQ(r.status, Status::InvalidInput) << r.reason;
    EXPECT_NE(r.reason.find("cam_from_world's rotation is not a rotation"), std::string::npos) << r.reason;
    EXPECT_EQ(r.keep, std::vector<std::uint8_t>(v.keypoints.size(), 1));
    EXPECT_FALSE(culler.has_keyframe());
  }
  CullerCore<T> culler(PinholeCamera<T>::tum_fr3());
  Rigid3<T> far = v.cam_from_world;
  far.t.x() = T(1e30);
  CullerCoreFrame<T> f = v.frame();
  f.cam_from_world = &far;
  const CullerResult& r = culler.cull(f);
  EXPECT_EQ(r.status, Status::InvalidInput) << r.reason;
  EXPECT_NE(r.reason.find("out of the range"), std::string::npos) << r.reason;
  // A rotation off by float rounding is rigid.
  Rigid3<T> rounded = v.cam_from_world;
  rounded.R = Eigen::AngleAxis<T>(T(0.3), Vec3<T>(T(0.6), T(0.8), T(0)).normalized()).toRotationMatrix();
  rounded.R(0, 0) += T(2e-6);
  f.cam_from_world = &rounded;
  EXPECT_NE(culler.cull(f).status, Status::InvalidInput) << culler.result().reason;
}

TYPED_TEST(CullerTest, AbsurdIntrinsicsAreRefusedNamingTheField) {
  using T = TypeParam;
  const std::pair<const char*, PinholeCamera<T>> cameras[] = {
      {"fx", PinholeCamera<T>{T(1e-30), T(525), T(319.5), T(239.5), 640, 480}},
      {"fy", PinholeCamera<T>{T(525), T(1e30), T(319.5), T(239.5), 640, 480}},
      {"cx", PinholeCamera<T>{T(525), T(525), T(1e30), T(239.5), 640, 480}},
      {"cy", PinholeCamera<T>{T(525), T(525), T(319.5), T(-2000), 640, 480}}};
  for (const auto& c : cameras) {
    SCOPED_TRACE(c.first);
    EXPECT_FALSE(c.second.valid());
    CullerCore<T> culler(c.second);
    EXPECT_EQ(culler.status(), Status::InvalidInput);
    EXPECT_NE(culler.reason().find(std::string(c.first) + " = "), std::string::npos) << culler.reason();
  }
  EXPECT_TRUE(PinholeCamera<T>::tum_fr3().valid());
  EXPECT_TRUE((PinholeCamera<T>{T(5), T(5), T(-600), T(900), 640, 480}.valid()));  // wide, off-centre: exists
}

TYPED_TEST(CullerTest, FrameWithoutKeypointsLacksNoDescriptors) {
  using T = TypeParam;
  CullerCore<T> culler(PinholeCamera<T>::tum_fr3());
  culler.cull(wall_view<T>(0).frame());
  const WallView<T> v = wall_view<T>(0.01);
  const std::vector<Vec2<T>> none;
  CullerCoreFrame<T> f = v.frame();
  f.keypoints = points_view(none);
  f.descriptors = DescriptorRows{};
  const CullerResult& r = culler.cull(f);
  EXPECT_FALSE(r.missing.descriptors) << r.reason;
  EXPECT_EQ(r.reason.find("descriptors"), std::string::npos) << r.reason;
  EXPECT_TRUE(r.keep.empty());
}

TYPED_TEST(CullerTest, PointsViewStrideBelowOnePairIsRefused) {
  using T = TypeParam;
  CullerCore<T> culler(PinholeCamera<T>::tum_fr3());
  const WallView<T> v = wall_view<T>(0);
  CullerCoreFrame<T> f = v.frame();
  f.keypoints = PointsView::of(v.keypoints[0].data(), v.keypoints.size(), sizeof(T));
  const CullerResult& r = culler.cull(f);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.reason.find("keypoints: stride_bytes " + std::to_string(sizeof(T)) + " is below the " +
                          std::to_string(2 * sizeof(T)) + " bytes of an x, y pair"),
            std::string::npos)
      << r.reason;
  EXPECT_EQ(r.keep, std::vector<std::uint8_t>(v.keypoints.size(), 1));
}

// A keyframe keypoint at u = 2^32 + 512 is off the image: it has no depth (an int conversion without a
// range check would wrap it to pixel 512 and give it that pixel's depth). Without depth the next frame
// searches it around its ray, where it is; with a wrong depth, around a projection shifted by the motion.
TEST(CullerKeyframe, KeypointBeyondTheIntRangeGetsNoDepthFromAWrappedPixel) {
  const PinholeCamera<double> camera = PinholeCamera<double>::tum_fr3();
  CullerCore<double> culler(camera, host_keyframes<double>());
  const double far_u = 4294967296.0 + 512.0;
  const std::vector<double> xy = {far_u, 240.0, 100.0, 100.0, 500.0, 300.0};
  std::vector<std::uint8_t> desc(3 * 32);
  for (std::size_t i = 0; i < desc.size(); ++i) desc[i] = static_cast<std::uint8_t>(i * 37 + 11);
  const std::vector<float> depth(640 * 480, 2.f);
  std::vector<Detection<double>> boxes;
  Rigid3<double> pose;
  CullerCoreFrame<double> f;
  f.keypoints = PointsView::of(xy.data(), 3);
  f.descriptors = DescriptorRows(desc.data(), 3, 0, 32);
  f.depth_m = DepthView<float>{depth.data(), 640, 480, 0, 1.f, 0.f, 1e30f};
  f.detections = &boxes;
  f.cam_from_world = &pose;
  const CullerResult& first = culler.cull(f);
  ASSERT_TRUE(first.keyframe) << first.reason;
  const std::int64_t far_id = first.track_ids[0];
  pose.t = Vec3<double>(-0.1, 0, 0);  // 0.1 m sideways: a point 2 m deep would move 26 px
  const CullerResult& second = culler.cull(f);
  EXPECT_EQ(second.track_ids[0], far_id) << second.reason;
}

}  // namespace
}  // namespace dyncull
