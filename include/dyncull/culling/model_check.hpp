/// @file model_check.hpp
/// One algorithm behind the moving-consistency and reprojection checks: fit a camera model by RANSAC on the
/// tracks outside dynamic-class boxes (SG-SLAM, Cheng et al. 2023), then label each track by its residual to
/// the model against a threshold, tighter inside the boxes (DFD-SLAM, Qian et al. 2024, eq. 3).
#pragma once

#include "dyncull/core/flags.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/culling/labels.hpp"

#include <algorithm>
#include <cstddef>
#include <string>
#include <utility>

namespace dyncull {
namespace detail {

/// Thresholds and fit-subset rule of a model check, in the estimator's residual unit (px).
template <class T>
struct ModelCheckRule {
  T max_residual;           ///< residual above this: dynamic (tracks outside dynamic boxes)
  T max_residual_in_boxes;  ///< the same inside dynamic-class boxes
  std::size_t min_tracks;   ///< fewer usable tracks: Skipped (never fewer than the estimator's minimal sample)
  bool fit_outside_boxes;   ///< fit on the tracks outside the boxes ...
  std::size_t min_tracks_outside_boxes;  ///< ... when at least this many of them are usable
};

// An estimator plugged into check_against_model provides:
//   constants  kMinimalTracks (the model's minimal sample), kSubsetLeavesSomeOut (the subset is reported
//              only when it excludes a track), kSizeMismatch and kTooFew (reason texts);
//   members    options (with validate()) and r (the result: status, reason, labels, inlier_mask, the num_*
//              counters, fitted_outside_boxes);
//   inputs     size(), sizes_agree(), inputs_valid(&why) (checks beyond sizes, flags and options), usable(i)
//              (finite inputs);
//   steps      reset() (its outputs to "not evaluated", its buffers emptied); keep(i) for each usable
//              track; begin_fit(subset), true to be handed the fit tracks by add_to_fit(k, i); fit();
//              polish(); residuals_ready(); label(k, i, limit) (Candidate = no evidence); finish().
//              fit() and residuals_ready() return false with status and reason set.
// i indexes all tracks, k the usable ones; both follow index order, which RANSAC's sampling depends on.

/// Every track a candidate, nothing fitted; false (InvalidInput, reason set) when the inputs break the
/// contract, checked in this order: sizes, flag views, options, the estimator's own inputs.
template <class Est>
bool model_check_start(Est& est, FlagView valid, FlagView in_box) {
  auto& r = *est.r;
  const std::size_t n = est.size();
  r.status = Status::Ok;
  r.reason.clear();
  r.num_tracks = n;
  r.num_valid = r.num_fit = r.num_inliers = r.num_dynamic = r.num_static = 0;
  r.fitted_outside_boxes = false;
  r.labels.assign(n, FeatureLabel::Candidate);
  r.inlier_mask.assign(n, 0);
  est.reset();
  auto stop = [&](std::string why) {
    r.status = Status::InvalidInput;
    r.reason = std::move(why);
    return false;
  };
  if (!est.sizes_agree()) return stop(Est::kSizeMismatch);
  std::string why;
  if (!flags_fit(valid, n, "valid", "tracks", &why) || !flags_fit(in_box, n, "in_box", "tracks", &why))
    return stop(why);
  if (est.options.validate(&why) != Status::Ok) return stop("invalid options: " + why);
  if (!est.inputs_valid(&why)) return stop(why);
  return true;
}

/// The check: usable tracks (flagged valid, finite inputs), too few -> Skipped; the fit subset; the model
/// by RANSAC, polished; then each usable track's residual against the threshold of its side of the boxes.
/// Writes est.r; the order of the tracks handed to the estimator is their index order throughout.
template <class Est, class T>
void check_against_model(Est& est, FlagView valid, FlagView in_box, const ModelCheckRule<T>& rule) {
  if (!model_check_start(est, valid, in_box)) return;
  auto& r = *est.r;
  const std::size_t n = est.size();
  auto usable = [&](std::size_t i) { return !(valid.given && !valid[i]) && est.usable(i); };
  auto inside = [&](std::size_t i) { return in_box.given && in_box[i]; };
  std::size_t m = 0, outside = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!usable(i)) continue;
    est.keep(i);
    ++m;
    outside += !inside(i);
  }
  r.num_valid = m;
  const std::size_t need = std::max<std::size_t>(rule.min_tracks, Est::kMinimalTracks);
  if (m < need) {
    r.status = Status::Skipped;  // a model from a handful of tracks labels noise, not motion
    r.reason = std::to_string(m) + Est::kTooFew + std::to_string(need);
    return;
  }
  // SG-SLAM: fit on the tracks outside the boxes, so a moving person does not pull the model.
  const bool subset = in_box.given && rule.fit_outside_boxes && outside >= rule.min_tracks_outside_boxes &&
                      (outside < m || !Est::kSubsetLeavesSomeOut);
  r.num_fit = subset ? outside : m;
  r.fitted_outside_boxes = subset;
  if (est.begin_fit(subset)) {  // false: the estimator fits on the tracks it kept
    for (std::size_t i = 0, k = 0; i < n; ++i) {
      if (!usable(i)) continue;
      if (!(subset && inside(i))) est.add_to_fit(k, i);
      ++k;
    }
  }
  if (!est.fit()) return;
  est.polish();
  if (!est.residuals_ready()) return;
  // eq. 3: a track whose residual exceeds its threshold is dynamic.
  for (std::size_t i = 0, k = 0; i < n; ++i) {
    if (!usable(i)) continue;
    const FeatureLabel label = est.label(k++, i, inside(i) ? rule.max_residual_in_boxes : rule.max_residual);
    if (label == FeatureLabel::Candidate) continue;  // no evidence either way
    r.labels[i] = label;
    r.num_dynamic += label == FeatureLabel::Dynamic;
    r.num_static += label == FeatureLabel::Static;
  }
  est.finish();
}

}  // namespace detail
}  // namespace dyncull
