// Tests of opencv/views.hpp: zero-copy views over cv::Mat depth and mask images (including ROIs with
// a row stride), empty views on a wrong type, and cv::Point2f / cv::KeyPoint read through PointTraits.
#include "dyncull/opencv/views.hpp"

#include "dyncull/geometry/rotation_centre.hpp"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include <cmath>
#include <vector>

namespace {

TEST(OpenCvViews, DepthU16WithRoiStride) {
  cv::Mat depth(10, 20, CV_16UC1, cv::Scalar(0));
  depth.at<std::uint16_t>(3, 7) = 5000;   // row 3, col 7: 1 m
  depth.at<std::uint16_t>(4, 8) = 12500;  // 2.5 m
  const auto full = dyncull::cv_adapter::depth_view_u16(depth, 5000.f);
  ASSERT_FALSE(full.empty());
  EXPECT_EQ(full.data, depth.ptr<std::uint16_t>(0));  // no copy
  EXPECT_FLOAT_EQ(full.depth_m(7, 3), 1.f);
  EXPECT_EQ(full.depth_m(0, 0), 0.f);
  // A ROI keeps the parent's row step: the view must use it.
  const cv::Mat roi = depth(cv::Rect(5, 2, 6, 4));
  const auto view = dyncull::cv_adapter::depth_view_u16(roi, 5000.f);
  EXPECT_EQ(view.width, 6);
  EXPECT_EQ(view.height, 4);
  EXPECT_EQ(view.row_stride(), 20);
  EXPECT_FLOAT_EQ(view.depth_m(2, 1), 1.f);
  EXPECT_FLOAT_EQ(view.depth_m(3, 2), 2.5f);
  EXPECT_EQ(view.depth_m(6, 1), 0.f);  // outside the ROI
  const auto ranged = dyncull::cv_adapter::depth_view_u16(depth, 5000.f, 1.5f, 10.f);
  EXPECT_EQ(ranged.depth_m(7, 3), 0.f);
}

TEST(OpenCvViews, DepthF32AndWrongTypes) {
  cv::Mat depth(4, 5, CV_32FC1, cv::Scalar(2.f));
  depth.at<float>(1, 1) = std::nanf("");
  const auto view = dyncull::cv_adapter::depth_view_f32(depth);
  ASSERT_FALSE(view.empty());
  EXPECT_FLOAT_EQ(view.depth_m(0, 0), 2.f);
  EXPECT_EQ(view.depth_m(1, 1), 0.f);
  // Wrong type or empty: an empty view, never a reinterpretation.
  EXPECT_TRUE(dyncull::cv_adapter::depth_view_f32(cv::Mat(4, 5, CV_16UC1)).empty());
  EXPECT_TRUE(dyncull::cv_adapter::depth_view_u16(depth, 5000.f).empty());
  EXPECT_TRUE(dyncull::cv_adapter::depth_view_u16(cv::Mat(4, 5, CV_16UC3), 5000.f).empty());
  EXPECT_TRUE(dyncull::cv_adapter::depth_view_u16(cv::Mat(), 5000.f).empty());
  cv::Mat color(4, 5, CV_8UC3);
  EXPECT_TRUE(dyncull::cv_adapter::mask_view(color).empty());
  EXPECT_TRUE(dyncull::cv_adapter::const_mask_view(cv::Mat(4, 5, CV_32FC1)).empty());
}

TEST(OpenCvViews, MasksWriteThroughAndShareMemory) {
  cv::Mat mask(6, 8, CV_8UC1, cv::Scalar(0));
  cv::Mat roi = mask(cv::Rect(2, 1, 4, 3));
  const auto view = dyncull::cv_adapter::mask_view(roi);
  ASSERT_FALSE(view.empty());
  view.at(1, 2) = 255;
  EXPECT_EQ(mask.at<std::uint8_t>(3, 3), 255);  // written into the parent image
  EXPECT_TRUE(dyncull::cv_adapter::const_mask_view(mask).test(3, 3));
  EXPECT_EQ(cv::countNonZero(mask), 1);

  dyncull::Mask m(5, 4);
  cv::Mat header = dyncull::cv_adapter::to_mat(m);
  header.at<std::uint8_t>(2, 3) = 1;
  EXPECT_TRUE(m.test(3, 2));
  EXPECT_EQ(header.data, m.pixels.data());
}

TEST(OpenCvViews, PointsAndKeypointsThroughTraits) {
  const cv::Point2f p(3.5f, -1.25f);
  EXPECT_EQ(dyncull::point_x(p), 3.5f);
  EXPECT_EQ(dyncull::point_y(p), -1.25f);
  const cv::KeyPoint kp(cv::Point2f(10.f, 20.f), 7.f, 45.f);
  EXPECT_EQ(dyncull::to_vec2<double>(kp), Eigen::Vector2d(10, 20));
  EXPECT_EQ(dyncull::point_z(cv::Point3d(1, 2, 3)), 3.0);

  // Whole algorithms take vectors of them directly: rotation centre on cv::Point2f / cv::KeyPoint.
  std::vector<cv::KeyPoint> prev;
  std::vector<cv::Point2f> next;
  const double a = 0.4;
  for (int i = 0; i < 60; ++i) {
    const float x = float(40 + (i * 37) % 560), y = float(30 + (i * 53) % 420);
    prev.emplace_back(cv::Point2f(x, y), 5.f);
    const double dx = x - 320.0, dy = y - 240.0;
    next.emplace_back(float(320 + std::cos(a) * dx - std::sin(a) * dy), float(240 + std::sin(a) * dx + std::cos(a) * dy));
  }
  const auto r = dyncull::estimate_rotation_centre<double>(prev, next, 640, 480);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_NEAR(r.centre.x(), 320.0, 0.01);
  EXPECT_NEAR(r.centre.y(), 240.0, 0.01);
  EXPECT_NEAR(r.angle_rad, a, 1e-4);
}

}  // namespace
