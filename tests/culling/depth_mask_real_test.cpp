// Depth mask on one real TUM frame (fr3_walking_xyz, two people): the plain DLD-SLAM rule must
// reproduce the independently computed expected_mask_rule.json exactly; the robust variant is
// compared with the whole box and the plain rule against the Mask R-CNN person mask.
#include "dyncull/culling/depth_mask.hpp"

#include <gtest/gtest.h>

#include "support/real_data.hpp"

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#ifdef DYNCULL_HAS_OPENCV
#include <opencv2/imgcodecs.hpp>

#include "dyncull/opencv/views.hpp"

namespace {

using namespace dyncull;

struct Counts {
  long tp = 0, fp = 0, fn = 0;
  double iou() const { return double(tp) / double(tp + fp + fn); }
  double precision() const { return double(tp) / double(tp + fp); }
  double recall() const { return double(tp) / double(tp + fn); }
};

class RealFrame : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string why_not;
    const std::string dir = dyncull::test::real_data_dir(&why_not);
    if (dir.empty()) GTEST_SKIP() << why_not;
    const std::string base = dir + "/tum/fr3_walking_xyz_frame/";
    depth_ = cv::imread(base + "depth_1341846313.592088.png", cv::IMREAD_UNCHANGED);
    person_ = cv::imread(base + "mask_1341846313.592026.png", cv::IMREAD_UNCHANGED);
    if (depth_.empty() || person_.empty())
      GTEST_SKIP() << "TUM frame not found under " << base << ": real-data depth-mask test skipped";
    ASSERT_EQ(depth_.type(), CV_16UC1);
    ASSERT_EQ(person_.type(), CV_8UC1);
  }

  // Within the box only; the reference mask has 0 = person (DynaSLAM convention).
  Counts score(const Mask& mask, const Box<double>& box) const {
    Counts c;
    const PixelRect r = pixel_rect(box, depth_.cols, depth_.rows);
    for (int v = r.r0; v < r.r1; ++v)
      for (int u = r.c0; u < r.c1; ++u) {
        const bool gt = person_.at<std::uint8_t>(v, u) == 0;
        const bool pred = mask.test(u, v);
        c.tp += gt && pred;
        c.fp += !gt && pred;
        c.fn += gt && !pred;
      }
    return c;
  }

  DepthMaskBoxInfo run(const Box<double>& box, const DepthMaskOptions& o, Mask* mask) const {
    mask->reset(depth_.cols, depth_.rows);
    return depth_mask_box(cv_adapter::depth_view_u16(depth_, 5000.f), box, o, mask->view());
  }

  cv::Mat depth_, person_;
  // Tight inclusive boxes of the two person components, from expected_mask_rule.json.
  const Box<double> standing_{473, 0, 639, 479};
  const Box<double> sitting_{35, 111, 244, 479};
};

TEST_F(RealFrame, PlainRuleReproducesReferenceOnSittingPerson) {
  DepthMaskOptions o;
  o.mode = DepthMaskMode::Plain;
  // Values of expected_mask_rule.json: eps -> (threshold_raw, tp, fp, fn).
  struct Ref {
    double eps;
    double threshold_raw;
    long tp, fp, fn;
    double iou;
  };
  for (const Ref& ref : {Ref{0.3, 13085, 31640, 8228, 9282, 0.6437436419125128},
                         Ref{0.5, 14085, 32028, 11067, 8894, 0.6160533959106734}}) {
    o.eps_m = ref.eps;
    Mask mask;
    const DepthMaskBoxInfo info = run(sitting_, o, &mask);
    ASSERT_TRUE(info.ok()) << info.reason;
    EXPECT_TRUE(info.rule_applies);
    EXPECT_EQ(info.outcome, DepthMaskOutcome::RuleApplied);
    EXPECT_NEAR(info.d_max_m, 7.835, 1e-6);
    EXPECT_NEAR(info.d_c_m, 2.317, 1e-6);
    EXPECT_EQ(info.threshold_raw, ref.threshold_raw);
    const Counts c = score(mask, sitting_);
    EXPECT_EQ(c.tp, ref.tp);
    EXPECT_EQ(c.fp, ref.fp);
    EXPECT_EQ(c.fn, ref.fn);
    EXPECT_EQ(info.num_mask_pixels, static_cast<std::size_t>(ref.tp + ref.fp));
    EXPECT_NEAR(c.iou(), ref.iou, 1e-12);
  }
}

TEST_F(RealFrame, PlainRuleDoesNotApplyOnStandingPerson) {
  DepthMaskOptions o;
  o.mode = DepthMaskMode::Plain;
  for (double eps : {0.3, 0.5}) {
    o.eps_m = eps;
    Mask mask;
    const DepthMaskBoxInfo info = run(standing_, o, &mask);
    ASSERT_TRUE(info.ok()) << info.reason;
    EXPECT_FALSE(info.rule_applies);
    EXPECT_EQ(info.outcome, DepthMaskOutcome::NotApplied);
    EXPECT_EQ(info.d_max_m, 0.0);
    EXPECT_NEAR(info.d_c_m, 1.292, 1e-6);
    EXPECT_EQ(mask.count(), 0u);
  }
}

TEST_F(RealFrame, WholeBoxReferenceFigures) {
  Mask mask(depth_.cols, depth_.rows);
  const Box<double> boxes[2] = {standing_, sitting_};
  const double ref_iou[2] = {0.8292415169660678, 0.5280939476061427};
  for (int k = 0; k < 2; ++k) {
    mask.reset(depth_.cols, depth_.rows, 255);
    EXPECT_NEAR(score(mask, boxes[k]).iou(), ref_iou[k], 1e-12);
  }
}

// The robust default (pixels without depth decided by their nearest measured pixel) beats the whole box on
// both people and the plain rule on the sitting one. Masking every pixel without depth (InMask, the default
// before) fell short of the whole box on the standing person: 26.8k of its box pixels have no depth, 9.8k
// of them background (the border band, the ceiling); it is printed alongside.
TEST_F(RealFrame, RobustMaskBeatsWholeBoxAndPlainRule) {
  const Box<double> boxes[2] = {sitting_, standing_};
  const char* names[2] = {"sitting person: ", "standing person:"};
  const double whole_box_iou[2] = {0.5280939476061427, 0.8292415169660678};
  for (int k = 0; k < 2; ++k) {
    Counts nearest;
    for (const MissingDepth policy : {MissingDepth::Nearest, MissingDepth::InMask}) {
      DepthMaskOptions o;  // defaults: robust, eps 0.3 m, MissingDepth::Nearest
      o.missing_depth = policy;
      Mask mask;
      const DepthMaskBoxInfo info = run(boxes[k], o, &mask);
      ASSERT_TRUE(info.ok()) << info.reason;
      const Counts c = score(mask, boxes[k]);
      std::printf("[ robust ] %s %s outcome=%s d_c=%.3f d_max=%.3f thr=%.3f  IoU %.4f (P %.3f R %.3f); whole box %.4f\n",
                  names[k], policy == MissingDepth::Nearest ? "missing=nearest" : "missing=in mask",
                  to_string(info.outcome), info.d_c_m, info.d_max_m, info.threshold_m, c.iou(), c.precision(),
                  c.recall(), whole_box_iou[k]);
      if (policy == MissingDepth::Nearest) nearest = c;
    }
    EXPECT_GT(nearest.iou(), whole_box_iou[k]) << names[k];
  }
  Mask mask;
  run(sitting_, DepthMaskOptions{}, &mask);
  EXPECT_GT(score(mask, sitting_).iou(), 0.6437436419125128) << "robust mask should beat the plain rule (sitting)";
}

}  // namespace
#else
TEST(DepthMaskReal, NeedsOpenCV) { GTEST_SKIP() << "built without OpenCV: cannot read the TUM PNGs"; }
#endif
