/// @file keyframe_matcher.hpp
/// Correspondences of the current frame's binary-descriptor keypoints to a reference keyframe by guided
/// matching: each keyframe point is predicted in the current image through the predicted pose and its
/// depth, u = pi(R X + t) (Mur-Artal, Montiel & Tardos 2015, ORB-SLAM §V-B, the guided search of the
/// previous frame's points), then matched by Hamming distance (Rublee et al. 2011, ORB) among the
/// current keypoints within a radius, with the nearest / second-nearest ratio test (Lowe 2004) and a
/// mutual check. A search examines at most max_candidates keypoints, so the cost stays linear in the
/// keypoints however they cluster (ORB-SLAM's extractor bounds the features per grid cell for the same end).
///
/// API:
///   KeyframeMatchWorkspace<float> ws;  KeyframeMatchResult<float> r;   // reused every frame
///   match_to_keyframe(kf_keypoints, kf_points, DescriptorRows(kf_desc.data, n_kf, kf_desc.step),
///                     cur_keypoints, DescriptorRows(cur_desc.data, n_cur, cur_desc.step),
///                     camera, &cam_from_keyframe /* or nullptr */, options, ws, &r);
///   r.keyframe_index[i]: keyframe keypoint matched to current keypoint i, or -1.
#pragma once

#include "dyncull/core/camera.hpp"
#include "dyncull/core/pixel.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/core/traits.hpp"
#include "dyncull/core/types.hpp"
#include "dyncull/core/views.hpp"
#include "dyncull/geometry/point_grid.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace dyncull {

struct KeyframeMatchOptions {
  /// Search radius (px) around a keyframe point's prediction through the pose and its depth: the pose
  /// prediction's error plus keypoint noise. ORB-SLAM2's search from the previous frame uses 15 px at
  /// the finest pyramid level for monocular and RGB-D input. In (0, 4096].
  double radius_px = 15.0;
  /// Search radius (px) when the prediction has no depth (rotation only, or the same pixel when no pose
  /// is given): the whole inter-frame parallax must fit in it. In (0, 4096].
  double radius_unpredicted_px = 40.0;
  /// Largest Hamming distance accepted for a match, in bits; ORB-SLAM accepts 100 of 256 in its search by
  /// projection and 50 for its tighter searches. In [0, 8 * row_bytes], at most 2048.
  int max_hamming = 80;
  /// Nearest / second-nearest ratio: a keyframe point is matched only when best <= ratio * second among
  /// its candidates (ORB-SLAM's 0.9 for guided search, 0.8 in Lowe 2004). 1 disables the test. In (0, 1].
  double ratio = 0.9;
  /// Side (px) of the grid cells the current keypoints are bucketed in; a radius of about a cell visits
  /// 3 x 3 cells. The grid has at most 256 cells per side: a larger keypoint spread widens the cells.
  static constexpr double kGridCellPx = 16.0;
  /// Most current keypoints one keyframe point's search examines: when the grid cells its disc overlaps
  /// hold more, an even subsample of them (every k-th in cell order) is examined instead, and the search
  /// is counted in KeyframeMatchResult::searches_capped. Bounds the work by n_kf * max_candidates when
  /// keypoints cluster (thousands in a few pixels); cv::ORB's 1000 features of a 640 x 480 frame put at
  /// most 512 in the cells of one 40 px search. Why you would change it: a tighter time budget per frame
  /// with many more keypoints. In [1, 2^20].
  std::size_t max_candidates = 1024;

  static constexpr std::size_t kMaxCandidatesLimit = std::size_t(1) << 20;

  /// Ok, or InvalidInput with the reason naming the field.
  Status validate(std::string* reason = nullptr) const {
    auto bad = [&](const char* field, const char* why) {
      if (reason) *reason = std::string("KeyframeMatchOptions: ") + field + " " + why;
      return Status::InvalidInput;
    };
    if (!(radius_px > 0.0 && radius_px <= 4096.0)) return bad("radius_px", "must be in (0, 4096]");
    if (!(radius_unpredicted_px > 0.0 && radius_unpredicted_px <= 4096.0))
      return bad("radius_unpredicted_px", "must be in (0, 4096]");
    if (max_hamming < 0 || max_hamming > 2048) return bad("max_hamming", "must be in [0, 2048]");
    if (!(ratio > 0.0 && ratio <= 1.0)) return bad("ratio", "must be in (0, 1]");
    if (max_candidates < 1 || max_candidates > kMaxCandidatesLimit)
      return bad("max_candidates", "must be in [1, 2^20]");
    if (reason) reason->clear();
    return Status::Ok;
  }
};

/// Per current keypoint: its keyframe correspondence. Vectors are parallel to the current keypoints
/// (resized on every call, also on a non-Ok status: then every entry says "no match").
template <class T>
struct KeyframeMatchResult {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }

  std::vector<int> keyframe_index;     ///< matched keyframe keypoint, -1 for none
  std::vector<Vec2<T>> keyframe_pixel; ///< that keypoint's position in the keyframe; NaN for none
  std::vector<int> distance;           ///< Hamming distance of the pair in bits, -1 for none

  std::size_t matched = 0;
  std::size_t predicted_by_depth = 0;     ///< keyframe points predicted through the pose and their depth
  std::size_t predicted_without_depth = 0;///< predicted by rotation only, or the same pixel without a pose
  std::size_t behind_camera = 0;          ///< keyframe points the predicted pose puts behind the camera
  std::size_t keyframe_nonfinite = 0;     ///< keyframe keypoints with a NaN / Inf coordinate (not matched)
  std::size_t current_nonfinite = 0;      ///< current keypoints with a NaN / Inf coordinate (not matched)
  std::size_t examined = 0;         ///< current keypoints the searches examined (at most n_kf * max_candidates)
  std::size_t searches_capped = 0;  ///< searches that examined a subsample of their cells (max_candidates)
  bool used_pose = false;           ///< a predicted pose was given and used
};

/// Buffers reused across calls: after the first frames of a sequence no call allocates.
template <class T>
struct KeyframeMatchWorkspace {
  std::vector<T> cur_x, cur_y;                 // current keypoints (NaN marks a non-finite one)
  std::vector<T> pred_x, pred_y;               // keyframe points' predictions (NaN: not searched)
  std::vector<std::uint8_t> pred_depth;        // 1: predicted through depth (radius_px)
  PointGrid<T> grid;                           // the current keypoints' grid (geometry/point_grid.hpp)
  std::vector<T> sorted_x, sorted_y;           // finite current keypoints in cell order
  std::vector<std::uint32_t> sorted_index;     // sorted position -> current keypoint index
  std::vector<std::uint8_t> sorted_desc;       // their descriptor rows, row_bytes apart
  std::vector<int> kf_best_cur, kf_best_dist;  // per keyframe point: nearest sorted position, -1 none
  std::vector<int> kf_second_dist;             // and the second-nearest distance
  std::vector<int> cur_best_kf, cur_best_dist; // per sorted position: nearest keyframe point that searched it
};

namespace detail {

inline std::uint64_t kfm_load_u64(const std::uint8_t* p) noexcept {
  std::uint64_t v;
  std::memcpy(&v, p, sizeof v);  // cv::Mat rows carry no alignment promise
  return v;
}

inline int kfm_popcount_swar(std::uint64_t x) noexcept {
  x = x - ((x >> 1) & 0x5555555555555555ull);
  x = (x & 0x3333333333333333ull) + ((x >> 2) & 0x3333333333333333ull);
  x = (x + (x >> 4)) & 0x0F0F0F0F0F0F0F0Full;
  return static_cast<int>((x * 0x0101010101010101ull) >> 56);
}

/// Plain data the scan reads: the keyframe predictions and the current keypoints sorted by grid cell
/// (positions, original indices and descriptor rows contiguous per cell row).
template <class T>
struct KfmScan {
  const T* pred_x;  // per keyframe point, NaN = do not search
  const T* pred_y;
  const std::uint8_t* pred_depth;  // 1: radius_px, 0: radius_unpredicted_px
  std::size_t n_kf;
  const T* cur_x;  // sorted by cell
  const T* cur_y;
  const std::uint32_t* cur_index;  // sorted position -> current keypoint index
  DescriptorRows kf_desc;
  const std::uint8_t* cur_desc;  // sorted rows, row_bytes apart
  std::size_t row_bytes;
  T r2_depth, r2_free, r_depth, r_free;
  T grid_x0, grid_y0, cell;
  int cols, rows;
  const std::uint32_t* cell_start;  // sorted positions of cell c: [cell_start[c], cell_start[c + 1])
  int* kf_best_cur;                 // sorted position, -1 none
  int* kf_best_dist;
  int* kf_second_dist;
  int* cur_best_kf;  // by sorted position
  int* cur_best_dist;
  std::uint32_t max_candidates;  // most sorted positions one search examines
};

/// The work of a scan: positions examined, searches subsampled.
struct KfmWork {
  std::size_t examined = 0, capped = 0;
};

/// Cell index along one axis, clamped in the floating type before the int conversion (NaN -> 0).
template <class T>
inline int kfm_cell(T v, T origin, T cell, int count) {
  return clamped_int((v - origin) / cell, 0, count - 1);
}

template <bool UseBuiltin>
inline int kfm_popcount(std::uint64_t x) noexcept {
  return UseBuiltin ? __builtin_popcountll(x) : kfm_popcount_swar(x);
}

/// Hamming distance of two rows of any length (whole words, then the tail bytes).
template <bool UseBuiltin>
inline int kfm_hamming(const std::uint8_t* a, const std::uint8_t* b, std::size_t row_bytes) {
  const std::size_t words = row_bytes / 8;
  int d = 0;
  for (std::size_t w = 0; w < words; ++w) d += kfm_popcount<UseBuiltin>(kfm_load_u64(a + 8 * w) ^ kfm_load_u64(b + 8 * w));
  for (std::size_t k = 8 * words; k < row_bytes; ++k) d += kfm_popcount_swar(static_cast<std::uint64_t>(a[k] ^ b[k]));
  return d;
}

/// Hamming distance of a row of sizeof...(W) words held in `a` (loaded once per search) to row `b`,
/// unrolled (g++ -O2 keeps a counted loop of four).
template <bool UseBuiltin, std::size_t... W>
inline int kfm_hamming_words(const std::uint64_t* a, const std::uint8_t* b, std::index_sequence<W...>) {
  return (0 + ... + kfm_popcount<UseBuiltin>(a[W] ^ kfm_load_u64(b + 8 * W)));
}

/// For every keyframe point: the nearest (ties: lowest current index) and second-nearest current
/// keypoints in its search disc; for every current keypoint: the nearest keyframe point (ties: lowest
/// index) among those whose disc held it. A search whose cells hold more than max_candidates keypoints
/// examines every step-th of them (step = ceil(held / max_candidates)).
template <class T, bool UseBuiltin, int kWords>
#if defined(__GNUC__) || defined(__clang__)
__attribute__((always_inline))
#endif
inline KfmWork kfm_scan_impl(const KfmScan<T>& s) {
  KfmWork work;
  for (std::size_t k = 0; k < s.n_kf; ++k) {
    const T px = s.pred_x[k], py = s.pred_y[k];
    if (!(px == px) || !(py == py)) continue;  // NaN: not searched
    const T r = s.pred_depth[k] ? s.r_depth : s.r_free;
    const T r2 = s.pred_depth[k] ? s.r2_depth : s.r2_free;
    const int c0 = kfm_cell(px - r, s.grid_x0, s.cell, s.cols), c1 = kfm_cell(px + r, s.grid_x0, s.cell, s.cols);
    const int q0 = kfm_cell(py - r, s.grid_y0, s.cell, s.rows), q1 = kfm_cell(py + r, s.grid_y0, s.cell, s.rows);
    const std::uint8_t* kd = s.kf_desc.row(k);
    std::uint64_t kw[kWords > 0 ? kWords : 1];
    for (int w = 0; w < kWords; ++w) kw[w] = kfm_load_u64(kd + 8 * w);
    // Key = distance << 32 | current index: one comparison orders by distance, then index. The updates
    // are selects, not branches: which candidate wins is unpredictable.
    std::uint64_t best = std::numeric_limits<std::uint64_t>::max();
    int best_d = std::numeric_limits<int>::max(), second = std::numeric_limits<int>::max(), best_pos = -1;
    std::uint32_t hits[64];
    // Cells c0..c1 of grid row q are one contiguous run of sorted positions.
    auto run_begin = [&](int q) { return s.cell_start[static_cast<std::size_t>(q) * std::size_t(s.cols) + std::size_t(c0)]; };
    auto run_end = [&](int q) { return s.cell_start[static_cast<std::size_t>(q) * std::size_t(s.cols) + std::size_t(c1) + 1]; };
    std::size_t held = 0;
    for (int q = q0; q <= q1; ++q) held += run_end(q) - run_begin(q);
    const std::size_t step = held > s.max_candidates ? (held + s.max_candidates - 1) / s.max_candidates : 1;
    auto compare = [&](std::uint32_t i) {
      const std::size_t row_bytes = kWords > 0 ? 8 * std::size_t(kWords) : s.row_bytes;
      const std::uint8_t* row = s.cur_desc + std::size_t(i) * row_bytes;
      int d;
      if constexpr (kWords > 0) d = kfm_hamming_words<UseBuiltin>(kw, row, std::make_index_sequence<std::size_t(kWords)>());
      else d = kfm_hamming<UseBuiltin>(kd, row, s.row_bytes);
      const std::uint64_t key = (static_cast<std::uint64_t>(d) << 32) | s.cur_index[i];
      const bool better = key < best;
      const int loser = better ? best_d : d;  // best_d <= second always
      second = loser < second ? loser : second;
      best = better ? key : best;
      best_d = better ? d : best_d;
      best_pos = better ? static_cast<int>(i) : best_pos;
      // Keyframe points come in ascending order: ties keep the lower one.
      const int cur = s.cur_best_dist[i];
      const bool nearer = d < cur;
      s.cur_best_dist[i] = nearer ? d : cur;
      s.cur_best_kf[i] = nearer ? static_cast<int>(k) : s.cur_best_kf[i];
    };
    if (step == 1) {
      work.examined += held;
      for (int q = q0; q <= q1; ++q) {
        const std::uint32_t end = run_end(q);
        for (std::uint32_t a = run_begin(q); a < end; a += 64) {
          const std::uint32_t b = end - a > 64 ? a + 64 : end;
          // Branch-free compaction of the keypoints inside the disc.
          std::uint32_t nh = 0;
          for (std::uint32_t i = a; i < b; ++i) {
            const T dx = s.cur_x[i] - px, dy = s.cur_y[i] - py;
            hits[nh] = i;
            nh += (dx * dx + dy * dy <= r2) ? 1u : 0u;
          }
          for (std::uint32_t h = 0; h < nh; ++h) compare(hits[h]);
        }
      }
    } else {
      // Every step-th position of the runs taken end to end: at most max_candidates, spread over the disc.
      ++work.capped;
      std::size_t offset = 0;  // into the next run, carried over from the last
      for (int q = q0; q <= q1; ++q) {
        const std::size_t begin = run_begin(q), end = run_end(q);
        std::size_t i = begin + offset;
        for (; i < end; i += step) {
          ++work.examined;
          const T dx = s.cur_x[i] - px, dy = s.cur_y[i] - py;
          if (dx * dx + dy * dy <= r2) compare(static_cast<std::uint32_t>(i));
        }
        offset = i - end;  // i >= end here
      }
    }
    s.kf_best_cur[k] = best_pos;
    s.kf_best_dist[k] = best_pos >= 0 ? best_d : -1;
    s.kf_second_dist[k] = second;
  }
  return work;
}

template <class T, bool UseBuiltin>
#if defined(__GNUC__) || defined(__clang__)
__attribute__((always_inline))
#endif
inline KfmWork kfm_scan_words(const KfmScan<T>& s) {
  if (s.row_bytes == 32) return kfm_scan_impl<T, UseBuiltin, 4>(s);
  return kfm_scan_impl<T, UseBuiltin, 0>(s);
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__)) && !defined(__POPCNT__)
#define DYNCULL_KFM_POPCNT_DISPATCH 1
// Baseline x86-64 has no POPCNT: __builtin_popcountll would call a library routine. The scan is compiled
// twice and the POPCNT one chosen at run time.
template <class T>
__attribute__((target("popcnt"))) KfmWork kfm_scan_popcnt(const KfmScan<T>& s) {
  return kfm_scan_words<T, true>(s);
}
template <class T>
KfmWork kfm_scan_portable(const KfmScan<T>& s) {
  return kfm_scan_words<T, false>(s);
}
inline bool kfm_cpu_has_popcnt() {
  static const bool has = __builtin_cpu_supports("popcnt");
  return has;
}
#endif

template <class T>
KfmWork kfm_scan(const KfmScan<T>& s) {
#ifdef DYNCULL_KFM_POPCNT_DISPATCH
  if (kfm_cpu_has_popcnt()) return kfm_scan_popcnt<T>(s);
  return kfm_scan_portable<T>(s);
#else
  return kfm_scan_words<T, true>(s);
#endif
}

inline bool kfm_rows_ok(const DescriptorRows& d, std::size_t n, const char* name, std::string* reason) {
  if (d.rows != n) {
    *reason = std::string(name) + " has " + std::to_string(d.rows) + " rows for " + std::to_string(n) + " keypoints";
    return false;
  }
  if (n > 0 && d.data == nullptr) {
    *reason = std::string(name) + ": data is null with " + std::to_string(n) + " rows";
    return false;
  }
  if (d.row_bytes == 0 || d.row_bytes > 256) {
    *reason = std::string(name) + ": row_bytes must be in [1, 256], got " + std::to_string(d.row_bytes);
    return false;
  }
  if (d.stride() < d.row_bytes) {
    *reason = std::string(name) + ": stride_bytes " + std::to_string(d.stride_bytes) + " is below row_bytes " +
              std::to_string(d.row_bytes) + ": rows would overlap";
    return false;
  }
  return true;
}

/// Keeps T deduced from the camera alone, so a literal nullptr pose is accepted.
template <class X>
struct kfm_identity {
  using type = X;
};

template <class V>
void kfm_fill(std::vector<V>& v, std::size_t n, const V& value) {
  v.resize(n);  // keeps the capacity: no allocation once grown
  for (auto& x : v) x = value;
}

/// Every current keypoint unmatched and every count zero: the result before any work (and of a refusal).
template <class T>
void kfm_reset(std::size_t n, KeyframeMatchResult<T>* out) {
  KeyframeMatchResult<T>& r = *out;
  r.status = Status::Ok;
  r.reason.clear();
  r.matched = r.predicted_by_depth = r.predicted_without_depth = r.behind_camera = 0;
  r.keyframe_nonfinite = r.current_nonfinite = 0;
  r.examined = r.searches_capped = 0;
  r.used_pose = false;
  const T nan = std::numeric_limits<T>::quiet_NaN();
  kfm_fill(r.keyframe_index, n, -1);
  kfm_fill(r.keyframe_pixel, n, Vec2<T>(nan, nan));
  kfm_fill(r.distance, n, -1);
}

/// The input contract of match_to_keyframe(); false with the status set and the reason naming the input.
template <class T>
bool kfm_inputs_ok(std::size_t n_kf, std::size_t n_kf_points, DescriptorRows kf_desc, std::size_t n,
                   DescriptorRows cur_desc, const PinholeCamera<T>& camera, const Rigid3<T>* cam_from_keyframe,
                   const KeyframeMatchOptions& options, KeyframeMatchResult<T>* r) {
  auto fail = [&](Status s, const std::string& why) {
    r->status = s;
    r->reason = "match_to_keyframe: " + why;
    return false;
  };
  std::string why;
  if (options.validate(&why) != Status::Ok) return fail(Status::InvalidInput, why);
  if (!camera.valid()) return fail(Status::InvalidInput, "camera needs finite, positive focal lengths, a finite "
                                                         "principal point and a positive image size");
  if (n_kf_points != 0 && n_kf_points != n_kf)
    return fail(Status::InvalidInput, "kf_points has " + std::to_string(n_kf_points) + " points for " +
                                          std::to_string(n_kf) + " keyframe keypoints (give one per keypoint, or none)");
  if (!kfm_rows_ok(kf_desc, n_kf, "kf_desc", &why)) return fail(Status::InvalidInput, why);
  if (!kfm_rows_ok(cur_desc, n, "cur_desc", &why)) return fail(Status::InvalidInput, why);
  if (kf_desc.row_bytes != cur_desc.row_bytes)
    return fail(Status::InvalidInput, "kf_desc rows have " + std::to_string(kf_desc.row_bytes) +
                                          " bytes, cur_desc rows " + std::to_string(cur_desc.row_bytes));
  if (static_cast<std::size_t>(options.max_hamming) > 8 * kf_desc.row_bytes)
    return fail(Status::InvalidInput, "KeyframeMatchOptions: max_hamming " + std::to_string(options.max_hamming) +
                                          " exceeds the descriptor's " + std::to_string(8 * kf_desc.row_bytes) +
                                          " bits");
  if (n > std::numeric_limits<std::uint32_t>::max() - 1 ||
      n_kf > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    return fail(Status::InvalidInput, "more keypoints than the matcher indexes (2^31)");
  if (cam_from_keyframe != nullptr && !cam_from_keyframe->all_finite())
    return fail(Status::NonFinite, "cam_from_keyframe has a NaN or Inf entry");
  if (n_kf == 0) return fail(Status::TooFewPoints, "the keyframe has no keypoints");
  if (n == 0) return fail(Status::TooFewPoints, "the current frame has no keypoints");
  return true;
}

/// Reads the current keypoints once (NaN marks a non-finite one) and sorts them by grid cell, so that
/// positions, indices and descriptor rows are contiguous per cell and a search reads one run of memory
/// per grid row. The grid spans the keypoints' own extent, not the camera's image size (which may be
/// bogus): keypoints off the image are still found.
template <class T, class CurKeypoints>
void kfm_sort_current(const CurKeypoints& cur_keypoints, DescriptorRows cur_desc, KeyframeMatchWorkspace<T>& ws,
                      KeyframeMatchResult<T>* r) {
  const std::size_t n = cur_keypoints.size();
  ws.cur_x.resize(n);
  ws.cur_y.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const T x = point_x<T>(cur_keypoints[i]), y = point_y<T>(cur_keypoints[i]);
    const bool finite = std::isfinite(x) && std::isfinite(y);
    ws.cur_x[i] = finite ? x : std::numeric_limits<T>::quiet_NaN();
    ws.cur_y[i] = finite ? y : std::numeric_limits<T>::quiet_NaN();
    r->current_nonfinite += finite ? 0 : 1;
  }
  constexpr int kMaxCellsPerSide = 256;
  size_point_grid(ws.cur_x.data(), ws.cur_y.data(), n, KeyframeMatchOptions::kGridCellPx, kMaxCellsPerSide, &ws.grid);
  const std::size_t n_sorted = n - r->current_nonfinite;
  const std::size_t row_bytes = cur_desc.row_bytes;
  ws.sorted_x.resize(n_sorted);
  ws.sorted_y.resize(n_sorted);
  ws.sorted_index.resize(n_sorted);
  ws.sorted_desc.resize(n_sorted * row_bytes);
  sort_by_cell(&ws.grid, [&](std::size_t i, std::uint32_t pos) {
    ws.sorted_x[pos] = ws.cur_x[i];
    ws.sorted_y[pos] = ws.cur_y[i];
    ws.sorted_index[pos] = static_cast<std::uint32_t>(i);
    std::memcpy(ws.sorted_desc.data() + std::size_t(pos) * row_bytes, cur_desc.row(i), row_bytes);
  });
}

/// Where keyframe point k is searched: through its depth and the pose (1 in pred_depth), along its ray
/// rotated by the pose's infinite homography K R K^-1 without depth, or at its own pixel without a pose;
/// NaN when it is not searched (non-finite, or the pose puts it behind the camera).
template <class T, class KfKeypoints, class KfPoints>
void kfm_predict(const KfKeypoints& kf_keypoints, const KfPoints& kf_points, const PinholeCamera<T>& camera,
                 const Rigid3<T>* cam_from_keyframe, KeyframeMatchWorkspace<T>& ws, KeyframeMatchResult<T>* out) {
  KeyframeMatchResult<T>& r = *out;
  const std::size_t n_kf = kf_keypoints.size();
  const T nan = std::numeric_limits<T>::quiet_NaN();
  ws.pred_x.resize(n_kf);
  ws.pred_y.resize(n_kf);
  ws.pred_depth.resize(n_kf);
  const bool have_depth = kf_points.size() == n_kf;
  const bool have_pose = cam_from_keyframe != nullptr;
  r.used_pose = have_pose;
  Mat3<T> H = Mat3<T>::Identity();
  if (have_pose) H = camera.K() * cam_from_keyframe->R * camera.K().inverse();
  for (std::size_t k = 0; k < n_kf; ++k) {
    const T u = point_x<T>(kf_keypoints[k]), v = point_y<T>(kf_keypoints[k]);
    ws.pred_x[k] = ws.pred_y[k] = nan;
    ws.pred_depth[k] = 0;
    if (!std::isfinite(u) || !std::isfinite(v)) {
      ++r.keyframe_nonfinite;
      continue;
    }
    Vec3<T> X(nan, nan, nan);
    if (have_pose && have_depth) X = Vec3<T>(point_x<T>(kf_points[k]), point_y<T>(kf_points[k]), point_z<T>(kf_points[k]));
    Vec2<T> p(u, v);  // without a pose: the same pixel
    if (have_pose && X.allFinite() && X.z() > T(0)) {
      const Vec3<T> Xc = cam_from_keyframe->apply(X);
      if (Xc.z() > T(0)) p = camera.project(Xc);  // a point at z ~ 0 projects to Inf: not searched below
      else p = Vec2<T>(nan, nan);
      ws.pred_depth[k] = 1;
    } else if (have_pose) {
      const Vec3<T> h = H * Vec3<T>(u, v, T(1));
      p = h.z() > T(0) ? Vec2<T>(h.x() / h.z(), h.y() / h.z()) : Vec2<T>(nan, nan);  // turned over 90 degrees
    }
    if (!p.allFinite()) {
      ws.pred_depth[k] = 0;
      ++r.behind_camera;
      continue;
    }
    ws.pred_x[k] = p.x();
    ws.pred_y[k] = p.y();
    ++(ws.pred_depth[k] ? r.predicted_by_depth : r.predicted_without_depth);
  }
}

/// The radius search of every predicted keyframe point over the sorted current keypoints (kfm_scan):
/// the nearest and second-nearest distance per keyframe point, the nearest keyframe point per keypoint.
template <class T>
void kfm_search(DescriptorRows kf_desc, std::size_t row_bytes, const KeyframeMatchOptions& options,
                KeyframeMatchWorkspace<T>& ws, KeyframeMatchResult<T>* r) {
  const std::size_t n_kf = ws.pred_x.size(), n_sorted = ws.sorted_index.size();
  kfm_fill(ws.kf_best_cur, n_kf, -1);
  kfm_fill(ws.kf_second_dist, n_kf, std::numeric_limits<int>::max());
  kfm_fill(ws.kf_best_dist, n_kf, -1);
  kfm_fill(ws.cur_best_kf, n_sorted, -1);
  kfm_fill(ws.cur_best_dist, n_sorted, std::numeric_limits<int>::max());
  KfmScan<T> s;
  s.pred_x = ws.pred_x.data();
  s.pred_y = ws.pred_y.data();
  s.pred_depth = ws.pred_depth.data();
  s.n_kf = n_kf;
  s.cur_x = ws.sorted_x.data();
  s.cur_y = ws.sorted_y.data();
  s.cur_index = ws.sorted_index.data();
  s.kf_desc = kf_desc;
  s.cur_desc = ws.sorted_desc.data();
  s.row_bytes = row_bytes;
  s.r_depth = static_cast<T>(options.radius_px);
  s.r_free = static_cast<T>(options.radius_unpredicted_px);
  s.r2_depth = s.r_depth * s.r_depth;
  s.r2_free = s.r_free * s.r_free;
  s.grid_x0 = ws.grid.x0;
  s.grid_y0 = ws.grid.y0;
  s.cell = ws.grid.cell;
  s.cols = ws.grid.cols;
  s.rows = ws.grid.rows;
  s.cell_start = ws.grid.cell_start.data();
  s.kf_best_cur = ws.kf_best_cur.data();
  s.kf_best_dist = ws.kf_best_dist.data();
  s.kf_second_dist = ws.kf_second_dist.data();
  s.cur_best_kf = ws.cur_best_kf.data();
  s.cur_best_dist = ws.cur_best_dist.data();
  s.max_candidates = static_cast<std::uint32_t>(options.max_candidates);  // at most 2^20 (validate)
  const KfmWork work = kfm_scan(s);
  r->examined = work.examined;
  r->searches_capped = work.capped;
}

/// Accepts a keyframe point's nearest keypoint on distance and ratio (Lowe's test against its second
/// nearest) and only when the keypoint's nearest over all keyframe points that searched it is that point
/// (mutual); a keypoint claimed by several keyframe points keeps the closest (the earliest on a tie).
template <class T, class KfKeypoints>
void kfm_accept(const KfKeypoints& kf_keypoints, const KeyframeMatchOptions& options,
                const KeyframeMatchWorkspace<T>& ws, KeyframeMatchResult<T>* out) {
  KeyframeMatchResult<T>& r = *out;
  for (std::size_t k = 0; k < ws.kf_best_cur.size(); ++k) {
    const int c = ws.kf_best_cur[k];
    if (c < 0) continue;
    const int d = ws.kf_best_dist[k], second = ws.kf_second_dist[k];
    if (d > options.max_hamming) continue;
    if (second != std::numeric_limits<int>::max() && !(double(d) <= options.ratio * double(second))) continue;
    if (ws.cur_best_kf[static_cast<std::size_t>(c)] != static_cast<int>(k)) continue;
    const std::size_t ci = ws.sorted_index[static_cast<std::size_t>(c)];
    if (r.keyframe_index[ci] >= 0 && r.distance[ci] <= d) continue;
    if (r.keyframe_index[ci] < 0) ++r.matched;
    r.keyframe_index[ci] = static_cast<int>(k);
    r.distance[ci] = d;
    r.keyframe_pixel[ci] = Vec2<T>(point_x<T>(kf_keypoints[k]), point_y<T>(kf_keypoints[k]));
  }
}

}  // namespace detail

/// Matches the current keypoints to the keyframe's (see the file comment). Inputs:
/// - kf_keypoints (n_kf points, keyframe pixels) with kf_desc (n_kf rows); kf_points: the keyframe
///   keypoints' 3-D points in the keyframe camera frame (n_kf points, NaN / z <= 0 for no depth) or an
///   empty container (no depth at all: monocular);
/// - cur_keypoints (n points, current pixels) with cur_desc (n rows, the same row_bytes);
/// - camera: the pinhole model both keypoint sets follow (pass undistorted keypoints for a distorted
///   camera; opencv/frame.hpp has undistort_keypoints);
/// - cam_from_keyframe: the predicted pose of the current camera from the keyframe camera, or nullptr.
/// A keyframe point with depth and a pose is searched within radius_px of its projection; without depth
/// but with a pose, around its rotated ray (the prediction of a point at infinity), and without a pose
/// around the same pixel, both within radius_unpredicted_px. Points the pose puts behind the camera are
/// not searched. Non-finite keypoints are never matched.
/// Status: InvalidInput (options, camera, sizes, descriptor rows: the reason names the input), NonFinite
/// (a non-finite pose), TooFewPoints (no keyframe or no current keypoints); every non-Ok status leaves
/// every current keypoint unmatched. `out`'s vectors are sized to the current keypoints in all cases.
template <class T, class KfKeypoints, class KfPoints, class CurKeypoints>
void match_to_keyframe(const KfKeypoints& kf_keypoints, const KfPoints& kf_points, DescriptorRows kf_desc,
                       const CurKeypoints& cur_keypoints, DescriptorRows cur_desc, const PinholeCamera<T>& camera,
                       const typename detail::kfm_identity<Rigid3<T>>::type* cam_from_keyframe,
                       const KeyframeMatchOptions& options,
                       KeyframeMatchWorkspace<T>& ws, KeyframeMatchResult<T>* out) {
  static_assert(std::is_floating_point<T>::value, "dyncull::match_to_keyframe: T is float or double");
  static_assert(is_point_container_v<KfKeypoints> && is_point_container_v<CurKeypoints>,
                "dyncull::match_to_keyframe: keypoints must be containers of points (PointTraits)");
  static_assert(is_point_container_v<KfPoints> && PointTraits<container_point_t<KfPoints>>::dim == 3,
                "dyncull::match_to_keyframe: kf_points must be a container of 3-D points");
  KeyframeMatchResult<T>& r = *out;
  detail::kfm_reset(cur_keypoints.size(), &r);
  if (!detail::kfm_inputs_ok(kf_keypoints.size(), kf_points.size(), kf_desc, cur_keypoints.size(), cur_desc, camera,
                             cam_from_keyframe, options, &r))
    return;
  detail::kfm_sort_current(cur_keypoints, cur_desc, ws, &r);
  detail::kfm_predict(kf_keypoints, kf_points, camera, cam_from_keyframe, ws, &r);
  detail::kfm_search(kf_desc, cur_desc.row_bytes, options, ws, &r);
  detail::kfm_accept(kf_keypoints, options, ws, &r);
}

/// Convenience form that allocates its workspace and result (tests, one-off calls).
template <class T, class KfKeypoints, class KfPoints, class CurKeypoints>
KeyframeMatchResult<T> match_to_keyframe(const KfKeypoints& kf_keypoints, const KfPoints& kf_points,
                                         DescriptorRows kf_desc, const CurKeypoints& cur_keypoints,
                                         DescriptorRows cur_desc, const PinholeCamera<T>& camera,
                                         const typename detail::kfm_identity<Rigid3<T>>::type* cam_from_keyframe,
                                         const KeyframeMatchOptions& options = {}) {
  KeyframeMatchWorkspace<T> ws;
  KeyframeMatchResult<T> r;
  match_to_keyframe(kf_keypoints, kf_points, kf_desc, cur_keypoints, cur_desc, camera, cam_from_keyframe, options, ws,
                    &r);
  return r;
}

}  // namespace dyncull
