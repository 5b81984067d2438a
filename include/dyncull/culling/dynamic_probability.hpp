/// @file dynamic_probability.hpp
/// Per-feature dynamic probability (DLD-SLAM, Yu et al. 2024, §3.4 eq. 3-5, Algorithm 1): P = a1 S + a2 M + a3 K, dynamic
/// iff P >= threshold. S from the motion level, M from LK flow against the static features' flow
/// (eq. 4-5, adaptive threshold defined here), K from a caller-owned per-track state store.
///
/// API (for the pipeline):
///   TrackStateStore store;                       // owned by the front end, carried between frames
///   DynamicProbabilityResult<T> r = dynamic_probability(prev_pts, curr_pts, levels, options,
///                                                        EgoMotion<T>{}, &store, &track_ids);
///   levels[i]: MotionLevel of the mask/box holding feature i (Ignore = in no mask: reference set).
///   r.labels / r.reasons / r.probability / r.moving, r.motion_threshold_px, r.reference_flow.
#pragma once

#include "dyncull/core/status.hpp"
#include "dyncull/core/traits.hpp"
#include "dyncull/core/types.hpp"
#include "dyncull/culling/labels.hpp"
#include "dyncull/culling/motion_levels.hpp"
#include "dyncull/culling/validation.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <unordered_map>
#include <vector>

namespace dyncull {

/// How a feature's flow is compared with the camera's own motion.
enum class FlowModel : std::uint8_t {
  MeanFlow = 0,     ///< DLD-SLAM eq. 4-5: |flow - reference flow| (right for small rotation, shallow scenes)
  Fundamental = 1,  ///< ego-motion compensated: distance of p_curr to the epipolar line F p_prev (DFD-SLAM eq. 3)
  Homography = 2,   ///< ego-motion compensated for pure rotation / planar scenes: |p_curr - H p_prev|
};

/// Camera-motion model for the ego-motion-compensated variants (x_curr ~ matrix x_prev).
template <class T>
struct EgoMotion {
  FlowModel model = FlowModel::MeanFlow;
  Mat3<T> matrix = Mat3<T>::Identity();  ///< F (x_curr^T F x_prev = 0) or H (x_curr ~ H x_prev)
};

template <class T>
struct DynamicProbabilityOptions {
  /// Weights (a1 + a2 + a3 = 1) and threshold. Chosen so that, with S in {1, 0.5, 0}:
  ///   high (person):  still -> 0.4 static;   moving (M) -> >= 0.8 dynamic;  moved last frame only (K) -> 0.6 dynamic
  ///   medium (chair): still -> 0.2 static;   moving -> >= 0.6 dynamic;      K only -> 0.4 static
  ///   low (tv):       M only -> 0.4 static;  K only -> 0.2 static;          M and K (two frames) -> 0.6 dynamic
  /// Every combination is at least 0.05 from the threshold, so rounding never decides.
  T weight_semantic = T(0.4);
  T weight_motion = T(0.4);
  T weight_temporal = T(0.2);
  T threshold = T(0.55);

  /// Adaptive threshold t of eq. 5 (the paper never defines it): over the reference features'
  /// residuals r, t = max(kMinMotionThresholdPx, median(r) + kMadScale * 1.4826 * MAD(r)):
  /// the spread of the background's own flow (LK noise, parallax, 3 sigma) plus a floor in pixels.
  static constexpr double kMinMotionThresholdPx = 1.5;
  static constexpr double kMadScale = 3;
  /// Fewer reference features than this: all features form the reference (most of a frame is
  /// static), and t = kFallbackMotionThresholdPx.
  static constexpr std::size_t kMinReferenceFeatures = 8;
  static constexpr double kFallbackMotionThresholdPx = 3;

  /// InvalidInput naming the first field out of its range: weights finite, >= 0 and summing to 1 (within
  /// 1e-3); threshold finite.
  Status validate(std::string* reason = nullptr) const {
    using detail::finite_in;
    using detail::invalid_option;
    if (!finite_in(weight_semantic, 0, 1)) return invalid_option(reason, "weight_semantic", "must be in [0, 1]");
    if (!finite_in(weight_motion, 0, 1)) return invalid_option(reason, "weight_motion", "must be in [0, 1]");
    if (!finite_in(weight_temporal, 0, 1)) return invalid_option(reason, "weight_temporal", "must be in [0, 1]");
    if (!(std::abs(weight_semantic + weight_motion + weight_temporal - T(1)) < T(1e-3)))
      return invalid_option(reason, "weight_semantic + weight_motion + weight_temporal", "must be 1");
    if (!std::isfinite(threshold)) return invalid_option(reason, "threshold", "must be finite");
    if (reason) reason->clear();
    return Status::Ok;
  }
};

/// Per-track memory for K: the last flow result and decision of each track id. Owned by the
/// caller; call begin_frame() once per frame so stale tracks age out.
class TrackStateStore {
 public:
  struct State {
    std::uint8_t moving = 0;   ///< M of the last frame the track was seen
    std::uint8_t dynamic = 0;  ///< final decision of that frame
    std::uint64_t frame = 0;   ///< frame counter when last updated
  };

  explicit TrackStateStore(std::uint64_t max_age_frames = 1) : max_age_(max_age_frames) {}

  /// Advances the frame counter and forgets tracks unseen for more than max_age frames.
  void begin_frame() {
    ++frame_;
    for (auto it = states_.begin(); it != states_.end();) {
      if (frame_ - it->second.frame > max_age_) it = states_.erase(it);
      else ++it;
    }
  }
  /// State of a track seen in an earlier frame, or nullptr (K = 0 for unmatched features).
  const State* find(std::int64_t track_id) const {
    const auto it = states_.find(track_id);
    return (it == states_.end() || it->second.frame >= frame_) ? nullptr : &it->second;
  }
  void update(std::int64_t track_id, bool moving, bool dynamic) {
    states_[track_id] = State{static_cast<std::uint8_t>(moving), static_cast<std::uint8_t>(dynamic), frame_};
  }
  std::size_t size() const { return states_.size(); }
  std::uint64_t frame() const { return frame_; }
  void clear() {
    states_.clear();
    frame_ = 0;
  }

 private:
  std::unordered_map<std::int64_t, State> states_;
  std::uint64_t frame_ = 0;
  std::uint64_t max_age_ = 1;
};

template <class T>
struct DynamicProbabilityResult {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }
  std::vector<FeatureLabel> labels;  ///< Dynamic iff in a mask (level != Ignore) and P >= threshold
  std::vector<CullReason> reasons;   ///< Probability for the dynamic ones
  std::vector<T> probability;        ///< P of eq. 3 (0 for features in no mask)
  std::vector<T> residual_px;        ///< flow residual against the camera-motion model (NaN: no flow)
  std::vector<std::uint8_t> moving;  ///< M of eq. 5, for every feature
  std::vector<std::uint8_t> temporal;///< K used for every feature
  Vec2<T> reference_flow = Vec2<T>::Zero();  ///< (U, V) of eq. 4 (MeanFlow model)
  T motion_threshold_px = T(0);      ///< t of eq. 5 as used
  std::size_t num_reference = 0;
  bool used_fallback = false;        ///< too few reference features: all features were the reference
  std::size_t num_masked = 0, num_dynamic = 0, num_no_flow = 0;
};

/// Scratch of dynamic_probability kept by a caller that runs it every frame.
template <class T>
struct DynamicProbabilityScratch {
  std::vector<Vec2<T>> flow;
  std::vector<std::uint8_t> has_flow;
  std::vector<std::size_t> ref;  ///< reference features of eq. 4
  std::vector<T> u, v, res;      ///< medians' working copies
};

namespace detail {
template <class T>
T median_in_place(std::vector<T>& v) {
  if (v.empty()) return T(0);
  const std::size_t mid = (v.size() - 1) / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  return v[mid];
}
}  // namespace detail

namespace detail {

/// Every feature static with no flow measured yet; false (status and reason set) when the inputs break
/// the contract.
template <class T>
bool dp_start(std::size_t n, std::size_t n_prev, std::size_t n_levels, const std::vector<std::int64_t>* track_ids,
              const DynamicProbabilityOptions<T>& o, const EgoMotion<T>& ego, DynamicProbabilityResult<T>* out) {
  DynamicProbabilityResult<T>& r = *out;
  r.status = Status::Ok;
  r.reason.clear();
  r.reference_flow = Vec2<T>::Zero();
  r.motion_threshold_px = T(0);
  r.num_reference = r.num_masked = r.num_dynamic = r.num_no_flow = 0;
  r.used_fallback = false;
  r.labels.assign(n, FeatureLabel::Static);
  r.reasons.assign(n, CullReason::None);
  r.probability.assign(n, T(0));
  r.residual_px.assign(n, Constants<T>::nan());
  r.moving.assign(n, 0);
  r.temporal.assign(n, 0);
  if (n_prev != n || n_levels != n || (track_ids && track_ids->size() != n)) {
    r.status = Status::InvalidInput;
    r.reason.assign("prev_points, curr_points, levels (and track_ids) must have the same size");
    return false;
  }
  if (o.validate(&r.reason) != Status::Ok) {
    r.status = Status::InvalidInput;
    r.reason.insert(0, "invalid options: ");
    return false;
  }
  if (static_cast<int>(ego.model) > 2) {
    r.status = Status::InvalidInput;
    r.reason.assign("ego.model must be MeanFlow, Fundamental or Homography");
    return false;
  }
  if (!ego.matrix.allFinite()) {
    r.status = Status::NonFinite;
    r.reason.assign("ego-motion matrix is not finite");
    return false;
  }
  return true;
}

/// Each feature's flow, and its residual against the camera-motion model where the model is F or H
/// (the MeanFlow residual needs the reference flow: dp_reference_flow).
template <class T, class Prev, class Curr>
void dp_flow(const Prev& prev_points, const Curr& curr_points, const EgoMotion<T>& ego,
             DynamicProbabilityScratch<T>* scratch, DynamicProbabilityResult<T>* r) {
  const std::size_t n = curr_points.size();
  std::vector<Vec2<T>>& flow = scratch->flow;
  std::vector<std::uint8_t>& has_flow = scratch->has_flow;
  flow.assign(n, Vec2<T>::Zero());
  has_flow.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2<T> p1 = to_vec2<T>(prev_points[i]), p2 = to_vec2<T>(curr_points[i]);
    if (!p1.allFinite() || !p2.allFinite()) continue;
    has_flow[i] = 1;
    flow[i] = p2 - p1;
    if (ego.model == FlowModel::Fundamental) {
      const Vec3<T> l = ego.matrix * Vec3<T>(p1.x(), p1.y(), T(1));
      const T norm = std::sqrt(l.x() * l.x() + l.y() * l.y());
      r->residual_px[i] = norm > T(0) ? std::abs(l.x() * p2.x() + l.y() * p2.y() + l.z()) / norm : T(0);
    } else if (ego.model == FlowModel::Homography) {
      const Vec3<T> q = ego.matrix * Vec3<T>(p1.x(), p1.y(), T(1));
      r->residual_px[i] = std::abs(q.z()) > Constants<T>::small()
                              ? (Vec2<T>(q.x() / q.z(), q.y() / q.z()) - p2).norm()
                              : std::numeric_limits<T>::infinity();
    }
  }
}

/// The reference set of eq. 4: features with flow in no mask or in a low-level one; every feature with
/// flow when fewer than kMinReferenceFeatures are left.
template <class T>
void dp_reference_set(const std::vector<MotionLevel>& levels, DynamicProbabilityScratch<T>* scratch,
                      DynamicProbabilityResult<T>* r) {
  const std::size_t n = levels.size();
  auto is_reference = [](MotionLevel l) { return l == MotionLevel::Ignore || l == MotionLevel::Low; };
  std::vector<std::size_t>& ref = scratch->ref;
  ref.clear();
  ref.reserve(n);
  for (std::size_t i = 0; i < n; ++i)
    if (scratch->has_flow[i] && is_reference(levels[i])) ref.push_back(i);
  if (ref.size() < DynamicProbabilityOptions<T>::kMinReferenceFeatures) {
    r->used_fallback = true;
    ref.clear();
    for (std::size_t i = 0; i < n; ++i)
      if (scratch->has_flow[i]) ref.push_back(i);
  }
  r->num_reference = ref.size();
}

/// MeanFlow (eq. 4): (U, V) = the component-wise median of the reference features' flow (eq. 4's mean
/// is dragged by a few mislabelled movers); residual = |flow - (U, V)|.
template <class T>
void dp_reference_flow(DynamicProbabilityScratch<T>* scratch, DynamicProbabilityResult<T>* r) {
  const std::vector<std::size_t>& ref = scratch->ref;
  const std::vector<Vec2<T>>& flow = scratch->flow;
  if (!ref.empty()) {
    std::vector<T>& u = scratch->u;
    std::vector<T>& v = scratch->v;
    u.clear();
    v.clear();
    u.reserve(ref.size());
    v.reserve(ref.size());
    for (std::size_t i : ref) {
      u.push_back(flow[i].x());
      v.push_back(flow[i].y());
    }
    r->reference_flow = Vec2<T>(median_in_place(u), median_in_place(v));
  }
  const Vec2<T> ref_flow = r->reference_flow;  // a local: stores into r must not force reloads
  T* res = r->residual_px.data();
  for (std::size_t i = 0; i < flow.size(); ++i)
    if (scratch->has_flow[i]) res[i] = (flow[i] - ref_flow).norm();
}

/// t of eq. 5, adaptive: median + kMadScale x 1.4826 MAD of the reference features' own residuals, at
/// least kMinMotionThresholdPx; the fixed fallback threshold without a reference of its own.
template <class T>
void dp_motion_threshold(DynamicProbabilityScratch<T>* scratch, DynamicProbabilityResult<T>* r) {
  using Options = DynamicProbabilityOptions<T>;
  const std::vector<std::size_t>& ref = scratch->ref;
  if (r->used_fallback || ref.empty()) {
    r->motion_threshold_px = T(Options::kFallbackMotionThresholdPx);
  } else {
    std::vector<T>& res = scratch->res;
    res.clear();
    res.reserve(ref.size());
    for (std::size_t i : ref) res.push_back(r->residual_px[i]);
    const T med = median_in_place(res);
    for (T& x : res) x = std::abs(x - med);
    const T mad = median_in_place(res);
    const T floor_px = T(Options::kMinMotionThresholdPx);
    const T t = med + T(Options::kMadScale) * T(1.4826) * mad;
    r->motion_threshold_px = std::isfinite(t) ? std::max(floor_px, t) : floor_px;
  }
  if (r->used_fallback) {
    r->reason.assign("only ");  // built in place: a reused result keeps the string's capacity
    r->reason += std::to_string(r->num_reference);
    r->reason += " features with flow as reference (fewer than ";
    r->reason += std::to_string(Options::kMinReferenceFeatures);
    r->reason += " outside masks): fallback threshold used";
  }
}

/// Eq. 3 per feature in a mask: P = a1 S + a2 M + a3 K, dynamic iff P >= threshold; M = residual > t
/// (eq. 5), K from the track's state in `store`, which is updated with this frame's M and decision.
template <class T>
void dp_combine(const std::vector<MotionLevel>& levels, const DynamicProbabilityOptions<T>& o, TrackStateStore* store,
                const std::vector<std::int64_t>* track_ids, const std::vector<std::uint8_t>& has_flow,
                DynamicProbabilityResult<T>* out) {
  DynamicProbabilityResult<T>& r = *out;
  // Locals and raw pointers: stores through `r` would otherwise alias every read of `r`.
  const T t = r.motion_threshold_px;
  const T a1 = o.weight_semantic, a2 = o.weight_motion, a3 = o.weight_temporal, threshold = o.threshold;
  const T* res = r.residual_px.data();
  std::uint8_t* moving = r.moving.data();
  std::uint8_t* temporal = r.temporal.data();
  T* prob = r.probability.data();
  FeatureLabel* labels = r.labels.data();
  CullReason* reasons = r.reasons.data();
  std::size_t num_no_flow = 0, num_masked = 0, num_dynamic = 0;
  const bool use_store = store && track_ids;
  for (std::size_t i = 0; i < levels.size(); ++i) {
    num_no_flow += !has_flow[i];
    const bool m = has_flow[i] && res[i] > t;
    moving[i] = static_cast<std::uint8_t>(m);
    bool k = false;
    const bool tracked = use_store && (*track_ids)[i] >= 0;
    if (tracked) {
      if (const TrackStateStore::State* st = store->find((*track_ids)[i]))
        k = st->moving != 0;  // Algorithm 1 step 9 re-runs the flow test (steps 5-8) on the last frame
    }
    temporal[i] = static_cast<std::uint8_t>(k);
    bool dynamic = false;
    if (levels[i] != MotionLevel::Ignore) {
      ++num_masked;
      const T p = a1 * motion_level_score<T>(levels[i]) + a2 * T(m) + a3 * T(k);
      prob[i] = p;
      dynamic = p >= threshold;
      if (dynamic) {
        labels[i] = FeatureLabel::Dynamic;
        reasons[i] = CullReason::Probability;
        ++num_dynamic;
      }
    }
    if (tracked) store->update((*track_ids)[i], m, dynamic);
  }
  r.num_no_flow = num_no_flow;
  r.num_masked = num_masked;
  r.num_dynamic = num_dynamic;
}

}  // namespace detail

/// Dynamic probability of every feature. prev_points[i] -> curr_points[i] is feature i's LK flow
/// (non-finite = lost track: M = 0). `levels` has one entry per feature. `track_ids` (optional, one
/// per feature, negative = untracked) with `store` gives K and is updated with this frame's M and
/// decisions (call store->begin_frame() before each frame). Writes into `*out`, reusing its and
/// `*scratch`'s buffers (no allocation once warm).
template <class T, class Prev, class Curr>
void dynamic_probability(const Prev& prev_points, const Curr& curr_points, const std::vector<MotionLevel>& levels,
                         const DynamicProbabilityOptions<T>& o, const EgoMotion<T>& ego, TrackStateStore* store,
                         const std::vector<std::int64_t>* track_ids, DynamicProbabilityResult<T>* out,
                         DynamicProbabilityScratch<T>* scratch) {
  static_assert(is_point_container_v<Prev> && is_point_container_v<Curr>,
                "dynamic_probability: points must be containers of points");
  if (!detail::dp_start(curr_points.size(), prev_points.size(), levels.size(), track_ids, o, ego, out)) return;
  detail::dp_flow(prev_points, curr_points, ego, scratch, out);           // flow, F / H residuals
  detail::dp_reference_set(levels, scratch, out);                         // eq. 4's static reference
  if (ego.model == FlowModel::MeanFlow) detail::dp_reference_flow(scratch, out);  // eq. 4
  detail::dp_motion_threshold(scratch, out);                              // t of eq. 5
  detail::dp_combine(levels, o, store, track_ids, scratch->has_flow, out);  // eq. 3 and 5
}

/// The same probability in a fresh result (allocates; the out-parameter form reuses buffers).
template <class T, class Prev, class Curr>
DynamicProbabilityResult<T> dynamic_probability(const Prev& prev_points, const Curr& curr_points,
                                                const std::vector<MotionLevel>& levels,
                                                const DynamicProbabilityOptions<T>& o, const EgoMotion<T>& ego = {},
                                                TrackStateStore* store = nullptr,
                                                const std::vector<std::int64_t>* track_ids = nullptr) {
  DynamicProbabilityResult<T> r;
  DynamicProbabilityScratch<T> scratch;
  dynamic_probability(prev_points, curr_points, levels, o, ego, store, track_ids, &r, &scratch);
  return r;
}

}  // namespace dyncull
