/// @file static_history.hpp
/// Per-track static history (our extension, in the spirit of the last-frame state K of DLD-SLAM,
/// Yu et al. 2024, eq. 3): a track whose
/// own reprojection residual stayed small and unflagged over its last few evaluated frames is still, whatever
/// the box rule (Zhu et al. 2024 / Zhang et al. 2023) or the sub-box vote (DFD-SLAM Algorithm 1) says about the region it lies in.
#pragma once

#include "dyncull/core/flags.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/culling/labels.hpp"
#include "dyncull/culling/validation.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace dyncull {

/// When a track's history keeps it static (PipelineOptions::static_history).
template <class T>
struct StaticHistoryOptions {
  /// Evaluated frames in a row, up to and including the current one, in which the track's own check said
  /// Static with a residual below max_residual_px. A seated person's still legs share DFD-SLAM's cells
  /// with its swaying upper body: one frame's residual does not separate the two (the sway pauses, so a
  /// moving track is often under any per-frame threshold), a few frames in a row mostly do.
  int min_frames = 6;
  /// Residual (px) a frame must stay below to count; above it, or flagged, the count restarts at 0.
  T max_residual_px = T(0.8);

  /// InvalidInput naming the first field out of its range: min_frames in [1, 65535] (the counts are
  /// 16-bit), max_residual_px finite and >= 0.
  Status validate(std::string* reason = nullptr) const {
    if (min_frames < 1 || min_frames > 0xFFFF)
      return detail::invalid_option(reason, "min_frames", "must be in [1, 65535]");
    if (!detail::finite_in(max_residual_px, 0, 1e30))
      return detail::invalid_option(reason, "max_residual_px", "must be finite and >= 0");
    if (reason) reason->clear();
    return Status::Ok;
  }
};

/// Consecutive still frames per track, owned by the caller (PipelineState holds one) and advanced once per
/// frame. Tracks missing from a frame are forgotten: front ends give a lost feature's id to no other track.
/// Two hash tables of the counts by id, swapped each frame: no allocation once they have grown to the track
/// count, and no sort, whatever order the front end keeps its tracks in.
class StaticHistory {
 public:
  /// Advances one frame over the n tracks `ids`. labels / residual_px (n each): each track's own geometric
  /// label (Static, Dynamic, or Candidate for no evidence) and residual this frame; not given (nullptr) or
  /// evaluated == false when this frame is no evidence (a baseline too short to see a slow mover, or the
  /// check did not run): the counts then carry over unchanged. A Candidate label leaves its track's count
  /// unchanged; Dynamic, a residual at or above max_residual_px, or a non-finite one resets it to 0.
  /// counts (resized to n): the track's count after this frame. An id given twice in a frame: each reads
  /// the same history, and the first one's count is kept. A given labels or residual_px view whose size is
  /// not ids.size(): InvalidInput with the reason (if asked), nothing read, history unchanged.
  /// (T is deduced from max_residual_px alone, so residual_px converts from a vector or nullptr.)
  template <class T>
  Status update(const std::vector<std::int64_t>& ids, ArrayView<FeatureLabel> labels,
                ArrayView<std::common_type_t<T>> residual_px, bool evaluated, T max_residual_px,
                std::vector<std::uint16_t>* counts, std::string* reason = nullptr) {
    const std::size_t n = ids.size();
    std::string why;
    if (!detail::flags_fit(labels, n, "labels", "track ids", &why) ||
        !detail::flags_fit(residual_px, n, "residual_px", "track ids", &why)) {
      if (reason) *reason = why;
      return Status::InvalidInput;
    }
    if (reason) reason->clear();
    counts->resize(n);
    next_.empty_for(n);
    const bool evidence = evaluated && labels.given && residual_px.given;
    for (std::size_t i = 0; i < n; ++i) {
      std::uint16_t count = last_.find(ids[i]);
      if (evidence && labels[i] != FeatureLabel::Candidate) {
        const bool still = labels[i] == FeatureLabel::Static && residual_px[i] < max_residual_px;  // false for NaN
        count = still ? static_cast<std::uint16_t>(std::min<int>(count + 1, kMaxCount)) : std::uint16_t(0);
      }
      next_.insert_first(ids[i], count);
      (*counts)[i] = count;
    }
    std::swap(last_, next_);
    num_tracks_ = n;
    return Status::Ok;
  }

  /// Count of a track after the last update (0 when unknown).
  std::uint16_t count(std::int64_t id) const { return last_.find(id); }
  /// Tracks given to the last update (an id given twice counts twice).
  std::size_t num_tracks() const { return num_tracks_; }
  void clear() {
    last_.empty_for(0);
    next_.empty_for(0);
    num_tracks_ = 0;
  }

 private:
  static constexpr int kMaxCount = 0xFFFF;

  /// Open addressing with linear probing, at most half full. A slot is taken when its stamp is the
  /// table's: emptying the table is one increment, not a pass over it.
  class Table {
   public:
    /// Empties the table and makes room for n ids.
    void empty_for(std::size_t n) {
      std::size_t capacity = 16;
      int bits = 4;
      while (capacity < 2 * n) {
        capacity *= 2;
        ++bits;
      }
      if (capacity > slots_.size()) {
        slots_.assign(capacity, Slot());
        bits_ = bits;
        stamp_ = 0;
      }
      if (++stamp_ == 0) {  // wrapped after 2^32 frames: stale stamps could match again
        for (Slot& s : slots_) s.stamp = 0;
        stamp_ = 1;
      }
    }
    std::uint16_t find(std::int64_t id) const {
      if (slots_.empty()) return 0;
      for (std::size_t i = home(id);; i = (i + 1) & mask()) {
        const Slot& s = slots_[i];
        if (s.stamp != stamp_) return 0;
        if (s.id == id) return s.count;
      }
    }
    /// Stores id's count unless id is already in the table.
    void insert_first(std::int64_t id, std::uint16_t count) {
      for (std::size_t i = home(id);; i = (i + 1) & mask()) {
        Slot& s = slots_[i];
        if (s.stamp != stamp_) {
          s = Slot{id, stamp_, count};
          return;
        }
        if (s.id == id) return;
      }
    }

   private:
    struct Slot {
      std::int64_t id = 0;
      std::uint32_t stamp = 0;
      std::uint16_t count = 0;
    };
    std::size_t mask() const { return slots_.size() - 1; }
    /// Fibonacci hashing: front ends number their tracks consecutively, and the multiply spreads them.
    std::size_t home(std::int64_t id) const {
      return static_cast<std::size_t>((static_cast<std::uint64_t>(id) * 0x9E3779B97F4A7C15ull) >> (64 - bits_));
    }

    std::vector<Slot> slots_;
    int bits_ = 4;
    std::uint32_t stamp_ = 0;
  };

  Table last_, next_;
  std::size_t num_tracks_ = 0;
};

}  // namespace dyncull
