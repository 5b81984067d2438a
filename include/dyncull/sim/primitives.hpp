/// @file primitives.hpp
/// Ray casting of the synthetic scene's primitives (oriented boxes, ellipsoids and the room seen
/// from inside), with rays from the camera centre x = lambda (x/z, y/z, 1) so lambda is the depth z.
#pragma once

#include "dyncull/core/box.hpp"
#include "dyncull/core/camera.hpp"
#include "dyncull/core/types.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace dyncull::sim {

enum class PrimitiveShape : std::uint8_t {
  Box,           ///< solid oriented box, seen from outside
  Ellipsoid,     ///< solid ellipsoid with semi-axes half_extents along its local axes
  RoomInterior,  ///< box seen from inside (walls, floor, ceiling): every ray from inside hits it
};

/// One textured primitive at one instant, in world coordinates.
struct Primitive {
  PrimitiveShape shape = PrimitiveShape::Box;
  Vec3<double> half_extents = Vec3<double>::Constant(0.5);  ///< metres, along local axes
  Rigid3<double> world_from_local;
  std::uint16_t instance = 0;          ///< 0 = static background / furniture without a detector class
  std::uint8_t moving = 0;             ///< 1 when the primitive moves in the world around this frame
  std::uint32_t texture_seed = 0;      ///< texture pattern (fixed per primitive so features track)
  double texture_cell_m = 0.1;         ///< coarse texture cell size in metres
  double texture_contrast = 1.0;       ///< 1 = full texture; smaller blends towards mid-grey (plainer walls)
  Vec3<double> albedo = Vec3<double>::Constant(0.8);  ///< RGB in [0, 1]
};

/// A primitive prepared for casting rays from one camera: everything in the camera's frame.
struct CameraPrimitive {
  Mat3<double> local_from_cam_R;  ///< local direction = R * camera direction
  Vec3<double> origin_local;      ///< camera centre in local coordinates
  Vec3<double> inv_half;          ///< 1 / half_extents (ellipsoid scaling)
  PixelRect bounds;               ///< pixels whose rays may hit the primitive
};

namespace detail {

/// Smallest positive distance to avoid 0 * inf in the slab test for axis-parallel rays.
constexpr double kTinyDirection = 1e-15;

inline double safe_inverse(double d) {
  if (std::abs(d) < kTinyDirection) d = d < 0 ? -kTinyDirection : kTinyDirection;
  return 1.0 / d;
}

}  // namespace detail

constexpr double kNoHit = std::numeric_limits<double>::infinity();

/// Entry (outside) or exit (RoomInterior) parameter of the ray o + lambda d with the box |x_i| <= h_i,
/// or kNoHit when the ray misses or the hit is not beyond min_lambda.
inline double intersect_box(const Vec3<double>& o, const Vec3<double>& d, const Vec3<double>& h, bool interior,
                            double min_lambda) {
  double t_near = -kNoHit, t_far = kNoHit;
  for (int i = 0; i < 3; ++i) {
    const double inv = detail::safe_inverse(d[i]);
    double t1 = (-h[i] - o[i]) * inv;
    double t2 = (h[i] - o[i]) * inv;
    if (t1 > t2) std::swap(t1, t2);
    t_near = std::max(t_near, t1);
    t_far = std::min(t_far, t2);
  }
  if (t_near > t_far) return kNoHit;
  if (interior) return t_far > min_lambda ? t_far : kNoHit;
  if (t_near > min_lambda) return t_near;
  return kNoHit;  // camera inside a solid box: treat as invisible rather than a wall at the lens
}

/// First hit of o + lambda d with the ellipsoid whose scaled coordinates are (o_s, d_s) (unit sphere).
inline double intersect_unit_sphere(const Vec3<double>& o_s, const Vec3<double>& d_s, double min_lambda) {
  const double a = d_s.squaredNorm();
  const double b = o_s.dot(d_s);
  const double c = o_s.squaredNorm() - 1.0;
  const double disc = b * b - a * c;
  if (disc < 0.0 || a <= 0.0) return kNoHit;
  const double lambda = (-b - std::sqrt(disc)) / a;
  return lambda > min_lambda ? lambda : kNoHit;
}

/// Hit depth of one prepared primitive along a ray whose direction, rotated into the primitive's
/// frame, is d_local = local_from_cam_R * (x/z, y/z, 1); kNoHit when missed.
inline double intersect_local(const Primitive& prim, const CameraPrimitive& cp, const Vec3<double>& d_local,
                              double min_lambda) {
  switch (prim.shape) {
    case PrimitiveShape::Ellipsoid:
      return intersect_unit_sphere(cp.origin_local.cwiseProduct(cp.inv_half), d_local.cwiseProduct(cp.inv_half),
                                   min_lambda);
    case PrimitiveShape::Box:
      return intersect_box(cp.origin_local, d_local, prim.half_extents, false, min_lambda);
    case PrimitiveShape::RoomInterior:
      return intersect_box(cp.origin_local, d_local, prim.half_extents, true, min_lambda);
  }
  return kNoHit;
}

/// Hit depth (lambda along the unit-depth camera ray d_cam) of one prepared primitive, or kNoHit.
inline double intersect(const Primitive& prim, const CameraPrimitive& cp, const Vec3<double>& d_cam,
                        double min_lambda) {
  return intersect_local(prim, cp, cp.local_from_cam_R * d_cam, min_lambda);
}

/// Outward unit normal (inward for RoomInterior) in local coordinates at a surface point, and for
/// boxes the index of the face axis (0..2), or -1 for ellipsoids.
inline Vec3<double> local_normal(const Primitive& prim, const Vec3<double>& p, int* face_axis) {
  if (prim.shape == PrimitiveShape::Ellipsoid) {
    *face_axis = -1;
    const Vec3<double> g = p.cwiseQuotient(prim.half_extents.cwiseProduct(prim.half_extents));
    return g.normalized();
  }
  // The face is the axis where the point is closest (relatively) to the box boundary.
  int axis = 0;
  double best = kNoHit;
  for (int i = 0; i < 3; ++i) {
    const double gap = std::abs(prim.half_extents[i] - std::abs(p[i])) / prim.half_extents[i];
    if (gap < best) {
      best = gap;
      axis = i;
    }
  }
  *face_axis = axis;
  Vec3<double> n = Vec3<double>::Zero();
  n[axis] = p[axis] >= 0 ? 1.0 : -1.0;
  if (prim.shape == PrimitiveShape::RoomInterior) n = -n;
  return n;
}

/// Prepares a primitive for a camera (cam_from_world) and computes the pixel bounds of its
/// projected bounding box; when a corner lies behind the near plane the bounds are the whole image.
inline CameraPrimitive prepare(const Primitive& prim, const Rigid3<double>& cam_from_world,
                               const PinholeCamera<double>& camera, double near_m) {
  CameraPrimitive cp;
  const Rigid3<double> cam_from_local = cam_from_world * prim.world_from_local;
  const Rigid3<double> local_from_cam = cam_from_local.inverse();
  cp.local_from_cam_R = local_from_cam.R;
  cp.origin_local = local_from_cam.t;
  cp.inv_half = prim.half_extents.cwiseInverse();
  const PixelRect full{0, 0, camera.width, camera.height};
  if (prim.shape == PrimitiveShape::RoomInterior) {
    cp.bounds = full;
    return cp;
  }
  double u0 = kNoHit, v0 = kNoHit, u1 = -kNoHit, v1 = -kNoHit;
  for (int corner = 0; corner < 8; ++corner) {
    const Vec3<double> local((corner & 1) ? prim.half_extents.x() : -prim.half_extents.x(),
                             (corner & 2) ? prim.half_extents.y() : -prim.half_extents.y(),
                             (corner & 4) ? prim.half_extents.z() : -prim.half_extents.z());
    const Vec3<double> pc = cam_from_local.apply(local);
    if (pc.z() < near_m) {
      cp.bounds = full;
      return cp;
    }
    const Vec2<double> uv = camera.project(pc);
    u0 = std::min(u0, uv.x());
    v0 = std::min(v0, uv.y());
    u1 = std::max(u1, uv.x());
    v1 = std::max(v1, uv.y());
  }
  // One pixel of slack: the box of the corners bounds the primitive, the slack covers rounding.
  cp.bounds = pixel_rect(Box<double>{u0 - 1.0, v0 - 1.0, u1 + 1.0, v1 + 1.0}, camera.width, camera.height);
  return cp;
}

}  // namespace dyncull::sim
