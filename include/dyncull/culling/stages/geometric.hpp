/// @file geometric.hpp
/// Stage 4 of the culling pipeline: per-feature geometric evidence from the tracks, the epipolar
/// distance to an F fitted outside the boxes (DFD-SLAM 2024 eq. 1-3; SG-SLAM 2023) and/or the RGB-D
/// reprojection residual, combined, with flags on occlusion edges discounted.
#pragma once

#include "dyncull/culling/stages/context.hpp"

#include <algorithm>
#include <cstddef>
#include <string>

namespace dyncull {
namespace detail {

/// What the geometric stages read: the epipolar and reprojection checks' options, the occlusion-edge
/// discount, and the inputs each check needs (their declarations in stages/builtin.hpp).
template <class T>
struct GeometricSlice {
  const MovingConsistencyStageOptions<T>& moving_consistency;
  const ReprojectionStageOptions<T>& reprojection;
  const EdgeEvidenceOptions& edge_evidence;
  FrameInputs moving_consistency_needs, reprojection_needs;
  GeometricSlice(const PipelineOptions<T>& o)  // implicit: the pipeline passes its options
      : moving_consistency(o.moving_consistency),
        reprojection(o.reprojection),
        edge_evidence(o.edge_evidence),
        moving_consistency_needs(stage_needs<MovingConsistencyStage<T>>(o)),
        reprojection_needs(stage_needs<ReprojectionStage<T>>(o)) {}
};

/// No Ok without its evidence: when enough tracks are flagged valid but none has a finite 3-D point
/// (depth given but all 0, NaN or out of range where the points came from), the reprojection check could
/// not run for want of a usable input. That is a missing input of the frame (MissingInput, the reason
/// naming points_3d), not a frame with nothing to do (Skipped, which leaves the frame Ok).
inline void report_unusable_points(FlagView track_valid, std::size_t n, std::size_t min_tracks, std::size_t num_usable,
                                   StageReport* report) {
  if (report->status != Status::Skipped || num_usable > 0) return;
  std::size_t flagged = n;
  if (track_valid.given) {
    flagged = 0;
    for (std::size_t i = 0; i < n && i < track_valid.size; ++i) flagged += track_valid[i] != 0;
  }
  if (flagged == 0 || flagged < min_tracks) return;
  report->status = Status::MissingInput;
  report->reason = "points_3d: none of the " + std::to_string(flagged) +
                   " valid tracks has a finite 3-D point (the depth they came from is unusable: 0, NaN or out of range)";
}

/// Geometric evidence of this frame (out->labels, valid when out->ok); reports into
/// r.moving_consistency and r.reprojection.
template <class T, class Frame>
void gather_geometric_evidence(const Frame& frame, const NonDeduced<GeometricSlice<T>>& options,
                               const BoxRegions<T>& regions, const SemanticEvidence<T>& semantic,
                               GeometricEvidence<T>* out, PipelineResult<T>* r) {
  const auto& kp = *frame.keypoints;
  const std::size_t n = r->num_features;
  GeometricEvidence<T>& g = *out;
  const FlagView in_boxes = regions.dyn_boxes.empty() ? nullptr : FlagView(semantic.in_dyn_box);
  if (options.moving_consistency.enabled) {
    if (has_needed_inputs(frame, options.moving_consistency_needs, &r->moving_consistency)) {
      check_moving_consistency(*frame.prev_keypoints, kp, options.moving_consistency, &g.moving, frame.track_valid,
                               in_boxes);
      r->moving_consistency.status = g.moving.status;
      r->moving_consistency.reason = g.moving.reason;
      r->moving_consistency.num_dynamic = g.moving.num_dynamic;
    }
  }
  if (r->moving_consistency.ran()) {
    g.labels.assign(g.moving.labels.begin(), g.moving.labels.end());
    g.source.assign(n, CullReason::Epipolar);
  }
  if (options.reprojection.enabled) {
    if (has_needed_inputs(frame, options.reprojection_needs, &r->reprojection)) {
      check_reprojection(*frame.points_3d, kp, frame.camera, options.reprojection, &g.reprojection, frame.track_valid,
                         in_boxes, frame.depth);
      r->reprojection.status = g.reprojection.status;
      r->reprojection.reason = g.reprojection.reason;
      r->reprojection.num_dynamic = g.reprojection.num_dynamic;
      report_unusable_points(frame.track_valid, n, options.reprojection.min_tracks, g.reprojection.num_valid,
                             &r->reprojection);
    }
    if (r->reprojection.ran()) {
      if (!r->moving_consistency.ran()) {
        g.labels.assign(g.reprojection.labels.begin(), g.reprojection.labels.end());
        g.source.assign(n, CullReason::Reprojection);
      } else {
        // The residual also sees the motion along the epipolar line: where it decided, it alone decides.
        for (std::size_t i = 0; i < n; ++i) {
          const FeatureLabel rl = g.reprojection.labels[i];
          if (rl == FeatureLabel::Candidate) continue;
          g.labels[i] = rl;
          g.source[i] = CullReason::Reprojection;
        }
      }
    }
  }
  g.ok = r->moving_consistency.ran() || r->reprojection.ran();
  g.fit_outside_boxes = (!r->moving_consistency.ran() || g.moving.fitted_outside_boxes) &&
                        (!r->reprojection.ran() || g.reprojection.fitted_outside_boxes);
  // An LK window straddling an occlusion edge follows the contour, not a 3-D point: not evidence.
  if (g.ok && options.edge_evidence.enabled && !frame.depth.empty()) {
    std::size_t discounted = 0;
    for (std::size_t i = 0; i < n; ++i) {
      int u = 0, v = 0;
      if (g.labels[i] != FeatureLabel::Dynamic ||
          !keypoint_in_image<T>(kp, i, frame.depth.width, frame.depth.height, &u, &v))
        continue;
      if (depth_step_near(frame.depth, u, v, options.edge_evidence.radius_px, EdgeEvidenceOptions::kDepthStepRatio)) {
        g.labels[i] = FeatureLabel::Candidate;
        ++discounted;
      }
    }
    r->moving_consistency.num_dynamic -= std::min(r->moving_consistency.num_dynamic, discounted);
  }
}

}  // namespace detail
}  // namespace dyncull
