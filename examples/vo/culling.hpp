/// @file culling.hpp
/// The culling strategies the dynamic_vo demo compares: no culling and each dyncull preset
/// (culling/presets.hpp), applied to the current frame's tracked features before PnP.
#pragma once

#include "dyncull/core/camera.hpp"
#include "dyncull/core/types.hpp"

#include "frontend.hpp"
#include "sources.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace dyncull {
namespace vo {

/// One strategy: a name for the table and how to build its culling.
struct StrategySpec {
  std::string name;
  std::string description;
  bool culls = false;             ///< false only for the no-culling reference
  bool needs_detections = false;  ///< cannot run without detector boxes
  bool recommended = false;       ///< the library's recommended default preset
  bool oracle = false;            ///< culls by the sim's per-pixel truth: the bound no culling can beat
};

/// "none" first (the reference of the improvement column), then the presets.
inline std::vector<StrategySpec> all_strategies() {
  std::vector<StrategySpec> out;
  out.push_back(StrategySpec{"none", "no culling: every tracked feature goes to PnP-RANSAC", false, false, false, false});
  out.push_back(StrategySpec{"oracle", "culls exactly the features on moving surfaces (sim truth): the best any culling can do",
                             true, false, false, true});
  return out;
}

/// Per-strategy culling state carried frame to frame.
class Culler {
 public:
  Culler(const StrategySpec& spec, const PinholeCamera<double>& camera) : spec_(spec), camera_(camera) {}

  /// keep[i] != 0 for the tracks PnP may use.
  void cull(const SequenceFrame& frame, const Tracks& tracks, const Rigid3<double>& prev_world_from_cam,
            std::vector<std::uint8_t>* keep) {
    (void)prev_world_from_cam;
    keep->assign(tracks.size(), 1);
    if (spec_.oracle && !frame.moving.empty()) {
      for (std::size_t i = 0; i < tracks.size(); ++i) {
        const int u = cvRound(tracks.cur_px[i].x), v = cvRound(tracks.cur_px[i].y);
        if (u >= 0 && v >= 0 && u < frame.moving.cols && v < frame.moving.rows && frame.moving.at<std::uint8_t>(v, u))
          (*keep)[i] = 0;
      }
    }
  }

  /// Called after the pose of the frame is known (keyframe bookkeeping of multi-view checks).
  void after_pose(const SequenceFrame& frame, const Tracks& tracks, const Rigid3<double>& world_from_cam, bool keyframe) {
    (void)frame;
    (void)tracks;
    (void)world_from_cam;
    (void)keyframe;
  }

 private:
  StrategySpec spec_;
  PinholeCamera<double> camera_;
};

}  // namespace vo
}  // namespace dyncull
