/// @file statistics.hpp
/// Summary statistics of an error sequence exactly as the TUM benchmark scripts print them
/// (evaluate_ate.py / evaluate_rpe.py: RMSE, numpy mean, median, population std, min, max).
#pragma once

#include "dyncull/core/status.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

namespace dyncull::eval {

/// RMSE / mean / median / std / min / max of non-negative errors (metres, degrees, ...).
/// std is the population std (numpy.std, ddof = 0); median is numpy.median (mean of the two middle
/// values for an even count). All fields are NaN unless ok().
template <class T>
struct ErrorStatistics {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }

  std::size_t count = 0;
  T rmse = std::numeric_limits<T>::quiet_NaN();
  T mean = std::numeric_limits<T>::quiet_NaN();
  T median = std::numeric_limits<T>::quiet_NaN();
  T std = std::numeric_limits<T>::quiet_NaN();
  T min = std::numeric_limits<T>::quiet_NaN();
  T max = std::numeric_limits<T>::quiet_NaN();
};

/// Statistics of values[0..n). `scratch` (optional) is reused for the median's partial sort so a
/// caller evaluating many sequences allocates once. Empty input -> TooFewPoints; any NaN/Inf ->
/// NonFinite (TUM would print nan; we refuse instead of hiding it in a mean).
/// Sums run in double whatever T is, so float errors are summarised without float round-off. Finite
/// values near the double limit, whose squares or sums overflow, are summed scaled by the largest
/// magnitude: every statistic of finite values is finite.
template <class T>
ErrorStatistics<T> compute_statistics(const T* values, std::size_t n, std::vector<T>* scratch = nullptr) {
  static_assert(std::is_floating_point<T>::value, "compute_statistics: T must be float or double");
  ErrorStatistics<T> out;
  out.count = n;
  if (n == 0 || values == nullptr) {
    out.status = Status::TooFewPoints;
    out.reason = "compute_statistics: no values";
    return out;
  }
  double sum = 0.0;
  double sum_sq = 0.0;
  double lo = static_cast<double>(values[0]);
  double hi = lo;
  for (std::size_t i = 0; i < n; ++i) {
    const double v = static_cast<double>(values[i]);
    if (!std::isfinite(v)) {
      out.status = Status::NonFinite;
      out.reason = "compute_statistics: value " + std::to_string(i) + " is not finite";
      return out;
    }
    sum += v;
    sum_sq += v * v;
    lo = v < lo ? v : lo;
    hi = v > hi ? v : hi;
  }
  const double dn = static_cast<double>(n);
  // Only when a square or a sum overflowed (values near 1e154 and beyond): rerun the sums on values
  // divided by the largest magnitude, a power of two so the scaling itself is exact.
  // ldexp, not a multiplication by 2^-exponent: 2^1024 itself is not a double.
  int exponent = 0;
  if (!std::isfinite(sum_sq) || !std::isfinite(sum)) {
    std::frexp(std::max(std::abs(lo), std::abs(hi)), &exponent);
    sum = 0.0;
    sum_sq = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const double v = std::ldexp(static_cast<double>(values[i]), -exponent);
      sum += v;
      sum_sq += v * v;
    }
  }
  const double mean = sum / dn;  // in units of 2^exponent
  // Two-pass variance (numpy: mean(|x - mean|^2)) rather than E[x^2] - mean^2, which cancels badly
  // when the spread is small against the mean.
  double sum_dev = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double d = std::ldexp(static_cast<double>(values[i]), -exponent) - mean;
    sum_dev += d * d;
  }

  std::vector<T> local;
  std::vector<T>& sorted = scratch != nullptr ? *scratch : local;
  sorted.assign(values, values + n);
  const std::size_t half = n / 2;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(half), sorted.end());
  double median = static_cast<double>(sorted[half]);
  if (n % 2 == 0) {
    // The lower middle is the largest element of the left part after nth_element.
    const double lower = static_cast<double>(
        *std::max_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(half)));
    median = 0.5 * lower + 0.5 * median;  // not (lower + median) / 2: that sum can overflow
  }

  // Rounding can put an rmse or std of values at the limit one ulp above it: clamp into T's range.
  const double top = static_cast<double>(std::numeric_limits<T>::max());
  out.rmse = static_cast<T>(std::min(std::ldexp(std::sqrt(sum_sq / dn), exponent), top));
  out.mean = static_cast<T>(std::max(std::min(std::ldexp(mean, exponent), top), -top));
  out.median = static_cast<T>(median);
  out.std = static_cast<T>(std::min(std::ldexp(std::sqrt(sum_dev / dn), exponent), top));
  out.min = static_cast<T>(lo);
  out.max = static_cast<T>(hi);
  return out;
}

/// Container overload (std::vector, std::array, Eigen vector: anything with data() and size()).
template <class Container>
auto compute_statistics(const Container& values)
    -> ErrorStatistics<std::remove_cv_t<std::remove_reference_t<decltype(*values.data())>>> {
  return compute_statistics(values.data(), static_cast<std::size_t>(values.size()));
}

/// Improvement rate of Zhu et al. 2024 eq. 7 / Zhang et al. 2023 eq. 11: (m - n) / m, with m the baseline's error and n ours
/// (0.8 = 80 % lower error). NaN when m is zero or either value is not finite: no rate exists then.
template <class T>
T improvement_rate(T baseline_m, T ours_n) {
  static_assert(std::is_floating_point<T>::value, "improvement_rate: T must be float or double");
  if (!std::isfinite(baseline_m) || !std::isfinite(ours_n) || baseline_m == T(0)) {
    return std::numeric_limits<T>::quiet_NaN();
  }
  return (baseline_m - ours_n) / baseline_m;
}

}  // namespace dyncull::eval
