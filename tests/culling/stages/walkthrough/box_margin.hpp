/// @file box_margin.hpp
/// Features just outside a dynamic-class box are candidates: a detector's box often cuts off a hand or a
/// foot. The worked example of a box classification stage in docs/design.md, "Adding a stage" (stages/
/// stage.hpp), in one header, run once it has its line in stages/list.hpp. No paper equation.
#pragma once

#include "dyncull/core/box.hpp"
#include "dyncull/core/traits.hpp"
#include "dyncull/culling/labels.hpp"
#include "dyncull/culling/stages/stage.hpp"
#include "dyncull/culling/validation.hpp"

#include <cstddef>
#include <string>

namespace dyncull {

/// Labels Candidate the features within margin_px outside a dynamic-class box (needs the detections).
template <class T>
struct BoxMarginStage {
  static constexpr const char* kName = "box_margin";
  static constexpr StageKind kKind = StageKind::BoxClassification;
  static constexpr CullReason kReason = CullReason::ListedStage;

  struct Options {
    bool enabled = false;
    /// How far outside its box a limb the detector cut off reaches, in pixels.
    T margin_px = T(12);

    /// InvalidInput unless margin_px is finite and in [0, 1e3] px.
    Status validate(std::string* reason = nullptr) const {
      if (!(margin_px >= T(0) && margin_px <= T(1e3)))
        return detail::invalid_option(reason, "margin_px", "must be finite and in [0, 1e3] px");
      if (reason) reason->clear();
      return Status::Ok;
    }
  };
  struct OptionsSlot {
    Options box_margin{};
  };
  struct ReportSlot {
    StageReport box_margin;
  };
  static constexpr Options OptionsSlot::*kOptions = &OptionsSlot::box_margin;
  static constexpr StageReport ReportSlot::*kReport = &ReportSlot::box_margin;

  struct Work {};  // nothing kept between frames

  static constexpr FrameInputs needs(const Options&) { return FrameInputs(FrameInput::Detections); }
  static constexpr FrameInputs uses(const Options&) { return 0; }

  /// labels[i] = Candidate for a feature in the margin of a dynamic-class box (the boxes after the filter
  /// and the tracker: context.earlier.regions.dyn_boxes); the box rule's labels inside the boxes stand.
  template <class Frame, class Context>
  static void run(const Frame& frame, const Options& options, const Context& context, Work*, FeatureLabel* labels,
                  StageReport* report) {
    const auto& kp = *frame.keypoints;
    for (const auto& detection : context.earlier.regions.dyn_boxes) {
      const Box<T> near = detection.box.padded(options.margin_px);
      for (std::size_t i = 0; i < static_cast<std::size_t>(kp.size()); ++i) {
        const T x = point_x<T>(kp[i]), y = point_y<T>(kp[i]);
        if (near.contains(x, y) && !detection.box.contains(x, y)) labels[i] = FeatureLabel::Candidate;  // NaN: no
      }
    }
    report->status = Status::Ok;
  }
};

}  // namespace dyncull
