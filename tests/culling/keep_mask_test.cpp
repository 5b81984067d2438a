#include "dyncull/culling/keep_mask.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>


namespace {
using namespace dyncull;

const std::vector<FeatureLabel> kLabels = {FeatureLabel::Static, FeatureLabel::Dynamic, FeatureLabel::Candidate,
                                           FeatureLabel::Static, FeatureLabel::Dynamic};

TEST(KeepMask, PoliciesDecideWhatCandidatesBecome) {
  EXPECT_EQ(make_keep_mask(kLabels), (std::vector<std::uint8_t>{1, 0, 1, 1, 0}));
  EXPECT_EQ(make_keep_mask(kLabels, KeepPolicy::DropDynamicAndCandidate), (std::vector<std::uint8_t>{1, 0, 0, 1, 0}));
  EXPECT_TRUE(make_keep_mask({}).empty());
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

}  // namespace
