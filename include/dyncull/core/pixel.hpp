/// @file pixel.hpp
/// Real values to integers, range-checked in floating point before any conversion, so NaN, Inf and
/// values beyond the int range never wrap into range (a raw conversion of those is undefined).
/// Pixel coordinates: pixel u has its centre at u, so a coordinate belongs to the nearest centre,
/// round(x) (half away from zero, as std::lround): pixel_index, pixel_of. Other real values (cells,
/// bins, radii, counts, class ids read from files): clamped_int, checked_int. scripts/check-casts.sh
/// fails on a raw float-to-int conversion elsewhere that carries no "checked:" comment.
#pragma once

#include <cmath>
#include <limits>
#include <type_traits>

namespace dyncull {

/// x truncated toward zero (as static_cast<int>) after clamping to [lo, hi] in floating point: NaN and
/// values below lo give lo, values at or above hi give hi. For indices whose range is known (a grid
/// cell, a histogram bin), where an outlier belongs in the first or last one. Requires lo <= hi.
template <class X>
int clamped_int(X x, int lo, int hi) {
  static_assert(std::is_floating_point<X>::value, "clamped_int: x must be a floating-point value");
  const double d = static_cast<double>(x);  // exact for float and double
  if (!(d >= static_cast<double>(lo))) return lo;
  if (d >= static_cast<double>(hi)) return hi;
  return static_cast<int>(d);  // checked: lo <= d < hi
}

/// x truncated toward zero into *out when x is finite and the result lies in [lo, hi]; false (and *out
/// left alone) otherwise. For values that must be refused, not clamped, when out of range (a count or a
/// class id read from a file).
template <class X>
bool checked_int(X x, int lo, int hi, int* out) {
  static_assert(std::is_floating_point<X>::value, "checked_int: x must be a floating-point value");
  const double t = std::trunc(static_cast<double>(x));
  if (!(t >= static_cast<double>(lo) && t <= static_cast<double>(hi))) return false;  // NaN fails both
  *out = static_cast<int>(t);  // checked: lo <= t <= hi
  return true;
}

/// Index of the pixel whose centre is nearest to x, when x is finite and that pixel lies in
/// [0, size). Returns false (and leaves *index alone) otherwise, including for size <= 0.
template <class T>
bool pixel_index(T x, int size, int* index) {
  static_assert(std::is_floating_point<T>::value, "pixel_index: x must be a floating-point coordinate");
  using std::round;
  // Compared in double: exact for float and double, and T(size) could round up in float.
  const double r = static_cast<double>(round(x));
  if (!(r >= 0.0 && r < static_cast<double>(size))) return false;  // NaN fails both
  *index = static_cast<int>(r);  // checked: 0 <= r < size
  return true;
}

/// Pixel (u, v) nearest to (x, y) inside a width x height image; false (outputs untouched) when
/// either coordinate is non-finite or falls outside.
template <class T>
bool pixel_of(T x, T y, int width, int height, int* u, int* v) {
  int pu = 0, pv = 0;
  if (!pixel_index(x, width, &pu) || !pixel_index(y, height, &pv)) return false;
  *u = pu;
  *v = pv;
  return true;
}

}  // namespace dyncull
