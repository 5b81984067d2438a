/// @file descriptor_switch.hpp
/// Descriptor choice after the frame-rotation estimate (DFD-SLAM, Qian et al. 2024, §3.3: above 20° match
/// ORB by Hamming distance, below learned descriptors by L2, eq. 17), brute-force matchers for both, and
/// the nearest keyframes by L2 distance of global descriptors (§3.4, eq. 18).
#pragma once

#include "dyncull/core/status.hpp"
#include "dyncull/geometry/rotation_centre.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

namespace dyncull {

// ------------------------------------------------------------------------------------------------
// The switch (eq. 17)
// ------------------------------------------------------------------------------------------------

/// Which local descriptors the front end should match with.
enum class DescriptorKind : std::uint8_t {
  Learned = 0,  ///< HFNet / SuperPoint float descriptors, L2 distance (eq. 17)
  Orb = 1,      ///< re-extracted ORB (rotated BRIEF) 256-bit descriptors, Hamming distance
};

inline const char* to_string(DescriptorKind k) noexcept { return k == DescriptorKind::Orb ? "orb" : "learned"; }

struct DescriptorSwitchOptions {
  /// Rotation (eq. 16 angle) above which learned descriptors are abandoned. The paper sets 20° because
  /// its matching degraded from about 15°. In [0, 180].
  double switch_angle_deg = 20.0;

  /// Ok, or InvalidInput with a reason naming the field.
  Status validate(std::string* reason = nullptr) const {
    if (!(switch_angle_deg >= 0.0 && switch_angle_deg <= 180.0)) {
      if (reason) *reason = "DescriptorSwitchOptions: switch_angle_deg must be in [0, 180]";
      return Status::InvalidInput;
    }
    if (reason) reason->clear();
    return Status::Ok;
  }
};

/// ORB when a rotation was found and its eq. 16 angle exceeds the threshold; learned descriptors
/// otherwise, including when no rotation was found (Algorithm 2 line 16: "rotation did not happen").
/// The decision has no status to carry a reason: invalid options (see validate()) select Learned, the
/// choice that needs no rotation estimate.
template <class T>
DescriptorKind choose_descriptor(const RotationCentreResult<T>& rotation, const DescriptorSwitchOptions& options = {}) {
  if (options.validate() != Status::Ok) return DescriptorKind::Learned;
  return rotation.ok() && static_cast<double>(rotation.angle_deg()) > options.switch_angle_deg ? DescriptorKind::Orb
                                                                                                 : DescriptorKind::Learned;
}

/// Same decision from an angle in degrees (NaN selects Learned; so do invalid options).
inline DescriptorKind choose_descriptor(double rotation_angle_deg, const DescriptorSwitchOptions& options = {}) {
  if (options.validate() != Status::Ok) return DescriptorKind::Learned;
  return std::abs(rotation_angle_deg) > options.switch_angle_deg ? DescriptorKind::Orb : DescriptorKind::Learned;
}

// ------------------------------------------------------------------------------------------------
// Distances
// ------------------------------------------------------------------------------------------------

namespace detail {
inline std::uint64_t load_u64(const std::uint8_t* p) noexcept {
  std::uint64_t v;
  std::memcpy(&v, p, sizeof v);  // no alignment assumption (cv::Mat rows are byte arrays)
  return v;
}
/// Bit count without the POPCNT instruction (Hacker's Delight 5-2).
inline int popcount64_swar(std::uint64_t x) noexcept {
  x = x - ((x >> 1) & 0x5555555555555555ull);
  x = (x & 0x3333333333333333ull) + ((x >> 2) & 0x3333333333333333ull);
  x = (x + (x >> 4)) & 0x0F0F0F0F0F0F0F0Full;
  return static_cast<int>((x * 0x0101010101010101ull) >> 56);
}
}  // namespace detail

/// Hamming distance of two 256-bit (32-byte) descriptors, e.g. ORB rows of a CV_8UC1 N x 32 cv::Mat.
/// Single pairs use POPCNT only when the build enables it (-mpopcnt / -march); without it g++ would call
/// a slow libgcc routine, so SWAR is used. The batch matcher below dispatches at run time instead.
inline int hamming256(const std::uint8_t* a, const std::uint8_t* b) noexcept {
  int d = 0;
  for (int w = 0; w < 4; ++w) {
    const std::uint64_t x = detail::load_u64(a + 8 * w) ^ detail::load_u64(b + 8 * w);
#ifdef __POPCNT__
    d += __builtin_popcountll(x);
#else
    d += detail::popcount64_swar(x);
#endif
  }
  return d;
}

/// Squared L2 distance of two float/double descriptors of length dim (vectorised by Eigen).
template <class T>
T l2_squared(const T* a, const T* b, int dim) {
  static_assert(std::is_floating_point<T>::value, "dyncull::l2_squared: float or double descriptors");
  using Vec = Eigen::Map<const Eigen::Matrix<T, Eigen::Dynamic, 1>>;
  return (Vec(a, dim) - Vec(b, dim)).squaredNorm();
}

/// eq. 17 / eq. 18: L2 distance.
template <class T>
T l2_distance(const T* a, const T* b, int dim) {
  using std::sqrt;
  return sqrt(l2_squared(a, b, dim));
}

// ------------------------------------------------------------------------------------------------
// Brute-force matching
// ------------------------------------------------------------------------------------------------

/// Rows of 256-bit binary descriptors: row i starts at data + i * stride_bytes (cv::Mat: ptr(0), rows, step).
struct BinaryDescriptors {
  const std::uint8_t* data = nullptr;
  std::size_t rows = 0;
  std::size_t stride_bytes = 32;
  const std::uint8_t* row(std::size_t i) const { return data + i * stride_bytes; }
};

/// Rows of float descriptors of length dim; row i starts at data + i * stride (elements; 0 means dim).
template <class T>
struct FloatDescriptors {
  const T* data = nullptr;
  std::size_t rows = 0;
  int dim = 0;
  std::size_t stride = 0;
  std::size_t row_stride() const { return stride > 0 ? stride : static_cast<std::size_t>(dim); }
  const T* row(std::size_t i) const { return data + i * row_stride(); }
};

struct MatchOptions {
  /// Lowe's ratio test: keep a match only if best < ratio * second best (distances, not squared).
  /// 0 disables it. Lowe suggests 0.8; ORB-SLAM uses 0.6-0.9 depending on the stage.
  double ratio = 0.0;
  bool cross_check = false;  ///< keep i -> j only if i is also j's nearest query (cv::BFMatcher crossCheck)
  /// Matches farther than this are dropped (bits for Hamming, L2 units otherwise). ORB-SLAM: TH_LOW = 50.
  double max_distance = std::numeric_limits<double>::infinity();

  /// Ok, or InvalidInput with a reason naming the field.
  Status validate(std::string* reason = nullptr) const {
    auto bad = [&](const char* why) {
      if (reason) *reason = why;
      return Status::InvalidInput;
    };
    if (!(ratio >= 0.0 && ratio <= 1.0)) return bad("MatchOptions: ratio must be in [0, 1] (0 disables the test)");
    if (!(max_distance >= 0.0)) return bad("MatchOptions: max_distance must be >= 0 (+inf disables it)");
    if (reason) reason->clear();
    return Status::Ok;
  }
};

struct DescriptorMatch {
  std::uint32_t query = 0;
  std::uint32_t train = 0;
  float distance = 0.f;  ///< Hamming bits or L2 distance (not squared)
};

struct MatchResult {
  Status status = Status::Ok;
  std::string reason;
  std::vector<DescriptorMatch> matches;  ///< in query order, at most one per query
  std::size_t rejected_distance = 0;     ///< nearest neighbour farther than max_distance
  std::size_t rejected_ratio = 0;        ///< failed the ratio test
  std::size_t rejected_cross_check = 0;  ///< not mutual nearest neighbours
  /// Queries with no finite distance to any train row (NaN / Inf in the query or in every train row,
  /// or values so large that the squared distances overflow): a non-finite distance never matches.
  std::size_t rejected_non_finite = 0;
  bool ok() const { return status == Status::Ok; }
};

/// Brute-force nearest neighbour of every query row among the train rows by Hamming distance.
inline MatchResult match_hamming256(const BinaryDescriptors& query, const BinaryDescriptors& train,
                                    const MatchOptions& options = {});

/// Brute-force nearest neighbour by L2 (eq. 17). Query and train must have the same dim.
template <class T>
MatchResult match_l2(const FloatDescriptors<T>& query, const FloatDescriptors<T>& train, const MatchOptions& options = {});

/// One keyframe candidate of eq. 18.
struct KeyframeCandidate {
  std::size_t index = 0;  ///< row in the keyframe library
  double distance = 0;    ///< L2 distance of the global descriptors
};

struct KeyframeSearchResult {
  Status status = Status::Ok;
  std::string reason;
  std::vector<KeyframeCandidate> candidates;  ///< nearest first, at most k
  bool ok() const { return status == Status::Ok; }
};

/// The k keyframes whose global descriptors (HFNet: 4096 floats) are nearest to `query` by L2 (eq. 18).
/// Rows with a non-finite distance are skipped. Ties are broken by the lower index.
template <class T>
KeyframeSearchResult nearest_keyframes(const T* query, const FloatDescriptors<T>& library, std::size_t k);

// ------------------------------------------------------------------------------------------------
// Implementation
// ------------------------------------------------------------------------------------------------

namespace detail {

/// Best / second-best per query and best query per train row, over distances D (any ordered type).
template <class D>
struct NearestTracker {
  std::vector<D> best, second;
  std::vector<std::uint32_t> best_index;
  std::vector<D> train_best;
  std::vector<std::uint32_t> train_best_index;

  void reset(std::size_t nq, std::size_t nt, bool cross) {
    const D inf = std::numeric_limits<D>::max();
    best.assign(nq, inf);
    second.assign(nq, inf);
    best_index.assign(nq, 0);
    train_best.assign(cross ? nt : 0, inf);
    train_best_index.assign(cross ? nt : 0, 0);
  }
};

/// Turns tracked neighbours into matches. `to_distance` maps the tracked value to the reported
/// distance (identity for bits, sqrt for squared L2).
template <class D, class ToDistance>
void collect_matches(const NearestTracker<D>& t, const MatchOptions& o, bool have_train, ToDistance to_distance,
                     MatchResult* out) {
  out->matches.clear();
  if (!have_train) return;
  const std::size_t nq = t.best.size();
  out->matches.reserve(nq);
  for (std::size_t i = 0; i < nq; ++i) {
    if (t.best[i] == std::numeric_limits<D>::max()) {  // every distance was NaN: no neighbour
      ++out->rejected_non_finite;
      continue;
    }
    const double d1 = to_distance(t.best[i]);
    if (!(d1 <= o.max_distance)) {
      ++out->rejected_distance;
      continue;
    }
    if (o.ratio > 0 && t.second[i] != std::numeric_limits<D>::max() && !(d1 < o.ratio * to_distance(t.second[i]))) {
      ++out->rejected_ratio;
      continue;
    }
    const std::uint32_t j = t.best_index[i];
    if (o.cross_check && t.train_best_index[j] != i) {
      ++out->rejected_cross_check;
      continue;
    }
    out->matches.push_back(DescriptorMatch{static_cast<std::uint32_t>(i), j, static_cast<float>(d1)});
  }
}

/// Inner loop of the Hamming matcher. UseBuiltin selects __builtin_popcountll, which compiles to the
/// POPCNT instruction only inside a function built for that target; elsewhere we use SWAR.
template <bool UseBuiltin>
__attribute__((always_inline)) inline void hamming_scan(const BinaryDescriptors& query, const BinaryDescriptors& train,
                                                        bool cross, NearestTracker<int>* t) {
  const std::size_t nq = query.rows, nt = train.rows;
  int* best = t->best.data();
  int* second = t->second.data();
  std::uint32_t* best_index = t->best_index.data();
  int* train_best = cross ? t->train_best.data() : nullptr;
  std::uint32_t* train_best_index = cross ? t->train_best_index.data() : nullptr;
  for (std::size_t i = 0; i < nq; ++i) {
    const std::uint8_t* q = query.row(i);
    const std::uint64_t q0 = load_u64(q), q1 = load_u64(q + 8), q2 = load_u64(q + 16), q3 = load_u64(q + 24);
    int b1 = best[i], b2 = second[i];
    std::uint32_t bi = best_index[i];
    for (std::size_t j = 0; j < nt; ++j) {
      const std::uint8_t* r = train.row(j);
      const std::uint64_t x0 = q0 ^ load_u64(r), x1 = q1 ^ load_u64(r + 8), x2 = q2 ^ load_u64(r + 16),
                          x3 = q3 ^ load_u64(r + 24);
      int d;
      if constexpr (UseBuiltin) {
        d = __builtin_popcountll(x0) + __builtin_popcountll(x1) + __builtin_popcountll(x2) + __builtin_popcountll(x3);
      } else {
        d = popcount64_swar(x0) + popcount64_swar(x1) + popcount64_swar(x2) + popcount64_swar(x3);
      }
      if (d < b1) {
        b2 = b1;
        b1 = d;
        bi = static_cast<std::uint32_t>(j);
      } else if (d < b2) {
        b2 = d;
      }
      if (cross && d < train_best[j]) {
        train_best[j] = d;
        train_best_index[j] = static_cast<std::uint32_t>(i);
      }
    }
    best[i] = b1;
    second[i] = b2;
    best_index[i] = bi;
  }
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define DYNCULL_POPCNT_DISPATCH 1
__attribute__((target("popcnt"))) inline void hamming_scan_popcnt(const BinaryDescriptors& query,
                                                                 const BinaryDescriptors& train, bool cross,
                                                                 NearestTracker<int>* t) {
  hamming_scan<true>(query, train, cross, t);
}
inline bool cpu_has_popcnt() {
  static const bool has = __builtin_cpu_supports("popcnt");
  return has;
}
#endif

}  // namespace detail

inline MatchResult match_hamming256(const BinaryDescriptors& query, const BinaryDescriptors& train,
                                    const MatchOptions& options) {
  MatchResult out;
  if ((query.rows > 0 && query.data == nullptr) || (train.rows > 0 && train.data == nullptr) ||
      query.stride_bytes < 32 || train.stride_bytes < 32) {
    out.status = Status::InvalidInput;
    out.reason = "match_hamming256: null data or a row stride below 32 bytes";
    return out;
  }
  std::string why;
  if (options.validate(&why) != Status::Ok) {
    out.status = Status::InvalidInput;
    out.reason = "match_hamming256: " + why;
    return out;
  }
  if (query.rows > std::numeric_limits<std::uint32_t>::max() || train.rows > std::numeric_limits<std::uint32_t>::max()) {
    out.status = Status::InvalidInput;
    out.reason = "match_hamming256: more than 2^32 rows";
    return out;
  }
  detail::NearestTracker<int> t;
  t.reset(query.rows, train.rows, options.cross_check);
#ifdef DYNCULL_POPCNT_DISPATCH
  if (detail::cpu_has_popcnt()) {
    detail::hamming_scan_popcnt(query, train, options.cross_check, &t);
  } else {
    detail::hamming_scan<false>(query, train, options.cross_check, &t);
  }
#else
  detail::hamming_scan<true>(query, train, options.cross_check, &t);
#endif
  detail::collect_matches(t, options, train.rows > 0, [](int d) { return static_cast<double>(d); }, &out);
  return out;
}

template <class T>
MatchResult match_l2(const FloatDescriptors<T>& query, const FloatDescriptors<T>& train, const MatchOptions& options) {
  static_assert(std::is_floating_point<T>::value, "dyncull::match_l2: float or double descriptors");
  using RowMajor = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  using Map = Eigen::Map<const RowMajor, 0, Eigen::OuterStride<>>;
  using std::sqrt;
  MatchResult out;
  if (query.dim <= 0 || query.dim != train.dim || (query.rows > 0 && query.data == nullptr) ||
      (train.rows > 0 && train.data == nullptr) || query.row_stride() < static_cast<std::size_t>(query.dim) ||
      train.row_stride() < static_cast<std::size_t>(train.dim)) {
    out.status = Status::InvalidInput;
    out.reason = "match_l2: dims must be equal and positive, data non-null, strides >= dim";
    return out;
  }
  std::string why;
  if (options.validate(&why) != Status::Ok) {
    out.status = Status::InvalidInput;
    out.reason = "match_l2: " + why;
    return out;
  }
  if (query.rows > std::numeric_limits<std::uint32_t>::max() ||
      train.rows > std::numeric_limits<std::uint32_t>::max()) {
    out.status = Status::InvalidInput;
    out.reason = "match_l2: more than 2^32 rows";
    return out;
  }
  const Eigen::Index nq = static_cast<Eigen::Index>(query.rows), nt = static_cast<Eigen::Index>(train.rows);
  detail::NearestTracker<T> t;
  t.reset(query.rows, train.rows, options.cross_check);
  if (nq > 0 && nt > 0) {
    const Map Q(query.data, nq, query.dim, Eigen::OuterStride<>(static_cast<Eigen::Index>(query.row_stride())));
    const Map R(train.data, nt, train.dim, Eigen::OuterStride<>(static_cast<Eigen::Index>(train.row_stride())));
    // |q - r|^2 = |q|^2 + |r|^2 - 2 q.r, the cross terms by blocked matrix products (Eigen's GEMM).
    // The cancellation error is ~eps |q|^2, far below the gaps a ratio test looks at.
    const Eigen::Matrix<T, Eigen::Dynamic, 1> train_sq = R.rowwise().squaredNorm();
    constexpr Eigen::Index kBlock = 64;  // queries per product: block of 64 x nt distances stays in cache
    Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> dots(std::min(kBlock, nq), nt);
    T* best = t.best.data();
    T* second = t.second.data();
    std::uint32_t* best_index = t.best_index.data();
    for (Eigen::Index i0 = 0; i0 < nq; i0 += kBlock) {
      const Eigen::Index rows = std::min(kBlock, nq - i0);
      dots.topRows(rows).noalias() = Q.middleRows(i0, rows) * R.transpose();
      for (Eigen::Index r = 0; r < rows; ++r) {
        const Eigen::Index i = i0 + r;
        const T q_sq = Q.row(i).squaredNorm();
        const T* drow = dots.row(r).data();
        T b1 = best[i], b2 = second[i];
        std::uint32_t bi = best_index[i];
        for (Eigen::Index j = 0; j < nt; ++j) {
          // NaN / Inf in either descriptor gives a NaN (or +inf) here, which fails every comparison
          // below: a non-finite descriptor never becomes a neighbour. max(0, NaN) would give 0.
          const T e = q_sq + train_sq[j] - T(2) * drow[j];
          const T d = e < T(0) ? T(0) : e;
          if (d < b1) {
            b2 = b1;
            b1 = d;
            bi = static_cast<std::uint32_t>(j);
          } else if (d < b2) {
            b2 = d;
          }
          if (options.cross_check && d < t.train_best[static_cast<std::size_t>(j)]) {
            t.train_best[static_cast<std::size_t>(j)] = d;
            t.train_best_index[static_cast<std::size_t>(j)] = static_cast<std::uint32_t>(i);
          }
        }
        best[i] = b1;
        second[i] = b2;
        best_index[i] = bi;
      }
    }
  }
  detail::collect_matches(t, options, nt > 0, [](T d2) { return static_cast<double>(sqrt(d2)); }, &out);
  return out;
}

template <class T>
KeyframeSearchResult nearest_keyframes(const T* query, const FloatDescriptors<T>& library, std::size_t k) {
  static_assert(std::is_floating_point<T>::value, "dyncull::nearest_keyframes: float or double descriptors");
  using std::isfinite;
  KeyframeSearchResult out;
  if (query == nullptr || library.dim <= 0 || (library.rows > 0 && library.data == nullptr) ||
      library.row_stride() < static_cast<std::size_t>(library.dim)) {
    out.status = Status::InvalidInput;
    out.reason = "nearest_keyframes: null query / library or dim <= 0";
    return out;
  }
  if (library.rows == 0 || k == 0) {
    out.status = Status::TooFewPoints;
    out.reason = library.rows == 0 ? "nearest_keyframes: empty keyframe library" : "nearest_keyframes: k = 0";
    return out;
  }
  std::vector<std::pair<T, std::size_t>> all;
  all.reserve(library.rows);
  for (std::size_t i = 0; i < library.rows; ++i) {
    const T d2 = l2_squared(query, library.row(i), library.dim);
    if (isfinite(d2)) all.emplace_back(d2, i);
  }
  if (all.empty()) {
    out.status = Status::NonFinite;
    out.reason = "nearest_keyframes: every distance is non-finite (NaN in the query or the library)";
    return out;
  }
  const std::size_t kk = std::min(k, all.size());
  std::partial_sort(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(kk), all.end());
  out.candidates.reserve(kk);
  for (std::size_t i = 0; i < kk; ++i) {
    out.candidates.push_back(KeyframeCandidate{all[i].second, std::sqrt(static_cast<double>(all[i].first))});
  }
  return out;
}

}  // namespace dyncull
