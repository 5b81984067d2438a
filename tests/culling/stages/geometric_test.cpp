// The geometric stage (stages/geometric.hpp) on its own: per-feature epipolar and reprojection evidence
// from synthetic tracks with a known moving subset, the check each label comes from, flags on depth
// edges discounted, and what it reports without tracks or 3-D points.
#include "dyncull/culling/stages/geometric.hpp"

#include "support/stage_context.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <vector>

namespace dyncull {
namespace {

template <class T>
class GeometricStageTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(GeometricStageTest, Scalars, );  // trailing comma: clang -Wpedantic rejects an empty variadic

constexpr std::size_t kFeatures = 80;
bool is_mover(std::size_t i) { return i % 8 == 3; }  // 10 of the 80

/// 80 world points on a 10 x 8 grid at depths 2-4.4 m, seen by a 640 x 480 camera at the origin, then
/// after it moved 0.1 m sideways and turned 0.01 rad. Every 8th point (from the 4th) moved 0.1 m down
/// in between: 11-25 px across the near-horizontal epipolar lines; the others are exact (distance 0).
/// points_3d: each track's point at the previous frame (world = previous camera).
template <class T>
test::StageFrame<T> moving_tracks() {
  test::StageFrame<T> f(640, 480);
  f.cam_from_world.R = Eigen::AngleAxis<T>(T(0.01), Vec3<T>::UnitY()).toRotationMatrix();
  f.cam_from_world.t = Vec3<T>(T(-0.1), T(-0.02), T(0));
  for (std::size_t i = 0; i < kFeatures; ++i) {
    const Vec3<T> X(T(-0.9 + 0.2 * double(i % 10)), T(-0.6 + 0.17 * double(i / 10)), T(2.0 + 0.6 * double((i * 7) % 5)));
    const Vec3<T> X_now = is_mover(i) ? Vec3<T>(X + Vec3<T>(T(0), T(0.1), T(0))) : X;
    const Vec2<T> prev = f.camera.project(X);
    const Vec2<T> cur = f.camera.project(f.cam_from_world.apply(X_now));
    f.add(cur.x(), cur.y(), prev.x(), prev.y());
    f.points_3d.push_back(X);
  }
  return f;
}

std::vector<FeatureLabel> truth_labels() {
  std::vector<FeatureLabel> t(kFeatures, FeatureLabel::Static);
  for (std::size_t i = 0; i < kFeatures; ++i)
    if (is_mover(i)) t[i] = FeatureLabel::Dynamic;
  return t;
}

TYPED_TEST(GeometricStageTest, EpipolarEvidenceFlagsExactlyTheMovingTracks) {
  using T = TypeParam;
  auto f = moving_tracks<T>();
  f.points_3d.clear();
  const PipelineOptions<T> o;  // moving consistency on (1 px), reprojection off
  detail::PipelineWork<T> w;
  PipelineResult<T> r = test::fresh_result(o, f.size());
  const auto work_before = test::parts_of(w);
  const auto result_before = test::parts_of(r);
  detail::gather_geometric_evidence(f.frame(), o, w.regions, w.semantic, &w.geometric, &r);

  ASSERT_TRUE(r.moving_consistency.ran()) << r.moving_consistency.reason;
  EXPECT_FALSE(r.reprojection.enabled);
  ASSERT_TRUE(w.geometric.ok);
  EXPECT_EQ(w.geometric.labels, truth_labels());
  EXPECT_EQ(w.geometric.source, std::vector<CullReason>(kFeatures, CullReason::Epipolar));
  EXPECT_EQ(r.moving_consistency.num_dynamic, 10u);
  for (std::size_t i = 0; i < kFeatures; ++i) {
    if (is_mover(i))
      EXPECT_GT(w.geometric.moving.distance_px[i], T(5)) << i;
    else
      EXPECT_LT(w.geometric.moving.distance_px[i], T(0.1)) << i;
  }
  test::expect_only_changed(work_before, test::parts_of(w), {"geometric"});
  test::expect_only_changed(result_before, test::parts_of(r), {"moving_consistency"});
}

TYPED_TEST(GeometricStageTest, ReprojectionLabelsReplaceTheEpipolarOnesAndNameTheirCheck) {
  using T = TypeParam;
  const auto f = moving_tracks<T>();
  PipelineOptions<T> o;
  o.reprojection.enabled = true;  // Replace: the residual decides where it labelled the track
  detail::PipelineWork<T> w;
  PipelineResult<T> r = test::fresh_result(o, f.size());
  const auto work_before = test::parts_of(w);
  const auto result_before = test::parts_of(r);
  detail::gather_geometric_evidence(f.frame(), o, w.regions, w.semantic, &w.geometric, &r);

  ASSERT_TRUE(r.moving_consistency.ran()) << r.moving_consistency.reason;
  ASSERT_TRUE(r.reprojection.ran()) << r.reprojection.reason;
  EXPECT_EQ(w.geometric.reprojection.labels, truth_labels());
  EXPECT_EQ(w.geometric.labels, truth_labels());
  EXPECT_EQ(w.geometric.source, std::vector<CullReason>(kFeatures, CullReason::Reprojection));
  EXPECT_EQ(r.reprojection.num_dynamic, 10u);
  test::expect_only_changed(work_before, test::parts_of(w), {"geometric"});
  test::expect_only_changed(result_before, test::parts_of(r), {"moving_consistency", "reprojection"});
}

TYPED_TEST(GeometricStageTest, ReprojectionAloneIsTheEvidenceWhenTheEpipolarCheckIsOff) {
  using T = TypeParam;
  const auto f = moving_tracks<T>();
  PipelineOptions<T> o;
  o.moving_consistency.enabled = false;
  o.reprojection.enabled = true;
  detail::PipelineWork<T> w;
  PipelineResult<T> r = test::fresh_result(o, f.size());
  detail::gather_geometric_evidence(f.frame(), o, w.regions, w.semantic, &w.geometric, &r);
  EXPECT_FALSE(r.moving_consistency.enabled);
  ASSERT_TRUE(w.geometric.ok);
  EXPECT_EQ(w.geometric.labels, truth_labels());
  EXPECT_EQ(w.geometric.source, std::vector<CullReason>(kFeatures, CullReason::Reprojection));
}

TYPED_TEST(GeometricStageTest, FlagOnADepthEdgeIsNotEvidence) {
  using T = TypeParam;
  auto f = moving_tracks<T>();
  f.points_3d.clear();
  // A 1 m patch beginning 2 px right of mover 3 on a 4 m background: a step of 75 % within 4 px of it
  // and of no other mover.
  const auto& k3 = f.keypoints[3];
  const int u3 = static_cast<int>(std::floor(k3.x())), v3 = static_cast<int>(std::floor(k3.y()));
  f.fill_depth(4.f);
  f.paint_depth(u3 + 2, v3 - 3, u3 + 10, v3 + 4, 1.f);
  PipelineOptions<T> o;
  o.edge_evidence.enabled = true;
  o.edge_evidence.radius_px = 4;  // kDepthStepRatio 0.05
  detail::PipelineWork<T> w;
  PipelineResult<T> r = test::fresh_result(o, f.size());
  detail::gather_geometric_evidence(f.frame(), o, w.regions, w.semantic, &w.geometric, &r);
  ASSERT_TRUE(w.geometric.ok);
  auto want = truth_labels();
  want[3] = FeatureLabel::Candidate;
  EXPECT_EQ(w.geometric.labels, want);
  EXPECT_EQ(w.geometric.moving.labels[3], FeatureLabel::Dynamic);  // the check's own label is kept
  EXPECT_EQ(r.moving_consistency.num_dynamic, 9u);
}

TYPED_TEST(GeometricStageTest, WithoutTracksOrPointsEachCheckSaysWhatItLacked) {
  using T = TypeParam;
  auto f = moving_tracks<T>();
  f.with_tracks = false;
  f.points_3d.clear();
  PipelineOptions<T> o;
  o.reprojection.enabled = true;
  detail::PipelineWork<T> w;
  PipelineResult<T> r = test::fresh_result(o, f.size());
  detail::gather_geometric_evidence(f.frame(), o, w.regions, w.semantic, &w.geometric, &r);
  EXPECT_FALSE(w.geometric.ok);
  test::expect_lacks_input(r.moving_consistency, "prev_keypoints");
  test::expect_lacks_input(r.reprojection, "points_3d");
}

}  // namespace
}  // namespace dyncull
