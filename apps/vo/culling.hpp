/// @file culling.hpp
/// The culling strategies the dynamic_vo demo compares: no culling, each dyncull preset
/// (culling/presets.hpp, run by culling/pipeline.hpp's cull_frame) and a truth oracle on the sim,
/// applied to the current frame's tracked features before PnP; the recommended preset through the
/// stateful culler (culling/culler.hpp: ORB descriptors matched to its own keyframe, Mur-Artal, Montiel &
/// Tardos 2015) as a host would run it; on request, the recommended preset with one kind of error
/// repaired by the sim's truth (what each kind costs the pose).
#pragma once

#include "dyncull/core/camera.hpp"
#include "dyncull/core/types.hpp"
#include "dyncull/culling/pipeline.hpp"
#include "dyncull/culling/presets.hpp"
#include "dyncull/opencv/culler.hpp"
#include "dyncull/opencv/views.hpp"

#include "frontend.hpp"
#include "report.hpp"
#include "sources.hpp"

#include <opencv2/features2d.hpp>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <memory>
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
  /// Runs `pipeline` through the stateful culler (opencv/culler.hpp) the way a host would: the tracked
  /// keypoints, ORB descriptors computed at them, depth, boxes and the motion-model pose in; the culler
  /// matches them to its own keyframe and keeps its own keyframes. The front end's LK tracks to the
  /// keyframe and 3-D points are not given.
  bool through_culler = false;

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
  add("dld_slam", "DLD-SLAM (Yu et al. 2024): depth mask in boxes + dynamic probability", true, true, false, false,
      presets::dld_slam<float>());
  add("rtd_slam", "RTD-SLAM (Gao et al. 2024): motion levels, box culling, multi-view check", true, true, false, false,
      presets::rtd_slam<float>());
  add("zhu_2024", "Zhu et al. 2024: static/dynamic box rule", true, true, false, false,
      presets::zhu_2024<float>());
  add("dfd_slam", "DFD-SLAM (Qian et al. 2024): epipolar check + 3x3 sub-box refinement", true, false, false, false,
      presets::dfd_slam<float>());
  add("zhang_2023", "Zhang et al. 2023: high/medium/low logical discrimination", true, true, false, false,
      presets::zhang_2023<float>());
  add("recommended", "dyncull's recommended preset (box rule + depth band + epipolar vs keyframe / sub-box + guard)",
      true, true, true, false, presets::recommended<float>());
  add("culler", "the recommended preset through the stateful culler: ORB descriptors, its own keyframe matching",
      true, true, false, false, presets::recommended<float>());
  out.back().through_culler = true;
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
      : spec_(spec), camera_(camera.cast<float>()) {
    if (!spec_.through_culler) return;
    CullerOptions options("recommended");
    // This front end keeps its tracks and adds corners only at its own keyframes, which the culler's
    // keyframe then lacks; at the culler's default 0.3 half the tracks went unmatched between its
    // keyframes and fell to the box rule (static features in boxes culled: precision 0.76 against the
    // hand-fed 0.87 on the walking sequence's still camera). 0.6 keeps its keyframe close to the tracks.
    options.keyframe_min_matched_ratio = kKeyframeMinMatchedRatio;
    frame_culler_ = std::make_unique<dyncull::Culler>(
        CullerCamera(camera.fx, camera.fy, camera.cx, camera.cy, camera.width, camera.height), options);
    // One level, descriptors only. The edge threshold is the front end's track border (border_px / 2):
    // ORB's own 31 would drop every track within 31 px of the edge; closer in, its pyramid pads the image
    // (reflected) so a descriptor there is defined, if less distinctive.
    orb_ = cv::ORB::create(1, 1.2f, 1, kOrbEdgePx, 0, 2, cv::ORB::HARRIS_SCORE, 31);
  }

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
        if (truth_at(frame.moving, tracks.cur_px[i]) == 1) (*keep)[i] = 0;
      return;
    }
    if (frame_culler_) {
      cull_through_culler(frame, tracks, predicted_world_from_cam, keep);
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
  /// The stateful culler's result of the last cull() (null unless StrategySpec::through_culler).
  const CullerResult* culler_result() const { return frame_culler_ ? &frame_culler_->result() : nullptr; }
  /// Milliseconds the last cull() spent computing ORB descriptors at the tracks (through_culler only): a
  /// host with ORB features has them already, so they are front-end time, not culling time.
  double descriptor_ms() const { return descriptor_ms_; }
  /// Tracks of the last cull() that ORB gave no descriptor (kept without asking the culler).
  std::size_t without_descriptor() const { return without_descriptor_; }

  /// ORB's edge threshold for the descriptors of StrategySpec::through_culler (see the constructor).
  static constexpr int kOrbEdgePx = 6;
  /// CullerOptions::keyframe_min_matched_ratio of StrategySpec::through_culler (see the constructor).
  static constexpr double kKeyframeMinMatchedRatio = 0.6;

 private:
  /// StrategySpec::through_culler: what a host with ORB features does. Keypoints are the tracked
  /// positions (before PnP), descriptors ORB's at them. A keypoint ORB drops (closer than kOrbEdgePx to
  /// the edge) has no descriptor: it is left out of the culler's frame and kept, since the culler
  /// could neither match it to its keyframe nor carry it into the next one, and a host that culls only
  /// what it has evidence on keeps what it cannot describe (ORB-SLAM has no such keypoints).
  void cull_through_culler(const SequenceFrame& frame, const Tracks& tracks,
                           const Rigid3<double>& predicted_world_from_cam, std::vector<std::uint8_t>* keep) {
    const std::size_t n = tracks.size();
    keys_.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      keys_[i] = cv::KeyPoint(tracks.cur_px[i], 31.f, -1.f, 0.f, 0, static_cast<int>(i));
    descriptors_.release();
    const auto t0 = std::chrono::steady_clock::now();
    if (n > 0) orb_->compute(frame.gray, keys_, descriptors_);
    descriptor_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    // ORB drops keypoints and keeps the rest in order; class_id says which track each one is.
    without_descriptor_ = n - keys_.size();
    const cv::Matx44d Tcw = to_matx(predicted_world_from_cam.inverse());
    const cv::Mat pose(Tcw);
    boxes_.clear();
    for (const Detection<float>& d : frame.detections)
      boxes_.push_back(DetectedBox(d.box.x0, d.box.y0, d.box.x1, d.box.y1, d.class_id, d.confidence));
    const CullerResult& r = cv_adapter::cull(*frame_culler_, keys_, descriptors_, frame.depth_m, boxes_, &pose);
    const std::vector<std::uint8_t>& k = r.keep;
    if (k.size() != keys_.size()) return;
    for (std::size_t j = 0; j < keys_.size(); ++j) {
      const std::size_t i = static_cast<std::size_t>(keys_[j].class_id);
      (*keep)[i] = k[j];
      if (r.reasons.size() == keys_.size()) reasons_[i] = r.reasons[j];
    }
  }

  static cv::Matx44d to_matx(const Rigid3<double>& p) {
    cv::Matx44d m = cv::Matx44d::eye();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) m(r, c) = p.R(r, c);
      m(r, 3) = p.t(r);
    }
    return m;
  }

  /// TruthRepair: flips the labels of one kind of error to the truth's (the pixel nearest each track).
  /// reasons() and kept_why() keep the preset's own decision, so --diagnose still says what it decided.
  void repair_by_truth(const SequenceFrame& frame, const Tracks& tracks, std::vector<std::uint8_t>* keep) const {
    const bool restore = spec_.truth_repair == TruthRepair::RestoreFalseCulls;
    for (std::size_t i = 0; i < tracks.size(); ++i) {
      const int truth = truth_at(frame.moving, tracks.cur_px[i]);
      if (restore && truth == 0) (*keep)[i] = 1;
      if (!restore && truth == 1) (*keep)[i] = 0;
    }
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
  // StrategySpec::through_culler.
  std::unique_ptr<dyncull::Culler> frame_culler_;
  std::vector<DetectedBox> boxes_;
  cv::Ptr<cv::ORB> orb_;
  double descriptor_ms_ = 0;
  std::vector<cv::KeyPoint> keys_;
  cv::Mat descriptors_;
  std::size_t without_descriptor_ = 0;
};

}  // namespace vo
}  // namespace dyncull
