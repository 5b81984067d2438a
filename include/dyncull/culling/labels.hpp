/// @file labels.hpp
/// Per-feature labels and cull reasons shared by every culling stage (semantic and geometric).
/// Three-valued labels follow RTD-SLAM (Gao et al. 2024) §III.D: medium-level objects are sent to geometric verification.
#pragma once

#include "dyncull/core/status.hpp"

#include <cstdint>

namespace dyncull {

/// What a stage decided about one feature. Candidate = "could be moving, let geometry decide".
enum class FeatureLabel : std::uint8_t { Static = 0, Candidate = 1, Dynamic = 2 };

/// Which rule produced a feature's label (first rule that marked it wins; None for untouched statics).
enum class CullReason : std::uint8_t {
  None = 0,
  HighLevelBox,       ///< inside a high-motion-level box (person, animal) and no low-level box
  LowLevelOverride,   ///< inside a high-level box but also inside a low-level box: kept (Zhu et al. 2024 Table 2)
  MediumLevelBox,     ///< inside a medium-level box only: candidate for geometric verification
  DepthMask,          ///< inside the depth-threshold object mask (DLD-SLAM §3.3)
  Probability,        ///< dynamic probability above threshold (DLD-SLAM §3.4)
  Epipolar,           ///< epipolar distance above threshold (DFD-SLAM eq. 3)
  SubBox,             ///< sub-box refinement marked it (geometric stage)
  MultiView,          ///< multi-view depth/angle check (geometric stage)
  SurvivorGuardUndo,  ///< culling undone because too few static features would remain
  TrackedBox,         ///< inside a box carried forward by the box tracker (detector miss)
  Reprojection,       ///< RGB-D reprojection residual above threshold (reprojection_check.hpp)
  CoherentMotion,     ///< its cell's residuals moved together (coherent_motion.hpp), culled by the sub-box vote
  InvalidInput,       ///< non-finite coordinates: never trusted as static
  ListedStage,        ///< culled by a stage of culling/stages/list.hpp without a reason of its own
};

DYNCULL_CONSTEXPR14 const char* to_string(FeatureLabel label) noexcept {
  switch (label) {
    case FeatureLabel::Static: return "static";
    case FeatureLabel::Candidate: return "candidate";
    case FeatureLabel::Dynamic: return "dynamic";
  }
  return "unknown";
}

DYNCULL_CONSTEXPR14 const char* to_string(CullReason reason) noexcept {
  switch (reason) {
    case CullReason::None: return "none";
    case CullReason::HighLevelBox: return "high-level box";
    case CullReason::LowLevelOverride: return "low-level override";
    case CullReason::MediumLevelBox: return "medium-level box";
    case CullReason::DepthMask: return "depth mask";
    case CullReason::Probability: return "probability";
    case CullReason::Epipolar: return "epipolar";
    case CullReason::SubBox: return "sub-box";
    case CullReason::MultiView: return "multi-view";
    case CullReason::SurvivorGuardUndo: return "survivor guard undo";
    case CullReason::TrackedBox: return "tracked box";
    case CullReason::Reprojection: return "reprojection";
    case CullReason::CoherentMotion: return "coherent motion";
    case CullReason::InvalidInput: return "invalid input";
    case CullReason::ListedStage: return "listed stage";
  }
  return "unknown";
}

/// Labels ordered by severity, so stages can combine with max(): Dynamic > Candidate > Static.
constexpr FeatureLabel max_label(FeatureLabel a, FeatureLabel b) noexcept {
  return static_cast<std::uint8_t>(a) >= static_cast<std::uint8_t>(b) ? a : b;
}

}  // namespace dyncull
