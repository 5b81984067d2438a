// geometry/point_grid.hpp: the grid spans the points' own extent, NaN points stay out of it, the sort is
// stable and contiguous per cell, and extents beyond the float range or the cell cap stay bounded.
#include "dyncull/geometry/point_grid.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace {

using dyncull::PointGrid;

template <class T>
std::vector<std::uint32_t> sorted_order(PointGrid<T>* g) {
  std::vector<std::uint32_t> order;
  dyncull::sort_by_cell(g, [&](std::size_t i, std::uint32_t pos) {
    if (order.size() <= pos) order.resize(pos + 1);
    order[pos] = static_cast<std::uint32_t>(i);
  });
  return order;
}

TEST(PointGrid, SpansThePointsExtentAndSortsStablyByCell) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  // Cells of 10 px from (100, 50): points 0 and 3 share cell (0, 0), point 2 is NaN.
  const std::vector<float> x = {101.f, 125.f, nan, 104.f, 100.f};
  const std::vector<float> y = {52.f, 50.f, 3.f, 59.f, 71.f};
  PointGrid<float> g;
  dyncull::size_point_grid(x.data(), y.data(), x.size(), 10.0, 256, &g);
  EXPECT_FLOAT_EQ(g.x0, 100.f);
  EXPECT_FLOAT_EQ(g.y0, 50.f);
  EXPECT_FLOAT_EQ(g.cell, 10.f);
  EXPECT_EQ(g.cols, 3);  // x extent 25 px
  EXPECT_EQ(g.rows, 3);  // y extent 21 px
  EXPECT_EQ(g.cell_of[2], PointGrid<float>::kNone);
  const std::vector<std::uint32_t> order = sorted_order(&g);
  EXPECT_EQ(order, (std::vector<std::uint32_t>{0, 3, 1, 4}));  // cell (0,0): 0 then 3; (2,0): 1; (0,2): 4
  ASSERT_EQ(g.cell_start.size(), g.num_cells() + 1);
  EXPECT_EQ(g.cell_start[0], 0u);
  EXPECT_EQ(g.cell_start[1], 2u);               // cell 0 holds positions [0, 2)
  EXPECT_EQ(g.cell_start[g.num_cells()], 4u);   // four points in the grid
  for (std::size_t c = 0; c < g.num_cells(); ++c) EXPECT_LE(g.cell_start[c], g.cell_start[c + 1]);
}

TEST(PointGrid, WideExtentsAreCappedAndBeyondTheFloatRangeFallIntoOneCell) {
  PointGrid<double> g;
  const std::vector<double> x = {0.0, 1e6}, y = {0.0, 10.0};
  dyncull::size_point_grid(x.data(), y.data(), x.size(), 8.0, 256, &g);
  EXPECT_EQ(g.cols, 256);  // 1e6 px over 8 px cells would be 125,001 columns
  EXPECT_EQ(g.rows, 1);
  EXPECT_EQ(g.column_of(1e6), 255);
  EXPECT_EQ(g.column_of(std::numeric_limits<double>::quiet_NaN()), 0);

  PointGrid<float> f;
  const float big = std::numeric_limits<float>::max();
  const std::vector<float> fx = {-big, big}, fy = {0.f, 0.f};
  dyncull::size_point_grid(fx.data(), fy.data(), fx.size(), 8.0, 256, &f);
  EXPECT_TRUE(std::isfinite(f.cell));
  EXPECT_EQ(f.num_cells(), 256u);
  EXPECT_EQ(sorted_order(&f).size(), 2u);
}

TEST(PointGrid, NoFinitePointGivesOneEmptyCell) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<float> x = {nan, nan}, y = {1.f, 2.f};
  PointGrid<float> g;
  dyncull::size_point_grid(x.data(), y.data(), x.size(), 8.0, 256, &g);
  EXPECT_EQ(g.num_cells(), 1u);
  EXPECT_TRUE(sorted_order(&g).empty());
  EXPECT_EQ(g.cell_start[1], 0u);
}

}  // namespace
