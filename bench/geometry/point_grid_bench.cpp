// The keypoint grid of geometry/point_grid.hpp (size, then a stable counting sort by cell) against its
// peer, std::stable_sort of the indices by cell, on 1000 keypoints spread over a 640x480 image.
#include "dyncull/geometry/point_grid.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <random>
#include <vector>

namespace {

struct Keypoints {
  std::vector<float> x, y;
  explicit Keypoints(std::size_t n) : x(n), y(n) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.f, 639.f), v(0.f, 479.f);
    for (std::size_t i = 0; i < n; ++i) {
      x[i] = u(rng);
      y[i] = v(rng);
    }
  }
};

void BM_PointGrid_Dyncull(benchmark::State& state) {
  const Keypoints k(static_cast<std::size_t>(state.range(0)));
  dyncull::PointGrid<float> grid;
  std::vector<std::uint32_t> order(k.x.size());
  for (auto _ : state) {
    dyncull::size_point_grid(k.x.data(), k.y.data(), k.x.size(), 8.0, 256, &grid);
    dyncull::sort_by_cell(&grid, [&](std::size_t i, std::uint32_t pos) { order[pos] = static_cast<std::uint32_t>(i); });
    benchmark::DoNotOptimize(order.data());
  }
  state.counters["cells"] = static_cast<double>(grid.num_cells());
}
BENCHMARK(BM_PointGrid_Dyncull)->Arg(1000)->Arg(4000);

// Peer: the same cells from the same grid geometry, ordered by a comparison sort.
void BM_PointGrid_StdStableSort(benchmark::State& state) {
  const Keypoints k(static_cast<std::size_t>(state.range(0)));
  dyncull::PointGrid<float> grid;
  dyncull::size_point_grid(k.x.data(), k.y.data(), k.x.size(), 8.0, 256, &grid);
  std::vector<std::uint32_t> order(k.x.size()), cell(k.x.size());
  for (auto _ : state) {
    for (std::size_t i = 0; i < k.x.size(); ++i)
      cell[i] = static_cast<std::uint32_t>(grid.row_of(k.y[i]) * grid.cols + grid.column_of(k.x[i]));
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return cell[a] < cell[b]; });
    benchmark::DoNotOptimize(order.data());
  }
}
BENCHMARK(BM_PointGrid_StdStableSort)->Arg(1000)->Arg(4000);

}  // namespace
