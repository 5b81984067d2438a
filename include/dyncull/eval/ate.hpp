/// @file ate.hpp
/// Absolute trajectory error as TUM evaluate_ate.py (DLD-SLAM, Yu et al. 2024, eq. 6-7;
/// Zhang et al. 2023 eq. 9-10): associate stamps,
/// align the estimate's positions onto the ground truth's (SE(3), or Sim(3) for monocular), then
/// summarise the per-pose position errors.
#pragma once

#include "dyncull/core/status.hpp"
#include "dyncull/core/types.hpp"
#include "dyncull/eval/statistics.hpp"
#include "dyncull/eval/trajectory.hpp"
#include "dyncull/geometry/rigid.hpp"

#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

namespace dyncull::eval {

struct AteOptions {
  AssociationOptions association;  ///< 0.02 s window, no offset (evaluate_ate.py defaults)
  /// Fit a similarity (scale too): for monocular estimates. evaluate_ate.py's --scale is instead a
  /// fixed factor given by the user; a fitted scale gives the lower bound of the error over scales.
  bool estimate_scale = false;

  /// Ok, or InvalidInput with a reason naming the field (association.* as nested).
  Status validate(std::string* reason = nullptr) const {
    std::string why;
    if (association.validate(&why) != Status::Ok) {
      if (reason) {
        const std::size_t colon = why.find(": ");
        *reason = "AteOptions: association." + (colon == std::string::npos ? why : why.substr(colon + 2));
      }
      return Status::InvalidInput;
    }
    if (reason) reason->clear();
    return Status::Ok;
  }
};

template <class T>
struct AteResult {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }

  ErrorStatistics<T> error_m;          ///< position error after alignment, metres
  std::size_t num_pairs = 0;           ///< associated pose pairs ("compared_pose_pairs")
  Sim3<T> groundtruth_from_estimate;   ///< the alignment applied to the estimate (scale 1 for SE(3))
  std::vector<std::uint32_t> groundtruth_index;  ///< per pair, index into the ground-truth trajectory
  std::vector<std::uint32_t> estimate_index;     ///< per pair, index into the estimate trajectory
  std::vector<T> errors_m;                       ///< per pair, sorted by ground-truth stamp
};

/// ATE of already associated positions: estimate_xyz and groundtruth_xyz are 3xN, column i
/// corresponds. Aligns with dyncull::umeyama (Horn/Kabsch with the reflection fix, exactly TUM's
/// `align`), then errors |s R e_i + t - g_i|. The index vectors of the result stay empty.
template <class DE, class DG>
AteResult<typename DE::Scalar> ate_from_positions(const Eigen::MatrixBase<DE>& estimate_xyz,
                                                  const Eigen::MatrixBase<DG>& groundtruth_xyz,
                                                  bool estimate_scale = false) {
  using T = typename DE::Scalar;
  static_assert(std::is_same<T, typename DG::Scalar>::value, "ate_from_positions: both inputs need the same scalar");
  AteResult<T> result;
  result.num_pairs = static_cast<std::size_t>(estimate_xyz.cols());
  AlignmentOptions align_options;
  align_options.estimate_scale = estimate_scale;
  const AlignmentResult<T> alignment = umeyama(estimate_xyz, groundtruth_xyz, align_options);
  if (!alignment.ok()) {
    result.status = alignment.status;
    result.reason = "ate: alignment failed: " + alignment.reason;
    return result;
  }
  result.groundtruth_from_estimate = alignment.dst_from_src;
  const Sim3<T>& s = alignment.dst_from_src;
  const Eigen::Index n = estimate_xyz.cols();
  result.errors_m.resize(static_cast<std::size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i) {
    const Vec3<T> e = estimate_xyz.col(i);
    const Vec3<T> g = groundtruth_xyz.col(i);
    const Vec3<T> d = s.apply(e) - g;
    T err = d.norm();
    if (!std::isfinite(err) && d.allFinite()) err = d.stableNorm();  // squares overflowed, the norm did not
    if (!std::isfinite(err)) {
      result.status = Status::InvalidInput;
      result.reason = "ate: the error of pair " + std::to_string(i) +
                      " is beyond the largest finite value (coordinates near the floating-point limit)";
      result.errors_m.clear();
      return result;
    }
    result.errors_m[static_cast<std::size_t>(i)] = err;
  }
  result.error_m = compute_statistics(result.errors_m.data(), result.errors_m.size());
  if (!result.error_m.ok()) {
    result.status = result.error_m.status;
    result.reason = "ate: " + result.error_m.reason;
  }
  return result;
}

/// evaluate_ate.py GROUNDTRUTH ESTIMATE: associate the stamps (see associate()), align, summarise.
/// Only positions enter ATE (as in TUM); orientations are ignored. Fails with TooFewPoints when
/// fewer than 3 pairs associate, with the alignment's status on degenerate (collinear) paths.
template <class T>
AteResult<T> evaluate_ate(const Trajectory<T>& groundtruth, const Trajectory<T>& estimate,
                          const AteOptions& options = {}) {
  AteResult<T> result;
  {
    std::string why;
    if (options.validate(&why) != Status::Ok) {
      result.status = Status::InvalidInput;
      result.reason = "ate: " + why;
      return result;
    }
  }
  if (groundtruth.stamps.size() != groundtruth.poses.size() || estimate.stamps.size() != estimate.poses.size()) {
    result.status = Status::InvalidInput;
    result.reason = "ate: a trajectory has different numbers of stamps and poses";
    return result;
  }
  AssociationResult matches = associate(groundtruth.stamps, estimate.stamps, options.association);
  if (!matches.ok()) {
    result.status = matches.status;
    result.reason = "ate: " + matches.reason;
    return result;
  }
  const Eigen::Index n = static_cast<Eigen::Index>(matches.size());
  if (n < 3) {
    result.status = Status::TooFewPoints;
    result.reason = "ate: only " + std::to_string(n) + " associated pose pairs, alignment needs 3";
    result.num_pairs = static_cast<std::size_t>(n);
    return result;
  }
  Eigen::Matrix<T, 3, Eigen::Dynamic> est(3, n);
  Eigen::Matrix<T, 3, Eigen::Dynamic> gt(3, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const std::size_t k = static_cast<std::size_t>(i);
    gt.col(i) = groundtruth.poses[matches.first[k]].t;
    est.col(i) = estimate.poses[matches.second[k]].t;
  }
  result = ate_from_positions(est, gt, options.estimate_scale);
  result.groundtruth_index = std::move(matches.first);
  result.estimate_index = std::move(matches.second);
  return result;
}

/// The estimate expressed in the ground-truth frame: world_from_cam' = (s R, t) applied to each pose
/// (position s R p + t, orientation R R_i), e.g. to plot or write the aligned trajectory. Stamps kept.
template <class T>
Trajectory<T> apply_alignment(const Sim3<T>& groundtruth_from_estimate, const Trajectory<T>& estimate) {
  Trajectory<T> out = estimate;
  for (Rigid3<T>& pose : out.poses) {
    pose.t = groundtruth_from_estimate.apply(pose.t);
    pose.R = groundtruth_from_estimate.R * pose.R;
  }
  return out;
}

}  // namespace dyncull::eval
