/// @file ransac.hpp
/// Generic LO-RANSAC with MSAC scoring (Torr & Zisserman 2000; Chum et al. 2003 local optimisation),
/// templated on an estimator; the adaptive stopping rule is k = log(1 - p) / log(1 - w^s) (Fischler & Bolles).
#pragma once

#include "dyncull/core/random.hpp"
#include "dyncull/core/status.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace dyncull {

namespace detail {
/// "Outer: member.field ..." from a nested struct's "Inner: field ..." reason, so the reason names the
/// field as the caller spells it (FundamentalOptions: ransac.max_residual ...).
inline std::string nested_reason(const char* outer, const char* member, const std::string& inner) {
  const std::size_t colon = inner.find(": ");
  return std::string(outer) + ": " + member + "." + (colon == std::string::npos ? inner : inner.substr(colon + 2));
}
}  // namespace detail

/// Options shared by every RANSAC in dyncull (F, PnP, rigid alignment).
struct RansacOptions {
  double max_residual = 1.0;      ///< inlier threshold in the estimator's residual units (NOT squared)
  double confidence = 0.99;       ///< probability p of drawing at least one all-inlier sample; in [0, 1]
  /// Bounds on drawn samples: 1 <= max_iterations <= kMaxIterations, min_iterations <= max_iterations.
  std::size_t min_iterations = 0, max_iterations = 10000;
  std::uint64_t seed = 0;         ///< deterministic for a seed (the generator is owned by the call)
  bool local_optimisation = true; ///< refit on inliers when a new best model is found, and at the end

  /// Largest accepted max_iterations: 1e7 samples bound one call to seconds, never hours.
  static constexpr std::size_t kMaxIterations = 10000000;

  /// Ok, or InvalidInput with a reason naming the field.
  Status validate(std::string* reason = nullptr) const {
    auto fail = [&](const char* why) {
      if (reason) *reason = why;
      return Status::InvalidInput;
    };
    if (!(max_residual > 0.0) || !std::isfinite(max_residual))
      return fail("RansacOptions: max_residual must be finite and > 0");
    if (!(confidence >= 0.0 && confidence <= 1.0)) return fail("RansacOptions: confidence must be in [0, 1]");
    if (max_iterations == 0 || max_iterations > kMaxIterations)
      return fail("RansacOptions: max_iterations must be in [1, 1e7]");
    if (min_iterations > max_iterations) return fail("RansacOptions: min_iterations must be <= max_iterations");
    if (reason) reason->clear();
    return Status::Ok;
  }
};

/// Result of ransac(). `score` is the MSAC cost sum_i min(r_i^2, t^2) of `model` (lower is better,
/// squared residual units); `inlier_mask[i]` is 1 when r_i < max_residual.
template <class Model>
struct RansacResult {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }

  Model model{};
  std::vector<std::uint8_t> inlier_mask;
  std::size_t num_inliers = 0;
  std::size_t iterations = 0;  ///< samples drawn
  double score = 0;
};

/// Number of samples needed so that, with probability `confidence`, at least one sample of size
/// `sample_size` is all-inlier when a fraction `inlier_ratio` of the data are inliers.
/// Guards: confidence <= 0 or inlier_ratio >= 1 -> 1; confidence >= 1, inlier_ratio <= 0 or a
/// sample probability that underflows -> max_iterations. The result is clamped to [1, max_iterations].
inline std::size_t ransac_required_iterations(double inlier_ratio, int sample_size, double confidence,
                                              std::size_t max_iterations) {
  const std::size_t cap = std::max<std::size_t>(max_iterations, 1);
  if (!(confidence > 0.0)) return 1;
  if (!(inlier_ratio > 0.0) || !(confidence < 1.0) || sample_size <= 0) return cap;
  if (inlier_ratio >= 1.0) return 1;
  const double all_inlier = std::pow(inlier_ratio, sample_size);
  // log1p keeps precision when w^s is tiny; a zero denominator means the sample probability underflowed.
  const double denom = std::log1p(-all_inlier);
  if (!(denom < 0.0)) return cap;
  const double k = std::ceil(std::log1p(-confidence) / denom);
  if (!(k < static_cast<double>(cap))) return cap;
  return std::max<std::size_t>(1, static_cast<std::size_t>(k));  // checked: 0 < k < cap
}

/// Buffers a RANSAC reuses from call to call (residuals and inlier indices, one entry per datum): a caller
/// that keeps one across frames allocates nothing once they have reached the largest data size.
template <class Scalar>
struct RansacWorkspace {
  std::vector<Scalar> residuals;
  std::vector<std::uint32_t> inliers;
};

namespace detail {
template <class...> using ransac_void_t = void;

template <class E, class = void> struct has_model_type : std::false_type {};
template <class E> struct has_model_type<E, ransac_void_t<typename E::Model>> : std::true_type {};

template <class E, class = void> struct has_scalar_type : std::false_type {};
template <class E> struct has_scalar_type<E, ransac_void_t<typename E::Scalar>> : std::true_type {};

template <class E, class = void> struct has_sample_size : std::false_type {};
template <class E>
struct has_sample_size<E, ransac_void_t<decltype(static_cast<int>(E::kSampleSize)),
                                        decltype(static_cast<int>(E::kMaxModels))>> : std::true_type {};

template <class E, class = void> struct has_num_data : std::false_type {};
template <class E>
struct has_num_data<E, ransac_void_t<decltype(static_cast<std::size_t>(std::declval<const E&>().num_data()))>>
    : std::true_type {};

template <class E, class = void> struct has_minimal_solve : std::false_type {};
template <class E>
struct has_minimal_solve<E, ransac_void_t<decltype(static_cast<int>(std::declval<const E&>().minimal_solve(
                                std::declval<const std::uint32_t*>(), std::declval<typename E::Model*>())))>>
    : std::true_type {};

template <class E, class = void> struct has_residuals_sq : std::false_type {};
template <class E>
struct has_residuals_sq<E, ransac_void_t<decltype(std::declval<const E&>().residuals_sq(
                               std::declval<const typename E::Model&>(), std::declval<typename E::Scalar*>()))>>
    : std::true_type {};

template <class E, class = void> struct has_refit : std::false_type {};
template <class E>
struct has_refit<E, ransac_void_t<decltype(static_cast<bool>(std::declval<const E&>().refit(
                        std::declval<const std::uint32_t*>(), std::size_t{}, std::declval<typename E::Model*>())))>>
    : std::true_type {};

/// Optional: reject a sample before solving (collinear, duplicate, ...).
template <class E, class = void> struct has_is_sample_good : std::false_type {};
template <class E>
struct has_is_sample_good<E, ransac_void_t<decltype(static_cast<bool>(
                                 std::declval<const E&>().is_sample_good(std::declval<const std::uint32_t*>())))>>
    : std::true_type {};

/// Optional: residuals of data [begin, end) into out[0, end - begin). Enables early bail-out while
/// scoring a model that can no longer beat the best one.
template <class E, class = void> struct has_range_residuals_sq : std::false_type {};
template <class E>
struct has_range_residuals_sq<E, ransac_void_t<decltype(std::declval<const E&>().residuals_sq(
                                     std::declval<const typename E::Model&>(), std::size_t{}, std::size_t{},
                                     std::declval<typename E::Scalar*>()))>> : std::true_type {};

/// Optional: residuals of the data at idx[0, n) into out[0, n). Enables the probe pre-test (below).
template <class E, class = void> struct has_indexed_residuals_sq : std::false_type {};
template <class E>
struct has_indexed_residuals_sq<E, ransac_void_t<decltype(std::declval<const E&>().residuals_sq(
                                       std::declval<const typename E::Model&>(), std::declval<const std::uint32_t*>(),
                                       std::size_t{}, std::declval<typename E::Scalar*>()))>> : std::true_type {};

template <class Estimator>
class RansacRunner {
 public:
  using Model = typename Estimator::Model;
  using Scalar = typename Estimator::Scalar;
  static constexpr int kSampleSize = Estimator::kSampleSize;
  static constexpr int kMaxModels = Estimator::kMaxModels;
  static constexpr std::size_t kChunk = 128;  // bail-out granularity: small enough to stop early, large enough to vectorise
  // Probe pre-test (a T(d,d) test, Chum & Matas 2002, with d = kProbe fixed random data): once a best model
  // with inlier ratio w exists, a hypothesis is scored only if at least w d - 3.5 sqrt(d w (1 - w)) of the
  // probe are inliers. A model as good as the best fails it with probability < 1e-3; a wrong one (few
  // inliers) fails after d residuals instead of hundreds.
  static constexpr std::size_t kProbe = 32;

  RansacRunner(const Estimator& estimator, const RansacOptions& options, RansacWorkspace<Scalar>* workspace)
      : est_(estimator), opt_(options), n_(estimator.num_data()), residuals_(workspace->residuals),
        inliers_(workspace->inliers) {
    thr_sq_ = static_cast<Scalar>(opt_.max_residual * opt_.max_residual);
    lo_min_support_ = std::max<std::size_t>(2 * static_cast<std::size_t>(kSampleSize), n_ / 10);
    residuals_.resize(n_);
    inliers_.resize(n_);
  }

  /// Writes into `out`, reset by the caller (its buffers are reused).
  void run(RansacResult<Model>* out) {
    RansacResult<Model>& result = *out;
    Random rng(opt_.seed);
    std::uint32_t sample[kSampleSize];
    Model models[kMaxModels];
    bool have_best = false;
    double best_cost = std::numeric_limits<double>::infinity();
    std::size_t best_inliers = 0;
    std::size_t required = opt_.max_iterations;
    std::size_t it = 0;
    std::size_t solver_failures = 0;

    constexpr bool kCanProbe = has_indexed_residuals_sq<Estimator>::value;
    const bool use_probe = kCanProbe && n_ >= 4 * kProbe;
    std::uint32_t probe[kProbe];
    std::size_t probe_min = 0;
    if (use_probe)
      for (std::size_t i = 0; i < kProbe; ++i) probe[i] = rng.index(static_cast<std::uint32_t>(n_));

    while (it < opt_.max_iterations && (it < required || it < opt_.min_iterations)) {
      ++it;
      draw_sample(rng, sample);
      if (!sample_good(sample)) continue;
      const int m = est_.minimal_solve(sample, models);
      if (m <= 0) {
        ++solver_failures;
        continue;
      }
      for (int k = 0; k < std::min(m, kMaxModels); ++k) {
        if constexpr (kCanProbe) {
          if (use_probe && have_best && !passes_probe(models[k], probe, probe_min)) continue;
        }
        const double cost = score(models[k], best_cost);
        if (!(cost < best_cost)) continue;
        best_cost = cost;
        result.model = models[k];
        lo_converged_ = false;
        best_inliers = count_inliers();
        have_best = true;
        // LO on a model supported by under 10 % of the data (and under two samples) is wasted: on F it took
        // ~17 of ~23 refits per call to polish junk models on their way to the real one. The final LO still runs.
        if (opt_.local_optimisation && best_inliers >= lo_min_support_)
          local_optimise(&result.model, &best_cost, &best_inliers, true);
        const double w = static_cast<double>(best_inliers) / static_cast<double>(n_);
        required = ransac_required_iterations(w, kSampleSize, opt_.confidence, opt_.max_iterations);
        const double d = static_cast<double>(kProbe);
        const double bound = w * d - 3.5 * std::sqrt(d * w * (1.0 - w));
        probe_min = bound > 0 ? static_cast<std::size_t>(bound) : 0;  // checked: bound <= w * kProbe
      }
    }
    result.iterations = it;

    if (!have_best) {
      result.status = Status::Degenerate;
      result.reason = "no minimal sample produced a model (" + std::to_string(solver_failures) + " of " +
                      std::to_string(it) + " samples failed in the solver; degenerate or non-finite data)";
      return;
    }
    // Final LO, unless the kept model is already the fixed point of an LO run.
    if (opt_.local_optimisation && !lo_converged_) local_optimise(&result.model, &best_cost, &best_inliers, false);

    label_by_model(&result);
  }

 private:
  /// The probe pre-test: true when at least probe_min of the probe data are inliers of `model`.
  bool passes_probe(const Model& model, const std::uint32_t* probe, std::size_t probe_min) const {
    Scalar probe_res[kProbe];
    est_.residuals_sq(model, probe, kProbe, probe_res);
    std::size_t hits = 0;
    for (std::size_t i = 0; i < kProbe; ++i) hits += probe_res[i] < thr_sq_;
    return hits >= probe_min;
  }

  /// Final labelling from the kept model (the residual buffer may hold a rejected refit): inlier mask,
  /// count and MSAC score; Degenerate when the model has fewer inliers than a minimal sample.
  void label_by_model(RansacResult<Model>* out) {
    RansacResult<Model>& result = *out;
    est_.residuals_sq(result.model, residuals_.data());
    result.inlier_mask.assign(n_, 0);
    std::size_t count = 0;
    double cost = 0;
    for (std::size_t i = 0; i < n_; ++i) {
      const Scalar r = residuals_[i];
      const bool in = r < thr_sq_;
      result.inlier_mask[i] = static_cast<std::uint8_t>(in);
      count += in;
      cost += static_cast<double>(in ? r : thr_sq_);
    }
    result.num_inliers = count;
    result.score = cost;
    if (count < static_cast<std::size_t>(kSampleSize)) {
      result.status = Status::Degenerate;
      result.reason = "best model has " + std::to_string(count) + " inliers, fewer than the minimal sample (" +
                      std::to_string(kSampleSize) + ")";
    }
  }

  void draw_sample(Random& rng, std::uint32_t* sample) {
    const auto n = static_cast<std::uint32_t>(n_);
    for (int i = 0; i < kSampleSize; ++i) {
      bool again = true;
      while (again) {
        sample[i] = rng.index(n);
        again = false;
        for (int j = 0; j < i; ++j) again = again || sample[j] == sample[i];
      }
    }
  }

  bool sample_good(const std::uint32_t* sample) const {
    if constexpr (has_is_sample_good<Estimator>::value) {
      return est_.is_sample_good(sample);
    } else {
      (void)sample;
      return true;
    }
  }

  /// MSAC cost of `model`; stops early (returning +inf) once the cost exceeds `bound`.
  double score(const Model& model, double bound) {
    const Scalar thr = thr_sq_;
    if constexpr (has_range_residuals_sq<Estimator>::value) {
      double cost = 0;
      for (std::size_t begin = 0; begin < n_; begin += kChunk) {
        const std::size_t end = std::min(n_, begin + kChunk);
        Scalar* r = residuals_.data() + begin;
        est_.residuals_sq(model, begin, end, r);
        cost += clamped_sum(r, end - begin, thr);
        if (cost >= bound) return std::numeric_limits<double>::infinity();
      }
      return cost;
    } else {
      est_.residuals_sq(model, residuals_.data());
      (void)bound;
      return clamped_sum(residuals_.data(), n_, thr);
    }
  }

  /// sum_i min(r_i, thr) with NaN -> thr. A single-accumulator float loop cannot vectorise (the compiler
  /// may not reorder the additions) and was 14 % of F-RANSAC time.
  static double clamped_sum(const Scalar* r, std::size_t len, Scalar thr) {
    // Eight independent accumulators: no loop-carried add latency, and g++ -O3 vectorises it. The select
    // `r < thr ? r : thr` maps NaN to thr (an outlier), which Eigen's vectorised min would not.
    Scalar acc[8] = {};
    std::size_t i = 0;
    for (; i + 8 <= len; i += 8)
      for (int j = 0; j < 8; ++j) acc[j] += r[i + j] < thr ? r[i + j] : thr;
    for (; i < len; ++i) acc[0] += r[i] < thr ? r[i] : thr;
    return static_cast<double>(((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7])));
  }

  /// Counts inliers in residuals_ (valid after a complete score()).
  std::size_t count_inliers() const {
    const Scalar thr = thr_sq_;
    const Scalar* r = residuals_.data();
    const std::size_t n = n_;
    std::size_t count = 0;
    for (std::size_t i = 0; i < n; ++i) count += r[i] < thr;
    return count;
  }

  std::size_t collect_inliers(Scalar thr) {
    std::size_t count = 0;
    for (std::size_t i = 0; i < n_; ++i) {
      inliers_[count] = static_cast<std::uint32_t>(i);
      count += residuals_[i] < thr;
    }
    return count;
  }

  /// Iterated least-squares refit on the inliers while the MSAC cost decreases (LO step).
  /// `residuals_valid`: residuals_ already holds the residuals of *best (right after a full score()).
  void local_optimise(Model* best, double* best_cost, std::size_t* best_inliers, bool residuals_valid) {
    // Iterated least squares with a shrinking threshold (Lebeda et al. 2012, LO+): the first refits take
    // inliers up to 2x and 1.5x the threshold, so a rough minimal model reaches the full inlier set in a
    // few steps instead of creeping up (which also keeps the adaptive iteration count from staying high).
    // Each refit starts from the previous refit (kept or not); the best by MSAC cost is kept.
    constexpr int kMaxRefits = 20;  // climbing from a rough model can take ~10 refits; a converged one exits at r = 2
    constexpr Scalar kWiden[3] = {Scalar(4), Scalar(2.25), Scalar(1)};  // squared threshold multipliers
    lo_converged_ = false;
    if (!residuals_valid) est_.residuals_sq(*best, residuals_.data());
    Model current = *best;
    std::size_t previous = 0;
    for (int r = 0; r < kMaxRefits; ++r) {
      const std::size_t count = collect_inliers(thr_sq_ * kWiden[r < 2 ? r : 2]);
      if (r >= 2 && count == previous) {  // same inlier set at the final threshold: fixed point
        lo_converged_ = true;
        return;
      }
      previous = count;
      if (count < static_cast<std::size_t>(kSampleSize)) return;
      if (!est_.refit(inliers_.data(), count, &current)) return;
      est_.residuals_sq(current, residuals_.data());
      const double cost = clamped_sum(residuals_.data(), n_, thr_sq_);
      if (cost < *best_cost) {
        *best = current;
        *best_cost = cost;
        *best_inliers = count_inliers();
      } else if (r >= 2) {  // no gain at the final threshold
        lo_converged_ = true;
        return;
      }
    }
  }

  const Estimator& est_;
  const RansacOptions& opt_;
  std::size_t n_;
  Scalar thr_sq_;
  std::vector<Scalar>& residuals_;
  std::vector<std::uint32_t>& inliers_;
  bool lo_converged_ = false;  // the best model is an LO fixed point: a further refit cannot improve it
  std::size_t lo_min_support_ = 0;  // inliers a new best needs before it is locally optimised
};
}  // namespace detail

/// Runs LO-RANSAC with MSAC scoring on `estimator`. Estimator concept:
///   using Model = ...; using Scalar = float|double;
///   static constexpr int kSampleSize; static constexpr int kMaxModels;
///   std::size_t num_data() const;
///   int minimal_solve(const std::uint32_t* sample, Model* models) const;   // returns the number of models written
///   void residuals_sq(const Model& m, Scalar* out) const;                   // all data, contiguous
///   bool refit(const std::uint32_t* inliers, std::size_t n, Model* model) const;
///   optional: bool is_sample_good(const std::uint32_t* sample) const;
///   optional: void residuals_sq(const Model& m, std::size_t begin, std::size_t end, Scalar* out) const;
///   optional: void residuals_sq(const Model& m, const std::uint32_t* idx, std::size_t n, Scalar* out) const;
/// The range overload enables early bail-out while scoring, the indexed one a 32-point pre-test of each
/// hypothesis. LO runs for new bests with at least max(2 kSampleSize, n / 10) inliers, and once at the end.
/// Residuals are squared; NaN residuals count as outliers. Deterministic for options.seed.
/// Writes into `out`; its buffers and the workspace's are reused, so a caller that keeps both across calls
/// allocates nothing once they have grown to the largest data size (reasons of failures aside).
template <class Estimator>
void ransac(const Estimator& estimator, const RansacOptions& options,
            RansacWorkspace<typename Estimator::Scalar>* workspace, RansacResult<typename Estimator::Model>* out) {
  static_assert(detail::has_model_type<Estimator>::value, "dyncull::ransac: Estimator needs `using Model = ...;`");
  static_assert(detail::has_scalar_type<Estimator>::value,
                "dyncull::ransac: Estimator needs `using Scalar = float|double;`");
  static_assert(std::is_floating_point<typename Estimator::Scalar>::value,
                "dyncull::ransac: Estimator::Scalar must be float or double");
  static_assert(detail::has_sample_size<Estimator>::value,
                "dyncull::ransac: Estimator needs `static constexpr int kSampleSize` and `kMaxModels`");
  static_assert(detail::has_num_data<Estimator>::value,
                "dyncull::ransac: Estimator needs `std::size_t num_data() const`");
  static_assert(detail::has_minimal_solve<Estimator>::value,
                "dyncull::ransac: Estimator needs `int minimal_solve(const std::uint32_t*, Model*) const`");
  static_assert(detail::has_residuals_sq<Estimator>::value,
                "dyncull::ransac: Estimator needs `void residuals_sq(const Model&, Scalar*) const`");
  static_assert(detail::has_refit<Estimator>::value,
                "dyncull::ransac: Estimator needs `bool refit(const std::uint32_t*, std::size_t, Model*) const`");

  RansacResult<typename Estimator::Model>& result = *out;
  result.status = Status::Ok;
  result.reason.clear();
  result.inlier_mask.clear();
  result.num_inliers = result.iterations = 0;
  result.score = 0;
  if (options.validate(&result.reason) != Status::Ok) {
    result.status = Status::InvalidInput;
    return;
  }
  if (Estimator::kSampleSize <= 0 || Estimator::kMaxModels <= 0) {
    result.status = Status::InvalidInput;
    result.reason = "estimator kSampleSize and kMaxModels must be positive";
    return;
  }
  const std::size_t n = estimator.num_data();
  if (n < static_cast<std::size_t>(Estimator::kSampleSize)) {
    result.status = Status::TooFewPoints;
    result.reason = std::to_string(n) + " data, the minimal sample needs " + std::to_string(Estimator::kSampleSize);
    result.inlier_mask.assign(n, 0);
    return;
  }
  if (n > static_cast<std::size_t>(std::numeric_limits<std::uint32_t>::max())) {
    result.status = Status::InvalidInput;
    result.reason = "more than 2^32 - 1 data";
    return;
  }
  detail::RansacRunner<Estimator> runner(estimator, options, workspace);
  runner.run(&result);
}

/// Convenience overload with its own workspace and a fresh result.
template <class Estimator>
RansacResult<typename Estimator::Model> ransac(const Estimator& estimator, const RansacOptions& options) {
  RansacWorkspace<typename Estimator::Scalar> workspace;
  RansacResult<typename Estimator::Model> result;
  ransac(estimator, options, &workspace, &result);
  return result;
}

}  // namespace dyncull
