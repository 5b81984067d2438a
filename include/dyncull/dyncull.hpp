/// @file dyncull.hpp
/// Umbrella header for the dyncull library (standard library + Eigen only): core, geometry and culling,
/// the stateful culler included. Including single headers compiles faster. The evaluation product
/// (dyncull/eval/..., dyncull/sim/...) and the adapters (dyncull/opencv/..., dyncull/ceres/...,
/// dyncull/host/...) are included by name (docs/design.md, "Modules and dependency rules").
#pragma once

#include "dyncull/core/box.hpp"
#include "dyncull/core/camera.hpp"
#include "dyncull/core/compact.hpp"
#include "dyncull/core/depth.hpp"
#include "dyncull/core/mask.hpp"
#include "dyncull/core/random.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/core/traits.hpp"
#include "dyncull/core/types.hpp"

#include "dyncull/geometry/bfgs.hpp"
#include "dyncull/geometry/epipolar.hpp"
#include "dyncull/geometry/fundamental.hpp"
#include "dyncull/geometry/icp.hpp"
#include "dyncull/geometry/kdtree.hpp"
#include "dyncull/geometry/pnp.hpp"
#include "dyncull/geometry/projection.hpp"
#include "dyncull/geometry/ransac.hpp"
#include "dyncull/geometry/rigid.hpp"
#include "dyncull/geometry/rotation_centre.hpp"

#include "dyncull/culling/box_rule.hpp"
#include "dyncull/culling/box_tracker.hpp"
#include "dyncull/culling/culler.hpp"
#include "dyncull/culling/depth_mask.hpp"
#include "dyncull/culling/descriptor_switch.hpp"
#include "dyncull/culling/detections.hpp"
#include "dyncull/culling/dynamic_probability.hpp"
#include "dyncull/culling/keep_mask.hpp"
#include "dyncull/culling/labels.hpp"
#include "dyncull/culling/motion_levels.hpp"
#include "dyncull/culling/moving_consistency.hpp"
#include "dyncull/culling/multiview_check.hpp"
#include "dyncull/culling/pipeline.hpp"
#include "dyncull/culling/presets.hpp"
#include "dyncull/culling/subbox_memory.hpp"
#include "dyncull/culling/subbox_refine.hpp"
