#include "dyncull/eval/labels.hpp"

#include <gtest/gtest.h>

#include <array>
#include <string>
#include <cstdint>
#include <vector>

namespace {

using namespace dyncull;
using namespace dyncull::eval;

TEST(ScoreLabels, CountsAndScoresOnUint8AndBool) {
  const std::vector<std::uint8_t> predicted{1, 1, 0, 0, 1, 0};
  const std::vector<bool> truth{true, false, true, false, true, false};
  const LabelScores s = score_labels(predicted, truth);
  ASSERT_TRUE(s.ok()) << s.reason;
  EXPECT_EQ(s.true_positive, 2u);
  EXPECT_EQ(s.false_positive, 1u);
  EXPECT_EQ(s.false_negative, 1u);
  EXPECT_EQ(s.true_negative, 2u);
  EXPECT_DOUBLE_EQ(s.precision(), 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(s.recall(), 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(s.iou(), 0.5);
  EXPECT_DOUBLE_EQ(s.f1(), 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(s.accuracy(), 4.0 / 6.0);
}

TEST(ScoreLabels, FeatureLabelsWithCandidatePolicy) {
  const std::array<FeatureLabel, 4> predicted{FeatureLabel::Dynamic, FeatureLabel::Candidate, FeatureLabel::Static,
                                              FeatureLabel::Candidate};
  const std::vector<int> truth{1, 1, 0, 0};
  const LabelScores strict = score_labels(predicted, truth);
  EXPECT_EQ(strict.true_positive, 1u);
  EXPECT_EQ(strict.false_negative, 1u);
  EXPECT_EQ(strict.false_positive, 0u);
  LabelScoreOptions options;
  options.candidate_is_dynamic = true;
  const LabelScores loose = score_labels(predicted, truth, options);
  EXPECT_EQ(loose.true_positive, 2u);
  EXPECT_EQ(loose.false_positive, 1u);
  EXPECT_EQ(loose.false_negative, 0u);
}

TEST(ScoreLabels, EmptyAndAllStaticAreDefinedSizeMismatchIsAnError) {
  const std::vector<std::uint8_t> none;
  const LabelScores e = score_labels(none, none);
  EXPECT_TRUE(e.ok());
  EXPECT_EQ(e.count(), 0u);
  EXPECT_EQ(e.precision(), 1.0);
  EXPECT_EQ(e.iou(), 1.0);
  const std::vector<std::uint8_t> zeros(10, 0);
  const LabelScores z = score_labels(zeros, zeros);
  EXPECT_EQ(z.true_negative, 10u);
  EXPECT_EQ(z.recall(), 1.0);  // nothing to find, nothing missed
  const std::vector<std::uint8_t> ones(10, 1);
  const LabelScores missed = score_labels(zeros, ones);
  EXPECT_EQ(missed.precision(), 1.0);  // no false alarm was raised...
  EXPECT_EQ(missed.recall(), 0.0);     // ...but every mover was kept
  EXPECT_EQ(missed.iou(), 0.0);
  const LabelScores bad = score_labels(zeros, none);
  EXPECT_EQ(bad.status, Status::InvalidInput);
  EXPECT_NE(bad.reason.find("10 predicted"), std::string::npos) << bad.reason;
}

TEST(ScoreLabels, OptionsAlwaysValidate) {
  std::string why = "stale";
  EXPECT_EQ(LabelScoreOptions{}.validate(&why), Status::Ok);
  EXPECT_TRUE(why.empty());
  LabelScoreOptions o;
  o.candidate_is_dynamic = true;
  EXPECT_EQ(o.validate(), Status::Ok);
}

TEST(ScoreMasks, StridedViewsAndValidMask) {
  // 4x2 masks stored with a 6-byte stride: padding bytes must be ignored.
  const std::vector<std::uint8_t> pred{255, 255, 0, 0, 9, 9,   //
                                       0, 1, 1, 0, 9, 9};
  const std::vector<std::uint8_t> truth{1, 0, 0, 0, 7, 7,  //
                                        0, 1, 1, 1, 7, 7};
  const ConstMaskView p(pred.data(), 4, 2, 6);
  const ConstMaskView t(truth.data(), 4, 2, 6);
  const LabelScores s = score_masks(p, t);
  ASSERT_TRUE(s.ok()) << s.reason;
  EXPECT_EQ(s.true_positive, 3u);
  EXPECT_EQ(s.false_positive, 1u);
  EXPECT_EQ(s.false_negative, 1u);
  EXPECT_EQ(s.true_negative, 3u);
  EXPECT_DOUBLE_EQ(s.iou(), 0.6);

  Mask valid(4, 2, 1);
  valid.pixels[1] = 0;  // ignore the false positive at (1, 0)
  const LabelScores v = score_masks(p, t, valid.view());
  EXPECT_EQ(v.false_positive, 0u);
  EXPECT_EQ(v.count(), 7u);

  LabelScores total = s;
  total += v;
  EXPECT_EQ(total.true_positive, 6u);
  EXPECT_EQ(total.count(), 15u);
}

TEST(ScoreMasks, SizeMismatchAndEmptyAreErrors) {
  Mask a(4, 3), b(3, 4);
  EXPECT_EQ(score_masks(a.view(), b.view()).status, Status::InvalidInput);
  EXPECT_EQ(score_masks(ConstMaskView{}, a.view()).status, Status::InvalidInput);
  Mask small_valid(2, 2, 1);
  EXPECT_EQ(score_masks(a.view(), a.view(), small_valid.view()).status, Status::InvalidInput);
}

}  // namespace
