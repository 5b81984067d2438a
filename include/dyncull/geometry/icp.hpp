/// @file icp.hpp
/// Point-to-point ICP (Besl & McKay 1992): nearest neighbours from a static k-d tree, Umeyama/Kabsch
/// closed form per iteration (Zhu et al. 2024, §2 eq. 4); Open3D's convergence criteria.
#pragma once

#include "dyncull/core/status.hpp"
#include "dyncull/core/traits.hpp"
#include "dyncull/core/types.hpp"
#include "dyncull/geometry/kdtree.hpp"
#include "dyncull/geometry/rigid.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace dyncull {

template <class T>
struct IcpOptions {
  int max_iterations = 30;                     ///< Open3D's default ICPConvergenceCriteria
  T max_correspondence_distance_m = T(0.05);   ///< pairs farther apart than this are not matched
  T relative_fitness = T(1e-6);                ///< stop when |fitness change| falls below this ...
  T relative_rmse = T(1e-6);                   ///< ... and |rmse change| below this (metres), as Open3D
  bool estimate_scale = false;                 ///< Sim(3) instead of SE(3) per step

  static constexpr int kMaxIterations = 10000;  ///< upper bound of max_iterations

  /// Ok, or InvalidInput with a reason naming the field.
  Status validate(std::string* reason = nullptr) const {
    auto bad = [&](const char* why) {
      if (reason) *reason = why;
      return Status::InvalidInput;
    };
    if (max_iterations < 0 || max_iterations > kMaxIterations)
      return bad("IcpOptions: max_iterations must be in [0, 10000]");
    if (!(max_correspondence_distance_m > T(0)) || !std::isfinite(max_correspondence_distance_m))
      return bad("IcpOptions: max_correspondence_distance_m must be finite and > 0");
    if (!(relative_fitness >= T(0)) || !std::isfinite(relative_fitness))
      return bad("IcpOptions: relative_fitness must be finite and >= 0");
    if (!(relative_rmse >= T(0)) || !std::isfinite(relative_rmse))
      return bad("IcpOptions: relative_rmse must be finite and >= 0");
    if (reason) reason->clear();
    return Status::Ok;
  }
};

template <class T>
struct IcpResult {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }
  Rigid3<T> target_from_source;          ///< maps source points onto the target cloud
  T scale = T(1);                        ///< != 1 only with estimate_scale (then x_t = s R x_s + t)
  T rmse = T(0);                         ///< RMS distance of the correspondences at the result (Open3D inlier_rmse)
  T fitness = T(0);                      ///< correspondences / source points at the result (Open3D fitness)
  std::size_t num_correspondences = 0;
  int iterations = 0;                    ///< transform updates made
  bool converged = false;                ///< stopped by the tolerances rather than max_iterations
};

namespace detail {

/// False, with the status and reason in `res`, for invalid options, a non-finite initial transform or an
/// empty target.
template <class T>
bool icp_inputs_ok(const KdTree3<T>& target, const Rigid3<T>& initial, const IcpOptions<T>& options,
                   IcpResult<T>* res) {
  std::string why;
  if (options.validate(&why) != Status::Ok) {
    res->status = Status::InvalidInput;
    res->reason = why;
    return false;
  }
  if (!initial.all_finite()) {
    res->status = Status::NonFinite;
    res->reason = "icp: initial transform is not finite";
    return false;
  }
  if (target.empty()) {
    res->status = Status::TooFewPoints;
    res->reason = "icp: the target cloud is empty";
    return false;
  }
  return true;
}

/// The finite source points, contiguous.
template <class T, class SourcePoints>
std::vector<Vec3<T>> finite_points(const SourcePoints& source) {
  const std::size_t n_in = static_cast<std::size_t>(source.size());
  std::vector<Vec3<T>> src;
  src.reserve(n_in);
  for (std::size_t i = 0; i < n_in; ++i) {
    const Vec3<T> p = to_vec3<T>(source[i]);
    if (p.allFinite()) src.push_back(p);
  }
  return src;
}

/// One correspondence pass at (sR, t): the nearest target point of each source point within the
/// correspondence distance (squared: max_d2), seeded by its previous match in `hint`; the moments of
/// (source, matched target) into `acc`, fitness (inv_n = 1 / source points) and rmse. Returns the matches.
template <class T>
std::size_t icp_match(const KdTree3<T>& target, const std::vector<Vec3<T>>& src, const Mat3<T>& sR, const Vec3<T>& t,
                      T max_d2, T inv_n, std::vector<std::uint32_t>* hint, AlignmentAccumulator<T>* acc, T* fitness,
                      T* rmse) {
  *acc = AlignmentAccumulator<T>();
  bool first = true;
  T sum_d2 = T(0);
  for (std::size_t i = 0; i < src.size(); ++i) {
    const Vec3<T> q = sR * src[i] + t;
    T d2 = T(0);
    const std::uint32_t slot = target.nearest_slot(q, &d2, max_d2, (*hint)[i]);
    (*hint)[i] = slot;
    if (slot == KdTree3<T>::kNone) continue;
    const Vec3<T> m = target.point_of_slot(slot);
    if (first) {
      acc->reset(src[i], m);
      first = false;
    }
    acc->add(src[i], m);
    sum_d2 += d2;
  }
  *fitness = static_cast<T>(acc->used) * inv_n;
  *rmse = acc->used > 0 ? std::sqrt(sum_d2 / static_cast<T>(acc->used)) : T(0);
  return acc->used;
}

}  // namespace detail

/// Aligns `source` to the cloud indexed by `target` starting from `initial` (target_from_source).
/// Non-finite source points are skipped. TooFewPoints when fewer than 3 correspondences are found;
/// the result then holds the last good transform.
template <class T, class SourcePoints>
IcpResult<T> icp_point_to_point(const KdTree3<T>& target, const SourcePoints& source,
                                const Rigid3<T>& initial = Rigid3<T>{}, const IcpOptions<T>& options = {}) {
  static_assert(is_point_container_v<SourcePoints> && PointTraits<container_point_t<SourcePoints>>::dim == 3,
                "icp_point_to_point: source must be a container of 3-D points");
  IcpResult<T> res;
  res.target_from_source = initial;
  if (!detail::icp_inputs_ok(target, initial, options, &res)) return res;
  // Finite source points once, contiguous; the previous match of each one seeds its next query.
  const std::vector<Vec3<T>> src = detail::finite_points<T>(source);
  if (src.size() < 3) {
    res.status = Status::TooFewPoints;
    res.reason = "icp: " + std::to_string(src.size()) + " finite source points, need 3";
    return res;
  }
  std::vector<std::uint32_t> hint(src.size(), KdTree3<T>::kNone);
  const T max_d2 = options.max_correspondence_distance_m * options.max_correspondence_distance_m;
  const T inv_n = T(1) / static_cast<T>(static_cast<std::size_t>(source.size()));

  Mat3<T> sR = initial.R;  // scale * R
  Vec3<T> t = initial.t;
  AlignmentAccumulator<T> acc;
  T fitness = T(0), rmse = T(0);
  std::size_t matched = detail::icp_match(target, src, sR, t, max_d2, inv_n, &hint, &acc, &fitness, &rmse);
  AlignmentOptions align;
  align.estimate_scale = options.estimate_scale;
  int it = 0;
  for (; it < options.max_iterations; ++it) {
    if (matched < 3) break;
    const auto a = acc.solve(align);
    if (!a.ok()) {
      res.status = a.status;
      res.reason = "icp: iteration " + std::to_string(it) + ": " + a.reason;
      break;
    }
    sR = a.dst_from_src.scale * a.dst_from_src.R;
    t = a.dst_from_src.t;
    res.scale = a.dst_from_src.scale;
    res.target_from_source.R = a.dst_from_src.R;
    res.target_from_source.t = t;
    const T prev_fitness = fitness, prev_rmse = rmse;
    matched = detail::icp_match(target, src, sR, t, max_d2, inv_n, &hint, &acc, &fitness, &rmse);
    if (std::abs(prev_fitness - fitness) < options.relative_fitness &&
        std::abs(prev_rmse - rmse) < options.relative_rmse) {
      res.converged = true;
      ++it;
      break;
    }
  }
  res.iterations = it;
  res.fitness = fitness;
  res.rmse = rmse;
  res.num_correspondences = matched;
  if (res.ok() && matched < 3) {
    res.status = Status::TooFewPoints;
    res.reason = "icp: " + std::to_string(matched) +
                 " correspondences within max_correspondence_distance_m (need 3); is the initial guess close?";
  }
  return res;
}

/// Convenience overload: builds the k-d tree of `target` (prefer the tree overload when the target is
/// aligned against repeatedly).
template <class T, class SourcePoints, class TargetPoints>
IcpResult<T> icp_point_to_point(const SourcePoints& source, const TargetPoints& target,
                                const Rigid3<T>& initial = Rigid3<T>{}, const IcpOptions<T>& options = {}) {
  const KdTree3<T> tree(target);
  return icp_point_to_point(tree, source, initial, options);
}

}  // namespace dyncull
