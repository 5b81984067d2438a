// Tests of culling/keyframe_matcher.hpp: guided Hamming matching of current keypoints to a keyframe on
// synthetic views with known motion (depth + pose, rotation only, no pose), the ratio, distance and
// mutual tests, bad inputs (NaN keypoints, empty sets, mismatched sizes, missing depth, bad options,
// non-finite pose) with defined results and reasons, no allocation after warm-up, a property test
// against a brute-force oracle on random input, and keypoints clustered in a few pixels matched in work
// linear in the keypoints.
#include "dyncull/culling/keyframe_matcher.hpp"

#include "dyncull/core/random.hpp"
#include "dyncull/core/compact.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <bitset>
#include <ctime>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <new>
#include <numeric>
#include <string>
#include <vector>

// Counting global allocator: the "no allocation after warm-up" test reads the counter. g++ flags
// free() on memory from operator new once both are inlined, though here both sides are malloc / free.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif
namespace {
std::atomic<long> g_allocations{0};
}
void* operator new(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace {

using dyncull::DescriptorRows;
using dyncull::KeyframeMatchOptions;
using dyncull::KeyframeMatchResult;
using dyncull::KeyframeMatchWorkspace;
using dyncull::Status;
using dyncull::Vec2;
using dyncull::Vec3;

int naive_hamming(const std::uint8_t* a, const std::uint8_t* b, std::size_t bytes) {
  int d = 0;
  for (std::size_t i = 0; i < bytes; ++i) d += static_cast<int>(std::bitset<8>(static_cast<unsigned>(a[i] ^ b[i])).count());
  return d;
}

template <class T>
dyncull::Rigid3<T> pose_from(double rx, double ry, double rz, double tx, double ty, double tz) {
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(rz, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(ry, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(rx, Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  dyncull::Rigid3<T> p;
  p.R = R.cast<T>();
  p.t = Eigen::Vector3d(tx, ty, tz).cast<T>();
  return p;
}

/// A keyframe of n points with depth and random 32-byte descriptors, and a current view after a known
/// motion: current keypoint j is keyframe point truth[j] (projection + noise, a few descriptor bits
/// flipped), in shuffled order; points leaving the image are dropped and `distractors` random keypoints
/// with random descriptors are added (truth -1).
template <class T>
struct TwoViews {
  dyncull::PinholeCamera<T> camera = dyncull::PinholeCamera<T>::tum_fr3();
  std::vector<Vec2<T>> kf_kp, cur_kp;
  std::vector<Vec3<T>> kf_pts;
  std::vector<std::uint8_t> kf_desc, cur_desc;
  std::vector<int> truth;
  dyncull::Rigid3<T> cam_from_kf;

  TwoViews(std::size_t n, const dyncull::Rigid3<T>& motion, std::uint64_t seed, double noise_px = 0.5,
           int flipped_bits = 6, std::size_t distractors = 50) {
    cam_from_kf = motion;
    dyncull::Random rng(seed);
    while (kf_kp.size() < n) {
      const Vec2<T> uv(T(rng.uniform(5, 634)), T(rng.uniform(5, 474)));
      const T z = T(rng.uniform(1.0, 5.0));
      kf_kp.push_back(uv);
      kf_pts.push_back(camera.backproject(uv, z));
    }
    kf_desc.resize(32 * n);
    for (auto& b : kf_desc) b = static_cast<std::uint8_t>(rng.next() >> 56);
    std::vector<int> order;
    std::vector<Vec2<T>> kp;
    for (std::size_t k = 0; k < n; ++k) {
      const Vec3<T> Xc = motion.apply(kf_pts[k]);
      if (Xc.z() <= T(0)) continue;
      const Vec2<T> p = camera.project(Xc) + Vec2<T>(T(noise_px * rng.normal()), T(noise_px * rng.normal()));
      if (!camera.in_image(p.x(), p.y())) continue;
      order.push_back(static_cast<int>(k));
      kp.push_back(p);
    }
    for (std::size_t d = 0; d < distractors; ++d) {
      order.push_back(-1);
      kp.push_back(Vec2<T>(T(rng.uniform(0, 639)), T(rng.uniform(0, 479))));
    }
    std::vector<std::size_t> perm(order.size());
    std::iota(perm.begin(), perm.end(), std::size_t{0});
    for (std::size_t i = perm.size(); i > 1; --i) std::swap(perm[i - 1], perm[rng.index(static_cast<std::uint32_t>(i))]);
    cur_desc.resize(32 * perm.size());
    for (std::size_t j = 0; j < perm.size(); ++j) {
      const int k = order[perm[j]];
      truth.push_back(k);
      cur_kp.push_back(kp[perm[j]]);
      std::uint8_t* row = &cur_desc[32 * j];
      if (k >= 0) {
        std::copy(&kf_desc[32 * std::size_t(k)], &kf_desc[32 * std::size_t(k)] + 32, row);
        for (int f = 0; f < flipped_bits; ++f) row[rng.index(32)] ^= static_cast<std::uint8_t>(1u << rng.index(8));
      } else {
        for (int b = 0; b < 32; ++b) row[b] = static_cast<std::uint8_t>(rng.next() >> 56);
      }
    }
  }
  DescriptorRows kf_rows() const { return DescriptorRows(kf_desc.data(), kf_kp.size()); }
  DescriptorRows cur_rows() const { return DescriptorRows(cur_desc.data(), cur_kp.size()); }

  KeyframeMatchResult<T> match(const std::vector<Vec3<T>>& pts, const dyncull::Rigid3<T>* pose,
                               const KeyframeMatchOptions& o = {}) const {
    return dyncull::match_to_keyframe(kf_kp, pts, kf_rows(), cur_kp, cur_rows(), camera, pose, o);
  }
  std::size_t matchable() const { return static_cast<std::size_t>(std::count_if(truth.begin(), truth.end(), [](int k) { return k >= 0; })); }
  /// (correct, wrong) matches of a result.
  std::pair<std::size_t, std::size_t> score(const KeyframeMatchResult<T>& r) const {
    std::size_t good = 0, bad = 0;
    for (std::size_t j = 0; j < truth.size(); ++j) {
      if (r.keyframe_index[j] < 0) continue;
      (r.keyframe_index[j] == truth[j] ? good : bad)++;
    }
    return {good, bad};
  }
};

template <class T>
class KeyframeMatcherTyped : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(KeyframeMatcherTyped, Scalars, );

template <class T>
void expect_unmatched(const KeyframeMatchResult<T>& r, std::size_t n) {
  ASSERT_EQ(r.keyframe_index.size(), n);
  ASSERT_EQ(r.keyframe_pixel.size(), n);
  ASSERT_EQ(r.distance.size(), n);
  EXPECT_EQ(r.matched, 0u);
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_EQ(r.keyframe_index[i], -1);
    EXPECT_EQ(r.distance[i], -1);
    EXPECT_TRUE(std::isnan(r.keyframe_pixel[i].x()));
  }
}

TYPED_TEST(KeyframeMatcherTyped, KnownMotionWithDepthIsMatchedThroughThePose) {
  using T = TypeParam;
  // 10 cm sideways and 4 degrees of pan: pixel shifts of 30-60 px, beyond the 15 px radius around the
  // same pixel, so only the pose prediction finds them.
  const TwoViews<T> v(1000, pose_from<T>(0.0, 0.07, 0.0, 0.1, 0.0, 0.03), 11);
  const auto r = v.match(v.kf_pts, &v.cam_from_kf);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_TRUE(r.used_pose);
  EXPECT_EQ(r.predicted_by_depth, 1000u);
  const auto s = v.score(r);
  // 6 of 256 bits flipped vs random descriptors (~128 bits apart): every true pair should pass; the
  // ratio and mutual tests drop a pair only when two keypoints of the same point are close.
  EXPECT_GE(double(s.first), 0.98 * double(v.matchable()));
  EXPECT_EQ(s.second, 0u);
  EXPECT_EQ(r.matched, s.first + s.second);
  for (std::size_t j = 0; j < v.truth.size(); ++j) {
    if (r.keyframe_index[j] < 0) continue;
    const std::size_t k = static_cast<std::size_t>(r.keyframe_index[j]);
    EXPECT_EQ(r.keyframe_pixel[j], v.kf_kp[k]);
    EXPECT_EQ(r.distance[j], naive_hamming(&v.kf_desc[32 * k], &v.cur_desc[32 * j], 32));
  }
  // The same pixel without a pose finds few of them: the motion is beyond a 15 px search.
  KeyframeMatchOptions narrow;
  narrow.radius_unpredicted_px = 15;
  const auto blind = v.match(v.kf_pts, nullptr, narrow);
  ASSERT_TRUE(blind.ok());
  EXPECT_FALSE(blind.used_pose);
  EXPECT_LT(double(v.score(blind).first), 0.3 * double(v.matchable()));
}

TYPED_TEST(KeyframeMatcherTyped, WithoutAPoseTheSamePixelIsSearched) {
  using T = TypeParam;
  const TwoViews<T> v(800, pose_from<T>(0.0, 0.01, 0.0, 0.02, 0.0, 0.0), 12);  // shifts of ~5-15 px
  const auto r = v.match({}, nullptr);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.predicted_without_depth, 800u);
  EXPECT_EQ(r.predicted_by_depth, 0u);
  const auto s = v.score(r);
  EXPECT_GE(double(s.first), 0.97 * double(v.matchable()));
  EXPECT_LE(s.second, 2u);
}

TYPED_TEST(KeyframeMatcherTyped, WithoutDepthThePoseRotatesTheRays) {
  using T = TypeParam;
  // 5 degrees of pan (~47 px) and 1 cm of translation: the rotated ray lands within a few px.
  const TwoViews<T> v(800, pose_from<T>(0.0, 0.087, 0.0, 0.01, 0.0, 0.0), 13);
  KeyframeMatchOptions o;
  o.radius_unpredicted_px = 15;
  const auto with_pose = v.match({}, &v.cam_from_kf, o);
  ASSERT_TRUE(with_pose.ok()) << with_pose.reason;
  EXPECT_EQ(with_pose.predicted_without_depth, 800u);
  EXPECT_GE(double(v.score(with_pose).first), 0.97 * double(v.matchable()));
  EXPECT_EQ(v.score(with_pose).second, 0u);
  const auto without_pose = v.match({}, nullptr, o);
  EXPECT_LT(double(v.score(without_pose).first), 0.2 * double(v.matchable()));
}

TYPED_TEST(KeyframeMatcherTyped, MissingDepthFallsBackPerPoint) {
  using T = TypeParam;
  const TwoViews<T> v(600, pose_from<T>(0.0, 0.03, 0.0, 0.02, 0.0, 0.0), 14);
  std::vector<Vec3<T>> pts = v.kf_pts;
  const T nan = std::numeric_limits<T>::quiet_NaN();
  for (std::size_t k = 0; k < pts.size(); k += 2) pts[k] = Vec3<T>(nan, nan, nan);  // no depth
  pts[1].z() = T(0);                                                                 // no depth either
  pts[3].z() = T(-1);
  const auto r = v.match(pts, &v.cam_from_kf);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.predicted_by_depth + r.predicted_without_depth, 600u);
  EXPECT_EQ(r.predicted_without_depth, 302u);
  EXPECT_GE(double(v.score(r).first), 0.97 * double(v.matchable()));
  EXPECT_EQ(v.score(r).second, 0u);
}

TYPED_TEST(KeyframeMatcherTyped, NanKeypointsAreNeverMatched) {
  using T = TypeParam;
  TwoViews<T> v(300, pose_from<T>(0.0, 0.0, 0.0, 0.01, 0.0, 0.0), 15);
  const T nan = std::numeric_limits<T>::quiet_NaN(), inf = std::numeric_limits<T>::infinity();
  v.cur_kp[0].x() = nan;
  v.cur_kp[1].y() = inf;
  v.cur_kp[2] = Vec2<T>(-inf, nan);
  v.kf_kp[0].x() = nan;
  v.kf_kp[1].y() = -inf;
  const auto r = v.match(v.kf_pts, &v.cam_from_kf);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.current_nonfinite, 3u);
  EXPECT_EQ(r.keyframe_nonfinite, 2u);
  for (int j = 0; j < 3; ++j) EXPECT_EQ(r.keyframe_index[std::size_t(j)], -1);
  for (std::size_t j = 0; j < v.truth.size(); ++j) {
    EXPECT_NE(r.keyframe_index[j], 0);
    EXPECT_NE(r.keyframe_index[j], 1);
  }
  EXPECT_GE(double(v.score(r).first), 0.95 * double(v.matchable() - 5));
  // All current keypoints non-finite: Ok, nothing matched.
  std::vector<Vec2<T>> all_nan(v.cur_kp.size(), Vec2<T>(nan, nan));
  const auto none = dyncull::match_to_keyframe(v.kf_kp, v.kf_pts, v.kf_rows(), all_nan, v.cur_rows(), v.camera,
                                               &v.cam_from_kf, KeyframeMatchOptions{});
  EXPECT_TRUE(none.ok()) << none.reason;
  expect_unmatched(none, all_nan.size());
}

TYPED_TEST(KeyframeMatcherTyped, HugeCoordinatesReadNothingOutOfRange) {
  using T = TypeParam;
  TwoViews<T> v(200, pose_from<T>(0.0, 0.0, 0.0, 0.01, 0.0, 0.0), 16);
  const T big = std::numeric_limits<T>::max();
  v.cur_kp[0] = Vec2<T>(big, -big);
  v.cur_kp[1] = Vec2<T>(T(4294967306.0), T(1e30));
  v.cur_kp[2] = Vec2<T>(-big, big);
  v.kf_kp[0] = Vec2<T>(big, big);
  v.kf_pts[5] = Vec3<T>(big, -big, big);
  v.kf_pts[6] = Vec3<T>(T(1), T(1), std::numeric_limits<T>::denorm_min());
  const dyncull::Rigid3<T>* poses[] = {nullptr, &v.cam_from_kf};
  for (const auto* pose : poses) {
    const auto r = v.match(v.kf_pts, pose);
    ASSERT_TRUE(r.ok()) << r.reason;
    ASSERT_EQ(r.keyframe_index.size(), v.cur_kp.size());
    for (int idx : r.keyframe_index) EXPECT_TRUE(idx >= -1 && idx < int(v.kf_kp.size()));
  }
  // The spread of the keypoints widens the grid's cells; the other keypoints are still matched.
  const auto r = v.match(v.kf_pts, &v.cam_from_kf);
  EXPECT_GE(double(v.score(r).first), 0.9 * double(v.matchable()));
}

TYPED_TEST(KeyframeMatcherTyped, EmptySetsAreTooFewPoints) {
  using T = TypeParam;
  const TwoViews<T> v(50, pose_from<T>(0, 0, 0, 0, 0, 0), 17, 0.5, 6, 0);
  const std::vector<Vec2<T>> none2;
  const std::vector<Vec3<T>> none3;
  auto r = dyncull::match_to_keyframe(none2, none3, DescriptorRows(), v.cur_kp, v.cur_rows(), v.camera,
                                      &v.cam_from_kf, KeyframeMatchOptions{});
  EXPECT_EQ(r.status, Status::TooFewPoints);
  EXPECT_NE(r.reason.find("keyframe"), std::string::npos) << r.reason;
  expect_unmatched(r, v.cur_kp.size());
  r = dyncull::match_to_keyframe(v.kf_kp, v.kf_pts, v.kf_rows(), none2, DescriptorRows(), v.camera, &v.cam_from_kf,
                                 KeyframeMatchOptions{});
  EXPECT_EQ(r.status, Status::TooFewPoints);
  EXPECT_NE(r.reason.find("current"), std::string::npos) << r.reason;
  expect_unmatched(r, 0);
}

TYPED_TEST(KeyframeMatcherTyped, MismatchedSizesNameTheInput) {
  using T = TypeParam;
  const TwoViews<T> v(100, pose_from<T>(0, 0, 0, 0.01, 0, 0), 18);
  const std::size_t n = v.cur_kp.size(), n_kf = v.kf_kp.size();
  auto expect_invalid = [&](const KeyframeMatchResult<T>& r, const char* name) {
    EXPECT_EQ(r.status, Status::InvalidInput);
    EXPECT_NE(r.reason.find(name), std::string::npos) << r.reason;
    expect_unmatched(r, n);
  };
  std::vector<Vec3<T>> short_pts(v.kf_pts.begin(), v.kf_pts.end() - 1);
  expect_invalid(v.match(short_pts, &v.cam_from_kf), "kf_points");
  auto call = [&](DescriptorRows kf, DescriptorRows cur) {
    return dyncull::match_to_keyframe(v.kf_kp, v.kf_pts, kf, v.cur_kp, cur, v.camera, &v.cam_from_kf,
                                      KeyframeMatchOptions{});
  };
  expect_invalid(call(DescriptorRows(v.kf_desc.data(), n_kf - 1), v.cur_rows()), "kf_desc");
  expect_invalid(call(v.kf_rows(), DescriptorRows(v.cur_desc.data(), n + 1)), "cur_desc");
  expect_invalid(call(DescriptorRows(nullptr, n_kf), v.cur_rows()), "kf_desc");
  expect_invalid(call(v.kf_rows(), DescriptorRows(v.cur_desc.data(), n, 16, 32)), "cur_desc");  // overlapping rows
  expect_invalid(call(v.kf_rows(), DescriptorRows(v.cur_desc.data(), n, 0, 0)), "cur_desc");
  expect_invalid(call(DescriptorRows(v.kf_desc.data(), n_kf / 2, 64, 32), v.cur_rows()), "kf_desc");
  // Different descriptor lengths cannot be compared.
  std::vector<std::uint8_t> wide(64 * n_kf, 0);
  expect_invalid(call(DescriptorRows(wide.data(), n_kf, 64, 64), v.cur_rows()), "row");
}

TYPED_TEST(KeyframeMatcherTyped, BadOptionsCameraAndPoseAreReported) {
  using T = TypeParam;
  const TwoViews<T> v(100, pose_from<T>(0, 0, 0, 0.01, 0, 0), 19);
  const std::size_t n = v.cur_kp.size();
  struct Case {
    const char* field;
    void (*set)(KeyframeMatchOptions&);
  };
  const Case cases[] = {
      {"radius_px", [](KeyframeMatchOptions& o) { o.radius_px = 0; }},
      {"radius_px", [](KeyframeMatchOptions& o) { o.radius_px = std::nan(""); }},
      {"radius_px", [](KeyframeMatchOptions& o) { o.radius_px = 1e9; }},
      {"radius_unpredicted_px", [](KeyframeMatchOptions& o) { o.radius_unpredicted_px = -3; }},
      {"radius_unpredicted_px", [](KeyframeMatchOptions& o) { o.radius_unpredicted_px = INFINITY; }},
      {"max_hamming", [](KeyframeMatchOptions& o) { o.max_hamming = -1; }},
      {"max_hamming", [](KeyframeMatchOptions& o) { o.max_hamming = 257; }},  // beyond 256 bits of ORB
      {"ratio", [](KeyframeMatchOptions& o) { o.ratio = 0; }},
      {"ratio", [](KeyframeMatchOptions& o) { o.ratio = 1.5; }},
      {"ratio", [](KeyframeMatchOptions& o) { o.ratio = std::nan(""); }},
      {"max_candidates", [](KeyframeMatchOptions& o) { o.max_candidates = 0; }},
      {"max_candidates", [](KeyframeMatchOptions& o) { o.max_candidates = std::size_t(1) << 21; }},
  };
  for (const Case& c : cases) {
    KeyframeMatchOptions o;
    c.set(o);
    const auto r = v.match(v.kf_pts, &v.cam_from_kf, o);
    EXPECT_EQ(r.status, Status::InvalidInput) << c.field;
    EXPECT_NE(r.reason.find(c.field), std::string::npos) << r.reason;
    expect_unmatched(r, n);
  }
  EXPECT_EQ(KeyframeMatchOptions{}.validate(), Status::Ok);

  dyncull::PinholeCamera<T> bad = v.camera;
  bad.fx = T(0);
  auto r = dyncull::match_to_keyframe(v.kf_kp, v.kf_pts, v.kf_rows(), v.cur_kp, v.cur_rows(), bad, &v.cam_from_kf,
                                      KeyframeMatchOptions{});
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.reason.find("camera"), std::string::npos) << r.reason;
  expect_unmatched(r, n);

  dyncull::Rigid3<T> nan_pose = v.cam_from_kf;
  nan_pose.t.x() = std::numeric_limits<T>::quiet_NaN();
  r = v.match(v.kf_pts, &nan_pose);
  EXPECT_EQ(r.status, Status::NonFinite);
  EXPECT_NE(r.reason.find("cam_from_keyframe"), std::string::npos) << r.reason;
  expect_unmatched(r, n);
}

TYPED_TEST(KeyframeMatcherTyped, PointsBehindTheCameraAreNotSearched) {
  using T = TypeParam;
  const TwoViews<T> v(200, pose_from<T>(0, 0, 0, 0.01, 0, 0), 20);
  const auto turned = pose_from<T>(0.0, 3.14159, 0.0, 0.0, 0.0, 0.0);  // facing backwards
  const auto r = v.match(v.kf_pts, &turned);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.behind_camera, 200u);
  EXPECT_EQ(r.matched, 0u);
}

/// Hand-made descriptors: row = 32 bytes of `fill` with the first `bits` bits of byte 0.. set differently.
std::vector<std::uint8_t> rows_at_distances(const std::vector<int>& bits_from_zero) {
  std::vector<std::uint8_t> d(32 * bits_from_zero.size(), 0);
  for (std::size_t i = 0; i < bits_from_zero.size(); ++i)
    for (int b = 0; b < bits_from_zero[i]; ++b) d[32 * i + std::size_t(b / 8)] |= static_cast<std::uint8_t>(1u << (b % 8));
  return d;
}

TEST(KeyframeMatcher, RatioAndDistanceTests) {
  const auto cam = dyncull::PinholeCamera<double>::tum_fr3();
  const std::vector<Vec2<double>> kf{{100, 100}};
  const std::vector<Vec3<double>> none;
  const auto kf_desc = rows_at_distances({0});
  // Two candidates at 11 and 12 bits: 11 <= 0.9 * 12 fails, ratio 1 accepts.
  std::vector<Vec2<double>> cur{{102, 100}, {98, 100}};
  auto cur_desc = rows_at_distances({11, 12});
  KeyframeMatchOptions o;
  auto r = dyncull::match_to_keyframe(kf, none, DescriptorRows(kf_desc.data(), 1), cur, DescriptorRows(cur_desc.data(), 2),
                                      cam, nullptr, o);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.matched, 0u);
  o.ratio = 1.0;
  r = dyncull::match_to_keyframe(kf, none, DescriptorRows(kf_desc.data(), 1), cur, DescriptorRows(cur_desc.data(), 2),
                                 cam, nullptr, o);
  EXPECT_EQ(r.matched, 1u);
  EXPECT_EQ(r.keyframe_index[0], 0);
  EXPECT_EQ(r.distance[0], 11);
  // Equal distances are ambiguous below ratio 1.
  cur_desc = rows_at_distances({10, 10});
  o.ratio = 0.99;
  r = dyncull::match_to_keyframe(kf, none, DescriptorRows(kf_desc.data(), 1), cur, DescriptorRows(cur_desc.data(), 2),
                                 cam, nullptr, o);
  EXPECT_EQ(r.matched, 0u);
  // A lone candidate passes the ratio test; max_hamming bounds it.
  cur = {{101, 101}};
  cur_desc = rows_at_distances({50});
  o = KeyframeMatchOptions{};
  o.max_hamming = 49;
  r = dyncull::match_to_keyframe(kf, none, DescriptorRows(kf_desc.data(), 1), cur, DescriptorRows(cur_desc.data(), 1),
                                 cam, nullptr, o);
  EXPECT_EQ(r.matched, 0u);
  o.max_hamming = 50;
  r = dyncull::match_to_keyframe(kf, none, DescriptorRows(kf_desc.data(), 1), cur, DescriptorRows(cur_desc.data(), 1),
                                 cam, nullptr, o);
  EXPECT_EQ(r.matched, 1u);
  // Outside the radius: not a candidate.
  cur = {{100 + 40.5, 100}};
  r = dyncull::match_to_keyframe(kf, none, DescriptorRows(kf_desc.data(), 1), cur, DescriptorRows(cur_desc.data(), 1),
                                 cam, nullptr, o);
  EXPECT_EQ(r.matched, 0u);
}

TEST(KeyframeMatcher, MutualCheckRejectsAKeypointAnotherPointPrefers) {
  // kf A (row 0 bits) and kf B (row of 40 bits) at the same pixel; current c0 at 10 bits from A,
  // 5 bits from B... arranged so that A's nearest is c0, c0's nearest is B, and B's nearest is c1.
  const auto cam = dyncull::PinholeCamera<double>::tum_fr3();
  const std::vector<Vec2<double>> kf{{200, 200}, {205, 200}};
  const std::vector<Vec3<double>> none;
  std::vector<std::uint8_t> kf_desc(64, 0), cur_desc(64, 0);
  // A = 0...; B = first 40 bits set. c0: first 30 bits set (A: 30, B: 10). c1: first 38 bits set (B: 2, A: 38).
  auto set_bits = [](std::uint8_t* row, int bits) {
    for (int b = 0; b < bits; ++b) row[b / 8] |= static_cast<std::uint8_t>(1u << (b % 8));
  };
  set_bits(&kf_desc[32], 40);
  set_bits(&cur_desc[0], 30);
  set_bits(&cur_desc[32], 38);
  const std::vector<Vec2<double>> cur{{201, 200}, {230, 200}};  // c1 is 25 px from B, 30 px from A
  KeyframeMatchOptions o;
  o.ratio = 1.0;
  o.radius_unpredicted_px = 27;  // A sees c0 only; B sees c0 and c1
  const auto r = dyncull::match_to_keyframe(kf, none, DescriptorRows(kf_desc.data(), 2), cur,
                                            DescriptorRows(cur_desc.data(), 2), cam, nullptr, o);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.keyframe_index[0], -1);  // A -> c0, but c0's nearest is B
  EXPECT_EQ(r.keyframe_index[1], 1);   // B <-> c1
}

TEST(KeyframeMatcher, RowsViewAndStridedRowsAreRead) {
  TwoViews<float> v(300, pose_from<float>(0, 0.02, 0, 0.01, 0, 0), 21);
  // The same descriptors in rows of 48 bytes (a cv::Mat ROI's step), through compact.hpp's RowsView.
  const std::size_t n = v.cur_kp.size();
  std::vector<std::uint8_t> strided(48 * n, 0xAB);
  for (std::size_t j = 0; j < n; ++j) std::copy(&v.cur_desc[32 * j], &v.cur_desc[32 * j] + 32, &strided[48 * j]);
  const dyncull::RowsView view{strided.data(), 32, 48, n};
  const auto a = v.match(v.kf_pts, &v.cam_from_kf);
  const auto b = dyncull::match_to_keyframe(v.kf_kp, v.kf_pts, v.kf_rows(), v.cur_kp, view, v.camera, &v.cam_from_kf,
                                            KeyframeMatchOptions{});
  ASSERT_TRUE(b.ok()) << b.reason;
  EXPECT_EQ(a.keyframe_index, b.keyframe_index);
  EXPECT_EQ(a.distance, b.distance);
}

TEST(KeyframeMatcher, NoAllocationAfterWarmUp) {
  const TwoViews<float> v(1000, pose_from<float>(0, 0.03, 0, 0.03, 0, 0), 22);
  const TwoViews<float> w(900, pose_from<float>(0, -0.02, 0, 0.01, 0, 0), 23);
  KeyframeMatchWorkspace<float> ws;
  KeyframeMatchResult<float> r;
  const KeyframeMatchOptions o;
  auto run = [&](const TwoViews<float>& x) {
    dyncull::match_to_keyframe(x.kf_kp, x.kf_pts, x.kf_rows(), x.cur_kp, x.cur_rows(), x.camera, &x.cam_from_kf, o, ws, &r);
  };
  run(v);
  run(w);
  const long before = g_allocations.load();
  for (int i = 0; i < 3; ++i) {
    run(w);
    run(v);
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_TRUE(r.ok());
  EXPECT_GT(r.matched, 900u);
}

/// n keyframe and n current keypoints inside a side x side pixel patch (no pose: every search disc holds
/// the whole patch), random descriptors: the worst case of a per-disc search.
struct ClusteredViews {
  dyncull::PinholeCamera<float> camera = dyncull::PinholeCamera<float>::tum_fr3();
  std::vector<Vec2<float>> kf_kp, cur_kp;
  std::vector<std::uint8_t> kf_desc, cur_desc;
  ClusteredViews(std::size_t n, double side, std::uint64_t seed) {
    dyncull::Random rng(seed);
    for (std::size_t i = 0; i < n; ++i) {
      kf_kp.emplace_back(float(300 + rng.uniform(0, side)), float(200 + rng.uniform(0, side)));
      cur_kp.emplace_back(float(300 + rng.uniform(0, side)), float(200 + rng.uniform(0, side)));
    }
    kf_desc.resize(32 * n);
    cur_desc.resize(32 * n);
    for (auto& b : kf_desc) b = static_cast<std::uint8_t>(rng.next() >> 56);
    for (auto& b : cur_desc) b = static_cast<std::uint8_t>(rng.next() >> 56);
  }
  void match(const KeyframeMatchOptions& o, KeyframeMatchWorkspace<float>& ws, KeyframeMatchResult<float>* r) const {
    const std::vector<Vec3<float>> no_depth;
    dyncull::match_to_keyframe(kf_kp, no_depth, DescriptorRows(kf_desc.data(), kf_kp.size()), cur_kp,
                               DescriptorRows(cur_desc.data(), cur_kp.size()), camera, nullptr, o, ws, r);
  }
};

// Generous: 0.1-0.4 s in a Release build; comparing every pair took 3-5 s (25 s under ASan + UBSan).
#if defined(__SANITIZE_ADDRESS__)
constexpr double kClusteredFrameSeconds = 15.0;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(undefined_behavior_sanitizer)
constexpr double kClusteredFrameSeconds = 15.0;
#else
constexpr double kClusteredFrameSeconds = 2.0;
#endif
#else
constexpr double kClusteredFrameSeconds = 2.0;
#endif

// 20,000 keypoints in a 20 px patch on both sides: each search examines at most max_candidates keypoints
// (an even subsample of its cells), so the work doubles with the keypoints instead of quadrupling, and the
// frame takes well under a second (every pair was compared before: 4e8 descriptor distances).
TEST(KeyframeMatcher, ClusteredKeypointsAreMatchedInLinearWork) {
  const KeyframeMatchOptions o;
  KeyframeMatchWorkspace<float> ws;
  KeyframeMatchResult<float> half, full;
  const ClusteredViews a(10000, 20.0, 41), b(20000, 20.0, 42);
  a.match(o, ws, &half);
  const std::clock_t t0 = std::clock();  // processor time: other processes on the machine do not count
  b.match(o, ws, &full);
  const double seconds = double(std::clock() - t0) / CLOCKS_PER_SEC;
  ASSERT_TRUE(half.ok()) << half.reason;
  ASSERT_TRUE(full.ok()) << full.reason;
  EXPECT_EQ(full.searches_capped, 20000u);
  EXPECT_LE(full.examined, 20000u * o.max_candidates);
  EXPECT_GE(full.examined, 20000u * (o.max_candidates / 2)) << "a capped search examines about max_candidates";
  EXPECT_LE(double(full.examined), 2.05 * double(half.examined)) << "work linear in the keypoints";
  EXPECT_LT(seconds, kClusteredFrameSeconds) << "one clustered frame of 20,000 keypoints";
  // Whatever was compared, a match is a pair within the radius at its true distance, each keypoint once.
  std::vector<int> used(b.kf_kp.size(), 0);
  for (std::size_t i = 0; i < full.keyframe_index.size(); ++i) {
    const int k = full.keyframe_index[i];
    if (k < 0) continue;
    EXPECT_EQ(full.distance[i], naive_hamming(&b.kf_desc[32 * std::size_t(k)], &b.cur_desc[32 * i], 32));
    EXPECT_LE((b.kf_kp[std::size_t(k)] - b.cur_kp[i]).norm(), float(o.radius_unpredicted_px));
    EXPECT_EQ(++used[std::size_t(k)], 1);
  }
}

// On ordinary input no search reaches the bound: the results are those of an unbounded search.
TYPED_TEST(KeyframeMatcherTyped, TheCandidateBoundLeavesOrdinaryInputUnchanged) {
  using T = TypeParam;
  const TwoViews<T> v(2000, pose_from<T>(0.01, 0.02, 0, 0.05, 0, 0.02), 77);
  KeyframeMatchOptions unbounded;
  unbounded.max_candidates = KeyframeMatchOptions::kMaxCandidatesLimit;
  for (int mode = 0; mode < 3; ++mode) {
    const std::vector<Vec3<T>> no_depth;
    const std::vector<Vec3<T>>& pts = mode == 0 ? v.kf_pts : no_depth;
    const dyncull::Rigid3<T>* pose = mode == 2 ? nullptr : &v.cam_from_kf;
    const auto bounded = v.match(pts, pose);
    const auto all = v.match(pts, pose, unbounded);
    ASSERT_TRUE(bounded.ok()) << bounded.reason;
    EXPECT_EQ(bounded.searches_capped, 0u) << mode;
    EXPECT_EQ(bounded.keyframe_index, all.keyframe_index) << mode;
    EXPECT_EQ(bounded.examined, all.examined) << mode;
    EXPECT_GT(bounded.matched, 1000u) << mode;
  }
}

// A bound below a disc's population subsamples it: fewer keypoints examined, each search counted.
TEST(KeyframeMatcher, ASmallCandidateBoundSubsamplesEachSearch) {
  const ClusteredViews c(500, 10.0, 43);
  KeyframeMatchOptions o;
  o.max_candidates = 50;
  KeyframeMatchWorkspace<float> ws;
  KeyframeMatchResult<float> r;
  c.match(o, ws, &r);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.searches_capped, 500u);
  EXPECT_LE(r.examined, 500u * 50u);
  EXPECT_GE(r.examined, 500u * 25u);
  o.max_candidates = 500;
  c.match(o, ws, &r);
  EXPECT_EQ(r.searches_capped, 0u);
  EXPECT_EQ(r.examined, 500u * 500u);
}

// Brute-force oracle: every pair, the same prediction, radius, distance, ratio and mutual rules.
template <class T>
std::vector<int> oracle(const std::vector<Vec2<T>>& kf, const std::vector<Vec3<T>>& pts, const std::uint8_t* kd,
                        const std::vector<Vec2<T>>& cur, const std::uint8_t* cd, std::size_t bytes,
                        const dyncull::PinholeCamera<T>& cam, const dyncull::Rigid3<T>* pose, const KeyframeMatchOptions& o) {
  const std::size_t n = cur.size(), m = kf.size();
  std::vector<int> best_cur(m, -1), best_d(m, -1), second(m, std::numeric_limits<int>::max());
  std::vector<int> cur_best(n, -1), cur_d(n, std::numeric_limits<int>::max());
  for (std::size_t k = 0; k < m; ++k) {
    if (!kf[k].allFinite()) continue;
    Vec2<T> p = kf[k];
    T rad = T(o.radius_unpredicted_px);
    if (pose) {
      const bool depth = !pts.empty() && pts[k].allFinite() && pts[k].z() > T(0);
      if (depth) {
        const Vec3<T> Xc = pose->apply(pts[k]);
        if (!(Xc.z() > T(0))) continue;
        p = cam.project(Xc);
        if (!p.allFinite()) continue;
        rad = T(o.radius_px);
      } else {
        const Vec3<T> h = (cam.K() * pose->R * cam.K().inverse()) * Vec3<T>(kf[k].x(), kf[k].y(), T(1));
        if (!(h.z() > T(0))) continue;
        p = Vec2<T>(h.x() / h.z(), h.y() / h.z());
        if (!p.allFinite()) continue;
      }
    }
    int b = std::numeric_limits<int>::max();
    for (std::size_t i = 0; i < n; ++i) {
      if (!cur[i].allFinite()) continue;
      const T dx = cur[i].x() - p.x(), dy = cur[i].y() - p.y();
      if (!(dx * dx + dy * dy <= rad * rad)) continue;
      const int d = naive_hamming(kd + bytes * k, cd + bytes * i, bytes);
      if (d < b) {
        second[k] = b;
        b = d;
        best_cur[k] = int(i);
      } else if (d < second[k]) {
        second[k] = d;
      }
      if (d < cur_d[i]) {
        cur_d[i] = d;
        cur_best[i] = int(k);
      }
    }
    best_d[k] = best_cur[k] >= 0 ? b : -1;
  }
  std::vector<int> out(n, -1), dist(n, -1);
  for (std::size_t k = 0; k < m; ++k) {
    const int c = best_cur[k];
    if (c < 0 || best_d[k] > o.max_hamming) continue;
    if (second[k] != std::numeric_limits<int>::max() && !(double(best_d[k]) <= o.ratio * double(second[k]))) continue;
    if (cur_best[std::size_t(c)] != int(k)) continue;
    if (out[std::size_t(c)] >= 0 && dist[std::size_t(c)] <= best_d[k]) continue;
    out[std::size_t(c)] = int(k);
    dist[std::size_t(c)] = best_d[k];
  }
  return out;
}

TYPED_TEST(KeyframeMatcherTyped, RandomInputMatchesTheBruteForceOracle) {
  using T = TypeParam;
  dyncull::Random rng(99);
  KeyframeMatchWorkspace<T> ws;  // reused across trials of different sizes
  KeyframeMatchResult<T> r;
  const T nan = std::numeric_limits<T>::quiet_NaN();
  for (int trial = 0; trial < 150; ++trial) {
    const std::size_t m = rng.index(120), n = rng.index(120);
    const std::size_t bytes = trial % 5 == 0 ? 61 : 32;  // a length with a tail after the 64-bit words
    auto coord = [&](double hi) -> T {
      const std::uint32_t u = rng.index(60);
      if (u == 0) return nan;
      if (u == 1) return std::numeric_limits<T>::infinity();
      if (u == 2) return T(-1e30);
      return T(rng.uniform(-20.0, hi));
    };
    std::vector<Vec2<T>> kf(m), cur(n);
    for (auto& p : kf) p = Vec2<T>(coord(200), coord(150));
    for (auto& p : cur) p = Vec2<T>(coord(200), coord(150));
    std::vector<Vec3<T>> pts;
    if (rng.index(3) != 0) {
      pts.resize(m);
      for (auto& p : pts) p = Vec3<T>(T(rng.uniform(-1, 1)), T(rng.uniform(-1, 1)), rng.index(8) == 0 ? nan : T(rng.uniform(-0.5, 4)));
    }
    // Descriptors from a few prototypes with some flipped bits: close, ambiguous and far pairs all occur.
    std::vector<std::uint8_t> proto(bytes * 6);
    for (auto& b : proto) b = static_cast<std::uint8_t>(rng.next() >> 56);
    auto make = [&](std::size_t rows) {
      std::vector<std::uint8_t> d(bytes * rows);
      for (std::size_t i = 0; i < rows; ++i) {
        const std::size_t p = bytes * rng.index(6);
        std::copy(&proto[p], &proto[p] + bytes, &d[bytes * i]);
        const std::uint32_t flips = rng.index(40);
        for (std::uint32_t f = 0; f < flips; ++f) d[bytes * i + rng.index(std::uint32_t(bytes))] ^= static_cast<std::uint8_t>(1u << rng.index(8));
      }
      return d;
    };
    const auto kd = make(m), cd = make(n);
    KeyframeMatchOptions o;
    o.radius_px = rng.uniform(1, 30);
    o.radius_unpredicted_px = rng.uniform(1, 60);
    o.max_hamming = int(rng.index(120));
    o.ratio = rng.uniform(0.5, 1.0);
    dyncull::PinholeCamera<T> cam{T(300), T(310), T(100), T(75), 200, 150};
    const auto pose = pose_from<T>(rng.uniform(-0.2, 0.2), rng.uniform(-0.2, 0.2), rng.uniform(-0.2, 0.2),
                                   rng.uniform(-0.3, 0.3), rng.uniform(-0.3, 0.3), rng.uniform(-0.3, 0.3));
    const dyncull::Rigid3<T>* pp = rng.index(3) == 0 ? nullptr : &pose;
    dyncull::match_to_keyframe(kf, pts, DescriptorRows(kd.data(), m, bytes, bytes), cur,
                               DescriptorRows(cd.data(), n, bytes, bytes), cam, pp, o, ws, &r);
    ASSERT_EQ(r.keyframe_index.size(), n);
    ASSERT_EQ(r.distance.size(), n);
    ASSERT_EQ(r.keyframe_pixel.size(), n);
    if (m == 0 || n == 0) {
      EXPECT_EQ(r.status, Status::TooFewPoints);
      continue;
    }
    ASSERT_TRUE(r.ok()) << r.reason;
    const auto want = oracle(kf, pts, kd.data(), cur, cd.data(), bytes, cam, pp, o);
    ASSERT_EQ(r.keyframe_index, want) << "trial " << trial;
    std::size_t matched = 0;
    std::vector<int> used(m, 0);
    for (std::size_t i = 0; i < n; ++i) {
      const int k = r.keyframe_index[i];
      if (k < 0) continue;
      ++matched;
      ++used[std::size_t(k)];
      EXPECT_EQ(r.distance[i], naive_hamming(&kd[bytes * std::size_t(k)], &cd[bytes * i], bytes));
      EXPECT_LE(r.distance[i], o.max_hamming);
      EXPECT_TRUE(r.keyframe_pixel[i].allFinite());
    }
    EXPECT_EQ(r.matched, matched);
    for (int u : used) EXPECT_LE(u, 1);  // a keyframe point has one nearest keypoint
  }
}

}  // namespace
