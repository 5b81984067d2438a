/// @file pose_refinement.hpp
/// Ceres (>= 2.1) motion-only pose refinement: the pixel reprojection error of geometry/pnp.hpp
/// (Zhu et al. 2024 §2) with an optional Huber loss, rotation on ceres::EigenQuaternionManifold.
#pragma once

#include "dyncull/core/camera.hpp"
#include "dyncull/core/flags.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/core/traits.hpp"
#include "dyncull/core/types.hpp"
#include "dyncull/geometry/pnp.hpp"

#include <ceres/ceres.h>
#include <ceres/version.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

static_assert(CERES_VERSION_MAJOR > 2 || (CERES_VERSION_MAJOR == 2 && CERES_VERSION_MINOR >= 1),
              "dyncull/ceres/pose_refinement.hpp needs Ceres >= 2.1 (ceres::Manifold)");

namespace dyncull {

/// Reprojection residual (pixels) of one world point for cam_from_world = (q, t); q is an Eigen
/// quaternion stored x, y, z, w (EigenQuaternionManifold's layout). Templated for Ceres Jets.
struct ReprojectionResidual {
  double X, Y, Z;  ///< world point
  double u, v;     ///< observed pixel
  double fx, fy, cx, cy;

  template <class J>
  bool operator()(const J* q_xyzw, const J* t, J* residual) const {
    const Eigen::Map<const Eigen::Quaternion<J>> q(q_xyzw);
    const Eigen::Map<const Eigen::Matrix<J, 3, 1>> tv(t);
    const Eigen::Matrix<J, 3, 1> p = q * Eigen::Matrix<J, 3, 1>(J(X), J(Y), J(Z)) + tv;
    // Points that move behind the camera during the solve: a large constant residual with zero
    // gradient would stall, so keep the division and let the trust region reject the step.
    residual[0] = J(fx) * p(0) / p(2) + J(cx) - J(u);
    residual[1] = J(fy) * p(1) / p(2) + J(cy) - J(v);
    return true;
  }
};

namespace detail {

/// False, with the status and reason in `res`, for inputs refine_pose_ceres refuses (see its contract).
template <class T, class Points3, class Points2>
bool ceres_refinement_inputs_ok(const Points3& world, const Points2& pixels, const PinholeCamera<T>& camera,
                                const Rigid3<T>& initial_cam_from_world, const PoseRefinementOptions<T>& options,
                                FlagView mask, PoseRefinementResult<T>* res) {
  if (!check_pnp_inputs(world, pixels, camera, &res->status, &res->reason)) {
    res->reason = "refine_pose_ceres: " + res->reason;
    return false;
  }
  std::string why;
  if (!flags_fit(mask, static_cast<std::size_t>(world.size()), "mask", "correspondences", &why) ||
      options.validate(&why) != Status::Ok) {
    res->status = Status::InvalidInput;
    res->reason = "refine_pose_ceres: " + why;
    return false;
  }
  if (!initial_cam_from_world.all_finite()) {
    res->status = Status::NonFinite;
    res->reason = "refine_pose_ceres: initial pose is not finite";
    return false;
  }
  return true;
}

/// Ceres' solver settings for the options' limits: dense QR on one thread, silent.
template <class T>
ceres::Solver::Options ceres_solver_options(const PoseRefinementOptions<T>& options) {
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = options.max_iterations;
  so.function_tolerance = static_cast<double>(options.cost_tolerance);
  so.parameter_tolerance = static_cast<double>(options.step_tolerance);
  so.gradient_tolerance = 1e-16;
  so.num_threads = 1;
  so.logging_type = ceres::SILENT;
  so.minimizer_progress_to_stdout = false;
  return so;
}

/// RMS of the plain squared reprojection errors at `pose`, over the points the refinement used (masked in,
/// finite, in front of the initial camera `init`).
template <class T, class Points3, class Points2>
double ceres_refinement_rmse(const Points3& world, const Points2& pixels, const PinholeCamera<T>& camera,
                             FlagView mask, const Rigid3<double>& init, const Rigid3<double>& pose) {
  const std::size_t n = static_cast<std::size_t>(world.size());
  double sq = 0;
  std::size_t m = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (mask.given && !mask[i]) continue;
    const Vec3<double> X = to_vec3<double>(world[i]);
    const Vec2<double> x = to_vec2<double>(pixels[i]);
    if (!X.allFinite() || !x.allFinite() || !((init.R * X + init.t)(2) > 0)) continue;
    const Vec3<double> p = pose.apply(X);
    const Vec2<double> e(camera.fx * p(0) / p(2) + camera.cx - x(0), camera.fy * p(1) / p(2) + camera.cy - x(1));
    sq += e.squaredNorm();
    ++m;
  }
  return m > 0 ? std::sqrt(sq / static_cast<double>(m)) : 0.0;
}

}  // namespace detail

/// Refines cam_from_world with Ceres' Levenberg-Marquardt on the same cost as refine_pose()
/// (0.5 sum rho(|r|^2), Huber of options.huber_threshold_px when options.huber) over the finite
/// correspondences in front of the initial camera (mask: optional, one flag per correspondence,
/// non-zero = use; a given mask of another size than world: InvalidInput). Double
/// internally; options.max_iterations, step_tolerance and cost_tolerance map to Ceres' limits.
/// InvalidInput for sizes that differ, an invalid camera or options that fail options.validate()
/// (the same checks as refine_pose()).
template <class T, class Points3, class Points2>
PoseRefinementResult<T> refine_pose_ceres(const Points3& world, const Points2& pixels, const PinholeCamera<T>& camera,
                                          const Rigid3<T>& initial_cam_from_world,
                                          const PoseRefinementOptions<T>& options = {},
                                          FlagView mask = nullptr) {
  static_assert(is_point_container_v<Points3> && PointTraits<container_point_t<Points3>>::dim == 3,
                "refine_pose_ceres: world must be a container of 3-D points");
  static_assert(is_point_container_v<Points2>, "refine_pose_ceres: pixels must be a container of 2-D points");
  PoseRefinementResult<T> res;
  res.cam_from_world = initial_cam_from_world;
  if (!detail::ceres_refinement_inputs_ok(world, pixels, camera, initial_cam_from_world, options, mask, &res))
    return res;
  const Rigid3<double> init = initial_cam_from_world.template cast<double>();
  Eigen::Quaterniond q(init.R);
  q.normalize();
  double q_xyzw[4] = {q.x(), q.y(), q.z(), q.w()};
  double t[3] = {init.t(0), init.t(1), init.t(2)};

  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.manifold_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  std::unique_ptr<ceres::LossFunction> loss;
  if (options.huber) loss = std::make_unique<ceres::HuberLoss>(static_cast<double>(options.huber_threshold_px));

  const std::size_t n = static_cast<std::size_t>(world.size());
  std::size_t used = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (mask.given && !mask[i]) continue;
    const Vec3<double> X = to_vec3<double>(world[i]);
    const Vec2<double> x = to_vec2<double>(pixels[i]);
    if (!X.allFinite() || !x.allFinite()) continue;
    if (!((init.R * X + init.t)(2) > 0)) continue;  // same point set as refine_pose() at the start
    auto* cost = new ceres::AutoDiffCostFunction<ReprojectionResidual, 2, 4, 3>(new ReprojectionResidual{
        X(0), X(1), X(2), x(0), x(1), static_cast<double>(camera.fx), static_cast<double>(camera.fy),
        static_cast<double>(camera.cx), static_cast<double>(camera.cy)});
    problem.AddResidualBlock(cost, loss.get(), q_xyzw, t);
    ++used;
  }
  res.num_points = used;
  if (used < 3) {
    res.status = Status::TooFewPoints;
    res.reason = "refine_pose_ceres: " + std::to_string(used) + " usable points in front of the camera, need 3";
    return res;
  }
  problem.SetManifold(q_xyzw, new ceres::EigenQuaternionManifold);

  ceres::Solver::Summary summary;
  ceres::Solve(detail::ceres_solver_options(options), &problem, &summary);

  res.initial_cost = summary.initial_cost;
  res.final_cost = summary.final_cost;
  res.iterations = static_cast<int>(summary.iterations.size() > 0 ? summary.iterations.size() - 1 : 0);
  const Eigen::Quaterniond qf(q_xyzw[3], q_xyzw[0], q_xyzw[1], q_xyzw[2]);
  Rigid3<double> out;
  out.R = qf.normalized().toRotationMatrix();
  out.t = Vec3<double>(t[0], t[1], t[2]);
  res.cam_from_world = out.template cast<T>();
  res.rmse_px = detail::ceres_refinement_rmse(world, pixels, camera, mask, init, out);
  if (!summary.IsSolutionUsable() || !res.cam_from_world.all_finite()) {
    res.status = Status::NotConverged;
    res.reason = "refine_pose_ceres: " + summary.message;
  }
  return res;
}

}  // namespace dyncull
