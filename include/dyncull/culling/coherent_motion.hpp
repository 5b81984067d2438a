/// @file coherent_motion.hpp
/// Cell-level motion evidence for the sub-box vote of DFD-SLAM (Qian et al. 2024,
/// Algorithm 1; our extension): the features of one
/// sub-box of an object move together, so the median of their reprojection residual vectors becomes
/// significant well before any single residual passes its threshold (a seated person's sway). A cell whose
/// median residual exceeds `sigmas` standard errors of a median is flagged as a whole (docs/algorithms.md).
#pragma once

#include "dyncull/core/box.hpp"
#include "dyncull/core/flags.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/core/traits.hpp"
#include "dyncull/core/types.hpp"
#include "dyncull/culling/labels.hpp"
#include "dyncull/culling/subbox_refine.hpp"
#include "dyncull/culling/validation.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace dyncull {

/// Options. The test: |median residual vector| > sigmas * 1.2533 * noise / sqrt(N) and > min_median_px,
/// with N the cell's features with a residual and noise the per-component sd of a static track's residual
/// (at least kMinNoisePx). 1.2533 sigma / sqrt(N) is the standard error of a median of N Gaussian samples.
template <class T>
struct CoherentMotionOptions {
  std::size_t min_points = 4;   ///< fewer features with a residual: the cell is not tested
  /// Far above a statistical 3: the residuals of a still object near the camera share an offset too (the
  /// map points' error and the pose fitted on the far background), which the noise does not model.
  T sigmas = T(10);
  static constexpr double kMinNoisePx = 0.2;  ///< floor of the noise: LK and map points rarely do better at 640x480
  T min_median_px = T(0.5);     ///< a shared offset below this is never motion

  /// InvalidInput naming the first field out of its range: min_points >= 1, sigmas positive and finite,
  /// min_median_px finite and >= 0.
  Status validate(std::string* reason = nullptr) const {
    using detail::finite_in;
    using detail::invalid_option;
    if (min_points < 1) return invalid_option(reason, "min_points", "must be >= 1");
    if (!(sigmas > T(0)) || !std::isfinite(sigmas)) return invalid_option(reason, "sigmas", "must be positive and finite");
    if (!finite_in(min_median_px, 0, 1e30)) return invalid_option(reason, "min_median_px", "must be finite and >= 0");
    if (reason) reason->clear();
    return Status::Ok;
  }
};

/// Outcome: which cells were flagged and how many features turned Dynamic.
template <class T>
struct CoherentMotionResult {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }

  std::vector<std::uint8_t> cells;  ///< per box grid*grid, 1 = coherent motion (box-major, as SubBoxResult)
  std::size_t num_cells_tested = 0, num_cells_flagged = 0;
  std::size_t num_flagged = 0;      ///< Static features made Dynamic
  T noise_px = T(0);                ///< the noise the test used

  // Scratch reused across frames.
  std::vector<std::uint32_t> scratch_order, scratch_start;
  std::vector<std::int8_t> scratch_cell;
  std::vector<T> scratch_u, scratch_v;
};

namespace detail {
/// T stays deduced from the other parameters, so a std::vector<Vec2<T>> converts to the view.
template <class X>
struct NonDeducedHolder {
  using type = X;
};
template <class X>
using NonDeduced = typename NonDeducedHolder<X>::type;
}  // namespace detail

namespace detail {

/// Nothing flagged yet; false (status and reason set) when the inputs break the contract or there is
/// nothing to test (Skipped: no features or no boxes).
template <class T>
bool coherent_start(std::size_t n, std::size_t nb, ArrayView<Vec2<T>> residuals, int grid,
                    const CoherentMotionOptions<T>& options,
                    const FeatureLabel* labels, FlagView in_object_mask, BoxBitsView object_box_bits,
                    FlagView eligible, CoherentMotionResult<T>* out) {
  CoherentMotionResult<T>& r = *out;
  r.status = Status::Ok;
  r.reason.clear();
  r.num_cells_tested = r.num_cells_flagged = r.num_flagged = 0;
  r.cells.clear();
  auto stop = [&](Status s, std::string why) {
    r.status = s;
    r.reason = std::move(why);
    return false;
  };
  std::string why;
  if (options.validate(&why) != Status::Ok) return stop(Status::InvalidInput, "invalid options: " + why);
  if (grid < 1 || grid > 8) return stop(Status::InvalidInput, "grid must be in [1, 8]");
  if (!residuals.given) return stop(Status::InvalidInput, "residuals is required (" + std::to_string(n) + " points)");
  if (!flags_fit(residuals, n, "residuals", "points", &why) ||
      !flags_fit(in_object_mask, n, "in_object_mask", "points", &why) ||
      !flags_fit(object_box_bits, n, "object_box_bits", "points", &why) ||
      !flags_fit(eligible, n, "eligible", "points", &why))
    return stop(Status::InvalidInput, why);
  r.cells.assign(nb * static_cast<std::size_t>(grid * grid), 0);
  if (n == 0 || nb == 0) return stop(Status::Skipped, n == 0 ? "no features" : "no boxes");
  if (!labels) return stop(Status::InvalidInput, "labels is required");
  return true;
}

/// Counting sort of box b's object features that have a residual by grid cell (allocation-free):
/// afterwards cell c's features are scratch_order[start[c - 1] .. start[c]) (from 0 for the first).
template <class T, class Points>
void sort_box_features_by_cell(const Points& points, ArrayView<Vec2<T>> residuals, const Box<T>& box, std::size_t b,
                               int g, FlagView in_object_mask, BoxBitsView object_box_bits, FlagView eligible,
                               CoherentMotionResult<T>* r) {
  const std::size_t n = static_cast<std::size_t>(points.size()), cells = static_cast<std::size_t>(g * g);
  std::uint32_t* start = r->scratch_start.data();
  std::fill(start, start + cells + 1, 0u);
  for (std::size_t i = 0; i < n; ++i) {
    int c = -1;
    if ((!eligible.given || eligible[i]) && subbox_in_object(in_object_mask, object_box_bits, i, b) &&
        residuals[i].allFinite())
      c = subbox_cell(box, g, point_x<T>(points[i]), point_y<T>(points[i]));
    r->scratch_cell[i] = static_cast<std::int8_t>(c);  // grid <= 8: cells 0-63
    if (c >= 0) ++start[c + 1];
  }
  for (std::size_t c = 0; c < cells; ++c) start[c + 1] += start[c];
  for (std::size_t i = 0; i < n; ++i) {
    const int c = r->scratch_cell[i];
    if (c >= 0) r->scratch_order[start[c]++] = static_cast<std::uint32_t>(i);
  }
}

/// The cell's features move together: the median of their residual vectors is above min_median_px and
/// `sigmas` standard errors of a median of static residuals (1.2533 noise / sqrt(count)).
template <class T>
bool cell_moves_coherently(ArrayView<Vec2<T>> residuals, std::uint32_t begin, std::uint32_t end,
                           const CoherentMotionOptions<T>& options, CoherentMotionResult<T>* r) {
  const std::size_t count = end - begin;
  for (std::uint32_t k = begin; k < end; ++k) {
    r->scratch_u[k - begin] = residuals[r->scratch_order[k]].x();
    r->scratch_v[k - begin] = residuals[r->scratch_order[k]].y();
  }
  const auto median = [count](std::vector<T>& v) {
    const auto mid = v.begin() + static_cast<std::ptrdiff_t>(count / 2);
    std::nth_element(v.begin(), mid, v.begin() + static_cast<std::ptrdiff_t>(count));
    return *mid;
  };
  const T mu = median(r->scratch_u), mv = median(r->scratch_v);
  const T magnitude = std::sqrt(mu * mu + mv * mv);
  const T standard_error = T(1.2533) * r->noise_px / std::sqrt(static_cast<T>(count));
  return magnitude > options.min_median_px && magnitude > options.sigmas * standard_error;
}

}  // namespace detail

/// Flags the cells of a grid x grid division of each box (the sub-box vote's SubBoxOptions::grid, in
/// [1, 8]) whose features' residual vectors share a significant median, and turns
/// their Static labels Dynamic (Candidate labels, features without evidence, stay). residuals[i]: measured
/// minus predicted pixel of feature i (ReprojectionCheckResult::residual_vec, NaN where none); noise_px:
/// per-component sd of a static residual (ReprojectionCheckResult::inlier_noise_px; NaN: kMinNoisePx).
/// in_object_mask / object_box_bits as in refine_subboxes: a box's cells hold only its object's features.
/// eligible: optional per feature, 0 = takes no part (neither tested nor flagged). residuals (required)
/// and a given flag view whose size is not points.size() give InvalidInput naming it and both sizes
/// (nothing read). labels is a raw pointer that must hold points.size() entries.
template <class T, class Points, class Boxes>
void flag_coherent_cells(const Points& points, detail::NonDeduced<ArrayView<Vec2<T>>> residuals, const Boxes& boxes,
                         int grid, T noise_px,
                         const CoherentMotionOptions<T>& options, FeatureLabel* labels, CoherentMotionResult<T>* out,
                         FlagView in_object_mask = nullptr, BoxBitsView object_box_bits = nullptr,
                         FlagView eligible = nullptr) {
  static_assert(is_point_container_v<Points>, "dyncull::flag_coherent_cells: points must hold points (see PointTraits)");
  CoherentMotionResult<T>& r = *out;
  const std::size_t n = static_cast<std::size_t>(points.size());
  const std::size_t nb = static_cast<std::size_t>(boxes.size());
  if (!detail::coherent_start(n, nb, residuals, grid, options, labels, in_object_mask, object_box_bits, eligible,
                              out))
    return;
  const int g = grid;
  const std::size_t cells_per_box = static_cast<std::size_t>(g * g);
  const T min_noise = T(CoherentMotionOptions<T>::kMinNoisePx);
  r.noise_px = std::isfinite(noise_px) ? std::max(noise_px, min_noise) : min_noise;
  r.scratch_order.resize(n);
  r.scratch_cell.resize(n);
  r.scratch_start.resize(cells_per_box + 1);
  r.scratch_u.resize(n);
  r.scratch_v.resize(n);
  for (std::size_t b = 0; b < nb; ++b) {
    const Box<T>& box = detail::subbox_as_box(boxes[b]);
    if (!box.valid()) continue;
    detail::sort_box_features_by_cell(points, residuals, box, b, g, in_object_mask, object_box_bits, eligible, &r);
    for (std::size_t c = 0; c < cells_per_box; ++c) {
      const std::uint32_t begin = c == 0 ? 0u : r.scratch_start[c - 1], end = r.scratch_start[c];
      if (end - begin < options.min_points) continue;
      ++r.num_cells_tested;
      if (!detail::cell_moves_coherently(residuals, begin, end, options, &r)) continue;
      r.cells[b * cells_per_box + c] = 1;
      ++r.num_cells_flagged;
      for (std::uint32_t k = begin; k < end; ++k) {  // Static turns Dynamic; Candidate (no evidence) stays
        FeatureLabel& l = labels[r.scratch_order[k]];
        if (l != FeatureLabel::Static) continue;
        l = FeatureLabel::Dynamic;
        ++r.num_flagged;
      }
    }
  }
}

}  // namespace dyncull
