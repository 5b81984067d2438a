/// @file point_grid.hpp
/// A uniform grid over a 2-D point set's own extent, its points counting-sorted by cell, for radius
/// searches: the keypoint grid of ORB-SLAM's Frame (Mur-Artal and Tardós 2017, Frame::AssignFeaturesToGrid)
/// sized to the points rather than to the image, so points off the image are still found. No paper equation.
#pragma once

#include "dyncull/core/pixel.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace dyncull {

/// Cells of `cell` pixels from (x0, y0), `cols` x `rows` of them; cell c holds sorted positions
/// [cell_start[c], cell_start[c + 1]). Buffers are kept across builds (no allocation once grown).
template <class T>
struct PointGrid {
  static constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();  ///< not in the grid

  T x0 = T(0), y0 = T(0), cell = T(1);
  int cols = 1, rows = 1;
  std::vector<std::uint32_t> cell_start;  ///< num_cells() + 1 entries
  std::vector<std::uint32_t> cell_of;     ///< per point: its cell, kNone for a NaN point

  std::size_t num_cells() const { return static_cast<std::size_t>(cols) * static_cast<std::size_t>(rows); }
  /// The cell index along one axis, clamped in the floating type before the int conversion (NaN -> 0).
  int column_of(T x) const { return clamped_int((x - x0) / cell, 0, cols - 1); }
  int row_of(T y) const { return clamped_int((y - y0) / cell, 0, rows - 1); }
};

/// Sizes `grid` to the extent of the points (x[i], y[i]) that are not NaN (the caller marks a
/// non-finite point by a NaN x), with cells of at least min_cell_px and at most max_cells_per_side per
/// side, and counts each cell's points into cell_start (cell_start[c + 1] = points in cell c). Extents
/// beyond T's range put every point in one cell. Call sort_by_cell() next.
template <class T>
void size_point_grid(const T* x, const T* y, std::size_t n, double min_cell_px, int max_cells_per_side,
                     PointGrid<T>* grid) {
  PointGrid<T>& g = *grid;
  T x0 = std::numeric_limits<T>::max(), y0 = x0, x1 = std::numeric_limits<T>::lowest(), y1 = x1;
  std::size_t finite = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!(x[i] == x[i])) continue;
    ++finite;
    x0 = x[i] < x0 ? x[i] : x0;
    x1 = x[i] > x1 ? x[i] : x1;
    y0 = y[i] < y0 ? y[i] : y0;
    y1 = y[i] > y1 ? y[i] : y1;
  }
  g.cols = g.rows = 1;
  g.cell = T(1);
  if (finite > 0) {
    // Extents in double: (x1 - x0) of two huge finite floats stays finite.
    const double ex = static_cast<double>(x1) - static_cast<double>(x0);
    const double ey = static_cast<double>(y1) - static_cast<double>(y0);
    double c = min_cell_px;
    const double spread = (ex > ey ? ex : ey) / double(max_cells_per_side - 1);
    if (spread > c) c = spread;
    if (std::isfinite(c) && c <= static_cast<double>(std::numeric_limits<T>::max())) {
      g.cell = static_cast<T>(c);
      g.cols = clamped_int(ex / c, 0, max_cells_per_side - 1) + 1;
      g.rows = clamped_int(ey / c, 0, max_cells_per_side - 1) + 1;
    } else {
      x0 = y0 = T(0);
      g.cell = std::numeric_limits<T>::max();
    }
  } else {
    x0 = y0 = T(0);
  }
  g.x0 = x0;
  g.y0 = y0;
  g.cell_start.resize(g.num_cells() + 1);  // keeps the capacity
  for (auto& s : g.cell_start) s = 0;
  g.cell_of.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (!(x[i] == x[i])) {
      g.cell_of[i] = PointGrid<T>::kNone;
      continue;
    }
    const std::uint32_t id = static_cast<std::uint32_t>(g.row_of(y[i])) * static_cast<std::uint32_t>(g.cols) +
                             static_cast<std::uint32_t>(g.column_of(x[i]));
    g.cell_of[i] = id;
    ++g.cell_start[id + 1];
  }
}

/// Counting sort by cell, stable (ascending index within a cell): place(i, position) is called once per
/// point in the grid, with positions 0..finite-1 in cell order, so the caller lays out whatever it keeps
/// per point contiguously per cell. Leaves cell_start as the cells' first positions.
template <class T, class Place>
void sort_by_cell(PointGrid<T>* grid, Place&& place) {
  PointGrid<T>& g = *grid;
  const std::size_t cells = g.num_cells();
  for (std::size_t c = 0; c < cells; ++c) g.cell_start[c + 1] += g.cell_start[c];
  for (std::size_t i = 0; i < g.cell_of.size(); ++i) {
    if (g.cell_of[i] == PointGrid<T>::kNone) continue;
    place(i, g.cell_start[g.cell_of[i]]++);  // cell_start[c] is c's write cursor here
  }
  for (std::size_t c = cells; c > 0; --c) g.cell_start[c] = g.cell_start[c - 1];
  g.cell_start[0] = 0;
}

}  // namespace dyncull
