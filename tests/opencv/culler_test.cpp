// Tests of opencv/culler.hpp, the OpenCV overloads of the public culler (dyncull::Culler, compiled into
// dyncull::culler): the README's loop (ORB keypoints, descriptor Mat, depth, boxes through
// cv_adapter::cull) labels the moving features of the synthetic walking scene as well as the recommended
// pipeline hand-fed with LK tracks into its keyframes; bad K, descriptor type, depth size and pose
// matrix are named; a distorted camera's keypoints are undistorted inside (as a host's own
// cv::undistortPoints copy would be); uint16 depth reads with its scale.
#include "dyncull/opencv/culler.hpp"

#include "dyncull/culling/pipeline.hpp"
#include "dyncull/culling/presets.hpp"
#include "dyncull/sim/families.hpp"
#include "dyncull/sim/scene.hpp"

#include "support/culler_inputs.hpp"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/video/tracking.hpp>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

namespace dyncull {
namespace {

using test::boxes_of;

/// Dynamic-label counts against the scene's per-pixel motion truth.
struct Score {
  std::size_t tp = 0, fp = 0, fn = 0;
  void add(const std::vector<cv::KeyPoint>& keys, const std::vector<std::uint8_t>& keep, const sim::FrameData& f) {
    for (std::size_t i = 0; i < keys.size(); ++i) {
      const int u = cvRound(keys[i].pt.x), v = cvRound(keys[i].pt.y);
      const bool moving = f.moving[static_cast<std::size_t>(v * f.width + u)] != 0;
      const bool culled = keep[i] == 0;
      tp += moving && culled;
      fp += !moving && culled;
      fn += moving && !culled;
    }
  }
  double precision() const { return tp + fp ? double(tp) / double(tp + fp) : 1.0; }
  double recall() const { return tp + fn ? double(tp) / double(tp + fn) : 1.0; }
};

cv::Mat camera_K(const sim::Scene& scene) {
  cv::Mat K;
  cv::eigen2cv(scene.camera().K(), K);
  return K;
}

/// The recommended pipeline fed by hand as the demo feeds it: LK from each frame's ORB keypoints into the
/// keyframe image, 3-D points from the keyframe's depth, ids of the nearest keyframe keypoint within 1.5 px.
class HandFed {
 public:
  explicit HandFed(const PinholeCamera<float>& camera) : camera_(camera) {}

  /// A new keyframe as the demo front end decides: moved 0.1 m or turned 15 deg from the keyframe, or fewer
  /// than half of the keypoints tracked into it.
  const std::vector<std::uint8_t>& cull(const std::vector<cv::KeyPoint>& keys, const cv::Mat& gray,
                                        const sim::FrameData& f, const Rigid3<float>& cam_from_world) {
    bool keyframe = kf_gray_.empty();
    const std::size_t n = keys.size();
    cv::KeyPoint::convert(keys, points_);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    points_3d_.assign(n, Vec3<float>(nan, nan, nan));
    ids_.resize(n);
    CullingFrame<float, std::vector<cv::Point2f>, std::vector<cv::Point2f>, float, std::vector<Vec3<float>>> frame;
    frame.keypoints = &points_;
    if (!kf_gray_.empty()) {
      cv::calcOpticalFlowPyrLK(gray, kf_gray_, points_, kf_points_, status_, error_, cv::Size(21, 21), 3);
      const Rigid3<float> world_from_kf = kf_pose_.inverse();
      for (std::size_t i = 0; i < n; ++i) {
        ids_[i] = next_id_++;
        if (!status_[i]) continue;
        const cv::Point2f p = kf_points_[i];
        const int u = cvRound(p.x), v = cvRound(p.y);
        if (u < 0 || v < 0 || u >= f.width || v >= f.height) {
          status_[i] = 0;
          continue;
        }
        const float z = kf_depth_[static_cast<std::size_t>(v * f.width + u)];
        if (z >= 0.4f && z <= 8.f)
          points_3d_[i] = world_from_kf.apply(camera_.backproject(Vec2<float>(p.x, p.y), z));
        double best = 1.5 * 1.5;
        for (std::size_t k = 0; k < kf_keys_.size(); ++k) {
          const double dx = kf_keys_[k].x - p.x, dy = kf_keys_[k].y - p.y;
          if (dx * dx + dy * dy < best) best = dx * dx + dy * dy, ids_[i] = kf_ids_[k];
        }
      }
      frame.prev_keypoints = &kf_points_;
      frame.track_valid = status_;
      frame.points_3d = &points_3d_;
      frame.evidence_frames = frames_since_kf_;
      std::size_t valid = 0;
      for (std::uint8_t s : status_) valid += s != 0;
      const Rigid3<float> rel = cam_from_world * kf_pose_.inverse();
      keyframe = rel.t.norm() > 0.1f || rotation_angle(rel.R) * Constants<float>::rad_to_deg() > 15.f ||
                 double(valid) < 0.5 * double(n);
    } else {
      for (std::size_t i = 0; i < n; ++i) ids_[i] = next_id_++;
    }
    depth_.assign(f.depth_m.begin(), f.depth_m.end());
    frame.track_ids = &ids_;
    frame.detections = &f.detections;
    frame.depth = DepthView<float>{depth_.data(), f.width, f.height, 0, 1.f, 0.f, 1e30f};
    frame.camera = camera_;
    frame.cam_from_world = &cam_from_world;
    frame.is_keyframe = keyframe;
    const PipelineResult<float>& r = cull_frame(frame, options_, &state_);
    ++frames_since_kf_;
    keyframes += keyframe;
    if (keyframe) {
      gray.copyTo(kf_gray_);
      kf_depth_ = depth_;
      kf_pose_ = cam_from_world;
      kf_keys_ = points_;
      kf_ids_ = ids_;
      frames_since_kf_ = 1;
    }
    return r.keep;
  }

 private:
  PinholeCamera<float> camera_;
  PipelineOptions<float> options_ = presets::recommended<float>();
  PipelineState<float> state_;
  cv::Mat kf_gray_;
  std::vector<float> kf_depth_, depth_;
  Rigid3<float> kf_pose_;
  std::vector<cv::Point2f> points_, kf_points_, kf_keys_;
  std::vector<std::uint8_t> status_;
  std::vector<float> error_;
  std::vector<Vec3<float>> points_3d_;
  std::vector<std::int64_t> ids_, kf_ids_;
  std::int64_t next_id_ = 0;
  int frames_since_kf_ = 0;

 public:
  std::size_t keyframes = 0;
};

/// The README's loop and the hand-fed reference over the same ORB features of `family`'s first 90 frames.
void expect_labels_like_the_hand_fed_pipeline(const char* family) {
  sim::SceneFamily scene_family;
  ASSERT_TRUE(sim::find_scene_family(family, &scene_family));
  sim::SceneOptions scene_options = scene_family.options;
  scene_options.num_frames = 90;
  const sim::Scene scene(scene_options);
  ASSERT_TRUE(scene.ok()) << scene.reason();
  Culler culler(cv_adapter::culler_camera(camera_K(scene), cv::Size(scene_options.width, scene_options.height)),
                CullerOptions("recommended"));
  ASSERT_TRUE(culler.ok()) << culler.reason();
  HandFed hand_fed(scene.camera().cast<float>());
  const cv::Ptr<cv::ORB> orb = cv::ORB::create(1000);
  Score own, reference;
  std::size_t keyframes = 0, matched = 0, features = 0;
  sim::FrameData frame;
  for (int i = 0; i < scene_options.num_frames; ++i) {
    scene.render(i, &frame);
    const cv::Mat gray(frame.height, frame.width, CV_8UC1, frame.gray.data());
    const cv::Mat depth(frame.height, frame.width, CV_32FC1, frame.depth_m.data());
    std::vector<cv::KeyPoint> keys;
    cv::Mat descriptors;
    orb->detectAndCompute(gray, cv::noArray(), keys, descriptors);
    const Rigid3<float> pose = frame.world_from_cam.inverse().cast<float>();
    cv::Mat Tcw;
    cv::eigen2cv(pose.matrix(), Tcw);
    const CullerResult& r = cv_adapter::cull(culler, keys, descriptors, depth, boxes_of(frame.detections), &Tcw);
    const std::vector<std::uint8_t> keep = r.keep;
    EXPECT_EQ(&r, &culler.result());
    if (i > 0) {
      EXPECT_TRUE(r.ok()) << "frame " << i << ": " << r.reason;
    }
    keyframes += r.keyframe;
    matched += r.matched;
    features += keys.size();
    // The reference decides its keyframes on its LK tracks with the same thresholds.
    const std::vector<std::uint8_t>& keep_ref = hand_fed.cull(keys, gray, frame, pose);
    ASSERT_EQ(keep.size(), keys.size());
    ASSERT_EQ(keep_ref.size(), keys.size());
    if (i == 0) continue;  // no keyframe to measure against yet
    own.add(keys, keep, frame);
    reference.add(keys, keep_ref, frame);
  }
  std::printf("%s\n", family);
  std::printf("culler:   precision %.3f recall %.3f (tp %zu fp %zu fn %zu)\n", own.precision(), own.recall(), own.tp,
              own.fp, own.fn);
  std::printf("hand-fed: precision %.3f recall %.3f (tp %zu fp %zu fn %zu)\n", reference.precision(),
              reference.recall(), reference.tp, reference.fp, reference.fn);
  std::printf("keyframes: culler %zu, hand-fed %zu; the culler matched %.1f %% of the features\n", keyframes,
              hand_fed.keyframes, 100.0 * double(matched) / double(features));
  EXPECT_NEAR(own.precision(), reference.precision(), 0.02);
  EXPECT_NEAR(own.recall(), reference.recall(), 0.02);
}

TEST(OpenCvCuller, LabelsLikeTheHandFedPipelineOnTheWalkingScene) {
  expect_labels_like_the_hand_fed_pipeline("walking");
}

TEST(OpenCvCuller, BadCalibrationAndInputsAreNamed) {
  const cv::Mat K = (cv::Mat_<double>(3, 3) << 525, 0, 319.5, 0, 525, 239.5, 0, 0, 1);
  const cv::Mat bad_K = (cv::Mat_<double>(3, 3) << 0, 0, 319.5, 0, 525, 239.5, 0, 0, 1);
  std::vector<cv::KeyPoint> keys(40);
  for (std::size_t i = 0; i < keys.size(); ++i) keys[i].pt = cv::Point2f(20.f + 10.f * float(i), 100.f);
  const cv::Mat descriptors(40, 32, CV_8UC1, cv::Scalar(7));
  const cv::Mat depth(480, 640, CV_32FC1, cv::Scalar(2.f));
  const std::vector<DetectedBox> boxes;
  using cv_adapter::cull;

  Culler no_focal(cv_adapter::culler_camera(bad_K, cv::Size(640, 480)));
  EXPECT_FALSE(no_focal.ok());
  EXPECT_NE(no_focal.reason().find("focal"), std::string::npos) << no_focal.reason();
  EXPECT_EQ(cull(no_focal, keys, descriptors, depth, boxes).keep, std::vector<std::uint8_t>(40, 1));
  EXPECT_EQ(no_focal.result().status, Status::InvalidInput);
  EXPECT_TRUE(no_focal.result().refused);

  Culler culler(cv_adapter::culler_camera(K, cv::Size(640, 480)));
  ASSERT_TRUE(culler.ok()) << culler.reason();
  const cv::Mat float_desc(40, 8, CV_32FC1, cv::Scalar(0.f));
  cull(culler, keys, float_desc, depth, boxes);
  EXPECT_EQ(culler.result().status, Status::InvalidInput);
  EXPECT_NE(culler.result().reason.find("CV_8U"), std::string::npos) << culler.result().reason;

  cull(culler, keys, descriptors.rowRange(0, 39), depth, boxes);
  EXPECT_NE(culler.result().reason.find("descriptors has 39 rows for 40 keypoints"), std::string::npos)
      << culler.result().reason;

  cull(culler, keys, descriptors, cv::Mat(240, 320, CV_32FC1, cv::Scalar(2.f)), boxes);
  EXPECT_NE(culler.result().reason.find("depth"), std::string::npos) << culler.result().reason;

  const cv::Mat Tcw3 = cv::Mat::eye(3, 4, CV_64F);
  cull(culler, keys, descriptors, depth, boxes, &Tcw3);
  EXPECT_NE(culler.result().reason.find("predicted_Tcw"), std::string::npos) << culler.result().reason;

  cull(culler, keys, descriptors, cv::Mat(), boxes);
  EXPECT_EQ(culler.result().status, Status::MissingInput);
  EXPECT_NE(culler.result().reason.find("monocular"), std::string::npos) << culler.result().reason;
}

TEST(OpenCvCuller, DistortedCameraUndistortsTheKeypointsItself) {
  const cv::Mat K = (cv::Mat_<double>(3, 3) << 517.3, 0, 318.6, 0, 516.5, 255.3, 0, 0, 1);
  const cv::Mat dist = (cv::Mat_<double>(1, 5) << 0.2624, -0.9531, -0.0054, 0.0026, 1.1633);  // TUM fr1
  Culler culler(cv_adapter::culler_camera(K, cv::Size(640, 480), dist));
  ASSERT_TRUE(culler.ok()) << culler.reason();
  EXPECT_TRUE(culler.camera().has_distortion());
  EXPECT_EQ(culler.camera().distortion.size(), 5u);
  // The same frames with the host's own undistorted copy (ORB-SLAM's mvKeysUn): the same outcome.
  Culler given(cv_adapter::culler_camera(K, cv::Size(640, 480), dist));
  std::vector<cv::KeyPoint> keys(60);
  for (std::size_t i = 0; i < keys.size(); ++i)
    keys[i].pt = cv::Point2f(30.f + 9.f * float(i), 60.f + 5.f * float(i % 7));
  cv::Mat descriptors(60, 32, CV_8UC1);
  cv::randu(descriptors, 0, 256);
  const cv::Mat depth(480, 640, CV_16UC1, cv::Scalar(10000));  // 2 m at TUM's 5000 per metre
  const cv::Mat Tcw = cv::Mat::eye(4, 4, CV_64F);
  const std::vector<DetectedBox> boxes;
  std::vector<cv::Point2f> raw, und;
  cv::KeyPoint::convert(keys, raw);
  cv::undistortPoints(raw, und, K, dist, cv::noArray(), K);
  std::vector<cv::KeyPoint> keys_un = keys;
  for (std::size_t i = 0; i < keys.size(); ++i) keys_un[i].pt = und[i];
  for (int frame = 0; frame < 2; ++frame) {
    const CullerResult& r = cv_adapter::cull(culler, keys, descriptors, depth, boxes, &Tcw);
    const CullerResult& g = cv_adapter::cull(given, keys, descriptors, depth, boxes, &Tcw, &keys_un);
    EXPECT_NE(r.status, Status::InvalidInput) << r.reason;
    EXPECT_EQ(r.status, g.status) << "frame " << frame;
    EXPECT_EQ(r.reason, g.reason);
    EXPECT_EQ(r.keep, g.keep);
    EXPECT_EQ(r.reasons, g.reasons);
    EXPECT_EQ(r.matched, g.matched);
  }
  EXPECT_EQ(culler.result().matched, keys.size());  // the same keypoints match themselves
}

}  // namespace
}  // namespace dyncull
