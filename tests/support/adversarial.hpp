// Test helper: a deterministic generator of adversarial scalars for property tests (mostly ordinary values,
// sometimes NaN, +-Inf, values near the type's max, denormals, zero or far out of range).
// Not a paper equation; draws only from dyncull::Random, so a seed fixes every case.
#pragma once

#include "dyncull/core/random.hpp"

#include <limits>

namespace dyncull::test {

// Cumulative upper bounds on one uniform draw u in [0, 1): u < nan gives NaN, else u < inf gives +Inf, ...,
// else u < scaled gives U(lo, hi) * scale, else U(lo, hi). A kind is off when its bound equals the one before.
struct AdversarialMix {
  double nan;
  double inf;
  double neg_inf;
  double huge;    // max() * U(-1, 1)
  double tiny;    // denorm_min(), times U(-tiny_spread, tiny_spread) when tiny_spread > 0
  double zero;
  double scaled;  // U(lo, hi) * scale
  double tiny_spread;
  double scale;
};

// Geometry solvers: 2% NaN, 1% +Inf, 2% huge, 1% denormal, 2% scaled by 1e20.
inline constexpr AdversarialMix kSolverMix{0.02, 0.03, 0.03, 0.05, 0.06, 0.06, 0.08, 0.0, 1e20};
// Point-set alignment: as the solver mix with signed denormal multiples and a 1e30 scale.
inline constexpr AdversarialMix kAlignmentMix{0.02, 0.03, 0.03, 0.05, 0.07, 0.07, 0.09, 100.0, 1e30};
// Statistics: 3% NaN, 2% +Inf, 2% -Inf, 3% huge, 2% denormal.
inline constexpr AdversarialMix kStatisticsMix{0.03, 0.05, 0.07, 0.10, 0.12, 0.12, 0.12, 0.0, 1.0};
// Projection: as the statistics mix plus 2% exact zero.
inline constexpr AdversarialMix kProjectionMix{0.03, 0.05, 0.07, 0.10, 0.12, 0.14, 0.14, 0.0, 1.0};

// One value from the mix; consumes one draw for the choice and at most one more for the value.
template <class T>
T adversarial_value(Random& rng, double lo, double hi, const AdversarialMix& mix) {
  const double u = rng.uniform();
  if (u < mix.nan) return std::numeric_limits<T>::quiet_NaN();
  if (u < mix.inf) return std::numeric_limits<T>::infinity();
  if (u < mix.neg_inf) return -std::numeric_limits<T>::infinity();
  if (u < mix.huge) return std::numeric_limits<T>::max() * T(rng.uniform(-1, 1));
  if (u < mix.tiny) {
    if (mix.tiny_spread > 0) {
      return std::numeric_limits<T>::denorm_min() * T(rng.uniform(-mix.tiny_spread, mix.tiny_spread));
    }
    return std::numeric_limits<T>::denorm_min();
  }
  if (u < mix.zero) return T(0);
  if (u < mix.scaled) return T(rng.uniform(lo, hi) * mix.scale);
  return T(rng.uniform(lo, hi));
}

// A value for the geometry solvers' property tests: the solver mix.
template <class T>
T solver_value(Random& rng, double lo, double hi) {
  return adversarial_value<T>(rng, lo, hi, kSolverMix);
}

}  // namespace dyncull::test
