// opencv/darknet_layout.hpp on its own: the weights size a Darknet cfg implies, which the YOLO detector
// compares with the weights file before OpenCV reads it.
#include "dyncull/opencv/darknet_layout.hpp"

#include <gtest/gtest.h>

#include <string>

namespace {

using namespace dyncull;

// One 3x3 convolution of 3 -> 8 channels with batch norm, then a 1x1 convolution to 3 x (5 + 2) filters
// with a bias, fed to a [yolo] head of 2 classes and 3 anchors.
const char* kTinyCfg =
    "[net]\nwidth=64\nheight=32\nchannels=3\n\n"
    "[convolutional]\nbatch_normalize=1\nfilters=8\nsize=3\nstride=1\npad=1\nactivation=leaky\n\n"
    "[convolutional]\nfilters=21\nsize=1\nstride=1\npad=1\nactivation=linear\n\n"
    "[yolo]\nmask=0,1,2\nanchors=10,14,23,27,37,58\nclasses=2\nnum=3\n";

TEST(DarknetLayout, CountsTheFloatsOfEachLayer) {
  cv_adapter::DarknetLayout layout;
  std::string why;
  ASSERT_TRUE(cv_adapter::darknet_layout(kTinyCfg, &layout, &why)) << why;
  // Batch-normalised: 8 biases, scales, means and variances, then 3 * 3 * 3 * 8 weights; the second
  // convolution: 21 biases and 8 * 21 weights.
  EXPECT_EQ(layout.num_floats, 4u * 8u + 3u * 3u * 3u * 8u + 21u + 8u * 21u);
  ASSERT_EQ(layout.heads.size(), 1u);
  EXPECT_EQ(layout.heads[0].classes, 2);
  EXPECT_EQ(layout.heads[0].anchors, 3);
  EXPECT_EQ(layout.weights_bytes(0, 2), 20u + 4u * layout.num_floats);  // "seen" as int64 from 0.2 on
  EXPECT_EQ(layout.weights_bytes(0, 1), 16u + 4u * layout.num_floats);
  EXPECT_EQ(layout.input_width, 64);  // [net]: the input the network was trained at
  EXPECT_EQ(layout.input_height, 32);
}

TEST(DarknetLayout, AnInputSizeIsOptionalAndBounded) {
  std::string cfg = kTinyCfg;
  cv_adapter::DarknetLayout layout;
  std::string why;
  cfg.erase(cfg.find("width=64\n"), 9);
  ASSERT_TRUE(cv_adapter::darknet_layout(cfg, &layout, &why)) << why;
  EXPECT_EQ(layout.input_width, 0);  // not given
  EXPECT_EQ(layout.input_height, 32);
  cfg.replace(cfg.find("height=32"), 9, "height=99999");
  EXPECT_FALSE(cv_adapter::darknet_layout(cfg, &layout, &why));
  EXPECT_NE(why.find("width and height"), std::string::npos) << why;
}

TEST(DarknetLayout, AHeadNotFedByAnchorsTimesClassesFiltersIsRefused) {
  std::string cfg = kTinyCfg;
  cfg.replace(cfg.find("filters=21"), 10, "filters=20");
  cv_adapter::DarknetLayout layout;
  std::string why;
  EXPECT_FALSE(cv_adapter::darknet_layout(cfg, &layout, &why));
  EXPECT_FALSE(why.empty());
}

}  // namespace
