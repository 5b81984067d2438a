// One frame contract for the culler's forms: the public dyncull::Culler (culling/culler.hpp, compiled into
// dyncull::culler) through its plain views and through its OpenCV overload (opencv/culler.hpp,
// cv_adapter::cull), and the templated CullerCore<float> it runs, set up with
// core_options<float>(CullerOptions()), get the same frames, good and bad (NaN / Inf keypoints, descriptor
// width changes, bad poses, absurd intrinsics, empty frames, mismatched sizes, bad strides), and give the
// same keep mask, labels, reasons, status and reason. Also the public forms' own findings: a double pose
// beyond float's range, a moved-from Culler, a quoted preset name, and a refused frame that keeps
// frames_since_keyframe.
#include "dyncull/culling/culler.hpp"
#include "dyncull/culling/culler_core.hpp"
#include "dyncull/opencv/culler.hpp"
#include "dyncull/opencv/views.hpp"

#include "support/culler_inputs.hpp"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace dyncull {
namespace {

using test::boxes_of;
using test::rows_of;

const cv::Mat kK = (cv::Mat_<double>(3, 3) << 525, 0, 319.5, 0, 525, 239.5, 0, 0, 1);
const cv::Size kSize(640, 480);

/// One frame as a host has it; each form gets it in its own containers.
struct Frame {
  std::vector<cv::KeyPoint> keys;
  cv::Mat descriptors;  // CV_8U rows, or empty
  cv::Mat depth;        // CV_32F metres, or empty (the OpenCV form also takes other types, to refuse them)
  std::vector<Detection<float>> boxes;
  cv::Mat Tcw;  // 4x4 CV_64F, or empty: no pose
  std::vector<cv::KeyPoint> undistorted;
  bool has_undistorted = false;
  std::size_t stride_bytes = 0;  // for the plain views (0: as the keys); the OpenCV form has no stride
};

/// A static scene seen from the same pose: 60 keypoints, each with its own descriptor, depth 2 m, a person
/// box over a quarter of them.
Frame good_frame(std::size_t width = 32) {
  Frame f;
  cv::RNG rng(7);
  for (int i = 0; i < 60; ++i) f.keys.emplace_back(cv::Point2f(20.f + 10.f * float(i), 60.f + 6.f * float(i % 11)), 31.f);
  f.descriptors.create(60, static_cast<int>(width), CV_8UC1);
  rng.fill(f.descriptors, cv::RNG::UNIFORM, 0, 256);
  f.depth = cv::Mat(480, 640, CV_32FC1, cv::Scalar(2.f));
  Detection<float> person;
  person.box = Box<float>{15.f, 50.f, 170.f, 130.f};
  person.class_id = 0;
  person.confidence = 0.9f;
  f.boxes.push_back(person);
  f.Tcw = cv::Mat::eye(4, 4, CV_64F);
  return f;
}

/// What the test compares, from any form.
struct Outcome {
  int status = 0;
  std::string reason;
  std::vector<std::uint8_t> keep;
  std::vector<int> labels, reasons;
  std::vector<std::int64_t> track_ids;
  int frames_since_keyframe = 0;
  bool keyframe = false;
  bool refused = false;
  std::size_t matched = 0;
};

Outcome outcome_of(const CullerResult& r) {
  Outcome o;
  o.status = static_cast<int>(r.status);
  o.reason = r.reason;
  o.keep = r.keep;
  for (FeatureLabel l : r.labels) o.labels.push_back(static_cast<int>(l));
  for (CullReason c : r.reasons) o.reasons.push_back(static_cast<int>(c));
  o.track_ids = r.track_ids;
  o.frames_since_keyframe = r.frames_since_keyframe;
  o.keyframe = r.keyframe;
  o.refused = r.refused;
  o.matched = r.matched;
  return o;
}


/// The public culler on the frame's data, read in place through plain views; the pose as 12 doubles.
class PlainForm {
 public:
  explicit PlainForm(const cv::Mat& K, const CullerOptions& o = CullerOptions())
      : culler_(cv_adapter::culler_camera(K, kSize), o) {}
  Outcome cull(const Frame& in) {
    CullerFrame f;
    f.keypoints = points_view(in.keys);
    if (in.stride_bytes != 0) f.keypoints.stride_bytes = in.stride_bytes;
    if (in.has_undistorted) f.undistorted_keypoints = points_view(in.undistorted);
    if (!in.descriptors.empty()) f.descriptors = rows_of(in.descriptors);
    if (!in.depth.empty()) f.depth_m = cv_adapter::depth_view_f32(in.depth);
    boxes_ = boxes_of(in.boxes);
    f.detections = &boxes_;
    if (!in.Tcw.empty()) {
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) Rt_[4 * r + c] = in.Tcw.at<double>(r, c);
      f.cam_from_world = Rt_;
    }
    return outcome_of(culler_.cull(f));
  }
  Culler culler_;

 private:
  std::vector<DetectedBox> boxes_;
  double Rt_[12];
};

/// The public culler through the OpenCV overload.
class CvForm {
 public:
  explicit CvForm(const cv::Mat& K, const CullerOptions& o = CullerOptions())
      : culler_(cv_adapter::culler_camera(K, kSize), o) {}
  Outcome cull(const Frame& in) {
    const std::vector<DetectedBox> boxes = boxes_of(in.boxes);
    return outcome_of(cv_adapter::cull(culler_, in.keys, in.descriptors, in.depth, boxes,
                                       in.Tcw.empty() ? nullptr : &in.Tcw,
                                       in.has_undistorted ? &in.undistorted : nullptr));
  }
  Culler culler_;
};

/// The templated core the public culler runs, with the options it derives from CullerOptions. Its pose is
/// a Rigid3<float>: a double pose beyond float's range cannot be given to it.
class CoreForm {
 public:
  explicit CoreForm(const cv::Mat& K, const CullerOptions& o = CullerOptions())
      : culler_(camera_of(K), core_options<float>(o)) {}
  Outcome cull(const Frame& in) {
    CullerCoreFrame<float> f;
    f.keypoints = points_view(in.keys);
    if (in.stride_bytes != 0) f.keypoints.stride_bytes = in.stride_bytes;
    if (in.has_undistorted) f.undistorted_keypoints = points_view(in.undistorted);
    if (!in.descriptors.empty()) f.descriptors = rows_of(in.descriptors);
    if (!in.depth.empty()) f.depth_m = cv_adapter::depth_view_f32(in.depth);
    f.detections = &in.boxes;
    if (!in.Tcw.empty()) {
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) pose_.R(r, c) = static_cast<float>(in.Tcw.at<double>(r, c));
        pose_.t(r) = static_cast<float>(in.Tcw.at<double>(r, 3));
      }
      f.cam_from_world = &pose_;
    }
    return outcome_of(culler_.cull(f));
  }
  CullerCore<float> culler_;

 private:
  static PinholeCamera<float> camera_of(const cv::Mat& K) {
    return PinholeCamera<float>{static_cast<float>(K.at<double>(0, 0)), static_cast<float>(K.at<double>(1, 1)),
                                static_cast<float>(K.at<double>(0, 2)), static_cast<float>(K.at<double>(1, 2)),
                                kSize.width, kSize.height};
  }
  Rigid3<float> pose_;
};

void expect_same(const Outcome& a, const Outcome& b, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(a.status, b.status);
  EXPECT_EQ(a.reason, b.reason);
  EXPECT_EQ(a.keep, b.keep);
  EXPECT_EQ(a.labels, b.labels);
  EXPECT_EQ(a.reasons, b.reasons);
  EXPECT_EQ(a.track_ids, b.track_ids);
  EXPECT_EQ(a.frames_since_keyframe, b.frames_since_keyframe);
  EXPECT_EQ(a.keyframe, b.keyframe);
  EXPECT_EQ(a.refused, b.refused);
  EXPECT_EQ(a.matched, b.matched);
}

/// Which forms get the frames: the OpenCV overload always; the plain views and the core when they can hold
/// the input.
struct Forms {
  bool plain = true, core = true;
};

/// Feeds the frames to the forms, each after a good first frame, compares every frame's outcome with the
/// OpenCV form's (or, without plain views on it, the plain form's) and returns the last one.
Outcome same_in_every_form(const std::vector<Frame>& frames, Forms forms = Forms(), bool cv_form = true) {
  PlainForm p(kK);
  CvForm c(kK);
  CoreForm k(kK);
  const Frame first = good_frame();
  const Outcome head = cv_form ? c.cull(first) : p.cull(first);
  if (cv_form && forms.plain) expect_same(p.cull(first), head, "first frame, plain views vs OpenCV overload");
  if (forms.core) expect_same(k.cull(first), head, "first frame, CullerCore<float> vs public culler");
  Outcome last = head;
  for (std::size_t n = 0; n < frames.size(); ++n) {
    const std::string step = "frame " + std::to_string(n + 1);
    last = cv_form ? c.cull(frames[n]) : p.cull(frames[n]);
    if (cv_form && forms.plain) expect_same(p.cull(frames[n]), last, step + ", plain views vs OpenCV overload");
    if (forms.core) expect_same(k.cull(frames[n]), last, step + ", CullerCore<float> vs public culler");
  }
  return last;
}

/// The status of a clean frame of good_frame()'s scene. The camera stands still, so the epipolar check of
/// moving consistency has no baseline to fit F on and reports Degenerate, naming itself: the frame status
/// is the worst of its stages. A frame's own finding (MissingInput) shows only when nothing worse does.
Outcome still_scene() { return same_in_every_form({good_frame()}); }

int worst_with_missing_input(int still_status) {
  return still_status == static_cast<int>(Status::Ok) ? static_cast<int>(Status::MissingInput) : still_status;
}

TEST(CullerContract, StillCameraGivesTheEpipolarCheckNoBaselineInEveryForm) {
  const Outcome still = still_scene();
  EXPECT_EQ(still.status, static_cast<int>(Status::Degenerate)) << still.reason;
  EXPECT_NE(still.reason.find("moving_consistency"), std::string::npos) << still.reason;
  EXPECT_EQ(still.keep.size(), 60u);
}

bool culled_as_invalid(const Outcome& o, std::size_t i) {
  return o.keep[i] == 0 && o.labels[i] == static_cast<int>(FeatureLabel::Dynamic) &&
         o.reasons[i] == static_cast<int>(CullReason::InvalidInput);
}

TEST(CullerContract, NonFiniteKeypointsAreCulledAndNamedAlikeInEveryForm) {
  Frame bad = good_frame();
  bad.keys[3].pt.x = std::numeric_limits<float>::quiet_NaN();
  bad.keys[40].pt.y = -std::numeric_limits<float>::infinity();
  const Outcome still = still_scene();
  const Outcome o = same_in_every_form({bad, good_frame()});
  EXPECT_EQ(o.status, still.status) << o.reason;  // the frame after is usable as ever
  EXPECT_EQ(o.reason, still.reason);

  const Outcome during = same_in_every_form({bad});
  EXPECT_EQ(during.status, worst_with_missing_input(still.status)) << during.reason;
  EXPECT_NE(during.reason.find("keypoints[3] and 1 other have a NaN or Inf coordinate: culled"), std::string::npos)
      << during.reason;
  EXPECT_TRUE(culled_as_invalid(during, 3));
  EXPECT_TRUE(culled_as_invalid(during, 40));
  EXPECT_GT(during.matched, 50u);  // the other keypoints were judged as usual

  Frame und = good_frame();
  und.undistorted = und.keys;
  und.has_undistorted = true;
  und.undistorted[8].pt.y = std::numeric_limits<float>::quiet_NaN();
  const Outcome u = same_in_every_form({und});
  EXPECT_EQ(u.status, worst_with_missing_input(still.status)) << u.reason;
  EXPECT_NE(u.reason.find("undistorted_keypoints[8] has a NaN or Inf coordinate: culled"), std::string::npos)
      << u.reason;
  EXPECT_TRUE(culled_as_invalid(u, 8));
}

TEST(CullerContract, DescriptorWidthChangeStartsANewKeyframeAlikeInEveryForm) {
  const Outcome still = still_scene();
  for (const std::size_t width : {std::size_t(64), std::size_t(33)}) {
    SCOPED_TRACE("rows of " + std::to_string(width) + " bytes");
    const Frame wide = good_frame(width);
    const Outcome o = same_in_every_form({wide});
    EXPECT_EQ(o.status, static_cast<int>(Status::MissingInput)) << o.reason;  // no keyframe match: no F fitted
    EXPECT_NE(o.reason.find("descriptors: rows of " + std::to_string(width) + " bytes where the keyframe's have 32"),
              std::string::npos)
        << o.reason;
    EXPECT_TRUE(o.keyframe);
    const Outcome after = same_in_every_form({wide, wide});
    EXPECT_EQ(after.status, still.status) << after.reason;
    EXPECT_EQ(after.matched, 60u);
  }
  const Outcome too_wide = same_in_every_form({good_frame(300), good_frame()});
  EXPECT_EQ(too_wide.status, still.status) << too_wide.reason;
  const Outcome refused = same_in_every_form({good_frame(300)});
  EXPECT_EQ(refused.status, static_cast<int>(Status::InvalidInput));
  EXPECT_NE(refused.reason.find("descriptors: rows of 300 bytes"), std::string::npos) << refused.reason;
  EXPECT_EQ(refused.keep, std::vector<std::uint8_t>(60, 1));
}

TEST(CullerContract, PoseThatIsNotRigidOrOutOfRangeIsRefusedAlikeInEveryForm) {
  const std::pair<const char*, cv::Mat> rotations[] = {
      {"zero", cv::Mat::zeros(3, 3, CV_64F)},
      {"doubled", 2 * cv::Mat::eye(3, 3, CV_64F)},
      {"reflection", (cv::Mat_<double>(3, 3) << 1, 0, 0, 0, 1, 0, 0, 0, -1)},
      {"shear", (cv::Mat_<double>(3, 3) << 1, 0.5, 0, 0, 1, 0, 0, 0, 1)}};
  for (const auto& r : rotations) {
    SCOPED_TRACE(r.first);
    Frame bad = good_frame();
    r.second.copyTo(bad.Tcw(cv::Rect(0, 0, 3, 3)));
    const Outcome o = same_in_every_form({bad});
    EXPECT_EQ(o.status, static_cast<int>(Status::InvalidInput));
    // The pose check is the culler's own, after the OpenCV overload read the matrix: it names the
    // culler's input, cam_from_world, in every form.
    EXPECT_NE(o.reason.find("cam_from_world's rotation is not a rotation"), std::string::npos) << o.reason;
    EXPECT_TRUE(o.refused);
    EXPECT_EQ(o.keep, std::vector<std::uint8_t>(60, 1));
  }
  Frame far = good_frame();
  far.Tcw.at<double>(1, 3) = 1e30;  // in float's range: the core reads it too
  const Outcome o = same_in_every_form({far});
  EXPECT_EQ(o.status, static_cast<int>(Status::InvalidInput));
  EXPECT_NE(o.reason.find("out of the range"), std::string::npos) << o.reason;
  Frame nan = good_frame();
  nan.Tcw.at<double>(0, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(same_in_every_form({nan}).status, static_cast<int>(Status::NonFinite));
  // Not [R t; 0 0 0 1]: only the OpenCV overload takes a 4x4 matrix, and it names its argument.
  Frame last_row = good_frame();
  last_row.Tcw.at<double>(3, 0) = 0.5;
  Forms cv_only;
  cv_only.plain = cv_only.core = false;
  const Outcome lr = same_in_every_form({last_row}, cv_only);
  EXPECT_EQ(lr.status, static_cast<int>(Status::InvalidInput));
  EXPECT_NE(lr.reason.find("predicted_Tcw must be a 4x4"), std::string::npos) << lr.reason;
}

TEST(CullerContract, DoublePoseBeyondFloatRangeIsOutOfRangeNotNonFinite) {
  for (const cv::Point at : {cv::Point(3, 0), cv::Point(1, 1)}) {
    Frame huge = good_frame();
    huge.Tcw.at<double>(at) = 1e300;
    Forms public_only;
    public_only.core = false;  // a float pose cannot hold 1e300
    const Outcome o = same_in_every_form({huge}, public_only);
    EXPECT_EQ(o.status, static_cast<int>(Status::InvalidInput)) << o.reason;
    EXPECT_NE(o.reason.find("cam_from_world has an entry of"), std::string::npos) << o.reason;
    EXPECT_NE(o.reason.find("out of the range"), std::string::npos) << o.reason;
    EXPECT_EQ(o.reason.find("NaN"), std::string::npos) << o.reason;
  }
}

TEST(CullerContract, AbsurdIntrinsicsAreRefusedInEveryForm) {
  const cv::Mat tiny_focal = (cv::Mat_<double>(3, 3) << 1e-42, 0, 319.5, 0, 525, 239.5, 0, 0, 1);
  const cv::Mat far_centre = (cv::Mat_<double>(3, 3) << 525, 0, 1e30, 0, 525, 239.5, 0, 0, 1);
  for (const auto& k : {std::make_pair("fx", tiny_focal), std::make_pair("cx", far_centre)}) {
    SCOPED_TRACE(k.first);
    PlainForm p(k.second);
    CvForm c(k.second);
    CoreForm d(k.second);
    EXPECT_FALSE(p.culler_.ok());
    EXPECT_FALSE(c.culler_.ok());
    EXPECT_EQ(d.culler_.status(), Status::InvalidInput);
    EXPECT_NE(c.culler_.reason().find(std::string("camera: ") + k.first + " = "), std::string::npos)
        << c.culler_.reason();
    EXPECT_EQ(c.culler_.reason(), d.culler_.reason());
    const Frame in = good_frame();
    const Outcome a = p.cull(in), b = c.cull(in), e = d.cull(in);
    for (const Outcome* o : {&a, &b, &e}) {
      EXPECT_EQ(o->status, static_cast<int>(Status::InvalidInput));
      EXPECT_NE(o->reason.find(std::string(k.first) + " = "), std::string::npos) << o->reason;
      EXPECT_EQ(o->keep, std::vector<std::uint8_t>(60, 1));
    }
    expect_same(a, b, "plain views vs OpenCV overload");
    expect_same(e, b, "CullerCore<float> vs public culler");
  }
}

TEST(CullerContract, EmptyFrameIsAlikeInEveryFormAndLacksNoDescriptors) {
  Frame empty = good_frame();
  empty.keys.clear();
  empty.descriptors = cv::Mat();
  const Outcome o = same_in_every_form({empty});
  EXPECT_TRUE(o.keep.empty());
  EXPECT_EQ(o.reason.find("descriptors"), std::string::npos) << o.reason;
  const Outcome after = same_in_every_form({empty, good_frame()});
  EXPECT_EQ(after.keep.size(), 60u);
}

TEST(CullerContract, MismatchedSizesAndBadStridesAreRefusedAlikeInEveryForm) {
  Frame rows = good_frame();
  rows.descriptors = rows.descriptors.rowRange(0, 59).clone();
  Outcome o = same_in_every_form({rows});
  EXPECT_EQ(o.status, static_cast<int>(Status::InvalidInput));
  EXPECT_NE(o.reason.find("descriptors has 59 rows for 60 keypoints"), std::string::npos) << o.reason;

  Frame und = good_frame();
  und.undistorted.assign(und.keys.begin(), und.keys.begin() + 5);
  und.has_undistorted = true;
  o = same_in_every_form({und});
  EXPECT_NE(o.reason.find("undistorted_keypoints has 5 points for 60 keypoints"), std::string::npos) << o.reason;

  Frame depth = good_frame();
  depth.depth = cv::Mat(240, 320, CV_32FC1, cv::Scalar(2.f));
  o = same_in_every_form({depth});
  EXPECT_NE(o.reason.find("depth: 320x240 for an image of 640x480"), std::string::npos) << o.reason;

  Frame stride = good_frame();
  stride.stride_bytes = 4;  // the OpenCV overload takes point vectors only: no stride to get wrong
  o = same_in_every_form({stride}, Forms(), /*cv_form=*/false);
  EXPECT_EQ(o.status, static_cast<int>(Status::InvalidInput));
  EXPECT_NE(o.reason.find("keypoints: stride_bytes 4 is below the 8 bytes of an x, y pair"), std::string::npos)
      << o.reason;
  EXPECT_EQ(o.keep, std::vector<std::uint8_t>(60, 1));
}

TEST(CullerContract, RefusedFrameKeepsFramesSinceKeyframeInEveryForm) {
  // Refused by the core's checks (descriptor rows), by its check of a plain view's stride, and by the
  // OpenCV overload's reading of a cv::Mat (8-bit depth, through Culler::refuse): the count goes on in each.
  Frame rows = good_frame();
  rows.descriptors = rows.descriptors.rowRange(0, 59).clone();
  Frame stride = good_frame();
  stride.stride_bytes = 4;
  Frame bytes = good_frame();
  bytes.depth = cv::Mat(480, 640, CV_8UC1, cv::Scalar(2));
  Forms all, views, cv_only;
  cv_only.plain = cv_only.core = false;
  const struct {
    const char* what;
    Frame frame;
    Forms forms;
    bool cv_form;
  } cases[] = {{"descriptor rows", rows, all, true}, {"stride", stride, views, false}, {"8-bit depth", bytes, cv_only, true}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    const Outcome o = same_in_every_form({good_frame(), good_frame(), c.frame}, c.forms, c.cv_form);
    EXPECT_EQ(o.status, static_cast<int>(Status::InvalidInput)) << o.reason;
    EXPECT_TRUE(o.refused);
    EXPECT_EQ(o.frames_since_keyframe, 3);
  }
}

TEST(CullerContract, ResetStartsAgainInEveryForm) {
  PlainForm p(kK);
  CvForm c(kK);
  CoreForm k(kK);
  for (int n = 0; n < 2; ++n) {
    p.cull(good_frame());
    c.cull(good_frame());
    k.cull(good_frame());
  }
  p.culler_.reset();
  c.culler_.reset();
  k.culler_.reset();
  EXPECT_EQ(c.culler_.keyframe_size(), 0u);
  const Outcome a = p.cull(good_frame()), b = c.cull(good_frame()), d = k.cull(good_frame());
  expect_same(a, b, "after reset, plain views vs OpenCV overload");
  expect_same(d, b, "after reset, CullerCore<float> vs public culler");
  EXPECT_TRUE(b.keyframe);
  EXPECT_EQ(b.matched, 0u);
  EXPECT_EQ(b.track_ids.front(), 0);
  EXPECT_EQ(c.culler_.keyframe_size(), 60u);
}

TEST(PublicCullerContract, MovedFromCullerKeepsAllParallelToTheKeys) {
  Culler a(cv_adapter::culler_camera(kK, kSize));
  Culler b(std::move(a));
  EXPECT_TRUE(b.ok());
  const Frame in = good_frame();
  const std::vector<DetectedBox> boxes = boxes_of(in.boxes);
  // NOLINTNEXTLINE(bugprone-use-after-move): the moved-from state is what is tested
  const CullerResult& r = cv_adapter::cull(a, in.keys, in.descriptors, in.depth, boxes, &in.Tcw);
  EXPECT_EQ(r.keep, std::vector<std::uint8_t>(60, 1));
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_TRUE(r.refused);
  EXPECT_NE(r.reason.find("moved from"), std::string::npos) << r.reason;
  EXPECT_EQ(r.labels.size(), 60u);
  std::vector<cv::Point2f> points;
  cv::KeyPoint::convert(in.keys, points);
  EXPECT_EQ(cv_adapter::cull(a, points, in.descriptors, in.depth, boxes).keep, std::vector<std::uint8_t>(60, 1));
  CullerFrame seven;
  seven.keypoints = PointsView::of(&points[0].x, 7);
  seven.depth_m = cv_adapter::depth_view_f32(in.depth);
  seven.detections = &boxes;
  EXPECT_EQ(a.cull(seven).keep, std::vector<std::uint8_t>(7, 1));
  EXPECT_EQ(a.result().status, Status::InvalidInput);
  EXPECT_FALSE(a.ok());
}

TEST(PublicCullerContract, PresetNameIsQuotedInTheReason) {
  const CullerOptions options("\x1b[31mred" + std::string(5000, 'k') + std::string(1, '\0') + "after");
  Culler culler(cv_adapter::culler_camera(kK, kSize), options);
  EXPECT_EQ(culler.status(), Status::InvalidInput);
  const std::string& why = culler.reason();
  EXPECT_EQ(why.find('\x1b'), std::string::npos) << why;
  EXPECT_EQ(why.find('\0'), std::string::npos);
  EXPECT_LT(why.size(), 200u) << why;
  EXPECT_NE(why.find("'\\x1b[31mred"), std::string::npos) << why;
  EXPECT_NE(why.find("is not one of"), std::string::npos) << why;  // the text after the name is not cut
}

}  // namespace
}  // namespace dyncull
