// libFuzzer target: the stateful culler through its OpenCV forms, cv_adapter::FrameCuller and
// cv_adapter::CompiledCuller, on several frames decoded from the input: random intrinsics (absurd ones
// too) and distortion, a random preset and keyframe thresholds; per frame random or clustered keypoints
// with NaN / Inf / huge coordinates, descriptors of random and changing widths (sometimes of another row
// count), depth of random type and size, random boxes, poses that are rigid, noisy, sheared, scaled,
// reflected or beyond float's range, and undistorted copies of the right or wrong length. Checks the
// frame contract on every frame: both forms give the same keep mask, labels, status and reason; the mask
// is parallel to the keypoints; a refused frame keeps all, a culled one keeps exactly its Static features
// and never a non-finite keypoint; a non-Ok status has a printable reason.
#include "dyncull/opencv/compiled_culler.hpp"
#include "dyncull/opencv/culler.hpp"

#include "fuzz_input.hpp"

#include <opencv2/core.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace {

using namespace dyncull;
using cv_adapter::CompiledCuller;
using cv_adapter::DetectedBox;
using cv_adapter::FrameCuller;

const char* const kPresets[] = {"recommended", "none", "dld_slam", "rtd_slam", "zhu_2024", "dfd_slam", "zhang_2023"};

PipelineOptions<float> preset_options(int k) {
  switch (k) {
    case 1: return presets::none<float>();
    case 2: return presets::dld_slam<float>();
    case 3: return presets::rtd_slam<float>();
    case 4: return presets::zhu_2024<float>();
    case 5: return presets::dfd_slam<float>();
    case 6: return presets::zhang_2023<float>();
    default: return presets::recommended<float>();
  }
}

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

void check_frame(const std::vector<cv::KeyPoint>& keys, const CullerResult& a, const CompiledCuller::Result& b,
                 bool comparable) {
  const std::size_t n = keys.size();
  DYNCULL_FUZZ_CHECK(b.keep.size() == n && b.labels.size() == n && b.reasons.size() == n && b.track_ids.size() == n);
  DYNCULL_FUZZ_CHECK(b.status == CompiledCuller::Status::Ok || !b.reason.empty());
  DYNCULL_FUZZ_CHECK(printable(b.reason));
  if (!comparable) {
    for (std::uint8_t k : b.keep) DYNCULL_FUZZ_CHECK(k == 1);
    return;
  }
  DYNCULL_FUZZ_CHECK(static_cast<int>(a.status) == static_cast<int>(b.status));
  DYNCULL_FUZZ_CHECK(a.reason == b.reason);
  DYNCULL_FUZZ_CHECK(a.keep == b.keep && a.refused == b.refused);
  DYNCULL_FUZZ_CHECK(a.track_ids == b.track_ids);
  DYNCULL_FUZZ_CHECK(a.frames_since_keyframe == b.frames_since_keyframe && a.keyframe == b.keyframe);
  DYNCULL_FUZZ_CHECK(a.labels.size() == n);
  std::size_t kept = 0;
  for (std::size_t i = 0; i < n; ++i) {
    DYNCULL_FUZZ_CHECK(static_cast<int>(a.labels[i]) == static_cast<int>(b.labels[i]));
    DYNCULL_FUZZ_CHECK(static_cast<int>(a.reasons[i]) == static_cast<int>(b.reasons[i]));
    kept += a.keep[i];
    if (a.refused) {
      DYNCULL_FUZZ_CHECK(a.keep[i] == 1);
      continue;
    }
    if (a.keep.empty()) continue;
    DYNCULL_FUZZ_CHECK(a.keep[i] == (a.labels[i] == FeatureLabel::Static ? 1 : 0));
    if (!std::isfinite(keys[i].pt.x) || !std::isfinite(keys[i].pt.y)) DYNCULL_FUZZ_CHECK(a.keep[i] == 0);
  }
  DYNCULL_FUZZ_CHECK(a.num_kept == kept && b.num_kept == kept);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::Input in(data, size);
  const int W = in.range(1, 160), H = in.range(1, 120);
  const cv::Mat K = random_K(in, W, H);
  cv::Mat distortion;
  if (in.u8() % 4 == 0) distortion = (cv::Mat_<double>(1, 5) << in.value(-0.3, 0.3), in.value(-0.3, 0.3), 0, 0, 0);
  const int preset = in.range(0, 7);  // 7: a name no preset has, with bytes a terminal would act on
  CompiledCuller::Options co;
  co.preset = preset < 7 ? kPresets[preset] : std::string("\x1b[2J\0x", 6) + std::string(in.range(0, 3000), 'p');
  co.depth_units_per_metre = in.flag() ? 5000.f : static_cast<float>(in.value(-1, 1e4));
  co.keyframe_max_translation_m = in.flag() ? 0.1 : in.value(-1, 1);
  co.keyframe_max_rotation_deg = in.flag() ? 15.0 : in.value(-1, 200);
  co.keyframe_min_matched_ratio = in.flag() ? 0.3 : in.value(-0.5, 1.5);
  CullerOptions<float> fo;
  fo.pipeline = preset_options(preset);
  fo.keyframe_max_translation_m = co.keyframe_max_translation_m;
  fo.keyframe_max_rotation_deg = co.keyframe_max_rotation_deg;
  fo.keyframe_min_matched_ratio = co.keyframe_min_matched_ratio;
  const bool comparable = preset < 7;  // a known preset: both forms run the same options
  FrameCuller frame_culler(K, cv::Size(W, H), distortion, fo, co.depth_units_per_metre);
  CompiledCuller compiled(K, cv::Size(W, H), distortion, co);
  if (comparable) DYNCULL_FUZZ_CHECK(frame_culler.ok() == compiled.ok() && frame_culler.reason() == compiled.reason());
  DYNCULL_FUZZ_CHECK(compiled.ok() || printable(compiled.reason()));

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
      frame_culler.reset();
      compiled.reset();
    }
    frame_culler.cull(keys, descriptors, depth, boxes, Tcw, und);
    compiled.cull(keys, descriptors, depth, dboxes, Tcw, und);
    check_frame(keys, frame_culler.result(), compiled.result(), comparable);
  }
  return 0;
}
