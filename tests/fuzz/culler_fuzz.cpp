// libFuzzer target: the public culler (dyncull::Culler, culling/culler.hpp) through its OpenCV overload
// (opencv/culler.hpp, cv_adapter::cull) and through its plain views, and the templated CullerCore<float>
// it runs (core_options<float> of the same CullerOptions), on several frames decoded from the input:
// random intrinsics (absurd ones too) and distortion, a random preset and keyframe thresholds; per frame
// random or clustered keypoints with NaN / Inf / huge coordinates, descriptors of random and changing
// widths (sometimes of another row count or type), depth of random type and size, random boxes, poses
// that are rigid, noisy, sheared, scaled, reflected or beyond float's range, and undistorted copies of the
// right or wrong length. Checks the frame contract on every frame: the OpenCV overload and the plain
// views give the same keep mask, labels, status and reason, and so does the core whenever it can hold
// the frame (a float pose; containers the plain views express); the mask is parallel to the keypoints; a
// refused frame keeps all, a culled one keeps exactly its Static features and never a non-finite
// keypoint; a non-Ok status has a printable reason.
#include "dyncull/culling/culler.hpp"
#include "dyncull/culling/culler_core.hpp"
#include "dyncull/opencv/culler.hpp"

#include "fuzz_input.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace {

using namespace dyncull;

const char* const kPresets[] = {"recommended", "none", "dld_slam", "rtd_slam", "zhu_2024", "dfd_slam", "zhang_2023"};

bool printable(const std::string& s) {
  for (char c : s)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e) return false;
  return true;
}

cv::Mat random_K(fuzz::Input& in, int W, int H) {
  if (in.u8() % 4 != 0) {  // mostly a camera that exists
    const double f = in.value(0.3 * W, 3.0 * W);
    return (cv::Mat_<double>(3, 3) << f, 0, in.value(0, W), 0, f, in.value(0, H), 0, 0, 1);
  }
  cv::Mat K = (cv::Mat_<double>(3, 3) << in.value(-10, 1e6), 0, in.value(-1e4, 1e4), 0, in.value(-10, 1e6),
               in.value(-1e4, 1e4), 0, 0, 1);
  if (in.u8() == 0) K.at<double>(0, 1) = in.value(-1, 1);
  return K;
}

/// cam_from_world: rigid, rigid with noise, or a random matrix (zero, scaled, sheared, reflected, huge).
cv::Mat random_pose(fuzz::Input& in) {
  cv::Mat T = cv::Mat::eye(4, 4, CV_64F);
  const int kind = in.range(0, 5);
  if (kind <= 2) {
    cv::Vec3d w(in.value(-1, 1), in.value(-1, 1), in.value(-1, 1));
    if (std::isfinite(w[0]) && std::isfinite(w[1]) && std::isfinite(w[2]) && cv::norm(w) < 10) {
      cv::Mat R;
      cv::Rodrigues(cv::Mat(w), R);
      R.copyTo(T(cv::Rect(0, 0, 3, 3)));
    }
    if (kind == 1) T.at<double>(in.range(0, 2), in.range(0, 2)) += in.value(-1e-3, 1e-3);
  } else {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) T.at<double>(r, c) = in.value(-2, 2);
  }
  for (int r = 0; r < 3; ++r) T.at<double>(r, 3) = in.value(-1, 1);
  if (in.u8() == 0) T.at<double>(3, in.range(0, 3)) = in.value(-1, 2);
  return T;
}

/// The frame contract on the OpenCV overload's result `a`, and `b` (another form's) equal to it.
void check_frame(const std::vector<cv::KeyPoint>& keys, const CullerResult& a, const CullerResult* b) {
  const std::size_t n = keys.size();
  DYNCULL_FUZZ_CHECK(a.keep.size() == n && a.labels.size() == n && a.reasons.size() == n && a.track_ids.size() == n);
  DYNCULL_FUZZ_CHECK(a.status == Status::Ok || !a.reason.empty());
  DYNCULL_FUZZ_CHECK(printable(a.reason));
  if (b) {
    DYNCULL_FUZZ_CHECK(a.status == b->status);
    DYNCULL_FUZZ_CHECK(a.reason == b->reason);
    DYNCULL_FUZZ_CHECK(a.keep == b->keep && a.refused == b->refused);
    DYNCULL_FUZZ_CHECK(a.labels == b->labels && a.reasons == b->reasons);
    DYNCULL_FUZZ_CHECK(a.track_ids == b->track_ids);
    DYNCULL_FUZZ_CHECK(a.frames_since_keyframe == b->frames_since_keyframe && a.keyframe == b->keyframe);
    DYNCULL_FUZZ_CHECK(a.matched == b->matched && a.num_kept == b->num_kept);
  }
  std::size_t kept = 0;
  for (std::size_t i = 0; i < n; ++i) {
    kept += a.keep[i];
    if (a.refused) {
      DYNCULL_FUZZ_CHECK(a.keep[i] == 1);
      continue;
    }
    DYNCULL_FUZZ_CHECK(a.keep[i] == (a.labels[i] == FeatureLabel::Static ? 1 : 0));
    if (!std::isfinite(keys[i].pt.x) || !std::isfinite(keys[i].pt.y)) DYNCULL_FUZZ_CHECK(a.keep[i] == 0);
  }
  DYNCULL_FUZZ_CHECK(a.num_kept == kept);
}

/// The keypoints through the lens model as Culler undistorts them when the host gives no copy
/// (src/culling/culler.cpp): cv::undistortPoints in float, a non-finite keypoint left as it is.
std::vector<cv::Point2f> undistort_as_the_culler(const std::vector<cv::KeyPoint>& keys, const CullerCamera& c) {
  std::vector<cv::Point2f> in(keys.size()), out;
  for (std::size_t i = 0; i < keys.size(); ++i) in[i] = keys[i].pt;
  if (in.empty()) return in;
  const cv::Mat K = (cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
  cv::undistortPoints(in, out, K, cv::Mat(c.distortion, true), cv::noArray(), K);
  for (std::size_t i = 0; i < in.size(); ++i)
    if (!std::isfinite(in[i].x) || !std::isfinite(in[i].y)) out[i] = in[i];
  return out;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::Input in(data, size);
  const int W = in.range(1, 160), H = in.range(1, 120);
  const cv::Mat K = random_K(in, W, H);
  cv::Mat distortion;
  if (in.u8() % 4 == 0) distortion = (cv::Mat_<double>(1, 5) << in.value(-0.3, 0.3), in.value(-0.3, 0.3), 0, 0, 0);
  const int preset = in.range(0, 7);  // 7: a name no preset has, with bytes a terminal would act on
  CullerOptions co(preset < 7 ? kPresets[preset] : std::string("\x1b[2J\0x", 6) + std::string(in.range(0, 3000), 'p'));
  co.depth_units_per_metre = in.flag() ? 5000.0 : in.value(-1, 1e4);
  if (!in.flag()) co.keyframe_max_translation_m = in.value(-1, 1);
  if (!in.flag()) co.keyframe_max_rotation_deg = in.value(-1, 200);
  if (!in.flag()) co.keyframe_min_matched_ratio = in.value(-0.5, 1.5);
  const CullerCamera camera = cv_adapter::culler_camera(K, cv::Size(W, H), distortion);
  Culler by_cv(camera, co), by_views(camera, co);
  DYNCULL_FUZZ_CHECK(by_cv.status() == by_views.status() && by_cv.reason() == by_views.reason());
  DYNCULL_FUZZ_CHECK(by_cv.ok() || printable(by_cv.reason()));
  // The core the public culler runs: compared only when the public one is ok (it then must be too; a bad
  // setting the core does not have, e.g. depth_units_per_metre, leaves it nothing to compare).
  CullerCoreOptions<float> core_opts = core_options<float>(co);
  core_opts.camera_has_distortion = camera.has_distortion();
  const PinholeCamera<float> pinhole{static_cast<float>(camera.fx), static_cast<float>(camera.fy),
                                     static_cast<float>(camera.cx), static_cast<float>(camera.cy), camera.width,
                                     camera.height};
  CullerCore<float> core(pinhole, core_opts);
  bool core_in_step = by_cv.ok();
  if (core_in_step) DYNCULL_FUZZ_CHECK(core.status() == Status::Ok);

  std::vector<cv::KeyPoint> keys, undistorted;
  std::vector<Detection<float>> boxes;
  std::vector<DetectedBox> dboxes;
  std::size_t width = static_cast<std::size_t>(in.flag() ? 32 : in.range(1, 300));
  const int frames = in.range(1, 4);
  for (int f = 0; f < frames && !in.empty(); ++f) {
    const std::size_t n = static_cast<std::size_t>(in.range(0, 300));
    const bool clustered = in.flag();
    const double cx = in.value(0, W), cy = in.value(0, H);
    keys.resize(n);
    for (auto& k : keys) {
      k = cv::KeyPoint();
      k.size = 31.f;
      if (clustered)
        k.pt = cv::Point2f(static_cast<float>(cx + 20.0 * in.unit()), static_cast<float>(cy + 20.0 * in.unit()));
      else
        k.pt = cv::Point2f(in.scalar<float>(-5, W + 5), in.scalar<float>(-5, H + 5));
    }
    if (in.u8() % 4 == 0) width = static_cast<std::size_t>(in.flag() ? 64 : in.range(1, 300));
    cv::Mat descriptors;
    const int desc_mode = in.range(0, 7);  // 0 none, 1 one row short, 2 float rows, else right
    if (desc_mode != 0) {
      const int rows = static_cast<int>(n) - (desc_mode == 1 ? 1 : 0);
      if (rows > 0) {
        descriptors.create(rows, static_cast<int>(width), desc_mode == 2 ? CV_32FC1 : CV_8UC1);
        for (int r = 0; r < rows; ++r) {
          const std::uint8_t base = in.u8();
          std::uint8_t* p = descriptors.ptr<std::uint8_t>(r);
          for (std::size_t b = 0; b < descriptors.cols * descriptors.elemSize(); ++b)
            p[b] = static_cast<std::uint8_t>(base * 31 + b * 7 + (r % 5));
        }
      }
    }
    cv::Mat depth;
    const int depth_mode = in.range(0, 4);  // 0 none, 1 wrong size, 2 8-bit, 3 metres, 4 raw
    const cv::Size ds = depth_mode == 1 ? cv::Size(W + 1, H) : cv::Size(W, H);
    if (depth_mode == 1 || depth_mode == 3) {
      depth = cv::Mat(ds, CV_32FC1, cv::Scalar(static_cast<float>(in.value(0, 8))));
      if (in.flag()) depth(cv::Rect(0, 0, (W + 1) / 2, H)).setTo(cv::Scalar(static_cast<float>(in.value(0, 8))));
    } else if (depth_mode == 2) {
      depth = cv::Mat(ds, CV_8UC1, cv::Scalar(3));
    } else if (depth_mode == 4) {
      depth = cv::Mat(ds, CV_16UC1, cv::Scalar(static_cast<double>(in.u16())));
    }
    const std::size_t nb = static_cast<std::size_t>(in.range(0, 4));
    boxes.resize(nb);
    dboxes.resize(nb);
    for (std::size_t b = 0; b < nb; ++b) {
      const float x0 = in.scalar<float>(-10, W + 10), y0 = in.scalar<float>(-10, H + 10);
      boxes[b].box = Box<float>{x0, y0, x0 + in.scalar<float>(-5, W), y0 + in.scalar<float>(-5, H)};
      boxes[b].class_id = in.range(-2, 85);
      boxes[b].confidence = in.scalar<float>(0, 1);
      dboxes[b] = DetectedBox(boxes[b].box.x0, boxes[b].box.y0, boxes[b].box.x1, boxes[b].box.y1, boxes[b].class_id,
                              boxes[b].confidence);
    }
    cv::Mat pose;
    const bool has_pose = in.u8() % 4 != 0;
    if (has_pose) pose = random_pose(in);
    const int und_mode = in.range(0, 5);  // 0 copy, 1 wrong length, 2 copy with a NaN, else none
    const std::vector<cv::KeyPoint>* und = nullptr;
    if (und_mode <= 2) {
      undistorted = keys;
      if (und_mode == 1) undistorted.resize(n + 1);
      if (und_mode == 2 && n > 0) undistorted[in.range(0, static_cast<int>(n) - 1)].pt.y = std::numeric_limits<float>::quiet_NaN();
      und = &undistorted;
    }
    const cv::Mat* Tcw = has_pose ? &pose : nullptr;
    if (in.u8() == 0) {
      by_cv.reset();
      by_views.reset();
      core.reset();
    }
    const CullerResult& a = cv_adapter::cull(by_cv, keys, descriptors, depth, dboxes, Tcw, und);

    // What the OpenCV overload refuses before the culler sees the frame: containers the plain views
    // cannot express. A refusal leaves the culler's state as it was, so the other forms skip the frame.
    const bool bad_descriptors = !descriptors.empty() && descriptors.type() != CV_8UC1;
    const bool bad_depth = !depth.empty() && depth.type() != CV_32FC1 && depth.type() != CV_16UC1;
    const bool bad_last_row = has_pose && !(pose.at<double>(3, 0) == 0.0 && pose.at<double>(3, 1) == 0.0 &&
                                            pose.at<double>(3, 2) == 0.0 && pose.at<double>(3, 3) == 1.0);
    if (by_cv.ok() && (bad_descriptors || bad_depth || bad_last_row)) {
      DYNCULL_FUZZ_CHECK(a.refused && a.status == Status::InvalidInput);
      check_frame(keys, a, nullptr);
      continue;
    }

    CullerFrame pf;
    pf.keypoints = points_view(keys);
    if (und) pf.undistorted_keypoints = points_view(*und);
    if (!descriptors.empty())
      pf.descriptors = DescriptorRows(descriptors.ptr<std::uint8_t>(0), static_cast<std::size_t>(descriptors.rows),
                                      descriptors.step[0], static_cast<std::size_t>(descriptors.cols));
    if (depth.type() == CV_32FC1 && !depth.empty()) {
      pf.depth_m.data = depth.ptr<float>(0);
      pf.depth_m.width = depth.cols;
      pf.depth_m.height = depth.rows;
      pf.depth_m.stride = static_cast<std::ptrdiff_t>(depth.step[0] / sizeof(float));
    } else if (!depth.empty()) {
      pf.depth_raw.data = depth.ptr<std::uint16_t>(0);
      pf.depth_raw.width = depth.cols;
      pf.depth_raw.height = depth.rows;
      pf.depth_raw.stride = static_cast<std::ptrdiff_t>(depth.step[0] / sizeof(std::uint16_t));
      pf.depth_raw.units_per_metre = static_cast<float>(co.depth_units_per_metre);
    }
    pf.detections = &dboxes;
    double Rt[12];
    if (has_pose) {
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) Rt[4 * r + c] = pose.at<double>(r, c);
      pf.cam_from_world = Rt;
    }
    const CullerResult& b = by_views.cull(pf);
    check_frame(keys, a, &b);
    if (!core_in_step) continue;

    // The core: the same views, the boxes as Detection<float>, the pose in float, the keypoints
    // undistorted here when the public culler undistorts them itself.
    CullerCoreFrame<float> cf;
    cf.keypoints = pf.keypoints;
    cf.undistorted_keypoints = pf.undistorted_keypoints;
    cf.descriptors = pf.descriptors;
    cf.depth_m = pf.depth_m;
    cf.depth_raw = pf.depth_raw;
    cf.detections = &boxes;
    std::vector<cv::Point2f> own_undistorted;
    if (!und && camera.has_distortion()) {
      own_undistorted = undistort_as_the_culler(keys, camera);
      cf.undistorted_keypoints = points_view(own_undistorted);
    }
    Rigid3<float> pose_f;
    if (has_pose) {
      double R[9], t[3];
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) R[3 * r + c] = Rt[4 * r + c];
        t[r] = Rt[4 * r + 3];
      }
      std::string why;
      // A pose the public culler refuses in double is not given to the core (a float may not hold it).
      if (culler_checks::check_pose(R, t, "cam_from_world", &why) != Status::Ok) {
        DYNCULL_FUZZ_CHECK(a.refused);
        continue;
      }
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) pose_f.R(r, c) = static_cast<float>(R[3 * r + c]);
        pose_f.t(r) = static_cast<float>(t[r]);
      }
      // Rounded to float, a rotation at the edge of the tolerance may fail the core's check: from there
      // on the core is no longer in step with the public culler.
      if (culler_checks::check_pose(pose_f, "cam_from_world", &why) != Status::Ok) {
        core_in_step = false;
        continue;
      }
      cf.cam_from_world = &pose_f;
    }
    check_frame(keys, a, &core.cull(cf));
  }
  return 0;
}
