#include "dyncull/culling/keep_mask.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#ifdef DYNCULL_HAS_OPENCV
#include <opencv2/core.hpp>
#endif

namespace {
using namespace dyncull;

const std::vector<FeatureLabel> kLabels = {FeatureLabel::Static, FeatureLabel::Dynamic, FeatureLabel::Candidate,
                                           FeatureLabel::Static, FeatureLabel::Dynamic};

TEST(KeepMask, PoliciesDecideWhatCandidatesBecome) {
  EXPECT_EQ(make_keep_mask(kLabels), (std::vector<std::uint8_t>{1, 0, 1, 1, 0}));
  EXPECT_EQ(make_keep_mask(kLabels, KeepPolicy::DropDynamicAndCandidate), (std::vector<std::uint8_t>{1, 0, 0, 1, 0}));
  EXPECT_TRUE(make_keep_mask({}).empty());
}

struct Key {  // an ORB-SLAM-like keypoint
  float x, y;
  int octave;
};

TEST(KeepMask, CompactsEveryParallelArrayTogether) {
  std::vector<Key> keys;
  std::vector<float> depth, right_u;
  std::vector<std::string> names;
  // Descriptor rows of 4 used bytes in a matrix with 8-byte stride (like a cv::Mat ROI).
  std::vector<std::uint8_t> desc(5 * 8, 0xEE);
  for (int i = 0; i < 5; ++i) {
    keys.push_back({float(i), float(10 * i), i % 3});
    depth.push_back(1.f + float(i));
    right_u.push_back(-1.f * float(i));
    names.push_back("kp" + std::to_string(i));
    for (int b = 0; b < 4; ++b) desc[std::size_t(i * 8 + b)] = std::uint8_t(i * 16 + b);
  }
  const std::vector<std::uint8_t> keep = make_keep_mask(kLabels);
  RowsView rows{desc.data(), 4, 8, 5};
  const CompactResult r = compact_parallel(keep, keys, rows, depth, right_u, names);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.count, 3u);
  EXPECT_EQ(r.removed, 2u);
  const int kept[] = {0, 2, 3};
  ASSERT_EQ(keys.size(), 3u);
  ASSERT_EQ(names.size(), 3u);
  EXPECT_EQ(rows.rows, 3u);
  for (int j = 0; j < 3; ++j) {
    const int i = kept[j];
    EXPECT_EQ(keys[std::size_t(j)].x, float(i));
    EXPECT_EQ(depth[std::size_t(j)], 1.f + float(i));
    EXPECT_EQ(right_u[std::size_t(j)], -1.f * float(i));
    EXPECT_EQ(names[std::size_t(j)], "kp" + std::to_string(i));
    for (int b = 0; b < 4; ++b) EXPECT_EQ(desc[std::size_t(j * 8 + b)], std::uint8_t(i * 16 + b));
    EXPECT_EQ(desc[std::size_t(j * 8 + 5)], 0xEE);  // padding bytes untouched
  }
}

TEST(KeepMask, MismatchedSizesTouchNothing) {
  std::vector<int> a = {1, 2, 3, 4, 5};
  std::vector<int> b = {1, 2, 3};  // an array left unshrunk, like ORB-SLAM3's N in forks
  const CompactResult r = compact_parallel(make_keep_mask(kLabels), a, b);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_FALSE(r.reason.empty());
  EXPECT_EQ(a.size(), 5u);
  EXPECT_EQ(b.size(), 3u);
  // No arrays at all: just the count.
  EXPECT_EQ(compact_parallel(make_keep_mask(kLabels)).count, 3u);
  // Everything dropped (an all-dynamic frame) and nothing dropped.
  std::vector<int> c = {1, 2};
  EXPECT_EQ(compact_parallel(std::vector<std::uint8_t>{0, 0}, c).count, 0u);
  EXPECT_TRUE(c.empty());
}

TEST(KeepMask, BadDescriptorViewsAreRefusedAndTouchNothing) {
  const std::vector<std::uint8_t> keep = make_keep_mask(kLabels);
  std::vector<int> ids = {0, 1, 2, 3, 4};
  // Null data with rows: nothing to move rows through.
  CompactResult r = compact_parallel(keep, ids, RowsView{nullptr, 32, 32, 5});
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.reason.find("null"), std::string::npos) << r.reason;
  EXPECT_EQ(ids.size(), 5u);
  EXPECT_EQ(r.count, 5u);
  EXPECT_EQ(r.removed, 0u);
  // Rows longer than the stride overlap each other.
  std::vector<std::uint8_t> desc(5 * 8, 7);
  r = compact_parallel(keep, ids, RowsView{desc.data(), 16, 8, 5});
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.reason.find("row_bytes"), std::string::npos) << r.reason;
  EXPECT_EQ(ids.size(), 5u);
  // Rows that would reach past the address space.
  r = compact_parallel(keep, RowsView{desc.data(), 8, std::numeric_limits<std::size_t>::max() / 2, 5});
  EXPECT_EQ(r.status, Status::InvalidInput);
  // Two views of the same rows, and the same vector twice: the second pass would read freed slots.
  r = compact_parallel(keep, RowsView{desc.data(), 8, 8, 5}, RowsView{desc.data() + 4, 4, 8, 5});
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.reason.find("overlap"), std::string::npos) << r.reason;
  r = compact_parallel(keep, ids, ids);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_EQ(ids, (std::vector<int>{0, 1, 2, 3, 4}));
  EXPECT_EQ(desc, std::vector<std::uint8_t>(5 * 8, 7));
  // Null data is fine with no rows, and an empty frame compacts nothing.
  EXPECT_TRUE(compact_parallel(std::vector<std::uint8_t>{}, RowsView{nullptr, 32, 32, 0}).ok());
  // Ordinary views side by side in one buffer do not overlap.
  std::vector<std::uint8_t> two(5 * 16, 1);
  r = compact_parallel(keep, RowsView{two.data(), 8, 16, 5}, RowsView{two.data() + 8, 8, 16, 5});
  EXPECT_FALSE(r.ok());  // interleaved rows share the same span of memory
  std::vector<std::uint8_t> a(5 * 8, 1), b(5 * 8, 2);
  EXPECT_TRUE(compact_parallel(keep, RowsView{a.data(), 8, 8, 5}, RowsView{b.data(), 8, 8, 5}, ids).ok());
}

template <class T>
class RegionPredicate : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(RegionPredicate, Scalars, );

TYPED_TEST(RegionPredicate, PyramidLevelsMapToLevelZero) {
  using T = TypeParam;
  const std::vector<Box<T>> boxes = {{T(100), T(100), T(200), T(300)}};
  const DynamicRegionPredicate<T> inside(boxes, ConstMaskView{}, T(1.2), 8);
  EXPECT_TRUE(inside(T(150), T(200)));
  EXPECT_FALSE(inside(T(50), T(200)));
  // (150, 200) at level 0 is (150, 200) / 1.2^3 at level 3.
  const T s3 = T(1.2) * T(1.2) * T(1.2);
  EXPECT_TRUE(inside(T(150) / s3, T(200) / s3, 3));
  EXPECT_FALSE(inside(T(150), T(200), 3));  // level-3 (150, 200) is level-0 (259, 346)
  // Beyond the configured pyramid the same law holds.
  const T s10 = std::pow(T(1.2), T(10));
  EXPECT_TRUE(inside(T(150) / s10, T(200) / s10, 10));
  EXPECT_TRUE(inside(std::numeric_limits<T>::quiet_NaN(), T(0)));  // never trust NaN as static
  EXPECT_FALSE(DynamicRegionPredicate<T>().operator()(T(1), T(1)));
}

TYPED_TEST(RegionPredicate, ObjectMaskAloneOrRefiningBoxes) {
  using T = TypeParam;
  Mask m(64, 48);
  for (int v = 10; v < 20; ++v)
    for (int u = 10; u < 20; ++u) m.view().at(u, v) = 255;
  const std::vector<Box<T>> boxes = {{T(5), T(5), T(30), T(30)}};
  const DynamicRegionPredicate<T> mask_only(std::vector<Box<T>>{}, m.view());
  EXPECT_TRUE(mask_only(T(15), T(15)));
  EXPECT_FALSE(mask_only(T(25), T(25)));
  const DynamicRegionPredicate<T> either(boxes, m.view());
  EXPECT_TRUE(either(T(25), T(25)));
  const DynamicRegionPredicate<T> refined(boxes, m.view(), T(1), 1, true);
  EXPECT_TRUE(refined(T(15), T(15)));
  EXPECT_FALSE(refined(T(25), T(25)));  // in the box, off the object's mask
}

// A mask lookup at x = 2^32 + 10 must not wrap to column 10 (or 0 in float): every pixel is set,
// so any wrapped read would report the point inside.
TYPED_TEST(RegionPredicate, MaskLookupBeyondTheIntRangeIsOutside) {
  using T = TypeParam;
  Mask m(64, 48, 255);
  const DynamicRegionPredicate<T> inside(std::vector<Box<T>>{}, m.view());
  const T beyond = T(4294967306.0);
  EXPECT_TRUE(inside(T(10), T(10)));
  EXPECT_FALSE(inside(beyond, T(10)));
  EXPECT_FALSE(inside(T(10), beyond));
  EXPECT_FALSE(inside(-beyond, T(10)));
  EXPECT_FALSE(inside(T(1e30), T(10)));
  EXPECT_FALSE(inside(T(63.6), T(10)));  // rounds to column 64, past the mask
  EXPECT_TRUE(inside(T(63.4), T(47.4)));
}

TYPED_TEST(RegionPredicate, AbsurdPyramidsAreBounded) {
  using T = TypeParam;
  const std::vector<Box<T>> boxes = {{T(100), T(100), T(200), T(300)}};
  // A huge level count must not allocate a table per level; levels past the table use pow().
  const DynamicRegionPredicate<T> many(boxes, ConstMaskView{}, T(1.2), std::numeric_limits<int>::max());
  const T s20 = std::pow(T(1.2), T(20));
  EXPECT_TRUE(many(T(150) / s20, T(200) / s20, 20));
  // Non-finite or non-positive scale factors fall back to 1.
  for (const T f : {std::numeric_limits<T>::quiet_NaN(), std::numeric_limits<T>::infinity(), T(0), T(-2)}) {
    const DynamicRegionPredicate<T> p(boxes, ConstMaskView{}, f, 8);
    EXPECT_TRUE(p(T(150), T(200), 3)) << f;
    EXPECT_FALSE(p(T(50), T(200), 3)) << f;
  }
}

TEST(Rasterise, ConventionsAndObjectMasks) {
  Mask object(40, 30);
  object.view().at(2, 3) = 1;
  Mask out(40, 30);
  const std::vector<Box<float>> boxes = {{10.f, 5.f, 19.5f, 9.f}};
  ASSERT_EQ(rasterise_dynamic_regions(boxes, object.view(), out.view()), Status::Ok);
  EXPECT_EQ(out.count(), 10u * 5u + 1u);  // columns 10..19, rows 5..9, plus the object pixel
  EXPECT_EQ(out.view().at(10, 5), 255);
  EXPECT_EQ(out.view().at(2, 3), 255);
  EXPECT_EQ(out.view().at(20, 5), 0);
  ASSERT_EQ(rasterise_dynamic_regions(boxes, ConstMaskView{}, out.view(), MaskConvention::StaticIs255), Status::Ok);
  EXPECT_EQ(out.view().at(10, 5), 0);
  EXPECT_EQ(out.view().at(2, 3), 255);
  EXPECT_EQ(out.count(), 40u * 30u - 50u);
  Mask wrong(10, 10);
  EXPECT_EQ(rasterise_dynamic_regions(boxes, wrong.view(), out.view()), Status::InvalidInput);
  EXPECT_EQ(rasterise_dynamic_regions(boxes, ConstMaskView{}, MaskView{}), Status::InvalidInput);
}

#ifdef DYNCULL_HAS_OPENCV
TEST(KeepMaskOpenCV, KeyPointsAndDescriptorMat) {
  std::vector<cv::KeyPoint> kps;
  cv::Mat desc(5, 32, CV_8UC1);
  for (int i = 0; i < 5; ++i) {
    kps.emplace_back(float(i), 0.f, 7.f);
    desc.row(i).setTo(cv::Scalar(i));
  }
  const CompactResult r = compact_parallel(make_keep_mask(kLabels), kps,
                                           RowsView{desc.data, std::size_t(desc.cols) * desc.elemSize(), desc.step, 5});
  ASSERT_TRUE(r.ok());
  desc = desc.rowRange(0, int(r.count));
  ASSERT_EQ(kps.size(), 3u);
  EXPECT_EQ(kps[1].pt.x, 2.f);
  EXPECT_EQ(desc.at<std::uint8_t>(1, 31), 2);
  EXPECT_EQ(desc.at<std::uint8_t>(2, 0), 3);
  EXPECT_EQ(desc.rows, 3);
}
#endif
}  // namespace
