// Tests of culling/descriptor_switch.hpp: the 20° switch (DFD-SLAM, Qian et al. 2024, eq. 17), Hamming and L2
// distances,
// brute-force matchers against a naive oracle (and cv::BFMatcher when OpenCV is present), ratio test,
// cross-check, strides, and the eq. 18 nearest-keyframe search.
#include "dyncull/culling/descriptor_switch.hpp"

#include "dyncull/core/random.hpp"

#include <gtest/gtest.h>

#ifdef DYNCULL_HAS_OPENCV
#include <opencv2/features2d.hpp>
#endif

#include <algorithm>
#include <bitset>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace {

using dyncull::DescriptorKind;
using dyncull::Status;

std::vector<std::uint8_t> random_bytes(std::size_t n, std::uint64_t seed) {
  dyncull::Random rng(seed);
  std::vector<std::uint8_t> v(n);
  for (auto& b : v) b = static_cast<std::uint8_t>(rng.next() >> 56);
  return v;
}

int naive_hamming(const std::uint8_t* a, const std::uint8_t* b) {
  int d = 0;
  for (int i = 0; i < 32; ++i) d += static_cast<int>(std::bitset<8>(static_cast<unsigned>(a[i] ^ b[i])).count());
  return d;
}

TEST(DescriptorSwitch, TwentyDegreeRule) {
  EXPECT_EQ(dyncull::choose_descriptor(25.0), DescriptorKind::Orb);
  EXPECT_EQ(dyncull::choose_descriptor(-25.0), DescriptorKind::Orb);  // direction does not matter
  EXPECT_EQ(dyncull::choose_descriptor(20.0), DescriptorKind::Learned);  // "bigger than" the threshold
  EXPECT_EQ(dyncull::choose_descriptor(5.0), DescriptorKind::Learned);
  EXPECT_EQ(dyncull::choose_descriptor(std::nan("")), DescriptorKind::Learned);
  dyncull::DescriptorSwitchOptions o;
  o.switch_angle_deg = 10.0;
  EXPECT_EQ(dyncull::choose_descriptor(15.0, o), DescriptorKind::Orb);
  EXPECT_STREQ(dyncull::to_string(DescriptorKind::Orb), "orb");
  EXPECT_DOUBLE_EQ(dyncull::DescriptorSwitchOptions{}.switch_angle_deg, 20.0);
}

TEST(DescriptorSwitch, FromRotationResult) {
  // A real 30° rotation about the image centre selects ORB; a 10° one keeps the learned descriptors.
  for (double deg : {30.0, 10.0}) {
    std::vector<Eigen::Vector2d> p1, p2;
    dyncull::Random rng(5);
    const double a = deg * M_PI / 180.0;
    for (int i = 0; i < 100; ++i) {
      const double x = rng.uniform(0, 639) - 319.5, y = rng.uniform(0, 479) - 239.5;
      p1.emplace_back(x + 319.5, y + 239.5);
      p2.emplace_back(std::cos(a) * x - std::sin(a) * y + 319.5, std::sin(a) * x + std::cos(a) * y + 239.5);
    }
    const auto r = dyncull::estimate_rotation_centre(p1, p2, 640, 480);
    ASSERT_TRUE(r.ok()) << r.reason;
    EXPECT_EQ(dyncull::choose_descriptor(r), deg > 20 ? DescriptorKind::Orb : DescriptorKind::Learned);
  }
  // No rotation found (here: too few vectors) -> learned, whatever the stale angle field says.
  dyncull::RotationCentreResult<double> failed;
  failed.status = Status::TooFewPoints;
  failed.angle_rad = 1.0;
  EXPECT_EQ(dyncull::choose_descriptor(failed), DescriptorKind::Learned);
}

TEST(Hamming, MatchesNaiveBitCount) {
  const auto a = random_bytes(32 * 200, 1), b = random_bytes(32 * 200, 2);
  for (std::size_t i = 0; i < 200; ++i) {
    EXPECT_EQ(dyncull::hamming256(&a[32 * i], &b[32 * i]), naive_hamming(&a[32 * i], &b[32 * i]));
  }
  EXPECT_EQ(dyncull::hamming256(&a[0], &a[0]), 0);
  std::vector<std::uint8_t> ones(32, 0xFF), zeros(32, 0);
  EXPECT_EQ(dyncull::hamming256(ones.data(), zeros.data()), 256);
  // The SWAR fallback equals the builtin.
  for (std::uint64_t x : {0ull, 1ull, 0xFFFFFFFFFFFFFFFFull, 0x8000000000000001ull, 0x0123456789ABCDEFull}) {
    EXPECT_EQ(dyncull::detail::popcount64_swar(x), __builtin_popcountll(x));
  }
}

/// Train set = shuffled copies of the queries with a few bits flipped, plus distractors.
struct BinarySet {
  std::vector<std::uint8_t> query, train;
  std::vector<std::uint32_t> truth;  // truth[i] = train row of query i
};

BinarySet planted_binary(std::size_t nq, std::size_t distractors, std::uint64_t seed) {
  BinarySet s;
  s.query = random_bytes(32 * nq, seed);
  const std::size_t nt = nq + distractors;
  s.train = random_bytes(32 * nt, seed + 1);
  dyncull::Random rng(seed + 2);
  std::vector<std::uint32_t> perm(nt);
  for (std::uint32_t i = 0; i < nt; ++i) perm[i] = i;
  for (std::size_t i = nt - 1; i > 0; --i) std::swap(perm[i], perm[rng.index(static_cast<std::uint32_t>(i + 1))]);
  s.truth.resize(nq);
  for (std::size_t i = 0; i < nq; ++i) {
    const std::uint32_t j = perm[i];
    s.truth[i] = j;
    std::copy(&s.query[32 * i], &s.query[32 * i] + 32, &s.train[32 * j]);
    for (int f = 0; f < 10; ++f) s.train[32 * j + rng.index(32)] ^= static_cast<std::uint8_t>(1u << rng.index(8));
  }
  return s;
}

TEST(MatchHamming, FindsPlantedMatchesAndAgreesWithNaive) {
  const auto s = planted_binary(150, 100, 10);
  const dyncull::BinaryDescriptors q{s.query.data(), 150, 32}, t{s.train.data(), 250, 32};
  const auto r = dyncull::match_hamming256(q, t);
  ASSERT_TRUE(r.ok()) << r.reason;
  ASSERT_EQ(r.matches.size(), 150u);
  for (const auto& m : r.matches) {
    EXPECT_EQ(m.train, s.truth[m.query]);
    int naive_best = 1000;
    for (std::size_t j = 0; j < 250; ++j) naive_best = std::min(naive_best, naive_hamming(&s.query[32 * m.query], &s.train[32 * j]));
    EXPECT_EQ(m.distance, static_cast<float>(naive_best));
    EXPECT_LE(m.distance, 10.f);
  }
}

TEST(MatchHamming, RatioCrossCheckAndMaxDistance) {
  // Pure random sets: nearest neighbours are ~90-110 bits away with no clear winner.
  const auto q = random_bytes(32 * 100, 20), t = random_bytes(32 * 100, 21);
  const dyncull::BinaryDescriptors Q{q.data(), 100, 32}, T{t.data(), 100, 32};
  dyncull::MatchOptions ratio;
  ratio.ratio = 0.8;
  const auto r_ratio = dyncull::match_hamming256(Q, T, ratio);
  EXPECT_GT(r_ratio.rejected_ratio, 80u);
  EXPECT_EQ(r_ratio.matches.size() + r_ratio.rejected_ratio, 100u);

  dyncull::MatchOptions cross;
  cross.cross_check = true;
  const auto r_cross = dyncull::match_hamming256(Q, T, cross);
  EXPECT_GT(r_cross.rejected_cross_check, 0u);
  for (const auto& m : r_cross.matches) {  // mutual: no query is nearer to m.train
    for (std::size_t i = 0; i < 100; ++i) {
      EXPECT_GE(naive_hamming(&q[32 * i], &t[32 * m.train]), static_cast<int>(m.distance));
    }
  }
  dyncull::MatchOptions near;
  near.max_distance = 50;  // ORB-SLAM's TH_LOW
  EXPECT_EQ(dyncull::match_hamming256(Q, T, near).rejected_distance, 100u);
}

TEST(MatchHamming, StridedRowsAndBadInput) {
  // 48-byte rows with the descriptor in the first 32 (a cv::Mat ROI of a wider matrix).
  const auto s = planted_binary(40, 0, 30);
  std::vector<std::uint8_t> wide(48 * 40, 0xAA);
  for (std::size_t i = 0; i < 40; ++i) std::copy(&s.train[32 * i], &s.train[32 * i] + 32, &wide[48 * i]);
  const auto r = dyncull::match_hamming256({s.query.data(), 40, 32}, {wide.data(), 40, 48});
  ASSERT_TRUE(r.ok());
  for (const auto& m : r.matches) EXPECT_EQ(m.train, s.truth[m.query]);

  EXPECT_EQ(dyncull::match_hamming256({nullptr, 5, 32}, {wide.data(), 40, 48}).status, Status::InvalidInput);
  EXPECT_EQ(dyncull::match_hamming256({wide.data(), 5, 16}, {wide.data(), 40, 48}).status, Status::InvalidInput);
  dyncull::MatchOptions bad;
  bad.ratio = 1.5;
  EXPECT_EQ(dyncull::match_hamming256({wide.data(), 5, 48}, {wide.data(), 5, 48}, bad).status, Status::InvalidInput);
  const auto empty_train = dyncull::match_hamming256({wide.data(), 5, 48}, {nullptr, 0, 32});
  EXPECT_TRUE(empty_train.ok());
  EXPECT_TRUE(empty_train.matches.empty());
}

#ifdef DYNCULL_HAS_OPENCV
TEST(MatchHamming, AgreesWithOpenCvBfMatcher) {
  const auto s = planted_binary(300, 300, 40);
  const cv::Mat Q(300, 32, CV_8UC1, const_cast<std::uint8_t*>(s.query.data()));
  const cv::Mat T(600, 32, CV_8UC1, const_cast<std::uint8_t*>(s.train.data()));
  std::vector<cv::DMatch> cv_matches;
  cv::BFMatcher(cv::NORM_HAMMING, true).match(Q, T, cv_matches);
  dyncull::MatchOptions cross;
  cross.cross_check = true;
  const auto r = dyncull::match_hamming256({Q.ptr<std::uint8_t>(0), 300, Q.step}, {T.ptr<std::uint8_t>(0), 600, T.step}, cross);
  ASSERT_EQ(r.matches.size(), cv_matches.size());
  for (std::size_t k = 0; k < r.matches.size(); ++k) {
    EXPECT_EQ(static_cast<int>(r.matches[k].query), cv_matches[k].queryIdx);
    EXPECT_EQ(r.matches[k].distance, cv_matches[k].distance);
  }
}
#endif

template <class T>
class MatchL2Test : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(MatchL2Test, Scalars, );

template <class T>
std::vector<T> random_floats(std::size_t n, std::uint64_t seed) {
  dyncull::Random rng(seed);
  std::vector<T> v(n);
  for (auto& x : v) x = static_cast<T>(rng.normal());
  return v;
}

TYPED_TEST(MatchL2Test, AgreesWithNaiveBruteForce) {
  using T = TypeParam;
  const int dim = 256;
  const std::size_t nq = 130, nt = 170;  // not multiples of the 64-row block
  auto q = random_floats<T>(nq * dim, 1);
  auto t = random_floats<T>(nt * dim, 2);
  // Plant: query i is train row 3i + 1 plus small noise.
  for (std::size_t i = 0; i < nq / 3; ++i) {
    for (int d = 0; d < dim; ++d) t[(3 * i + 1) * dim + d] = q[i * dim + d] + T(0.05) * T(std::sin(double(d + i)));
  }
  const dyncull::FloatDescriptors<T> Q{q.data(), nq, dim, 0}, R{t.data(), nt, dim, 0};
  const auto r = dyncull::match_l2(Q, R);
  ASSERT_TRUE(r.ok()) << r.reason;
  ASSERT_EQ(r.matches.size(), nq);
  for (const auto& m : r.matches) {
    double best = 1e300;
    std::size_t best_j = 0;
    for (std::size_t j = 0; j < nt; ++j) {
      double s = 0;
      for (int d = 0; d < dim; ++d) {
        const double diff = double(q[m.query * dim + d]) - double(t[j * dim + d]);
        s += diff * diff;
      }
      if (s < best) {
        best = s;
        best_j = j;
      }
    }
    EXPECT_EQ(m.train, best_j);
    // |q|^2 ~ 256: the expanded form loses ~eps * 256 in the squared distance; the reported distance
    // is a float (as cv::DMatch), so double runs agree to float precision.
    EXPECT_NEAR(m.distance, std::sqrt(best), sizeof(T) == 4 ? 2e-2 : 1e-6);
    if (m.query < nq / 3) {
      EXPECT_EQ(m.train, 3 * m.query + 1);
    }
  }
  EXPECT_NEAR(dyncull::l2_distance(&q[0], &t[dim], dim), r.matches[0].distance, sizeof(T) == 4 ? 2e-2 : 1e-6);
}

TYPED_TEST(MatchL2Test, RatioCrossCheckStrideAndBadInput) {
  using T = TypeParam;
  const int dim = 32;
  auto q = random_floats<T>(50 * dim, 3);
  // Train rows padded to 40 elements: stride 40.
  std::vector<T> t(60 * 40, T(1e6));
  const auto raw = random_floats<T>(60 * dim, 4);
  for (int i = 0; i < 60; ++i) std::copy(&raw[i * dim], &raw[i * dim] + dim, &t[i * 40]);
  for (int i = 0; i < 20; ++i) std::copy(&q[i * dim], &q[i * dim] + dim, &t[(2 * i) * 40]);  // exact copies
  const dyncull::FloatDescriptors<T> Q{q.data(), 50, dim, 0}, R{t.data(), 60, dim, 40};
  dyncull::MatchOptions o;
  o.ratio = 0.6;
  o.cross_check = true;
  const auto r = dyncull::match_l2(Q, R, o);
  ASSERT_TRUE(r.ok()) << r.reason;
  std::size_t exact = 0;
  for (const auto& m : r.matches) {
    if (m.query < 20) {
      EXPECT_EQ(m.train, 2 * m.query);
      EXPECT_NEAR(m.distance, 0.f, 1e-2f);
      ++exact;
    }
  }
  EXPECT_EQ(exact, 20u);  // copies survive ratio and cross-check
  EXPECT_GT(r.rejected_ratio + r.rejected_cross_check, 15u);  // random pairs mostly do not

  EXPECT_EQ(dyncull::match_l2(Q, dyncull::FloatDescriptors<T>{t.data(), 60, 16, 40}).status, Status::InvalidInput);
  EXPECT_EQ(dyncull::match_l2(Q, dyncull::FloatDescriptors<T>{t.data(), 60, dim, 8}).status, Status::InvalidInput);
  EXPECT_EQ(dyncull::match_l2(dyncull::FloatDescriptors<T>{nullptr, 3, dim, 0}, R).status, Status::InvalidInput);
  const auto none = dyncull::match_l2(Q, dyncull::FloatDescriptors<T>{nullptr, 0, dim, 0});
  EXPECT_TRUE(none.ok());
  EXPECT_TRUE(none.matches.empty());
}

TYPED_TEST(MatchL2Test, NonFiniteDescriptorsNeverMatch) {
  using T = TypeParam;
  const int dim = 16;
  const std::size_t nq = 6, nt = 9;
  auto q = random_floats<T>(nq * dim, 11);
  auto t = random_floats<T>(nt * dim, 12);
  for (int d = 0; d < dim; ++d) t[4 * dim + d] = q[1 * dim + d];  // train 4 is an exact copy of query 1
  const T nan = std::numeric_limits<T>::quiet_NaN(), inf = std::numeric_limits<T>::infinity();
  t[2 * dim + 3] = nan;  // one NaN in train row 2
  t[6 * dim + 0] = inf;  // one Inf in train row 6
  q[3 * dim + 7] = nan;  // query 3 has a NaN
  q[5 * dim + 1] = -inf;  // query 5 has an Inf
  const dyncull::FloatDescriptors<T> Q{q.data(), nq, dim, 0}, R{t.data(), nt, dim, 0};
  for (bool cross : {false, true}) {
    dyncull::MatchOptions o;
    o.ratio = 0.9;
    o.cross_check = cross;
    const auto r = dyncull::match_l2(Q, R, o);
    ASSERT_TRUE(r.ok()) << r.reason;
    bool found_copy = false;
    for (const auto& m : r.matches) {
      EXPECT_NE(m.train, 2u) << "a NaN train row matched query " << m.query;
      EXPECT_NE(m.train, 6u) << "an Inf train row matched query " << m.query;
      EXPECT_NE(m.query, 3u) << "a NaN query matched train " << m.train;
      EXPECT_NE(m.query, 5u) << "an Inf query matched train " << m.train;
      EXPECT_TRUE(std::isfinite(m.distance));
      found_copy |= m.query == 1 && m.train == 4;
    }
    EXPECT_TRUE(found_copy);
    EXPECT_EQ(r.rejected_non_finite, 2u);  // the two corrupt queries have no finite distance at all
  }
  // Every train row corrupt: nothing matches.
  for (std::size_t j = 0; j < nt; ++j) t[j * dim] = nan;
  const auto none = dyncull::match_l2(Q, R);
  ASSERT_TRUE(none.ok()) << none.reason;
  EXPECT_TRUE(none.matches.empty());
  EXPECT_EQ(none.rejected_non_finite, nq);
}

// A value for property tests: mostly normal, sometimes NaN, +-Inf, huge or tiny.
template <class T>
T wild_value(dyncull::Random& rng) {
  const double u = rng.uniform();
  if (u < 0.02) return std::numeric_limits<T>::quiet_NaN();
  if (u < 0.03) return std::numeric_limits<T>::infinity();
  if (u < 0.04) return -std::numeric_limits<T>::infinity();
  if (u < 0.05) return std::numeric_limits<T>::max() * T(rng.uniform(-1, 1));
  if (u < 0.06) return T(rng.normal() * 1e18);
  if (u < 0.07) return std::numeric_limits<T>::denorm_min();
  return T(rng.normal());
}

TYPED_TEST(MatchL2Test, PropertyEveryMatchIsFiniteOrTheCallFails) {
  using T = TypeParam;
  dyncull::Random rng(2024);
  for (int trial = 0; trial < 300; ++trial) {
    // Sizes around the 64-query block and Eigen's packet widths.
    const std::size_t nq = rng.index(140), nt = rng.index(140);
    const int dim = 1 + static_cast<int>(rng.index(20));
    const bool sparse = rng.uniform() < 0.5;  // half the trials have no corrupt value at all
    std::vector<T> q(nq * static_cast<std::size_t>(dim)), t(nt * static_cast<std::size_t>(dim));
    for (auto& v : q) v = sparse ? T(rng.normal()) : wild_value<T>(rng);
    for (auto& v : t) v = sparse ? T(rng.normal()) : wild_value<T>(rng);
    dyncull::MatchOptions o;
    const double pick = rng.uniform();
    o.ratio = pick < 0.1 ? std::nan("") : pick < 0.2 ? rng.uniform(-2, 3) : rng.uniform(0, 1);
    o.cross_check = rng.uniform() < 0.5;
    const double md = rng.uniform();
    o.max_distance = md < 0.1 ? std::nan("") : md < 0.2 ? -1.0 : md < 0.6 ? rng.uniform(0, 10) : o.max_distance;
    const dyncull::FloatDescriptors<T> Q{q.data(), nq, dim, 0}, R{t.data(), nt, dim, 0};
    const auto r = dyncull::match_l2(Q, R, o);
    if (!r.ok()) {
      EXPECT_EQ(r.status, Status::InvalidInput);
      EXPECT_FALSE(r.reason.empty());
      EXPECT_NE(o.validate(), Status::Ok);
      continue;
    }
    EXPECT_EQ(o.validate(), Status::Ok);
    auto row_finite = [dim](const std::vector<T>& v, std::size_t i) {
      for (int d = 0; d < dim; ++d) {
        if (!std::isfinite(v[i * static_cast<std::size_t>(dim) + static_cast<std::size_t>(d)])) return false;
      }
      return true;
    };
    std::size_t previous = 0;
    for (std::size_t k = 0; k < r.matches.size(); ++k) {
      const auto& m = r.matches[k];
      ASSERT_LT(m.query, nq);
      ASSERT_LT(m.train, nt);
      if (k > 0) {
        EXPECT_GT(m.query, previous);
      }
      previous = m.query;
      EXPECT_TRUE(std::isfinite(m.distance));
      EXPECT_TRUE(row_finite(q, m.query)) << "trial " << trial;
      EXPECT_TRUE(row_finite(t, m.train)) << "trial " << trial;
    }
    if (nt > 0) {
      EXPECT_EQ(r.matches.size() + r.rejected_distance + r.rejected_ratio + r.rejected_cross_check +
                    r.rejected_non_finite,
                nq);
    }
  }
}

TEST(DescriptorSwitch, OptionsAreValidated) {
  std::string why;
  dyncull::DescriptorSwitchOptions s;
  EXPECT_EQ(s.validate(&why), Status::Ok);
  EXPECT_TRUE(why.empty());
  for (double bad : {-1.0, 181.0, std::nan(""), HUGE_VAL}) {
    s.switch_angle_deg = bad;
    EXPECT_EQ(s.validate(&why), Status::InvalidInput);
    EXPECT_NE(why.find("switch_angle_deg"), std::string::npos);
    EXPECT_EQ(dyncull::choose_descriptor(90.0, s), DescriptorKind::Learned);
  }
  dyncull::MatchOptions m;
  EXPECT_EQ(m.validate(&why), Status::Ok);
  m.max_distance = std::nan("");
  EXPECT_EQ(m.validate(&why), Status::InvalidInput);
  EXPECT_NE(why.find("max_distance"), std::string::npos);
  const std::vector<std::uint8_t> bytes(64, 0);
  const dyncull::BinaryDescriptors b{bytes.data(), 2, 32};
  const auto r = dyncull::match_hamming256(b, b, m);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.reason.find("max_distance"), std::string::npos);
  m.max_distance = 1;
  m.ratio = 2;
  EXPECT_EQ(m.validate(&why), Status::InvalidInput);
  EXPECT_NE(why.find("ratio"), std::string::npos);
}

TYPED_TEST(MatchL2Test, NearestKeyframesEquationEighteen) {
  using T = TypeParam;
  const int dim = 4096;
  const std::size_t n = 40;
  auto lib = random_floats<T>(n * dim, 5);
  std::vector<T> query(lib.begin() + 17 * dim, lib.begin() + 18 * dim);  // keyframe 17 revisited
  for (int d = 0; d < dim; d += 7) query[d] += T(0.1);
  lib[3 * dim + 5] = std::numeric_limits<T>::quiet_NaN();  // a corrupt keyframe is skipped
  const dyncull::FloatDescriptors<T> L{lib.data(), n, dim, 0};
  const auto r = dyncull::nearest_keyframes(query.data(), L, 5);
  ASSERT_TRUE(r.ok()) << r.reason;
  ASSERT_EQ(r.candidates.size(), 5u);
  EXPECT_EQ(r.candidates[0].index, 17u);
  // Oracle: sort all finite distances.
  std::vector<std::pair<double, std::size_t>> all;
  for (std::size_t i = 0; i < n; ++i) {
    double s = 0;
    for (int d = 0; d < dim; ++d) s += std::pow(double(query[d]) - double(lib[i * dim + d]), 2);
    if (std::isfinite(s)) all.emplace_back(std::sqrt(s), i);
  }
  std::sort(all.begin(), all.end());
  for (std::size_t k = 0; k < 5; ++k) {
    EXPECT_EQ(r.candidates[k].index, all[k].second);
    EXPECT_NEAR(r.candidates[k].distance, all[k].first, sizeof(T) == 4 ? 1e-2 : 1e-9);
    EXPECT_NE(r.candidates[k].index, 3u);
  }
  EXPECT_EQ(dyncull::nearest_keyframes(query.data(), L, 100).candidates.size(), n - 1);
  EXPECT_EQ(dyncull::nearest_keyframes(query.data(), dyncull::FloatDescriptors<T>{lib.data(), 0, dim, 0}, 5).status,
            Status::TooFewPoints);
  EXPECT_EQ(dyncull::nearest_keyframes<T>(nullptr, L, 5).status, Status::InvalidInput);
  query[0] = std::numeric_limits<T>::quiet_NaN();
  EXPECT_EQ(dyncull::nearest_keyframes(query.data(), L, 5).status, Status::NonFinite);
}

}  // namespace
