// Tests of opencv/frame.hpp: PinholeCamera from K with its distortion reported and bad K named, TUM
// uint16 depth, and keypoint undistortion against cv::projectPoints on TUM fr1's coefficients.
#include "dyncull/opencv/frame.hpp"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace {

namespace cva = dyncull::cv_adapter;
using dyncull::Status;

template <class T>
class OpenCvFrameTyped : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(OpenCvFrameTyped, Scalars, );

TYPED_TEST(OpenCvFrameTyped, CameraFromKInBothMatrixTypes) {
  using T = TypeParam;
  const cv::Mat K64 = (cv::Mat_<double>(3, 3) << 517.3, 0, 318.6, 0, 516.5, 255.3, 0, 0, 1);
  cv::Mat K32;
  K64.convertTo(K32, CV_32F);
  const cv::Mat fr1_dist = (cv::Mat_<double>(1, 5) << 0.2624, -0.9531, -0.0054, 0.0026, 1.1633);
  for (const cv::Mat& K : {K64, K32}) {
    const auto c = cva::camera_from_K<T>(K, cv::Size(640, 480), fr1_dist);
    ASSERT_TRUE(c.ok()) << c.reason;
    EXPECT_NEAR(double(c.camera.fx), 517.3, 1e-4);
    EXPECT_NEAR(double(c.camera.fy), 516.5, 1e-4);
    EXPECT_NEAR(double(c.camera.cx), 318.6, 1e-4);
    EXPECT_NEAR(double(c.camera.cy), 255.3, 1e-4);
    EXPECT_EQ(c.camera.width, 640);
    EXPECT_EQ(c.camera.height, 480);
    EXPECT_TRUE(c.has_distortion);
    ASSERT_EQ(c.distortion.size(), 5u);
    EXPECT_DOUBLE_EQ(c.distortion[0], 0.2624);
  }
  // No coefficients, or all zero: no distortion.
  EXPECT_FALSE(cva::camera_from_K<T>(K64, cv::Size(640, 480)).has_distortion);
  EXPECT_FALSE(cva::camera_from_K<T>(K64, cv::Size(640, 480), cv::Mat::zeros(4, 1, CV_32F)).has_distortion);
}

TYPED_TEST(OpenCvFrameTyped, BadKSizeOrDistortionAreNamed) {
  using T = TypeParam;
  const cv::Mat K = (cv::Mat_<double>(3, 3) << 500, 0, 320, 0, 500, 240, 0, 0, 1);
  auto expect_bad = [](const cva::CameraFromK<T>& c, Status s, const char* word) {
    EXPECT_EQ(c.status, s) << c.reason;
    EXPECT_NE(c.reason.find(word), std::string::npos) << c.reason;
  };
  const cv::Size vga(640, 480);
  expect_bad(cva::camera_from_K<T>(cv::Mat(), vga), Status::InvalidInput, "K");
  expect_bad(cva::camera_from_K<T>(cv::Mat::eye(3, 4, CV_64F), vga), Status::InvalidInput, "3x3");
  expect_bad(cva::camera_from_K<T>(cv::Mat::eye(3, 3, CV_8U), vga), Status::InvalidInput, "CV_32F");
  expect_bad(cva::camera_from_K<T>(cv::Mat::eye(3, 3, CV_64FC2), vga), Status::InvalidInput, "single-channel");
  cv::Mat bad = K.clone();
  bad.at<double>(0, 0) = -500;
  expect_bad(cva::camera_from_K<T>(bad, vga), Status::InvalidInput, "focal");
  bad = K.clone();
  bad.at<double>(1, 1) = 0;
  expect_bad(cva::camera_from_K<T>(bad, vga), Status::InvalidInput, "focal");
  bad = K.clone();
  bad.at<double>(0, 2) = std::numeric_limits<double>::quiet_NaN();
  expect_bad(cva::camera_from_K<T>(bad, vga), Status::NonFinite, "K");
  bad = K.clone();
  bad.at<double>(0, 1) = 0.5;
  expect_bad(cva::camera_from_K<T>(bad, vga), Status::InvalidInput, "skew");
  bad = K.clone();
  bad.at<double>(2, 2) = 2;
  expect_bad(cva::camera_from_K<T>(bad, vga), Status::InvalidInput, "0 0 1");
  expect_bad(cva::camera_from_K<T>(K, cv::Size(0, 480)), Status::InvalidInput, "image_size");
  expect_bad(cva::camera_from_K<T>(K, cv::Size(640, -1)), Status::InvalidInput, "image_size");
  expect_bad(cva::camera_from_K<T>(K, vga, cv::Mat::zeros(1, 3, CV_64F)), Status::InvalidInput, "3 coefficients");
  expect_bad(cva::camera_from_K<T>(K, vga, cv::Mat::zeros(2, 4, CV_64F)), Status::InvalidInput, "distortion");
  cv::Mat nan_dist = cv::Mat::zeros(1, 5, CV_64F);
  nan_dist.at<double>(0, 4) = std::numeric_limits<double>::infinity();
  expect_bad(cva::camera_from_K<T>(K, vga, nan_dist), Status::NonFinite, "distortion");
  bad = K.clone();
  bad.at<double>(0, 0) = 1e300;  // finite in K, infinite as a float: out of bounds before any conversion
  expect_bad(cva::camera_from_K<T>(bad, vga), Status::InvalidInput, "K: fx = ");
}

TYPED_TEST(OpenCvFrameTyped, IntrinsicsNoCameraHasAreNamed) {
  using T = TypeParam;
  const cv::Size vga(640, 480);
  const struct {
    double fx, fy, cx, cy;
    const char* named;
  } cases[] = {{1e-42, 500, 320, 240, "K: fx = "}, {500, 1e-42, 320, 240, "K: fy = "},
               {1e8, 500, 320, 240, "K: fx = "},   {500, 500, 1e30, 240, "K: cx = "},
               {500, 500, 320, -1e4, "K: cy = "},  {500, 500, -700, 240, "K: cx = "}};
  for (const auto& c : cases) {
    const cv::Mat K = (cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
    const auto cam = cva::camera_from_K<T>(K, vga);
    EXPECT_EQ(cam.status, Status::InvalidInput) << c.named;
    EXPECT_NE(cam.reason.find(c.named), std::string::npos) << cam.reason;
  }
  // Wide-angle, long-focus and off-centre cameras that exist are accepted.
  for (const cv::Vec4d& k : {cv::Vec4d(150, 150, 320, 240), cv::Vec4d(40000, 40000, 320, 240),
                            cv::Vec4d(500, 500, -300, 700)}) {
    const cv::Mat K = (cv::Mat_<double>(3, 3) << k[0], 0, k[2], 0, k[1], k[3], 0, 0, 1);
    const auto cam = cva::camera_from_K<T>(K, vga);
    EXPECT_TRUE(cam.ok()) << cam.reason;
  }
  // undistort_keypoints checks K without an image size: no bound on where its principal point is.
  const cv::Mat K = (cv::Mat_<double>(3, 3) << 500, 0, 320, 0, 500, 240, 0, 0, 1);
  const cv::Mat dist = (cv::Mat_<double>(1, 4) << 0.1, 0, 0, 0);
  std::vector<cv::Point2f> pts = {cv::Point2f(100.f, 100.f)}, out;
  std::string why;
  EXPECT_EQ(cva::undistort_keypoints(pts, K, dist, &out, &why), Status::Ok) << why;
}

TEST(OpenCvFrame, TumDepthAndItsChecks) {
  cv::Mat depth(480, 640, CV_16UC1, cv::Scalar(0));
  depth.at<std::uint16_t>(10, 20) = 7500;  // 1.5 m
  const auto view = cva::tum_depth_view(depth);
  ASSERT_FALSE(view.empty());
  EXPECT_FLOAT_EQ(view.depth_m(20, 10), 1.5f);
  EXPECT_EQ(view.depth_m(0, 0), 0.f);
  EXPECT_EQ(view.validate(), Status::Ok);
  std::string why;
  EXPECT_EQ(cva::check_depth(depth, cv::Size(640, 480), &why), Status::Ok) << why;
  EXPECT_EQ(cva::check_depth(cv::Mat(480, 640, CV_32FC1), cv::Size(640, 480), &why), Status::Ok) << why;
  EXPECT_EQ(cva::check_depth(cv::Mat(), cv::Size(640, 480), &why), Status::InvalidInput);
  EXPECT_NE(why.find("empty"), std::string::npos) << why;
  EXPECT_EQ(cva::check_depth(cv::Mat(480, 640, CV_8UC1), cv::Size(640, 480), &why), Status::InvalidInput);
  EXPECT_NE(why.find("IMREAD_UNCHANGED"), std::string::npos) << why;
  EXPECT_EQ(cva::check_depth(cv::Mat(480, 640, CV_16UC3), cv::Size(640, 480), &why), Status::InvalidInput);
  EXPECT_NE(why.find("type"), std::string::npos) << why;
  EXPECT_EQ(cva::check_depth(depth, cv::Size(320, 240), &why), Status::InvalidInput);
  EXPECT_NE(why.find("640x480"), std::string::npos) << why;
  EXPECT_TRUE(cva::tum_depth_view(cv::Mat(480, 640, CV_8UC1)).empty());
}

/// Pixels of TUM fr1 (k1 = 0.26) distorted by cv::projectPoints from known undistorted pixels.
struct DistortedGrid {
  cv::Mat K = (cv::Mat_<double>(3, 3) << 517.3, 0, 318.6, 0, 516.5, 255.3, 0, 0, 1);
  cv::Mat dist = (cv::Mat_<double>(1, 5) << 0.2624, -0.9531, -0.0054, 0.0026, 1.1633);
  std::vector<cv::Point2f> ideal, distorted;
  DistortedGrid() {
    std::vector<cv::Point3d> rays;
    for (int v = 20; v < 480; v += 46) {
      for (int u = 20; u < 640; u += 50) {
        ideal.emplace_back(float(u), float(v));
        rays.emplace_back((u - 318.6) / 517.3, (v - 255.3) / 516.5, 1.0);
      }
    }
    std::vector<cv::Point2d> px;
    cv::projectPoints(rays, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, dist, px);
    for (const auto& p : px) distorted.emplace_back(float(p.x), float(p.y));
  }
};

TEST(OpenCvFrame, UndistortKeypointsRecoversTheIdealPixels) {
  const DistortedGrid g;
  std::vector<cv::KeyPoint> kps;
  for (std::size_t i = 0; i < g.distorted.size(); ++i) kps.emplace_back(g.distorted[i], 31.f, 45.f, 0.5f, 2, int(i));
  std::vector<cv::KeyPoint> un;
  std::string why;
  cva::UndistortWorkspace ws;
  ASSERT_EQ(cva::undistort_keypoints(kps, g.K, g.dist, &un, &why, &ws), Status::Ok) << why;
  ASSERT_EQ(un.size(), kps.size());
  double worst = 0, moved = 0;
  for (std::size_t i = 0; i < un.size(); ++i) {
    worst = std::max(worst, double(cv::norm(un[i].pt - g.ideal[i])));
    moved = std::max(moved, double(cv::norm(kps[i].pt - g.ideal[i])));
    EXPECT_EQ(un[i].size, 31.f);  // the other fields travel with the position
    EXPECT_EQ(un[i].octave, 2);
    EXPECT_EQ(un[i].class_id, int(i));
  }
  EXPECT_GT(moved, 5.0);   // fr1's distortion moves the corners by pixels...
  EXPECT_LT(worst, 0.01) << worst;  // ...and undistortion brings them back (5 OpenCV default iterations: 0.06 px)
  // cv::Point2f and cv::Point2d, in place.
  std::vector<cv::Point2f> pts = g.distorted;
  ASSERT_EQ(cva::undistort_keypoints(pts, g.K, g.dist, &pts), Status::Ok);
  for (std::size_t i = 0; i < pts.size(); ++i) EXPECT_LT(cv::norm(pts[i] - g.ideal[i]), 0.01);
  std::vector<cv::Point2d> ptd(g.distorted.begin(), g.distorted.end());
  ASSERT_EQ(cva::undistort_keypoints(ptd, g.K, g.dist, &ptd), Status::Ok);
  EXPECT_LT(cv::norm(ptd[0] - cv::Point2d(g.ideal[0])), 0.05);
}

TEST(OpenCvFrame, UndistortKeepsNonFinitePointsAndReportsBadCalibration) {
  const DistortedGrid g;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<cv::Point2f> pts{g.distorted[0], cv::Point2f(nan, 3.f), cv::Point2f(std::numeric_limits<float>::infinity(), 0.f),
                               g.distorted[1]};
  std::vector<cv::Point2f> un;
  ASSERT_EQ(cva::undistort_keypoints(pts, g.K, g.dist, &un), Status::Ok);
  EXPECT_LT(cv::norm(un[0] - g.ideal[0]), 0.05);
  EXPECT_TRUE(std::isnan(un[1].x));
  EXPECT_EQ(un[1].y, 3.f);
  EXPECT_TRUE(std::isinf(un[2].x));
  EXPECT_LT(cv::norm(un[3] - g.ideal[1]), 0.05);
  // No distortion: a copy.
  ASSERT_EQ(cva::undistort_keypoints(pts, g.K, cv::Mat(), &un), Status::Ok);
  EXPECT_EQ(un[0], pts[0]);
  // Empty input.
  std::vector<cv::Point2f> none;
  EXPECT_EQ(cva::undistort_keypoints(none, g.K, g.dist, &un), Status::Ok);
  EXPECT_TRUE(un.empty());
  // Bad K or coefficients: the reason, and the input copied through.
  std::string why;
  EXPECT_EQ(cva::undistort_keypoints(pts, cv::Mat::zeros(3, 3, CV_64F), g.dist, &un, &why), Status::InvalidInput);
  EXPECT_NE(why.find("focal"), std::string::npos) << why;
  ASSERT_EQ(un.size(), pts.size());
  EXPECT_EQ(un[0], pts[0]);
  EXPECT_EQ(cva::undistort_keypoints(pts, g.K, cv::Mat::zeros(1, 7, CV_64F), &un, &why), Status::InvalidInput);
  EXPECT_NE(why.find("distortion"), std::string::npos) << why;
}

}  // namespace
