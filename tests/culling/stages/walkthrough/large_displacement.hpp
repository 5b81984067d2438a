/// @file large_displacement.hpp
/// A track that moved farther in the image since the previous frame than max_displacement_px is flagged
/// moving. The worked example of docs/design.md, "Adding a stage": an evidence stage (stages/stage.hpp)
/// in one header, run once it has its line in stages/list.hpp. No paper equation.
#pragma once

#include "dyncull/core/traits.hpp"
#include "dyncull/culling/labels.hpp"
#include "dyncull/culling/stages/stage.hpp"
#include "dyncull/culling/validation.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

namespace dyncull {

/// Flags the tracks whose image displacement exceeds a bound (needs prev_keypoints).
template <class T>
struct LargeDisplacementStage {
  static constexpr const char* kName = "large_displacement";
  static constexpr StageKind kKind = StageKind::Evidence;
  static constexpr CullReason kReason = CullReason::ListedStage;

  struct Options {
    bool enabled = false;
    /// Pixels a static point's track moves at most between two frames (camera motion and tracking noise).
    T max_displacement_px = T(40);

    /// InvalidInput unless max_displacement_px is finite and in (0, 1e4] px.
    Status validate(std::string* reason = nullptr) const {
      if (!(max_displacement_px > T(0) && max_displacement_px <= T(1e4)))
        return detail::invalid_option(reason, "max_displacement_px", "must be finite and in (0, 1e4] px");
      if (reason) reason->clear();
      return Status::Ok;
    }
  };
  struct OptionsSlot {
    Options large_displacement{};
  };
  struct ReportSlot {
    StageReport large_displacement;
  };
  static constexpr Options OptionsSlot::*kOptions = &OptionsSlot::large_displacement;
  static constexpr StageReport ReportSlot::*kReport = &ReportSlot::large_displacement;

  struct Work {};  // nothing kept between frames

  static constexpr FrameInputs needs(const Options&) { return FrameInputs(FrameInput::PrevKeypoints); }
  static constexpr FrameInputs uses(const Options&) { return 0; }

  template <class Frame, class Context>
  static void run(const Frame& frame, const Options& options, const Context&, Work*, std::uint8_t* dynamic,
                  StageReport* report) {
    const auto& kp = *frame.keypoints;
    const auto& prev = *frame.prev_keypoints;
    const T max_squared = options.max_displacement_px * options.max_displacement_px;
    for (std::size_t i = 0; i < static_cast<std::size_t>(kp.size()); ++i) {
      if (frame.track_valid.given && !frame.track_valid[i]) continue;  // accept_inputs checked its size
      const T dx = point_x<T>(kp[i]) - point_x<T>(prev[i]);
      const T dy = point_y<T>(kp[i]) - point_y<T>(prev[i]);
      dynamic[i] = dx * dx + dy * dy > max_squared;  // NaN compares false: a broken track is not evidence
    }
    report->status = Status::Ok;
  }
};

}  // namespace dyncull
