/// @file list.hpp
/// The evidence stages the culling pipeline runs, in order (the form of one: stages/stage.hpp). A new
/// check is one header and one entry here (docs/design.md, "Adding a stage"). Pipeline plumbing, no paper.
#pragma once

#include "dyncull/culling/stages/multiview.hpp"

namespace dyncull {

template <class T>
using EvidenceStages = StageList<MultiViewStage<T>>;

}  // namespace dyncull
