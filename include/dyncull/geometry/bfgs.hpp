/// @file bfgs.hpp
/// Small fixed-size BFGS minimiser (Nocedal & Wright Alg. 6.1) with an Armijo backtracking line search
/// that interpolates and extrapolates; the inverse-Hessian update is eq. 10-14 of DFD-SLAM (Qian et al. 2024).
#pragma once

#include "dyncull/core/status.hpp"
#include "dyncull/core/types.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>

namespace dyncull {

/// Stopping rules and line-search constants. Tolerances below the scalar's precision are raised to
/// a few machine epsilons, so float problems stop instead of running to the iteration limit.
struct BfgsOptions {
  int max_iterations = 100;           ///< BFGS iterations (one line search each)
  double gradient_tolerance = 1e-10;  ///< stop when max_i |g_i| <= this (absolute, objective units per x unit)
  double function_tolerance = 1e-12;  ///< stop when |f_k - f_k+1| <= this * max(|f_k|, tiny)
  double parameter_tolerance = 1e-12; ///< stop when |s| <= this * (|x| + this)
  double armijo_c1 = 1e-4;            ///< sufficient-decrease constant of the Armijo condition
  double wolfe_c2 = 0.9;              ///< curvature constant: extrapolate while g_new.p < c2 g.p
  int max_line_search_steps = 30;     ///< function evaluations per line search

  static constexpr int kMaxIterations = 100000;       ///< upper bound of max_iterations
  static constexpr int kMaxLineSearchSteps = 1000;    ///< upper bound of max_line_search_steps

  /// Ok, or InvalidInput with a reason naming the field.
  Status validate(std::string* reason = nullptr) const {
    auto bad = [&](const char* why) {
      if (reason) *reason = why;
      return Status::InvalidInput;
    };
    if (max_iterations < 0 || max_iterations > kMaxIterations)
      return bad("BfgsOptions: max_iterations must be in [0, 100000]");
    if (max_line_search_steps < 1 || max_line_search_steps > kMaxLineSearchSteps)
      return bad("BfgsOptions: max_line_search_steps must be in [1, 1000]");
    if (!(gradient_tolerance >= 0.0) || !std::isfinite(gradient_tolerance))
      return bad("BfgsOptions: gradient_tolerance must be finite and >= 0");
    if (!(function_tolerance >= 0.0) || !std::isfinite(function_tolerance))
      return bad("BfgsOptions: function_tolerance must be finite and >= 0");
    if (!(parameter_tolerance >= 0.0) || !std::isfinite(parameter_tolerance))
      return bad("BfgsOptions: parameter_tolerance must be finite and >= 0");
    if (!(armijo_c1 > 0.0)) return bad("BfgsOptions: armijo_c1 must be > 0");
    if (!(wolfe_c2 > armijo_c1) || !(wolfe_c2 < 1.0)) return bad("BfgsOptions: wolfe_c2 must be in (armijo_c1, 1)");
    if (reason) reason->clear();
    return Status::Ok;
  }
};

/// Outcome of bfgs_minimize. status: Ok (a tolerance was met), NotConverged (iteration limit or a
/// line search that found no decrease while the gradient is not small), NonFinite (x0 or f(x0) not
/// finite), InvalidInput (bad options).
template <class T, int N>
struct BfgsResult {
  using Vector = Eigen::Matrix<T, N, 1>;
  Status status = Status::Ok;
  std::string reason;
  Vector x = Vector::Zero();         ///< best point found (always the last accepted iterate)
  T value = T(0);                    ///< f(x)
  Vector gradient = Vector::Zero();  ///< gradient at x
  int iterations = 0;                ///< accepted BFGS steps
  int evaluations = 0;               ///< objective + gradient evaluations, line searches included
  bool ok() const { return status == Status::Ok; }
};

/// Minimises f from x0. The functor is called as `T value = f(x, &gradient)` with
/// x, gradient of type Eigen::Matrix<T, N, 1>; it must write the full gradient. A non-finite value is
/// treated as "too far": the line search backs off. No allocation: everything is fixed-size.
template <class T, int N, class Functor>
BfgsResult<T, N> bfgs_minimize(const Functor& f, const Eigen::Matrix<T, N, 1>& x0, const BfgsOptions& options = {});

// ------------------------------------------------------------------------------------------------
// Implementation
// ------------------------------------------------------------------------------------------------

namespace detail {

/// Whether f is callable as `T f(const Vector& x, Vector* gradient) const`.
template <class Functor, class T, int N>
constexpr bool is_bfgs_objective =
    std::is_convertible<decltype(std::declval<const Functor&>()(std::declval<const Eigen::Matrix<T, N, 1>&>(),
                                                                std::declval<Eigen::Matrix<T, N, 1>*>())),
                        T>::value;

/// BfgsOptions in the scalar, with tolerances no tighter than it allows (float would otherwise never
/// meet 1e-12).
template <class T>
struct BfgsConstants {
  T eps, gtol, ftol, xtol, c1, c2;
  int max_line_search_steps;
  explicit BfgsConstants(const BfgsOptions& options)
      : eps(std::numeric_limits<T>::epsilon()),
        gtol(static_cast<T>(options.gradient_tolerance)),
        ftol(std::max(static_cast<T>(options.function_tolerance), T(4) * eps)),
        xtol(std::max(static_cast<T>(options.parameter_tolerance), T(4) * eps)),
        c1(static_cast<T>(options.armijo_c1)),
        c2(static_cast<T>(options.wolfe_c2)),
        max_line_search_steps(options.max_line_search_steps) {}
};

/// The line search's accepted point (x_new, g_new, f_new), fixed-size and reused by every iteration.
template <class T, int N>
struct BfgsLineSearch {
  using Vector = Eigen::Matrix<T, N, 1>;
  Vector x_new, g_new;
  T f_new = T(0);
  int steps = 0;  ///< evaluations of this line search
};

/// The point the line search evaluates f at (x) and its gradient (g).
template <class T, int N>
struct BfgsTrial {
  Eigen::Matrix<T, N, 1> x, g;
};

/// False, with the status and reason in `result`, when the options are invalid or x0 is not finite.
template <class T, int N>
bool bfgs_check_start(const BfgsOptions& options, const Eigen::Matrix<T, N, 1>& x0, BfgsResult<T, N>* result) {
  std::string why;
  if (options.validate(&why) != Status::Ok) {
    result->status = Status::InvalidInput;
    result->reason = "bfgs: " + why;
    return false;
  }
  if (!x0.allFinite()) {
    result->status = Status::NonFinite;
    result->reason = "bfgs: non-finite starting point";
    return false;
  }
  return true;
}

/// False, with NonFinite, f(x0) and its gradient in `result`, when either is not finite.
template <class T, int N>
bool bfgs_start_finite(T fx, const Eigen::Matrix<T, N, 1>& g, BfgsResult<T, N>* result) {
  if (std::isfinite(fx) && g.allFinite()) return true;
  result->status = Status::NonFinite;
  result->reason = "bfgs: objective or gradient not finite at the starting point";
  result->value = fx;
  result->gradient = g;
  return false;
}

/// When round-off has cost H its positive definiteness (p = -H g is no descent direction): restart from
/// the identity, p as steepest descent, with its slope dphi0.
template <class T, int N>
void restart_as_steepest_descent(const Eigen::Matrix<T, N, 1>& g, Eigen::Matrix<T, N, N>* H, bool* scaled,
                                 Eigen::Matrix<T, N, 1>* p, T* dphi0) {
  H->setIdentity();
  *scaled = false;
  *p = -g;
  *dphi0 = -g.squaredNorm();
}

/// After an Armijo point at step alpha: while the slope is still steep (curvature condition fails),
/// extrapolate with the secant of phi' (exact for quadratics), keeping the better of the two points.
template <class T, int N, class Functor>
void bfgs_extrapolate(const Functor& f, const Eigen::Matrix<T, N, 1>& x, T fx, const Eigen::Matrix<T, N, 1>& p,
                      T dphi0, T alpha, const BfgsConstants<T>& c, BfgsTrial<T, N>* trial, BfgsLineSearch<T, N>* ls,
                      int* evaluations) {
  using std::isfinite;
  T dphi = ls->g_new.dot(p);
  while (dphi < c.c2 * dphi0 && ls->steps < c.max_line_search_steps) {
    const T curvature = dphi - dphi0;
    const T next = curvature > T(0) ? alpha * dphi0 / (dphi0 - dphi) : T(4) * alpha;
    const T alpha_ext = std::min(next, T(100) * alpha);
    if (!(alpha_ext > alpha)) break;
    trial->x = x + alpha_ext * p;
    const T f_ext = f(trial->x, &trial->g);
    ++ls->steps;
    ++*evaluations;
    if (!isfinite(f_ext) || !trial->g.allFinite() || f_ext > fx + c.c1 * alpha_ext * dphi0 || f_ext >= ls->f_new)
      break;
    alpha = alpha_ext;
    ls->x_new = trial->x;
    ls->g_new = trial->g;
    ls->f_new = f_ext;
    dphi = ls->g_new.dot(p);
  }
}

/// Armijo backtracking along p from step alpha, then extrapolation; true with the accepted point in `ls`,
/// false when no step within max_line_search_steps decreases f enough.
template <class T, int N, class Functor>
bool bfgs_line_search(const Functor& f, const Eigen::Matrix<T, N, 1>& x, T fx, const Eigen::Matrix<T, N, 1>& p,
                      T dphi0, T alpha, const BfgsConstants<T>& c, BfgsTrial<T, N>* trial, BfgsLineSearch<T, N>* ls,
                      int* evaluations) {
  using std::isfinite;
  ls->f_new = fx;
  ls->steps = 0;
  while (ls->steps < c.max_line_search_steps) {
    trial->x = x + alpha * p;
    const T f_try = f(trial->x, &trial->g);
    ++ls->steps;
    ++*evaluations;
    if (!isfinite(f_try) || !trial->g.allFinite()) {
      alpha *= T(0.25);
      continue;
    }
    if (f_try > fx + c.c1 * alpha * dphi0) {
      // Armijo fails: minimise the quadratic through phi(0), phi'(0), phi(alpha), kept in [0.1, 0.5] alpha.
      const T denom = T(2) * (f_try - fx - dphi0 * alpha);
      T next = denom > T(0) ? -dphi0 * alpha * alpha / denom : T(0.5) * alpha;
      alpha = std::min(std::max(next, T(0.1) * alpha), T(0.5) * alpha);
      continue;
    }
    ls->x_new = trial->x;
    ls->g_new = trial->g;
    ls->f_new = f_try;
    bfgs_extrapolate(f, x, fx, p, dphi0, alpha, c, trial, ls, evaluations);
    return true;
  }
  return false;
}

/// After a line search found no decrease along a descent direction, f is at its round-off floor: that is
/// convergence (Ok) only if the gradient is tiny compared with the objective's scale; otherwise
/// NotConverged, with the reason.
template <class T, int N>
Status no_decrease_status(const Eigen::Matrix<T, N, 1>& g, T fx, T eps, std::string* reason) {
  const T g_inf = g.template lpNorm<Eigen::Infinity>();
  if (g_inf <= std::sqrt(eps) * std::max(T(1), std::abs(fx))) return Status::Ok;
  *reason = "bfgs: line search found no decrease (gradient " + std::to_string(g_inf) + ")";
  return Status::NotConverged;
}

}  // namespace detail

template <class T, int N, class Functor>
BfgsResult<T, N> bfgs_minimize(const Functor& f, const Eigen::Matrix<T, N, 1>& x0, const BfgsOptions& options) {
  static_assert(std::is_floating_point<T>::value, "dyncull::bfgs_minimize: scalar must be float or double");
  static_assert(N > 0, "dyncull::bfgs_minimize: fixed positive dimension required");
  static_assert(detail::is_bfgs_objective<Functor, T, N>,
                "dyncull::bfgs_minimize: functor must be callable as `T f(const Vector& x, Vector* gradient) const`");
  using Vector = Eigen::Matrix<T, N, 1>;
  using Matrix = Eigen::Matrix<T, N, N>;
  using std::abs;
  using std::max;
  using std::min;

  BfgsResult<T, N> result;
  result.x = x0;
  if (!detail::bfgs_check_start(options, x0, &result)) return result;
  const detail::BfgsConstants<T> c(options);

  Vector x = x0;
  Vector g;
  T fx = f(x, &g);
  result.evaluations = 1;
  if (!detail::bfgs_start_finite(fx, g, &result)) return result;

  Matrix H = Matrix::Identity();  // inverse Hessian approximation B_k^-1 (eq. 11)
  bool scaled = false;
  detail::BfgsTrial<T, N> trial;
  detail::BfgsLineSearch<T, N> ls;

  auto finish = [&](Status status, std::string reason) {
    result.status = status;
    result.reason = std::move(reason);
    result.x = x;
    result.value = fx;
    result.gradient = g;
    return result;
  };

  for (int k = 0;; ++k) {
    if (g.template lpNorm<Eigen::Infinity>() <= c.gtol) return finish(Status::Ok, "");
    if (k >= options.max_iterations) {
      return finish(Status::NotConverged, "bfgs: stopped at max_iterations = " + std::to_string(options.max_iterations));
    }

    Vector p = -(H * g);  // eq. 10
    T dphi0 = g.dot(p);
    if (!(dphi0 < T(0))) detail::restart_as_steepest_descent(g, &H, &scaled, &p, &dphi0);
    // Before the first curvature pair the step length is unknown: make the first trial move the point
    // by about one unit of x, then let the line search extrapolate.
    const T alpha = scaled ? T(1) : min(T(1), T(1) / g.template lpNorm<Eigen::Infinity>());

    if (!detail::bfgs_line_search(f, x, fx, p, dphi0, alpha, c, &trial, &ls, &result.evaluations)) {
      std::string why;
      const Status status = detail::no_decrease_status(g, fx, c.eps, &why);
      return finish(status, std::move(why));
    }

    const Vector s = ls.x_new - x;  // eq. 12
    const Vector y = ls.g_new - g;  // eq. 13
    const T f_old = fx;
    x = ls.x_new;
    g = ls.g_new;
    fx = ls.f_new;
    ++result.iterations;
    const T sy = s.dot(y);
    // Update only with positive curvature (keeps H positive definite); eq. 11 with rho = 1 / y^T s (eq. 14).
    // Written inline: as a function g++ keeps it out of line, and a small problem costs 11 % more.
    if (sy > c.eps * s.norm() * y.norm()) {
      if (!scaled) {
        H = Matrix::Identity() * (sy / y.squaredNorm());  // Nocedal & Wright eq. 6.20
        scaled = true;
      }
      const T rho = T(1) / sy;
      const Vector Hy = H * y;
      // Expanded form of (I - rho s y^T) H (I - rho y s^T) + rho s s^T.
      H += (rho * rho * y.dot(Hy) + rho) * (s * s.transpose()) - rho * (Hy * s.transpose() + s * Hy.transpose());
    }

    if (abs(f_old - fx) <= c.ftol * max(abs(f_old), std::numeric_limits<T>::min())) return finish(Status::Ok, "");
    if (s.norm() <= c.xtol * (x.norm() + c.xtol)) return finish(Status::Ok, "");
  }
}

}  // namespace dyncull
