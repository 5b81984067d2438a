// Point-to-point ICP on two 5000-point clouds, 30 iterations, one thread: dyncull vs Open3D's
// RegistrationICP (when found), and the nearest-neighbour kernel: dyncull::KdTree3 vs nanoflann.
// Run Open3D single-threaded: OMP_NUM_THREADS=1.
#include "dyncull/geometry/icp.hpp"
#include "dyncull/geometry/kdtree.hpp"

#include "support/pose_data.hpp"

#include <benchmark/benchmark.h>

#include <vector>

#if __has_include(<nanoflann.hpp>)
#include <nanoflann.hpp>
#define DYNCULL_BENCH_NANOFLANN 1
#endif

#ifdef DYNCULL_HAS_OPEN3D
#include <open3d/Open3D.h>
#endif

namespace {

using dyncull::Random;
using dyncull::Rigid3;
using dyncull::Vec3;

struct IcpData {
  std::vector<Vec3<double>> source, target;
  Rigid3<double> truth;  // target_from_source
};

// 5000 + 5000 points, 80 % overlap, 2 mm noise, a 3 deg / 3 cm motion.
IcpData make_icp_data() {
  Random rng(90);
  const auto cloud = dyncull::test::room_cloud<double>(rng, 6000);
  IcpData d;
  d.truth = dyncull::test::random_rigid<double>(rng, 0.05, 0.03);
  const Rigid3<double> inv = d.truth.inverse();
  d.target.assign(cloud.begin(), cloud.begin() + 5000);
  for (std::size_t i = 1000; i < cloud.size(); ++i)
    d.source.push_back(inv.apply(cloud[i]) + 0.002 * Vec3<double>(rng.normal(), rng.normal(), rng.normal()));
  return d;
}

constexpr double kMaxCorrespondence = 0.05;
constexpr int kIterations = 30;

void BM_dyncull_icp(benchmark::State& state) {
  const IcpData d = make_icp_data();
  dyncull::IcpOptions<double> o;
  o.max_correspondence_distance_m = kMaxCorrespondence;
  o.max_iterations = kIterations;
  o.relative_fitness = 0;  // force all 30 iterations, as in the Open3D case below
  o.relative_rmse = 0;
  dyncull::IcpResult<double> r;
  for (auto _ : state) {
    const dyncull::KdTree3<double> tree(d.target);  // tree build inside the loop: Open3D builds its own too
    r = dyncull::icp_point_to_point(tree, d.source, Rigid3<double>{}, o);
    benchmark::DoNotOptimize(r.target_from_source.t.data());
  }
  state.counters["iterations"] = r.iterations;
  state.counters["fitness"] = r.fitness;
  state.counters["rmse_mm"] = 1000 * r.rmse;
  state.counters["rot_err_deg"] = dyncull::test::rotation_error_deg(r.target_from_source, d.truth);
  state.counters["trans_err_mm"] = 1000 * dyncull::test::translation_error(r.target_from_source, d.truth);
}
BENCHMARK(BM_dyncull_icp)->Unit(benchmark::kMillisecond);

#ifdef DYNCULL_HAS_OPEN3D
void BM_open3d_icp(benchmark::State& state) {
  const IcpData d = make_icp_data();
  open3d::geometry::PointCloud src, tgt;
  for (const auto& p : d.source) src.points_.push_back(p);
  for (const auto& p : d.target) tgt.points_.push_back(p);
  // Tolerances 0: Open3D then runs all 30 iterations like the dyncull case.
  const open3d::pipelines::registration::ICPConvergenceCriteria criteria(0.0, 0.0, kIterations);
  open3d::pipelines::registration::RegistrationResult r;
  for (auto _ : state) {
    r = open3d::pipelines::registration::RegistrationICP(
        src, tgt, kMaxCorrespondence, Eigen::Matrix4d::Identity(),
        open3d::pipelines::registration::TransformationEstimationPointToPoint(), criteria);
    benchmark::DoNotOptimize(r.transformation_.data());
  }
  Rigid3<double> g;
  g.R = r.transformation_.topLeftCorner<3, 3>();
  g.t = r.transformation_.topRightCorner<3, 1>();
  state.counters["fitness"] = r.fitness_;
  state.counters["rmse_mm"] = 1000 * r.inlier_rmse_;
  state.counters["rot_err_deg"] = dyncull::test::rotation_error_deg(g, d.truth);
  state.counters["trans_err_mm"] = 1000 * dyncull::test::translation_error(g, d.truth);
}
BENCHMARK(BM_open3d_icp)->Unit(benchmark::kMillisecond);
#else
void BM_open3d_icp_skipped(benchmark::State& state) {
  for (auto _ : state) {
  }
  state.SkipWithError("Open3D not found at configure time: the ICP peer was skipped");
}
BENCHMARK(BM_open3d_icp_skipped);
#endif

// Nearest-neighbour kernel: 5000 queries (the ICP source) into 5000 points, no hints.
void BM_dyncull_kdtree_nn(benchmark::State& state) {
  const IcpData d = make_icp_data();
  const dyncull::KdTree3<double> tree(d.target, static_cast<int>(state.range(0)));
  double checksum = 0;
  for (auto _ : state) {
    for (const auto& q : d.source) {
      double d2 = 0;
      benchmark::DoNotOptimize(tree.nearest(q, &d2));
      checksum += d2;
    }
  }
  benchmark::DoNotOptimize(checksum);
}
BENCHMARK(BM_dyncull_kdtree_nn)->Arg(8)->Arg(12)->Arg(16)->Unit(benchmark::kMicrosecond);

void BM_dyncull_kdtree_build(benchmark::State& state) {
  const IcpData d = make_icp_data();
  for (auto _ : state) {
    const dyncull::KdTree3<double> tree(d.target);
    benchmark::DoNotOptimize(tree.size());
  }
}
BENCHMARK(BM_dyncull_kdtree_build)->Unit(benchmark::kMicrosecond);

#ifdef DYNCULL_BENCH_NANOFLANN
struct CloudAdaptor {
  const std::vector<Vec3<double>>* pts;
  std::size_t kdtree_get_point_count() const { return pts->size(); }
  double kdtree_get_pt(std::size_t i, std::size_t dim) const { return (*pts)[i](static_cast<Eigen::Index>(dim)); }
  template <class B>
  bool kdtree_get_bbox(B&) const {
    return false;
  }
};
using NanoTree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, CloudAdaptor>, CloudAdaptor, 3>;

void BM_nanoflann_kdtree_nn(benchmark::State& state) {
  const IcpData d = make_icp_data();
  CloudAdaptor cloud{&d.target};
  NanoTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(static_cast<std::size_t>(state.range(0))));
  tree.buildIndex();
  double checksum = 0;
  for (auto _ : state) {
    for (const auto& q : d.source) {
      std::size_t idx = 0;
      double d2 = 0;
      nanoflann::KNNResultSet<double> rs(1);
      rs.init(&idx, &d2);
      tree.findNeighbors(rs, q.data(), nanoflann::SearchParams(10));
      benchmark::DoNotOptimize(idx);
      checksum += d2;
    }
  }
  benchmark::DoNotOptimize(checksum);
}
BENCHMARK(BM_nanoflann_kdtree_nn)->Arg(10)->Unit(benchmark::kMicrosecond);

void BM_nanoflann_kdtree_build(benchmark::State& state) {
  const IcpData d = make_icp_data();
  CloudAdaptor cloud{&d.target};
  for (auto _ : state) {
    NanoTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
    tree.buildIndex();
    benchmark::DoNotOptimize(&tree);
  }
}
BENCHMARK(BM_nanoflann_kdtree_build)->Unit(benchmark::kMicrosecond);
#endif

}  // namespace
