// Tests of opencv/compiled_culler.hpp (library dyncull::culler): on the synthetic walking scene its
// cv::KeyPoint, cv::Point2f and float-pair overloads give exactly the header-only FrameCuller's keep mask,
// labels, reasons, track ids and status; bad calibration, options and inputs are refused with the input
// named; compact() shrinks the descriptors with the parallel vectors; after warm-up a frame costs no heap
// allocation beyond the header-only culler's. The C++11 / C++14 host compile is checked by
// compiled_culler_host.cpp (built twice, -Werror).
#include "dyncull/opencv/compiled_culler.hpp"

#include "support/counting_allocator.hpp"

#include "dyncull/opencv/culler.hpp"
#include "dyncull/sim/families.hpp"
#include "dyncull/sim/scene.hpp"

#include <gtest/gtest.h>

#include <opencv2/core/eigen.hpp>
#include <opencv2/features2d.hpp>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace dyncull {
namespace {

using cv_adapter::CompiledCuller;
using cv_adapter::DetectedBox;
using cv_adapter::FrameCuller;

std::vector<DetectedBox> boxes_of(const std::vector<Detection<float>>& detections) {
  std::vector<DetectedBox> out;
  for (const Detection<float>& d : detections)
    out.emplace_back(d.box.x0, d.box.y0, d.box.x1, d.box.y1, d.class_id, d.confidence);
  return out;
}

/// The compiled result equals the header-only one, element by element.
void expect_same(const CullerResult& expected, const CompiledCuller::Result& got, int step, const char* overload) {
  SCOPED_TRACE(std::string(overload) + " overload, step " + std::to_string(step));
  EXPECT_EQ(static_cast<int>(got.status), static_cast<int>(expected.status));
  EXPECT_EQ(got.reason, expected.reason);
  EXPECT_EQ(got.keep, expected.keep);
  ASSERT_EQ(got.labels.size(), expected.labels.size());
  ASSERT_EQ(got.reasons.size(), expected.reasons.size());
  for (std::size_t i = 0; i < got.labels.size(); ++i) {
    EXPECT_EQ(static_cast<int>(got.labels[i]), static_cast<int>(expected.labels[i])) << "feature " << i;
    EXPECT_EQ(static_cast<int>(got.reasons[i]), static_cast<int>(expected.reasons[i])) << "feature " << i;
  }
  EXPECT_EQ(got.track_ids, expected.track_ids);
  EXPECT_EQ(got.num_kept, expected.num_kept);
  EXPECT_EQ(got.matched, expected.matched);
  EXPECT_EQ(got.frames_since_keyframe, expected.frames_since_keyframe);
  EXPECT_EQ(got.keyframe, expected.keyframe);
}

TEST(CompiledCuller, GivesTheFrameCullersLabelsOnTheWalkingSceneForEveryKeypointTypeWithoutExtraAllocations) {
  sim::SceneFamily family;
  ASSERT_TRUE(sim::find_scene_family("walking", &family));
  sim::SceneOptions scene_options = family.options;
  scene_options.num_frames = 30;
  const sim::Scene scene(scene_options);
  ASSERT_TRUE(scene.ok()) << scene.reason();
  cv::Mat K;
  cv::eigen2cv(scene.camera().K(), K);
  const cv::Size size(scene_options.width, scene_options.height);
  FrameCuller header_only(K, size);
  CompiledCuller with_keypoints(K, size), with_points(K, size), with_floats(K, size);
  ASSERT_TRUE(header_only.ok()) << header_only.reason();
  ASSERT_TRUE(with_keypoints.ok()) << with_keypoints.reason();
  const cv::Ptr<cv::ORB> orb = cv::ORB::create(1000);
  std::size_t dynamic = 0, keyframes = 0;
  // Heap allocations of each call summed over the second pass through the frames: the header-only
  // culler's, and the compiled overloads' beyond them (their result copies and point buffers reuse the
  // capacity the first pass grew them to).
  std::size_t header_only_allocations = 0, extra_keypoints = 0, extra_points = 0, extra_floats = 0;
  sim::FrameData frame;
  for (int step = 0; step < 2 * scene_options.num_frames; ++step) {
    const int i = step % scene_options.num_frames;
    const bool second_pass = step >= scene_options.num_frames;
    scene.render(i, &frame);
    const cv::Mat gray(frame.height, frame.width, CV_8UC1, frame.gray.data());
    const cv::Mat depth(frame.height, frame.width, CV_32FC1, frame.depth_m.data());
    std::vector<cv::KeyPoint> keys;
    cv::Mat descriptors;
    orb->detectAndCompute(gray, cv::noArray(), keys, descriptors);
    cv::Mat Tcw;
    cv::eigen2cv(frame.world_from_cam.inverse().matrix(), Tcw);
    const std::vector<DetectedBox> boxes = boxes_of(frame.detections);
    std::vector<cv::Point2f> points;
    cv::KeyPoint::convert(keys, points);

    std::size_t before = test::allocations();
    header_only.cull(keys, descriptors, depth, frame.detections, &Tcw);
    const std::size_t reference = test::allocations() - before;
    before = test::allocations();
    with_keypoints.cull(keys, descriptors, depth, boxes, &Tcw);
    const std::size_t by_keypoints = test::allocations() - before;
    before = test::allocations();
    with_points.cull(points, descriptors, depth, boxes, &Tcw);
    const std::size_t by_points = test::allocations() - before;
    before = test::allocations();
    with_floats.cull(points.empty() ? nullptr : &points[0].x, points.size(), sizeof(cv::Point2f), descriptors, depth,
                     boxes, &Tcw);
    const std::size_t by_floats = test::allocations() - before;
    if (second_pass) {
      header_only_allocations += reference;
      extra_keypoints += by_keypoints > reference ? by_keypoints - reference : 0;
      extra_points += by_points > reference ? by_points - reference : 0;
      extra_floats += by_floats > reference ? by_floats - reference : 0;
    }
    const CullerResult& expected = header_only.result();
    expect_same(expected, with_keypoints.result(), step, "cv::KeyPoint");
    expect_same(expected, with_points.result(), step, "cv::Point2f");
    expect_same(expected, with_floats.result(), step, "float pairs");
    for (FeatureLabel l : expected.labels) dynamic += l == FeatureLabel::Dynamic;
    keyframes += expected.keyframe;
  }
  // The comparison means something only when the scene made the culler cull and change keyframes.
  EXPECT_GT(dynamic, 100u);
  EXPECT_GT(keyframes, 1u);
  std::printf("allocations in the second pass: header-only %zu; beyond it: cv::KeyPoint %zu, cv::Point2f %zu, "
              "floats %zu\n",
              header_only_allocations, extra_keypoints, extra_points, extra_floats);
  EXPECT_EQ(extra_keypoints, 0u);
  EXPECT_EQ(extra_points, 0u);
  EXPECT_EQ(extra_floats, 0u);
}

struct BadInputFixture {
  cv::Mat K = (cv::Mat_<double>(3, 3) << 525, 0, 319.5, 0, 525, 239.5, 0, 0, 1);
  std::vector<cv::KeyPoint> keys = std::vector<cv::KeyPoint>(40);
  cv::Mat descriptors = cv::Mat(40, 32, CV_8UC1, cv::Scalar(7));
  cv::Mat depth = cv::Mat(480, 640, CV_32FC1, cv::Scalar(2.f));
  cv::Mat Tcw = cv::Mat::eye(4, 4, CV_64F);
  std::vector<DetectedBox> boxes;
  BadInputFixture() {
    for (std::size_t i = 0; i < keys.size(); ++i) keys[i].pt = cv::Point2f(20.f + 10.f * float(i), 100.f);
  }
};

TEST(CompiledCuller, MismatchedDescriptorRowsAreRefusedNamingTheDescriptors) {
  BadInputFixture in;
  CompiledCuller culler(in.K, cv::Size(640, 480));
  ASSERT_TRUE(culler.ok()) << culler.reason();
  const std::vector<std::uint8_t>& keep = culler.cull(in.keys, in.descriptors.rowRange(0, 39), in.depth, in.boxes, &in.Tcw);
  EXPECT_EQ(culler.result().status, CompiledCuller::Status::InvalidInput);
  EXPECT_NE(culler.result().reason.find("descriptors has 39 rows for 40 keypoints"), std::string::npos)
      << culler.result().reason;
  EXPECT_EQ(keep, std::vector<std::uint8_t>(40, 1));
  EXPECT_EQ(culler.result().labels.size(), 40u);
}

TEST(CompiledCuller, EmptyOrBadCalibrationIsNamedAndEveryCullKeepsAll) {
  BadInputFixture in;
  CompiledCuller empty_K(cv::Mat(), cv::Size(640, 480));
  EXPECT_FALSE(empty_K.ok());
  EXPECT_EQ(empty_K.status(), CompiledCuller::Status::InvalidInput);
  EXPECT_NE(empty_K.reason().find("K must be a 3x3"), std::string::npos) << empty_K.reason();
  EXPECT_EQ(empty_K.cull(in.keys, in.descriptors, in.depth, in.boxes, &in.Tcw), std::vector<std::uint8_t>(40, 1));
  EXPECT_EQ(empty_K.result().status, CompiledCuller::Status::InvalidInput);
  EXPECT_EQ(empty_K.result().reason, empty_K.reason());

  CompiledCuller no_size(in.K, cv::Size(0, 480));
  EXPECT_NE(no_size.reason().find("image_size"), std::string::npos) << no_size.reason();

  CompiledCuller::Options options;
  options.preset = "fastest";
  CompiledCuller unknown_preset(in.K, cv::Size(640, 480), cv::Mat(), options);
  EXPECT_EQ(unknown_preset.status(), CompiledCuller::Status::InvalidInput);
  EXPECT_NE(unknown_preset.reason().find("preset 'fastest'"), std::string::npos) << unknown_preset.reason();

  CompiledCuller::Options bad_threshold;
  bad_threshold.keyframe_max_rotation_deg = -1;
  CompiledCuller negative(in.K, cv::Size(640, 480), cv::Mat(), bad_threshold);
  EXPECT_NE(negative.reason().find("keyframe_max_rotation_deg"), std::string::npos) << negative.reason();

  CompiledCuller::Options bad_scale;
  bad_scale.depth_units_per_metre = 0.f;
  CompiledCuller zero_scale(in.K, cv::Size(640, 480), cv::Mat(), bad_scale);
  EXPECT_NE(zero_scale.reason().find("depth_units_per_metre"), std::string::npos) << zero_scale.reason();
  // A scale the depth view refuses is refused at construction, not on every frame.
  bad_scale.depth_units_per_metre = 2e6f;
  CompiledCuller huge_scale(in.K, cv::Size(640, 480), cv::Mat(), bad_scale);
  EXPECT_NE(huge_scale.reason().find("depth_units_per_metre"), std::string::npos) << huge_scale.reason();
}

TEST(CompiledCuller, NonFiniteKeypointIsCulledNamingItsIndexOnEveryOverload) {
  BadInputFixture in;
  CompiledCuller culler(in.K, cv::Size(640, 480));
  in.keys[3].pt.y = std::numeric_limits<float>::quiet_NaN();
  const std::vector<std::uint8_t>& keep = culler.cull(in.keys, in.descriptors, in.depth, in.boxes, &in.Tcw);
  ASSERT_EQ(keep.size(), 40u);
  EXPECT_EQ(keep[3], 0);
  EXPECT_EQ(culler.result().status, CompiledCuller::Status::MissingInput);
  EXPECT_EQ(culler.result().reasons[3], CompiledCuller::Reason::InvalidInput);
  EXPECT_NE(culler.result().reason.find("keypoints[3] has a NaN or Inf coordinate: culled"), std::string::npos)
      << culler.result().reason;

  std::vector<cv::Point2f> points;
  cv::KeyPoint::convert(in.keys, points);
  points[3].y = 100.f;
  points[7].x = std::numeric_limits<float>::infinity();
  culler.cull(points, in.descriptors, in.depth, in.boxes, &in.Tcw);
  EXPECT_EQ(culler.result().status, CompiledCuller::Status::MissingInput);
  EXPECT_NE(culler.result().reason.find("keypoints[7]"), std::string::npos) << culler.result().reason;
  EXPECT_EQ(culler.result().keep[7], 0);
  EXPECT_EQ(culler.result().keep[3], 1);

  culler.cull(&points[0].x, points.size(), 0, in.descriptors, in.depth, in.boxes, &in.Tcw);
  EXPECT_EQ(culler.result().status, CompiledCuller::Status::MissingInput);
  EXPECT_NE(culler.result().reason.find("keypoints[7]"), std::string::npos) << culler.result().reason;

  culler.cull(nullptr, 5, 0, cv::Mat(), in.depth, in.boxes, &in.Tcw);
  EXPECT_EQ(culler.result().status, CompiledCuller::Status::InvalidInput);
  EXPECT_NE(culler.result().reason.find("keypoints: null data with a count of 5"), std::string::npos)
      << culler.result().reason;
  EXPECT_EQ(culler.result().keep, std::vector<std::uint8_t>(5, 1));

  culler.cull(&points[0].x, points.size(), 4, in.descriptors, in.depth, in.boxes, &in.Tcw);
  EXPECT_NE(culler.result().reason.find("stride_bytes 4"), std::string::npos) << culler.result().reason;
}

TEST(CompiledCuller, MovedFromCullerRefusesInsteadOfCrashing) {
  BadInputFixture in;
  CompiledCuller a(in.K, cv::Size(640, 480));
  CompiledCuller b(std::move(a));
  EXPECT_TRUE(b.ok());
  EXPECT_FALSE(a.ok());  // NOLINT(bugprone-use-after-move): the moved-from state is what is tested
  EXPECT_NE(a.reason().find("moved from"), std::string::npos);
  EXPECT_EQ(a.cull(in.keys, in.descriptors, in.depth, in.boxes), std::vector<std::uint8_t>(40, 1));
}

TEST(CompiledCuller, CompactShrinksDescriptorsWithEveryParallelVector) {
  const std::vector<std::uint8_t> keep = {1, 0, 1, 0, 1};
  cv::Mat descriptors(5, 32, CV_8UC1);
  for (int r = 0; r < 5; ++r) descriptors.row(r).setTo(cv::Scalar(r));
  std::vector<cv::KeyPoint> keys(5);
  std::vector<float> depths = {0.f, 1.f, 2.f, 3.f, 4.f};
  for (int i = 0; i < 5; ++i) keys[static_cast<std::size_t>(i)].pt = cv::Point2f(float(i), 0.f);
  EXPECT_EQ(CompiledCuller::compact(keep, descriptors, keys, depths), 3);
  EXPECT_EQ(descriptors.rows, 3);
  EXPECT_EQ(descriptors.at<std::uint8_t>(1, 31), 2);
  EXPECT_EQ(descriptors.at<std::uint8_t>(2, 0), 4);
  ASSERT_EQ(keys.size(), 3u);
  EXPECT_EQ(keys[2].pt.x, 4.f);
  EXPECT_EQ(depths, (std::vector<float>{0.f, 2.f, 4.f}));

  std::vector<float> short_vector(2);
  EXPECT_EQ(CompiledCuller::compact(std::vector<std::uint8_t>(3, 0), descriptors, keys, short_vector), -1);
  EXPECT_EQ(descriptors.rows, 3);  // untouched
  EXPECT_EQ(keys.size(), 3u);
}

TEST(CompiledCuller, DetectedBoxFromARectSpansItsWidthAndHeight) {
  const DetectedBox b(cv::Rect2f(10.f, 20.f, 30.f, 40.f), 0, 0.9f);
  EXPECT_EQ(b.x0, 10.f);
  EXPECT_EQ(b.y0, 20.f);
  EXPECT_EQ(b.x1, 40.f);
  EXPECT_EQ(b.y1, 60.f);
  EXPECT_EQ(b.class_id, 0);
  EXPECT_EQ(b.confidence, 0.9f);
  EXPECT_STREQ(CompiledCuller::to_string(CompiledCuller::Status::MissingInput), "missing input");
  EXPECT_STREQ(CompiledCuller::to_string(CompiledCuller::Label::Dynamic), "dynamic");
}

}  // namespace
}  // namespace dyncull
