/// @file multiview.hpp
/// The multi-view check of RTD-SLAM 2024 §III.A (after DynaSLAM, Bescos et al. 2018) as an evidence stage:
/// stored keyframes' points projected into the current depth image (depth difference and parallax,
/// multiview_check.hpp), the moving points grown into a mask over the depth image, read at each feature.
#pragma once

#include "dyncull/core/mask.hpp"
#include "dyncull/culling/labels.hpp"
#include "dyncull/culling/multiview_check.hpp"
#include "dyncull/culling/stages/stage.hpp"
#include "dyncull/culling/validation.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace dyncull {

/// The multi-view check's options with its switch and how many keyframes it compares with.
template <class T>
struct MultiViewStageOptions : MultiViewOptions<T> {
  bool enabled = false;
  std::size_t max_reference_keyframes = 2;  ///< keyframes checked per frame (DynaSLAM: 5)

  static constexpr std::size_t kMaxReferenceKeyframes = 64;

  /// MultiViewOptions::validate, then max_reference_keyframes in [1, 64].
  Status validate(std::string* reason = nullptr) const {
    if (MultiViewOptions<T>::validate(reason) != Status::Ok) return Status::InvalidInput;
    if (max_reference_keyframes < 1 || max_reference_keyframes > kMaxReferenceKeyframes)
      return detail::invalid_option(reason, "max_reference_keyframes", "must be in [1, 64]");
    if (reason) reason->clear();
    return Status::Ok;
  }
};

/// The multi-view check (needs the current pose, depth and a stored keyframe). Its flags cull wherever
/// they are (DynaSLAM).
template <class T>
struct MultiViewStage {
  static constexpr const char* kName = "multiview";
  static constexpr StageKind kKind = StageKind::Evidence;
  static constexpr CullReason kReason = CullReason::MultiView;
  using Options = MultiViewStageOptions<T>;
  struct OptionsSlot {
    Options multiview{};
  };
  struct ReportSlot {
    StageReport multiview;
  };
  static constexpr Options OptionsSlot::*kOptions = &OptionsSlot::multiview;
  static constexpr StageReport ReportSlot::*kReport = &ReportSlot::multiview;

  struct Work {
    MultiViewResult<T> check;
    Mask mask;
    std::vector<std::uint32_t> flood_stack;
    std::vector<std::size_t> ref_index;
  };

  static constexpr FrameInputs needs(const Options&) {
    return FrameInput::CamFromWorld | FrameInput::Depth | FrameInput::ReferenceKeyframe;
  }
  static constexpr FrameInputs uses(const Options&) { return 0; }

  template <class Frame, class Context>
  static void run(const Frame& frame, const Options& options, const Context& context, Work* work,
                  std::uint8_t* dynamic, StageReport* report) {
    const std::size_t checked = grow_moving_regions(frame, options, context.keyframes, work);
    if (checked == 0) {
      report->status = Status::TooFewPoints;
      report->reason = "no keyframe point could be compared";
      return;
    }
    report->status = Status::Ok;
    const auto& kp = *frame.keypoints;
    const Mask& mask = work->mask;
    for (std::size_t i = 0; i < static_cast<std::size_t>(kp.size()); ++i) {
      int u = 0, v = 0;
      if (detail::keypoint_in_image<T>(kp, i, mask.width, mask.height, &u, &v))
        dynamic[i] = mask.pixels[static_cast<std::size_t>(v) * mask.width + u] != 0;
    }
  }

  /// work->mask: the regions grown from the moving points of the nearest stored keyframes; returns the
  /// number of keyframes with a point to compare. Seeds grow over the whole image: a flag culls wherever
  /// it is (DynaSLAM).
  template <class Frame>
  static std::size_t grow_moving_regions(const Frame& frame, const Options& options,
                                         const KeyframeRing<T>& keyframes, Work* work) {
    Work& m = *work;
    PixelRect roi{0, 0, frame.depth.width, frame.depth.height};
    m.ref_index.resize(std::max<std::size_t>(1, std::min(options.max_reference_keyframes, keyframes.size())));
    const std::size_t k =
        keyframes.select_references(*frame.cam_from_world, options.max_reference_keyframes, m.ref_index.data());
    if (m.mask.width != frame.depth.width || m.mask.height != frame.depth.height)
      m.mask.reset(frame.depth.width, frame.depth.height, 0);
    else
      std::fill(m.mask.pixels.begin(), m.mask.pixels.end(), std::uint8_t(0));
    std::size_t checked = 0;
    for (std::size_t j = 0; j < k; ++j) {
      const MultiViewKeyframe<T>& kf = keyframes[m.ref_index[j]];
      check_multiview(kf.points, kf.depth_m, kf.cam_from_world, *frame.cam_from_world, frame.depth, frame.camera,
                      options, &m.check);
      if (m.check.num_checked == 0) continue;
      ++checked;
      grow_multiview_regions(m.check, frame.depth, &m.mask, &m.flood_stack, &roi);
    }
    return checked;
  }
};

}  // namespace dyncull
