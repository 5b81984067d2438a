// Tests of geometry/epipolar.hpp: DFD-SLAM (Qian et al. 2024) eq. 3 distance, symmetric and Sampson distances,
// batch kernels against a scalar double-precision oracle, thresholded labels, and cv::computeCorrespondEpilines.
#include "dyncull/geometry/epipolar.hpp"

#include "support/two_view.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <deque>
#include <limits>
#include <vector>

#ifdef DYNCULL_HAS_OPENCV
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#endif

namespace dyncull {
namespace {

using test::TwoViewOptions;
using test::make_two_view;

template <class T>
class EpipolarTyped : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(EpipolarTyped, Scalars, );  // trailing comma: clang -Wpedantic rejects an empty variadic

/// Relative tolerance of the batch kernels against the double oracle: float rounding of ~1e3-magnitude
/// products (pixels times F entries) leaves ~1e-4 relative error in the residual p2^T F p1.
template <class T> double batch_rel_tol() { return std::is_same<T, double>::value ? 1e-9 : 2e-3; }

/// Oracle in double, written from the definitions.
double oracle(const Mat3<double>& F, const Vec2<double>& a, const Vec2<double>& b, EpipolarDistance kind) {
  const Vec3<double> p1(a.x(), a.y(), 1), p2(b.x(), b.y(), 1);
  const Vec3<double> l2 = F * p1, l1 = F.transpose() * p2;
  const double e = p2.dot(F * p1);
  const double n2 = l2.head<2>().squaredNorm(), n1 = l1.head<2>().squaredNorm();
  switch (kind) {
    case EpipolarDistance::PointToLine: return std::abs(e) / std::sqrt(n2);
    case EpipolarDistance::PointToLineSq: return e * e / n2;
    case EpipolarDistance::SymmetricSq: return e * e / n2 + e * e / n1;
    case EpipolarDistance::SampsonSq: return e * e / (n1 + n2);
  }
  return 0;
}

TEST(Epipolar, PointToLineByHand) {
  // Pure horizontal translation, K = I: F = [t]x with t = (1, 0, 0): lines are y = const.
  Mat3<double> F;
  F << 0, 0, 0, 0, 0, -1, 0, 1, 0;
  const Vec2<double> p1(10, 20);
  const Vec3<double> l = epipolar_line(F, p1);  // (0, -1, 20): y = 20
  EXPECT_DOUBLE_EQ(l[0], 0);
  EXPECT_DOUBLE_EQ(l[1], -1);
  EXPECT_DOUBLE_EQ(l[2], 20);
  EXPECT_DOUBLE_EQ(epipolar_distance(F, p1, Vec2<double>(300, 23)), 3.0);
  EXPECT_DOUBLE_EQ(epipolar_distance(F, p1, Vec2<double>(-5, 20)), 0.0);
  // Both lines horizontal with unit normals: symmetric = 2 d^2, Sampson = d^2 / 2.
  EXPECT_DOUBLE_EQ(symmetric_epipolar_distance_sq(F, p1, Vec2<double>(0, 23)), 18.0);
  EXPECT_DOUBLE_EQ(sampson_distance_sq(F, p1, Vec2<double>(0, 23)), 4.5);
  // Scale invariance of F.
  EXPECT_DOUBLE_EQ(epipolar_distance(Mat3<double>(7.0 * F), p1, Vec2<double>(300, 23)), 3.0);
}

TEST(Epipolar, UndefinedLineIsNaN) {
  Mat3<double> F;
  F << 0, 0, 0, 0, 0, -1, 0, 1, 0;
  // p1 = epipole direction: F p1 = 0 for p1 at infinity; a finite p1 with (X, Y) = 0 needs F p1 = (0, 0, z).
  Mat3<double> G = Mat3<double>::Zero();
  G(2, 2) = 1;  // every line is (0, 0, 1): the line at infinity
  EXPECT_TRUE(std::isnan(epipolar_distance(G, Vec2<double>(1, 2), Vec2<double>(3, 4))));
  EXPECT_TRUE(std::isnan(sampson_distance_sq(Mat3<double>(Mat3<double>::Zero()), Vec2<double>(1, 2), Vec2<double>(3, 4))));
  const std::vector<Vec2<double>> a{Vec2<double>(1, 2)}, b{Vec2<double>(3, 4)};
  std::uint8_t label = 7;
  std::size_t count = 9;
  ASSERT_EQ(label_epipolar(G, a, b, 1.0, &label, &count), Status::Ok);
  // 1 > 1 * 0 would label it; (p2^T G p1)^2 = 1 > 0: the line at infinity is "infinitely far".
  EXPECT_EQ(label, 1);
  EXPECT_EQ(count, 1u);
  // Non-finite input: NaN distance, label 0 (no evidence).
  const std::vector<Vec2<double>> c{Vec2<double>(std::nan(""), 2)};
  ASSERT_EQ(label_epipolar(F, c, b, 1.0, &label, &count), Status::Ok);
  EXPECT_EQ(label, 0);
  EXPECT_EQ(count, 0u);
  std::vector<double> d;
  ASSERT_EQ(epipolar_distances(F, c, b, &d), Status::Ok);
  EXPECT_TRUE(std::isnan(d[0]));
}

TYPED_TEST(EpipolarTyped, BatchMatchesScalarOracleAcrossBlockBoundaries) {
  using T = TypeParam;
  for (const int n : {0, 1, 7, 255, 256, 257, 1000}) {
    TwoViewOptions o;
    o.num_points = n;
    o.seed = 100 + std::uint64_t(n);
    const auto d = make_two_view<T>(o);
    const Mat3<double> Fd = d.F.template cast<double>();
    for (const auto kind : {EpipolarDistance::PointToLine, EpipolarDistance::PointToLineSq,
                            EpipolarDistance::SymmetricSq, EpipolarDistance::SampsonSq}) {
      std::vector<T> out;
      ASSERT_EQ(epipolar_distances(d.F, d.points1, d.points2, &out, kind), Status::Ok);
      ASSERT_EQ(out.size(), std::size_t(n));
      for (int i = 0; i < n; ++i) {
        const double ref = oracle(Fd, d.points1[std::size_t(i)].template cast<double>(),
                                  d.points2[std::size_t(i)].template cast<double>(), kind);
        // Absolute floor for near-zero distances of inliers (float: 1e-3 px).
        EXPECT_NEAR(double(out[std::size_t(i)]), ref, batch_rel_tol<T>() * ref + (std::is_same<T, double>::value ? 1e-9 : 1e-3))
            << "n " << n << " i " << i << " kind " << int(kind);
      }
    }
    // Scalar helpers agree with the batch.
    std::vector<T> line, sampson, sym;
    ASSERT_EQ(epipolar_distances(d.F, d.points1, d.points2, &line), Status::Ok);
    ASSERT_EQ(sampson_distances_sq(d.F, d.points1, d.points2, &sampson), Status::Ok);
    ASSERT_EQ(symmetric_epipolar_distances_sq(d.F, d.points1, d.points2, &sym), Status::Ok);
    for (int i = 0; i < n; ++i) {
      const auto& a = d.points1[std::size_t(i)];
      const auto& b = d.points2[std::size_t(i)];
      const double tol = std::is_same<T, double>::value ? 1e-9 : 2e-3;
      EXPECT_NEAR(double(epipolar_distance(d.F, a, b)), double(line[std::size_t(i)]), tol * (1 + line[std::size_t(i)]));
      EXPECT_NEAR(double(sampson_distance_sq(d.F, a, b)), double(sampson[std::size_t(i)]), tol * (1 + sampson[std::size_t(i)]));
      EXPECT_NEAR(double(symmetric_epipolar_distance_sq(d.F, a, b)), double(sym[std::size_t(i)]), tol * (1 + sym[std::size_t(i)]));
    }
  }
}

// Packed (x, y) containers take a fused one-pass path for eq. 3; it must give what the SoA kernel gives,
// in the SIMD body and the tail, for NaN input and for undefined lines (X = Y = 0).
TYPED_TEST(EpipolarTyped, PackedPathMatchesSoaKernel) {
  using T = TypeParam;
  TwoViewOptions o;
  o.num_points = 11;  // two SIMD blocks of 4 floats / five of 2 doubles, then a tail
  const auto d = make_two_view<T>(o);
  std::vector<Vec2<T>> a = d.points1, b = d.points2;
  a[1].x() = std::numeric_limits<T>::quiet_NaN();
  b[6].y() = std::numeric_limits<T>::infinity();
  a[10].y() = std::numeric_limits<T>::quiet_NaN();
  auto soa = [](const Mat3<T>& F, const std::vector<Vec2<T>>& p, const std::vector<Vec2<T>>& q) {
    std::vector<T> x1, y1, x2, y2, out(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) {
      x1.push_back(p[i].x());
      y1.push_back(p[i].y());
      x2.push_back(q[i].x());
      y2.push_back(q[i].y());
    }
    epipolar_distances_soa(F, x1.data(), y1.data(), x2.data(), y2.data(), p.size(), out.data());
    return out;
  };
  Mat3<T> line_at_infinity = Mat3<T>::Zero();
  line_at_infinity(2, 2) = T(1);
  for (const Mat3<T>& F : {d.F, line_at_infinity}) {
    std::vector<T> packed;
    ASSERT_EQ(epipolar_distances(F, a, b, &packed), Status::Ok);
    const std::vector<T> ref = soa(F, a, b);
    ASSERT_EQ(packed.size(), ref.size());
    for (std::size_t i = 0; i < ref.size(); ++i) {
      if (std::isnan(ref[i])) {
        EXPECT_TRUE(std::isnan(packed[i])) << i;
      } else if (std::isinf(ref[i])) {
        EXPECT_EQ(packed[i], ref[i]) << i;
      } else {
        EXPECT_NEAR(packed[i], ref[i], 4 * std::numeric_limits<T>::epsilon() * (T(1) + ref[i])) << i;
      }
    }
  }
  // The points that must be NaN are.
  std::vector<T> out;
  ASSERT_EQ(epipolar_distances(d.F, a, b, &out), Status::Ok);
  EXPECT_TRUE(std::isnan(out[1]));
  EXPECT_TRUE(std::isnan(out[10]));
  EXPECT_FALSE(std::isfinite(out[6]));
  EXPECT_TRUE(std::isfinite(out[0]) && std::isfinite(out[9]));
}

TYPED_TEST(EpipolarTyped, LabelsMatchThresholdedDistances) {
  using T = TypeParam;
  TwoViewOptions o;  // 1000 points, 30 % outliers >= 3 px off their line, 0.5 px noise
  const auto d = make_two_view<T>(o);
  std::vector<T> dist;
  ASSERT_EQ(epipolar_distances(d.F, d.points1, d.points2, &dist), Status::Ok);
  for (const T thr : {T(0.5), T(1), T(2.5)}) {
    std::vector<std::uint8_t> labels(dist.size(), 9);
    std::size_t count = 0;
    ASSERT_EQ(label_epipolar(d.F, d.points1, d.points2, thr, labels.data(), &count), Status::Ok);
    std::size_t expected = 0, mismatched = 0;
    for (std::size_t i = 0; i < dist.size(); ++i) {
      const bool above = dist[i] > thr;
      expected += above;
      // Equality within rounding may flip; no exact ties in random data, so demand agreement off a 1e-4 band.
      if (std::abs(double(dist[i]) - double(thr)) > 1e-4) mismatched += (labels[i] != 0) != above;
      EXPECT_LE(labels[i], 1);
    }
    EXPECT_EQ(mismatched, 0u);
    EXPECT_NEAR(double(count), double(expected), 1.0);
  }
  // Semantics: clean inliers are on their lines, outliers at least 3 px off (the generator's guarantee).
  std::vector<T> clean;
  ASSERT_EQ(epipolar_distances(d.F, d.clean1, d.clean2, &clean), Status::Ok);
  const double on_line_tol = std::is_same<T, double>::value ? 1e-6 : 5e-3;
  for (std::size_t i = 0; i < clean.size(); ++i) {
    if (d.is_inlier[i]) {
      EXPECT_LT(double(clean[i]), on_line_tol);
    }
  }
  std::vector<std::uint8_t> labels(dist.size());
  ASSERT_EQ(label_epipolar(d.F, d.clean1, d.points2, T(2.9), labels.data()), Status::Ok);
  for (std::size_t i = 0; i < labels.size(); ++i) {
    if (!d.is_inlier[i]) {
      EXPECT_EQ(labels[i], 1) << i;
    }
  }
}

TYPED_TEST(EpipolarTyped, SizeMismatchIsInvalidInput) {
  using T = TypeParam;
  const std::vector<Vec2<T>> a(3, Vec2<T>(T(1), T(2))), b(2, Vec2<T>(T(1), T(2)));
  std::vector<T> out;
  EXPECT_EQ(epipolar_distances(Mat3<T>(Mat3<T>::Identity()), a, b, &out), Status::InvalidInput);
  std::uint8_t labels[3];
  EXPECT_EQ(label_epipolar(Mat3<T>(Mat3<T>::Identity()), a, b, T(1), labels), Status::InvalidInput);
}

TYPED_TEST(EpipolarTyped, UndeterminedMatrixIsReportedNotNaN) {
  using T = TypeParam;
  const std::vector<Vec2<T>> a = {Vec2<T>(10, 20), Vec2<T>(30, 40)}, b = {Vec2<T>(11, 19), Vec2<T>(29, 41)};
  std::vector<T> out;
  std::vector<std::uint8_t> labels(2);
  for (auto kind : {dyncull::EpipolarDistance::PointToLine, dyncull::EpipolarDistance::SampsonSq}) {
    EXPECT_EQ(epipolar_distances(Mat3<T>(Mat3<T>::Zero()), a, b, &out, kind), Status::Degenerate);
    Mat3<T> F = Mat3<T>::Identity();
    F(1, 2) = std::numeric_limits<T>::quiet_NaN();
    EXPECT_EQ(epipolar_distances(F, a, b, &out, kind), Status::NonFinite);
  }
  EXPECT_EQ(label_epipolar(Mat3<T>(Mat3<T>::Zero()), a, b, T(1), labels.data()), Status::Degenerate);
  // A valid F with entries so large that X^2 + Y^2 overflows: the distance is scale-free in F.
  Mat3<T> F;
  F << 0, 0, 0, 0, 0, -1, 0, 1, 0;  // pure horizontal translation: lines are rows, distance = |y2 - y1|
  ASSERT_EQ(epipolar_distances(F, a, b, &out), Status::Ok);
  EXPECT_NEAR(out[0], T(1), T(1e-5));
  const Mat3<T> huge = F * (std::numeric_limits<T>::max() / T(4));
  for (auto kind : {dyncull::EpipolarDistance::PointToLine, dyncull::EpipolarDistance::PointToLineSq,
                    dyncull::EpipolarDistance::SymmetricSq, dyncull::EpipolarDistance::SampsonSq}) {
    ASSERT_EQ(epipolar_distances(huge, a, b, &out, kind), Status::Ok);
    EXPECT_TRUE(std::isfinite(out[0])) << static_cast<int>(kind);
    EXPECT_TRUE(std::isfinite(out[1])) << static_cast<int>(kind);
  }
  std::size_t count = 9;
  ASSERT_EQ(label_epipolar(huge, a, b, T(0.5), labels.data(), &count), Status::Ok);
  EXPECT_EQ(count, 2u);  // both distances are 1 px > 0.5
}

template <class T>
T wild_coordinate(Random& rng) {
  const double u = rng.uniform();
  if (u < 0.03) return std::numeric_limits<T>::quiet_NaN();
  if (u < 0.05) return std::numeric_limits<T>::infinity();
  if (u < 0.07) return -std::numeric_limits<T>::infinity();
  if (u < 0.09) return std::numeric_limits<T>::max() * T(rng.uniform(-1, 1));
  if (u < 0.11) return std::numeric_limits<T>::denorm_min();
  return T(rng.uniform(-50, 700));
}

// The SSE2 packed path, the SoA block path (a container without data()) and the scalar one-point
// function agree on NaN, Inf and huge inputs at sizes around the vector widths and the 256-point block.
// Property: Ok means every distance is finite unless its own line is undefined.
TYPED_TEST(EpipolarTyped, PropertyPackedSoaAndScalarAgreeOnWildInput) {
  using T = TypeParam;
  Random rng(99);
  const std::vector<std::size_t> sizes = {0, 1, 2, 3, 4, 5, 7, 8, 9, 15, 16, 17, 255, 256, 257, 263, 513};
  for (int trial = 0; trial < 300; ++trial) {
    const std::size_t n = sizes[rng.index(static_cast<std::uint32_t>(sizes.size()))];
    Mat3<T> F;
    const double kind_of_f = rng.uniform();
    for (int k = 0; k < 9; ++k) F(k / 3, k % 3) = T(rng.normal());
    if (kind_of_f < 0.1) F(rng.index(3), rng.index(3)) = wild_coordinate<T>(rng);
    if (kind_of_f > 0.9) F *= std::numeric_limits<T>::max() / T(64);
    if (kind_of_f > 0.85 && kind_of_f <= 0.9) F *= T(1e-30);
    const bool clean = rng.uniform() < 0.3;
    std::vector<Vec2<T>> a(n), b(n);
    std::deque<Vec2<T>> da, db;
    for (std::size_t i = 0; i < n; ++i) {
      for (Vec2<T>* p : {&a[i], &b[i]}) {
        *p = clean ? Vec2<T>(T(rng.uniform(0, 640)), T(rng.uniform(0, 480)))
                   : Vec2<T>(wild_coordinate<T>(rng), wild_coordinate<T>(rng));
      }
      da.push_back(a[i]);
      db.push_back(b[i]);
    }
    std::vector<T> packed, blocked;
    const Status s = epipolar_distances(F, a, b, &packed);
    ASSERT_EQ(epipolar_distances(F, da, db, &blocked), s);
    if (s != Status::Ok) {
      EXPECT_TRUE(s == Status::NonFinite || s == Status::Degenerate) << static_cast<int>(s);
      EXPECT_FALSE(F.allFinite() && F.cwiseAbs().maxCoeff() > T(0));
      continue;
    }
    ASSERT_EQ(packed.size(), n);
    const T m = F.cwiseAbs().maxCoeff();
    const Mat3<T> Fn = F / m;  // the one-point function is not normalised: give it a tame F
    for (std::size_t i = 0; i < n; ++i) {
      const T one = dyncull::epipolar_distance(Fn, a[i], b[i]);
      // Finite coordinates beyond 1e15 px are not pixels: X^2 may overflow and each path may give NaN,
      // +inf or 0 there (documented); everything else must agree.
      const bool huge = (a[i].allFinite() && a[i].cwiseAbs().maxCoeff() > T(1e15)) ||
                        (b[i].allFinite() && b[i].cwiseAbs().maxCoeff() > T(1e15));
      if (huge) continue;
      if (std::isfinite(packed[i])) {
        const T tol = T(64) * std::numeric_limits<T>::epsilon() * (T(1) + std::abs(packed[i]));
        EXPECT_NEAR(blocked[i], packed[i], tol) << "trial " << trial << " i " << i;
        if (std::isfinite(one)) {
          EXPECT_NEAR(one, packed[i], T(1e3) * tol) << "trial " << trial << " i " << i;
        }
      } else {
        EXPECT_FALSE(std::isfinite(blocked[i])) << "trial " << trial << " i " << i;
        // Not finite only where the line is undefined: a non-finite coordinate or the epipole.
        const bool wild = !a[i].allFinite() || !b[i].allFinite();
        const Vec3<T> l = Fn * Vec3<T>(a[i].x(), a[i].y(), T(1));
        const bool at_epipole = !(l.x() * l.x() + l.y() * l.y() > T(0));
        EXPECT_TRUE(wild || at_epipole) << "trial " << trial << " i " << i << ": " << packed[i];
      }
    }
    // Labels agree with the thresholded distances wherever the distance is finite.
    std::vector<std::uint8_t> labels(n, 7);
    std::size_t count = 0;
    const T thr = T(rng.uniform(0, 5));
    ASSERT_EQ(label_epipolar(F, a, b, thr, labels.data(), &count), Status::Ok);
    std::size_t ones = 0;
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_LE(labels[i], 1);
      ones += labels[i];
      if (std::isfinite(packed[i]) && std::abs(packed[i] - thr) > T(1e-3) * (T(1) + thr)) {
        EXPECT_EQ(labels[i], packed[i] > thr ? 1 : 0) << "trial " << trial << " i " << i;
      }
    }
    EXPECT_EQ(ones, count);
  }
  std::vector<std::uint8_t> one_label(1);
  const std::vector<Vec2<T>> p = {Vec2<T>(1, 2)};
  EXPECT_EQ(label_epipolar(Mat3<T>(Mat3<T>::Identity()), p, p, std::numeric_limits<T>::quiet_NaN(), one_label.data()),
            Status::InvalidInput);
  EXPECT_EQ(label_epipolar(Mat3<T>(Mat3<T>::Identity()), p, p, T(-1), one_label.data()), Status::InvalidInput);
}

TEST(EpipolarPointTypes, StructAndKeypointContainers) {
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
  std::vector<float> out;
  ASSERT_EQ(epipolar_distances(Mat3<float>(d.F.cast<float>()), a, b, &out), Status::Ok);
  for (std::size_t i = 0; i < out.size(); ++i)
    EXPECT_NEAR(out[i], epipolar_distance(d.F, d.points1[i], d.points2[i]), 2e-3 * (1 + out[i]));
}

#ifdef DYNCULL_HAS_OPENCV
TEST(EpipolarOpenCV, MatchesComputeCorrespondEpilines) {
  const auto d = make_two_view<double>(TwoViewOptions{});
  std::vector<cv::Point2f> a, b;
  for (std::size_t i = 0; i < d.points1.size(); ++i) {
    a.emplace_back(float(d.points1[i].x()), float(d.points1[i].y()));
    b.emplace_back(float(d.points2[i].x()), float(d.points2[i].y()));
  }
  cv::Mat Fcv(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) Fcv.at<double>(r, c) = d.F(r, c);
  std::vector<cv::Vec3f> lines;
  cv::computeCorrespondEpilines(a, 1, Fcv, lines);  // lines in image 2, normalised a^2 + b^2 = 1
  std::vector<float> ours;
  ASSERT_EQ(epipolar_distances(Mat3<float>(d.F.cast<float>()), a, b, &ours), Status::Ok);
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double cvd = std::abs(lines[i][0] * b[i].x + lines[i][1] * b[i].y + lines[i][2]);
    EXPECT_NEAR(ours[i], cvd, 2e-3 * (1 + cvd)) << i;
  }
}
#endif

}  // namespace
}  // namespace dyncull
