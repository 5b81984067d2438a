/// @file multiview.hpp
/// Stage 7 of the culling pipeline: the multi-view depth and parallax check of RTD-SLAM 2024 §III.A
/// (after DynaSLAM, Bescos et al. 2018) against stored keyframes, grown into a mask over the depth image.
#pragma once

#include "dyncull/culling/stages/context.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>

namespace dyncull {
namespace detail {

/// out->dynamic: per feature, in a region the check found moving (valid when out->ok); reports into r.multiview.
template <class T, class Frame>
void check_against_keyframes(const Frame& frame, const PipelineOptions<T>& options, const KeyframeRing<T>& keyframes,
                             MultiViewFlags<T>* out, PipelineResult<T>* r) {
  MultiViewFlags<T>& m = *out;
  const std::size_t n = r->num_features;
  m.dynamic.assign(n, 0);
  m.ok = false;
  if (!options.multiview.enabled) return;
  const auto& kp = *frame.keypoints;
  // Before the first keyframe is stored (is_keyframe, or pushed by hand) there is no reference view: an
  // input the check lacks, as a pose or depth would be, so the frame says so.
  if (!stage_has_inputs(frame, options, &PipelineResult<T>::multiview, r, !keyframes.empty())) return;
  // Seeds grow over the whole image: a flag culls wherever it is (DynaSLAM).
  PixelRect roi{0, 0, frame.depth.width, frame.depth.height};
  m.ref_index.resize(std::max<std::size_t>(1, std::min(options.multiview.max_reference_keyframes, keyframes.size())));
  const std::size_t k =
      keyframes.select_references(*frame.cam_from_world, options.multiview.max_reference_keyframes, m.ref_index.data());
  if (m.mask.width != frame.depth.width || m.mask.height != frame.depth.height)
    m.mask.reset(frame.depth.width, frame.depth.height, 0);
  else
    std::fill(m.mask.pixels.begin(), m.mask.pixels.end(), std::uint8_t(0));
  std::size_t checked = 0;
  for (std::size_t j = 0; j < k; ++j) {
    const MultiViewKeyframe<T>& kf = keyframes[m.ref_index[j]];
    check_multiview(kf.points, kf.depth_m, kf.cam_from_world, *frame.cam_from_world, frame.depth, frame.camera,
                    options.multiview, &m.check);
    if (m.check.num_checked == 0) continue;
    ++checked;
    grow_multiview_regions(m.check, frame.depth, options.multiview, &m.mask, &m.flood_stack, &roi);
  }
  if (checked == 0) {
    r->multiview.status = Status::TooFewPoints;
    r->multiview.reason = "no keyframe point could be compared";
    return;
  }
  r->multiview.status = Status::Ok;
  for (std::size_t i = 0; i < n; ++i) {
    int u = 0, v = 0;
    if (keypoint_in_image<T>(kp, i, m.mask.width, m.mask.height, &u, &v))
      m.dynamic[i] = m.mask.pixels[static_cast<std::size_t>(v) * m.mask.width + u] != 0;
    r->multiview.num_dynamic += m.dynamic[i];
  }
  m.ok = r->multiview.ran();
}

}  // namespace detail
}  // namespace dyncull
