// Tests of culling/model_check.hpp with a one-parameter estimator (tracks a -> b, model: a constant shift):
// the fit subset outside the boxes, the thresholds on either side, too few tracks, unusable tracks and
// tracks without evidence, and inputs that break the contract.
#include "dyncull/culling/model_check.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace dyncull {
namespace {

struct ShiftOptions {
  Status validate(std::string* reason) const {
    if (reason) reason->clear();
    return Status::Ok;
  }
};

struct ShiftResult {
  Status status = Status::Ok;
  std::string reason;
  std::vector<FeatureLabel> labels;
  std::vector<std::uint8_t> inlier_mask;
  std::size_t num_tracks = 0, num_valid = 0, num_fit = 0, num_inliers = 0, num_dynamic = 0, num_static = 0;
  bool fitted_outside_boxes = false;
  double shift = 0;
  bool finished = false;
};

// The model is the mean shift b - a of the fit tracks; a track's residual is its distance to it. A track
// with a == 0 gives no evidence (Candidate), as the epipolar check at the epipole.
struct ShiftEstimator {
  static constexpr std::size_t kMinimalTracks = 2;
  static constexpr bool kSubsetLeavesSomeOut = true;
  static constexpr const char* kSizeMismatch = "a and b differ in size";
  static constexpr const char* kTooFew = " usable tracks, the shift check needs at least ";
  const std::vector<double>& a;
  const std::vector<double>& b;
  ShiftOptions options;
  ShiftResult* r;
  std::vector<std::size_t> fit_set;

  std::size_t size() const { return b.size(); }
  bool sizes_agree() const { return a.size() == b.size(); }
  bool inputs_valid(std::string*) const { return true; }
  bool usable(std::size_t i) const { return std::isfinite(a[i]) && std::isfinite(b[i]); }
  void reset() {
    fit_set.clear();
    r->finished = false;
  }
  void keep(std::size_t i) { fit_set.push_back(i); }
  bool begin_fit(bool subset) {
    if (subset) fit_set.clear();
    return subset;
  }
  void add_to_fit(std::size_t, std::size_t i) { fit_set.push_back(i); }
  bool fit() {
    double sum = 0;
    for (std::size_t i : fit_set) sum += b[i] - a[i];
    r->shift = sum / double(fit_set.size());
    for (std::size_t i : fit_set) r->inlier_mask[i] = 1;
    r->num_inliers = fit_set.size();
    return true;
  }
  void polish() {}
  bool residuals_ready() { return true; }
  FeatureLabel label(std::size_t, std::size_t i, double limit) const {
    if (a[i] == 0) return FeatureLabel::Candidate;
    return std::abs(b[i] - a[i] - r->shift) > limit ? FeatureLabel::Dynamic : FeatureLabel::Static;
  }
  void finish() { r->finished = true; }
};

const detail::ModelCheckRule<double> kRule{0.5, 0.25, 4, true, 5};

// 7 still tracks shifted by 1 outside the boxes, 3 movers shifted by 5 inside.
struct Scene {
  std::vector<double> a{1, 2, 3, 4, 5, 6, 7, 8, 9, 10};
  std::vector<double> b{2, 3, 4, 5, 6, 7, 8, 13, 14, 15};
  std::vector<std::uint8_t> in_box{0, 0, 0, 0, 0, 0, 0, 1, 1, 1};
};

ShiftResult run(const Scene& s, FlagView valid, FlagView in_box, const detail::ModelCheckRule<double>& rule = kRule) {
  ShiftResult r;
  ShiftEstimator est{s.a, s.b, ShiftOptions{}, &r, {}};
  detail::check_against_model(est, valid, in_box, rule);
  return r;
}

TEST(ModelCheck, FitsOutsideTheBoxesAndFlagsTheMoversInside) {
  const Scene s;
  const ShiftResult r = run(s, nullptr, s.in_box);
  ASSERT_EQ(r.status, Status::Ok) << r.reason;
  EXPECT_TRUE(r.fitted_outside_boxes);
  EXPECT_EQ(r.num_fit, 7u);
  EXPECT_DOUBLE_EQ(r.shift, 1.0);
  EXPECT_EQ(r.num_dynamic, 3u);
  EXPECT_EQ(r.num_static, 7u);
  for (std::size_t i = 0; i < 10; ++i)
    EXPECT_EQ(r.labels[i], i < 7 ? FeatureLabel::Static : FeatureLabel::Dynamic) << i;
  EXPECT_EQ(r.inlier_mask[8], 0);  // not in the fit
  EXPECT_TRUE(r.finished);
}

TEST(ModelCheck, WithoutBoxesTheMoversPullTheModelAndTheThresholdDecides) {
  const Scene s;
  const ShiftResult r = run(s, nullptr, nullptr);
  ASSERT_EQ(r.status, Status::Ok) << r.reason;
  EXPECT_FALSE(r.fitted_outside_boxes);
  EXPECT_EQ(r.num_fit, 10u);
  EXPECT_DOUBLE_EQ(r.shift, 2.2);  // (7 * 1 + 3 * 5) / 10: every still track 1.2 off, above 0.5
  EXPECT_EQ(r.num_dynamic, 10u);
}

TEST(ModelCheck, TooFewOutsideTheBoxesFitsOnAll) {
  Scene s;
  s.in_box.assign(10, 1);
  s.in_box[0] = 0;  // one track outside: fewer than min_tracks_outside_boxes
  const ShiftResult r = run(s, nullptr, s.in_box);
  EXPECT_FALSE(r.fitted_outside_boxes);
  EXPECT_EQ(r.num_fit, 10u);
}

TEST(ModelCheck, UnusableAndInvalidTracksStayCandidatesAndTooFewIsSkipped) {
  Scene s;
  s.a[0] = std::nan("");
  s.a[1] = 0;  // no evidence either way
  std::vector<std::uint8_t> valid(10, 1);
  valid[2] = 0;
  const ShiftResult r = run(s, valid, s.in_box);
  ASSERT_EQ(r.status, Status::Ok) << r.reason;
  EXPECT_EQ(r.num_valid, 8u);
  for (std::size_t i : {0u, 1u, 2u}) EXPECT_EQ(r.labels[i], FeatureLabel::Candidate) << i;
  EXPECT_EQ(r.num_static + r.num_dynamic, 7u);

  const std::vector<std::uint8_t> three = {1, 1, 1, 0, 0, 0, 0, 0, 0, 0};
  const ShiftResult few = run(Scene{}, three, nullptr);
  EXPECT_EQ(few.status, Status::Skipped);
  EXPECT_EQ(few.reason, "3 usable tracks, the shift check needs at least 4");
  EXPECT_FALSE(few.finished);
}

TEST(ModelCheck, BrokenInputsAreInvalidAndLabelNothing) {
  Scene s;
  s.b.pop_back();
  ShiftResult r = run(s, nullptr, nullptr);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_EQ(r.reason, "a and b differ in size");
  const std::vector<std::uint8_t> short_flags(3, 1);
  r = run(Scene{}, short_flags, nullptr);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.reason.find("valid"), std::string::npos) << r.reason;
  EXPECT_EQ(r.labels, std::vector<FeatureLabel>(10, FeatureLabel::Candidate));
}

}  // namespace
}  // namespace dyncull
