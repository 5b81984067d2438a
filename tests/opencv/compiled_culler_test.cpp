// Tests of the compiled public culler (dyncull::Culler of culling/culler.hpp, library dyncull::culler) and
// its OpenCV overloads (opencv/culler.hpp): on the synthetic walking scene, cv_adapter::cull with
// cv::KeyPoint and with cv::Point2f keypoints and the plain views (float pairs with a stride) give exactly
// the keep mask, labels, reasons, track ids and status of the templated CullerCore<float> it runs, set up
// with core_options<float>(CullerOptions("recommended")); bad calibration, options and inputs are refused
// with the input named; cv_adapter::compact() shrinks the descriptors with the parallel vectors; after
// warm-up a frame costs no heap allocation beyond the core's. The C++11 / C++14 host compile is checked by
// compiled_culler_host.cpp (built twice, -Werror).
#include "dyncull/culling/culler.hpp"

#include "support/culler_inputs.hpp"
#include "support/counting_allocator.hpp"

#include "dyncull/culling/culler_core.hpp"
#include "dyncull/opencv/culler.hpp"
#include "dyncull/opencv/views.hpp"
#include "dyncull/sim/families.hpp"
#include "dyncull/sim/scene.hpp"

#include <gtest/gtest.h>

#include <opencv2/core/eigen.hpp>
#include <opencv2/features2d.hpp>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace dyncull {
namespace {

using test::boxes_of;
using test::rows_of;


/// The public culler's result equals the core's, element by element.
void expect_same(const CullerResult& expected, const CullerResult& got, int step, const char* form) {
  SCOPED_TRACE(std::string(form) + ", step " + std::to_string(step));
  EXPECT_EQ(got.status, expected.status);
  EXPECT_EQ(got.reason, expected.reason);
  EXPECT_EQ(got.refused, expected.refused);
  EXPECT_EQ(got.keep, expected.keep);
  EXPECT_EQ(got.labels, expected.labels);
  EXPECT_EQ(got.reasons, expected.reasons);
  EXPECT_EQ(got.track_ids, expected.track_ids);
  EXPECT_EQ(got.num_kept, expected.num_kept);
  EXPECT_EQ(got.matched, expected.matched);
  EXPECT_EQ(got.frames_since_keyframe, expected.frames_since_keyframe);
  EXPECT_EQ(got.keyframe, expected.keyframe);
}

TEST(CompiledCuller, GivesTheCoresLabelsOnTheWalkingSceneForEveryKeypointTypeWithoutExtraAllocations) {
  sim::SceneFamily family;
  ASSERT_TRUE(sim::find_scene_family("walking", &family));
  sim::SceneOptions scene_options = family.options;
  scene_options.num_frames = 30;
  const sim::Scene scene(scene_options);
  ASSERT_TRUE(scene.ok()) << scene.reason();
  cv::Mat K;
  cv::eigen2cv(scene.camera().K(), K);
  const cv::Size size(scene_options.width, scene_options.height);
  const CullerCamera camera = cv_adapter::culler_camera(K, size);
  const CullerOptions options("recommended");
  CullerCore<float> core(scene.camera().cast<float>(), core_options<float>(options));
  Culler with_keypoints(camera, options), with_points(camera, options), with_views(camera, options);
  ASSERT_EQ(core.status(), Status::Ok) << core.reason();
  ASSERT_TRUE(with_keypoints.ok()) << with_keypoints.reason();
  const cv::Ptr<cv::ORB> orb = cv::ORB::create(1000);
  std::size_t dynamic = 0, keyframes = 0;
  // Heap allocations of each call summed over the second pass through the frames: the core's, and the
  // public forms' beyond them (their box and pose conversions reuse the capacity the first pass grew).
  std::size_t core_allocations = 0, extra_keypoints = 0, extra_points = 0, extra_views = 0;
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
    const Rigid3<double> pose = frame.world_from_cam.inverse();
    cv::Mat Tcw;
    cv::eigen2cv(pose.matrix(), Tcw);
    const Rigid3<float> pose_f = pose.cast<float>();
    double Rt[12];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) Rt[4 * r + c] = Tcw.at<double>(r, c);
    const std::vector<DetectedBox> boxes = boxes_of(frame.detections);
    std::vector<cv::Point2f> points;
    cv::KeyPoint::convert(keys, points);
    CullerCoreFrame<float> cf;
    cf.keypoints = points_view(keys);
    if (!descriptors.empty()) cf.descriptors = rows_of(descriptors);
    cf.depth_m = cv_adapter::depth_view_f32(depth);
    cf.detections = &frame.detections;
    cf.cam_from_world = &pose_f;
    CullerFrame pf;  // float pairs with the stride of cv::Point2f, as a host's own point array
    pf.keypoints = PointsView::of(points.empty() ? nullptr : &points[0].x, points.size(), sizeof(cv::Point2f));
    pf.descriptors = cf.descriptors;
    pf.depth_m = cf.depth_m;
    pf.detections = &boxes;
    pf.cam_from_world = Rt;

    std::size_t before = test::allocations();
    core.cull(cf);
    const std::size_t reference = test::allocations() - before;
    before = test::allocations();
    cv_adapter::cull(with_keypoints, keys, descriptors, depth, boxes, &Tcw);
    const std::size_t by_keypoints = test::allocations() - before;
    before = test::allocations();
    cv_adapter::cull(with_points, points, descriptors, depth, boxes, &Tcw);
    const std::size_t by_points = test::allocations() - before;
    before = test::allocations();
    with_views.cull(pf);
    const std::size_t by_views = test::allocations() - before;
    if (second_pass) {
      core_allocations += reference;
      extra_keypoints += by_keypoints > reference ? by_keypoints - reference : 0;
      extra_points += by_points > reference ? by_points - reference : 0;
      extra_views += by_views > reference ? by_views - reference : 0;
    }
    const CullerResult& expected = core.result();
    expect_same(expected, with_keypoints.result(), step, "OpenCV overload, cv::KeyPoint");
    expect_same(expected, with_points.result(), step, "OpenCV overload, cv::Point2f");
    expect_same(expected, with_views.result(), step, "plain views, float pairs");
    for (FeatureLabel l : expected.labels) dynamic += l == FeatureLabel::Dynamic;
    keyframes += expected.keyframe;
  }
  // The comparison means something only when the scene made the culler cull and change keyframes.
  EXPECT_GT(dynamic, 100u);
  EXPECT_GT(keyframes, 1u);
  std::printf("allocations in the second pass: CullerCore<float> %zu; beyond it: cv::KeyPoint %zu, cv::Point2f %zu, "
              "plain views %zu\n",
              core_allocations, extra_keypoints, extra_points, extra_views);
  EXPECT_EQ(extra_keypoints, 0u);
  EXPECT_EQ(extra_points, 0u);
  EXPECT_EQ(extra_views, 0u);
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
  CullerCamera camera() const { return cv_adapter::culler_camera(K, cv::Size(640, 480)); }
};

TEST(CompiledCuller, MismatchedDescriptorRowsAreRefusedNamingTheDescriptors) {
  BadInputFixture in;
  Culler culler(in.camera());
  ASSERT_TRUE(culler.ok()) << culler.reason();
  const std::vector<std::uint8_t>& keep =
      cv_adapter::cull(culler, in.keys, in.descriptors.rowRange(0, 39), in.depth, in.boxes, &in.Tcw).keep;
  EXPECT_EQ(culler.result().status, Status::InvalidInput);
  EXPECT_TRUE(culler.result().refused);
  EXPECT_NE(culler.result().reason.find("descriptors has 39 rows for 40 keypoints"), std::string::npos)
      << culler.result().reason;
  EXPECT_EQ(keep, std::vector<std::uint8_t>(40, 1));
  EXPECT_EQ(culler.result().labels.size(), 40u);
}

TEST(CompiledCuller, EmptyOrBadCalibrationIsNamedAndEveryCullKeepsAll) {
  BadInputFixture in;
  // An empty K gives a camera without intrinsics: refused, naming the camera.
  Culler empty_K(cv_adapter::culler_camera(cv::Mat(), cv::Size(640, 480)));
  EXPECT_FALSE(empty_K.ok());
  EXPECT_EQ(empty_K.status(), Status::InvalidInput);
  EXPECT_NE(empty_K.reason().find("camera: focal lengths"), std::string::npos) << empty_K.reason();
  EXPECT_EQ(cv_adapter::cull(empty_K, in.keys, in.descriptors, in.depth, in.boxes, &in.Tcw).keep,
            std::vector<std::uint8_t>(40, 1));
  EXPECT_EQ(empty_K.result().status, Status::InvalidInput);
  EXPECT_EQ(empty_K.result().reason, empty_K.reason());

  Culler no_size(cv_adapter::culler_camera(in.K, cv::Size(0, 480)));
  EXPECT_NE(no_size.reason().find("image size"), std::string::npos) << no_size.reason();

  Culler unknown_preset(in.camera(), CullerOptions("fastest"));
  EXPECT_EQ(unknown_preset.status(), Status::InvalidInput);
  EXPECT_NE(unknown_preset.reason().find("preset 'fastest'"), std::string::npos) << unknown_preset.reason();

  CullerOptions bad_threshold;
  bad_threshold.keyframe_max_rotation_deg = -1;
  Culler negative(in.camera(), bad_threshold);
  EXPECT_NE(negative.reason().find("keyframe_max_rotation_deg"), std::string::npos) << negative.reason();

  CullerOptions bad_scale;
  bad_scale.depth_units_per_metre = 0;
  Culler zero_scale(in.camera(), bad_scale);
  EXPECT_NE(zero_scale.reason().find("depth_units_per_metre"), std::string::npos) << zero_scale.reason();
  // A scale the depth view refuses is refused at construction, not on every frame.
  bad_scale.depth_units_per_metre = 2e6;
  Culler huge_scale(in.camera(), bad_scale);
  EXPECT_NE(huge_scale.reason().find("depth_units_per_metre"), std::string::npos) << huge_scale.reason();
}

TEST(CompiledCuller, NonFiniteKeypointIsCulledNamingItsIndexOnEveryOverload) {
  BadInputFixture in;
  Culler culler(in.camera());
  in.keys[3].pt.y = std::numeric_limits<float>::quiet_NaN();
  const std::vector<std::uint8_t>& keep = cv_adapter::cull(culler, in.keys, in.descriptors, in.depth, in.boxes, &in.Tcw).keep;
  ASSERT_EQ(keep.size(), 40u);
  EXPECT_EQ(keep[3], 0);
  EXPECT_EQ(culler.result().status, Status::MissingInput);
  EXPECT_EQ(culler.result().reasons[3], CullReason::InvalidInput);
  EXPECT_NE(culler.result().reason.find("keypoints[3] has a NaN or Inf coordinate: culled"), std::string::npos)
      << culler.result().reason;

  std::vector<cv::Point2f> points;
  cv::KeyPoint::convert(in.keys, points);
  points[3].y = 100.f;
  points[7].x = std::numeric_limits<float>::infinity();
  cv_adapter::cull(culler, points, in.descriptors, in.depth, in.boxes, &in.Tcw);
  EXPECT_EQ(culler.result().status, Status::MissingInput);
  EXPECT_NE(culler.result().reason.find("keypoints[7]"), std::string::npos) << culler.result().reason;
  EXPECT_EQ(culler.result().keep[7], 0);
  EXPECT_EQ(culler.result().keep[3], 1);

  // The plain views: packed float pairs, a null pointer with a count, a stride shorter than a pair.
  CullerFrame f;
  f.descriptors = rows_of(in.descriptors);
  f.depth_m = cv_adapter::depth_view_f32(in.depth);
  f.detections = &in.boxes;
  double Rt[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
  f.cam_from_world = Rt;
  f.keypoints = PointsView::of(&points[0].x, points.size());
  culler.cull(f);
  EXPECT_EQ(culler.result().status, Status::MissingInput);
  EXPECT_NE(culler.result().reason.find("keypoints[7]"), std::string::npos) << culler.result().reason;

  CullerFrame null_points = f;
  null_points.keypoints = PointsView::of(static_cast<const float*>(nullptr), 5);
  null_points.descriptors = DescriptorRows();
  culler.cull(null_points);
  EXPECT_EQ(culler.result().status, Status::InvalidInput);
  EXPECT_NE(culler.result().reason.find("keypoints: null data with a count of 5"), std::string::npos)
      << culler.result().reason;
  EXPECT_EQ(culler.result().keep, std::vector<std::uint8_t>(5, 1));

  f.keypoints = PointsView::of(&points[0].x, points.size(), 4);
  culler.cull(f);
  EXPECT_NE(culler.result().reason.find("stride_bytes 4"), std::string::npos) << culler.result().reason;
}

TEST(CompiledCuller, MovedFromCullerRefusesInsteadOfCrashing) {
  BadInputFixture in;
  Culler a(in.camera());
  Culler b(std::move(a));
  EXPECT_TRUE(b.ok());
  EXPECT_FALSE(a.ok());  // NOLINT(bugprone-use-after-move): the moved-from state is what is tested
  EXPECT_NE(a.reason().find("moved from"), std::string::npos);
  EXPECT_EQ(cv_adapter::cull(a, in.keys, in.descriptors, in.depth, in.boxes).keep, std::vector<std::uint8_t>(40, 1));
  // Move assignment hands the culler on as well.
  Culler c(CullerCamera{});
  EXPECT_FALSE(c.ok());
  c = std::move(b);
  EXPECT_TRUE(c.ok()) << c.reason();
  EXPECT_FALSE(cv_adapter::cull(c, in.keys, in.descriptors, in.depth, in.boxes, &in.Tcw).refused);
}

TEST(CompiledCuller, CompactShrinksDescriptorsWithEveryParallelVector) {
  const std::vector<std::uint8_t> keep = {1, 0, 1, 0, 1};
  cv::Mat descriptors(5, 32, CV_8UC1);
  for (int r = 0; r < 5; ++r) descriptors.row(r).setTo(cv::Scalar(r));
  std::vector<cv::KeyPoint> keys(5);
  std::vector<float> depths = {0.f, 1.f, 2.f, 3.f, 4.f};
  for (int i = 0; i < 5; ++i) keys[static_cast<std::size_t>(i)].pt = cv::Point2f(float(i), 0.f);
  EXPECT_EQ(cv_adapter::compact(keep, descriptors, keys, depths), 3);
  EXPECT_EQ(descriptors.rows, 3);
  EXPECT_EQ(descriptors.at<std::uint8_t>(1, 31), 2);
  EXPECT_EQ(descriptors.at<std::uint8_t>(2, 0), 4);
  ASSERT_EQ(keys.size(), 3u);
  EXPECT_EQ(keys[2].pt.x, 4.f);
  EXPECT_EQ(depths, (std::vector<float>{0.f, 2.f, 4.f}));

  std::vector<float> short_vector(2);
  EXPECT_EQ(cv_adapter::compact(std::vector<std::uint8_t>(3, 0), descriptors, keys, short_vector), -1);
  EXPECT_EQ(descriptors.rows, 3);  // untouched
  EXPECT_EQ(keys.size(), 3u);
  // A matrix of another row count is refused the same way.
  cv::Mat two_rows(2, 32, CV_8UC1, cv::Scalar(1));
  EXPECT_EQ(cv_adapter::compact(std::vector<std::uint8_t>(3, 1), two_rows, keys), -1);
  EXPECT_EQ(two_rows.rows, 2);
}

TEST(CompiledCuller, CompactReadsAStridedRoiAndFloatDescriptors) {
  cv::Mat wide(5, 64, CV_8UC1, cv::Scalar(255));
  for (int r = 0; r < 5; ++r) wide(cv::Rect(0, r, 32, 1)).setTo(cv::Scalar(r));
  cv::Mat roi = wide(cv::Rect(0, 0, 32, 5));  // step 64 bytes
  std::vector<int> v{0, 1, 2, 3, 4};
  ASSERT_EQ(cv_adapter::compact({0, 1, 0, 1, 1}, roi, v), 3);
  ASSERT_EQ(roi.rows, 3);
  EXPECT_EQ(roi.at<std::uint8_t>(0, 0), 1);
  EXPECT_EQ(roi.at<std::uint8_t>(2, 31), 4);
  EXPECT_EQ(wide.at<std::uint8_t>(0, 40), 255);  // the bytes beyond the ROI are not touched
  EXPECT_EQ(v, (std::vector<int>{1, 3, 4}));
  // Learned float descriptors (HFNet / SuperPoint): rows of 256 floats.
  cv::Mat fdesc(3, 256, CV_32FC1);
  for (int i = 0; i < 3; ++i) fdesc.row(i).setTo(cv::Scalar(double(i) + 0.5));
  std::vector<double> w{1, 2, 3};
  ASSERT_EQ(cv_adapter::compact({1, 0, 1}, fdesc, w), 2);
  ASSERT_EQ(fdesc.rows, 2);
  EXPECT_EQ(fdesc.at<float>(1, 255), 2.5f);
  EXPECT_EQ(w, (std::vector<double>{1, 3}));
}

TEST(CompiledCuller, CompactRefusesMissingDescriptorsTheSameVectorTwiceAndAcceptsAnEmptyFrame) {
  const std::vector<std::uint8_t> keep{1, 0, 1, 0};
  std::vector<int> a{0, 1, 2, 3};
  cv::Mat none;  // a host without descriptors for 4 features is a mismatch, not a silent skip
  EXPECT_EQ(cv_adapter::compact(keep, none, a), -1);
  cv::Mat desc(4, 32, CV_8UC1, cv::Scalar(9));
  EXPECT_EQ(cv_adapter::compact(keep, desc, a, a), -1);  // it would be compacted twice
  EXPECT_EQ(a.size(), 4u);
  EXPECT_EQ(desc.rows, 4);
  cv::Mat cube(std::vector<int>{4, 2, 2}, CV_8UC1, cv::Scalar(0));
  EXPECT_EQ(cv_adapter::compact(keep, cube, a), -1);  // not one row per feature
  cv::Mat empty;
  std::vector<int> e;
  EXPECT_EQ(cv_adapter::compact({}, empty, e), 0);
}

TEST(CompiledCuller, DetectedBoxFromARectSpansItsWidthAndHeight) {
  const DetectedBox b = cv_adapter::detected_box(cv::Rect2f(10.f, 20.f, 30.f, 40.f), 0, 0.9f);
  EXPECT_EQ(b.x0, 10.f);
  EXPECT_EQ(b.y0, 20.f);
  EXPECT_EQ(b.x1, 40.f);
  EXPECT_EQ(b.y1, 60.f);
  EXPECT_EQ(b.class_id, 0);
  EXPECT_EQ(b.confidence, 0.9f);
  EXPECT_STREQ(to_string(Status::MissingInput), "missing input");
  EXPECT_STREQ(to_string(FeatureLabel::Dynamic), "dynamic");
}

}  // namespace
}  // namespace dyncull
