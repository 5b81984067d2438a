/// @file rotation_centre.hpp
/// In-plane frame rotation from optical flow, DFD-SLAM (Qian et al. 2024) §3.3 Algorithm 2: perpendicular
/// bisectors of the flow vectors (eq. 4), the centre OP minimising eq. 5 (exact 2x2 normal equations by
/// default, BFGS of eq. 6-14 or IRLS for robust losses), the equidistance filter (eq. 15) and the mean angle (eq. 16).
#pragma once

#include "dyncull/core/status.hpp"
#include "dyncull/core/traits.hpp"
#include "dyncull/core/types.hpp"
#include "dyncull/geometry/bfgs.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

namespace dyncull {

/// How OP is found. NormalEquations solves the 2x2 normal equations of eq. 5 exactly (one pass; with a
/// robust loss it becomes iteratively reweighted least squares). Bfgs runs the paper's BFGS from the
/// start point (image centre); it is exact for eq. 5 too, and the natural choice for robust losses.
enum class RotationCentreSolver { NormalEquations, Bfgs };

/// Loss on the point-to-bisector distance r (px). None is eq. 5 (r^2). Huber: r^2 inside the scale,
/// 2 k |r| - k^2 outside. Cauchy: k^2 log(1 + r^2 / k^2). Both equal r^2 near 0, so costs stay in px^2.
enum class RobustLoss { None, Huber, Cauchy };

inline const char* to_string(RotationCentreSolver s) noexcept {
  return s == RotationCentreSolver::Bfgs ? "bfgs" : "normal-equations";
}
inline const char* to_string(RobustLoss l) noexcept {
  switch (l) {
    case RobustLoss::None: return "none";
    case RobustLoss::Huber: return "huber";
    case RobustLoss::Cauchy: return "cauchy";
  }
  return "unknown";
}

/// Options of estimate_rotation_centre. The paper gives none of these values; the defaults and their
/// reasons are in docs/algorithms.md.
struct RotationCentreOptions {
  RotationCentreSolver solver = RotationCentreSolver::NormalEquations;
  RobustLoss loss = RobustLoss::None;
  double loss_scale_px = 3.0;         ///< Huber / Cauchy scale k on the bisector distance
  double min_flow_px = 0.5;           ///< shorter vectors have no reliable direction: not used
  std::size_t min_vectors = 8;        ///< usable vectors needed to fit OP at all
  /// Conditioning: smallest / largest eigenvalue of the 2x2 normal matrix sum n n^T. Near 0 means the
  /// bisectors are near-parallel (the flow is a translation and OP is at infinity).
  double min_eigenvalue_ratio = 1e-2;
  double distance_threshold_px = 2.0;  ///< eq. 15: | |OP - P1| - |OP - P2| | must not exceed this
  double min_inlier_fraction = 0.5;    ///< eq. 15 survivors needed, as a fraction of the usable vectors
  std::size_t min_inliers = 8;         ///< ... and as an absolute count ("sufficient", Algorithm 2 l. 13)
  int max_irls_iterations = 50;        ///< NormalEquations with a robust loss
  BfgsOptions bfgs{};                  ///< Bfgs solver

  static constexpr int kMaxIrlsIterations = 10000;  ///< upper bound of max_irls_iterations

  /// Ok, or InvalidInput with a reason naming the field.
  Status validate(std::string* reason = nullptr) const {
    auto bad = [&](const char* why) {
      if (reason) *reason = why;
      return Status::InvalidInput;
    };
    if (solver != RotationCentreSolver::NormalEquations && solver != RotationCentreSolver::Bfgs)
      return bad("RotationCentreOptions: solver is not a RotationCentreSolver value");
    if (loss != RobustLoss::None && loss != RobustLoss::Huber && loss != RobustLoss::Cauchy)
      return bad("RotationCentreOptions: loss is not a RobustLoss value");
    if (!(loss_scale_px > 0.0) || !std::isfinite(loss_scale_px))
      return bad("RotationCentreOptions: loss_scale_px must be finite and > 0");
    if (!(min_flow_px >= 0.0) || !std::isfinite(min_flow_px))
      return bad("RotationCentreOptions: min_flow_px must be finite and >= 0");
    if (!(min_eigenvalue_ratio >= 0.0 && min_eigenvalue_ratio <= 1.0))
      return bad("RotationCentreOptions: min_eigenvalue_ratio must be in [0, 1]");
    if (!(distance_threshold_px >= 0.0) || !std::isfinite(distance_threshold_px))
      return bad("RotationCentreOptions: distance_threshold_px must be finite and >= 0");
    if (!(min_inlier_fraction >= 0.0 && min_inlier_fraction <= 1.0))
      return bad("RotationCentreOptions: min_inlier_fraction must be in [0, 1]");
    if (max_irls_iterations < 0 || max_irls_iterations > kMaxIrlsIterations)
      return bad("RotationCentreOptions: max_irls_iterations must be in [0, 10000]");
    std::string why;
    if (bfgs.validate(&why) != Status::Ok) {
      const std::size_t colon = why.find(": ");
      if (reason) *reason = "RotationCentreOptions: bfgs." + (colon == std::string::npos ? why : why.substr(colon + 2));
      return Status::InvalidInput;
    }
    if (reason) reason->clear();
    return Status::Ok;
  }
};

/// Bisectors of the usable flow vectors, eq. 4 normalised: n_x x + n_y y = e with |n| = 1, in
/// coordinates relative to `origin` (keeps float sums well conditioned). Structure of arrays.
template <class T>
struct BisectorLines {
  Vec2<T> origin = Vec2<T>::Zero();
  std::vector<T> nx, ny, e;
  std::vector<std::uint32_t> source;  ///< index of the flow vector each line came from
  std::size_t num_non_finite = 0;     ///< input vectors skipped for NaN / Inf coordinates
  std::size_t num_short = 0;          ///< input vectors skipped for being shorter than min_flow_px
  std::size_t size() const { return e.size(); }
};

/// OP from a set of bisectors (centre in absolute pixel coordinates).
template <class T>
struct CentreSolution {
  Status status = Status::Ok;
  std::string reason;
  Vec2<T> centre = Vec2<T>::Zero();
  T cost = T(0);            ///< eq. 5 (or the robust loss) at centre, px^2
  T eigenvalue_ratio = T(0);///< lambda_min / lambda_max of the (final-weight) normal matrix
  int iterations = 0;       ///< IRLS or BFGS iterations (0 for the one-step exact solve)
  bool ok() const { return status == Status::Ok; }
};

/// Result of Algorithm 2. ok() means "a rotation was found"; otherwise status/reason say why not.
/// `centre` and `eigenvalue_ratio` are filled whenever the fit itself succeeded (also when eq. 15 then
/// rejects the rotation), so callers can still draw OP.
template <class T>
struct RotationCentreResult {
  Status status = Status::Ok;
  std::string reason;
  Vec2<T> centre = Vec2<T>::Zero();  ///< OP in pixels
  T angle_rad = T(0);         ///< eq. 16: mean unsigned angle P1-OP-P2 over the eq. 15 survivors
  T signed_angle_rad = T(0);  ///< mean signed angle; positive turns P1 towards P2 from +x to +y (clockwise on screen)
  T cost = T(0);              ///< objective at OP
  T eigenvalue_ratio = T(0);  ///< conditioning, see RotationCentreOptions::min_eigenvalue_ratio
  std::vector<std::uint8_t> inlier_mask;  ///< per input vector: 1 = used and passed eq. 15
  std::size_t num_vectors = 0;  ///< usable vectors (finite, long enough)
  std::size_t num_inliers = 0;  ///< eq. 15 survivors
  int iterations = 0;
  bool ok() const { return status == Status::Ok; }
  T angle_deg() const { return angle_rad * Constants<T>::rad_to_deg(); }
  T signed_angle_deg() const { return signed_angle_rad * Constants<T>::rad_to_deg(); }
};

/// Builds the normalised bisectors of flow p1[i] -> p2[i]. Returns the number of lines. Reuses the
/// vectors of `lines` (no allocation once they have grown).
template <class T, class C1, class C2>
std::size_t make_bisector_lines(const C1& points1, const C2& points2, const Vec2<T>& origin, T min_flow_px,
                                BisectorLines<T>* lines);

/// Exact minimiser of eq. 5 (loss None) by the 2x2 normal equations, or IRLS for Huber / Cauchy.
/// Degenerate when the normal matrix is singular or its eigenvalue ratio is below min_eigenvalue_ratio.
template <class T>
CentreSolution<T> solve_centre_normal_equations(const BisectorLines<T>& lines, RobustLoss loss = RobustLoss::None,
                                                T loss_scale_px = T(3), T min_eigenvalue_ratio = T(1e-2),
                                                int max_irls_iterations = 50);

/// BFGS on eq. 5 (or the robust loss) from `start` (absolute pixels), gradient eq. 6-8.
template <class T>
CentreSolution<T> solve_centre_bfgs(const BisectorLines<T>& lines, const Vec2<T>& start,
                                    RobustLoss loss = RobustLoss::None, T loss_scale_px = T(3),
                                    T min_eigenvalue_ratio = T(1e-2), const BfgsOptions& bfgs = {});

/// Objective at an absolute pixel position: eq. 5 for RobustLoss::None. Optional gradient (eq. 7-8).
template <class T>
T bisector_cost(const BisectorLines<T>& lines, const Vec2<T>& centre, RobustLoss loss = RobustLoss::None,
                T loss_scale_px = T(3), Vec2<T>* gradient = nullptr);

/// Algorithm 2 on flow p1[i] -> p2[i] (two parallel containers of points read through PointTraits).
/// `start` is the BFGS start and the coordinate origin; the paper uses the image centre. T defaults to
/// the points' scalar type.
template <class T = void, class C1, class C2>
auto estimate_rotation_centre(const C1& points1, const C2& points2, const Vec2<std::conditional_t<std::is_void<T>::value, typename PointTraits<container_point_t<C1>>::Scalar, T>>& start,
                              const RotationCentreOptions& options = {});

/// Same, starting from the centre of a width x height image, ((width - 1) / 2, (height - 1) / 2).
template <class T = void, class C1, class C2>
auto estimate_rotation_centre(const C1& points1, const C2& points2, int width, int height,
                              const RotationCentreOptions& options = {});

// ------------------------------------------------------------------------------------------------
// Implementation
// ------------------------------------------------------------------------------------------------

namespace detail {

/// IRLS weight w(r) with rho'(r) = 2 w(r) r.
template <class T>
inline T robust_weight(RobustLoss loss, T r, T k) {
  using std::abs;
  switch (loss) {
    case RobustLoss::None: return T(1);
    case RobustLoss::Huber: return abs(r) <= k ? T(1) : k / abs(r);
    case RobustLoss::Cauchy: return T(1) / (T(1) + (r * r) / (k * k));
  }
  return T(1);
}

template <class T>
inline T robust_rho(RobustLoss loss, T r, T k) {
  using std::abs;
  using std::log1p;
  switch (loss) {
    case RobustLoss::None: return r * r;
    case RobustLoss::Huber: return abs(r) <= k ? r * r : T(2) * k * abs(r) - k * k;
    case RobustLoss::Cauchy: return k * k * log1p((r * r) / (k * k));
  }
  return r * r;
}

/// Weighted normal matrix [[a, b], [b, c]] and right-hand side at relative position x (weights from r(x)).
template <class T>
struct Normal2 {
  T a = T(0), b = T(0), c = T(0), ra = T(0), rb = T(0);
};

template <class T>
using ConstArrayMap = Eigen::Map<const Eigen::Array<T, Eigen::Dynamic, 1>>;

template <class T>
inline Normal2<T> accumulate_normal(const BisectorLines<T>& lines, RobustLoss loss, T k, const Vec2<T>& x_rel) {
  Normal2<T> n;
  const Eigen::Index m = static_cast<Eigen::Index>(lines.size());
  const ConstArrayMap<T> nx(lines.nx.data(), m), ny(lines.ny.data(), m), e(lines.e.data(), m);
  if (loss == RobustLoss::None) {
    // Eigen reductions are vectorised (a scalar loop is not: it may not reorder the sums).
    n.a = nx.square().sum();
    n.b = (nx * ny).sum();
    n.c = ny.square().sum();
    n.ra = (nx * e).sum();
    n.rb = (ny * e).sum();
    return n;
  }
  for (Eigen::Index i = 0; i < m; ++i) {
    const T r = nx[i] * x_rel.x() + ny[i] * x_rel.y() - e[i];
    const T w = robust_weight(loss, r, k);
    n.a += w * nx[i] * nx[i];
    n.b += w * nx[i] * ny[i];
    n.c += w * ny[i] * ny[i];
    n.ra += w * nx[i] * e[i];
    n.rb += w * ny[i] * e[i];
  }
  return n;
}

template <class T>
inline T eigen_ratio(const Normal2<T>& n) {
  using std::abs;
  using std::sqrt;
  const T half_tr = T(0.5) * (n.a + n.c);
  const T half_diff = T(0.5) * (n.a - n.c);
  const T disc = sqrt(half_diff * half_diff + n.b * n.b);
  const T lmax = half_tr + disc;
  const T lmin = half_tr - disc;
  return lmax > T(0) ? std::max(T(0), lmin) / lmax : T(0);
}

template <class T>
inline std::string ill_conditioned_reason(T ratio, T min_ratio) {
  return "bisectors are near-parallel (eigenvalue ratio " + std::to_string(static_cast<double>(ratio)) + " < " +
         std::to_string(static_cast<double>(min_ratio)) + "): the flow is a translation, not a rotation";
}

}  // namespace detail

template <class T, class C1, class C2>
std::size_t make_bisector_lines(const C1& points1, const C2& points2, const Vec2<T>& origin, T min_flow_px,
                                BisectorLines<T>* lines) {
  static_assert(std::is_floating_point<T>::value, "dyncull::make_bisector_lines: scalar must be float or double");
  static_assert(is_point_container_v<C1> && is_point_container_v<C2>,
                "dyncull::make_bisector_lines: containers need size() and operator[] returning points readable "
                "by dyncull::PointTraits");
  using std::isfinite;
  using std::sqrt;
  lines->origin = origin;
  lines->nx.clear();
  lines->ny.clear();
  lines->e.clear();
  lines->source.clear();
  lines->num_non_finite = 0;
  lines->num_short = 0;
  const std::size_t n = std::min<std::size_t>(points1.size(), points2.size());
  lines->nx.reserve(n);
  lines->ny.reserve(n);
  lines->e.reserve(n);
  lines->source.reserve(n);
  const T min_len_sq = min_flow_px * min_flow_px;
  for (std::size_t i = 0; i < n; ++i) {
    const T x1 = point_x<T>(points1[i]) - origin.x(), y1 = point_y<T>(points1[i]) - origin.y();
    const T x2 = point_x<T>(points2[i]) - origin.x(), y2 = point_y<T>(points2[i]) - origin.y();
    if (!(isfinite(x1) && isfinite(y1) && isfinite(x2) && isfinite(y2))) {
      ++lines->num_non_finite;
      continue;
    }
    const T dx = x2 - x1, dy = y2 - y1;
    const T len_sq = dx * dx + dy * dy;
    // The bisector of a zero-length vector is undefined; also guards len_sq == 0 for min_flow_px == 0.
    if (!(len_sq >= min_len_sq) || !(len_sq > T(0))) {
      ++lines->num_short;
      continue;
    }
    const T inv_len = T(1) / sqrt(len_sq);
    const T ux = dx * inv_len, uy = dy * inv_len;
    // Bisector through the midpoint, normal along the flow: u . x = u . m  (eq. 4 with a, b = u).
    lines->nx.push_back(ux);
    lines->ny.push_back(uy);
    lines->e.push_back(T(0.5) * (ux * (x1 + x2) + uy * (y1 + y2)));
    lines->source.push_back(static_cast<std::uint32_t>(i));
  }
  return lines->size();
}

template <class T>
T bisector_cost(const BisectorLines<T>& lines, const Vec2<T>& centre, RobustLoss loss, T loss_scale_px,
                Vec2<T>* gradient) {
  const Vec2<T> x = centre - lines.origin;
  const Eigen::Index m = static_cast<Eigen::Index>(lines.size());
  const detail::ConstArrayMap<T> nx(lines.nx.data(), m), ny(lines.ny.data(), m), e(lines.e.data(), m);
  T f = T(0), gx = T(0), gy = T(0);
  if (loss == RobustLoss::None) {
    const auto r = nx * x.x() + ny * x.y() - e;  // signed distances (eq. 5 with |n| = 1), lazily evaluated
    f = r.square().sum();
    gx = (r * nx).sum();
    gy = (r * ny).sum();
  } else {
    for (Eigen::Index i = 0; i < m; ++i) {
      const T r = nx[i] * x.x() + ny[i] * x.y() - e[i];
      const T wr = detail::robust_weight(loss, r, loss_scale_px) * r;
      f += detail::robust_rho(loss, r, loss_scale_px);
      gx += wr * nx[i];
      gy += wr * ny[i];
    }
  }
  if (gradient) *gradient = Vec2<T>(T(2) * gx, T(2) * gy);  // eq. 7-8 (|n| = 1 already)
  return f;
}

template <class T>
CentreSolution<T> solve_centre_normal_equations(const BisectorLines<T>& lines, RobustLoss loss, T loss_scale_px,
                                                T min_eigenvalue_ratio, int max_irls_iterations) {
  using std::abs;
  CentreSolution<T> out;
  if (lines.size() < 2) {
    out.status = Status::TooFewPoints;
    out.reason = "rotation centre: need at least 2 bisectors, got " + std::to_string(lines.size());
    return out;
  }
  if (loss != RobustLoss::None && !(loss_scale_px > T(0))) {
    out.status = Status::InvalidInput;
    out.reason = "rotation centre: loss_scale_px must be > 0 for a robust loss";
    return out;
  }
  Vec2<T> x = Vec2<T>::Zero();
  const int rounds = loss == RobustLoss::None ? 1 : 1 + std::max(0, max_irls_iterations);
  // The first round is plain least squares (weights at x = 0 would bias towards the start point).
  bool converged = loss == RobustLoss::None;
  for (int it = 0; it < rounds; ++it) {
    const auto n = detail::accumulate_normal(lines, it == 0 ? RobustLoss::None : loss, loss_scale_px, x);
    out.eigenvalue_ratio = detail::eigen_ratio(n);
    const T det = n.a * n.c - n.b * n.b;
    if (!(out.eigenvalue_ratio >= min_eigenvalue_ratio) || !(det > T(0))) {
      out.status = Status::Degenerate;
      out.reason = detail::ill_conditioned_reason(out.eigenvalue_ratio, min_eigenvalue_ratio);
      return out;
    }
    const Vec2<T> x_new((n.c * n.ra - n.b * n.rb) / det, (n.a * n.rb - n.b * n.ra) / det);
    const T step = (x_new - x).norm();
    x = x_new;
    out.iterations = it;
    // IRLS stops when OP moves less than a millipixel (times the scalar's resolution of |x|).
    if (it > 0 && step <= T(1e-6) * (T(1) + x.norm()) + T(16) * Constants<T>::epsilon() * x.norm()) {
      converged = true;
      break;
    }
  }
  out.centre = x + lines.origin;
  out.cost = bisector_cost(lines, out.centre, loss, loss_scale_px);
  if (!x.allFinite()) {
    out.status = Status::NonFinite;
    out.reason = "rotation centre: non-finite solution";
  } else if (!converged) {
    out.status = Status::NotConverged;
    out.reason = "rotation centre: IRLS did not settle in " + std::to_string(max_irls_iterations) + " iterations";
  }
  return out;
}

template <class T>
CentreSolution<T> solve_centre_bfgs(const BisectorLines<T>& lines, const Vec2<T>& start, RobustLoss loss,
                                    T loss_scale_px, T min_eigenvalue_ratio, const BfgsOptions& bfgs) {
  CentreSolution<T> out;
  if (lines.size() < 2) {
    out.status = Status::TooFewPoints;
    out.reason = "rotation centre: need at least 2 bisectors, got " + std::to_string(lines.size());
    return out;
  }
  if (loss != RobustLoss::None && !(loss_scale_px > T(0))) {
    out.status = Status::InvalidInput;
    out.reason = "rotation centre: loss_scale_px must be > 0 for a robust loss";
    return out;
  }
  // Conditioning is a property of the bisector directions (unit weights): check it before iterating,
  // since BFGS on a near-singular quadratic wanders along the valley instead of failing.
  const auto n0 = detail::accumulate_normal(lines, RobustLoss::None, loss_scale_px, Vec2<T>(Vec2<T>::Zero()));
  out.eigenvalue_ratio = detail::eigen_ratio(n0);
  if (!(out.eigenvalue_ratio >= min_eigenvalue_ratio)) {
    out.status = Status::Degenerate;
    out.reason = detail::ill_conditioned_reason(out.eigenvalue_ratio, min_eigenvalue_ratio);
    return out;
  }
  // Iterate in origin-relative coordinates (same numbers as the exact solve; better float accuracy).
  BisectorLines<T> const* L = &lines;
  const auto objective = [L, loss, loss_scale_px](const Vec2<T>& x_rel, Vec2<T>* g) {
    return bisector_cost(*L, Vec2<T>(x_rel + L->origin), loss, loss_scale_px, g);
  };
  const auto r = bfgs_minimize(objective, Vec2<T>(start - lines.origin), bfgs);
  out.centre = r.x + lines.origin;
  out.cost = r.value;
  out.iterations = r.iterations;
  out.status = r.status;
  out.reason = r.reason;
  if (loss != RobustLoss::None && r.x.allFinite()) {
    out.eigenvalue_ratio = detail::eigen_ratio(detail::accumulate_normal(lines, loss, loss_scale_px, r.x));
    if (!(out.eigenvalue_ratio >= min_eigenvalue_ratio) && out.ok()) {
      out.status = Status::Degenerate;
      out.reason = detail::ill_conditioned_reason(out.eigenvalue_ratio, min_eigenvalue_ratio);
    }
  }
  return out;
}

namespace detail {

/// Eq. 15 filter and eq. 16 sums: each bisector's vector pair whose ends are equidistant from `centre`
/// (within thr px) is marked in inlier_mask, its angle about the centre added to sum_signed and its
/// magnitude to sum_abs; returns their number. The unsigned eq. 16 angle acos(a.b / |a||b|) equals
/// |atan2(a x b, a.b)|, which is accurate near 0 where acos is not.
template <class S, class C1, class C2>
std::size_t sum_rotation_angles(const C1& points1, const C2& points2, const BisectorLines<S>& lines,
                                const Vec2<S>& centre, S thr, std::vector<std::uint8_t>* inlier_mask, S* sum_abs,
                                S* sum_signed) {
  using std::abs;
  using std::atan2;
  using std::sqrt;
  std::size_t inliers = 0;
  for (std::size_t j = 0; j < lines.size(); ++j) {
    const std::size_t i = lines.source[j];
    const S ax = point_x<S>(points1[i]) - centre.x(), ay = point_y<S>(points1[i]) - centre.y();
    const S bx = point_x<S>(points2[i]) - centre.x(), by = point_y<S>(points2[i]) - centre.y();
    const S ra = sqrt(ax * ax + ay * ay), rb = sqrt(bx * bx + by * by);
    if (!(abs(ra - rb) <= thr)) continue;  // eq. 15, with the absolute value the paper leaves out
    const S angle = atan2(ax * by - ay * bx, ax * bx + ay * by);
    *sum_signed += angle;
    *sum_abs += abs(angle);
    (*inlier_mask)[i] = 1;
    ++inliers;
  }
  return inliers;
}

/// Inliers a rotation needs among `vectors` usable ones: min_inliers, the min_inlier_fraction, at least 1.
inline std::size_t required_rotation_inliers(const RotationCentreOptions& options, std::size_t vectors) {
  const std::size_t by_fraction =
      static_cast<std::size_t>(std::ceil(options.min_inlier_fraction * static_cast<double>(vectors)));  // checked: fraction in [0, 1] (validate)
  return std::max<std::size_t>({options.min_inliers, by_fraction, std::size_t{1}});
}

}  // namespace detail

template <class T, class C1, class C2>
auto estimate_rotation_centre(
    const C1& points1, const C2& points2,
    const Vec2<std::conditional_t<std::is_void<T>::value, typename PointTraits<container_point_t<C1>>::Scalar, T>>& start,
    const RotationCentreOptions& options) {
  static_assert(is_point_container_v<C1> && is_point_container_v<C2>,
                "dyncull::estimate_rotation_centre: containers need size() and operator[] returning points readable "
                "by dyncull::PointTraits");
  using S = std::conditional_t<std::is_void<T>::value, typename PointTraits<container_point_t<C1>>::Scalar, T>;
  static_assert(std::is_floating_point<S>::value, "dyncull::estimate_rotation_centre: scalar must be float or double");

  RotationCentreResult<S> res;
  res.centre = start;
  const std::size_t n = points1.size();
  res.inlier_mask.assign(n, 0);
  auto fail = [&res](Status s, std::string reason) {
    res.status = s;
    res.reason = std::move(reason);
    return res;
  };
  if (points2.size() != n) {
    return fail(Status::InvalidInput, "rotation centre: point containers differ in size (" + std::to_string(n) +
                                          " vs " + std::to_string(points2.size()) + ")");
  }
  if (!start.allFinite()) return fail(Status::NonFinite, "rotation centre: non-finite start point");
  {
    std::string why;
    if (options.validate(&why) != Status::Ok) return fail(Status::InvalidInput, "rotation centre: " + why);
  }

  // Line 1 of Algorithm 2. Thread-local scratch keeps repeated per-frame calls allocation-free.
  thread_local BisectorLines<S> lines;
  make_bisector_lines(points1, points2, start, static_cast<S>(options.min_flow_px), &lines);
  res.num_vectors = lines.size();
  const std::size_t needed = std::max<std::size_t>(options.min_vectors, 2);
  if (lines.size() < needed) {
    if (lines.num_non_finite > 0) {
      return fail(Status::NonFinite, "rotation centre: " + std::to_string(lines.num_non_finite) + " of " +
                                         std::to_string(n) + " vectors non-finite, " + std::to_string(lines.size()) +
                                         " usable < " + std::to_string(needed));
    }
    return fail(Status::TooFewPoints, "rotation centre: " + std::to_string(lines.size()) + " usable vectors (longer than " +
                                          std::to_string(options.min_flow_px) + " px) < " + std::to_string(needed));
  }

  // Lines 2-3: OP.
  const S k = static_cast<S>(options.loss_scale_px);
  const S min_ratio = static_cast<S>(options.min_eigenvalue_ratio);
  const CentreSolution<S> sol =
      options.solver == RotationCentreSolver::Bfgs
          ? solve_centre_bfgs(lines, start, options.loss, k, min_ratio, options.bfgs)
          : solve_centre_normal_equations(lines, options.loss, k, min_ratio, options.max_irls_iterations);
  res.eigenvalue_ratio = sol.eigenvalue_ratio;
  res.iterations = sol.iterations;
  if (!sol.ok()) return fail(sol.status, sol.reason);
  res.centre = sol.centre;
  res.cost = sol.cost;

  // Lines 4-12: eq. 15 filter and the angles of eq. 16 over the survivors.
  S sum_abs = S(0), sum_signed = S(0);
  const std::size_t inliers =
      detail::sum_rotation_angles(points1, points2, lines, res.centre, static_cast<S>(options.distance_threshold_px),
                                  &res.inlier_mask, &sum_abs, &sum_signed);
  res.num_inliers = inliers;
  const std::size_t need_inliers = detail::required_rotation_inliers(options, lines.size());
  if (inliers < need_inliers) {
    return fail(Status::TooFewPoints, "rotation centre: only " + std::to_string(inliers) + " of " +
                                          std::to_string(lines.size()) + " vectors are equidistant from OP (eq. 15, " +
                                          std::to_string(options.distance_threshold_px) + " px), need " +
                                          std::to_string(need_inliers) + ": the motion is not a frame rotation");
  }
  // Lines 13-14: eq. 16.
  res.angle_rad = sum_abs / static_cast<S>(inliers);
  res.signed_angle_rad = sum_signed / static_cast<S>(inliers);
  return res;
}

template <class T, class C1, class C2>
auto estimate_rotation_centre(const C1& points1, const C2& points2, int width, int height,
                              const RotationCentreOptions& options) {
  using S = std::conditional_t<std::is_void<T>::value, typename PointTraits<container_point_t<C1>>::Scalar, T>;
  // Pixel centres run from 0 to width - 1, so the image centre is at (width - 1) / 2. The paper's
  // (H//2, W//2) swaps x and y; we take x from the width.
  const Vec2<S> start(S(width - 1) / S(2), S(height - 1) / S(2));
  return estimate_rotation_centre<T>(points1, points2, start, options);
}

}  // namespace dyncull
