/// @file depth_range.hpp
/// A box label on a feature farther than max_depth_m is dropped: what a box holds beyond the range
/// people walk at is the wall behind them. The worked example of a depth stage in docs/design.md, "Adding
/// a stage" (stages/stage.hpp), in one header, run once it has its line in stages/list.hpp. No paper
/// equation.
#pragma once

#include "dyncull/culling/labels.hpp"
#include "dyncull/culling/stages/stage.hpp"
#include "dyncull/culling/validation.hpp"

#include <cstddef>
#include <cstdint>
#include <string>

namespace dyncull {

/// Flags the box-labelled features whose depth exceeds max_depth_m as off their object (needs depth).
template <class T>
struct DepthRangeStage {
  static constexpr const char* kName = "depth_range";
  static constexpr StageKind kKind = StageKind::Depth;
  static constexpr CullReason kReason = CullReason::ListedStage;

  struct Options {
    bool enabled = false;
    /// Farthest a moving object in view is, in metres (a room's depth).
    double max_depth_m = 6.0;

    /// InvalidInput unless max_depth_m is finite and in (0, 1e4] m.
    Status validate(std::string* reason = nullptr) const {
      if (!(max_depth_m > 0 && max_depth_m <= 1e4))
        return detail::invalid_option(reason, "max_depth_m", "must be finite and in (0, 1e4] m");
      if (reason) reason->clear();
      return Status::Ok;
    }
  };
  struct OptionsSlot {
    Options depth_range{};
  };
  struct ReportSlot {
    StageReport depth_range;
  };
  static constexpr Options OptionsSlot::*kOptions = &OptionsSlot::depth_range;
  static constexpr StageReport ReportSlot::*kReport = &ReportSlot::depth_range;

  struct Work {};  // nothing kept between frames

  static constexpr FrameInputs needs(const Options&) { return FrameInputs(FrameInput::Depth); }
  static constexpr FrameInputs uses(const Options&) { return 0; }

  /// off_object[i] = 1 for a feature the boxes labelled (context.earlier.semantic.labels) whose depth is
  /// beyond max_depth_m; a feature without depth keeps its label.
  template <class Frame, class Context>
  static void run(const Frame& frame, const Options& options, const Context& context, Work*, std::uint8_t* off_object,
                  StageReport* report) {
    const auto& kp = *frame.keypoints;
    const auto& labels = context.earlier.semantic.labels;
    for (std::size_t i = 0; i < static_cast<std::size_t>(kp.size()); ++i) {
      int u = 0, v = 0;
      if (labels[i] == FeatureLabel::Static ||
          !detail::keypoint_in_image<T>(kp, i, frame.depth.width, frame.depth.height, &u, &v))
        continue;
      off_object[i] = frame.depth.depth_m(u, v) > options.max_depth_m;
    }
    report->status = Status::Ok;
  }
};

}  // namespace dyncull
