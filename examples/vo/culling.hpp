/// @file culling.hpp
/// The culling strategies the dynamic_vo demo compares: no culling, each dyncull preset
/// (culling/presets.hpp, run by culling/pipeline.hpp's cull_frame) and a truth oracle on the sim,
/// applied to the current frame's tracked features before PnP; on request, the recommended preset with
/// one kind of error repaired by the sim's truth (what each kind costs the pose).
#pragma once

#include "dyncull/core/camera.hpp"
#include "dyncull/core/types.hpp"
#include "dyncull/culling/pipeline.hpp"
#include "dyncull/culling/presets.hpp"
#include "dyncull/opencv/views.hpp"

#include "frontend.hpp"
#include "report.hpp"
#include "sources.hpp"

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace dyncull {
namespace vo {

/// Which of a preset's errors the sim's truth repairs (diagnostic strategies, never in the default run).
enum class TruthRepair : std::uint8_t {
  None,
  RestoreFalseCulls,  ///< static features it culled are kept: precision 1, recall unchanged
  CullMisses,         ///< moving features it kept are culled: recall 1, precision unchanged
};

/// One strategy: a name for the table and how to build its culling.
struct StrategySpec {
  std::string name;
  std::string description;
  bool culls = false;             ///< false only for the no-culling reference
  bool needs_detections = false;  ///< cannot run without detector boxes
  bool recommended = false;       ///< the library's recommended default preset
  bool oracle = false;            ///< culls by the sim's per-pixel truth: the bound no culling can beat
  /// Evidence against the keyframe: the epipolar check between its positions (Tracks::kf_px) and the
  /// current frame instead of the previous frame, and the reprojection check of the points measured in
  /// its depth (Tracks::kf_world). What the recommended preset expects (presets.hpp); the papers' presets
  /// use the previous frame and no 3-D points.
  bool tracks_from_keyframe = false;
  PipelineOptions<float> pipeline{};
  TruthRepair truth_repair = TruthRepair::None;
  bool in_default = true;  ///< run when --strategies does not name the strategies

  /// Needs the sim's per-pixel motion truth (cannot run on a TUM directory).
  bool needs_truth() const { return oracle || truth_repair != TruthRepair::None; }
};

/// "none" first (the reference of the improvement column), then the presets, then the oracle, then the
/// truth-repaired copies of the recommended preset (only when named in --strategies).
inline std::vector<StrategySpec> all_strategies() {
  std::vector<StrategySpec> out;
  auto add = [&](const char* name, const char* description, bool culls, bool dets, bool rec, bool oracle,
                 PipelineOptions<float> o) {
    out.push_back(StrategySpec{name, description, culls, dets, rec, oracle, rec, o});
  };
  add("none", "no culling: every tracked feature goes to PnP-RANSAC", false, false, false, false,
      presets::none<float>());
  add("dld_slam", "000: depth mask in boxes + dynamic probability", true, true, false, false, presets::dld_slam<float>());
  add("rtd_slam", "001: motion levels, box culling, multi-view check", true, true, false, false,
      presets::rtd_slam<float>());
  add("zhu_2024", "002: static/dynamic box rule", true, true, false, false, presets::zhu_2024<float>());
  add("dfd_slam", "003: epipolar check + 3x3 sub-box refinement", true, false, false, false, presets::dfd_slam<float>());
  add("zhang_2023", "004: high/medium/low logical discrimination", true, true, false, false,
      presets::zhang_2023<float>());
  add("recommended", "dyncull's recommended preset (box rule + depth band + epipolar vs keyframe / sub-box + guard)",
      true, true, true, false, presets::recommended<float>());
  add("oracle", "culls exactly the features on moving surfaces (sim truth): the best any culling can do", true, false,
      false, true, presets::none<float>());
  // The recommended preset with one kind of error undone by the truth: how much of its ATE gap to the oracle
  // its false culls cause, and how much its missed movers.
  const StrategySpec recommended =
      *std::find_if(out.begin(), out.end(), [](const StrategySpec& s) { return s.recommended; });
  for (const TruthRepair repair : {TruthRepair::RestoreFalseCulls, TruthRepair::CullMisses}) {
    StrategySpec spec = recommended;
    const bool restore = repair == TruthRepair::RestoreFalseCulls;
    spec.name = restore ? "recommended_no_false_culls" : "recommended_no_misses";
    spec.description = restore ? "recommended, but the static features it culls are kept (sim truth; diagnostic)"
                               : "recommended, but the moving features it keeps are culled (sim truth; diagnostic)";
    spec.recommended = false;
    spec.truth_repair = repair;
    spec.in_default = false;
    out.push_back(spec);
  }
  return out;
}

/// Per-strategy culling state carried frame to frame.
class Culler {
 public:
  /// Multi-view references are stored every this many frames (at the motion-model pose).
  static constexpr int kReferenceEvery = 5;

  Culler(const StrategySpec& spec, const PinholeCamera<double>& camera)
      : spec_(spec), camera_(camera.cast<float>()) {}

  /// keep[i] != 0 for the tracks PnP may use. `predicted_world_from_cam`: the motion-model pose;
  /// `frames_since_keyframe`: FrontEnd::frames_since_keyframe() (the baseline of tracks from the keyframe).
  void cull(const SequenceFrame& frame, const Tracks& tracks, const Rigid3<double>& predicted_world_from_cam,
            int frames_since_keyframe, std::vector<std::uint8_t>* keep) {
    keep->assign(tracks.size(), 1);
    reasons_.assign(tracks.size(), CullReason::None);
    kept_why_.assign(tracks.size(), KeptWhy::NotExplained);
    ++frame_index_;
    if (!spec_.culls) return;
    if (spec_.oracle) {
      for (std::size_t i = 0; i < tracks.size(); ++i)
        if (truth_at(frame, tracks.cur_px[i]) == 1) (*keep)[i] = 0;
      return;
    }
    ids_.assign(tracks.ids.begin(), tracks.ids.end());
    pose_ = predicted_world_from_cam.inverse().cast<float>();
    CullingFrame<float, std::vector<cv::Point2f>, std::vector<cv::Point2f>, float, std::vector<Vec3<double>>> f;
    f.keypoints = &tracks.cur_px;
    f.prev_keypoints = spec_.tracks_from_keyframe ? &tracks.kf_px : &tracks.prev_px;
    if (spec_.tracks_from_keyframe) f.points_3d = &tracks.kf_world;
    f.track_ids = &ids_;
    f.detections = &frame.detections;
    f.depth = cv_adapter::depth_view_f32(frame.depth_m, 0.4f, 8.f);
    f.camera = camera_;
    f.cam_from_world = &pose_;
    f.is_keyframe = frame_index_ % kReferenceEvery == 1;
    f.evidence_frames = spec_.tracks_from_keyframe ? frames_since_keyframe : 1;
    const PipelineResult<float>& r = cull_frame(f, spec_.pipeline, &state_);
    if (r.keep.size() == tracks.size()) {
      *keep = r.keep;
      reasons_ = r.reasons;
      explain_kept(r);
      if (spec_.truth_repair != TruthRepair::None) repair_by_truth(frame, tracks, keep);
    }
  }

  /// Why each track of the last cull() was labelled (None for the oracle and no culling).
  const std::vector<CullReason>& reasons() const { return reasons_; }
  /// For each track the last cull() kept with reason None: at which stage it stayed static.
  const std::vector<KeptWhy>& kept_why() const { return kept_why_; }

 private:
  /// TruthRepair: flips the labels of one kind of error to the truth's (the pixel nearest each track).
  /// reasons() and kept_why() keep the preset's own decision, so --diagnose still says what it decided.
  void repair_by_truth(const SequenceFrame& frame, const Tracks& tracks, std::vector<std::uint8_t>* keep) const {
    const bool restore = spec_.truth_repair == TruthRepair::RestoreFalseCulls;
    for (std::size_t i = 0; i < tracks.size(); ++i) {
      const int truth = truth_at(frame, tracks.cur_px[i]);
      if (restore && truth == 0) (*keep)[i] = 1;
      if (!restore && truth == 1) (*keep)[i] = 0;
    }
  }

  /// The sim's motion truth at the pixel nearest p: 1 moving, 0 static, -1 none (no truth, outside).
  static int truth_at(const SequenceFrame& frame, const cv::Point2f& p) {
    const int u = cvRound(p.x), v = cvRound(p.y);
    if (frame.moving.empty() || u < 0 || v < 0 || u >= frame.moving.cols || v >= frame.moving.rows) return -1;
    return frame.moving.at<std::uint8_t>(v, u) != 0 ? 1 : 0;
  }

  /// Reads the per-feature trace of this frame (PipelineResult::trace): which stage left a kept track
  /// static. Diagnostic only (dynamic_vo --diagnose).
  void explain_kept(const PipelineResult<float>& r) {
    const std::size_t n = r.labels.size();
    kept_why_.assign(n, KeptWhy::NotExplained);
    if (r.trace.size() != n) return;
    for (std::size_t i = 0; i < n; ++i) {
      if (!r.keep[i] || r.reasons[i] != CullReason::None) continue;
      const FeatureTrace& t = r.trace[i];
      KeptWhy& why = kept_why_[i];
      if (t.history_kept) {
        why = KeptWhy::StaticHistory;
      } else if (!t.in_dynamic_box) {
        why = KeptWhy::OutsideBoxes;
      } else if (!t.in_object) {
        why = KeptWhy::OutsideObjectBand;
      } else if (t.semantic == FeatureLabel::Candidate) {
        why = KeptWhy::CandidateNotFlagged;
      } else if (t.geometric == FeatureLabel::Candidate) {
        why = KeptWhy::NoGeometricEvidence;
      } else if (t.geometric == FeatureLabel::Dynamic) {
        why = KeptWhy::FlaggedInStaticSubBox;
      } else {
        why = KeptWhy::NotFlagged;
      }
    }
  }

  StrategySpec spec_;
  PinholeCamera<float> camera_;
  PipelineState<float> state_;
  std::vector<std::int64_t> ids_;
  std::vector<CullReason> reasons_;
  std::vector<KeptWhy> kept_why_;
  Rigid3<float> pose_;
  int frame_index_ = 0;
};

}  // namespace vo
}  // namespace dyncull
