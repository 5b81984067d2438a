// Tests that each preset switches on exactly its paper's strategies, with the documented values.
#include "dyncull/culling/presets.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace dyncull {
namespace {

TEST(Presets, EachPaperRunsItsStrategies) {
  const auto dld = presets::dld_slam<double>();
  EXPECT_TRUE(dld.depth_mask.enabled && dld.probability.enabled && dld.box_rule.enabled);
  EXPECT_FALSE(dld.moving_consistency.enabled || dld.subbox.enabled || dld.multiview.enabled);
  EXPECT_EQ(dld.depth_mask.mode, DepthMaskMode::Plain);
  EXPECT_EQ(dld.probability.flow_model, FlowModel::MeanFlow);

  const auto rtd = presets::rtd_slam<double>();
  EXPECT_TRUE(rtd.box_rule.enabled && rtd.multiview.enabled);
  EXPECT_FALSE(rtd.moving_consistency.enabled || rtd.depth_mask.enabled || rtd.probability.enabled);
  EXPECT_DOUBLE_EQ(rtd.multiview.depth_threshold_m, 0.4);
  EXPECT_DOUBLE_EQ(rtd.multiview.max_parallax_deg, 30.0);
  EXPECT_EQ(rtd.candidates, CandidatePolicy::Verify);

  const auto zhu = presets::zhu_2024<float>();
  EXPECT_TRUE(zhu.box_rule.enabled);
  EXPECT_FALSE(zhu.box_rule.medium_as_candidate);
  EXPECT_FALSE(zhu.moving_consistency.enabled || zhu.multiview.enabled || zhu.depth_mask.enabled);

  const auto dfd = presets::dfd_slam<float>();
  EXPECT_TRUE(dfd.moving_consistency.enabled && dfd.subbox.enabled);
  EXPECT_FLOAT_EQ(dfd.subbox.merge_ratio, 0.f);  // the paper's literal merge
  EXPECT_EQ(dfd.subbox.sigma2, 4);
  EXPECT_FALSE(dfd.moving_consistency.fit_outside_boxes);
  EXPECT_FLOAT_EQ(dfd.moving_consistency.max_epipolar_distance_px, 1.f);
  EXPECT_FLOAT_EQ(dfd.moving_consistency.max_epipolar_distance_in_boxes_px, 1.f);
  EXPECT_FALSE(dfd.subbox.requires_fit_outside_boxes);  // F on all tracks, the vote always trusted

  const auto zhang = presets::zhang_2023<float>();
  EXPECT_EQ(zhang.candidates, CandidatePolicy::Cull);
  EXPECT_FALSE(zhang.moving_consistency.enabled);
  // Our additions stay out of the papers' presets.
  const auto without_our_additions = [](const auto& paper) {
    return !paper.static_history.enabled && !paper.coherent_motion.enabled && !paper.edge_evidence.enabled &&
           !paper.reprojection.enabled && !paper.tracker.enabled;
  };
  EXPECT_TRUE(without_our_additions(dld) && without_our_additions(rtd) && without_our_additions(zhu) &&
              without_our_additions(dfd) && without_our_additions(zhang));
}

TEST(Presets, RecommendedCombinesThemWithTheGuard) {
  const auto o = presets::recommended<float>();
  EXPECT_TRUE(o.box_rule.enabled && o.depth_mask.enabled && o.moving_consistency.enabled && o.subbox.enabled &&
              o.tracker.enabled && o.detections.enabled && o.guard.enabled && o.depth_mask.assign_overlaps_by_depth);
  EXPECT_FALSE(o.probability.enabled);
  EXPECT_FALSE(o.multiview.enabled);
  EXPECT_TRUE(o.moving_consistency.fit_outside_boxes);
  EXPECT_FLOAT_EQ(o.moving_consistency.max_epipolar_distance_in_boxes_px, 1.0f);  // tracks against the keyframe
  EXPECT_TRUE(o.edge_evidence.enabled);
  EXPECT_EQ(o.edge_evidence.radius_px, 8);
  // RGB-D evidence when the frame carries 3-D points: the reprojection residual replaces the epipolar one.
  EXPECT_TRUE(o.reprojection.enabled);
  EXPECT_TRUE(o.coherent_motion.enabled && o.static_history.enabled);
  EXPECT_FALSE(o.subbox.verifies_candidates);
  EXPECT_EQ(o.subbox.min_evidence_frames, 2);
  EXPECT_TRUE(o.subbox.short_baseline_keeps_last_vote);
  EXPECT_FLOAT_EQ(o.reprojection.max_residual_in_boxes_px, 1.5f);
  EXPECT_FLOAT_EQ(o.subbox.merge_ratio, 0.35f);
  EXPECT_EQ(o.candidates, CandidatePolicy::Verify);
  EXPECT_DOUBLE_EQ(o.guard.min_fraction, 0.10);
  EXPECT_EQ(o.guard.min_survivors, 30u);
  EXPECT_FLOAT_EQ(o.detections.box_padding_px, 5.f);
  EXPECT_DOUBLE_EQ(o.depth_mask.eps_m, 0.5);  // DLD-SLAM's range is 0.3-0.5 m; see the test below
  EXPECT_EQ(o.static_history.min_frames, 6);  // docs/results.md
  EXPECT_FLOAT_EQ(o.static_history.max_residual_px, 0.8f);
}

// The recommended preset's object band reaches 0.5 m behind the centre depth (DLD-SLAM's eps range is 0.3-0.5 m):
// the far side of a close, oblique walker 0.4 m behind its torso is in the object; the background is not.
TEST(Presets, RecommendedBandTakesInTheFarSideOfACloseWalker) {
  const int w = 100, h = 100;
  std::vector<float> depth(static_cast<std::size_t>(w * h), 3.0f);  // background wall at 3 m
  for (int r = 0; r < h; ++r)
    for (int c = 30; c <= 72; ++c) depth[static_cast<std::size_t>(r * w + c)] = c <= 60 ? 0.85f : 1.25f;
  const DepthView<float> view{depth.data(), w, h, 0, 1.f, 0.4f, 8.f};
  const std::vector<Box<float>> boxes = {Box<float>{20, 0, 80, 99}};
  const std::vector<Vec2<float>> points = {{45, 50}, {66, 50}, {25, 50}};  // torso, far side, wall
  const DepthMaskResult recommended = depth_mask(view, boxes, points, presets::recommended<float>().depth_mask);
  ASSERT_TRUE(recommended.ok()) << recommended.reason;
  EXPECT_EQ(recommended.labels[0], FeatureLabel::Dynamic);
  EXPECT_EQ(recommended.labels[1], FeatureLabel::Dynamic);
  EXPECT_EQ(recommended.labels[2], FeatureLabel::Static);
  const DepthMaskResult plain_eps = depth_mask(view, boxes, points, DepthMaskOptions{});  // eps 0.3 m
  ASSERT_TRUE(plain_eps.ok()) << plain_eps.reason;
  EXPECT_EQ(plain_eps.labels[0], FeatureLabel::Dynamic);
  EXPECT_EQ(plain_eps.labels[1], FeatureLabel::Static);
}

TEST(Presets, DefaultsOfTheGeometricOptions) {
  const MovingConsistencyOptions<double> m;
  EXPECT_DOUBLE_EQ(m.fundamental_fit().ransac.max_residual, 1.0);
  EXPECT_DOUBLE_EQ(m.fundamental_fit().ransac.confidence, 0.99);
  EXPECT_EQ(m.fundamental_fit().ransac.max_iterations, 10000u);
  EXPECT_FALSE(m.fundamental_fit().check_homography_degeneracy);
  EXPECT_EQ(m.min_tracks_outside_boxes, 20u);
  const ReprojectionCheckOptions<double> p;
  EXPECT_DOUBLE_EQ(p.max_residual_px, 3.0);
  EXPECT_DOUBLE_EQ(p.pose_fit().ransac.max_residual, 2.0);
  EXPECT_EQ(p.pose_fit().ransac.max_iterations, 300u);
  EXPECT_TRUE(p.pose_fit().refinement.huber);
  EXPECT_EQ(p.min_tracks_outside_boxes, 20u);
  EXPECT_FALSE(presets::none<double>().reprojection.enabled);
  const SubBoxOptions<double> s;
  EXPECT_EQ(s.grid, 3);
  EXPECT_DOUBLE_EQ(s.sigma1, 0.5);
  EXPECT_EQ(s.dilation_radius_px, 15);
  const MultiViewOptions<double> v;
  EXPECT_DOUBLE_EQ(v.depth_threshold_m, 0.4);
  EXPECT_DOUBLE_EQ(v.max_parallax_deg, 30.0);
  EXPECT_DOUBLE_EQ(MultiViewOptions<double>::kRegionDepthToleranceM, 0.2);
}

}  // namespace
}  // namespace dyncull
