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
/// Two sorted buffers swapped each frame: no allocation once they have grown to the track count.
class StaticHistory {
 public:
  /// Advances one frame over the n tracks `ids`. labels / residual_px (n each): each track's own geometric
  /// label (Static, Dynamic, or Candidate for no evidence) and residual this frame; not given (nullptr) or
  /// evaluated == false when this frame is no evidence (a baseline too short to see a slow mover, or the
  /// check did not run): the counts then carry over unchanged. A Candidate label leaves its track's count
  /// unchanged; Dynamic, a residual at or above max_residual_px, or a non-finite one resets it to 0.
  /// counts (resized to n): the track's count after this frame. A given labels or residual_px view whose
  /// size is not ids.size(): InvalidInput with the reason (if asked), nothing read, history unchanged.
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
    next_.resize(n);
    const bool evidence = evaluated && labels.given && residual_px.given;
    // Front ends usually keep their tracks in creation order (ascending ids): then one merge walk over the
    // sorted history replaces a binary search per track, and the new buffer needs no sort.
    const bool ascending = std::is_sorted(ids.begin(), ids.end());
    std::size_t walk = 0;
    for (std::size_t i = 0; i < n; ++i) {
      Entry e{ids[i], 0};
      if (ascending) {
        while (walk < entries_.size() && entries_[walk].id < ids[i]) ++walk;
        if (walk < entries_.size() && entries_[walk].id == ids[i]) e.count = entries_[walk].count;
      } else {
        e.count = previous_count(ids[i]);
      }
      if (evidence && labels[i] != FeatureLabel::Candidate) {
        const bool still = labels[i] == FeatureLabel::Static && residual_px[i] < max_residual_px;  // false for NaN
        e.count = still ? static_cast<std::uint16_t>(std::min<int>(e.count + 1, kMaxCount)) : std::uint16_t(0);
      }
      next_[i] = e;
      (*counts)[i] = e.count;
    }
    if (!ascending) std::sort(next_.begin(), next_.end(), [](const Entry& a, const Entry& b) { return a.id < b.id; });
    entries_.swap(next_);
    return Status::Ok;
  }

  /// Count of a track after the last update (0 when unknown).
  std::uint16_t count(std::int64_t id) const { return previous_count(id); }
  std::size_t num_tracks() const { return entries_.size(); }
  void clear() {
    entries_.clear();
    next_.clear();
  }

 private:
  static constexpr int kMaxCount = 0xFFFF;
  struct Entry {
    std::int64_t id = 0;
    std::uint16_t count = 0;
  };
  std::uint16_t previous_count(std::int64_t id) const {
    const auto it = std::lower_bound(entries_.begin(), entries_.end(), id,
                                     [](const Entry& e, std::int64_t v) { return e.id < v; });
    return it != entries_.end() && it->id == id ? it->count : std::uint16_t(0);
  }

  std::vector<Entry> entries_, next_;  ///< entries_: sorted by id (duplicates allowed, the first is read)
};

}  // namespace dyncull
