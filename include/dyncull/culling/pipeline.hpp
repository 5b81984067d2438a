/// @file pipeline.hpp
/// The culling pipeline: composes the semantic (002/004 box rule, 000 depth mask and probability) and
/// geometric (003 epipolar + sub-box, 001 multi-view) strategies in front-end order, with a survivor guard.
#pragma once

#include "dyncull/core/box.hpp"
#include "dyncull/core/camera.hpp"
#include "dyncull/core/depth.hpp"
#include "dyncull/core/mask.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/core/traits.hpp"
#include "dyncull/core/types.hpp"
#include "dyncull/culling/box_rule.hpp"
#include "dyncull/culling/box_tracker.hpp"
#include "dyncull/culling/coherent_motion.hpp"
#include "dyncull/culling/depth_mask.hpp"
#include "dyncull/culling/detections.hpp"
#include "dyncull/culling/dynamic_probability.hpp"
#include "dyncull/culling/labels.hpp"
#include "dyncull/culling/motion_levels.hpp"
#include "dyncull/culling/moving_consistency.hpp"
#include "dyncull/culling/reprojection_check.hpp"
#include "dyncull/culling/multiview_check.hpp"
#include "dyncull/culling/static_history.hpp"
#include "dyncull/culling/subbox_memory.hpp"
#include "dyncull/culling/subbox_refine.hpp"
#include "dyncull/culling/validation.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace dyncull {

/// What happens to features still labelled Candidate (medium-level boxes, 001 §III.D) at the end.
enum class CandidatePolicy : std::uint8_t {
  Keep = 0,  ///< static: only proven motion culls them
  Cull,      ///< dynamic: treat medium-level objects as moving (004 Algorithm 1)
  Verify,    ///< dynamic only when a geometric stage flags the feature, else static (001)
};

/// What the minimum-survivor guard did.
enum class GuardAction : std::uint8_t { None = 0, Softened, Undone };

constexpr const char* to_string(GuardAction a) noexcept {
  switch (a) {
    case GuardAction::None: return "none";
    case GuardAction::Softened: return "softened";
    case GuardAction::Undone: return "undone";
  }
  return "unknown";
}

/// Which strategies run and their options. presets.hpp builds the papers' configurations.
template <class T>
struct PipelineOptions {
  bool use_detection_filter = true;   ///< padding and class-dependent confidence (detections.hpp)
  bool use_box_tracker = false;       ///< carry missed boxes forward (Dynamic-VINS)
  bool use_box_rule = true;           ///< 002 Table 2 / 004 Algorithm 1
  bool use_depth_mask = false;        ///< 000 eq. 1-2: box culls limited to the object's depth band
  bool use_probability = false;       ///< 000 eq. 3-5 for features in object masks (needs tracks)
  bool use_moving_consistency = true; ///< 003 eq. 1-3 (needs tracks)
  /// RGB-D reprojection check (reprojection_check.hpp; needs CullingFrame::points_3d): its labels join
  /// the epipolar ones as the geometric evidence (see reprojection_evidence).
  bool use_reprojection = false;
  bool use_subbox = true;             ///< 003 Algorithm 1 (needs the moving-consistency labels)
  bool use_multiview = false;         ///< 001 §III.A (needs the current pose and a keyframe)

  DetectionOptions<T> detections{};
  BoxTrackerOptions<T> tracker{};
  MotionLevelTable levels = MotionLevelTable::coco80();
  BoxRuleOptions<T> box_rule{};
  DepthMaskOptions depth_mask{};
  DynamicProbabilityOptions<T> probability{};
  /// Flow model of the probability's M term: Fundamental reuses the moving-consistency F when it ran.
  FlowModel probability_flow_model = FlowModel::Fundamental;
  MovingConsistencyOptions<T> moving{};
  ReprojectionCheckOptions<T> reprojection{};
  /// How the reprojection labels combine with the epipolar ones when both ran: Replace (the residual
  /// sees the motion along the epipolar line too, so it alone decides) or Either (dynamic when either
  /// check flags the track, static when one says static and the other does not flag it).
  enum class Evidence { Replace, Either } reprojection_evidence = Evidence::Replace;
  SubBoxOptions<T> subbox{};
  MultiViewOptions<T> multiview{};
  std::size_t max_reference_keyframes = 2;  ///< keyframes checked per frame (DynaSLAM: 5)

  CandidatePolicy candidates = CandidatePolicy::Verify;
  /// Epipolar-dynamic features outside every dynamic-class box are culled (DS-SLAM) or only used as
  /// evidence inside boxes (false: an unexplained flow outlier outside boxes is more often LK error).
  bool cull_geometric_outside_boxes = true;
  /// Multi-view-dynamic features are culled wherever they are (DynaSLAM); false: only candidates.
  bool multiview_overrides_static = true;
  /// Run the sub-box refinement only when F was fitted on tracks outside the dynamic-class boxes
  /// (or no track lay inside one). An F fitted through a large mover absorbs its motion (measured in
  /// docs/algorithms.md), and the refinement would then clear the whole box.
  bool subbox_requires_fit_outside_boxes = true;
  /// Medium-level candidates (a chair) are culled by a dynamic sub-box of their region (true), or only
  /// on their own evidence, their epipolar distance or the multi-view check (false): a chair under a
  /// seated person or behind a walker otherwise inherits the person's sub-box vote.
  bool subbox_verifies_candidates = true;

  /// A feature held by the depth masks of several dynamic-class boxes (a chair in front of a walker,
  /// a walker passing a chair) belongs to the one whose object depth d_c is nearest its own depth, and
  /// takes that box's level: a static chair's features are then candidates verified on their own
  /// evidence instead of inheriting the walker's label and sub-box vote. The same applies to a
  /// feature in a person's box but only in a chair's mask. false: the box rule's label (highest level
  /// of the rectangles holding it) stands.
  bool assign_overlaps_by_depth = false;
  /// With assign_overlaps_by_depth: a high-level object (a person) takes the feature unless another
  /// object's d_c is nearer its depth by more than this: a seated person's torso and its chair lie at
  /// nearly the same depth, and the torso's features would go to the chair. 0 = nearest d_c only.
  double overlap_high_level_margin_m = 0;
  /// A low-level box (a TV) shelters a feature that a dynamic-class object's depth mask holds only when
  /// the feature's depth is at least as near the low-level object's depth as that object's d_c: a walker
  /// passing in front of a TV is not on it, and 002/004's rule would keep its features. The low-level
  /// object's depth is its box's d_c (000's centre sample, re-estimated from the pixels outside a nearer
  /// box that covers its centre: DepthMaskOptions::occluded_centre_search); without a depth there the
  /// shelter stands. Needs the depth mask.
  bool low_override_by_depth = false;
  /// Sub-box memory (subbox_memory.hpp): a sub-box its own features voted dynamic stays dynamic for this
  /// many frames in the same tracked box, for the tracks flagged in that time or younger than it. 0 = off.
  /// Needs the box tracker (use_box_tracker) and CullingFrame::track_ids; without them the stage report
  /// says so and the vote is this frame's only.
  int subbox_memory_frames = 0;
  /// An epipolar flag of a feature with a depth step above edge_depth_step_ratio within this many
  /// pixels (sampled every 2 px) is not evidence (its moving-consistency label becomes Candidate): an LK
  /// window straddling an occlusion edge follows the contour, not a 3-D point, and is flagged although
  /// its surface is static. 0 = off. Needs the depth image.
  int edge_evidence_radius_px = 0;
  double edge_depth_step_ratio = 0.05;

  /// Shortest baseline, in frames (CullingFrame::evidence_frames), at which the geometric labels may make
  /// part of a dynamic-class box static through the sub-box vote. Over fewer frames a slow mover has not
  /// moved past the thresholds (a walker at 0.4 m/s covers 13 mm a frame, at 2.5 m about 2.8 px sideways
  /// and nothing along the ray), so "not flagged" says nothing: the sub-box refinement is skipped and the
  /// box rule decides (high-level objects culled, candidates on their own flags). A front end that
  /// measures against its keyframe has such frames right after each keyframe, when its corners on the
  /// movers are new. 0 = off; frames with evidence_frames 0 (unknown) are never affected.
  int min_evidence_frames = 0;
  /// With min_evidence_frames: in a frame whose baseline is too short, the cells of a tracked box (box
  /// tracker) keep the states of its last vote within min_evidence_frames frames, where there was one:
  /// static where none of that cell's features was flagged (a seated person's still legs), dynamic where
  /// it voted dynamic; the box rule decides elsewhere and in boxes without such a vote (a walker just
  /// come into view). Needs the box tracker; without it the box rule decides.
  bool short_baseline_keeps_last_vote = false;
  /// Cell-level evidence before the sub-box vote (coherent_motion.hpp): in a cell of a high-level object
  /// (features the box rule labelled Dynamic; candidates such as chairs stay on their own evidence) whose
  /// features' reprojection residuals share a significant median, every feature counts as flagged, so the
  /// vote culls a seated person's sway that no single residual shows. Needs the reprojection check; runs
  /// with the sub-box refinement, on its grid.
  bool use_coherent_motion = false;
  CoherentMotionOptions<T> coherent_motion{};
  /// Track history (static_history.hpp; off while min_frames is 0): a feature culled only for the region it
  /// lies in (its box, its medium-level box, a tracked box or its sub-box) stays static when the reprojection
  /// check said Static with a residual below max_residual_px in each of its last min_frames evaluated frames
  /// (baseline of at least min_evidence_frames, or unknown) and does not flag it now. Needs
  /// CullingFrame::track_ids and the reprojection check.
  StaticHistoryOptions<T> static_history{};

  /// Minimum-survivor guard: if fewer than max(min_survivor_fraction * n, min_survivors) features stay
  /// static, first soften (restore the culls of single geometric stages and of candidates), then undo
  /// all culling. ORB-SLAM2 loses tracking below ~30 local-map inliers; SG-SLAM guards at 10 %.
  bool survivor_guard = true;
  double min_survivor_fraction = 0.10;
  std::size_t min_survivors = 30;

  static constexpr std::size_t kMaxReferenceKeyframes = 64;  ///< upper bound of max_reference_keyframes
  static constexpr int kMaxEdgeEvidenceRadiusPx = 64;        ///< upper bound of edge_evidence_radius_px

  /// InvalidInput naming the first field out of its range, nested fields as "depth_mask.histogram_bin_m":
  /// every nested options struct that has a validate() passes it (whether its stage is on or not);
  /// enums in range; max_reference_keyframes <= kMaxReferenceKeyframes; edge_evidence_radius_px in
  /// [0, kMaxEdgeEvidenceRadiusPx]; edge_depth_step_ratio and overlap_high_level_margin_m finite and >= 0;
  /// subbox_memory_frames and min_evidence_frames in [0, 65535]; min_survivor_fraction in [0, 1].
  Status validate(std::string* reason = nullptr) const {
    using detail::finite_in;
    using detail::invalid_option;
    using detail::validate_nested;
    // Nested structs first, in stage order; the first failure's reason stands.
    if (validate_nested(detections, "detections", reason) != Status::Ok ||
        validate_nested(tracker, "tracker", reason) != Status::Ok ||
        validate_nested(levels, "levels", reason) != Status::Ok ||
        validate_nested(box_rule, "box_rule", reason) != Status::Ok ||
        validate_nested(depth_mask, "depth_mask", reason) != Status::Ok ||
        validate_nested(probability, "probability", reason) != Status::Ok ||
        validate_nested(moving, "moving", reason) != Status::Ok ||
        validate_nested(reprojection, "reprojection", reason) != Status::Ok ||
        validate_nested(subbox, "subbox", reason) != Status::Ok ||
        validate_nested(multiview, "multiview", reason) != Status::Ok ||
        validate_nested(coherent_motion, "coherent_motion", reason) != Status::Ok ||
        validate_nested(static_history, "static_history", reason) != Status::Ok)
      return Status::InvalidInput;
    if (static_cast<int>(probability_flow_model) > 2)
      return invalid_option(reason, "probability_flow_model", "must be MeanFlow, Fundamental or Homography");
    if (static_cast<int>(reprojection_evidence) > 1)
      return invalid_option(reason, "reprojection_evidence", "must be Replace or Either");
    if (static_cast<int>(candidates) > 2) return invalid_option(reason, "candidates", "must be Keep, Cull or Verify");
    if (max_reference_keyframes > kMaxReferenceKeyframes)
      return invalid_option(reason, "max_reference_keyframes", "must be at most 64");
    if (!finite_in(overlap_high_level_margin_m, 0, 1e4))
      return invalid_option(reason, "overlap_high_level_margin_m", "must be finite and in [0, 1e4] m");
    if (subbox_memory_frames < 0 || subbox_memory_frames > 0xFFFF)
      return invalid_option(reason, "subbox_memory_frames", "must be in [0, 65535]");
    if (edge_evidence_radius_px < 0 || edge_evidence_radius_px > kMaxEdgeEvidenceRadiusPx)
      return invalid_option(reason, "edge_evidence_radius_px", "must be in [0, 64]");
    if (!finite_in(edge_depth_step_ratio, 0, 1e30))
      return invalid_option(reason, "edge_depth_step_ratio", "must be finite and >= 0");
    if (min_evidence_frames < 0 || min_evidence_frames > 0xFFFF)
      return invalid_option(reason, "min_evidence_frames", "must be in [0, 65535]");
    if (!finite_in(min_survivor_fraction, 0, 1))
      return invalid_option(reason, "min_survivor_fraction", "must be in [0, 1]");
    if (reason) reason->clear();
    return Status::Ok;
  }
};

/// Outcome of one stage in one frame.
struct StageReport {
  bool enabled = false;
  Status status = Status::Skipped;
  std::string reason;
  std::size_t num_dynamic = 0;  ///< features this stage labelled Dynamic (before combination)
  bool ran() const { return enabled && status == Status::Ok; }
};

/// Per-frame result: labels for the caller's keypoint vector (same order), why, and per-stage counts.
template <class T>
struct PipelineResult {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }

  std::vector<FeatureLabel> labels;  ///< Static or Dynamic (Candidates are resolved by CandidatePolicy)
  std::vector<CullReason> reasons;   ///< deciding strategy (None for untouched statics)
  std::vector<std::uint8_t> keep;    ///< 1 = static: apply to every parallel per-keypoint array
  std::size_t num_features = 0, num_static = 0, num_dynamic = 0;
  StageReport detections, tracker, box_rule, depth_mask, probability, moving_consistency, reprojection,
      coherent_motion, subbox, multiview;
  StageReport static_history;       ///< PipelineOptions::static_history
  std::size_t history_kept = 0;     ///< features the static history kept against a region's cull
  std::size_t unsheltered = 0;      ///< features low_override_by_depth took out of a low-level box's shelter
  GuardAction guard = GuardAction::None;
  std::size_t guard_restored = 0;   ///< features the guard turned back to static
};

/// Caller-owned state carried between frames, plus scratch buffers reused so the pipeline's own
/// stages allocate nothing after warm-up.
template <class T>
struct PipelineState {
  BoxTracker<T> tracker;
  TrackStateStore track_states;      ///< K of 000 eq. 3, keyed by the caller's track ids
  SubBoxMemory subbox_memory;        ///< PipelineOptions::subbox_memory_frames
  StaticHistory static_history;      ///< PipelineOptions::static_history
  KeyframeRing<T> keyframes;         ///< multi-view references (push with is_keyframe or by hand)
  std::uint64_t frame_index = 0;

  PipelineResult<T> result;
  // Scratch (internal).
  std::vector<Detection<T>> boxes, dyn_boxes, untracked_boxes, shelter_boxes;
  std::vector<std::uint32_t> object_box_bits;  ///< per feature: the dynamic boxes whose depth mask holds it
  std::vector<std::int32_t> dyn_box_source;
  std::vector<std::int64_t> box_track_id, dyn_box_track_id;  ///< box-tracker id per box (-1: none)
  std::vector<std::uint8_t> remembered_cells, memory_eligible;
  std::vector<FeatureLabel> sem_labels;
  std::vector<CullReason> sem_reasons;
  std::vector<std::uint8_t> in_dyn_box, in_object, mv_dynamic, coherent_eligible;
  std::vector<std::uint16_t> still_frames;    ///< static history count per feature this frame
  std::vector<std::uint8_t> history_kept;     ///< 1: kept static by its history this frame
  std::vector<MotionLevel> prob_levels;
  std::vector<Vec2<T>> prob_prev;
  std::vector<T> keypoint_depth;
  MovingConsistencyResult<T> moving;
  ReprojectionCheckResult<T> reprojection;
  CoherentMotionResult<T> coherent_motion;
  SubBoxResult<T> subbox;
  MultiViewResult<T> multiview;
  Mask multiview_mask;
  std::vector<std::uint32_t> flood_stack;
  std::vector<std::size_t> ref_index;

  explicit PipelineState(std::size_t keyframe_capacity = 20) : keyframes(keyframe_capacity) {}
  void reset() {
    tracker = BoxTracker<T>(tracker_options_);
    track_states.clear();
    subbox_memory.clear();
    static_history.clear();
    keyframes.clear();
    frame_index = 0;
  }

 private:
  BoxTrackerOptions<T> tracker_options_{};
};

/// Non-owning view of per-track flags with their count (data[i] != 0: valid). Built from a
/// std::vector<std::uint8_t> (implicitly) or a pointer and a count: then given, and its count is checked
/// against the keypoints' (an empty vector for keypoints is a mismatch, not "all valid"); default or
/// nullptr: no flags.
struct FlagView {
  const std::uint8_t* data = nullptr;
  std::size_t size = 0;
  bool given = false;

  FlagView() = default;
  FlagView(std::nullptr_t) {}  // NOLINT(google-explicit-constructor): nullptr means "no flags"
  FlagView(const std::uint8_t* flags, std::size_t count) : data(flags), size(count), given(true) {}
  FlagView(const std::vector<std::uint8_t>& flags)  // NOLINT(google-explicit-constructor)
      : data(flags.data()), size(flags.size()), given(true) {}
  bool empty() const { return !given; }
  /// Given, and readable for n entries.
  bool holds(std::size_t n) const { return given && size == n && (data != nullptr || n == 0); }
  std::uint8_t operator[](std::size_t i) const { return data[i]; }
};

/// One frame as the front end has it. Keypoints: the caller's container (cv::KeyPoint, Eigen, ...);
/// prev_keypoints: previous-frame positions parallel to keypoints (any point container), with
/// track_valid (not given = all valid; else one flag per keypoint, checked); nothing is copied out of them
/// except into scratch buffers.
/// points_3d: optional 3-D point of each track in one fixed frame (the map point, or the reference
/// keyframe's back-projection in world or keyframe coordinates), parallel to keypoints, non-finite where
/// there is none; used by the reprojection check.
template <class T, class Keypoints, class Prev = Keypoints, class Raw = float, class Points3 = std::vector<Vec3<T>>>
struct CullingFrame {
  const Keypoints* keypoints = nullptr;
  const Prev* prev_keypoints = nullptr;
  FlagView track_valid{};
  const std::vector<std::int64_t>* track_ids = nullptr;  ///< for the probability's K term (optional)
  const Points3* points_3d = nullptr;                     ///< for the reprojection check (optional)
  const std::vector<Detection<T>>* detections = nullptr;  ///< pixel boxes after NMS
  DepthView<Raw> depth{};
  PinholeCamera<T> camera{};
  const Rigid3<T>* cam_from_world = nullptr;  ///< current pose (a motion-model prediction is enough)
  bool is_keyframe = false;  ///< store this frame's static features with depth as a multi-view reference
  /// Frames between the reference of prev_keypoints / points_3d and this frame (1: the previous frame;
  /// a keyframe-based front end: frames since its keyframe); 0 = unknown. See min_evidence_frames.
  int evidence_frames = 0;
};

namespace detail {
inline bool is_soft_cull(CullReason r) {
  return r == CullReason::Epipolar || r == CullReason::MultiView || r == CullReason::SubBox ||
         r == CullReason::MediumLevelBox || r == CullReason::TrackedBox;
}

/// Culls for the region a feature lies in (its box, tracked box or sub-box), not for its own evidence: the
/// ones a track's static history may overrule (PipelineOptions::static_history).
inline bool is_regional_cull(CullReason r) {
  return r == CullReason::SubBox || r == CullReason::HighLevelBox || r == CullReason::TrackedBox ||
         r == CullReason::MediumLevelBox;
}

template <class T, class Keypoints>
bool keypoint_in_image(const Keypoints& kp, std::size_t i, int w, int h, int* u, int* v) {
  return pixel_of(point_x<T>(kp[i]), point_y<T>(kp[i]), w, h, u, v);
}

/// PipelineOptions::low_override_by_depth: features the box rule sheltered (LowLevelOverride) that a
/// dynamic-class object's depth mask holds lose the shelter when their depth is nearer that object's d_c
/// than the d_c of every low-level box holding them. `combined` lists the dynamic-class boxes, then the
/// low-level ones (scratch); their depth is planned again with occluded_centre_search so a TV's depth is
/// not read off the walker in front of its centre. Returns how many features lost the shelter.
template <class T, class Keypoints, class Raw>
std::size_t unshelter_by_depth(const Keypoints& kp, const DepthView<Raw>& depth, const DepthMaskResult& dm,
                               const std::vector<Detection<T>>& dyn_boxes, const std::vector<Detection<T>>& boxes,
                               const MotionLevelTable& levels, DepthMaskOptions depth_options,
                               std::vector<Detection<T>>* combined, std::vector<std::uint32_t>* bits,
                               std::vector<FeatureLabel>* labels, std::vector<CullReason>* reasons,
                               std::vector<std::uint8_t>* in_dyn_box) {
  const std::size_t n = bits->size();
  bool any = false;
  for (std::size_t i = 0; i < n && !any; ++i) any = (*reasons)[i] == CullReason::LowLevelOverride && (*bits)[i] != 0;
  if (!any) return 0;
  const std::size_t nd = std::min<std::size_t>({dyn_boxes.size(), dm.boxes.size(), 32});
  combined->assign(dyn_boxes.begin(), dyn_boxes.begin() + static_cast<std::ptrdiff_t>(nd));
  for (const Detection<T>& b : boxes)
    if (levels.level(b.class_id) == MotionLevel::Low) combined->push_back(b);
  if (combined->size() == nd) return 0;
  depth_options.occluded_centre_search = true;
  // Only the per-box depths are needed: no points.
  const DepthMaskResult planned = depth_mask(depth, *combined, std::vector<Vec2<T>>{}, depth_options);
  if (!planned.ok() || planned.boxes.size() != combined->size()) return 0;
  std::size_t changed = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t b = (*bits)[i];
    if ((*reasons)[i] != CullReason::LowLevelOverride || b == 0) continue;
    int u = 0, v = 0;
    if (!keypoint_in_image<T>(kp, i, depth.width, depth.height, &u, &v)) continue;
    const double d = depth.depth_m(u, v);
    if (!(d > 0)) continue;
    // Nearest dynamic-class object among the masks holding the feature.
    std::size_t best = nd;
    double best_gap = 0;
    for (std::size_t k = 0; k < nd; ++k) {
      const double dc = dm.boxes[k].d_c_m;
      if (!(b & (std::uint32_t(1) << k)) || !(dc > 0)) continue;
      const double gap = std::abs(d - dc);
      if (best == nd || gap < best_gap) {
        best = k;
        best_gap = gap;
      }
    }
    if (best == nd) continue;
    // Sheltered by any low-level box holding it whose depth is unknown or at least as near.
    bool sheltered = false;
    const T x = point_x<T>(kp[i]), y = point_y<T>(kp[i]);
    for (std::size_t k = nd; k < combined->size() && !sheltered; ++k) {
      const Box<T>& box = (*combined)[k].box;
      if (!box.contains(x, y)) continue;
      const DepthMaskBoxInfo& info = planned.boxes[k];
      sheltered = !info.ok() || !(info.d_c_m > 0) || std::abs(d - info.d_c_m) <= best_gap;
    }
    if (sheltered) continue;
    (*bits)[i] = std::uint32_t(1) << best;
    (*in_dyn_box)[i] = 1;
    if (levels.level(dyn_boxes[best].class_id) == MotionLevel::High) {
      (*labels)[i] = FeatureLabel::Dynamic;
      (*reasons)[i] = CullReason::HighLevelBox;
    } else {
      (*labels)[i] = FeatureLabel::Candidate;
      (*reasons)[i] = CullReason::MediumLevelBox;
    }
    ++changed;
  }
  return changed;
}

/// PipelineOptions::assign_overlaps_by_depth: for features inside a dynamic-class box whose depth
/// masks hold them, keeps one mask bit (the box with d_c nearest the feature's depth, a high-level box's
/// gap counted `high_level_margin_m` smaller; ties and missing depth: the highest level, then the first
/// box) and sets the semantic label from that box's level.
template <class T, class Keypoints, class Raw>
void assign_overlaps_by_depth(const Keypoints& kp, const DepthView<Raw>& depth, const DepthMaskResult& dm,
                              const std::vector<Detection<T>>& dyn_boxes, const MotionLevelTable& levels,
                              std::vector<std::uint32_t>* bits, std::vector<FeatureLabel>* labels,
                              std::vector<CullReason>* reasons, double high_level_margin_m = 0) {
  const std::size_t n = bits->size();
  const std::size_t nb = std::min<std::size_t>({dyn_boxes.size(), dm.boxes.size(), 32});
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t b = (*bits)[i];
    const CullReason why = (*reasons)[i];
    // Only the box rule's own labels are re-decided (not a low-level override or invalid input).
    if (b == 0 || !(why == CullReason::HighLevelBox || why == CullReason::MediumLevelBox || why == CullReason::DepthMask))
      continue;
    int u = 0, v = 0;
    float d = 0.f;
    if (keypoint_in_image<T>(kp, i, depth.width, depth.height, &u, &v)) d = depth.depth_m(u, v);
    std::size_t best = nb;
    double best_gap = 0;
    MotionLevel best_level = MotionLevel::Ignore;
    for (std::size_t k = 0; k < nb; ++k) {
      if (!(b & (std::uint32_t(1) << k))) continue;
      const MotionLevel lv = levels.level(dyn_boxes[k].class_id);
      const double dc = dm.boxes[k].d_c_m;
      double gap = d > 0.f && dc > 0 ? std::abs(static_cast<double>(d) - dc) : 0.0;
      if (lv == MotionLevel::High && d > 0.f && dc > 0) gap -= high_level_margin_m;
      const bool better = best == nb || gap < best_gap ||
                          (gap == best_gap && lv == MotionLevel::High && best_level != MotionLevel::High);
      if (better) {
        best = k;
        best_gap = gap;
        best_level = lv;
      }
    }
    if (best == nb) continue;
    (*bits)[i] = std::uint32_t(1) << best;
    if (best_level == MotionLevel::High && (*labels)[i] != FeatureLabel::Dynamic) {
      (*labels)[i] = FeatureLabel::Dynamic;
      (*reasons)[i] = CullReason::HighLevelBox;
    } else if (best_level == MotionLevel::Medium && (*labels)[i] == FeatureLabel::Dynamic) {
      (*labels)[i] = FeatureLabel::Candidate;
      (*reasons)[i] = CullReason::MediumLevelBox;
    }
  }
}
}  // namespace detail

/// Runs the enabled strategies on one frame and returns the labels (a reference into `state`, valid
/// until the next call). Never throws; bad or missing inputs skip the stages that need them, with a
/// reason in the stage report. Options that fail PipelineOptions::validate, an invalid depth view
/// (DepthView::validate) or a track_valid whose size is not the keypoints' give status InvalidInput with
/// the reason and cull nothing: every keypoint is labelled Static and kept.
template <class T, class Keypoints, class Prev, class Raw, class Points3>
const PipelineResult<T>& cull_frame(const CullingFrame<T, Keypoints, Prev, Raw, Points3>& frame,
                                    const PipelineOptions<T>& options, PipelineState<T>* state) {
  static_assert(is_point_container_v<Keypoints>, "dyncull::cull_frame: keypoints must hold points (see PointTraits)");
  static_assert(is_point_container_v<Prev>, "dyncull::cull_frame: prev_keypoints must hold points");
  PipelineState<T>& s = *state;
  PipelineResult<T>& r = s.result;
  ++s.frame_index;
  r.status = Status::Ok;
  r.reason.clear();
  r.guard = GuardAction::None;
  r.guard_restored = 0;
  r.history_kept = 0;
  r.unsheltered = 0;
  for (StageReport* st : {&r.detections, &r.tracker, &r.box_rule, &r.depth_mask, &r.probability, &r.moving_consistency,
                          &r.reprojection, &r.coherent_motion, &r.subbox, &r.multiview, &r.static_history}) {
    st->status = Status::Skipped;
    st->reason.clear();
    st->num_dynamic = 0;
  }
  r.detections.enabled = options.use_detection_filter;
  r.tracker.enabled = options.use_box_tracker;
  r.box_rule.enabled = options.use_box_rule;
  r.depth_mask.enabled = options.use_depth_mask;
  r.probability.enabled = options.use_probability;
  r.moving_consistency.enabled = options.use_moving_consistency;
  r.reprojection.enabled = options.use_reprojection;
  r.coherent_motion.enabled = options.use_coherent_motion;
  if (options.use_coherent_motion)
    r.coherent_motion.reason = "runs with the sub-box refinement, on the reprojection check's residuals";
  r.subbox.enabled = options.use_subbox;
  r.multiview.enabled = options.use_multiview;
  r.static_history.enabled = options.static_history.min_frames > 0;

  if (!frame.keypoints) {
    r.status = Status::InvalidInput;
    r.reason = "no keypoints given";
    r.labels.clear();
    r.reasons.clear();
    r.keep.clear();
    r.num_features = r.num_static = r.num_dynamic = 0;
    return r;
  }
  const Keypoints& kp = *frame.keypoints;
  const std::size_t n = static_cast<std::size_t>(kp.size());
  const int W = frame.camera.width, H = frame.camera.height;
  r.num_features = n;
  r.labels.assign(n, FeatureLabel::Static);
  r.reasons.assign(n, CullReason::None);
  {
    std::string why;
    Status bad = Status::Ok;
    if (options.validate(&why) != Status::Ok) {
      bad = Status::InvalidInput;
      why = "invalid options: " + why;
    } else if (frame.depth.validate(&why) != Status::Ok) {
      bad = Status::InvalidInput;
    } else if (!frame.track_valid.empty() && !frame.track_valid.holds(n)) {
      bad = Status::InvalidInput;
      why = "track_valid has " + std::to_string(frame.track_valid.size) + " flags for " + std::to_string(n) +
            " keypoints";
    }
    if (bad != Status::Ok) {
      r.status = bad;
      r.reason = why;
      r.keep.assign(n, 1);
      r.num_static = n;
      r.num_dynamic = 0;
      return r;
    }
  }
  const std::uint8_t* const track_valid = frame.track_valid.empty() ? nullptr : frame.track_valid.data;
  s.sem_labels.assign(n, FeatureLabel::Static);
  s.sem_reasons.assign(n, CullReason::None);
  s.in_dyn_box.assign(n, 0);
  s.in_object.assign(n, 1);
  s.mv_dynamic.assign(n, 0);
  const bool have_tracks = frame.prev_keypoints && static_cast<std::size_t>(frame.prev_keypoints->size()) == n;
  auto no_tracks = [&]() {  // the reason of a stage that needs tracks (built only when it is needed)
    return frame.prev_keypoints ? "prev_keypoints has " + std::to_string(frame.prev_keypoints->size()) +
                                      " positions for " + std::to_string(n) + " keypoints"
                                : std::string("no previous-frame positions (tracks) given");
  };

  // 1. Boxes: filter (padding, class thresholds), then carry missed ones forward.
  s.boxes.clear();
  if (frame.detections) {
    if (options.use_detection_filter) {
      DetectionsResult<T> d = filter_detections(*frame.detections, W, H, options.detections);
      r.detections.status = d.status;
      r.detections.reason = d.reason;
      if (d.ok()) s.boxes = d.detections;
    } else {
      s.boxes = *frame.detections;
    }
  } else if (options.use_detection_filter) {
    r.detections.reason = "no detections given";
  }
  if (options.use_box_tracker) {
    // Only dynamic-class boxes are tracked: carrying a missed (or one-frame false positive) low-level box
    // would only stretch its shelter over whatever moves in front of it.
    s.untracked_boxes.clear();
    std::size_t kept = 0;
    for (std::size_t b = 0; b < s.boxes.size(); ++b) {
      const MotionLevel lv = options.levels.level(s.boxes[b].class_id);
      if (lv == MotionLevel::High || lv == MotionLevel::Medium)
        s.boxes[kept++] = s.boxes[b];
      else
        s.untracked_boxes.push_back(s.boxes[b]);
    }
    s.boxes.resize(kept);
    BoxTrackerResult<T> t = s.tracker.update(s.boxes, W, H);
    r.tracker.status = t.status;
    r.tracker.reason = t.reason;
    s.box_track_id.assign(s.boxes.size(), -1);
    if (t.ok()) {
      s.boxes = t.boxes;
      s.box_track_id = t.track_id;
    }
    s.boxes.insert(s.boxes.end(), s.untracked_boxes.begin(), s.untracked_boxes.end());
    s.box_track_id.resize(s.boxes.size(), -1);
  } else {
    s.box_track_id.assign(s.boxes.size(), -1);
  }
  // Dynamic-class boxes (high and medium level): the ones sub-box refinement and the depth mask act on.
  s.dyn_boxes.clear();
  s.dyn_box_source.clear();
  s.dyn_box_track_id.clear();
  for (std::size_t b = 0; b < s.boxes.size(); ++b) {
    const MotionLevel lv = options.levels.level(s.boxes[b].class_id);
    if (lv == MotionLevel::High || lv == MotionLevel::Medium) {
      s.dyn_boxes.push_back(s.boxes[b]);
      s.dyn_box_source.push_back(static_cast<std::int32_t>(b));
      s.dyn_box_track_id.push_back(b < s.box_track_id.size() ? s.box_track_id[b] : -1);
    }
  }

  // 2. Box rule.
  std::vector<std::int32_t> no_index;
  const std::vector<std::int32_t>* rule_box_index = &no_index;
  BoxRuleResult<T> rule;
  if (options.use_box_rule) {
    rule = apply_box_rule(kp, s.boxes, options.levels, options.box_rule);
    r.box_rule.status = rule.status;
    r.box_rule.reason = rule.reason;
    if (rule.ok()) {
      rule_box_index = &rule.box_index;
      for (std::size_t i = 0; i < n; ++i) {
        s.sem_labels[i] = rule.labels[i];
        s.sem_reasons[i] = rule.reasons[i];
        s.in_dyn_box[i] = rule.reasons[i] == CullReason::HighLevelBox || rule.reasons[i] == CullReason::MediumLevelBox;
      }
      r.box_rule.num_dynamic = rule.num_dynamic;
    }
  }

  // 3. Depth mask: inside dynamic-class boxes only the object's depth band is culled.
  if (options.use_depth_mask) {
    if (frame.depth.empty()) {
      r.depth_mask.reason = "no depth image";
    } else {
      const DepthMaskResult dm = depth_mask(frame.depth, s.dyn_boxes, kp, options.depth_mask);
      r.depth_mask.status = dm.status;
      r.depth_mask.reason = dm.reason;
      if (dm.ok()) {
        r.depth_mask.num_dynamic = dm.num_dynamic;
        s.object_box_bits.assign(dm.box_bits.begin(), dm.box_bits.end());
        if (options.low_override_by_depth && options.use_box_rule)
          r.unsheltered = detail::unshelter_by_depth(kp, frame.depth, dm, s.dyn_boxes, s.boxes, options.levels,
                                                     options.depth_mask, &s.shelter_boxes, &s.object_box_bits,
                                                     &s.sem_labels, &s.sem_reasons, &s.in_dyn_box);
        if (options.assign_overlaps_by_depth && options.use_box_rule)
          detail::assign_overlaps_by_depth(kp, frame.depth, dm, s.dyn_boxes, options.levels, &s.object_box_bits,
                                           &s.sem_labels, &s.sem_reasons, options.overlap_high_level_margin_m);
        for (std::size_t i = 0; i < n; ++i) {
          s.in_object[i] = dm.labels[i] != FeatureLabel::Static;
          if (dm.labels[i] == FeatureLabel::Dynamic && dm.reasons[i] == CullReason::InvalidInput) {
            s.sem_labels[i] = FeatureLabel::Dynamic;
            s.sem_reasons[i] = CullReason::InvalidInput;
          } else if (s.in_dyn_box[i] && dm.labels[i] == FeatureLabel::Static) {
            s.sem_labels[i] = FeatureLabel::Static;  // box background behind or in front of the object
            s.sem_reasons[i] = CullReason::None;
          } else if (s.in_dyn_box[i] && dm.labels[i] == FeatureLabel::Dynamic &&
                     s.sem_labels[i] == FeatureLabel::Dynamic) {
            s.sem_reasons[i] = CullReason::DepthMask;
          } else if (!options.use_box_rule && dm.labels[i] != FeatureLabel::Static) {
            s.sem_labels[i] = dm.labels[i];
            s.sem_reasons[i] = dm.reasons[i];
            s.in_dyn_box[i] = 1;
          }
        }
      }
    }
  }

  // 4. Moving consistency (tracks -> F -> eq. 3 distance), SG-SLAM fit outside boxes when flagged.
  const bool have_boxes = !s.dyn_boxes.empty();
  if (options.use_moving_consistency) {
    if (!have_tracks) {
      r.moving_consistency.reason = no_tracks();
    } else {
      check_moving_consistency(*frame.prev_keypoints, kp, options.moving, &s.moving, track_valid,
                               have_boxes ? s.in_dyn_box.data() : nullptr);
      r.moving_consistency.status = s.moving.status;
      r.moving_consistency.reason = s.moving.reason;
      r.moving_consistency.num_dynamic = s.moving.num_dynamic;
    }
  }
  // 4b. Reprojection check (RGB-D): merged into s.moving.labels, the geometric evidence of the later stages.
  if (options.use_reprojection) {
    if (!frame.points_3d) {
      r.reprojection.reason = "no 3-D points (CullingFrame::points_3d) given";
    } else {
      check_reprojection(*frame.points_3d, kp, frame.camera, options.reprojection, &s.reprojection, track_valid,
                         have_boxes ? s.in_dyn_box.data() : nullptr, frame.depth);
      r.reprojection.status = s.reprojection.status;
      r.reprojection.reason = s.reprojection.reason;
      r.reprojection.num_dynamic = s.reprojection.num_dynamic;
    }
    if (r.reprojection.ran()) {
      if (!r.moving_consistency.ran()) {
        s.moving.labels = s.reprojection.labels;
      } else {
        for (std::size_t i = 0; i < n; ++i) {
          const FeatureLabel rl = s.reprojection.labels[i];
          FeatureLabel& gl = s.moving.labels[i];
          if (options.reprojection_evidence == PipelineOptions<T>::Evidence::Replace) {
            if (rl != FeatureLabel::Candidate) gl = rl;
          } else if (rl == FeatureLabel::Dynamic || gl == FeatureLabel::Candidate) {
            gl = rl == FeatureLabel::Candidate ? gl : rl;
          }
        }
      }
    }
  }
  const bool geo_ok = r.moving_consistency.ran() || r.reprojection.ran();
  // Every check whose labels are in the evidence fitted its model outside the dynamic-class boxes.
  const bool geo_fit_outside_boxes = (!r.moving_consistency.ran() || s.moving.fitted_outside_boxes) &&
                                     (!r.reprojection.ran() || s.reprojection.fitted_outside_boxes);
  // Flags on depth edges stop counting (edge_evidence_radius_px); s.moving keeps its own num_dynamic.
  if (geo_ok && options.edge_evidence_radius_px > 0 && !frame.depth.empty()) {
    std::size_t discounted = 0;
    for (std::size_t i = 0; i < n; ++i) {
      int u = 0, v = 0;
      if (s.moving.labels[i] != FeatureLabel::Dynamic ||
          !detail::keypoint_in_image<T>(kp, i, frame.depth.width, frame.depth.height, &u, &v))
        continue;
      if (depth_step_near(frame.depth, u, v, options.edge_evidence_radius_px, options.edge_depth_step_ratio)) {
        s.moving.labels[i] = FeatureLabel::Candidate;
        ++discounted;
      }
    }
    r.moving_consistency.num_dynamic -= std::min(r.moving_consistency.num_dynamic, discounted);
  }

  // 5. Dynamic probability for features in object masks (000 Algorithm 1).
  if (options.use_probability) {
    if (!have_tracks) {
      r.probability.reason = no_tracks();
    } else {
      s.prob_levels.assign(n, MotionLevel::Ignore);
      s.prob_prev.resize(n);
      for (std::size_t i = 0; i < n; ++i) {
        const bool valid = !track_valid || track_valid[i] != 0;
        s.prob_prev[i] = valid ? Vec2<T>(point_x<T>((*frame.prev_keypoints)[i]), point_y<T>((*frame.prev_keypoints)[i]))
                               : Vec2<T>(Constants<T>::nan(), Constants<T>::nan());
        if (s.in_dyn_box[i] && s.in_object[i] && i < rule_box_index->size() && (*rule_box_index)[i] >= 0)
          s.prob_levels[i] = options.levels.level(s.boxes[static_cast<std::size_t>((*rule_box_index)[i])].class_id);
      }
      EgoMotion<T> ego;
      if (options.probability_flow_model == FlowModel::Fundamental && r.moving_consistency.ran()) {
        ego.model = FlowModel::Fundamental;
        ego.matrix = s.moving.F;
      }
      if (frame.track_ids) s.track_states.begin_frame();
      const DynamicProbabilityResult<T> pr = dynamic_probability(s.prob_prev, kp, s.prob_levels, options.probability, ego,
                                                                 frame.track_ids ? &s.track_states : nullptr, frame.track_ids);
      r.probability.status = pr.status;
      r.probability.reason = pr.reason;
      if (pr.ok()) {
        r.probability.num_dynamic = pr.num_dynamic;
        for (std::size_t i = 0; i < n; ++i) {
          if (s.prob_levels[i] == MotionLevel::Ignore || s.sem_reasons[i] == CullReason::InvalidInput) continue;
          s.sem_labels[i] = pr.labels[i];
          s.sem_reasons[i] = pr.labels[i] == FeatureLabel::Dynamic ? CullReason::Probability : CullReason::None;
        }
      }
    }
  }

  // 6. Sub-box refinement of the dynamic-class boxes with the geometric labels.
  if (options.use_subbox) {
    const bool masks = options.use_depth_mask && r.depth_mask.ran();
    if (!geo_ok) {
      r.subbox.reason = "needs geometric labels (moving consistency or reprojection), unavailable this frame";
    } else if (!have_boxes) {
      r.subbox.reason = "no dynamic-class boxes";
    } else if (options.min_evidence_frames > 0 && frame.evidence_frames > 0 &&
               frame.evidence_frames < options.min_evidence_frames) {
      const std::size_t recalled =
          options.short_baseline_keeps_last_vote && options.use_box_tracker && r.tracker.ran()
              ? s.subbox_memory.recall_states(s.dyn_box_track_id, options.subbox.grid, s.frame_index,
                                              options.min_evidence_frames, &s.remembered_cells)
              : 0;
      if (recalled > 0) {
        apply_subbox_states(kp, s.moving.labels.data(), s.dyn_boxes, s.remembered_cells.data(), options.subbox, &s.subbox,
                            masks ? s.in_object.data() : nullptr, masks ? s.object_box_bits.data() : nullptr);
        r.subbox.status = s.subbox.status;
        r.subbox.num_dynamic = s.subbox.num_dynamic;
      }
      r.subbox.reason = "baseline of " + std::to_string(frame.evidence_frames) +
                        " frame(s) too short for static evidence (min_evidence_frames): " +
                        (recalled > 0 ? "the last vote of " + std::to_string(recalled) +
                                            " tracked box(es) kept, the box rule elsewhere"
                                      : std::string("the box rule decides"));
    } else if (options.subbox_requires_fit_outside_boxes && !geo_fit_outside_boxes &&
               std::any_of(s.in_dyn_box.begin(), s.in_dyn_box.end(), [](std::uint8_t f) { return f != 0; })) {
      r.subbox.reason = "F or the pose was fitted through the dynamic-class boxes (too few tracks outside them): "
                        "its evidence inside the boxes is not trusted";
    } else {
      if (options.use_coherent_motion) {
        if (!r.reprojection.ran() || s.reprojection.residual_vec.size() != n) {
          r.coherent_motion.reason = "needs the reprojection check's residuals (use_reprojection, points_3d)";
        } else {
          CoherentMotionOptions<T> co = options.coherent_motion;
          co.grid = options.subbox.grid;  // the cells the vote will count
          // High-level objects only: a candidate (a chair) stays verified on its own evidence.
          s.coherent_eligible.resize(n);
          for (std::size_t i = 0; i < n; ++i) s.coherent_eligible[i] = s.sem_labels[i] == FeatureLabel::Dynamic;
          flag_coherent_cells(kp, s.reprojection.residual_vec.data(), s.dyn_boxes, s.reprojection.inlier_noise_px, co,
                              s.moving.labels.data(), &s.coherent_motion, masks ? s.in_object.data() : nullptr,
                              masks ? s.object_box_bits.data() : nullptr, s.coherent_eligible.data());
          r.coherent_motion.status = s.coherent_motion.status;
          r.coherent_motion.reason = s.coherent_motion.reason;
          r.coherent_motion.num_dynamic = s.coherent_motion.num_flagged;
        }
      }
      const bool memory = options.subbox_memory_frames > 0 && options.use_box_tracker && r.tracker.ran() &&
                          frame.track_ids && frame.track_ids->size() == n;
      if (memory) {
        s.subbox_memory.recall(s.dyn_box_track_id, options.subbox.grid, s.frame_index, options.subbox_memory_frames,
                               &s.remembered_cells);
        s.subbox_memory.update_tracks(*frame.track_ids, s.moving.labels.data(), s.frame_index,
                                      options.subbox_memory_frames, &s.memory_eligible);
      }
      refine_subboxes(kp, s.moving.labels.data(), s.dyn_boxes, options.subbox, &s.subbox,
                      masks ? s.in_object.data() : nullptr, masks ? s.object_box_bits.data() : nullptr,
                      memory ? s.remembered_cells.data() : nullptr, memory ? s.memory_eligible.data() : nullptr);
      if (memory && s.subbox.ok())
        s.subbox_memory.remember(s.dyn_box_track_id, s.subbox, options.subbox, s.frame_index,
                                 options.subbox_memory_frames);
      if (options.short_baseline_keeps_last_vote && options.min_evidence_frames > 0 && options.use_box_tracker &&
          r.tracker.ran() && s.subbox.ok())
        s.subbox_memory.remember_states(s.dyn_box_track_id, s.subbox, options.subbox, s.frame_index,
                                        options.min_evidence_frames);
      r.subbox.status = s.subbox.status;
      r.subbox.reason = s.subbox.reason;
      r.subbox.num_dynamic = s.subbox.num_dynamic;
      if (options.subbox_memory_frames > 0 && !memory && s.subbox.ok())
        r.subbox.reason = "sub-box memory off this frame: it needs the box tracker and CullingFrame::track_ids";
    }
  }
  const bool subbox_ok = r.subbox.ran();

  // 7. Multi-view depth check against stored keyframes, grown into a mask over the depth image.
  if (options.use_multiview) {
    if (!frame.cam_from_world || !frame.cam_from_world->all_finite()) {
      r.multiview.reason = "no current pose (tracking not initialised or lost)";
    } else if (s.keyframes.empty()) {
      r.multiview.reason = "no keyframe stored yet";
    } else if (frame.depth.empty()) {
      r.multiview.reason = "no depth image";
    } else if (!options.multiview_overrides_static &&
               std::none_of(s.sem_labels.begin(), s.sem_labels.end(),
                            [](FeatureLabel l) { return l == FeatureLabel::Candidate; })) {
      r.multiview.reason = "no candidate features to verify (multiview_overrides_static is off)";
    } else {
      // Growth only where labels are still open: all the image, or around the candidates.
      PixelRect roi{0, 0, frame.depth.width, frame.depth.height};
      if (!options.multiview_overrides_static) {
        roi = PixelRect{frame.depth.width, frame.depth.height, 0, 0};
        for (std::size_t i = 0; i < n; ++i) {
          int u = 0, v = 0;
          if (s.sem_labels[i] != FeatureLabel::Candidate ||
              !detail::keypoint_in_image<T>(kp, i, frame.depth.width, frame.depth.height, &u, &v))
            continue;
          roi.c0 = std::min(roi.c0, u);
          roi.r0 = std::min(roi.r0, v);
          roi.c1 = std::max(roi.c1, u + 1);
          roi.r1 = std::max(roi.r1, v + 1);
        }
      }
      s.ref_index.resize(std::max<std::size_t>(1, std::min(options.max_reference_keyframes, s.keyframes.size())));
      const std::size_t k = s.keyframes.select_references(*frame.cam_from_world, options.max_reference_keyframes,
                                                          s.ref_index.data());
      if (s.multiview_mask.width != frame.depth.width || s.multiview_mask.height != frame.depth.height)
        s.multiview_mask.reset(frame.depth.width, frame.depth.height, 0);
      else
        std::fill(s.multiview_mask.pixels.begin(), s.multiview_mask.pixels.end(), std::uint8_t(0));
      std::size_t checked = 0;
      for (std::size_t j = 0; j < k; ++j) {
        const MultiViewKeyframe<T>& kf = s.keyframes[s.ref_index[j]];
        check_multiview(kf.points, kf.depth_m, kf.cam_from_world, *frame.cam_from_world, frame.depth, frame.camera,
                        options.multiview, &s.multiview);
        if (s.multiview.num_checked == 0) continue;
        ++checked;
        grow_multiview_regions(s.multiview, frame.depth, options.multiview, &s.multiview_mask, &s.flood_stack, &roi);
      }
      if (checked == 0) {
        r.multiview.status = Status::TooFewPoints;
        r.multiview.reason = "no keyframe point could be compared";
      } else {
        r.multiview.status = Status::Ok;
        for (std::size_t i = 0; i < n; ++i) {
          int u = 0, v = 0;
          if (detail::keypoint_in_image<T>(kp, i, s.multiview_mask.width, s.multiview_mask.height, &u, &v))
            s.mv_dynamic[i] = s.multiview_mask.pixels[static_cast<std::size_t>(v) * s.multiview_mask.width + u] != 0;
          r.multiview.num_dynamic += s.mv_dynamic[i];
        }
      }
    }
  }
  const bool mv_ok = r.multiview.ran();

  // 8. Combination, in the order of evidence strength: semantics, then the geometric refinements.
  for (std::size_t i = 0; i < n; ++i) {
    FeatureLabel lab = s.sem_labels[i];
    CullReason why = s.sem_reasons[i];
    if (why == CullReason::InvalidInput) {
      r.labels[i] = FeatureLabel::Dynamic;
      r.reasons[i] = why;
      continue;
    }
    const bool sheltered = why == CullReason::LowLevelOverride;
    const bool geo_dyn = geo_ok && s.moving.labels[i] == FeatureLabel::Dynamic;
    bool geo_flagged = geo_dyn;
    if (subbox_ok) {
      if (lab == FeatureLabel::Candidate && !options.subbox_verifies_candidates) {
        // Stays a candidate, verified below on its own evidence: flagged itself inside a dynamic sub-box,
        // or by the multi-view check.
        geo_flagged = geo_dyn && s.subbox.reasons[i] == CullReason::SubBox;
        if (geo_flagged) why = CullReason::SubBox;
      } else if (s.subbox.reasons[i] == CullReason::SubBox && (!sheltered || geo_dyn)) {
        lab = FeatureLabel::Dynamic;
        why = CullReason::SubBox;
        geo_flagged = true;
      } else if (s.in_dyn_box[i] && s.sem_reasons[i] != CullReason::Probability) {
        lab = FeatureLabel::Static;  // refined: in a static sub-box of its box
        why = CullReason::None;
      } else if (geo_dyn && options.cull_geometric_outside_boxes && lab == FeatureLabel::Static && !sheltered) {
        lab = FeatureLabel::Dynamic;
        why = CullReason::Epipolar;
      }
    } else if (geo_dyn && lab != FeatureLabel::Dynamic &&
               (lab == FeatureLabel::Candidate || (options.cull_geometric_outside_boxes && !sheltered))) {
      lab = FeatureLabel::Dynamic;
      why = CullReason::Epipolar;
    }
    if (mv_ok && s.mv_dynamic[i]) {
      geo_flagged = true;
      if (lab == FeatureLabel::Candidate || (lab == FeatureLabel::Static && options.multiview_overrides_static)) {
        lab = FeatureLabel::Dynamic;
        why = CullReason::MultiView;
      }
    }
    if (lab == FeatureLabel::Candidate) {
      const bool cull = options.candidates == CandidatePolicy::Cull ||
                        (options.candidates == CandidatePolicy::Verify && geo_flagged);
      lab = cull ? FeatureLabel::Dynamic : FeatureLabel::Static;
      if (!cull) why = CullReason::None;
    }
    r.labels[i] = lab;
    r.reasons[i] = lab == FeatureLabel::Static ? CullReason::None : why;
  }

  // 8b. Static history: a track proven still over its last frames outweighs its region's cull.
  s.history_kept.assign(n, 0);
  if (r.static_history.enabled) {
    if (!frame.track_ids || frame.track_ids->size() != n) {
      r.static_history.reason = "needs CullingFrame::track_ids";
    } else {
      const bool checked =
          r.reprojection.ran() && s.reprojection.labels.size() == n && s.reprojection.residual_px.size() == n;
      // A baseline too short to vote (min_evidence_frames) is too short to prove a slow mover still.
      const bool evaluated = checked && (frame.evidence_frames <= 0 ||
                                         frame.evidence_frames >= std::max(1, options.min_evidence_frames));
      s.static_history.update(*frame.track_ids, checked ? s.reprojection.labels.data() : nullptr,
                              checked ? s.reprojection.residual_px.data() : nullptr, evaluated,
                              options.static_history.max_residual_px, &s.still_frames);
      if (!checked) {
        r.static_history.reason =
            "needs the reprojection check (use_reprojection, points_3d), which did not run: counts carried over";
      } else {
        const auto min_frames = static_cast<std::uint16_t>(std::min(options.static_history.min_frames, 0xFFFF));
        for (std::size_t i = 0; i < n; ++i) {
          if (r.labels[i] != FeatureLabel::Dynamic || !detail::is_regional_cull(r.reasons[i]) ||
              s.still_frames[i] < min_frames || s.reprojection.labels[i] == FeatureLabel::Dynamic)
            continue;
          r.labels[i] = FeatureLabel::Static;
          r.reasons[i] = CullReason::None;
          s.history_kept[i] = 1;
          ++r.history_kept;
        }
        r.static_history.status = Status::Ok;
        r.static_history.reason = std::to_string(r.history_kept) + " feature(s) kept static by their history";
      }
    }
  }

  // 9. Minimum-survivor guard.
  auto count_static = [&]() {
    std::size_t c = 0;
    for (std::size_t i = 0; i < n; ++i) c += r.labels[i] == FeatureLabel::Static;
    return c;
  };
  std::size_t survivors = count_static();
  // The fraction is clamped to [0, 1] before the conversion (validate() rejects others; NaN counts as 0).
  const double survivor_fraction = options.min_survivor_fraction >= 0 ? std::min(options.min_survivor_fraction, 1.0) : 0.0;
  const std::size_t need =
      std::max(options.min_survivors, static_cast<std::size_t>(std::ceil(survivor_fraction * double(n))));
  if (options.survivor_guard && survivors < need && n > 0) {
    std::size_t soft = 0;
    for (std::size_t i = 0; i < n; ++i) soft += r.labels[i] == FeatureLabel::Dynamic && detail::is_soft_cull(r.reasons[i]);
    const bool soften_enough = survivors + soft >= need;
    for (std::size_t i = 0; i < n; ++i) {
      if (r.labels[i] != FeatureLabel::Dynamic || r.reasons[i] == CullReason::InvalidInput) continue;
      if (soften_enough && !detail::is_soft_cull(r.reasons[i])) continue;
      r.labels[i] = FeatureLabel::Static;
      r.reasons[i] = CullReason::SurvivorGuardUndo;
      ++r.guard_restored;
    }
    r.guard = soften_enough ? GuardAction::Softened : GuardAction::Undone;
    r.reason = std::string("survivor guard ") + to_string(r.guard) + ": " + std::to_string(survivors) +
               " static features of " + std::to_string(n) + " were below " + std::to_string(need) + ", " +
               std::to_string(r.guard_restored) + " restored";
    survivors = count_static();
  }
  r.num_static = survivors;
  r.num_dynamic = n - survivors;
  r.keep.resize(n);
  for (std::size_t i = 0; i < n; ++i) r.keep[i] = r.labels[i] == FeatureLabel::Static;

  // 10. Keyframe for later multi-view checks: this frame's static features with their depth.
  if (frame.is_keyframe && frame.cam_from_world && frame.cam_from_world->all_finite() && !frame.depth.empty()) {
    s.keypoint_depth.assign(n, T(0));
    for (std::size_t i = 0; i < n; ++i) {
      int u = 0, v = 0;
      if (detail::keypoint_in_image<T>(kp, i, frame.depth.width, frame.depth.height, &u, &v))
        s.keypoint_depth[i] = T(frame.depth.depth_m(u, v));
    }
    s.keyframes.push(*frame.cam_from_world, kp, s.keypoint_depth, r.keep.data());
  }
  return r;
}

}  // namespace dyncull
