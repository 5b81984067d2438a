/// @file list.hpp
/// The stages of the culling pipeline, in front-end order, each in the form of stages/stage.hpp. The
/// options, the reports, validate(), the stage table (stages/declarations.hpp) and the culler's inputs
/// derive from this list: a new stage is one header and one line here (docs/design.md, "Adding a
/// stage"), placed where its kind runs (stages/stage.hpp): a box classification stage after the depth
/// masks, a depth stage after the box classifications, an evidence stage after the sub-box vote.
/// Pipeline plumbing, no paper.
#pragma once

#include "dyncull/culling/stages/builtin.hpp"
#include "dyncull/culling/stages/multiview.hpp"

namespace dyncull {

template <class T>
using PipelineStages = StageList<
    DetectionFilterStage<T>,
    BoxTrackerStage<T>,
    BoxRuleStage<T>,
    DepthMaskStage<T>,
    ProbabilityStage<T>,
    MovingConsistencyStage<T>,
    ReprojectionStage<T>,
    CoherentMotionStage<T>,
    SubBoxStage<T>,
    MultiViewStage<T>,
    StaticHistoryStage<T>>;

}  // namespace dyncull
