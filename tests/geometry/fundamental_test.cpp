// Tests of geometry/fundamental.hpp: 7-point and normalised 8-point solvers, F-RANSAC accuracy and
// robustness on synthetic two-view data with ground truth (tests/support/two_view.hpp), degenerate input,
// determinism, and a cross-check against cv::findFundamentalMat when OpenCV is available.
#include "dyncull/geometry/fundamental.hpp"

#include "support/two_view.hpp"

#include <gtest/gtest.h>

#include <string>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#ifdef DYNCULL_HAS_OPENCV
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#endif

namespace dyncull {
namespace {

using test::TwoViewData;
using test::TwoViewKind;
using test::TwoViewOptions;
using test::fundamental_difference;
using test::make_two_view;

template <class T>
class FundamentalTyped : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(FundamentalTyped, Scalars, );  // trailing comma: clang -Wpedantic rejects an empty variadic

/// Relative tolerance on exact recovery (Frobenius difference of unit-norm F): double 1e-9 (the task's bound);
/// float: coordinates of ~500 px carry ~3e-5 px rounding, which the normalised solve amplifies by the
/// conditioning of the 9x9 system (~1e2-1e3); 5e-3 bounds it with margin.
template <class T> double exact_tolerance() { return std::is_same<T, double>::value ? 1e-9 : 5e-3; }
/// Looser tolerances for the 7-point solutions (the cubic root is polished but the 7x9 elimination is not).
template <class T> double seven_point_residual_tolerance() { return std::is_same<T, double>::value ? 1e-6 : 2e-2; }
template <class T> double seven_point_tolerance() { return std::is_same<T, double>::value ? 1e-7 : 2e-2; }

template <class T>
TwoViewData<T> clean_data(int n, std::uint64_t seed) {
  TwoViewOptions o;
  o.num_points = n;
  o.noise_px = 0;
  o.outlier_fraction = 0;
  o.seed = seed;
  return make_two_view<T>(o);
}

/// Max Sampson distance (px) of the clean (noise-free) correspondences under F.
template <class T>
double max_clean_sampson(const Mat3<T>& F, const TwoViewData<T>& d) {
  double worst = 0;
  for (std::size_t i = 0; i < d.clean1.size(); ++i)
    worst = std::max(worst, std::sqrt(double(sampson_distance_sq(F, d.clean1[i], d.clean2[i]))));
  return worst;
}

/// RMS Sampson distance (px) of the true inliers' clean correspondences: how well F models the truth.
template <class T>
double rms_true_sampson(const Mat3<T>& F, const TwoViewData<T>& d) {
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < d.clean1.size(); ++i) {
    if (!d.is_inlier[i]) continue;
    sum += double(sampson_distance_sq(F, d.clean1[i], d.clean2[i]));
    ++n;
  }
  return std::sqrt(sum / double(n));
}

TYPED_TEST(FundamentalTyped, EightPointExactWithoutNoise) {
  using T = TypeParam;
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const auto d = clean_data<T>(50, seed);
    const auto r = fundamental_8point(d.points1, d.points2);
    ASSERT_TRUE(r.ok()) << r.reason;
    EXPECT_LT(fundamental_difference(r.F, d.F), exact_tolerance<T>()) << "seed " << seed;
    EXPECT_NEAR(double(r.F.norm()), 1.0, 1e-5);
    // Rank 2: the smallest singular value is (numerically) zero.
    const Eigen::JacobiSVD<Mat3<double>> svd(r.F.template cast<double>());
    EXPECT_LT(svd.singularValues()[2], 1e-6 * svd.singularValues()[0]);
    EXPECT_EQ(r.num_inliers, 50u);
  }
}

TYPED_TEST(FundamentalTyped, SevenPointContainsTheTruth) {
  using T = TypeParam;
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    const auto d = clean_data<T>(7, seed);
    const auto r = fundamental_7point(d.points1, d.points2);
    ASSERT_TRUE(r.ok()) << r.reason;
    ASSERT_GE(r.count, 1);
    ASSERT_LE(r.count, 3);
    double best = 1e9;
    for (int k = 0; k < r.count; ++k) {
      best = std::min(best, fundamental_difference(r.F[std::size_t(k)], d.F));
      // Every solution satisfies the seven constraints and has rank 2.
      for (std::size_t i = 0; i < 7; ++i)
        EXPECT_LT(std::sqrt(double(sampson_distance_sq(r.F[std::size_t(k)], d.points1[i], d.points2[i]))),
                  seven_point_residual_tolerance<T>());
      EXPECT_LT(std::abs(r.F[std::size_t(k)].template cast<double>().determinant()), 1e-6);
    }
    EXPECT_LT(best, seven_point_tolerance<T>()) << "seed " << seed;
  }
}

TYPED_TEST(FundamentalTyped, EightPointErrorBoundWithHalfPixelNoise) {
  using T = TypeParam;
  TwoViewOptions o;
  o.num_points = 300;
  o.noise_px = 0.5;
  o.outlier_fraction = 0;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    o.seed = seed;
    const auto d = make_two_view<T>(o);
    const auto r = fundamental_8point(d.points1, d.points2);
    ASSERT_TRUE(r.ok()) << r.reason;
    // The clean correspondences fit the estimate to a fraction of the noise.
    EXPECT_LT(rms_true_sampson(r.F, d), 0.25) << "seed " << seed;
    EXPECT_LT(max_clean_sampson(r.F, d), 1.0) << "seed " << seed;
  }
}

TYPED_TEST(FundamentalTyped, RansacRecoversInliersWith30PercentOutliers) {
  using T = TypeParam;
  TwoViewOptions o;  // 1000 points, 0.5 px noise, 30 % outliers at >= 3 px
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    o.seed = seed;
    const auto d = make_two_view<T>(o);
    FundamentalOptions<T> fo;
    fo.ransac.seed = seed;
    const auto r = estimate_fundamental_ransac(d.points1, d.points2, fo);
    ASSERT_TRUE(r.ok()) << r.reason;
    std::size_t tp = 0, fp = 0;
    for (std::size_t i = 0; i < d.is_inlier.size(); ++i) {
      tp += r.inlier_mask[i] && d.is_inlier[i];
      fp += r.inlier_mask[i] && !d.is_inlier[i];
    }
    const double recall = double(tp) / double(d.num_inliers);
    const double precision = double(tp) / double(tp + fp);
    // With 0.5 px noise in both images the Sampson distance of a true inlier is about |N(0, 0.5^2)|, so a
    // 1 px threshold keeps P(|N| < 2 sigma) = 95.4 % of them; allow 2 % below that.
    EXPECT_GT(recall, 0.934) << "seed " << seed;
    // Outliers lie >= 3 px off their line; a few land near the estimated line by chance.
    EXPECT_GT(precision, 0.99) << "seed " << seed;
    EXPECT_EQ(r.num_inliers, tp + fp);
    EXPECT_LT(rms_true_sampson(r.F, d), 0.2) << "seed " << seed;
    EXPECT_LT(r.iterations, 300u);  // adaptive stop near 54 samples for w = 0.7
    EXPECT_LT(r.homography_inlier_fraction, 0.5);
  }
}

TYPED_TEST(FundamentalTyped, RansacExactWithoutNoise) {
  using T = TypeParam;
  TwoViewOptions o;
  o.noise_px = 0;
  o.num_points = 200;
  const auto d = make_two_view<T>(o);
  const auto r = estimate_fundamental_ransac(d.points1, d.points2, FundamentalOptions<T>{});
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.inlier_mask, d.is_inlier);
  EXPECT_LT(fundamental_difference(r.F, d.F), exact_tolerance<T>());
}

TYPED_TEST(FundamentalTyped, DeterministicForASeed) {
  using T = TypeParam;
  const auto d = make_two_view<T>(TwoViewOptions{});
  FundamentalOptions<T> fo;
  fo.ransac.seed = 42;
  const auto a = estimate_fundamental_ransac(d.points1, d.points2, fo);
  const auto b = estimate_fundamental_ransac(d.points1, d.points2, fo);
  ASSERT_TRUE(a.ok());
  EXPECT_EQ(a.inlier_mask, b.inlier_mask);
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_TRUE(a.F == b.F);
  // Other seeds draw other samples (different iteration counts or models) yet agree on the inliers.
  int differ = 0;
  for (std::uint64_t s = 43; s < 48; ++s) {
    fo.ransac.seed = s;
    const auto c = estimate_fundamental_ransac(d.points1, d.points2, fo);
    ASSERT_TRUE(c.ok());
    differ += !(c.F == a.F) || c.iterations != a.iterations;
    std::size_t disagree = 0;
    for (std::size_t i = 0; i < c.inlier_mask.size(); ++i) disagree += c.inlier_mask[i] != a.inlier_mask[i];
    EXPECT_LT(disagree, 15u);  // borderline points within noise of the threshold
  }
  EXPECT_GE(differ, 4);
}

TYPED_TEST(FundamentalTyped, TooFewPoints) {
  using T = TypeParam;
  const auto d = clean_data<T>(7, 3);
  const std::vector<Vec2<T>> six1(d.points1.begin(), d.points1.begin() + 6), six2(d.points2.begin(), d.points2.begin() + 6);
  EXPECT_EQ(fundamental_8point(d.points1, d.points2).status, Status::TooFewPoints);
  EXPECT_EQ(fundamental_7point(six1, six2).status, Status::TooFewPoints);
  const auto r = estimate_fundamental_ransac(six1, six2, FundamentalOptions<T>{});
  EXPECT_EQ(r.status, Status::TooFewPoints);
  EXPECT_FALSE(r.reason.empty());
  EXPECT_EQ(r.inlier_mask.size(), 6u);
  const std::vector<Vec2<T>> empty;
  EXPECT_EQ(estimate_fundamental_ransac(empty, empty, FundamentalOptions<T>{}).status, Status::TooFewPoints);
  EXPECT_EQ(estimate_fundamental_ransac(six1, d.points2, FundamentalOptions<T>{}).status, Status::InvalidInput);
}

TYPED_TEST(FundamentalTyped, PlanarAndPureRotationAreDegenerate) {
  using T = TypeParam;
  for (const auto kind : {TwoViewKind::Planar, TwoViewKind::PureRotation}) {
    for (const double noise : {0.0, 0.5}) {
      TwoViewOptions o;
      o.kind = kind;
      o.noise_px = noise;
      o.outlier_fraction = 0.2;
      o.num_points = 500;
      const auto d = make_two_view<T>(o);
      const auto r = estimate_fundamental_ransac(d.points1, d.points2, FundamentalOptions<T>{});
      EXPECT_EQ(r.status, Status::Degenerate) << "kind " << int(kind) << " noise " << noise;
      EXPECT_FALSE(r.reason.empty());
      EXPECT_GE(r.homography_inlier_fraction, 0.95);
      if (noise == 0.0) {
        std::vector<Vec2<T>> in1, in2;
        for (std::size_t i = 0; i < d.points1.size(); ++i)
          if (d.is_inlier[i]) in1.push_back(d.points1[i]), in2.push_back(d.points2[i]);
        const auto e = fundamental_8point(in1, in2);
        EXPECT_EQ(e.status, Status::Degenerate) << "8-point, kind " << int(kind) << ": " << e.reason;
      }
    }
  }
}

TYPED_TEST(FundamentalTyped, CollinearAndDuplicatePointsAreRejected) {
  using T = TypeParam;
  // Collinear in both images: points on a 3-D line.
  std::vector<Vec2<T>> a, b;
  for (int i = 0; i < 40; ++i) {
    a.emplace_back(T(100 + 5 * i), T(50 + 3 * i));
    b.emplace_back(T(120 + 4 * i), T(60 + 2 * i));
  }
  const auto r = estimate_fundamental_ransac(a, b, FundamentalOptions<T>{});
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.status, Status::Degenerate) << r.reason;
  EXPECT_EQ(fundamental_8point(a, b).status, Status::Degenerate);
  // The same correspondence repeated.
  const std::vector<Vec2<T>> same1(30, Vec2<T>(T(10), T(20))), same2(30, Vec2<T>(T(11), T(22)));
  const auto s = estimate_fundamental_ransac(same1, same2, FundamentalOptions<T>{});
  EXPECT_EQ(s.status, Status::Degenerate) << s.reason;
  EXPECT_EQ(fundamental_8point(same1, same2).status, Status::Degenerate);
  const auto seven = fundamental_7point(same1, same2);
  EXPECT_EQ(seven.status, Status::Degenerate);
  EXPECT_EQ(seven.count, 0);
}

TYPED_TEST(FundamentalTyped, NoBaselineIsDegenerateBeforeAnySample) {
  using T = TypeParam;
  // Every correspondence at the same pixel in both images: any F = [e]x fits, no 7-point sample can give a
  // model, so the call says Degenerate without drawing the max_iterations samples that would all fail.
  const auto d = make_two_view<T>(TwoViewOptions{});
  const auto r = estimate_fundamental_ransac(d.points1, d.points1, FundamentalOptions<T>{});
  EXPECT_EQ(r.status, Status::Degenerate);
  EXPECT_NE(r.reason.find("no baseline"), std::string::npos) << r.reason;
  EXPECT_EQ(r.iterations, 0u);
  EXPECT_EQ(r.num_inliers, 0u);
  EXPECT_EQ(r.inlier_mask, std::vector<std::uint8_t>(d.points1.size(), 0));
  // One correspondence that moved is enough for samples holding it to give a model (an F = [e]x through
  // its two pixels, which every still one fits): RANSAC runs and finds it.
  std::vector<Vec2<T>> moved = d.points1;
  moved[0] += Vec2<T>(T(3), T(1));
  const auto m = estimate_fundamental_ransac(d.points1, moved, FundamentalOptions<T>{});
  EXPECT_GT(m.iterations, 0u);
  EXPECT_EQ(m.reason.find("no baseline"), std::string::npos) << m.reason;
}

TYPED_TEST(FundamentalTyped, NonFiniteCorrespondencesAreSkipped) {
  using T = TypeParam;
  auto d = make_two_view<T>(TwoViewOptions{});
  const T nan = std::numeric_limits<T>::quiet_NaN();
  for (std::size_t i = 0; i < d.points1.size(); i += 10) d.points1[i].x() = nan;
  d.points2[5].y() = std::numeric_limits<T>::infinity();
  const auto r = estimate_fundamental_ransac(d.points1, d.points2, FundamentalOptions<T>{});
  ASSERT_TRUE(r.ok()) << r.reason;
  for (std::size_t i = 0; i < d.points1.size(); i += 10) EXPECT_EQ(r.inlier_mask[i], 0);
  EXPECT_EQ(r.inlier_mask[5], 0);
  EXPECT_LT(rms_true_sampson(r.F, d), 0.2);
  // All NaN: too few finite points.
  std::vector<Vec2<T>> bad(20, Vec2<T>(nan, nan));
  EXPECT_EQ(estimate_fundamental_ransac(bad, bad, FundamentalOptions<T>{}).status, Status::TooFewPoints);
  EXPECT_EQ(fundamental_7point(bad, bad).status, Status::NonFinite);
  EXPECT_EQ(fundamental_8point(bad, bad).status, Status::TooFewPoints);
}

/// Inputs of different sizes and outcomes in turn (large, small with NaN, all coincident, medium): a workspace
/// kept across them must not carry anything from one call into the next.
template <class T>
std::vector<TwoViewData<T>> varied_inputs() {
  std::vector<TwoViewData<T>> out;
  TwoViewOptions o;
  out.push_back(make_two_view<T>(o));
  o.num_points = 60;
  o.seed = 7;
  out.push_back(make_two_view<T>(o));
  out.back().points1[3].x() = std::numeric_limits<T>::quiet_NaN();
  TwoViewData<T> same = out.back();
  for (auto& p : same.points1) p = Vec2<T>(T(5), T(6));
  out.push_back(same);
  o.num_points = 300;
  o.seed = 8;
  out.push_back(make_two_view<T>(o));
  return out;
}

template <class T>
void expect_same_result(const FundamentalResult<T>& kept, const FundamentalResult<T>& fresh, std::size_t call) {
  EXPECT_EQ(kept.status, fresh.status) << "call " << call;
  EXPECT_EQ(kept.reason, fresh.reason) << "call " << call;
  EXPECT_TRUE(kept.F == fresh.F) << "call " << call;  // bit for bit
  EXPECT_EQ(kept.inlier_mask, fresh.inlier_mask) << "call " << call;
  EXPECT_EQ(kept.num_inliers, fresh.num_inliers) << "call " << call;
  EXPECT_EQ(kept.iterations, fresh.iterations) << "call " << call;
  EXPECT_EQ(kept.score, fresh.score) << "call " << call;
}

TYPED_TEST(FundamentalTyped, KeptWorkspaceGivesTheFreshResultWhateverCameBefore) {
  using T = TypeParam;
  const std::vector<TwoViewData<T>> inputs = varied_inputs<T>();
  FundamentalOptions<T> fo;
  FundamentalWorkspace<T> workspace;
  FundamentalResult<T> ransac_kept, eight_kept;
  for (int round = 0; round < 2; ++round) {
    for (std::size_t k = 0; k < inputs.size(); ++k) {
      const TwoViewData<T>& d = inputs[k];
      estimate_fundamental_ransac(d.points1, d.points2, fo, &workspace, &ransac_kept);
      expect_same_result(ransac_kept, estimate_fundamental_ransac(d.points1, d.points2, fo), k);
      fundamental_8point(d.points1, d.points2, &workspace, &eight_kept);
      expect_same_result(eight_kept, fundamental_8point(d.points1, d.points2), k);
    }
  }
  EXPECT_EQ(ransac_kept.status, Status::Ok);  // the last input is an ordinary one
}

TYPED_TEST(FundamentalTyped, BadOptions) {
  using T = TypeParam;
  const auto d = make_two_view<T>(TwoViewOptions{});
  FundamentalOptions<T> fo;
  fo.ransac.max_residual = 0;
  EXPECT_EQ(estimate_fundamental_ransac(d.points1, d.points2, fo).status, Status::InvalidInput);
  fo = FundamentalOptions<T>{};
  fo.degenerate_homography_fraction = -1;
  EXPECT_EQ(estimate_fundamental_ransac(d.points1, d.points2, fo).status, Status::InvalidInput);
}

TEST(FundamentalDefaults, Options) {
  const FundamentalOptions<double> o;
  EXPECT_EQ(o.ransac.max_residual, 1.0);
  EXPECT_EQ(o.ransac.confidence, 0.99);
  EXPECT_TRUE(o.sampson_weighted_refit);
  EXPECT_TRUE(o.check_homography_degeneracy);
  const FundamentalResult<float> r;
  EXPECT_TRUE(r.ok());
  EXPECT_TRUE(r.F.isZero());
}

TEST(FundamentalCubic, KnownRoots) {
  double roots[3];
  // (x - 1)(x - 2)(x + 3) = x^3 - 7x + 6.
  ASSERT_EQ(detail::solve_cubic(1, 0, -7, 6, roots), 3);
  std::sort(roots, roots + 3);
  EXPECT_NEAR(roots[0], -3, 1e-12);
  EXPECT_NEAR(roots[1], 1, 1e-12);
  EXPECT_NEAR(roots[2], 2, 1e-12);
  // x^3 + x + 1: one real root near -0.6823278.
  ASSERT_EQ(detail::solve_cubic(1, 0, 1, 1, roots), 1);
  EXPECT_NEAR(roots[0], -0.6823278038280193, 1e-12);
  // Leading coefficient zero: 2x^2 - 8 = 0.
  ASSERT_EQ(detail::solve_cubic(0, 2, 0, -8, roots), 2);
  EXPECT_NEAR(std::abs(roots[0]), 2, 1e-12);
  EXPECT_NEAR(roots[0] + roots[1], 0, 1e-12);
  EXPECT_EQ(detail::solve_cubic(0, 0, 0, 0, roots), 0);
}

TEST(FundamentalPointTypes, KeypointLikeAndStructPoints) {
  struct P {
    float x, y;
  };
  struct K {
    P pt;
  };
  const auto d = make_two_view<double>(TwoViewOptions{});
  std::vector<P> a;
  std::vector<K> b;
  for (std::size_t i = 0; i < d.points1.size(); ++i) {
    a.push_back(P{float(d.points1[i].x()), float(d.points1[i].y())});
    b.push_back(K{P{float(d.points2[i].x()), float(d.points2[i].y())}});
  }
  const auto r = estimate_fundamental_ransac(a, b, FundamentalOptions<float>{});
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_LT(rms_true_sampson<double>(r.F.cast<double>(), d), 0.2);
}

#ifdef DYNCULL_HAS_OPENCV
TEST(FundamentalOpenCV, AgreesWithFindFundamentalMat) {
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    TwoViewOptions o;
    o.seed = seed;
    const auto d = make_two_view<double>(o);
    std::vector<cv::Point2f> a, b;
    for (std::size_t i = 0; i < d.points1.size(); ++i) {
      a.emplace_back(float(d.points1[i].x()), float(d.points1[i].y()));
      b.emplace_back(float(d.points2[i].x()), float(d.points2[i].y()));
    }
    cv::Mat mask;
    const cv::Mat Fcv = cv::findFundamentalMat(a, b, cv::USAC_ACCURATE, 1.0, 0.99, 10000, mask);
    ASSERT_EQ(Fcv.rows, 3);
    Mat3<double> Fo;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) Fo(r, c) = Fcv.at<double>(r, c);
    const auto ours = estimate_fundamental_ransac(a, b, FundamentalOptions<float>{});
    ASSERT_TRUE(ours.ok()) << ours.reason;
    // Same data, same threshold: both model the truth within noise, and ours is no worse than OpenCV's.
    const double e_cv = rms_true_sampson<double>(Fo, d);
    const double e_ours = rms_true_sampson<double>(ours.F.cast<double>(), d);
    EXPECT_LT(e_ours, 0.2);
    EXPECT_LT(e_ours, e_cv * 1.25 + 0.02) << "opencv " << e_cv;
    // Inlier sets agree except near the threshold.
    std::size_t disagree = 0;
    for (std::size_t i = 0; i < a.size(); ++i) disagree += (mask.at<uchar>(int(i)) != 0) != (ours.inlier_mask[i] != 0);
    // About 5 % of true inliers lie within noise of the 1 px threshold (see the recall test): two good F
    // split them differently.
    EXPECT_LT(double(disagree), 0.08 * double(a.size()));
    // The 8-point on the same inliers agrees with cv::FM_8POINT.
    std::vector<cv::Point2f> ia, ib;
    for (std::size_t i = 0; i < a.size(); ++i)
      if (d.is_inlier[i]) ia.push_back(a[i]), ib.push_back(b[i]);
    const cv::Mat F8 = cv::findFundamentalMat(ia, ib, cv::FM_8POINT);
    Mat3<double> F8e;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) F8e(r, c) = F8.at<double>(r, c);
    const auto e8 = fundamental_8point(ia, ib);
    ASSERT_TRUE(e8.ok());
    EXPECT_NEAR(rms_true_sampson<double>(e8.F.cast<double>(), d), rms_true_sampson<double>(F8e, d), 0.05);
  }
}
#endif

TEST(FundamentalOptionsValidate, NamesTheFieldIncludingNestedRansac) {
  std::string why;
  FundamentalOptions<double> o;
  EXPECT_EQ(o.validate(&why), Status::Ok);
  EXPECT_TRUE(why.empty());
  const auto d = clean_data<double>(40, 3);
  auto check = [&](const FundamentalOptions<double>& bad, const char* field) {
    EXPECT_EQ(bad.validate(&why), Status::InvalidInput);
    EXPECT_NE(why.find(field), std::string::npos) << why;
    const auto r = estimate_fundamental_ransac(d.points1, d.points2, bad);
    EXPECT_EQ(r.status, Status::InvalidInput);
    EXPECT_NE(r.reason.find(field), std::string::npos) << r.reason;
  };
  FundamentalOptions<double> bad = o;
  bad.degenerate_homography_fraction = 5;  // a fraction above 1 silently disabled the check
  check(bad, "degenerate_homography_fraction");
  bad = o;
  bad.homography_threshold_factor = HUGE_VAL;
  check(bad, "homography_threshold_factor");
  bad = o;
  bad.ransac.max_iterations = static_cast<std::size_t>(-1);
  check(bad, "ransac.max_iterations");
}

template <class T>
T wild_pixel(Random& rng) {
  const double u = rng.uniform();
  if (u < 0.02) return std::numeric_limits<T>::quiet_NaN();
  if (u < 0.03) return -std::numeric_limits<T>::infinity();
  if (u < 0.05) return std::numeric_limits<T>::max() * T(rng.uniform(-1, 1));
  if (u < 0.06) return std::numeric_limits<T>::denorm_min();
  if (u < 0.08) return T(rng.uniform(-1, 1) * 1e18);
  return T(rng.uniform(0, 640));
}

// For any correspondences and options: a non-Ok status with a reason, or a finite F with a consistent
// mask (8-point, 7-point and RANSAC).
TYPED_TEST(FundamentalTyped, PropertyModelIsFiniteOrTheCallFails) {
  using T = TypeParam;
  Random rng(51);
  for (int trial = 0; trial < 200; ++trial) {
    const std::size_t n = rng.index(40);
    const bool half_clean = rng.uniform() < 0.5;
    TwoViewOptions tv;
    tv.num_points = static_cast<int>(n);
    tv.seed = trial;
    auto d = make_two_view<T>(tv);
    for (std::size_t i = 0; i < n; ++i) {
      if (half_clean && rng.uniform() < 0.8) continue;
      d.points1[i] = Vec2<T>(wild_pixel<T>(rng), wild_pixel<T>(rng));
      if (rng.uniform() < 0.5) d.points2[i] = Vec2<T>(wild_pixel<T>(rng), wild_pixel<T>(rng));
    }
    FundamentalOptions<T> o;
    o.ransac.max_iterations = 1 + rng.index(300);
    o.ransac.max_residual = rng.uniform() < 0.1 ? -1.0 : rng.uniform(0.1, 5);
    o.ransac.seed = trial;
    o.sampson_weighted_refit = rng.uniform() < 0.5;
    if (rng.uniform() < 0.1) o.degenerate_homography_fraction = std::nan("");
    const auto check = [&](const FundamentalResult<T>& r, const char* which) {
      if (!r.ok()) {
        EXPECT_FALSE(r.reason.empty()) << which << " trial " << trial;
        return;
      }
      EXPECT_TRUE(r.F.allFinite()) << which << " trial " << trial;
      ASSERT_EQ(r.inlier_mask.size(), n) << which;
      std::size_t count = 0;
      for (std::size_t i = 0; i < n; ++i) {
        count += r.inlier_mask[i];
        if (r.inlier_mask[i]) {
          EXPECT_TRUE(d.points1[i].allFinite() && d.points2[i].allFinite()) << which << " trial " << trial;
        }
      }
      EXPECT_EQ(count, r.num_inliers) << which << " trial " << trial;
    };
    check(estimate_fundamental_ransac(d.points1, d.points2, o), "ransac");
    check(fundamental_8point(d.points1, d.points2), "8-point");
    const auto seven = fundamental_7point(d.points1, d.points2);
    if (seven.ok()) {
      for (int k = 0; k < seven.count; ++k) EXPECT_TRUE(seven.F[static_cast<std::size_t>(k)].allFinite()) << trial;
    } else {
      EXPECT_FALSE(seven.reason.empty()) << trial;
    }
  }
}

}  // namespace
}  // namespace dyncull
