/// @file frontend.hpp
/// RGB-D visual odometry front end of the dynamic_vo demo: ORB corners spread over a grid, pyramidal
/// LK tracking frame to frame, 3-D points from the keyframe's depth (Zhu et al. 2024 eq. 5-6), PnP-RANSAC on the
/// features the culling kept (Zhu et al. 2024 §2), motion-only refinement on the inliers, constant-velocity fallback.
#pragma once

#include "dyncull/core/pixel.hpp"
#include "dyncull/core/camera.hpp"
#include "dyncull/core/depth.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/core/types.hpp"
#include "dyncull/geometry/pnp.hpp"

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace dyncull {
namespace vo {

/// Front-end settings. Defaults follow ORB-SLAM2's RGB-D front end where it has one.
struct FrontEndOptions {
  int max_features = 800;             ///< features per keyframe (tracked + newly detected)
  int grid_cols = 8, grid_rows = 6;   ///< detection grid: spreads the budget over the image
  int fast_threshold = 12;            ///< ORB's FAST threshold (OpenCV default 20 finds too few on flat walls)
  int min_feature_distance_px = 10;   ///< new corners keep this far from tracked ones ...
  /// ... and, at a keyframe, from the tracks the culling removed in that frame: otherwise the budget
  /// freed by dropping them is spent on new corners on the same mover, which the culling then sees with
  /// a one-frame baseline only (a keyframe resets every track's reference). Lowers the ATE with culling
  /// (figures in docs/results.md); no effect without culling.
  bool detect_away_from_culled = true;
  int border_px = 12;                 ///< no features this close to the edge (Kinect depth band, LK window)
  float min_depth_m = 0.4f;           ///< TUM sensor's reliable range
  float max_depth_m = 8.f;
  float max_depth_step_ratio = 0.05f; ///< reject corners near depth edges: a step above this fraction ...
  /// ... within this radius (sampled every 2 px beyond 2; 1 = the 3x3 neighbourhood). A corner whose LK
  /// window straddles an occlusion edge tracks the contour (a T-junction), not a 3-D point, and the
  /// epipolar check flags it although its surface is static. A larger radius raises label precision but
  /// leaves fewer corners and a weaker VO, so the default is 1 and the culling discounts flags on depth
  /// edges instead (PipelineOptions::edge_evidence).
  int depth_edge_radius_px = 1;
  int lk_window_px = 21;              ///< LK window and pyramid depth (dynamic ORB-SLAM forks: 21 px, 3-5 levels)
  int lk_levels = 3;
  /// Re-track every feature from its keyframe image, starting at the frame-to-frame LK result, so its
  /// position error does not accumulate frame after frame (see track()).
  bool refine_against_keyframe = true;
  double refine_max_shift_px = 2.0;   ///< refinement moving a track further than this is not used
  double refine_max_rotation_deg = 5.0;  ///< refinement against the keyframe image as it is up to this turn ...
  /// ... and beyond it against the keyframe image warped by the predicted rotation since the keyframe
  /// (the homography K R K^-1 of a point at infinity; what is left, parallax and the prediction's error, is
  /// a shift LK handles). Without it the tracks of a turning camera (rpy: up to 0.8 deg a frame) are not
  /// refined from 5 deg on and their LK error adds up again (on the sim's rpy sequence it halves the ATE
  /// for 0.7 ms per frame). Below 5 deg the unwarped patch does as well or better: a warped one is blurred.
  bool refine_rotation_compensated = true;
  double pnp_threshold_px = 2.0;      ///< reprojection inlier threshold of PnP-RANSAC
  double track_max_error_px = 4.0;    ///< tracks (kept or culled) further than this from their point's
                                      ///< projection at the accepted pose are dropped (ORB-SLAM discards outliers)
  int min_pnp_inliers = 15;           ///< ORB-SLAM2 loses reference tracking below 15 matches
  int keyframe_min_inliers = 120;     ///< new keyframe when fewer inliers remain ...
  double keyframe_min_tracked_ratio = 0.5;  ///< ... or fewer tracks than this share of the keyframe's ...
  double keyframe_max_translation_m = 0.1;  ///< ... or the camera moved this far from the keyframe ...
  double keyframe_max_rotation_deg = 15.0;  ///< ... or turned this much.
  // 0.1 m rather than 0.2 m: shorter keyframe baselines lower the ATE on the translating sequences (xyz,
  // halfsphere) for 15-18 % more keyframes.
  std::uint64_t seed = 7;             ///< PnP-RANSAC seed (deterministic runs)
};

/// One input frame; the views must stay valid during process calls.
struct FrameInput {
  double timestamp = 0;
  cv::Mat gray;     ///< CV_8UC1
  cv::Mat depth_m;  ///< CV_32FC1 metres, 0 = no measurement
};

/// Per-frame outcome, for progress and statistics.
struct FrameStats {
  Status status = Status::Ok;  ///< Ok when PnP gave the pose; Skipped on the first frame; else the fallback's reason
  std::string reason;
  std::size_t tracks = 0;      ///< features tracked into this frame
  std::size_t kept = 0;        ///< of them, kept by the culling and used for PnP
  std::size_t inliers = 0;     ///< PnP inliers
  bool keyframe = false;       ///< this frame became a keyframe
  bool fallback = false;       ///< pose from the constant-velocity prior (PnP failed)
};

/// The tracked features of the current frame, structure of arrays (all the same length).
struct Tracks {
  std::vector<std::uint32_t> ids;          ///< stable per feature, for per-track culling state
  std::vector<cv::Point2f> prev_px;        ///< position in the previous frame
  std::vector<cv::Point2f> cur_px;         ///< position in the current frame
  std::vector<cv::Point2f> kf_px;          ///< position in the current keyframe's image
  std::vector<Vec3<double>> world;         ///< 3-D point from its keyframe's depth, world frame
  /// 3-D point from the current keyframe's depth at kf_px, world frame (NaN without depth there). Unlike
  /// `world`, which a PnP inlier keeps from the keyframe that created it, this is re-measured at every
  /// keyframe, so a chair that moved and stopped is consistent again from the next keyframe on.
  std::vector<Vec3<double>> kf_world;
  std::vector<std::uint8_t> pnp_inlier;    ///< set by estimate()

  std::size_t size() const { return ids.size(); }
  /// Keeps the tracks i with keep(i), in order, in every array (keep may read index i of any array).
  template <class Keep>
  void keep_if(Keep&& keep) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < size(); ++i) {
      if (!keep(i)) continue;
      ids[n] = ids[i];
      prev_px[n] = prev_px[i];
      cur_px[n] = cur_px[i];
      kf_px[n] = kf_px[i];
      world[n] = world[i];
      kf_world[n] = kf_world[i];
      pnp_inlier[n] = pnp_inlier[i];
      ++n;
    }
    ids.resize(n);
    prev_px.resize(n);
    cur_px.resize(n);
    kf_px.resize(n);
    world.resize(n);
    kf_world.resize(n);
    pnp_inlier.resize(n);
  }
  void clear() {
    ids.clear();
    prev_px.clear();
    cur_px.clear();
    kf_px.clear();
    world.clear();
    kf_world.clear();
    pnp_inlier.clear();
  }
};

/// Frame-to-keyframe RGB-D odometry. Call track(frame), cull tracks(), then estimate(keep).
class FrontEnd {
 public:
  FrontEnd(const PinholeCamera<double>& camera, const FrontEndOptions& options = {})
      : camera_(camera), options_(options) {
    orb_ = cv::ORB::create(options_.max_features * 2, 1.2f, 4, 19, 0, 2, cv::ORB::HARRIS_SCORE, 31,
                           options_.fast_threshold);
  }

  /// Tracks the features of the previous frame into `frame` (LK). On the first frame there is
  /// nothing to track: tracks() is empty and estimate() makes the frame the first keyframe.
  void track(const FrameInput& frame) {
    frame_ = frame;
    ++frames_since_keyframe_;
    if (prev_gray_.empty() || tracks_.size() == 0) {
      tracks_.clear();
      return;
    }
    // The previous frame's positions become prev_px; LK writes the new ones.
    tracks_.prev_px.swap(tracks_.cur_px);
    std::vector<std::uint8_t> status;
    std::vector<float> err;
    cv::calcOpticalFlowPyrLK(prev_gray_, frame.gray, tracks_.prev_px, tracks_.cur_px, status, err,
                             cv::Size(options_.lk_window_px, options_.lk_window_px), options_.lk_levels,
                             cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 20, 0.03));
    const float b = static_cast<float>(options_.border_px) * 0.5f;
    const float umax = static_cast<float>(frame.gray.cols) - 1.f - b, vmax = static_cast<float>(frame.gray.rows) - 1.f - b;
    tracks_.keep_if([&](std::size_t i) {
      const cv::Point2f p = tracks_.cur_px[i];
      return status[i] && p.x >= b && p.y >= b && p.x <= umax && p.y <= vmax;
    });
    tracks_.pnp_inlier.assign(tracks_.size(), 0);
    if (options_.refine_against_keyframe && tracks_.size() > 0 && !kf_gray_.empty()) {
      // LK models a translated patch: across a large rotation from the keyframe (rpy) the keyframe
      // patch no longer matches and would bias the tracks, so there the keyframe image is first turned
      // by the predicted rotation (or, without refine_rotation_compensated, the refinement is skipped).
      const Rigid3<double> kf_from_pred = keyframe_world_from_cam_.inverse() * predicted_world_from_cam();
      const double angle_deg = rotation_angle(kf_from_pred.R) * Constants<double>::rad_to_deg();
      if (angle_deg <= options_.refine_max_rotation_deg)
        refine_against_keyframe(nullptr);
      else if (options_.refine_rotation_compensated)
        refine_against_keyframe(&kf_from_pred.R);
    }
  }

  const Tracks& tracks() const { return tracks_; }
  /// Frames from the current keyframe to the frame last given to track() (1 right after a keyframe): the
  /// baseline of the evidence measured against the keyframe (Tracks::kf_px, kf_world).
  int frames_since_keyframe() const { return frames_since_keyframe_; }

  /// Pose given to the first frame (default identity: the world is the first camera).
  void set_initial_pose(const Rigid3<double>& world_from_cam) {
    if (!initialised_) initial_world_from_cam_ = world_from_cam;
  }

  /// Pose of the current frame from the tracks with keep[i] != 0 (keep.size() == tracks().size()),
  /// then keyframe management. Returns what happened; pose() is always set (fallback: prior).
  FrameStats estimate(const std::vector<std::uint8_t>& keep) {
    FrameStats stats;
    stats.tracks = tracks_.size();
    if (!initialised_) {
      world_from_cam_ = initial_world_from_cam_;
      velocity_ = Rigid3<double>::identity();
      stats.status = Status::Skipped;
      stats.reason = "first frame";
      make_keyframe(stats);
      initialised_ = true;
      finish_frame();
      return stats;
    }

    culled_px_.clear();  // before outlier tracks are dropped: keep is indexed by this frame's tracks
    if (options_.detect_away_from_culled)
      for (std::size_t i = 0; i < tracks_.size() && i < keep.size(); ++i)
        if (!keep[i]) culled_px_.push_back(tracks_.cur_px[i]);
    // Constant-velocity prior: the last inter-frame motion repeated (cam_from_world of this frame).
    const Rigid3<double> prior_world_from_cam = world_from_cam_ * velocity_;
    world_pts_.clear();
    pixels_.clear();
    index_.clear();
    for (std::size_t i = 0; i < tracks_.size(); ++i) {
      if (i < keep.size() && !keep[i]) continue;
      world_pts_.push_back(tracks_.world[i]);
      pixels_.emplace_back(static_cast<double>(tracks_.cur_px[i].x), static_cast<double>(tracks_.cur_px[i].y));
      index_.push_back(i);
    }
    stats.kept = index_.size();

    Rigid3<double> world_from_cam = prior_world_from_cam;
    bool ok = false;
    if (index_.size() >= static_cast<std::size_t>(options_.min_pnp_inliers)) {
      PnpOptions<double> pnp;
      pnp.ransac.max_residual = options_.pnp_threshold_px;
      pnp.ransac.confidence = 0.999;
      pnp.ransac.max_iterations = 1000;
      pnp.ransac.seed = options_.seed + frame_count_;
      pnp.refine = true;
      pnp.refinement.huber = true;  // motion-only refinement robust to the outliers RANSAC let through
      const PnpResult<double> r = solve_pnp_ransac(world_pts_, pixels_, camera_, pnp);
      if (r.ok() && r.num_inliers >= static_cast<std::size_t>(options_.min_pnp_inliers) &&
          r.cam_from_world.all_finite()) {
        ok = true;
        world_from_cam = r.cam_from_world.inverse();
        stats.inliers = r.num_inliers;
        for (std::size_t k = 0; k < index_.size(); ++k) tracks_.pnp_inlier[index_[k]] = r.inlier_mask[k];
      } else {
        stats.status = r.ok() ? Status::TooFewPoints : r.status;
        stats.reason = r.ok() ? "PnP inliers below minimum" : r.reason;
      }
    } else {
      stats.status = Status::TooFewPoints;
      stats.reason = "too few kept tracks for PnP";
    }
    if (!ok) stats.fallback = true;
    if (ok) drop_outlier_tracks(world_from_cam.inverse());

    velocity_ = world_from_cam_.inverse() * world_from_cam;
    world_from_cam_ = world_from_cam;

    const Rigid3<double> kf_from_cam = keyframe_world_from_cam_.inverse() * world_from_cam_;
    const bool far = kf_from_cam.t.norm() > options_.keyframe_max_translation_m ||
                     rotation_angle(kf_from_cam.R) * Constants<double>::rad_to_deg() > options_.keyframe_max_rotation_deg;
    const bool weak = stats.inliers < static_cast<std::size_t>(options_.keyframe_min_inliers) ||
                      static_cast<double>(tracks_.size()) < options_.keyframe_min_tracked_ratio * keyframe_size_;
    if (far || weak) make_keyframe(stats);
    finish_frame();
    return stats;
  }

  /// Constant-velocity prediction of the next frame's pose (valid between estimate() and track()).
  Rigid3<double> predicted_world_from_cam() const { return world_from_cam_ * velocity_; }

  /// Estimated pose of the current frame (world = first frame's camera).
  const Rigid3<double>& world_from_cam() const { return world_from_cam_; }
  const PinholeCamera<double>& camera() const { return camera_; }
  const FrontEndOptions& options() const { return options_; }

 private:
  /// Metric depth at a corner, or 0 when missing, out of range or near a depth edge.
  float usable_depth(float u, float v) const {
    const cv::Mat& d = frame_.depth_m;
    int x = 0, y = 0;
    if (!pixel_of(u, v, d.cols, d.rows, &x, &y)) return 0.f;
    const int r = std::max(1, options_.depth_edge_radius_px);
    if (x < r || y < r || x >= d.cols - r || y >= d.rows - r) return 0.f;
    const float z = d.at<float>(y, x);
    if (!(z >= options_.min_depth_m && z <= options_.max_depth_m)) return 0.f;
    // Points on an occlusion edge back-project half on the object, half on the background, and their
    // LK window follows the contour (see depth_edge_radius_px).
    const DepthView<float> view{d.ptr<float>(), d.cols, d.rows, static_cast<std::ptrdiff_t>(d.step1()), 1.f, 0.f, 1e30f};
    return depth_step_near(view, x, y, r, options_.max_depth_step_ratio) ? 0.f : z;
  }

  /// Removes tracks whose 3-D point does not reproject near them: LK tracks dragged along by an
  /// occluding person and points that were on a moving surface when their keyframe was made. Without
  /// this they accumulate until the next keyframe and can form a coherent wrong consensus.
  void drop_outlier_tracks(const Rigid3<double>& cam_from_world) {
    const double max_sq = options_.track_max_error_px * options_.track_max_error_px;
    tracks_.keep_if([&](std::size_t i) {
      const Vec3<double> pc = cam_from_world.apply(tracks_.world[i]);
      if (!(pc.z() > 0)) return false;
      const Vec2<double> q = camera_.project(pc);
      const double du = q.x() - tracks_.cur_px[i].x, dv = q.y() - tracks_.cur_px[i].y;
      return du * du + dv * dv <= max_sq;
    });
  }

  /// The current frame becomes the keyframe: its PnP inliers keep the 3-D points they were created
  /// with, like ORB-SLAM's map points (re-anchoring them on this frame's depth at this frame's
  /// estimated pose adds each keyframe's pose error to the points: ATE of the oracle culling on 150 xyz
  /// frames 2.9 cm re-anchored, 1.3 cm kept), and the rest of the budget is new ORB corners.
  void make_keyframe(FrameStats& stats) {
    stats.keyframe = true;
    keyframe_world_from_cam_ = world_from_cam_;
    frames_since_keyframe_ = 0;
    // After a PnP failure (no inliers) no track is trusted.
    const bool have_inliers = stats.inliers > 0;
    tracks_.keep_if([&](std::size_t i) { return have_inliers && tracks_.pnp_inlier[i] != 0; });

    const int budget = options_.max_features - static_cast<int>(tracks_.size());
    if (budget > 0) detect_new(budget);
    tracks_.prev_px = tracks_.cur_px;
    tracks_.kf_px = tracks_.cur_px;
    tracks_.kf_world.resize(tracks_.size());
    for (std::size_t i = 0; i < tracks_.size(); ++i) {
      const float z = usable_depth(tracks_.cur_px[i].x, tracks_.cur_px[i].y);
      tracks_.kf_world[i] = z > 0.f ? world_from_cam_.apply(camera_.backproject(
                                          Vec2<double>(tracks_.cur_px[i].x, tracks_.cur_px[i].y), static_cast<double>(z)))
                                    : Vec3<double>::Constant(std::numeric_limits<double>::quiet_NaN());
    }
    frame_.gray.copyTo(kf_gray_);
    tracks_.pnp_inlier.assign(tracks_.size(), 0);
    keyframe_size_ = static_cast<double>(tracks_.size());
  }

  /// ORB corners away from existing tracks, the best few per grid cell.
  void detect_new(int budget) {
    const cv::Mat& gray = frame_.gray;
    mask_.create(gray.size(), CV_8UC1);
    mask_.setTo(0);
    // An image no wider or taller than its two borders has no room for a feature: the rectangle
    // would be empty or negative (which OpenCV refuses with an exception).
    const int b = std::max(0, options_.border_px);
    if (gray.cols <= 2 * b || gray.rows <= 2 * b) return;
    mask_(cv::Rect(b, b, gray.cols - 2 * b, gray.rows - 2 * b)).setTo(255);
    for (const cv::Point2f& p : tracks_.cur_px)
      cv::circle(mask_, cv::Point(cvRound(p.x), cvRound(p.y)), options_.min_feature_distance_px, cv::Scalar(0), -1);
    for (const cv::Point2f& p : culled_px_)
      cv::circle(mask_, cv::Point(cvRound(p.x), cvRound(p.y)), options_.min_feature_distance_px, cv::Scalar(0), -1);
    keypoints_.clear();
    orb_->detect(gray, keypoints_, mask_);

    const int cells = options_.grid_cols * options_.grid_rows;
    const int per_cell = std::max(1, (budget + cells - 1) / cells);
    cell_points_.assign(static_cast<std::size_t>(cells), {});
    for (const cv::KeyPoint& k : keypoints_) {
      const int c = clamped_int(k.pt.x * options_.grid_cols / gray.cols, 0, options_.grid_cols - 1);
      const int r = clamped_int(k.pt.y * options_.grid_rows / gray.rows, 0, options_.grid_rows - 1);
      cell_points_[static_cast<std::size_t>(r * options_.grid_cols + c)].push_back(k);
    }
    int added = 0;
    for (auto& cell : cell_points_) {
      std::sort(cell.begin(), cell.end(), [](const cv::KeyPoint& a, const cv::KeyPoint& b2) { return a.response > b2.response; });
      int in_cell = 0;
      for (const cv::KeyPoint& k : cell) {
        if (in_cell >= per_cell || added >= budget) break;
        // ORB detects on a pyramid: two keypoints can share a pixel; the mask check drops the second.
        const int x = cvRound(k.pt.x), y = cvRound(k.pt.y);
        if (mask_.at<std::uint8_t>(y, x) == 0) continue;
        const float z = usable_depth(k.pt.x, k.pt.y);
        if (z <= 0.f) continue;
        cv::circle(mask_, cv::Point(x, y), options_.min_feature_distance_px / 2, cv::Scalar(0), -1);
        tracks_.ids.push_back(next_id_++);
        tracks_.cur_px.push_back(k.pt);
        tracks_.world.push_back(
            world_from_cam_.apply(camera_.backproject(Vec2<double>(k.pt.x, k.pt.y), static_cast<double>(z))));
        ++in_cell;
        ++added;
      }
    }
  }

  /// Frame-to-frame LK adds a few tenths of a pixel of error per frame (rendered and real textures
  /// alias), and the errors add up along a track: on the synthetic xyz sequence with exact depth the
  /// tracks' RMS error against the truth grew from 0.5 to 1.1 px within 7 frames, and PnP turned it
  /// into 2-3 cm of pose error. Tracking each feature again from its keyframe image, starting at the
  /// frame-to-frame result, keeps the error from adding up between keyframes. Measured with the
  /// truth-oracle culling, 300 frames: ATE static / xyz / rpy / halfsphere 0.66 / 2.70 / 2.79 / 1.66 cm
  /// without, 0.45 / 0.79 / 1.56 / 1.29 cm with it (docs/results.md). kf_from_cam_rotation: null to
  /// track from the keyframe image as it is, else the predicted rotation to compensate first.
  void refine_against_keyframe(const Mat3<double>* kf_from_cam_rotation) {
    refined_px_ = tracks_.cur_px;
    const cv::Mat* reference = &kf_gray_;
    const std::vector<cv::Point2f>* reference_px = &tracks_.kf_px;
    if (kf_from_cam_rotation) {
      // kf_from_cam maps a current-frame pixel to where a point at infinity was in the keyframe,
      // x_kf ~ K R x_cam; the warped keyframe W(x) = kf(kf_from_cam x) looks like the current frame.
      const Mat3<double> K = camera_.K();
      const Mat3<double> kf_from_cam = K * *kf_from_cam_rotation * K.inverse();
      const Mat3<double> cam_from_kf = kf_from_cam.inverse();
      const cv::Matx33d h(kf_from_cam(0, 0), kf_from_cam(0, 1), kf_from_cam(0, 2), kf_from_cam(1, 0), kf_from_cam(1, 1),
                          kf_from_cam(1, 2), kf_from_cam(2, 0), kf_from_cam(2, 1), kf_from_cam(2, 2));
      cv::warpPerspective(kf_gray_, warped_kf_, h, kf_gray_.size(), cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                          cv::BORDER_REPLICATE);
      warped_px_.resize(tracks_.size());
      for (std::size_t i = 0; i < tracks_.size(); ++i) {
        const Vec3<double> q = cam_from_kf * Vec3<double>(tracks_.kf_px[i].x, tracks_.kf_px[i].y, 1.0);
        warped_px_[i] = cv::Point2f(static_cast<float>(q.x() / q.z()), static_cast<float>(q.y() / q.z()));
      }
      reference = &warped_kf_;
      reference_px = &warped_px_;
    }
    cv::calcOpticalFlowPyrLK(*reference, frame_.gray, *reference_px, refined_px_, refine_status_, refine_err_,
                             cv::Size(options_.lk_window_px, options_.lk_window_px), 1,
                             cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 20, 0.01),
                             cv::OPTFLOW_USE_INITIAL_FLOW);
    const double max_sq = options_.refine_max_shift_px * options_.refine_max_shift_px;
    for (std::size_t i = 0; i < tracks_.size(); ++i) {
      const double du = refined_px_[i].x - tracks_.cur_px[i].x, dv = refined_px_[i].y - tracks_.cur_px[i].y;
      if (refine_status_[i] && du * du + dv * dv <= max_sq) tracks_.cur_px[i] = refined_px_[i];
    }
  }

  void finish_frame() {
    frame_.gray.copyTo(prev_gray_);
    ++frame_count_;
  }

  PinholeCamera<double> camera_;
  FrontEndOptions options_;
  cv::Ptr<cv::ORB> orb_;
  FrameInput frame_;
  cv::Mat prev_gray_, kf_gray_, mask_;
  Tracks tracks_;
  bool initialised_ = false;
  int frames_since_keyframe_ = 0;
  Rigid3<double> world_from_cam_, velocity_, keyframe_world_from_cam_, initial_world_from_cam_;
  double keyframe_size_ = 0;
  std::uint32_t next_id_ = 1;
  std::uint64_t frame_count_ = 0;
  // Scratch buffers reused frame to frame.
  std::vector<Vec3<double>> world_pts_;
  std::vector<Vec2<double>> pixels_;
  std::vector<std::size_t> index_;
  std::vector<cv::KeyPoint> keypoints_;
  std::vector<cv::Point2f> refined_px_, warped_px_, culled_px_;
  cv::Mat warped_kf_;
  std::vector<std::uint8_t> refine_status_;
  std::vector<float> refine_err_;
  std::vector<std::vector<cv::KeyPoint>> cell_points_;
};

}  // namespace vo
}  // namespace dyncull
