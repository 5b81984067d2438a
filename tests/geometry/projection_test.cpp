// Tests of geometry/projection.hpp: project/back-project round trip (fx != fy, so eq. 6's fx typo
// would be caught), depth image to cloud with mask/stride/missing depth, voxel grid vs an oracle.
#include "dyncull/geometry/projection.hpp"

#include "support/adversarial.hpp"
#include "support/pose_data.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <map>
#include <string>
#include <tuple>
#include <vector>

namespace {

using dyncull::PinholeCamera;
using dyncull::Random;
using dyncull::Rigid3;
using dyncull::Status;
using dyncull::Vec2;
using dyncull::Vec3;

template <class T>
class ProjectionTest : public ::testing::Test {
 protected:
  static T tol() { return std::is_same<T, double>::value ? T(1e-9) : T(2e-4); }
};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(ProjectionTest, Scalars, dyncull::test::ScalarNames);

TYPED_TEST(ProjectionTest, ProjectBackprojectRoundTrip) {
  using T = TypeParam;
  const PinholeCamera<T> cam = PinholeCamera<T>::tum_fr3();  // fx = 535.4, fy = 539.2
  Random rng(61);
  const Rigid3<T> cfw = dyncull::test::random_rigid<T>(rng, 0.3, 0.5);
  std::vector<Vec3<T>> world;
  for (int i = 0; i < 200; ++i) {
    const Vec3<T> pc(T(rng.uniform(-2, 2)), T(rng.uniform(-1.5, 1.5)), T(rng.uniform(1, 6)));
    world.push_back(cfw.inverse().apply(pc));
  }
  world.push_back(cfw.inverse().apply(Vec3<T>(0, 0, -1)));  // behind the camera
  world.push_back(Vec3<T>(std::numeric_limits<T>::quiet_NaN(), 0, 0));
  std::vector<Vec2<T>> px(world.size());
  std::vector<std::uint8_t> valid(world.size());
  std::vector<T> z(world.size());
  EXPECT_EQ(dyncull::project_points(cam, cfw, world, px.data(), valid.data(), z.data()), 200u);
  EXPECT_EQ(valid[200], 0);
  EXPECT_EQ(valid[201], 0);
  EXPECT_TRUE(std::isnan(px[200].x()));
  std::vector<Vec3<T>> back(world.size());
  EXPECT_EQ(dyncull::backproject_points(cam, px, z.data(), back.data()), 200u);
  for (std::size_t i = 0; i < 200; ++i) {
    EXPECT_EQ(valid[i], 1);
    EXPECT_LT((cfw.inverse().apply(back[i]) - world[i]).norm(), this->tol() * T(10));
    // Same as the core camera's scalar path.
    EXPECT_LT((cam.project(cfw.apply(world[i])) - px[i]).norm(), this->tol() * T(100));
  }
}

TYPED_TEST(ProjectionTest, DepthToPointsUsesFyAndMask) {
  using T = TypeParam;
  PinholeCamera<T> cam{T(500), T(400), T(3.5), T(2.5), 8, 6};  // fx != fy on purpose
  std::vector<std::uint16_t> depth(48, 0);
  for (int v = 0; v < 6; ++v)
    for (int u = 0; u < 8; ++u) depth[static_cast<std::size_t>(v * 8 + u)] = static_cast<std::uint16_t>(5000 + 100 * u);
  depth[9] = 0;  // (1, 1) no measurement
  dyncull::Mask dyn(8, 6);
  dyn.view().at(2, 3) = 1;  // a dynamic pixel
  const auto view = dyncull::tum_depth_view(depth.data(), 8, 6);
  const auto cloud = dyncull::depth_to_points(view, cam, dyn.view(), 1);
  ASSERT_TRUE(cloud.ok()) << cloud.reason;
  EXPECT_EQ(cloud.points.size(), 46u);
  EXPECT_EQ(cloud.num_missing, 1u);
  EXPECT_EQ(cloud.num_excluded, 1u);
  for (std::size_t k = 0; k < cloud.points.size(); ++k) {
    const int u = static_cast<int>(cloud.pixel_index[k] % 8), v = static_cast<int>(cloud.pixel_index[k] / 8);
    EXPECT_FALSE(u == 2 && v == 3);
    const T zt = T(1) + T(0.02) * T(u);
    const Vec3<T>& p = cloud.points[k];
    // DepthView converts to float metres (core/depth.hpp): 1e-6 relative for both scalar types.
    const T tol = T(1e-6);
    EXPECT_NEAR(p.z(), zt, tol);
    EXPECT_NEAR(p.x(), (T(u) - T(3.5)) * zt / T(500), tol);
    EXPECT_NEAR(p.y(), (T(v) - T(2.5)) * zt / T(400), tol);  // fy, not fx (Zhu et al. 2024 eq. 6 typo)
  }
  // Stride 2 samples pixels (0, 2, 4, 6) x (0, 2, 4); none of them is missing or masked.
  const auto sparse = dyncull::depth_to_points(view, cam, dyncull::ConstMaskView{}, 2);
  EXPECT_EQ(sparse.points.size(), 12u);
  // Float-metre depth with NaN counts as missing.
  std::vector<float> dm(48, 2.f);
  dm[0] = std::numeric_limits<float>::quiet_NaN();
  dyncull::DepthView<float> fview{dm.data(), 8, 6};
  EXPECT_EQ(dyncull::depth_to_points(fview, cam).num_missing, 1u);
}

TYPED_TEST(ProjectionTest, DepthToPointsBadInput) {
  using T = TypeParam;
  PinholeCamera<T> cam{T(500), T(500), T(3.5), T(2.5), 8, 6};
  std::vector<std::uint16_t> depth(48, 5000);
  const auto view = dyncull::tum_depth_view(depth.data(), 8, 6);
  EXPECT_EQ(dyncull::depth_to_points(dyncull::DepthView<std::uint16_t>{}, cam).status, Status::InvalidInput);
  EXPECT_EQ(dyncull::depth_to_points(view, cam, {}, 0).status, Status::InvalidInput);
  dyncull::Mask wrong(4, 4);
  EXPECT_EQ(dyncull::depth_to_points(view, cam, wrong.view()).status, Status::InvalidInput);
  PinholeCamera<T> other = cam;
  other.width = 640;
  const auto r = dyncull::depth_to_points(view, other);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_FALSE(r.reason.empty());
  // All depth missing: an empty cloud, not an error.
  std::vector<std::uint16_t> none(48, 0);
  const auto e = dyncull::depth_to_points(dyncull::tum_depth_view(none.data(), 8, 6), cam);
  EXPECT_TRUE(e.ok());
  EXPECT_TRUE(e.points.empty());
  EXPECT_EQ(e.num_missing, 48u);
}

TYPED_TEST(ProjectionTest, ProjectionAtInfinityIsNotValid) {
  using T = TypeParam;
  const PinholeCamera<T> cam = PinholeCamera<T>::tum_fr3();
  // Just in front of the camera (z -> 0+) or far off-axis: x / z overflows, the pixel is not finite.
  const T tiny = std::numeric_limits<T>::denorm_min();
  const T big = std::numeric_limits<T>::max() / T(4);
  const std::vector<Vec3<T>> world = {Vec3<T>(T(1), T(0.5), tiny), Vec3<T>(big, T(0), T(0.5)),
                                      Vec3<T>(T(0), -big, T(1)), Vec3<T>(T(0.1), T(0.2), T(2))};
  std::vector<Vec2<T>> px(world.size());
  std::vector<std::uint8_t> valid(world.size(), 7);
  std::vector<T> z(world.size());
  const std::size_t n = dyncull::project_points(cam, Rigid3<T>{}, world, px.data(), valid.data(), z.data());
  EXPECT_EQ(n, 1u);
  for (std::size_t i = 0; i < world.size(); ++i) {
    EXPECT_EQ(valid[i], i == 3 ? 1 : 0) << i;
    EXPECT_EQ(px[i].allFinite(), i == 3) << i;
  }
  // Back-projection with a degenerate ray (tiny fx: 1 / fx is finite, (u - cx) z / fx is not) does not
  // count an infinite point as finite.
  PinholeCamera<T> thin = cam;
  thin.fx = T(16) / std::numeric_limits<T>::max();
  const std::vector<Vec2<T>> pix = {Vec2<T>(T(600), T(10)), Vec2<T>(thin.cx, T(10))};
  const std::vector<T> depth = {T(3), T(3)};
  std::vector<Vec3<T>> back(2);
  EXPECT_EQ(dyncull::backproject_points(thin, pix, depth.data(), back.data()), 1u);
  EXPECT_FALSE(back[0].allFinite());
  EXPECT_TRUE(back[1].allFinite());
}

TYPED_TEST(ProjectionTest, DepthToPointsRejectsImagesBeyondThirtyTwoBitPixelIndices) {
  using T = TypeParam;
  // 70000 x 66000 pixels (4.6e9 > 2^32): the pixel index of the last rows would wrap. The data pointer
  // is never read when the call rejects the size, so a one-row buffer stands in for the image.
  const int w = 70000, h = 66000;
  std::vector<std::uint16_t> row(static_cast<std::size_t>(w), 5000);
  const auto view = dyncull::tum_depth_view(row.data(), w, h);
  const PinholeCamera<T> cam{T(500), T(500), T(w / 2), T(h / 2), w, h};
  const auto cloud = dyncull::depth_to_points(view, cam, dyncull::ConstMaskView{}, 1000);
  EXPECT_EQ(cloud.status, Status::InvalidInput);
  EXPECT_NE(cloud.reason.find("2^32"), std::string::npos) << cloud.reason;
  EXPECT_TRUE(cloud.points.empty());
}

TYPED_TEST(ProjectionTest, DepthToPointsNeverReturnsNonFinitePoints) {
  using T = TypeParam;
  // fx so small that x / z overflows T at the image border: the camera cannot give finite rays.
  std::vector<float> dm(48, 2.f);
  const dyncull::DepthView<float> view{dm.data(), 8, 6};
  PinholeCamera<T> cam{std::numeric_limits<T>::denorm_min(), T(400), T(3.5), T(2.5), 8, 6};
  const auto bad = dyncull::depth_to_points(view, cam);
  EXPECT_EQ(bad.status, Status::InvalidInput);
  EXPECT_NE(bad.reason.find("fx"), std::string::npos) << bad.reason;
  // A focal length no camera has (PinholeCamera::validate: at least 1e-3 times the larger side), whose
  // rays times a huge depth (accepted: max_m is 1e30) would overflow T, is refused as well.
  cam.fx = std::is_same<T, float>::value ? T(1e-15) : T(1e-300);
  dm[5] = 1e30f;
  const auto absurd = dyncull::depth_to_points(view, cam);
  EXPECT_EQ(absurd.status, Status::InvalidInput);
  // The smallest focal length a camera has keeps every point of a huge depth finite.
  cam.fx = T(8e-3);
  const auto cloud = dyncull::depth_to_points(view, cam);
  ASSERT_TRUE(cloud.ok()) << cloud.reason;
  for (const auto& p : cloud.points) EXPECT_TRUE(p.allFinite());
  EXPECT_EQ(cloud.points.size() + cloud.num_missing, 48u);
}

// A value for property tests: mostly ordinary, sometimes NaN, Inf, huge or tiny (tests/support/adversarial.hpp).
template <class T>
T wild(Random& rng, double lo, double hi) {
  return dyncull::test::adversarial_value<T>(rng, lo, hi, dyncull::test::kProjectionMix);
}

TYPED_TEST(ProjectionTest, PropertyOutputsAreFiniteOrFlagged) {
  using T = TypeParam;
  Random rng(77);
  for (int trial = 0; trial < 300; ++trial) {
    PinholeCamera<T> cam{wild<T>(rng, 1, 1000), wild<T>(rng, 1, 1000), wild<T>(rng, -50, 700), wild<T>(rng, -50, 500),
                         1 + static_cast<int>(rng.index(40)), 1 + static_cast<int>(rng.index(30))};
    // project / backproject: a point counted valid has a finite pixel (finite camera point).
    const std::size_t n = rng.index(40);
    std::vector<Vec3<T>> world(n);
    std::vector<Vec2<T>> pix(n);
    std::vector<T> depth(n);
    for (std::size_t i = 0; i < n; ++i) {
      world[i] = Vec3<T>(wild<T>(rng, -5, 5), wild<T>(rng, -5, 5), wild<T>(rng, -1, 8));
      pix[i] = Vec2<T>(wild<T>(rng, -10, 700), wild<T>(rng, -10, 500));
      depth[i] = wild<T>(rng, -1, 10);
    }
    std::vector<Vec2<T>> px(n);
    std::vector<std::uint8_t> valid(n);
    std::vector<Vec3<T>> back(n);
    const std::size_t nv = dyncull::project_points(cam, Rigid3<T>{}, world, px.data(), valid.data());
    const std::size_t nb = dyncull::backproject_points(cam, pix, depth.data(), back.data());
    std::size_t count_v = 0, count_b = 0;
    for (std::size_t i = 0; i < n; ++i) {
      count_v += valid[i];
      EXPECT_EQ(valid[i] != 0, px[i].allFinite()) << trial << " " << i;
      count_b += back[i].allFinite();
    }
    EXPECT_EQ(nv, count_v);
    EXPECT_EQ(nb, count_b);
    // depth_to_points: non-Ok with a reason, or every point finite and every index in the image.
    const int w = cam.width, h = cam.height;
    std::vector<float> dm(static_cast<std::size_t>(w * h));
    for (auto& d : dm) d = wild<float>(rng, 0, 12);
    dyncull::DepthView<float> view{dm.data(), w, h};
    if (rng.uniform() < 0.2) view.units_per_metre = wild<float>(rng, -2, 2);
    if (rng.uniform() < 0.2) view.max_m = wild<float>(rng, 0, 1e30);
    const int stride = rng.uniform() < 0.1 ? static_cast<int>(rng.index(3)) - 1 : 1 + static_cast<int>(rng.index(4));
    const auto cloud = dyncull::depth_to_points(view, cam, dyncull::ConstMaskView{}, stride);
    if (!cloud.ok()) {
      EXPECT_EQ(cloud.status, Status::InvalidInput);
      EXPECT_FALSE(cloud.reason.empty());
      EXPECT_TRUE(cloud.points.empty());
      continue;
    }
    ASSERT_EQ(cloud.points.size(), cloud.pixel_index.size());
    for (std::size_t k = 0; k < cloud.points.size(); ++k) {
      EXPECT_TRUE(cloud.points[k].allFinite()) << "trial " << trial;
      EXPECT_LT(cloud.pixel_index[k], static_cast<std::uint32_t>(w * h));
    }
    // Voxel downsampling of whatever came out, with a random voxel size.
    std::vector<Vec3<T>> vox;
    std::string why;
    const T voxel = wild<T>(rng, 0.01, 1);
    if (dyncull::voxel_downsample(back, voxel, &vox, &why) != Status::Ok) {
      EXPECT_FALSE(why.empty());
    } else {
      for (const auto& p : vox) EXPECT_TRUE(p.allFinite());
    }
  }
}

TYPED_TEST(ProjectionTest, VoxelCentroidOfHugeCoordinatesStaysFinite) {
  using T = TypeParam;
  // Two points near the largest finite value in one voxel: their sum overflows, their mean does not.
  const T big = std::numeric_limits<T>::max() * T(0.75);
  const std::vector<Vec3<T>> pts = {Vec3<T>(big, -big, big), Vec3<T>(big, -big, big)};
  std::vector<Vec3<T>> out;
  ASSERT_EQ(dyncull::voxel_downsample(pts, T(1), &out), Status::Ok);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_TRUE(out[0].allFinite()) << out[0].transpose();
  EXPECT_EQ(out[0].x(), big);
}

TYPED_TEST(ProjectionTest, VoxelDownsampleMatchesOracle) {
  using T = TypeParam;
  Random rng(62);
  std::vector<Vec3<T>> pts;
  for (int i = 0; i < 5000; ++i) pts.push_back(dyncull::test::random_points<T>(rng, 1, Vec3<T>(1, -2, 3), 0.5).col(0));
  pts.push_back(Vec3<T>(std::numeric_limits<T>::quiet_NaN(), 0, 0));
  const T voxel = T(0.1);
  dyncull::VoxelDownsampler<T> ds;
  std::vector<Vec3<T>> out;
  ASSERT_EQ(ds.run(pts, voxel, &out), Status::Ok);
  // Oracle: std::map keyed by floor((p - min) / voxel), centroid in double.
  Vec3<T> lo = Vec3<T>::Constant(T(1e9));
  for (std::size_t i = 0; i + 1 < pts.size(); ++i) lo = lo.cwiseMin(pts[i]);
  std::map<std::tuple<long, long, long>, std::pair<Vec3<double>, int>> cells;
  for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
    const Vec3<T> c = ((pts[i] - lo) * (T(1) / voxel)).array().floor();
    auto key = std::make_tuple(static_cast<long>(c(0)), static_cast<long>(c(1)), static_cast<long>(c(2)));
    auto it = cells.find(key);
    if (it == cells.end()) it = cells.emplace(key, std::make_pair(Vec3<double>::Zero().eval(), 0)).first;
    auto& cell = it->second;
    cell.first += pts[i].template cast<double>();
    cell.second += 1;
  }
  ASSERT_EQ(out.size(), cells.size());
  std::size_t k = 0;
  for (const auto& kv : cells) {  // map order = (x, y, z) lexicographic = our key order
    const Vec3<double> centroid = kv.second.first / kv.second.second;
    EXPECT_LT((out[k++].template cast<double>() - centroid).norm(), 1e-6);
  }
  // Reuse: same result on a second call with the warm buffer.
  std::vector<Vec3<T>> again;
  ASSERT_EQ(ds.run(pts, voxel, &again), Status::Ok);
  EXPECT_EQ(again.size(), out.size());
  std::string why;
  EXPECT_EQ(dyncull::voxel_downsample(pts, T(0), &out, &why), Status::InvalidInput);
  EXPECT_FALSE(why.empty());
  EXPECT_EQ(dyncull::voxel_downsample(pts, T(1e-9), &out), Status::InvalidInput);
  EXPECT_EQ(dyncull::voxel_downsample(std::vector<Vec3<T>>{}, voxel, &out), Status::Ok);
  EXPECT_TRUE(out.empty());
}

}  // namespace
