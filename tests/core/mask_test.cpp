// Tests of core/mask.hpp: owning masks, mutable and const views, strides, bounds and counting.
#include "dyncull/core/mask.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace {

TEST(Mask, ConstructResetAndCount) {
  dyncull::Mask m(4, 3);
  EXPECT_EQ(m.pixels.size(), 12u);
  EXPECT_EQ(m.count(), 0u);
  m.view().at(1, 2) = 255;
  m.view().at(3, 0) = 1;
  EXPECT_EQ(m.count(), 2u);
  EXPECT_TRUE(m.test(1, 2));
  EXPECT_FALSE(m.test(2, 1));
  EXPECT_EQ(m.pixels[2 * 4 + 1], 255);  // row-major, contiguous
  m.reset(2, 2, 7);
  EXPECT_EQ(m.count(), 4u);
  EXPECT_EQ(m.width, 2);
  const dyncull::Mask negative(-3, 5);  // nonsense size: empty, no crash
  EXPECT_TRUE(negative.pixels.empty());
  EXPECT_TRUE(negative.view().empty());
  EXPECT_FALSE(negative.test(0, 0));
}

TEST(Mask, OutOfBoundsTestsAreFalse) {
  const dyncull::Mask m(3, 3, 1);
  EXPECT_TRUE(m.test(0, 0));
  EXPECT_TRUE(m.test(2, 2));
  EXPECT_FALSE(m.test(-1, 0));
  EXPECT_FALSE(m.test(3, 0));
  EXPECT_FALSE(m.test(0, 3));
  EXPECT_TRUE(dyncull::MaskView{}.empty());
  EXPECT_FALSE(dyncull::ConstMaskView{}.test(0, 0));
}

TEST(MaskView, StrideAndConstConversion) {
  // 3 x 2 mask inside a buffer with 4 bytes per row; the padding byte must never be read as a pixel.
  std::vector<std::uint8_t> buf{0, 1, 0, 9, 1, 0, 1, 9};
  const dyncull::MaskView view{buf.data(), 3, 2, 4};
  EXPECT_TRUE(view.test(1, 0));
  EXPECT_TRUE(view.test(0, 1));
  EXPECT_TRUE(view.test(2, 1));
  EXPECT_FALSE(view.test(3, 0));  // the padding column is outside
  view.at(2, 0) = 1;
  EXPECT_EQ(buf[2], 1);
  const dyncull::ConstMaskView cview = view;
  EXPECT_EQ(cview.row_stride(), 4);
  EXPECT_TRUE(cview.test(2, 0));
  EXPECT_EQ(cview.row(1)[2], 1);
  const dyncull::ConstMaskView packed(buf.data(), 4, 2);
  EXPECT_EQ(packed.row_stride(), 4);
  EXPECT_TRUE(packed.test(3, 0));
}

}  // namespace
