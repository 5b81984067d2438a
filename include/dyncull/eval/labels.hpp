/// @file labels.hpp
/// Precision, recall and IoU of dynamic labels (per feature) and dynamic masks (per pixel) against
/// ground truth: the culling quality numbers beside ATE/RPE (positive class = dynamic).
#pragma once

#include "dyncull/core/mask.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/culling/labels.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>

namespace dyncull::eval {

/// Confusion counts and the scores derived from them. When a score's denominator is zero the score
/// is 1: nothing predicted means no false alarm (precision), nothing to find means nothing missed
/// (recall), both empty means full agreement (IoU, F1). A frame without movers then does not drag an
/// average down, and all four are always finite.
struct LabelScores {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }

  std::size_t true_positive = 0;   ///< predicted dynamic, truly dynamic
  std::size_t false_positive = 0;  ///< predicted dynamic, truly static (a static feature lost)
  std::size_t false_negative = 0;  ///< predicted static, truly dynamic (a mover kept: hurts the pose)
  std::size_t true_negative = 0;

  std::size_t count() const { return true_positive + false_positive + false_negative + true_negative; }
  double precision() const { return ratio(true_positive, true_positive + false_positive); }
  double recall() const { return ratio(true_positive, true_positive + false_negative); }
  double iou() const { return ratio(true_positive, true_positive + false_positive + false_negative); }
  double f1() const { return ratio(2 * true_positive, 2 * true_positive + false_positive + false_negative); }
  double accuracy() const { return ratio(true_positive + true_negative, count()); }

  /// Adds another frame's counts (micro-averaging over a sequence).
  LabelScores& operator+=(const LabelScores& other) {
    true_positive += other.true_positive;
    false_positive += other.false_positive;
    false_negative += other.false_negative;
    true_negative += other.true_negative;
    if (ok() && !other.ok()) {
      status = other.status;
      reason = other.reason;
    }
    return *this;
  }

 private:
  static double ratio(std::size_t num, std::size_t den) {
    return den == 0 ? 1.0 : static_cast<double>(num) / static_cast<double>(den);
  }
};

struct LabelScoreOptions {
  /// How a FeatureLabel::Candidate counts: false = static (only Dynamic features are culled), true =
  /// dynamic (a pipeline that culls candidates too).
  bool candidate_is_dynamic = false;

  /// Always Ok: the only field is a flag. Present so every options struct has the same shape.
  Status validate(std::string* reason = nullptr) const {
    if (reason) reason->clear();
    return Status::Ok;
  }
};

namespace detail {
inline bool label_is_dynamic(FeatureLabel label, const LabelScoreOptions& options) {
  return label == FeatureLabel::Dynamic || (options.candidate_is_dynamic && label == FeatureLabel::Candidate);
}
template <class V>
bool label_is_dynamic(const V& value, const LabelScoreOptions&) {
  static_assert(std::is_arithmetic<V>::value,
                "score_labels: elements must be bool, an integer (non-zero = dynamic) or dyncull::FeatureLabel");
  return value != V(0);
}
}  // namespace detail

/// Scores per-feature labels. predicted and truth: containers with size() and operator[] of bool,
/// uint8 / int (non-zero = dynamic) or FeatureLabel, e.g. std::vector<std::uint8_t> and the labels of a
/// culling result. InvalidInput when the sizes differ (counts then stay zero). The options are not
/// validated: a flag cannot be out of range (LabelScoreOptions::validate is always Ok).
template <class Predicted, class Truth>
LabelScores score_labels(const Predicted& predicted, const Truth& truth, const LabelScoreOptions& options = {}) {
  LabelScores scores;
  const std::size_t n = static_cast<std::size_t>(predicted.size());
  if (n != static_cast<std::size_t>(truth.size())) {
    scores.status = Status::InvalidInput;
    scores.reason = "score_labels: " + std::to_string(n) + " predicted labels but " +
                    std::to_string(static_cast<std::size_t>(truth.size())) + " ground-truth labels";
    return scores;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const bool p = detail::label_is_dynamic(predicted[i], options);
    const bool t = detail::label_is_dynamic(truth[i], options);
    scores.true_positive += p && t;
    scores.false_positive += p && !t;
    scores.false_negative += !p && t;
    scores.true_negative += !p && !t;
  }
  return scores;
}

/// Scores a predicted dynamic mask against a ground-truth mask, pixel by pixel (non-zero = dynamic).
/// `valid` (optional, same size) restricts the comparison to its non-zero pixels, e.g. pixels with a
/// ground-truth annotation. InvalidInput on empty views or different sizes.
inline LabelScores score_masks(ConstMaskView predicted, ConstMaskView truth, ConstMaskView valid = {}) {
  LabelScores scores;
  if (predicted.empty() || truth.empty()) {
    scores.status = Status::InvalidInput;
    scores.reason = "score_masks: empty mask";
    return scores;
  }
  if (predicted.width != truth.width || predicted.height != truth.height ||
      (!valid.empty() && (valid.width != truth.width || valid.height != truth.height))) {
    scores.status = Status::InvalidInput;
    scores.reason = "score_masks: mask sizes differ (predicted " + std::to_string(predicted.width) + "x" +
                    std::to_string(predicted.height) + ", truth " + std::to_string(truth.width) + "x" +
                    std::to_string(truth.height) + ")";
    return scores;
  }
  for (int v = 0; v < truth.height; ++v) {
    const std::uint8_t* p = predicted.row(v);
    const std::uint8_t* t = truth.row(v);
    const std::uint8_t* m = valid.empty() ? nullptr : valid.row(v);
    std::size_t tp = 0, fp = 0, fn = 0, tn = 0;
    for (int u = 0; u < truth.width; ++u) {
      if (m != nullptr && m[u] == 0) continue;
      const bool pd = p[u] != 0;
      const bool td = t[u] != 0;
      tp += pd && td;
      fp += pd && !td;
      fn += !pd && td;
      tn += !pd && !td;
    }
    scores.true_positive += tp;
    scores.false_positive += fp;
    scores.false_negative += fn;
    scores.true_negative += tn;
  }
  return scores;
}

}  // namespace dyncull::eval
