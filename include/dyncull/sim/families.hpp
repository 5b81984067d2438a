/// @file families.hpp
/// Named scene families: a sim::SceneOptions preset each (walkers as in TUM fr3/walking_*, seated
/// people as in fr3/sitting_* (Sturm et al. 2012), a crowd, a far walker, brisk walkers, a low-texture
/// room, a noisy detector), so culling claims are measured over a suite of scenes. No paper equation.
#pragma once

#include "dyncull/core/text.hpp"
#include "dyncull/sim/scene.hpp"
#include "dyncull/sim/scene_keys.hpp"

#include <algorithm>
#include <string>
#include <vector>

namespace dyncull::sim {

/// One family: the scene it stands for. Its options leave `motion`, `seed` and `num_frames` at their
/// defaults: every family runs with every camera motion (camera_motions()) and any seed.
struct SceneFamily {
  std::string name;
  std::string description;
  SceneOptions options;
};

/// Every family, the default scene ("walking") first.
inline std::vector<SceneFamily> scene_families() {
  std::vector<SceneFamily> out;
  auto add = [&](const char* name, const char* description) -> SceneOptions& {
    out.push_back(SceneFamily{name, description, SceneOptions{}});
    return out.back().options;
  };
  add("walking",
      "the default scene: two walkers one behind the other at 0.4 m/s on a loop 1-1.7 m in front of the camera, "
      "a seated person, a pushed chair, a TV");

  {
    // As fr3/sitting_*: the two desk people's boxes cover about half of the image, most of it still.
    SceneOptions& o = add("sitting", "two people seated at a desk with monitors, keyboards and other clutter, "
                                     "swaying, turning their heads, gesturing, swivelling; no walkers; the "
                                     "detector calibrated on the real streams");
    o.actors.walking_people = 0;
    o.actors.pushed_chair = false;
    o.actors.sitting_person = false;
    o.actors.desk_people = 2;
    o.actors.desk_clutter = true;
    use_calibrated_detector(&o);
  }
  {
    // Spread around the loop (about a quarter turn apart), so several are in view at once.
    SceneOptions& o = add("crowd", "four walkers at 0.4 m/s spread around the loop 1-1.7 m in front of the "
                                   "camera, seated person, pushed chair, TV");
    o.actors.walking_people = 4;
    o.actors.walker_gap_rad = 1.5;
  }
  {
    // A loop 2.4-3.2 m from the camera, between the seated person's knees and the pushed chair's path.
    SceneOptions& o = add("far_walker", "one walker 2.4-3.2 m from the camera (small box, a few pixels of motion "
                                        "a frame), seated person and pushed chair as in walking");
    o.actors.walking_people = 1;
    o.actors.loop_centre_m = Vec2<double>(0.0, 2.5);
    o.actors.loop_semi_axes_m = Vec2<double>(0.7, 0.35);
  }
  {
    SceneOptions& o = add("brisk", "the walking scene with the walkers at 1.2 m/s, an ordinary walking pace");
    o.actors.walking_speed_mps = 1.2;
  }
  {
    // Plainer walls and larger texture cells: fewer static corners, so each culled one costs more.
    SceneOptions& o = add("low_texture", "the walking scene in a plainer room: wall contrast 0.15, texture cells "
                                         "1.6x larger (fewer static corners)");
    o.actors.wall_contrast = 0.15;
    o.actors.texture_scale = 1.6;
  }
  {
    SceneOptions& o = add("noisy_detector", "the walking scene seen by a worse detector: box edges jitter 6 px, "
                                            "20 % of instances missed, a spurious box in 20 % of frames");
    o.box_jitter_px = 6.0;
    o.miss_rate = 0.2;
    o.false_positive_rate = 0.2;
  }
  return out;
}

/// The family named `name`; false (with `reason` listing the families) for an unknown name.
inline bool find_scene_family(const std::string& name, SceneFamily* out, std::string* reason = nullptr) {
  std::string names;
  for (const SceneFamily& f : scene_families()) {
    if (f.name == name) {
      if (out) *out = f;
      return true;
    }
    names += (names.empty() ? "" : ", ") + f.name;
  }
  if (reason) *reason = "unknown scene family " + text::quote_token(name) + " (families: " + names + ")";
  return false;
}

/// One line per family: "  name  description  [its keys that differ from the default scene]", for --help.
inline std::string format_scene_families() {
  std::size_t width = 0;
  for (const SceneFamily& f : scene_families()) width = std::max(width, f.name.size());
  std::string out;
  for (const SceneFamily& f : scene_families()) {
    const std::string diff = scene_difference(f.options);
    out += "  " + f.name + std::string(width + 2 - f.name.size(), ' ') + f.description + "\n";
    if (!diff.empty()) out += "  " + std::string(width + 2, ' ') + "= --scene " + diff + "\n";
  }
  return out;
}

}  // namespace dyncull::sim
