// A synthetic textured wall seen by a translating camera, with descriptors, depth and the pose: the frame
// the culler tests feed (tests/culling/culler_test.cpp, culler_public_test.cpp).
#pragma once

#include "dyncull/core/camera.hpp"
#include "dyncull/core/random.hpp"
#include "dyncull/culling/culler_core.hpp"

#include <cmath>
#include <cstdint>
#include <vector>

namespace dyncull {
namespace test {

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

  CullerCoreFrame<T> frame() const {
    CullerCoreFrame<T> f;
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

}  // namespace test
}  // namespace dyncull
