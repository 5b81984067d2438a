/// @file motion_truth.hpp
/// Per-pixel motion truth for a real RGB-D sequence with ground-truth camera poses: a pixel is static
/// when, under the (slightly corrected) relative pose of its neighbours K frames before and after, its
/// back-projected depth lands where dense optical flow sees it, and moving when it lands far from it
/// (the static-world test of Palazzolo et al. 2019's residuals, with DIS flow, Kroeger et al. 2016), or
/// when the neighbour's depth at its static place is farther than it (no static surface can be seen
/// through). No detector boxes are used. The method, its thresholds and their reasons: docs/motion_truth.md.
#pragma once

#include "dyncull/core/camera.hpp"
#include "dyncull/core/types.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/video/tracking.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <vector>

namespace dyncull {
namespace truth {

/// Label values of the truth images.
constexpr std::uint8_t kStatic = 0, kUnknown = 128, kMoving = 255;

struct MotionTruthOptions {
  /// Neighbours t - K and t + K: about 0.13 s at 30 Hz, long enough for a walker's 1 m/s to move
  /// 10-40 px, short enough that flow still finds the surface.
  int window_frames = 4;
  /// A pixel is static when every neighbour's residual is below static_px and moving when every
  /// neighbour that sees it puts it above moving_px: flow that fails on a blurred or blank patch
  /// rarely fails the same way in both directions. Otherwise it is unknown (a slow arm, a leg
  /// briefly still, flow noise).
  double static_px = 2.0;
  double moving_px = 4.0;
  /// Forward-backward flow disagreement allowed (plus 5 % of the flow): beyond it the pixel is
  /// occluded or untrackable in that neighbour.
  double consistency_px = 1.0;
  /// The ground-truth relative pose is refined on the whole image (trimmed PnP on flow matches);
  /// a refinement larger than this is refused and the ground truth kept (a mover took the fit).
  double max_correction_m = 0.03;
  double max_correction_deg = 1.5;
  /// Pixels closer than this to a depth discontinuity (relative step above 5 %) are unknown: their
  /// depth belongs to either side of the edge.
  int depth_edge_px = 2;
  /// On a pixel whose 7x7 structure tensor's smaller eigenvalue (cv::cornerMinEigenVal) is below this,
  /// flow is only what the regulariser spreads from the neighbourhood: on a blank wall it lags the
  /// camera's motion in both directions. Such a pixel is moving only when depth agrees: the other
  /// frame's depth where the static world puts it differs by more than moved_depth_ratio.
  double min_texture = 3e-5;
  double moved_depth_ratio = 0.08;
  /// A visible static point is where the static world puts it in the neighbour, and a hidden one lies
  /// behind what the neighbour sees there; so where the neighbour's nearest depth within 2 px of that
  /// place is farther than the point by more than this, the point has left (a walker's pixel whose
  /// place now shows the wall). Structured-light depth is about 1.5 % noisy at 4-5 m.
  double farther_depth_ratio = 0.04;
  /// An untextured pixel (see min_texture) whose flow lags between the thresholds is static when every
  /// neighbour sees depth within this ratio at its static place and no consistent flow puts it beyond
  /// moving_px.
  double same_depth_ratio = 0.03;
  double min_depth_m = 0.3, max_depth_m = 6.0;
};

/// One frame of the sequence.
struct TruthFrame {
  cv::Mat gray;     ///< CV_8UC1
  cv::Mat depth_m;  ///< CV_32FC1, 0 = no measurement
  bool has_pose = false;
  Rigid3<double> world_from_cam;
};

/// The pose refinement of one neighbour pair (see MotionTruthOptions::max_correction_m).
struct PoseCorrection {
  bool fitted = false;   ///< false: too few matches or too large; the ground truth was used
  double translation_m = 0, rotation_deg = 0;
  int matches = 0;
  double static_median_px = 0;  ///< median residual of the fit's inliers after refinement
};

struct FrameTruth {
  cv::Mat labels;  ///< CV_8UC1: kStatic, kMoving, kUnknown
  std::size_t with_depth = 0, known = 0, moving = 0;
  std::vector<PoseCorrection> corrections;  ///< one per neighbour used
  std::string note;  ///< why the whole frame is unknown, when it is
};

namespace detail {

inline Rigid3<double> rigid_from_cv(const cv::Mat& rvec, const cv::Mat& tvec) {
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  Rigid3<double> out;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out.R(r, c) = R.at<double>(r, c);
    out.t(r) = tvec.at<double>(r);
  }
  return out;
}

inline void rigid_to_cv(const Rigid3<double>& p, cv::Mat* rvec, cv::Mat* tvec) {
  cv::Mat R(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R.at<double>(r, c) = p.R(r, c);
  cv::Rodrigues(R, *rvec);
  *tvec = (cv::Mat_<double>(3, 1) << p.t(0), p.t(1), p.t(2));
}

inline double rotation_deg(const Mat3<double>& R) {
  const double c = std::clamp((R.trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(c) * 180.0 / 3.14159265358979323846;
}

inline double median(std::vector<double> v) {
  if (v.empty()) return 0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

/// 1 where the pixel can be labelled: depth in range and not within depth_edge_px of a relative depth
/// step above 5 %.
inline cv::Mat usable_pixels(const cv::Mat& depth, const MotionTruthOptions& o) {
  cv::Mat in_range = (depth >= o.min_depth_m) & (depth <= o.max_depth_m);
  cv::Mat step(depth.size(), CV_8UC1, cv::Scalar(0));
  for (int v = 0; v < depth.rows; ++v) {
    const float* d = depth.ptr<float>(v);
    const float* below = depth.ptr<float>(std::min(v + 1, depth.rows - 1));
    std::uint8_t* s = step.ptr<std::uint8_t>(v);
    for (int u = 0; u < depth.cols; ++u) {
      const float right = d[std::min(u + 1, depth.cols - 1)];
      const float z = d[u];
      auto jumps = [z](float w) { return w > 0 && z > 0 && std::abs(w - z) > 0.05f * std::min(w, z); };
      if (jumps(right) || jumps(below[u])) s[u] = 255;
    }
  }
  if (o.depth_edge_px > 0) {
    const int k = 2 * o.depth_edge_px + 1;
    cv::dilate(step, step, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(k, k)));
  }
  return in_range & ~step;
}

/// 1 where flow can be trusted on its own (see MotionTruthOptions::min_texture).
inline cv::Mat textured_pixels(const cv::Mat& gray, const MotionTruthOptions& o) {
  cv::Mat texture;
  cv::cornerMinEigenVal(gray, texture, 7, 3);
  return texture >= o.min_texture;
}

/// The nearest measured depth within `radius` px of each pixel (0 where none is measured).
inline cv::Mat nearest_depth(const cv::Mat& depth, int radius) {
  constexpr float kNone = std::numeric_limits<float>::max();
  cv::Mat nearest = depth.clone();
  nearest.setTo(kNone, depth <= 0);
  cv::erode(nearest, nearest, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * radius + 1, 2 * radius + 1)));
  nearest.setTo(0, nearest == kNone);
  return nearest;
}

/// Per pixel, what the neighbours said so far.
struct Evidence {
  cv::Mat least, worst;  ///< CV_32F: smallest and largest flow residual (px)
  cv::Mat seen;          ///< CV_8U: neighbours that saw the pixel
  cv::Mat depth_moved;   ///< CV_8U: neighbours whose depth says the surface left its static place
  cv::Mat farther;       ///< CV_8U: neighbours whose nearest depth at the static place is farther
  cv::Mat depth_same;    ///< CV_8U: neighbours whose depth at the static place agrees
  explicit Evidence(cv::Size size)
      : least(size, CV_32FC1, cv::Scalar(1e9f)), worst(size, CV_32FC1, cv::Scalar(-1.f)),
        seen(size, CV_8UC1, cv::Scalar(0)), depth_moved(size, CV_8UC1, cv::Scalar(0)),
        farther(size, CV_8UC1, cv::Scalar(0)), depth_same(size, CV_8UC1, cv::Scalar(0)) {}
};

/// Flow of both directions between two frames.
struct FlowPair {
  cv::Mat forward, backward;  ///< CV_32FC2: first -> second, second -> first
};

}  // namespace detail

/// Labels the frames of a sequence one by one, keeping the flows of the pairs it still needs.
class MotionLabeller {
 public:
  explicit MotionLabeller(const MotionTruthOptions& options = {})
      : options_(options), flow_(cv::DISOpticalFlow::create(cv::DISOpticalFlow::PRESET_MEDIUM)) {}

  const MotionTruthOptions& options() const { return options_; }

  /// Labels frame `t` of `frames` (all of the sequence's frames that are loaded; neighbours without a
  /// pose or of another image size are skipped). Frames must stay the same objects between calls for
  /// the flow cache to hold. A frame that cannot be labelled is all unknown, and `note` says why.
  FrameTruth label(const std::vector<TruthFrame>& frames, int t, const PinholeCamera<double>& camera) {
    FrameTruth out;
    if (t < 0 || t >= static_cast<int>(frames.size()) || frames[static_cast<std::size_t>(t)].gray.type() != CV_8UC1) {
      out.note = "no grey frame " + std::to_string(t);
      return out;
    }
    const TruthFrame& ref = frames[static_cast<std::size_t>(t)];
    out.labels = cv::Mat(ref.gray.size(), CV_8UC1, cv::Scalar(kUnknown));
    if (ref.depth_m.empty() || !ref.has_pose) {
      out.note = ref.depth_m.empty() ? "no depth" : "no ground-truth pose";
      return out;
    }
    if (ref.depth_m.type() != CV_32FC1 || ref.depth_m.size() != ref.gray.size()) {
      out.note = "depth is not CV_32F metres of the grey frame's size";
      return out;
    }
    const cv::Mat usable = detail::usable_pixels(ref.depth_m, options_);
    const cv::Mat textured = detail::textured_pixels(ref.gray, options_);
    detail::Evidence evidence(ref.gray.size());
    const int k = options_.window_frames;
    for (int s : {t - k, t + k}) {
      if (s < 0 || s >= static_cast<int>(frames.size())) continue;
      const TruthFrame& other = frames[static_cast<std::size_t>(s)];
      if (!other.has_pose || other.gray.type() != CV_8UC1 || other.gray.size() != ref.gray.size()) continue;
      if (!other.depth_m.empty() && (other.depth_m.type() != CV_32FC1 || other.depth_m.size() != ref.gray.size()))
        continue;
      const detail::FlowPair& f = flows(frames, std::min(t, s), std::max(t, s));
      const cv::Mat& ts = t < s ? f.forward : f.backward;
      const cv::Mat& st = t < s ? f.backward : f.forward;
      out.corrections.push_back(add_residuals(ref, other, ts, st, usable, textured, camera, &evidence));
    }
    evict_before(t - k);
    if (out.corrections.empty()) {
      out.with_depth = static_cast<std::size_t>(cv::countNonZero(ref.depth_m > 0));
      out.note = "no neighbour with a pose";
      return out;
    }
    decide(ref.depth_m, usable, textured, evidence, static_cast<int>(out.corrections.size()), &out);
    return out;
  }

 private:
  const detail::FlowPair& flows(const std::vector<TruthFrame>& frames, int a, int b) {
    const auto key = std::make_pair(a, b);
    auto it = cache_.find(key);
    if (it != cache_.end()) return it->second;
    detail::FlowPair& f = cache_[key];
    flow_->calc(frames[static_cast<std::size_t>(a)].gray, frames[static_cast<std::size_t>(b)].gray, f.forward);
    flow_->calc(frames[static_cast<std::size_t>(b)].gray, frames[static_cast<std::size_t>(a)].gray, f.backward);
    return f;
  }

  void evict_before(int first_needed) {
    for (auto it = cache_.begin(); it != cache_.end();)
      it = it->first.first < first_needed ? cache_.erase(it) : std::next(it);
  }

  /// Where the flow from ref to other sees pixel (u, v), and whether the flow back agrees.
  bool observed(const cv::Mat& ts, const cv::Mat& st, int u, int v, cv::Point2f* q) const {
    const cv::Point2f f = ts.at<cv::Point2f>(v, u);
    *q = cv::Point2f(static_cast<float>(u) + f.x, static_cast<float>(v) + f.y);
    const int bu = cvRound(q->x), bv = cvRound(q->y);
    if (bu < 0 || bv < 0 || bu >= st.cols || bv >= st.rows) return false;
    const cv::Point2f b = st.at<cv::Point2f>(bv, bu);
    const double disagree = std::hypot(f.x + b.x, f.y + b.y);
    return disagree <= options_.consistency_px + 0.05 * std::hypot(f.x, f.y);
  }

  /// Refines other_from_ref on a grid of flow matches with a trimmed PnP: the static world is the
  /// majority of the image near the ground-truth pose, so the lower half of the residuals is static.
  PoseCorrection refine(const TruthFrame& ref, const cv::Mat& ts, const cv::Mat& st, const cv::Mat& usable,
                        const cv::Mat& textured, const PinholeCamera<double>& camera,
                        Rigid3<double>* other_from_ref) const {
    PoseCorrection c;
    std::vector<cv::Point3f> X;
    std::vector<cv::Point2f> q;
    int with_texture = 0;
    for (int v = 4; v < ref.gray.rows; v += 8) {
      for (int u = 4; u < ref.gray.cols; u += 8) {
        cv::Point2f seen;
        if (!usable.at<std::uint8_t>(v, u) || !observed(ts, st, u, v, &seen)) continue;
        with_texture += textured.at<std::uint8_t>(v, u) != 0;
        const Vec3<double> p = camera.backproject(Vec2<double>(u, v), ref.depth_m.at<float>(v, u));
        X.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
        q.push_back(seen);
      }
    }
    c.matches = static_cast<int>(X.size());
    // Flow without texture is what DIS's regulariser spreads (zero on a blank image): too little texture
    // and the fit would take the camera's motion for noise.
    if (X.size() < 60 || with_texture < 60) return c;
    const cv::Matx33d K(camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1);
    cv::Mat rvec, tvec;
    detail::rigid_to_cv(*other_from_ref, &rvec, &tvec);
    std::vector<cv::Point2f> projected;
    std::vector<double> residual(X.size());
    std::vector<cv::Point3f> X_in;
    std::vector<cv::Point2f> q_in;
    for (int round = 0; round < 3; ++round) {
      cv::projectPoints(X, rvec, tvec, K, cv::noArray(), projected);
      for (std::size_t i = 0; i < X.size(); ++i) residual[i] = cv::norm(projected[i] - q[i]);
      const double cut = detail::median(residual);
      X_in.clear();
      q_in.clear();
      for (std::size_t i = 0; i < X.size(); ++i)
        if (residual[i] <= cut) {
          X_in.push_back(X[i]);
          q_in.push_back(q[i]);
        }
      cv::solvePnPRefineLM(X_in, q_in, K, cv::noArray(), rvec, tvec);
    }
    const Rigid3<double> refined = detail::rigid_from_cv(rvec, tvec);
    const Rigid3<double> delta = refined * other_from_ref->inverse();
    c.translation_m = delta.t.norm();
    c.rotation_deg = detail::rotation_deg(delta.R);
    if (!refined.all_finite() || c.translation_m > options_.max_correction_m ||
        c.rotation_deg > options_.max_correction_deg)
      return c;
    cv::projectPoints(X_in, rvec, tvec, K, cv::noArray(), projected);
    std::vector<double> r(X_in.size());
    for (std::size_t i = 0; i < X_in.size(); ++i) r[i] = cv::norm(projected[i] - q_in[i]);
    c.static_median_px = detail::median(r);
    c.fitted = true;
    *other_from_ref = refined;
    return c;
  }

  /// Adds one neighbour's residuals: |flow position - static-world prediction| in pixels.
  PoseCorrection add_residuals(const TruthFrame& ref, const TruthFrame& other, const cv::Mat& ts, const cv::Mat& st,
                               const cv::Mat& usable, const cv::Mat& textured, const PinholeCamera<double>& camera,
                               detail::Evidence* e) const {
    Rigid3<double> other_from_ref = other.world_from_cam.inverse() * ref.world_from_cam;
    const PoseCorrection c = refine(ref, ts, st, usable, textured, camera, &other_from_ref);
    const cv::Mat nearest = other.depth_m.empty() ? cv::Mat() : detail::nearest_depth(other.depth_m, 2);
    for (int v = 0; v < ref.gray.rows; ++v) {
      for (int u = 0; u < ref.gray.cols; ++u) {
        if (!usable.at<std::uint8_t>(v, u)) continue;
        const Vec3<double> p =
            other_from_ref.apply(camera.backproject(Vec2<double>(u, v), ref.depth_m.at<float>(v, u)));
        if (p.z() <= 0) continue;
        const Vec2<double> predicted = camera.project(p);
        if (predicted.x() < 0 || predicted.y() < 0 || predicted.x() > camera.width - 1 ||
            predicted.y() > camera.height - 1)
          continue;  // leaves the other view: no evidence either way
        if (!nearest.empty()) add_depth_evidence(other.depth_m, nearest, predicted, p.z(), u, v, e);
        cv::Point2f q;
        if (!observed(ts, st, u, v, &q)) continue;
        const float r = static_cast<float>(std::hypot(predicted.x() - q.x, predicted.y() - q.y));
        float& w = e->worst.at<float>(v, u);
        w = std::max(w, r);
        float& l = e->least.at<float>(v, u);
        l = std::min(l, r);
        ++e->seen.at<std::uint8_t>(v, u);
        const float there = other.depth_m.empty() ? 0.f
                                                  : other.depth_m.at<float>(cvRound(predicted.y()), cvRound(predicted.x()));
        if (there > 0 && std::abs(there - p.z()) > options_.moved_depth_ratio * p.z()) ++e->depth_moved.at<std::uint8_t>(v, u);
      }
    }
    return c;
  }

  /// What the other frame's depth says at the static place of a point at depth `z` there.
  void add_depth_evidence(const cv::Mat& depth, const cv::Mat& nearest, const Vec2<double>& place, double z, int u,
                          int v, detail::Evidence* e) const {
    const int pu = cvRound(place.x()), pv = cvRound(place.y());
    const float near = nearest.at<float>(pv, pu), there = depth.at<float>(pv, pu);
    if (near > 0 && near > (1 + options_.farther_depth_ratio) * z) ++e->farther.at<std::uint8_t>(v, u);
    if (there > 0 && std::abs(there - z) < options_.same_depth_ratio * z) ++e->depth_same.at<std::uint8_t>(v, u);
  }

  /// Moving needs every neighbour's flow (one direction's flow alone is wrong too often: glare, blur), or
  /// one neighbour's depth seen behind the point's static place; static needs every neighbour's flow, or
  /// every neighbour's depth where flow has no texture to follow, and no depth seen behind.
  void decide(const cv::Mat& depth, const cv::Mat& usable, const cv::Mat& textured, const detail::Evidence& e,
              int neighbours, FrameTruth* out) const {
    for (int v = 0; v < depth.rows; ++v) {
      for (int u = 0; u < depth.cols; ++u) {
        if (depth.at<float>(v, u) > 0) ++out->with_depth;
        if (!usable.at<std::uint8_t>(v, u)) continue;
        const std::uint8_t seen = e.seen.at<std::uint8_t>(v, u);
        const bool has_texture = textured.at<std::uint8_t>(v, u) != 0;
        const bool flow_moved = seen == neighbours && e.least.at<float>(v, u) > options_.moving_px;
        const bool depth_agrees = has_texture || e.depth_moved.at<std::uint8_t>(v, u) == seen;
        const bool flow_static = seen > 0 && e.worst.at<float>(v, u) < options_.static_px;
        const bool depth_static = !has_texture && e.depth_same.at<std::uint8_t>(v, u) == neighbours &&
                                  seen > 0 && e.worst.at<float>(v, u) <= options_.moving_px;
        const bool seen_behind = e.farther.at<std::uint8_t>(v, u) > 0;
        std::uint8_t& label = out->labels.at<std::uint8_t>(v, u);
        if ((flow_moved && depth_agrees) || (seen_behind && !flow_static)) label = kMoving;
        else if ((flow_static || depth_static) && !seen_behind) label = kStatic;
        else continue;
        ++out->known;
        if (label == kMoving) ++out->moving;
      }
    }
  }

  MotionTruthOptions options_;
  cv::Ptr<cv::DISOpticalFlow> flow_;
  std::map<std::pair<int, int>, detail::FlowPair> cache_;
};

}  // namespace truth
}  // namespace dyncull
