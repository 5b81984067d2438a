// Ray casting of boxes, ellipsoids and the room interior against closed-form hits, screen bounds
// that contain every hit pixel, and the procedural texture's determinism and contrast.
#include "dyncull/sim/primitives.hpp"
#include "dyncull/sim/texture.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

namespace {

using dyncull::PinholeCamera;
using dyncull::Rigid3;
using dyncull::Vec2;
using dyncull::Vec3;
using namespace dyncull::sim;

Primitive make(PrimitiveShape shape, const Vec3<double>& centre, const Vec3<double>& half) {
  Primitive p;
  p.shape = shape;
  p.half_extents = half;
  p.world_from_local.t = centre;
  return p;
}

TEST(SimPrimitives, SphereHitMatchesClosedForm) {
  // Camera at the origin looking along +z (world = camera); sphere of radius 0.5 at z = 3.
  const Primitive s = make(PrimitiveShape::Ellipsoid, {0, 0, 3}, {0.5, 0.5, 0.5});
  const auto cam = PinholeCamera<double>::tum_fr3();
  const CameraPrimitive cp = prepare(s, Rigid3<double>::identity(), cam, 0.05);
  EXPECT_NEAR(intersect(s, cp, {0, 0, 1}, 0.05), 2.5, 1e-12);
  // Oblique ray (x/z = 0.1): |lambda (0.1, 0, 1) - (0, 0, 3)| = 0.5.
  const double lambda = intersect(s, cp, {0.1, 0, 1}, 0.05);
  EXPECT_NEAR((lambda * Vec3<double>(0.1, 0, 1) - Vec3<double>(0, 0, 3)).norm(), 0.5, 1e-12);
  EXPECT_EQ(intersect(s, cp, {0.5, 0, 1}, 0.05), kNoHit);  // passes beside it
  // Behind the camera: no hit.
  const Primitive behind = make(PrimitiveShape::Ellipsoid, {0, 0, -3}, {0.5, 0.5, 0.5});
  const CameraPrimitive cpb = prepare(behind, Rigid3<double>::identity(), cam, 0.05);
  EXPECT_EQ(intersect(behind, cpb, {0, 0, 1}, 0.05), kNoHit);
}

TEST(SimPrimitives, RotatedEllipsoidAndBoxHitsLieOnTheirSurfaces) {
  Primitive e = make(PrimitiveShape::Ellipsoid, {0.2, -0.1, 2.5}, {0.3, 0.6, 0.2});
  e.world_from_local.R = Eigen::AngleAxisd(0.7, Vec3<double>(1, 2, 3).normalized()).toRotationMatrix();
  Primitive b = make(PrimitiveShape::Box, {-0.3, 0.2, 3.0}, {0.4, 0.2, 0.3});
  b.world_from_local.R = Eigen::AngleAxisd(-0.4, Vec3<double>(0, 1, 1).normalized()).toRotationMatrix();
  const auto cam = PinholeCamera<double>::tum_fr3();
  for (const Primitive* p : {&e, &b}) {
    const CameraPrimitive cp = prepare(*p, Rigid3<double>::identity(), cam, 0.05);
    int hits = 0;
    for (int v = 0; v < cam.height; v += 4) {
      for (int u = 0; u < cam.width; u += 4) {
        const Vec3<double> ray = cam.ray(Vec2<double>(u, v));
        const double lambda = intersect(*p, cp, ray, 0.05);
        if (lambda == kNoHit) continue;
        ++hits;
        // Every hit pixel lies inside the screen bounds used to skip pixels.
        EXPECT_TRUE(u >= cp.bounds.c0 && u < cp.bounds.c1 && v >= cp.bounds.r0 && v < cp.bounds.r1);
        const Vec3<double> local = p->world_from_local.inverse().apply(lambda * ray);
        const Vec3<double> scaled = local.cwiseQuotient(p->half_extents);
        const double level = p->shape == PrimitiveShape::Ellipsoid ? scaled.norm() : scaled.cwiseAbs().maxCoeff();
        EXPECT_NEAR(level, 1.0, 1e-9);
        int axis = -2;
        const Vec3<double> n = local_normal(*p, local, &axis);
        EXPECT_NEAR(n.norm(), 1.0, 1e-12);
        EXPECT_LT(n.dot(p->world_from_local.R.transpose() * ray), 0.0);  // faces the camera
        EXPECT_EQ(axis >= 0, p->shape == PrimitiveShape::Box);
      }
    }
    EXPECT_GT(hits, 100);
  }
}

TEST(SimPrimitives, RoomInteriorIsHitByEveryRayFromInside) {
  const Primitive room = make(PrimitiveShape::RoomInterior, {0, 0, 1}, {3, 2, 4});
  const auto cam = PinholeCamera<double>::tum_fr3();
  const CameraPrimitive cp = prepare(room, Rigid3<double>::identity(), cam, 0.05);
  EXPECT_EQ(cp.bounds.area(), static_cast<long long>(cam.width) * cam.height);
  EXPECT_NEAR(intersect(room, cp, {0, 0, 1}, 0.05), 5.0, 1e-12);  // far wall at z = 1 + 4
  for (int v = 0; v < cam.height; v += 37) {
    for (int u = 0; u < cam.width; u += 41) {
      const Vec3<double> ray = cam.ray(Vec2<double>(u, v));
      const double lambda = intersect(room, cp, ray, 0.05);
      ASSERT_LT(lambda, kNoHit);
      const Vec3<double> local = lambda * ray - Vec3<double>(0, 0, 1);
      EXPECT_NEAR(local.cwiseQuotient(room.half_extents).cwiseAbs().maxCoeff(), 1.0, 1e-9);
      int axis = -1;
      EXPECT_LT(local_normal(room, local, &axis).dot(ray), 0.0);  // inward normal faces the camera
    }
  }
}

TEST(SimPrimitives, PrimitiveStraddlingTheNearPlaneUsesTheWholeImage) {
  const Primitive big = make(PrimitiveShape::Box, {0, 0, 0.5}, {1, 1, 1});  // camera inside its bounds
  const auto cam = PinholeCamera<double>::tum_fr3();
  EXPECT_EQ(prepare(big, Rigid3<double>::identity(), cam, 0.05).bounds.area(),
            static_cast<long long>(cam.width) * cam.height);
  const Primitive off = make(PrimitiveShape::Box, {50, 0, 3}, {0.2, 0.2, 0.2});  // far outside the view
  EXPECT_TRUE(prepare(off, Rigid3<double>::identity(), cam, 0.05).bounds.empty());
}

TEST(SimTexture, DeterministicVariedAndBounded) {
  double lo = 1, hi = 0, sum = 0;
  int changes = 0;
  double previous = texture_value(Vec3<double>(0, 0, 0), 0.1, 5);
  for (int k = 0; k < 2000; ++k) {
    const Vec3<double> p(0.013 * k, 0.007 * k, 0.0);
    const double a = texture_value(p, 0.1, 5);
    EXPECT_EQ(a, texture_value(p, 0.1, 5));
    lo = std::min(lo, a);
    hi = std::max(hi, a);
    sum += a;
    changes += a != previous ? 1 : 0;
    previous = a;
  }
  EXPECT_GE(lo, 0.08);
  EXPECT_LE(hi, 1.0);
  EXPECT_GT(hi - lo, 0.6);       // strong contrast somewhere along the line
  EXPECT_GT(changes, 200);       // cells of ~0.1 m and ~0.04 m cross a 30 m line many times
  EXPECT_NEAR(sum / 2000, 0.54, 0.08);
  EXPECT_NE(texture_value(Vec3<double>(0.05, 0.05, 0), 0.1, 5), texture_value(Vec3<double>(0.05, 0.05, 0), 0.1, 6));
}

}  // namespace
