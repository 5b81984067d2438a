// Tests of culling/culler.hpp on a synthetic textured wall with known camera motion: the keyframe policy
// (own: by motion and by matched share; host-decided), stable track ids, the host's matches, the inputs a
// configuration lists, missing inputs and mismatched sizes named in the status, monocular and distortion
// statuses, and no default intrinsics.
#include "dyncull/culling/culler.hpp"

#include "dyncull/core/random.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace dyncull {
namespace {

/// Textured points 2.5-4 m in front of the world origin (= first camera frame; not one plane, so the
/// epipolar geometry is determined), seen by a camera translated by `x` metres along its x axis; every
/// point has its own 32-byte descriptor in every view, and its depth in a 5 x 5 patch of the depth image.
template <class T>
struct WallView {
  PinholeCamera<T> camera = PinholeCamera<T>::tum_fr3();
  std::vector<Vec2<T>> keypoints;
  std::vector<int> point_index;       // which wall point each keypoint sees
  std::vector<std::uint8_t> descriptors;  // 32 bytes per keypoint
  std::vector<float> depth;
  std::vector<Detection<T>> detections;
  Rigid3<T> cam_from_world;

  CullerFrame<T> frame() const {
    CullerFrame<T> f;
    f.keypoints = points_view(keypoints);
    f.descriptors = DescriptorRows(descriptors.data(), keypoints.size(), 0, 32);
    f.depth_m = DepthView<float>{depth.data(), camera.width, camera.height, 0, 1.f, 0.f, 1e30f};
    f.detections = &detections;
    f.cam_from_world = &cam_from_world;
    return f;
  }
};

constexpr int kWallPoints = 400;

template <class T>
WallView<T> wall_view(double x, std::uint64_t texture_seed = 3, bool reversed = false) {
  WallView<T> v;
  Random rng(11);  // the wall's points: the same in every view
  Random tex(texture_seed);
  v.cam_from_world.t = Vec3<T>(T(-x), T(0), T(0));
  v.depth.assign(static_cast<std::size_t>(v.camera.width * v.camera.height), 0.f);
  for (int j = 0; j < kWallPoints; ++j) {
    const double wx = rng.uniform(-2.0, 2.0), wy = rng.uniform(-1.4, 1.4), wz = rng.uniform(2.5, 4.0);
    std::uint8_t d[32];
    for (auto& b : d) b = static_cast<std::uint8_t>(tex.next() & 0xFF);
    const Vec3<T> pc = v.cam_from_world.apply(Vec3<T>(T(wx), T(wy), T(wz)));
    const Vec2<T> px = v.camera.project(pc);
    if (!v.camera.in_image(px.x(), px.y(), T(16))) continue;
    const int u0 = static_cast<int>(std::lround(px.x())), v0 = static_cast<int>(std::lround(px.y()));
    for (int dv = -2; dv <= 2; ++dv)
      for (int du = -2; du <= 2; ++du)
        v.depth[static_cast<std::size_t>((v0 + dv) * v.camera.width + u0 + du)] = static_cast<float>(pc.z());
    v.keypoints.push_back(px);
    v.point_index.push_back(j);
    v.descriptors.insert(v.descriptors.end(), d, d + 32);
  }
  if (reversed) {  // the same points in the opposite order: ids must follow the points, not the indices
    std::vector<Vec2<T>> k(v.keypoints.rbegin(), v.keypoints.rend());
    std::vector<int> p(v.point_index.rbegin(), v.point_index.rend());
    std::vector<std::uint8_t> d;
    for (std::size_t i = v.keypoints.size(); i-- > 0;)
      d.insert(d.end(), v.descriptors.begin() + 32 * i, v.descriptors.begin() + 32 * (i + 1));
    v.keypoints.swap(k);
    v.point_index.swap(p);
    v.descriptors.swap(d);
  }
  return v;
}

template <class T>
CullerOptions<T> host_keyframes() {
  CullerOptions<T> o;
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
  Culler<T> culler(camera);
  EXPECT_EQ(culler.status(), Status::InvalidInput);
  EXPECT_NE(culler.reason().find("camera"), std::string::npos) << culler.reason();
  const WallView<T> v = wall_view<T>(0);
  const CullerResult& r = culler.cull(v.frame());
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.reason.find("no default intrinsics"), std::string::npos) << r.reason;
  ASSERT_EQ(r.keep.size(), v.keypoints.size());
  for (std::uint8_t k : r.keep) EXPECT_EQ(k, 1);
}

TYPED_TEST(CullerTest, InvalidOptionsNameTheField) {
  using T = TypeParam;
  CullerOptions<T> o;
  o.keyframe_min_matched_ratio = 2;
  Culler<T> culler(PinholeCamera<T>::tum_fr3(), o);
  EXPECT_EQ(culler.status(), Status::InvalidInput);
  EXPECT_NE(culler.reason().find("keyframe_min_matched_ratio"), std::string::npos) << culler.reason();
}

TYPED_TEST(CullerTest, TrackIdsFollowTheKeyframePointsAcrossFrames) {
  using T = TypeParam;
  Culler<T> culler(PinholeCamera<T>::tum_fr3(), host_keyframes<T>());
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
  Culler<T> culler(PinholeCamera<T>::tum_fr3(), host_keyframes<T>());
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
  Culler<T> culler(PinholeCamera<T>::tum_fr3());
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
  Culler<T> culler(PinholeCamera<T>::tum_fr3());
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
  Culler<T> culler(PinholeCamera<T>::tum_fr3());
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
  Culler<T> culler(PinholeCamera<T>::tum_fr3(), host_keyframes<T>());
  EXPECT_TRUE(culler.cull(wall_view<T>(0).frame()).keyframe);  // the first frame always is one
  const WallView<T> far = wall_view<T>(0.3);
  EXPECT_FALSE(culler.cull(far.frame()).keyframe);  // the own policy would take it
  CullerFrame<T> f = wall_view<T>(0.01).frame();
  const WallView<T> v = wall_view<T>(0.01);
  f = v.frame();
  f.is_keyframe = true;
  EXPECT_TRUE(culler.cull(f).keyframe);
}

TYPED_TEST(CullerTest, HostMatchesReplaceOwnMatching) {
  using T = TypeParam;
  Culler<T> culler(PinholeCamera<T>::tum_fr3(), host_keyframes<T>());
  const WallView<T> v0 = wall_view<T>(0);
  const CullerResult r0 = culler.cull(v0.frame());
  const WallView<T> v1 = wall_view<T>(0.02, 3, true);
  std::vector<int> match(v1.keypoints.size(), -1);
  for (std::size_t i = 0; i < v1.keypoints.size(); ++i)
    for (std::size_t k = 0; k < v0.keypoints.size(); ++k)
      if (v0.point_index[k] == v1.point_index[i]) match[i] = static_cast<int>(k);
  CullerFrame<T> f = v1.frame();
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
  Culler<T> recommended(PinholeCamera<T>::tum_fr3());
  EXPECT_EQ(recommended.inputs().names(), "keypoints, descriptors, depth, detections, pose");
  CullerOptions<T> o;
  o.pipeline = presets::zhu_2024<T>();
  Culler<T> boxes_only(PinholeCamera<T>::tum_fr3(), o);
  EXPECT_EQ(boxes_only.inputs().names(), "keypoints, detections");
  o.pipeline = presets::dfd_slam<T>();
  o.keyframe_policy = KeyframePolicy::Host;
  Culler<T> epipolar(PinholeCamera<T>::tum_fr3(), o);
  EXPECT_EQ(epipolar.inputs().names(), "keypoints, descriptors, detections");
}

TYPED_TEST(CullerTest, MissingInputsAreNamed) {
  using T = TypeParam;
  struct Case {
    const char* name;
    void (*drop)(CullerFrame<T>*);
  };
  const Case cases[] = {
      {"descriptors", [](CullerFrame<T>* f) { f->descriptors = DescriptorRows(); }},
      {"detections", [](CullerFrame<T>* f) { f->detections = nullptr; }},
      {"pose", [](CullerFrame<T>* f) { f->cam_from_world = nullptr; }},
      {"depth", [](CullerFrame<T>* f) { f->depth_m = DepthView<float>{}; }},
  };
  for (const Case& c : cases) {
    Culler<T> culler(PinholeCamera<T>::tum_fr3());
    culler.cull(wall_view<T>(0).frame());
    const WallView<T> v = wall_view<T>(0.01);
    CullerFrame<T> f = v.frame();
    c.drop(&f);
    const CullerResult& r = culler.cull(f);
    EXPECT_EQ(r.status, Status::MissingInput) << c.name;
    EXPECT_EQ(r.missing.names(), c.name);
    EXPECT_NE(r.reason.find(std::string("missing input: ") + c.name), std::string::npos) << r.reason;
    EXPECT_EQ(r.keep.size(), v.keypoints.size());
  }
  Culler<T> culler(PinholeCamera<T>::tum_fr3());
  CullerFrame<T> none;
  const CullerResult& r = culler.cull(none);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.reason.find("keypoints"), std::string::npos) << r.reason;
}

TYPED_TEST(CullerTest, MonocularRunsAndSaysDepthStagesDidNotRun) {
  using T = TypeParam;
  Culler<T> culler(PinholeCamera<T>::tum_fr3());
  for (int k = 0; k < 3; ++k) {
    const WallView<T> v = wall_view<T>(0.01 * k);
    CullerFrame<T> f = v.frame();
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
    Culler<T> culler(PinholeCamera<T>::tum_fr3());
    CullerFrame<T> f = v.frame();
    f.descriptors.rows = n - 1;
    const CullerResult& r = culler.cull(f);
    EXPECT_EQ(r.status, Status::InvalidInput);
    EXPECT_NE(r.reason.find("descriptors has " + std::to_string(n - 1) + " rows"), std::string::npos) << r.reason;
    EXPECT_EQ(r.keep, std::vector<std::uint8_t>(n, 1));
    EXPECT_FALSE(culler.has_keyframe());  // a refused frame changes no state
  }
  {
    Culler<T> culler(PinholeCamera<T>::tum_fr3());
    CullerFrame<T> f = v.frame();
    f.undistorted_keypoints = PointsView::of(static_cast<const T*>(v.keypoints[0].data()), n - 2, sizeof(Vec2<T>));
    const CullerResult& r = culler.cull(f);
    EXPECT_EQ(r.status, Status::InvalidInput);
    EXPECT_NE(r.reason.find("undistorted_keypoints has"), std::string::npos) << r.reason;
  }
  {
    Culler<T> culler(PinholeCamera<T>::tum_fr3());
    CullerFrame<T> f = v.frame();
    f.depth_m.width = 320;
    const CullerResult& r = culler.cull(f);
    EXPECT_EQ(r.status, Status::InvalidInput);
    EXPECT_NE(r.reason.find("depth is 320x480"), std::string::npos) << r.reason;
  }
  {
    Culler<T> culler(PinholeCamera<T>::tum_fr3());
    CullerFrame<T> f = v.frame();
    const std::vector<std::uint16_t> raw(v.depth.size(), 15000);
    f.depth_raw = DepthView<std::uint16_t>{raw.data(), 640, 480, 0, 5000.f, 0.f, 1e30f};
    const CullerResult& r = culler.cull(f);
    EXPECT_EQ(r.status, Status::InvalidInput);
    EXPECT_NE(r.reason.find("not both"), std::string::npos) << r.reason;
  }
  {
    Culler<T> culler(PinholeCamera<T>::tum_fr3());
    CullerFrame<T> f = v.frame();
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
  CullerOptions<T> o;
  o.camera_has_distortion = true;
  Culler<T> culler(PinholeCamera<T>::tum_fr3(), o);
  const WallView<T> v = wall_view<T>(0);
  CullerFrame<T> f = v.frame();
  const CullerResult& r = culler.cull(f);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.reason.find("undistorted_keypoints"), std::string::npos) << r.reason;
  EXPECT_NE(r.reason.find("distortion"), std::string::npos) << r.reason;
  f.undistorted_keypoints = points_view(v.keypoints);
  const CullerResult& first = culler.cull(f);
  EXPECT_EQ(first.status, Status::MissingInput);  // no keyframe to track against yet
  EXPECT_NE(first.reason.find("first frame"), std::string::npos) << first.reason;
  const WallView<T> v1 = wall_view<T>(0.01);
  CullerFrame<T> f1 = v1.frame();
  f1.undistorted_keypoints = points_view(v1.keypoints);
  const CullerResult& second = culler.cull(f1);
  EXPECT_TRUE(second.ok()) << second.reason;
}

TYPED_TEST(CullerTest, Uint16DepthGivesTheSameResultAsMetres) {
  using T = TypeParam;
  Culler<T> metres(PinholeCamera<T>::tum_fr3()), raw(PinholeCamera<T>::tum_fr3());
  for (int k = 0; k < 3; ++k) {
    const WallView<T> v = wall_view<T>(0.01 * k);
    std::vector<std::uint16_t> depth(v.depth.size());  // 5000 per metre, as TUM's PNGs
    for (std::size_t i = 0; i < depth.size(); ++i) depth[i] = static_cast<std::uint16_t>(std::lround(v.depth[i] * 5000.f));
    CullerFrame<T> f = v.frame();
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

}  // namespace
}  // namespace dyncull
