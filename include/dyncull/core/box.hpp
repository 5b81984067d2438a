/// @file box.hpp
/// Axis-aligned image boxes and detector detections. A Box holds pixel corners in continuous
/// coordinates, [x0, x1] x [y0, y1] inclusive; pixel (u, v) has its centre at (u, v).
#pragma once

#include "dyncull/core/pixel.hpp"
#include "dyncull/core/types.hpp"

#include <algorithm>
#include <cmath>

namespace dyncull {

template <class T>
struct Box {
  T x0 = T(0), y0 = T(0), x1 = T(0), y1 = T(0);

  T width() const { return x1 - x0; }
  T height() const { return y1 - y0; }
  T area() const { return std::max(T(0), width()) * std::max(T(0), height()); }
  Vec2<T> centre() const { return Vec2<T>((x0 + x1) / T(2), (y0 + y1) / T(2)); }
  bool contains(T x, T y) const { return x >= x0 && x <= x1 && y >= y0 && y <= y1; }
  bool finite() const { return std::isfinite(x0) && std::isfinite(y0) && std::isfinite(x1) && std::isfinite(y1); }
  /// Non-empty and finite.
  bool valid() const { return finite() && x1 >= x0 && y1 >= y0; }
  /// Grown by `pad` pixels on every side (negative shrinks).
  Box padded(T pad) const { return Box{x0 - pad, y0 - pad, x1 + pad, y1 + pad}; }
  /// Intersection with the pixel centres of a width x height image, [0, width-1] x [0, height-1].
  /// A box that misses the image, an empty image (width or height <= 0) and a non-finite box give an
  /// invalid box (inverted or NaN, area 0).
  Box clipped(int width, int height) const {
    if (width <= 0 || height <= 0) return Box{T(0), T(0), T(-1), T(-1)};
    const T xmax = T(width) - T(1), ymax = T(height) - T(1);
    // max/min, not clamp: a corner beyond the far edge must stay there so the box inverts.
    // std::max(NaN, 0) returns the NaN, which keeps a NaN box invalid.
    return Box{std::max(x0, T(0)), std::max(y0, T(0)), std::min(x1, xmax), std::min(y1, ymax)};
  }
  template <class U> Box<U> cast() const { return Box<U>{U(x0), U(y0), U(x1), U(y1)}; }
};

/// Intersection over union of two boxes (0 when either is empty).
template <class T>
T iou(const Box<T>& a, const Box<T>& b) {
  const Box<T> inter{std::max(a.x0, b.x0), std::max(a.y0, b.y0), std::min(a.x1, b.x1), std::min(a.y1, b.y1)};
  const T i = inter.area();
  const T u = a.area() + b.area() - i;
  return u > T(0) ? i / u : T(0);
}

/// Integer pixel range of a box inside an image: columns [c0, c1), rows [r0, r1); empty when
/// c0 >= c1 or r0 >= r1. A pixel belongs to the box when its centre does.
struct PixelRect {
  int c0 = 0, r0 = 0, c1 = 0, r1 = 0;
  bool empty() const { return c0 >= c1 || r0 >= r1; }
  int width() const { return c1 - c0; }
  int height() const { return r1 - r0; }
  long long area() const { return empty() ? 0 : static_cast<long long>(width()) * height(); }
};

template <class T>
PixelRect pixel_rect(const Box<T>& box, int width, int height) {
  PixelRect r;
  if (!box.valid() || width <= 0 || height <= 0) return r;
  using std::ceil;
  using std::floor;
  // Clamped to [0, size] before the conversion: corners beyond the int range are finite user input,
  // and converting them raw would be undefined. Double holds every float, double and int.
  auto index = [](double v, int size) { return clamped_int(v, 0, size); };
  r.c0 = index(static_cast<double>(ceil(box.x0)), width);
  r.r0 = index(static_cast<double>(ceil(box.y0)), height);
  r.c1 = index(static_cast<double>(floor(box.x1)) + 1.0, width);
  r.r1 = index(static_cast<double>(floor(box.y1)) + 1.0, height);
  if (r.c1 < r.c0) r.c1 = r.c0;
  if (r.r1 < r.r0) r.r1 = r.r0;
  return r;
}

/// One detector output after NMS: box in pixels, class id (COCO-80 index by default) and score.
template <class T>
struct Detection {
  Box<T> box;
  int class_id = -1;
  T confidence = T(1);
};

}  // namespace dyncull
