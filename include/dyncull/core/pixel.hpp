/// @file pixel.hpp
/// Real pixel coordinates to integer pixel indices. Pixel u has its centre at u, so a coordinate
/// belongs to the nearest centre, round(x) (half away from zero, as std::lround). The range test is
/// done in floating point before any conversion: NaN, Inf and coordinates beyond the int range
/// never wrap back into the image.
#pragma once

#include <cmath>
#include <type_traits>

namespace dyncull {

/// Index of the pixel whose centre is nearest to x, when x is finite and that pixel lies in
/// [0, size). Returns false (and leaves *index alone) otherwise, including for size <= 0.
template <class T>
bool pixel_index(T x, int size, int* index) {
  static_assert(std::is_floating_point<T>::value, "pixel_index: x must be a floating-point coordinate");
  using std::round;
  // Compared in double: exact for float and double, and T(size) could round up in float.
  const double r = static_cast<double>(round(x));
  if (!(r >= 0.0 && r < static_cast<double>(size))) return false;  // NaN fails both
  *index = static_cast<int>(r);
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
