// Keyframe matcher on real ORB features: one real TUM fr3 frame (two people, real depth with its holes)
// and a second view of it made by rotating the camera (a homography K R K^-1 warp, exact for a pure
// rotation), ORB on both with cv::ORB, then culling/keyframe_matcher.hpp with the pose and the real
// depth. The matches must agree with the known warp, for float and double.
#include "dyncull/culling/keyframe_matcher.hpp"

#include "dyncull/opencv/frame.hpp"

#include <gtest/gtest.h>

#include "support/real_data.hpp"

#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace {

using dyncull::Vec2;
using dyncull::Vec3;

template <class T>
class KeyframeMatcherOrb : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string why_not;
    const std::string dir = dyncull::test::real_data_dir(&why_not);
    if (dir.empty()) GTEST_SKIP() << why_not;
    const std::string base = dir + "/tum/fr3_walking_xyz_frame/";
    const cv::Mat rgb = cv::imread(base + "rgb_1341846313.592026.png", cv::IMREAD_GRAYSCALE);
    depth_ = cv::imread(base + "depth_1341846313.592088.png", cv::IMREAD_UNCHANGED);
    if (rgb.empty() || depth_.empty()) GTEST_SKIP() << "TUM frame not found under " << base << ": test skipped";
    kf_gray_ = rgb;
    const cv::Mat K = (cv::Mat_<double>(3, 3) << 535.4, 0, 320.1, 0, 539.2, 247.6, 0, 0, 1);
    const auto cam = dyncull::cv_adapter::camera_from_K<T>(K, kf_gray_.size());
    ASSERT_TRUE(cam.ok()) << cam.reason;
    camera_ = cam.camera;
    // 4 degrees of pan, 1.5 of tilt, 2 of roll: shifts of ~40 px, beyond a same-pixel search of 15 px.
    const Eigen::Matrix3d R = (Eigen::AngleAxisd(0.035, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(0.07, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(0.026, Eigen::Vector3d::UnitX()))
                                  .toRotationMatrix();
    pose_.R = R.cast<T>();
    Eigen::Matrix3d Kd;
    Kd << 535.4, 0, 320.1, 0, 539.2, 247.6, 0, 0, 1;
    H_ = Kd * R * Kd.inverse();
    cv::Mat Hcv(3, 3, CV_64F);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) Hcv.at<double>(r, c) = H_(r, c);
    cv::warpPerspective(kf_gray_, cur_gray_, Hcv, kf_gray_.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);

    auto orb = cv::ORB::create(1000);
    orb->detectAndCompute(kf_gray_, cv::noArray(), kf_kp_, kf_desc_);
    orb->detectAndCompute(cur_gray_, cv::noArray(), cur_kp_, cur_desc_);
    const auto depth = dyncull::cv_adapter::tum_depth_view(depth_);
    const T nan = std::numeric_limits<T>::quiet_NaN();
    for (const auto& k : kf_kp_) {
      const float z = depth.depth_m(int(k.pt.x + 0.5f), int(k.pt.y + 0.5f));
      kf_pts_.push_back(z > 0.f ? camera_.backproject(Vec2<T>(T(k.pt.x), T(k.pt.y)), T(z)) : Vec3<T>(nan, nan, nan));
    }
  }

  /// Distance (px) of a current keypoint from where the warp puts a keyframe keypoint.
  double warp_error(const cv::KeyPoint& kf, const cv::KeyPoint& cur) const {
    const Eigen::Vector3d h = H_ * Eigen::Vector3d(kf.pt.x, kf.pt.y, 1.0);
    return (h.hnormalized() - Eigen::Vector2d(cur.pt.x, cur.pt.y)).norm();
  }

  dyncull::KeyframeMatchResult<T> match(const dyncull::Rigid3<T>* pose, const dyncull::KeyframeMatchOptions& o) const {
    return dyncull::match_to_keyframe(kf_kp_, kf_pts_, dyncull::DescriptorRows(kf_desc_.ptr(0), kf_kp_.size(), kf_desc_.step),
                                      cur_kp_, dyncull::DescriptorRows(cur_desc_.ptr(0), cur_kp_.size(), cur_desc_.step),
                                      camera_, pose, o);
  }

  cv::Mat kf_gray_, cur_gray_, depth_, kf_desc_, cur_desc_;
  std::vector<cv::KeyPoint> kf_kp_, cur_kp_;
  std::vector<Vec3<T>> kf_pts_;
  dyncull::PinholeCamera<T> camera_;
  dyncull::Rigid3<T> pose_;
  Eigen::Matrix3d H_;
};

using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(KeyframeMatcherOrb, Scalars, );

TYPED_TEST(KeyframeMatcherOrb, RealOrbFeaturesAgreeWithTheKnownRotation) {
  ASSERT_GT(this->kf_kp_.size(), 900u);
  const dyncull::KeyframeMatchOptions o;
  const auto r = this->match(&this->pose_, o);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_GT(r.predicted_by_depth, 0u);
  EXPECT_GT(r.predicted_without_depth, 0u);  // the real depth has holes (edge band, dark surfaces)
  std::size_t good = 0;
  for (std::size_t i = 0; i < r.keyframe_index.size(); ++i) {
    if (r.keyframe_index[i] < 0) continue;
    const cv::KeyPoint& kf = this->kf_kp_[std::size_t(r.keyframe_index[i])];
    const cv::KeyPoint& cur = this->cur_kp_[i];
    // ORB localises a keypoint to about a pixel of its pyramid level: 3 px scaled by the coarser level.
    const double tolerance = 3.0 * std::pow(1.2, std::max(kf.octave, cur.octave));
    good += this->warp_error(kf, cur) <= tolerance;
  }
  // About 590 of the 1000 features are matched here, all of them true pairs: ORB re-detects about two
  // thirds of its features after a rotation and resampling, and the ratio and mutual tests drop the rest.
  EXPECT_GE(r.matched, 450u) << "matched " << r.matched;
  EXPECT_GE(double(good), 0.99 * double(r.matched)) << good << " of " << r.matched;
  // Without the pose, a 15 px search around the same pixel misses the motion.
  dyncull::KeyframeMatchOptions narrow;
  narrow.radius_unpredicted_px = 15;
  const auto blind = this->match(nullptr, narrow);
  ASSERT_TRUE(blind.ok()) << blind.reason;
  EXPECT_LT(blind.matched, r.matched / 3) << blind.matched << " vs " << r.matched;
}

}  // namespace
