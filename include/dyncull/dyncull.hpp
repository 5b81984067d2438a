/// @file dyncull.hpp
/// Umbrella header for dyncull's core modules (standard library + Eigen only). The OpenCV and
/// Ceres adapters are included separately: dyncull/opencv/..., dyncull/ceres/....
#pragma once

#include "dyncull/core/box.hpp"
#include "dyncull/core/camera.hpp"
#include "dyncull/core/depth.hpp"
#include "dyncull/core/mask.hpp"
#include "dyncull/core/random.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/core/traits.hpp"
#include "dyncull/core/types.hpp"
