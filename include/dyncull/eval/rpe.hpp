/// @file rpe.hpp
/// Relative pose error exactly as TUM evaluate_rpe.py --fixed_delta (drift over a fixed delta in
/// frames, seconds, metres or degrees): E = (P_i^-1 P_j)(Q_i^-1 Q_j)^-1, |t(E)| and angle(R(E)).
#pragma once

#include "dyncull/core/status.hpp"
#include "dyncull/core/types.hpp"
#include "dyncull/eval/statistics.hpp"
#include "dyncull/eval/trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

namespace dyncull::eval {

/// Unit of RpeOptions::delta (evaluate_rpe.py --delta_unit f / s / m / rad / deg).
enum class DeltaUnit { Frames, Seconds, Metres, Radians, Degrees };

constexpr const char* to_string(DeltaUnit unit) noexcept {
  switch (unit) {
    case DeltaUnit::Frames: return "frames";
    case DeltaUnit::Seconds: return "seconds";
    case DeltaUnit::Metres: return "metres";
    case DeltaUnit::Radians: return "radians";
    case DeltaUnit::Degrees: return "degrees";
  }
  return "unknown";
}

/// Pair selection is always TUM's --fixed_delta mode and always uses every pair: TUM's default mode
/// (all or 10000 random pairs of any separation, mean printed) is a trap for drift numbers, and its
/// random subsampling above 10000 pairs is not reproducible. Below 10000 pairs the numbers are TUM's.
struct RpeOptions {
  /// 1 second, as `evaluate_rpe.py --fixed_delta` (the drift per second the TUM benchmark recommends
  /// for RGB-D, and what DynaSLAM's repository ran).
  double delta = 1.0;
  DeltaUnit delta_unit = DeltaUnit::Seconds;
  double offset_s = 0.0;  ///< added to the estimate's stamps (evaluate_rpe.py --offset)
  /// Fixed factor on the estimate's relative translations (evaluate_rpe.py --scale); set it to the
  /// ATE Sim(3) scale to evaluate a monocular estimate.
  double scale = 1.0;

  /// Ok, or InvalidInput with a reason naming the field.
  Status validate(std::string* reason = nullptr) const {
    auto bad = [&](const char* why) {
      if (reason) *reason = why;
      return Status::InvalidInput;
    };
    if (!(delta > 0.0) || !std::isfinite(delta)) return bad("RpeOptions: delta must be positive and finite");
    switch (delta_unit) {
      case DeltaUnit::Frames:
      case DeltaUnit::Seconds:
      case DeltaUnit::Metres:
      case DeltaUnit::Radians:
      case DeltaUnit::Degrees:
        break;
      default:
        return bad("RpeOptions: delta_unit is not one of the DeltaUnit values");
    }
    if (!std::isfinite(offset_s)) return bad("RpeOptions: offset_s must be finite");
    if (!std::isfinite(scale)) return bad("RpeOptions: scale must be finite");
    if (reason) reason->clear();
    return Status::Ok;
  }
};

/// One compared pair. Indices point into the caller's trajectories (not the sorted order).
template <class T>
struct RpePair {
  std::uint32_t estimate_i = 0, estimate_j = 0;
  std::uint32_t groundtruth_i = 0, groundtruth_j = 0;
  T translation_m = T(0);
  T rotation_deg = T(0);
};

template <class T>
struct RpeResult {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }

  ErrorStatistics<T> translation_m;   ///< |t(E)|, metres
  ErrorStatistics<T> rotation_deg;    ///< angle of R(E), degrees
  std::size_t num_pairs = 0;          ///< "compared_pose_pairs"
  std::size_t num_dropped_gap = 0;    ///< pairs dropped: a ground-truth stamp further than 2 x median GT interval
  double max_gap_s = 0;               ///< that gap limit
  std::vector<RpePair<T>> pairs;
};

/// evaluate_rpe.py GROUNDTRUTH ESTIMATE --fixed_delta --delta D --delta_unit U, every pair used.
/// Both trajectories are first sorted by stamp (duplicates: last entry wins, non-finite stamps
/// ignored). For each estimate pose i (sorted), j = the pose whose delta coordinate (frame index,
/// stamp, distance or angle travelled) is closest to that of i plus delta; the pair is dropped when
/// j is the LAST estimate pose (TUM's rule, so the final frame never pairs). Each estimate stamp
/// takes the closest ground-truth stamp (not unique, no 0.02 s window); the pair is dropped when
/// either stamp gap exceeds 2 x the median ground-truth stamp interval.
/// Rotation angles: arccos(clamp((trace - 1) / 2)) in double as TUM for double input; for float input
/// the atan2(|vee(R - R^T)| / 2, (trace - 1) / 2) form, since arccos near 1 amplifies float round-off
/// of the rotation matrices (1e-7) into 5e-4 rad.
template <class T>
RpeResult<T> evaluate_rpe(const Trajectory<T>& groundtruth, const Trajectory<T>& estimate,
                          const RpeOptions& options = {});

// ------------------------------------------------------------------------------------------------
// Implementation
// ------------------------------------------------------------------------------------------------
namespace detail {

/// evaluate_rpe.py find_closest_index, line for line (binary search remembering the best probe;
/// its tie-breaking decides which of two equidistant stamps is taken, so it is ported, not rewritten).
inline std::size_t find_closest_index(const std::vector<double>& list, double t) {
  std::size_t beginning = 0;
  double difference = std::abs(list[0] - t);
  std::size_t best = 0;
  std::size_t end = list.size();
  while (beginning < end) {
    const std::size_t middle = (end + beginning) / 2;
    if (std::abs(list[middle] - t) < difference) {
      difference = std::abs(list[middle] - t);
      best = middle;
    }
    if (t == list[middle]) return middle;
    if (list[middle] > t) {
      end = middle;
    } else {
      beginning = middle + 1;
    }
  }
  return best;
}

/// TUM compute_angle for double; the atan2 form for float input (see evaluate_rpe).
template <class T>
double relative_rotation_angle_rad(const Mat3<double>& R) {
  if (std::is_same<T, double>::value) return rotation_angle(R);
  const Vec3<double> w(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  return std::atan2(0.5 * w.norm(), 0.5 * (R.trace() - 1.0));
}

/// TUM's overlap check: true when at least 2 distinct estimate stamps round-trip est -> closest GT ->
/// closest est (sorted stamps; offset added to the estimate's).
inline bool stamps_overlap(const std::vector<double>& stamps_gt, const std::vector<double>& stamps_est,
                           double offset) {
  std::vector<std::uint8_t> returned(stamps_est.size(), 0);
  std::size_t distinct = 0;
  for (std::size_t k = 0; k < stamps_est.size(); ++k) {
    const double t_gt = stamps_gt[find_closest_index(stamps_gt, stamps_est[k] + offset)];
    const std::size_t back = find_closest_index(stamps_est, t_gt - offset);
    distinct += returned[back] == 0;
    returned[back] = 1;
  }
  return distinct >= 2;
}

/// The coordinate along which delta is measured (evaluate_rpe.py index_est), per estimate pose P[k].
inline void delta_index(const RpeOptions& options, const std::vector<double>& stamps_est,
                        const std::vector<Rigid3<double>>& P, std::vector<double>* index) {
  const std::size_t n_est = stamps_est.size();
  switch (options.delta_unit) {
    case DeltaUnit::Frames:
      for (std::size_t k = 0; k < n_est; ++k) (*index)[k] = static_cast<double>(k);
      break;
    case DeltaUnit::Seconds:
      *index = stamps_est;
      break;
    case DeltaUnit::Metres:
    case DeltaUnit::Radians:
    case DeltaUnit::Degrees: {
      const double unit = options.delta_unit == DeltaUnit::Degrees ? Constants<double>::rad_to_deg() : 1.0;
      double sum = 0.0;
      (*index)[0] = 0.0;
      for (std::size_t k = 0; k + 1 < n_est; ++k) {
        const Rigid3<double> motion = P[k + 1].inverse() * P[k];
        sum += options.delta_unit == DeltaUnit::Metres ? motion.t.norm() : rotation_angle(motion.R) * unit;
        (*index)[k + 1] = sum;
      }
      break;
    }
  }
}

/// The gap rule's limit: 2 x the median ground-truth stamp interval (sorted stamps, at least 2).
inline double max_stamp_gap(const std::vector<double>& stamps_gt) {
  std::vector<double> gt_intervals(stamps_gt.size() - 1);
  for (std::size_t k = 0; k + 1 < stamps_gt.size(); ++k) gt_intervals[k] = stamps_gt[k + 1] - stamps_gt[k];
  const ErrorStatistics<double> interval_stats = compute_statistics(gt_intervals.data(), gt_intervals.size());
  return 2.0 * interval_stats.median;
}

/// Translation (m) and rotation (deg) error of the estimate's motion from P_i to P_j (translation scaled)
/// against the ground truth's from Q_gi to Q_gj: ominus(scale(ominus(P_j, P_i)), ominus(Q_j, Q_i)) with
/// ominus(a, b) = a^-1 b.
template <class T>
void relative_pose_error(const Rigid3<double>& P_i, const Rigid3<double>& P_j, const Rigid3<double>& Q_gi,
                         const Rigid3<double>& Q_gj, double scale, RpePair<T>* pair) {
  Rigid3<double> est_motion = P_j.inverse() * P_i;
  est_motion.t *= scale;
  const Rigid3<double> gt_motion = Q_gj.inverse() * Q_gi;
  const Rigid3<double> error = est_motion.inverse() * gt_motion;
  pair->translation_m = static_cast<T>(error.t.norm());
  pair->rotation_deg = static_cast<T>(relative_rotation_angle_rad<T>(error.R) * Constants<double>::rad_to_deg());
}

/// A trajectory in stamp order (distinct finite stamps only): each entry's position in the caller's
/// trajectory, its stamp, and its pose in double.
struct SortedTrajectory {
  std::vector<std::uint32_t> order;
  std::vector<double> stamps;
  std::vector<Rigid3<double>> poses;
  std::size_t size() const { return order.size(); }
};

/// The stamps of `traj` in `sorted->order`.
template <class T>
void sorted_stamps(const Trajectory<T>& traj, SortedTrajectory* sorted) {
  sorted->stamps.resize(sorted->size());
  for (std::size_t k = 0; k < sorted->size(); ++k) sorted->stamps[k] = traj.stamps[sorted->order[k]];
}

/// The poses of `traj` in `sorted->order`, in double; false when one is not finite.
template <class T>
bool sorted_finite_poses(const Trajectory<T>& traj, SortedTrajectory* sorted) {
  sorted->poses.resize(sorted->size());
  for (std::size_t k = 0; k < sorted->size(); ++k) sorted->poses[k] = traj.poses[sorted->order[k]].template cast<double>();
  return std::all_of(sorted->poses.begin(), sorted->poses.end(), [](const Rigid3<double>& p) { return p.all_finite(); });
}

/// Every pair (i, j) of estimate poses delta apart along `index` (j not the last pose) whose two stamps
/// have a ground-truth stamp within max_gap, with its errors, into result->pairs, trans and rot; pairs
/// beyond the gap are counted in result->num_dropped_gap. False, with the estimate position i in
/// *bad_i, when a pair's error leaves the range of T (finite poses whose relative motion overflows).
template <class T>
bool collect_rpe_pairs(const RpeOptions& options, const std::vector<double>& index, const SortedTrajectory& gt,
                       const SortedTrajectory& est, double max_gap, RpeResult<T>* result, std::vector<T>* trans,
                       std::vector<T>* rot, std::size_t* bad_i) {
  const std::size_t n_est = est.size();
  const double offset = options.offset_s;
  for (std::size_t i = 0; i < n_est; ++i) {
    const std::size_t j = find_closest_index(index, index[i] + options.delta);
    if (j == n_est - 1) continue;
    const double te_i = est.stamps[i] + offset;
    const double te_j = est.stamps[j] + offset;
    const std::size_t gi = find_closest_index(gt.stamps, te_i);
    const std::size_t gj = find_closest_index(gt.stamps, te_j);
    if (std::abs(gt.stamps[gi] - te_i) > max_gap || std::abs(gt.stamps[gj] - te_j) > max_gap) {
      ++result->num_dropped_gap;
      continue;
    }
    RpePair<T> pair;
    pair.estimate_i = est.order[i];
    pair.estimate_j = est.order[j];
    pair.groundtruth_i = gt.order[gi];
    pair.groundtruth_j = gt.order[gj];
    relative_pose_error(est.poses[i], est.poses[j], gt.poses[gi], gt.poses[gj], options.scale, &pair);
    if (!std::isfinite(pair.translation_m) || !std::isfinite(pair.rotation_deg)) {
      *bad_i = i;
      return false;
    }
    trans->push_back(pair.translation_m);
    rot->push_back(pair.rotation_deg);
    result->pairs.push_back(pair);
  }
  return true;
}

}  // namespace detail

template <class T>
RpeResult<T> evaluate_rpe(const Trajectory<T>& groundtruth, const Trajectory<T>& estimate, const RpeOptions& options) {
  RpeResult<T> result;
  auto fail = [&result](Status status, const std::string& why) {
    result.status = status;
    result.reason = "rpe: " + why;
    return result;
  };
  if (groundtruth.stamps.size() != groundtruth.poses.size() || estimate.stamps.size() != estimate.poses.size()) {
    return fail(Status::InvalidInput, "a trajectory has different numbers of stamps and poses");
  }
  {
    std::string why;
    if (options.validate(&why) != Status::Ok) return fail(Status::InvalidInput, why);
  }
  detail::SortedTrajectory gt, est;
  detail::sorted_unique_stamp_order(groundtruth.stamps.data(), groundtruth.size(), &gt.order);
  detail::sorted_unique_stamp_order(estimate.stamps.data(), estimate.size(), &est.order);
  if (gt.size() < 2 || est.size() < 2) {
    return fail(Status::TooFewPoints, "need at least 2 distinct finite stamps in each trajectory, got " +
                                          std::to_string(gt.size()) + " ground truth and " +
                                          std::to_string(est.size()) + " estimate");
  }
  detail::sorted_stamps(groundtruth, &gt);
  detail::sorted_stamps(estimate, &est);
  if (!detail::stamps_overlap(gt.stamps, est.stamps, options.offset_s)) {
    return fail(Status::TooFewPoints, "the stamps of the two trajectories do not overlap (wrong files?)");
  }
  if (!detail::sorted_finite_poses(estimate, &est) || !detail::sorted_finite_poses(groundtruth, &gt)) {
    return fail(Status::NonFinite, "non-finite pose");
  }

  const std::size_t n_est = est.size();
  std::vector<double> index(n_est);
  detail::delta_index(options, est.stamps, est.poses, &index);
  const double max_gap = detail::max_stamp_gap(gt.stamps);
  result.max_gap_s = max_gap;

  result.pairs.reserve(n_est);
  std::vector<T> trans;
  std::vector<T> rot;
  trans.reserve(n_est);
  rot.reserve(n_est);
  std::size_t bad_i = 0;
  if (!detail::collect_rpe_pairs(options, index, gt, est, max_gap, &result, &trans, &rot, &bad_i)) {
    return fail(Status::InvalidInput, "the translation error of the pair from estimate pose " +
                                          std::to_string(est.order[bad_i]) + " is beyond the range of the scalar type "
                                          "(positions near the floating-point limit)");
  }
  result.num_pairs = result.pairs.size();
  if (result.num_pairs < 2) {
    return fail(Status::TooFewPoints, "only " + std::to_string(result.num_pairs) +
                                          " pose pairs matched the ground truth (TUM needs 2); " +
                                          std::to_string(result.num_dropped_gap) + " dropped by the " +
                                          std::to_string(max_gap) + " s gap rule");
  }
  result.translation_m = compute_statistics(trans.data(), trans.size());
  result.rotation_deg = compute_statistics(rot.data(), rot.size());
  for (const ErrorStatistics<T>* s : {&result.translation_m, &result.rotation_deg}) {
    if (!s->ok()) return fail(s->status, s->reason);
  }
  return result;
}

}  // namespace dyncull::eval
