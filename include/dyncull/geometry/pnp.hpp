/// @file pnp.hpp
/// Camera pose from 3-D world points and their pixels (Zhu et al. 2024 §2 eq. 4-6): Lambda Twist P3P
/// (Persson & Nordberg, ECCV 2018) as the minimal solver, DLT on normalised coordinates for all points,
/// Levenberg-Marquardt on SE(3) of the pixel reprojection error (optional Huber loss), and PnP-RANSAC via ransac().
#pragma once

#include "dyncull/core/camera.hpp"
#include "dyncull/core/flags.hpp"
#include "dyncull/core/precompiled.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/core/traits.hpp"
#include "dyncull/core/types.hpp"
#include "dyncull/geometry/ransac.hpp"
#include "dyncull/geometry/symmetric_eigen.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace dyncull {

/// Options of refine_pose(): Levenberg-Marquardt on the reprojection error in pixels.
template <class T>
struct PoseRefinementOptions {
  int max_iterations = 20;          ///< LM iterations (each one pass over the points)
  bool huber = false;               ///< robust Huber loss instead of plain least squares
  T huber_threshold_px = T(2);      ///< Huber knee in pixels (same meaning as ceres::HuberLoss(a))
  T step_tolerance = T(1e-10);      ///< stop when |delta (rad, world units)| falls below this
  T cost_tolerance = T(1e-12);      ///< stop when the relative cost decrease falls below this
  T initial_damping = T(1e-4);      ///< LM lambda, relative to the diagonal of J^T J
  /// Levenberg-Marquardt with a cost check per step; false runs plain Gauss-Newton steps (cheaper:
  /// one pass per iteration) for callers that score the result themselves, as RANSAC's LO does.
  bool check_cost = true;

  static constexpr int kMaxIterations = 10000;  ///< upper bound of max_iterations

  /// Ok, or InvalidInput with a reason naming the field.
  Status validate(std::string* reason = nullptr) const {
    auto bad = [&](const char* why) {
      if (reason) *reason = why;
      return Status::InvalidInput;
    };
    if (max_iterations < 0 || max_iterations > kMaxIterations)
      return bad("PoseRefinementOptions: max_iterations must be in [0, 10000]");
    if (!(huber_threshold_px > T(0)) || !std::isfinite(huber_threshold_px))
      return bad("PoseRefinementOptions: huber_threshold_px must be finite and > 0");
    if (!(step_tolerance >= T(0)) || !std::isfinite(step_tolerance))
      return bad("PoseRefinementOptions: step_tolerance must be finite and >= 0");
    if (!(cost_tolerance >= T(0)) || !std::isfinite(cost_tolerance))
      return bad("PoseRefinementOptions: cost_tolerance must be finite and >= 0");
    if (!(initial_damping >= T(0)) || !std::isfinite(initial_damping))
      return bad("PoseRefinementOptions: initial_damping must be finite and >= 0");
    if (reason) reason->clear();
    return Status::Ok;
  }
};

template <class T>
struct PoseRefinementResult {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }
  Rigid3<T> cam_from_world;
  int iterations = 0;
  std::size_t num_points = 0;  ///< points used (finite, in front of the camera)
  double initial_cost = 0;     ///< 0.5 sum rho(|r|^2) in px^2 (the Ceres cost convention)
  double final_cost = 0;
  double rmse_px = 0;          ///< RMS reprojection error over the used points at the final pose
};

/// Options of solve_pnp() (all points) and solve_pnp_ransac().
template <class T>
struct PnpOptions {
  /// RANSAC; max_residual is the reprojection error in pixels (ORB-SLAM's chi2 5.991 at 1 px sigma = 2.45 px).
  RansacOptions ransac = default_ransac();
  bool refine = true;                      ///< LM on the inliers after RANSAC / after the linear solve
  PoseRefinementOptions<T> refinement{};   ///< used when refine
  static RansacOptions default_ransac() {
    RansacOptions o;
    o.max_residual = 2.0;
    o.max_iterations = 1000;
    return o;
  }

  /// Ok, or InvalidInput with a reason naming the field (ransac.* and refinement.* as nested).
  Status validate(std::string* reason = nullptr) const {
    std::string why;
    if (ransac.validate(&why) != Status::Ok) {
      if (reason) *reason = detail::nested_reason("PnpOptions", "ransac", why);
      return Status::InvalidInput;
    }
    if (refinement.validate(&why) != Status::Ok) {
      if (reason) *reason = detail::nested_reason("PnpOptions", "refinement", why);
      return Status::InvalidInput;
    }
    if (reason) reason->clear();
    return Status::Ok;
  }
};

template <class T>
struct PnpResult {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }
  Rigid3<T> cam_from_world;
  std::vector<std::uint8_t> inlier_mask;  ///< per correspondence: reprojection error < max_residual at the result
  std::size_t num_inliers = 0;
  std::size_t iterations = 0;             ///< RANSAC samples drawn (0 for solve_pnp)
  double rmse_px = 0;                     ///< RMS reprojection error of the inliers
};

/// Lambda Twist P3P. bearings: unit vectors (camera frame) towards world[0..2]. Writes up to 4
/// cam_from_world poses to `out`, returns their number (0 for degenerate input). Double only:
/// the cubic/quadratic closed forms lose too many digits in float.
/// Without a template parameter: compiled once into dyncull::pipeline with DYNCULL_PRECOMPILED.
DYNCULL_SOLVER int solve_p3p(const Vec3<double> bearings[3], const Vec3<double> world[3], Rigid3<double> out[4]);

/// Pose from >= 6 non-coplanar points by DLT on normalised coordinates (world points centred and
/// scaled, pixels through K^-1), projected onto SO(3). Degenerate for coplanar points (use solve_pnp).
template <class T, class Points3, class Points2>
PnpResult<T> solve_pnp_dlt(const Points3& world, const Points2& pixels, const PinholeCamera<T>& camera);

/// Levenberg-Marquardt refinement of cam_from_world on all finite correspondences in front of the
/// camera (mask: optional, one flag per correspondence, non-zero = use). Never throws; NonFinite /
/// TooFewPoints on bad input, InvalidInput when a given mask's size is not world.size().
template <class T, class Points3, class Points2>
PoseRefinementResult<T> refine_pose(const Points3& world, const Points2& pixels, const PinholeCamera<T>& camera,
                                    const Rigid3<T>& initial_cam_from_world,
                                    const PoseRefinementOptions<T>& options = {}, FlagView mask = nullptr);

/// Pose from all correspondences (no outliers expected): DLT when >= 6 non-coplanar points, else the
/// best P3P solution on a well-spread triple; then LM when options.refine.
template <class T, class Points3, class Points2>
PnpResult<T> solve_pnp(const Points3& world, const Points2& pixels, const PinholeCamera<T>& camera,
                       const PnpOptions<T>& options = {});

/// PnP-RANSAC: P3P samples, MSAC scoring on the pixel reprojection error, local optimisation by LM on
/// the inliers, final LM (Huber if options.refinement.huber) and relabelling at the returned pose.
template <class T, class Points3, class Points2>
PnpResult<T> solve_pnp_ransac(const Points3& world, const Points2& pixels, const PinholeCamera<T>& camera,
                              const PnpOptions<T>& options = {});

/// Buffers PnP-RANSAC reuses from call to call (defined below).
template <class T>
struct PnpWorkspace;

/// solve_pnp_ransac writing into `out`, reusing its buffers and the workspace's: a caller that keeps both
/// across frames allocates nothing once they have held the largest input (failures' reasons aside).
template <class T, class Points3, class Points2>
void solve_pnp_ransac(const Points3& world, const Points2& pixels, const PinholeCamera<T>& camera,
                      const PnpOptions<T>& options, PnpWorkspace<T>* workspace, PnpResult<T>* out);

// ---------------------------------------------------------------------------------------------
// Implementation
// ---------------------------------------------------------------------------------------------
namespace detail {

/// Normalised correspondences in structure-of-arrays layout (contiguous, vectorisable residual loops).
template <class T>
struct PnpData {
  std::vector<T> X, Y, Z, x, y;  // world coordinates; normalised image coordinates (K^-1 pixel)
  std::vector<std::uint32_t> index;  // position in the caller's containers
  T fx = T(1), fy = T(1);
  std::size_t size() const { return X.size(); }
};

/// Copies finite correspondences (world point and normalised pixel); returns the number skipped.
template <class T, class Points3, class Points2>
std::size_t load_pnp_data(const Points3& world, const Points2& pixels, const PinholeCamera<T>& camera,
                          PnpData<T>* d) {
  const std::size_t n = static_cast<std::size_t>(world.size());
  for (auto* v : {&d->X, &d->Y, &d->Z, &d->x, &d->y}) {
    v->clear();
    v->reserve(n);
  }
  d->index.clear();
  d->index.reserve(n);
  d->fx = camera.fx;
  d->fy = camera.fy;
  const T ifx = T(1) / camera.fx, ify = T(1) / camera.fy;
  std::size_t skipped = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const T X = point_x<T>(world[i]), Y = point_y<T>(world[i]), Z = point_z<T>(world[i]);
    const T u = point_x<T>(pixels[i]), v = point_y<T>(pixels[i]);
    const T xn = (u - camera.cx) * ifx, yn = (v - camera.cy) * ify;  // NaN / Inf in u, v propagate
    if (!(std::isfinite(X) && std::isfinite(Y) && std::isfinite(Z) && std::isfinite(xn) && std::isfinite(yn))) {
      ++skipped;
      continue;
    }
    d->X.push_back(X);
    d->Y.push_back(Y);
    d->Z.push_back(Z);
    d->x.push_back(xn);
    d->y.push_back(yn);
    d->index.push_back(static_cast<std::uint32_t>(i));
  }
  return skipped;
}

/// Squared pixel reprojection errors of data [begin, end); points at or behind the camera get +max.
template <class T>
void pnp_residuals_sq(const PnpData<T>& d, const Rigid3<T>& pose, std::size_t begin, std::size_t end, T* out) {
  const T r00 = pose.R(0, 0), r01 = pose.R(0, 1), r02 = pose.R(0, 2);
  const T r10 = pose.R(1, 0), r11 = pose.R(1, 1), r12 = pose.R(1, 2);
  const T r20 = pose.R(2, 0), r21 = pose.R(2, 1), r22 = pose.R(2, 2);
  const T t0 = pose.t(0), t1 = pose.t(1), t2 = pose.t(2);
  const T fx = d.fx, fy = d.fy;
  const T big = std::numeric_limits<T>::max();
  const T* X = d.X.data();
  const T* Y = d.Y.data();
  const T* Z = d.Z.data();
  const T* x = d.x.data();
  const T* y = d.y.data();
  for (std::size_t i = begin; i < end; ++i) {
    const T pc0 = r00 * X[i] + r01 * Y[i] + r02 * Z[i] + t0;
    const T pc1 = r10 * X[i] + r11 * Y[i] + r12 * Z[i] + t1;
    const T pc2 = r20 * X[i] + r21 * Y[i] + r22 * Z[i] + t2;
    const T iz = T(1) / pc2;
    const T du = fx * (pc0 * iz - x[i]);
    const T dv = fy * (pc1 * iz - y[i]);
    const T r = du * du + dv * dv;
    out[i - begin] = pc2 > T(0) ? r : big;
  }
}

/// exp of so(3) (Rodrigues), double.
inline Mat3<double> so3_exp(const Vec3<double>& w) {
  const double theta2 = w.squaredNorm();
  Mat3<double> W;
  W << 0, -w(2), w(1), w(2), 0, -w(0), -w(1), w(0), 0;
  if (theta2 < 1e-16) return Mat3<double>::Identity() + W + 0.5 * W * W;
  const double theta = std::sqrt(theta2);
  return Mat3<double>::Identity() + (std::sin(theta) / theta) * W + ((1 - std::cos(theta)) / theta2) * W * W;
}

/// Huber rho(s) for a squared residual s (Ceres' HuberLoss convention); k2 <= 0 means plain s.
inline double huber_rho(double s, double k, double k2) {
  if (k2 <= 0 || s <= k2) return s;
  return 2.0 * k * std::sqrt(s) - k2;
}

/// The correspondences refine_pose_data iterates over (the indices `idx`, or all when idx == nullptr),
/// the focal lengths and the Huber threshold k (k2 = k^2 <= 0: no robust kernel), in double.
template <class T>
struct PoseLmProblem {
  const PnpData<T>& d;
  const std::uint32_t* idx;
  std::size_t count;
  double fx, fy, k, k2;
  std::size_t at(std::size_t j) const { return idx ? idx[j] : j; }
};

/// The pose refinement's iterate: pose, cost (0.5 sum rho), points in front and their squared-error sum.
struct PoseLmState {
  Mat3<double> R;
  Vec3<double> t;
  double cost = 0;
  std::size_t used = 0;
  double sq = 0;
};

/// Cost (0.5 sum rho) at (Rc, tc); the number of points in front and their squared errors' sum to
/// `used` and `sq_sum`.
template <class T>
double pose_lm_cost(const PoseLmProblem<T>& pr, const Mat3<double>& Rc, const Vec3<double>& tc, std::size_t* used,
                    double* sq_sum) {
  double cost = 0, sq = 0;
  std::size_t m = 0;
  for (std::size_t j = 0; j < pr.count; ++j) {
    const std::size_t i = pr.at(j);
    const Vec3<double> p = Rc * Vec3<double>(pr.d.X[i], pr.d.Y[i], pr.d.Z[i]) + tc;
    if (!(p(2) > 0)) continue;
    const double du = pr.fx * (p(0) / p(2) - static_cast<double>(pr.d.x[i]));
    const double dv = pr.fy * (p(1) / p(2) - static_cast<double>(pr.d.y[i]));
    const double s = du * du + dv * dv;
    if (!std::isfinite(s)) continue;  // an overflowing reprojection is unusable, like a point behind
    cost += huber_rho(s, pr.k, pr.k2);
    sq += s;
    ++m;
  }
  *used = m;
  *sq_sum = sq;
  return 0.5 * cost;
}

/// Points in front of the camera at (R, t), counted up to 3 (Gauss-Newton mode's check before its first pass).
template <class T>
std::size_t count_in_front_up_to_3(const PoseLmProblem<T>& pr, const Mat3<double>& R, const Vec3<double>& t) {
  std::size_t used = 0;
  for (std::size_t j = 0; j < pr.count && used < 3; ++j) {
    const std::size_t i = pr.at(j);
    used += (R.row(2).dot(Vec3<double>(pr.d.X[i], pr.d.Y[i], pr.d.Z[i])) + t(2)) > 0;
  }
  return used;
}

/// Gauss-Newton normal equations H = J^T W J (full, symmetric) and g = J^T W r at (R, t), W the Huber IRLS
/// weights; points at or behind the camera are left out.
template <class T>
void pose_normal_equations(const PoseLmProblem<T>& pr, const Mat3<double>& R, const Vec3<double>& t,
                           Eigen::Matrix<double, 6, 6>* H_out, Eigen::Matrix<double, 6, 1>* g_out) {
  const double fx = pr.fx, fy = pr.fy, k = pr.k, k2 = pr.k2;
  Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
  for (std::size_t j = 0; j < pr.count; ++j) {
    const std::size_t i = pr.at(j);
    const Vec3<double> p = R * Vec3<double>(pr.d.X[i], pr.d.Y[i], pr.d.Z[i]) + t;
    if (!(p(2) > 0)) continue;
    const double iz = 1.0 / p(2);
    const double xn = p(0) * iz, yn = p(1) * iz;
    const double du = fx * (xn - static_cast<double>(pr.d.x[i]));
    const double dv = fy * (yn - static_cast<double>(pr.d.y[i]));
    double w = 1.0;
    if (k2 > 0) {
      const double s = du * du + dv * dv;
      if (s > k2) w = k / std::sqrt(s);  // IRLS weight rho'(s) of Huber
    }
    // d(pixel)/d(p_cam), then p_cam' = exp(omega) p_cam + v: d p/d omega = -[p]x, d p/d v = I.
    const double a = fx * iz, b = fy * iz;
    const double j05 = -a * xn, j15 = -b * yn;
    const double j0[6] = {j05 * p(1), a * p(2) - j05 * p(0), -a * p(1), a, 0.0, j05};
    const double j1[6] = {-b * p(2) + j15 * p(1), -j15 * p(0), b * p(0), 0.0, b, j15};
    // Upper triangle only (21 entries): the symmetric rank-2 update is the inner loop's cost.
    for (int r = 0; r < 6; ++r) {
      const double w0 = w * j0[r], w1 = w * j1[r];
      for (int c = r; c < 6; ++c) H(r, c) += w0 * j0[c] + w1 * j1[c];
      g(r) += w0 * du + w1 * dv;
    }
  }
  *H_out = H;
  *g_out = g;
}

/// The pose moved by a step (omega, v): R' = exp(omega) R, t' = exp(omega) t + v.
inline void apply_pose_step(const Eigen::Matrix<double, 6, 1>& delta, const Mat3<double>& R, const Vec3<double>& t,
                            Mat3<double>* R_new, Vec3<double>* t_new) {
  const Mat3<double> dR = so3_exp(delta.head<3>());
  *R_new = dR * R;
  *t_new = dR * t + delta.tail<3>();
}

/// One Levenberg-Marquardt iteration: up to 10 dampings until the cost does not rise with 3 points in
/// front. False when the refinement should stop (no step accepted, or a step below step_tolerance); a
/// decrease below cost_tolerance sets `it` to max_iterations, ending the loop after this iteration.
template <class T>
bool levenberg_marquardt_step(const PoseLmProblem<T>& pr, const Eigen::Matrix<double, 6, 6>& H,
                              const Eigen::Matrix<double, 6, 1>& g, const PoseRefinementOptions<T>& o, double* lambda,
                              PoseLmState* st, int* it) {
  bool accepted = false;
  Eigen::Matrix<double, 6, 1> delta;
  for (int tries = 0; tries < 10 && !accepted; ++tries) {
    Eigen::Matrix<double, 6, 6> A = H;
    A.diagonal() += *lambda * H.diagonal().cwiseMax(1e-12);
    delta = -A.ldlt().solve(g);
    if (!delta.allFinite()) {
      *lambda *= 10;
      continue;
    }
    Mat3<double> R_new;
    Vec3<double> t_new;
    apply_pose_step(delta, st->R, st->t, &R_new, &t_new);
    std::size_t used_new = 0;
    double sq_new = 0;
    const double cost_new = pose_lm_cost(pr, R_new, t_new, &used_new, &sq_new);
    if (cost_new <= st->cost && used_new >= 3) {
      const double decrease = st->cost - cost_new;
      st->R = R_new;
      st->t = t_new;
      st->cost = cost_new;
      st->used = used_new;
      st->sq = sq_new;
      *lambda = std::max(*lambda * 0.1, 1e-12);
      accepted = true;
      if (decrease <= static_cast<double>(o.cost_tolerance) * (st->cost + 1e-300)) *it = o.max_iterations;
    } else {
      *lambda *= 10;
    }
  }
  return accepted && !(delta.norm() < static_cast<double>(o.step_tolerance));
}

/// Plain Gauss-Newton step (RANSAC's local optimisation scores the result itself); false when the
/// refinement should stop (a non-finite step, or one below step_tolerance after moving).
template <class T>
bool gauss_newton_step(const Eigen::Matrix<double, 6, 6>& H, const Eigen::Matrix<double, 6, 1>& g,
                       const PoseRefinementOptions<T>& o, PoseLmState* st) {
  const Eigen::Matrix<double, 6, 1> delta = -H.ldlt().solve(g);
  if (!delta.allFinite()) return false;
  apply_pose_step(delta, st->R, st->t, &st->R, &st->t);
  return !(delta.norm() < static_cast<double>(o.step_tolerance));
}

/// False, with the status and reason in `res`, when the starting cost overflows or fewer than 3 points
/// are in front of the camera.
template <class T>
bool check_refinement_start(const PoseLmState& st, PoseRefinementResult<T>* res) {
  res->initial_cost = st.cost;
  if (!std::isfinite(st.cost)) {
    res->status = Status::InvalidInput;
    res->reason = "refine_pose: the reprojection cost overflows (coordinates near the floating-point limit)";
    res->initial_cost = res->final_cost = 0;
    return false;
  }
  if (st.used < 3) {
    res->status = Status::TooFewPoints;
    res->reason = "refine_pose: " + std::to_string(st.used) + " points in front of the camera, need 3";
    res->final_cost = st.cost;
    return false;
  }
  return true;
}

/// The refined pose, its statistics and status into `res`. R is re-orthonormalised: exp() products drift
/// by ~1e-16 per step only, but keep R exactly in SO(3).
template <class T>
void finish_refinement(PoseLmState st, int it, const PoseRefinementOptions<T>& o, PoseRefinementResult<T>* res) {
  Eigen::JacobiSVD<Mat3<double>> svd(st.R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  st.R = svd.matrixU() * svd.matrixV().transpose();
  res->cam_from_world.R = st.R.cast<T>();
  res->cam_from_world.t = st.t.cast<T>();
  res->iterations = std::min(it + 1, o.max_iterations);
  res->num_points = st.used;
  res->final_cost = st.cost;
  res->rmse_px = st.used > 0 ? std::sqrt(st.sq / static_cast<double>(st.used)) : 0.0;
  if (!res->cam_from_world.all_finite()) {
    res->status = Status::NonFinite;
    res->reason = "refine_pose: the refinement diverged to a non-finite pose";
  } else if (!std::isfinite(res->final_cost) || !std::isfinite(res->rmse_px)) {
    res->status = Status::InvalidInput;
    res->reason = "refine_pose: the reprojection cost overflows (coordinates near the floating-point limit)";
  } else if (st.used < 3) {
    res->status = Status::TooFewPoints;
    res->reason = "refine_pose: " + std::to_string(st.used) + " usable points at the final pose, need 3";
  }
}

/// LM on the pose over the indices `idx` (or all when idx == nullptr). Accumulates in double.
template <class T>
PoseRefinementResult<T> refine_pose_data(const PnpData<T>& d, const std::uint32_t* idx, std::size_t count,
                                         const Rigid3<T>& initial, const PoseRefinementOptions<T>& o) {
  PoseRefinementResult<T> res;
  res.cam_from_world = initial;
  if (!initial.all_finite()) {
    res.status = Status::NonFinite;
    res.reason = "refine_pose: initial pose is not finite";
    return res;
  }
  const double k = o.huber ? static_cast<double>(o.huber_threshold_px) : 0.0;
  const PoseLmProblem<T> pr{d, idx, count, static_cast<double>(d.fx), static_cast<double>(d.fy), k, k * k};
  PoseLmState st;
  st.R = initial.R.template cast<double>();
  st.t = initial.t.template cast<double>();
  // Gauss-Newton mode skips the initial cost pass; the in-front count is checked in the first pass.
  if (o.check_cost)
    st.cost = pose_lm_cost(pr, st.R, st.t, &st.used, &st.sq);
  else
    st.used = count_in_front_up_to_3(pr, st.R, st.t);
  if (!check_refinement_start(st, &res)) return res;
  double lambda = static_cast<double>(o.initial_damping);
  int it = 0;
  Eigen::Matrix<double, 6, 6> H;
  Eigen::Matrix<double, 6, 1> g;
  for (; it < o.max_iterations; ++it) {
    pose_normal_equations(pr, st.R, st.t, &H, &g);
    // A point whose Jacobian overflows (huge coordinates, z -> 0+) poisons the step: stop at the pose so far.
    if (!H.allFinite() || !g.allFinite()) break;
    H.template triangularView<Eigen::StrictlyLower>() = H.transpose();
    const bool go_on = o.check_cost ? levenberg_marquardt_step(pr, H, g, o, &lambda, &st, &it)
                                    : gauss_newton_step(H, g, o, &st);
    if (!go_on) break;
  }
  if (!o.check_cost) st.cost = pose_lm_cost(pr, st.R, st.t, &st.used, &st.sq);
  finish_refinement(st, it, o, &res);
  return res;
}

// The P3P pieces below have no template parameter: with DYNCULL_PRECOMPILED they are compiled once into
// dyncull::pipeline (src/geometry/pnp.cpp) and only declared here; header-only, they are inline.
DYNCULL_SOLVER void refine_lambdas(double* l, double a12, double a13, double a23, double b12, double b13,
                                   double b23);
DYNCULL_SOLVER bool eig3x3_known0(const Mat3<double>& M, Mat3<double>* E, double* sig1, double* sig2);

#if !defined(DYNCULL_PRECOMPILED) || defined(DYNCULL_PNP_SOURCE)

/// Solves lambda_i^2 + lambda_j^2 - 2 b_ij lambda_i lambda_j = a_ij by Gauss-Newton (the paper's
/// refinement of the depths; 2-3 steps recover the digits the closed forms lose).
DYNCULL_SOLVER void refine_lambdas(double* l, double a12, double a13, double a23, double b12, double b13,
                                   double b23) {
  for (int it = 0; it < 3; ++it) {
    const double r1 = l[0] * l[0] + l[1] * l[1] - 2 * b12 * l[0] * l[1] - a12;
    const double r2 = l[0] * l[0] + l[2] * l[2] - 2 * b13 * l[0] * l[2] - a13;
    const double r3 = l[1] * l[1] + l[2] * l[2] - 2 * b23 * l[1] * l[2] - a23;
    if (std::abs(r1) + std::abs(r2) + std::abs(r3) < 1e-14 * (a12 + a13 + a23)) return;
    Mat3<double> J;
    J << 2 * (l[0] - b12 * l[1]), 2 * (l[1] - b12 * l[0]), 0,  //
        2 * (l[0] - b13 * l[2]), 0, 2 * (l[2] - b13 * l[0]),   //
        0, 2 * (l[1] - b23 * l[2]), 2 * (l[2] - b23 * l[1]);
    const double det = J.determinant();
    if (!(std::abs(det) > 1e-300)) return;
    const Vec3<double> step = J.inverse() * Vec3<double>(r1, r2, r3);
    if (!step.allFinite()) return;
    l[0] -= step(0);
    l[1] -= step(1);
    l[2] -= step(2);
  }
}

/// Eigen-decomposition of a symmetric 3x3 matrix known to be singular (Lambda Twist's eig3x3known0):
/// eigenvalues sig1 (largest |.|), sig2 and 0, eigenvectors in E's columns.
DYNCULL_SOLVER bool eig3x3_known0(const Mat3<double>& M, Mat3<double>* E, double* sig1, double* sig2) {
  const double p1 = -M.trace();
  const double p0 = -M(0, 1) * M(0, 1) - M(0, 2) * M(0, 2) - M(1, 2) * M(1, 2) + M(0, 0) * (M(1, 1) + M(2, 2)) +
                    M(1, 1) * M(2, 2);
  const double disc2 = p1 * p1 / 4.0 - p0;
  const double disc = std::sqrt(std::max(disc2, 0.0));
  double s1 = -p1 / 2.0 + disc, s2 = -p1 / 2.0 - disc;
  if (std::abs(s1) < std::abs(s2)) std::swap(s1, s2);
  for (int k = 0; k < 2; ++k) {
    const double s = k == 0 ? s1 : s2;
    const double c = s * s + M(0, 0) * M(1, 1) - s * (M(0, 0) + M(1, 1)) - M(0, 1) * M(0, 1);
    const double a1 = (s * M(0, 2) + M(0, 1) * M(1, 2) - M(0, 2) * M(1, 1)) / c;
    const double a2 = (s * M(1, 2) + M(0, 1) * M(0, 2) - M(0, 0) * M(1, 2)) / c;
    const double inv = 1.0 / std::sqrt(1.0 + a1 * a1 + a2 * a2);
    E->col(k) = Vec3<double>(a1 * inv, a2 * inv, inv);
  }
  E->col(2) = M.col(1).cross(M.col(2)).normalized();
  *sig1 = s1;
  *sig2 = s2;
  return E->allFinite() && std::isfinite(s1) && std::isfinite(s2);
}

/// Squared world-side lengths a_ij and bearing cosines b_ij of the P3P triangle (the paper's notation).
struct P3pTriangle {
  double a12, a13, a23, b12, b13, b23;
};

/// A real root gamma of det(D1 + gamma D2) = 0 (eq. 9): one root of the monic cubic in closed form (Lambda
/// Twist needs any real root), then two Newton steps. False for a degenerate cubic or a non-finite root.
DYNCULL_SOLVER bool p3p_gamma(const Mat3<double>& D1, const Mat3<double>& D2, double* gamma_out) {
  Mat3<double> A1, A2;  // adjugates (transposed cofactors) by columns
  A1 << D1.col(1).cross(D1.col(2)), D1.col(2).cross(D1.col(0)), D1.col(0).cross(D1.col(1));
  A2 << D2.col(1).cross(D2.col(2)), D2.col(2).cross(D2.col(0)), D2.col(0).cross(D2.col(1));
  const double c3 = D2.col(0).dot(A2.col(0));
  if (!(std::abs(c3) > 1e-300) || !std::isfinite(c3)) return false;
  const double c2 = (D1.array() * A2.array()).sum() / c3;
  const double c1 = (D2.array() * A1.array()).sum() / c3;
  const double c0 = D1.col(0).dot(A1.col(0)) / c3;

  const double p = c1 - c2 * c2 / 3.0;
  const double q = (2.0 * c2 * c2 * c2 - 9.0 * c2 * c1) / 27.0 + c0;
  const double disc = q * q / 4.0 + p * p * p / 27.0;
  double gamma;
  if (disc > 0) {
    const double sd = std::sqrt(disc);
    gamma = std::cbrt(-q / 2.0 + sd) + std::cbrt(-q / 2.0 - sd) - c2 / 3.0;
  } else {
    const double arg = std::max(-1.0, std::min(1.0, 3.0 * q / (2.0 * p) * std::sqrt(-3.0 / p)));
    gamma = 2.0 * std::sqrt(-p / 3.0) * std::cos(std::acos(arg) / 3.0) - c2 / 3.0;
  }
  for (int it = 0; it < 2; ++it) {
    const double f = ((gamma + c2) * gamma + c1) * gamma + c0;
    const double df = (3.0 * gamma + 2.0 * c2) * gamma + c1;
    if (std::abs(df) > 1e-300) gamma -= f / df;
  }
  *gamma_out = gamma;
  return std::isfinite(gamma);
}

/// The poses whose depths lie on the plane lambda1 = w0 lambda2 + w1 lambda3 (eq. 13): the roots tau =
/// lambda3 / lambda2 of its quadratic, the depths refined, each pose from the world and camera triangles
/// (XX_inv: the world triangle's frame inverted); appended to out while *count < 4.
DYNCULL_SOLVER void p3p_poses_on_plane(const P3pTriangle& tri, double w0, double w1, const Vec3<double> bearings[3],
                                       const Vec3<double>& world0, const Mat3<double>& XX_inv, Rigid3<double> out[4],
                                       int* count) {
  const double a12 = tri.a12, a13 = tri.a13, a23 = tri.a23, b12 = tri.b12, b13 = tri.b13, b23 = tri.b23;
  const Vec3<double>& x0 = bearings[0];
  const Vec3<double>& x1 = bearings[1];
  const Vec3<double>& x2 = bearings[2];
  const double a = (a13 - a12) * w1 * w1 + 2.0 * a12 * b13 * w1 - a12;
  const double b = -2.0 * a13 * b12 * w1 + 2.0 * a12 * b13 * w0 - 2.0 * w0 * w1 * (a12 - a13);
  const double c = (a13 - a12) * w0 * w0 - 2.0 * a13 * b12 * w0 + a13;
  const double b2m4ac = b * b - 4.0 * a * c;
  if (!(b2m4ac > 0) || !std::isfinite(b2m4ac)) return;
  const double sq = std::sqrt(b2m4ac);
  double taus[2];
  taus[0] = (b > 0) ? (2.0 * c) / (-b - sq) : (2.0 * c) / (-b + sq);  // stable quadratic roots
  taus[1] = c / (a * taus[0]);
  for (double tau : taus) {
    if (!(tau > 0) || !std::isfinite(tau)) continue;
    const double den2 = tau * (tau - 2.0 * b23) + 1.0;
    if (!(den2 > 0)) continue;
    double l[3];
    l[1] = std::sqrt(a23 / den2);
    l[2] = tau * l[1];
    l[0] = w0 * l[1] + w1 * l[2];
    if (!(l[0] > 0)) continue;
    refine_lambdas(l, a12, a13, a23, b12, b13, b23);
    const Vec3<double> v1 = l[0] * x0 - l[1] * x1;
    const Vec3<double> v2 = l[0] * x0 - l[2] * x2;
    Mat3<double> YY;
    YY << v1, v2, v1.cross(v2);
    Rigid3<double> pose;
    pose.R = YY * XX_inv;
    pose.t = l[0] * x0 - pose.R * world0;
    if (!pose.all_finite() || *count >= 4) continue;
    out[(*count)++] = pose;
  }
}

#endif  // solver definitions

}  // namespace detail

#if !defined(DYNCULL_PRECOMPILED) || defined(DYNCULL_PNP_SOURCE)
DYNCULL_SOLVER int solve_p3p(const Vec3<double> bearings[3], const Vec3<double> world[3], Rigid3<double> out[4]) {
  const Vec3<double>& x0 = bearings[0];
  const Vec3<double>& x1 = bearings[1];
  const Vec3<double>& x2 = bearings[2];
  const Vec3<double> d12 = world[0] - world[1];
  const Vec3<double> d13 = world[0] - world[2];
  const Vec3<double> d23 = world[1] - world[2];
  const double a12 = d12.squaredNorm(), a13 = d13.squaredNorm(), a23 = d23.squaredNorm();
  const double b12 = x0.dot(x1), b13 = x0.dot(x2), b23 = x1.dot(x2);

  // The two quadrics D1, D2 of the paper (eq. 6); gamma is a root of det(D1 + gamma D2) = 0 (eq. 9).
  Mat3<double> D1, D2;
  D1 << a23, -a23 * b12, 0.0, -a23 * b12, a23 - a12, a12 * b23, 0.0, a12 * b23, -a12;
  D2 << a23, 0.0, -a23 * b13, 0.0, -a13, a13 * b23, -a23 * b13, a13 * b23, a23 - a13;
  double gamma = 0;
  if (!detail::p3p_gamma(D1, D2, &gamma)) return 0;

  const Mat3<double> D0 = D1 + gamma * D2;
  Mat3<double> E;
  double sig1 = 0, sig2 = 0;
  if (!detail::eig3x3_known0(D0, &E, &sig1, &sig2)) return 0;
  const double ratio = -sig2 / sig1;
  if (!(ratio >= 0)) return 0;
  const double s = std::sqrt(ratio);

  Mat3<double> XX;
  XX << d12, d13, d12.cross(d13);
  const double det_xx = XX.determinant();
  // Collinear world points: the triangle spans no plane and the pose is not determined.
  if (!(std::abs(det_xx) > 1e-12 * std::pow(std::max(a12, a13), 2))) return 0;
  const Mat3<double> XX_inv = XX.inverse();

  const detail::P3pTriangle tri{a12, a13, a23, b12, b13, b23};
  int count = 0;
  for (int sign = -1; sign <= 1; sign += 2) {
    // lambda1 = w0 lambda2 + w1 lambda3 on each of the two planes through the degenerate conic (eq. 13).
    const double ss = sign * s;
    const double den = ss * E(0, 1) - E(0, 0);
    const double w0 = (E(1, 0) - ss * E(1, 1)) / den;
    const double w1 = (E(2, 0) - ss * E(2, 1)) / den;
    detail::p3p_poses_on_plane(tri, w0, w1, bearings, world[0], XX_inv, out, &count);
  }
  return count;
}

#endif  // solver definitions

namespace detail {

/// RANSAC estimator over PnpData (contract #1): P3P minimal solver, LM refit on inliers.
template <class T>
class PnpEstimator {
 public:
  using Model = Rigid3<T>;
  using Scalar = T;
  static constexpr int kSampleSize = 3;
  static constexpr int kMaxModels = 4;

  explicit PnpEstimator(const PnpData<T>& data) : d_(data) {
    refit_options_.max_iterations = 2;  // LO refits start from a good pose: two GN steps converge
    refit_options_.check_cost = false;
  }
  std::size_t num_data() const { return d_.size(); }

  bool is_sample_good(const std::uint32_t* s) const {
    const Vec3<double> a = world(s[0]), b = world(s[1]), c = world(s[2]);
    const Vec3<double> ab = b - a, ac = c - a;
    // Reject (near-)collinear or duplicate world points: relative triangle area below 1e-6.
    return ab.cross(ac).squaredNorm() > 1e-12 * ab.squaredNorm() * ac.squaredNorm() && ab.squaredNorm() > 0 &&
           ac.squaredNorm() > 0;
  }

  int minimal_solve(const std::uint32_t* s, Model* models) const {
    Vec3<double> bearings[3], pts[3];
    for (int k = 0; k < 3; ++k) {
      bearings[k] = Vec3<double>(static_cast<double>(d_.x[s[k]]), static_cast<double>(d_.y[s[k]]), 1.0).normalized();
      pts[k] = world(s[k]);
    }
    Rigid3<double> poses[4];
    const int m = solve_p3p(bearings, pts, poses);
    for (int k = 0; k < m; ++k) models[k] = poses[k].template cast<T>();
    return m;
  }

  void residuals_sq(const Model& m, T* out) const { pnp_residuals_sq(d_, m, 0, d_.size(), out); }
  void residuals_sq(const Model& m, std::size_t begin, std::size_t end, T* out) const {
    pnp_residuals_sq(d_, m, begin, end, out);
  }

  bool refit(const std::uint32_t* inliers, std::size_t n, Model* model) const {
    if (n < 3) return false;
    const auto r = refine_pose_data(d_, inliers, n, *model, refit_options_);
    if (!r.ok()) return false;
    *model = r.cam_from_world;
    return true;
  }

 private:
  Vec3<double> world(std::uint32_t i) const {
    return Vec3<double>(static_cast<double>(d_.X[i]), static_cast<double>(d_.Y[i]), static_cast<double>(d_.Z[i]));
  }
  const PnpData<T>& d_;
  PoseRefinementOptions<T> refit_options_;
};

template <class T, class Points3, class Points2>
bool check_pnp_inputs(const Points3& world, const Points2& pixels, const PinholeCamera<T>& camera, Status* status,
                      std::string* reason) {
  static_assert(is_point_container_v<Points3> && PointTraits<container_point_t<Points3>>::dim == 3,
                "dyncull PnP: world must be a container of 3-D points");
  static_assert(is_point_container_v<Points2>, "dyncull PnP: pixels must be a container of 2-D points");
  if (static_cast<std::size_t>(world.size()) != static_cast<std::size_t>(pixels.size())) {
    *status = Status::InvalidInput;
    *reason = "PnP: " + std::to_string(world.size()) + " world points but " + std::to_string(pixels.size()) +
              " pixels";
    return false;
  }
  if (!camera.valid()) {
    *status = Status::InvalidInput;
    *reason = "PnP: invalid camera intrinsics";
    return false;
  }
  return true;
}

/// An Ok result must carry a finite pose: closed forms on wild but finite data (huge or subnormal
/// coordinates) can still produce NaN. Degenerate then, with an empty mask.
template <class T>
void require_finite_pose(const char* who, std::size_t n_total, PnpResult<T>* res) {
  if (!res->ok() || res->cam_from_world.all_finite()) return;
  res->status = Status::Degenerate;
  res->reason = std::string(who) + ": the solver produced a non-finite pose (coordinates too large or too small)";
  res->inlier_mask.assign(n_total, 0);
  res->num_inliers = 0;
  res->rmse_px = 0;
}

/// Relabels `res` at its pose: inlier mask (caller order), count and inlier RMSE. `residuals`: scratch.
template <class T>
void label_pnp(const PnpData<T>& d, std::size_t n_total, double max_residual, std::vector<T>* residuals,
               PnpResult<T>* res) {
  std::vector<T>& r = *residuals;
  r.resize(d.size());
  pnp_residuals_sq(d, res->cam_from_world, 0, d.size(), r.data());
  res->inlier_mask.assign(n_total, 0);
  const T thr = static_cast<T>(max_residual * max_residual);
  double sum = 0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < d.size(); ++i) {
    if (r[i] < thr) {
      res->inlier_mask[d.index[i]] = 1;
      sum += static_cast<double>(r[i]);
      ++count;
    }
  }
  res->num_inliers = count;
  res->rmse_px = count > 0 ? std::sqrt(sum / static_cast<double>(count)) : 0.0;
}

template <class T>
void label_pnp(const PnpData<T>& d, std::size_t n_total, double max_residual, PnpResult<T>* res) {
  std::vector<T> residuals;
  label_pnp(d, n_total, max_residual, &residuals, res);
}

/// Best P3P pose on a spread-out triple, scored by the robust cost over all points.
template <class T>
bool pnp_from_spread_triple(const PnpData<T>& d, double max_residual, Rigid3<T>* best) {
  const std::size_t n = d.size();
  Vec3<double> c = Vec3<double>::Zero();
  for (std::size_t i = 0; i < n; ++i) c += Vec3<double>(d.X[i], d.Y[i], d.Z[i]);
  c /= static_cast<double>(n);
  auto P = [&](std::size_t i) { return Vec3<double>(d.X[i], d.Y[i], d.Z[i]); };
  std::size_t i0 = 0, i1 = 0, i2 = 0;
  double best_d = -1;
  for (std::size_t i = 0; i < n; ++i)
    if ((P(i) - c).squaredNorm() > best_d) best_d = (P(i) - c).squaredNorm(), i0 = i;
  best_d = -1;
  for (std::size_t i = 0; i < n; ++i)
    if ((P(i) - P(i0)).squaredNorm() > best_d) best_d = (P(i) - P(i0)).squaredNorm(), i1 = i;
  best_d = -1;
  for (std::size_t i = 0; i < n; ++i) {
    const double area = (P(i1) - P(i0)).cross(P(i) - P(i0)).squaredNorm();
    if (area > best_d) best_d = area, i2 = i;
  }
  const std::uint32_t sample[3] = {static_cast<std::uint32_t>(i0), static_cast<std::uint32_t>(i1),
                                   static_cast<std::uint32_t>(i2)};
  PnpEstimator<T> est(d);
  if (!est.is_sample_good(sample)) return false;
  Rigid3<T> models[4];
  const int m = est.minimal_solve(sample, models);
  std::vector<T> r(n);
  const T thr = static_cast<T>(max_residual * max_residual);
  double best_cost = std::numeric_limits<double>::infinity();
  for (int k = 0; k < m; ++k) {
    est.residuals_sq(models[k], r.data());
    double cost = 0;
    for (std::size_t i = 0; i < n; ++i) cost += static_cast<double>(std::min(r[i], thr));
    if (cost < best_cost) best_cost = cost, *best = models[k];
  }
  return m > 0;
}

/// DLT on PnpData (normalised): 2n x 12 system accumulated as 12x12 normal matrix.
template <class T>
Status pnp_dlt_data(const PnpData<T>& d, Rigid3<T>* out, std::string* reason) {
  const std::size_t n = d.size();
  if (n < 6) {
    *reason = "DLT PnP needs 6 points, got " + std::to_string(n);
    return Status::TooFewPoints;
  }
  Vec3<double> mean = Vec3<double>::Zero();
  for (std::size_t i = 0; i < n; ++i) mean += Vec3<double>(d.X[i], d.Y[i], d.Z[i]);
  mean /= static_cast<double>(n);
  Mat3<double> cov = Mat3<double>::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3<double> q = Vec3<double>(d.X[i], d.Y[i], d.Z[i]) - mean;
    cov.noalias() += q * q.transpose();
  }
  SymmetricEigen<3> es;
  if (!symmetric_eigen(cov, &es)) {
    *reason = "DLT PnP: eigen-decomposition of the world points' covariance failed";
    return Status::NotConverged;
  }
  const Vec3<double> ev = es.values;  // ascending
  // Coplanar points leave a 3-dimensional null space in the DLT: thickness below 1 % of the extent.
  if (!(ev(2) > 0) || ev(0) < 1e-4 * ev(2)) {
    *reason = "DLT PnP: world points are (nearly) coplanar";
    return Status::Degenerate;
  }
  const double scale = std::sqrt(ev.sum() / static_cast<double>(3));
  const double inv_scale = 1.0 / scale;
  Eigen::Matrix<double, 12, 12> AtA = Eigen::Matrix<double, 12, 12>::Zero();
  Eigen::Matrix<double, 12, 1> r1, r2;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3<double> q = (Vec3<double>(d.X[i], d.Y[i], d.Z[i]) - mean) * inv_scale;
    const double x = d.x[i], y = d.y[i];
    // Rows of P (row-major 3x4): x (P3 . Xh) - P1 . Xh = 0, y (P3 . Xh) - P2 . Xh = 0.
    r1 << -q(0), -q(1), -q(2), -1, 0, 0, 0, 0, x * q(0), x * q(1), x * q(2), x;
    r2 << 0, 0, 0, 0, -q(0), -q(1), -q(2), -1, y * q(0), y * q(1), y * q(2), y;
    AtA.selfadjointView<Eigen::Lower>().rankUpdate(r1);
    AtA.selfadjointView<Eigen::Lower>().rankUpdate(r2);
  }
  AtA.triangularView<Eigen::StrictlyUpper>() = AtA.transpose();
  SymmetricEigen<12> es12;
  if (!symmetric_eigen(AtA, &es12)) {
    *reason = "DLT PnP: eigen-decomposition of the normal matrix failed";
    return Status::NotConverged;
  }
  const Eigen::Matrix<double, 12, 1> p = es12.vectors.col(0);
  Eigen::Matrix<double, 3, 4> P;
  P << p.segment<4>(0).transpose(), p.segment<4>(4).transpose(), p.segment<4>(8).transpose();
  Mat3<double> M = P.leftCols<3>();
  if (M.determinant() < 0) {
    P = -P;
    M = -M;
  }
  Eigen::JacobiSVD<Mat3<double>> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const double sigma = svd.singularValues().mean();
  if (!(sigma > 0) || !std::isfinite(sigma)) {
    *reason = "DLT PnP: degenerate projection matrix";
    return Status::Degenerate;
  }
  const Mat3<double> R = svd.matrixU() * svd.matrixV().transpose();
  // P ~ [R | (R mean + t) / scale]: undo the world normalisation.
  const Vec3<double> t = scale * P.col(3) / sigma - R * mean;
  out->R = R.cast<T>();
  out->t = t.cast<T>();
  if (!out->all_finite()) {
    *reason = "DLT PnP: non-finite pose";
    return Status::NonFinite;
  }
  return Status::Ok;
}

}  // namespace detail

template <class T>
struct PnpWorkspace {
  detail::PnpData<T> data;
  RansacWorkspace<T> ransac;
  RansacResult<Rigid3<T>> ransac_result;
  std::vector<std::uint32_t> inliers;  // the data the final refinement takes
  std::vector<T> residuals;            // the final labelling's
};

template <class T, class Points3, class Points2>
PnpResult<T> solve_pnp_dlt(const Points3& world, const Points2& pixels, const PinholeCamera<T>& camera) {
  PnpResult<T> res;
  if (!detail::check_pnp_inputs(world, pixels, camera, &res.status, &res.reason)) return res;
  detail::PnpData<T> d;
  detail::load_pnp_data(world, pixels, camera, &d);
  res.status = detail::pnp_dlt_data(d, &res.cam_from_world, &res.reason);
  detail::require_finite_pose("solve_pnp_dlt", static_cast<std::size_t>(world.size()), &res);
  if (res.ok()) detail::label_pnp(d, static_cast<std::size_t>(world.size()), PnpOptions<T>{}.ransac.max_residual, &res);
  return res;
}

template <class T, class Points3, class Points2>
PoseRefinementResult<T> refine_pose(const Points3& world, const Points2& pixels, const PinholeCamera<T>& camera,
                                    const Rigid3<T>& initial_cam_from_world, const PoseRefinementOptions<T>& options,
                                    FlagView mask) {
  PoseRefinementResult<T> res;
  res.cam_from_world = initial_cam_from_world;
  if (!detail::check_pnp_inputs(world, pixels, camera, &res.status, &res.reason)) return res;
  {
    std::string why;
    if (!detail::flags_fit(mask, static_cast<std::size_t>(world.size()), "mask", "correspondences", &why)) {
      res.status = Status::InvalidInput;
      res.reason = "refine_pose: " + why;
      return res;
    }
    if (options.validate(&why) != Status::Ok) {
      res.status = Status::InvalidInput;
      res.reason = "refine_pose: " + why;
      return res;
    }
  }
  detail::PnpData<T> d;
  detail::load_pnp_data(world, pixels, camera, &d);
  std::vector<std::uint32_t> idx;
  if (mask.given) {
    idx.reserve(d.size());
    for (std::size_t i = 0; i < d.size(); ++i)
      if (mask[d.index[i]]) idx.push_back(static_cast<std::uint32_t>(i));
    return detail::refine_pose_data(d, idx.data(), idx.size(), initial_cam_from_world, options);
  }
  return detail::refine_pose_data<T>(d, nullptr, d.size(), initial_cam_from_world, options);
}

template <class T, class Points3, class Points2>
PnpResult<T> solve_pnp(const Points3& world, const Points2& pixels, const PinholeCamera<T>& camera,
                       const PnpOptions<T>& options) {
  PnpResult<T> res;
  if (!detail::check_pnp_inputs(world, pixels, camera, &res.status, &res.reason)) return res;
  if (options.validate(&res.reason) != Status::Ok) {
    res.status = Status::InvalidInput;
    res.reason = "solve_pnp: " + res.reason;
    res.inlier_mask.assign(static_cast<std::size_t>(world.size()), 0);
    return res;
  }
  detail::PnpData<T> d;
  const std::size_t skipped = detail::load_pnp_data(world, pixels, camera, &d);
  const std::size_t n_total = static_cast<std::size_t>(world.size());
  if (d.size() < 4) {
    res.status = skipped > 0 && d.size() + skipped >= 4 ? Status::NonFinite : Status::TooFewPoints;
    res.reason = "solve_pnp: " + std::to_string(d.size()) + " finite correspondences, need 4 (P3P + one check)";
    res.inlier_mask.assign(n_total, 0);
    return res;
  }
  std::string why;
  if (detail::pnp_dlt_data(d, &res.cam_from_world, &why) != Status::Ok &&
      !detail::pnp_from_spread_triple(d, options.ransac.max_residual, &res.cam_from_world)) {
    res.status = Status::Degenerate;
    res.reason = "solve_pnp: " + why + "; P3P fallback found no pose (collinear points?)";
    res.inlier_mask.assign(n_total, 0);
    return res;
  }
  if (options.refine) {
    const auto r = detail::refine_pose_data<T>(d, nullptr, d.size(), res.cam_from_world, options.refinement);
    if (r.ok()) res.cam_from_world = r.cam_from_world;
  }
  detail::require_finite_pose("solve_pnp", n_total, &res);
  if (res.ok()) detail::label_pnp(d, n_total, options.ransac.max_residual, &res);
  return res;
}

template <class T, class Points3, class Points2>
void solve_pnp_ransac(const Points3& world, const Points2& pixels, const PinholeCamera<T>& camera,
                      const PnpOptions<T>& options, PnpWorkspace<T>* workspace, PnpResult<T>* out) {
  PnpResult<T>& res = *out;
  res.status = Status::Ok;
  res.reason.clear();
  res.cam_from_world = Rigid3<T>();
  res.inlier_mask.clear();
  res.num_inliers = res.iterations = 0;
  res.rmse_px = 0;
  if (!detail::check_pnp_inputs(world, pixels, camera, &res.status, &res.reason)) return;
  if (options.validate(&res.reason) != Status::Ok) {
    res.status = Status::InvalidInput;
    res.reason = "solve_pnp_ransac: " + res.reason;
    res.inlier_mask.assign(static_cast<std::size_t>(world.size()), 0);
    return;
  }
  const std::size_t n_total = static_cast<std::size_t>(world.size());
  detail::PnpData<T>& d = workspace->data;
  const std::size_t skipped = detail::load_pnp_data(world, pixels, camera, &d);
  if (d.size() < 4) {
    res.status = skipped > 0 && d.size() + skipped >= 4 ? Status::NonFinite : Status::TooFewPoints;
    res.reason = "solve_pnp_ransac: " + std::to_string(d.size()) + " finite correspondences, need at least 4";
    res.inlier_mask.assign(n_total, 0);
    return;
  }
  detail::PnpEstimator<T> est(d);
  RansacResult<Rigid3<T>>& rr = workspace->ransac_result;
  ransac(est, options.ransac, &workspace->ransac, &rr);
  res.iterations = rr.iterations;
  if (!rr.ok()) {
    res.status = rr.status;
    res.reason = "solve_pnp_ransac: " + rr.reason;
    res.inlier_mask.assign(n_total, 0);
    return;
  }
  res.cam_from_world = rr.model;
  if (options.refine) {
    std::vector<std::uint32_t>& idx = workspace->inliers;
    idx.clear();
    for (std::size_t i = 0; i < d.size(); ++i)
      if (rr.inlier_mask[i]) idx.push_back(static_cast<std::uint32_t>(i));
    const auto r = detail::refine_pose_data(d, idx.data(), idx.size(), rr.model, options.refinement);
    if (r.ok()) res.cam_from_world = r.cam_from_world;
  }
  detail::require_finite_pose("solve_pnp_ransac", n_total, &res);
  if (!res.ok()) return;
  detail::label_pnp(d, n_total, options.ransac.max_residual, &workspace->residuals, &res);
  if (res.num_inliers < 4) {
    res.status = Status::Degenerate;
    res.reason = "solve_pnp_ransac: only " + std::to_string(res.num_inliers) + " inliers at the best pose";
  }
}

template <class T, class Points3, class Points2>
PnpResult<T> solve_pnp_ransac(const Points3& world, const Points2& pixels, const PinholeCamera<T>& camera,
                              const PnpOptions<T>& options) {
  PnpWorkspace<T> workspace;
  PnpResult<T> res;
  solve_pnp_ransac(world, pixels, camera, options, &workspace, &res);
  return res;
}

#if defined(DYNCULL_PRECOMPILED)
// Compiled once into dyncull::pipeline (src/geometry/pnp.cpp) for the pipeline's point containers.
extern template PnpResult<float> solve_pnp_ransac(const std::vector<Vec3<float>>&, const std::vector<Vec2<float>>&,
                                                  const PinholeCamera<float>&, const PnpOptions<float>&);
extern template PnpResult<double> solve_pnp_ransac(const std::vector<Vec3<double>>&,
                                                   const std::vector<Vec2<double>>&, const PinholeCamera<double>&,
                                                   const PnpOptions<double>&);
extern template void solve_pnp_ransac(const std::vector<Vec3<float>>&, const std::vector<Vec2<float>>&,
                                      const PinholeCamera<float>&, const PnpOptions<float>&, PnpWorkspace<float>*,
                                      PnpResult<float>*);
extern template void solve_pnp_ransac(const std::vector<Vec3<double>>&, const std::vector<Vec2<double>>&,
                                      const PinholeCamera<double>&, const PnpOptions<double>&,
                                      PnpWorkspace<double>*, PnpResult<double>*);
#endif

}  // namespace dyncull
