/// @file subbox_memory.hpp
/// Temporal memory of the sub-box vote (003 Algorithm 1 across frames; our extension, in the spirit of
/// 000's last-frame state K): a sub-box whose own features voted it dynamic stays dynamic for a few frames
/// in the same tracked box, for the tracks that showed motion themselves in that time or are younger
/// than it. 003 votes every frame afresh, so a slow mover is kept whenever its motion pauses (a seated
/// person's sway turning round) and its new corners, which have no history, are kept too.
#pragma once

#include "dyncull/core/flags.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/culling/labels.hpp"
#include "dyncull/culling/subbox_refine.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

namespace dyncull {

/// Memory of the sub-box votes, owned by the caller (PipelineState holds one). Frames are counted by
/// the caller (any increasing counter). Boxes are identified by their box-tracker id, features by
/// their track id; boxes without an id (-1) have no memory.
class SubBoxMemory {
 public:
  /// Flags, per feature, the tracks a remembered cell may cull: flagged dynamic by the geometric check, or
  /// first seen, in this frame or one of the `frames` frames before it.
  /// Records this frame's geometric flags and forgets tracks unseen for more than `frames` frames.
  /// geometric: optional (not given: no track is flagged); given with a size other than track_ids.size():
  /// InvalidInput with `reason` naming it and both sizes, nothing recorded and no track eligible.
  Status update_tracks(const std::vector<std::int64_t>& track_ids, ArrayView<FeatureLabel> geometric,
                       std::uint64_t frame, int frames, std::vector<std::uint8_t>* eligible,
                       std::string* reason = nullptr) {
    const std::size_t n = track_ids.size();
    eligible->assign(n, 0);
    if (!detail::flags_fit(geometric, n, "geometric", "tracks", reason)) return Status::InvalidInput;
    const auto window = static_cast<std::uint64_t>(std::max(frames, 0));
    for (std::size_t i = 0; i < n; ++i) {
      TrackHistory& h = tracks_[track_ids[i]];
      if (h.first_seen == 0) h.first_seen = frame;
      h.last_seen = frame;
      if (geometric.given && geometric[i] == FeatureLabel::Dynamic) h.last_flagged = frame;
      const bool flagged = h.last_flagged != 0 && frame - h.last_flagged <= window;
      const bool young = frame - h.first_seen <= window;
      (*eligible)[i] = flagged || young;
    }
    for (auto it = tracks_.begin(); it != tracks_.end();)
      it = frame - it->second.last_seen > window ? tracks_.erase(it) : std::next(it);
    return Status::Ok;
  }

  /// Cells (per box grid*grid, box-major like SubBoxResult::cells) that a vote of the last `frames`
  /// frames before `frame` made dynamic in the same tracked box. A grid outside [1, 8] recalls nothing
  /// (cells cleared).
  void recall(const std::vector<std::int64_t>& box_ids, int grid, std::uint64_t frame, int frames,
              std::vector<std::uint8_t>* cells) const {
    if (!grid_ok(grid)) {  // no cells to recall: empty, not a huge or wrapped allocation
      cells->clear();
      return;
    }
    const std::size_t cpb = static_cast<std::size_t>(grid) * static_cast<std::size_t>(grid);
    cells->assign(box_ids.size() * cpb, 0);
    const auto window = static_cast<std::uint64_t>(std::max(frames, 0));
    for (std::size_t b = 0; b < box_ids.size(); ++b) {
      const BoxCells* m = find(box_ids[b]);
      if (!m) continue;
      for (std::size_t c = 0; c < cpb; ++c)
        (*cells)[b * cpb + c] = m->last_dynamic[c] != 0 && m->last_dynamic[c] < frame && frame - m->last_dynamic[c] <= window;
    }
  }

  /// Stores the cells this frame's own votes made dynamic (detail::subbox_cell_vote; not merged
  /// cells, not the whole-box rule: those are inferences, remembering them would spread them) and
  /// forgets boxes unseen for more than `frames` frames.
  template <class T>
  void remember(const std::vector<std::int64_t>& box_ids, const SubBoxResult<T>& votes, const SubBoxOptions<T>& options,
                std::uint64_t frame, int frames) {
    if (!grid_ok(options.grid) || (votes.grid != 0 && votes.grid != options.grid)) return;
    const std::size_t cpb = static_cast<std::size_t>(options.grid) * static_cast<std::size_t>(options.grid);
    if (votes.dyn_count.size() < box_ids.size() * cpb || votes.static_count.size() < box_ids.size() * cpb) return;
    for (std::size_t b = 0; b < box_ids.size(); ++b) {
      if (box_ids[b] < 0) continue;
      BoxCells* m = find(box_ids[b]);
      if (!m) {
        boxes_.push_back(BoxCells{});
        m = &boxes_.back();
        m->id = box_ids[b];
      }
      m->last_seen = frame;
      for (std::size_t c = 0; c < cpb; ++c)
        if (detail::subbox_cell_vote(votes.dyn_count[b * cpb + c], votes.static_count[b * cpb + c], options) == 1)
          m->last_dynamic[c] = frame;
    }
    const auto window = static_cast<std::uint64_t>(std::max(frames, 0));
    boxes_.erase(std::remove_if(boxes_.begin(), boxes_.end(),
                                [&](const BoxCells& m) { return frame - m.last_seen > window; }),
                 boxes_.end());
  }

  /// Stores the final state of every cell of this frame's vote per tracked box, for a later frame whose
  /// own baseline is too short to vote (PipelineOptions::min_evidence_frames): 1 dynamic (voted, merged
  /// or whole box), 0 static with unanimous evidence (none of its features flagged), 2 otherwise (no
  /// evidence, or static by a split vote: not trusted beyond its frame). Forgets boxes not stored for
  /// `frames` frames.
  template <class T>
  void remember_states(const std::vector<std::int64_t>& box_ids, const SubBoxResult<T>& votes,
                       const SubBoxOptions<T>& options, std::uint64_t frame, int frames) {
    if (!grid_ok(options.grid) || (votes.grid != 0 && votes.grid != options.grid)) return;
    const std::size_t cpb = static_cast<std::size_t>(options.grid) * static_cast<std::size_t>(options.grid);
    if (votes.cells.size() < box_ids.size() * cpb || votes.dyn_count.size() < box_ids.size() * cpb ||
        votes.static_count.size() < box_ids.size() * cpb)
      return;
    for (std::size_t b = 0; b < box_ids.size(); ++b) {
      if (box_ids[b] < 0) continue;
      auto it = std::find_if(states_.begin(), states_.end(), [&](const BoxStates& m) { return m.id == box_ids[b]; });
      if (it == states_.end()) it = states_.insert(states_.end(), BoxStates{});
      it->id = box_ids[b];
      it->frame = frame;
      for (std::size_t c = 0; c < cpb; ++c) {
        const std::size_t k = b * cpb + c;
        const std::uint8_t vote = detail::subbox_cell_vote(votes.dyn_count[k], votes.static_count[k], options);
        it->state[c] = votes.cells[k] || vote == 1 ? 1 : vote == 2 || votes.dyn_count[k] > 0 ? 2 : 0;
      }
    }
    const auto window = static_cast<std::uint64_t>(std::max(frames, 0));
    states_.erase(std::remove_if(states_.begin(), states_.end(),
                                 [&](const BoxStates& m) { return frame - m.frame > window; }),
                  states_.end());
  }

  /// Cell states (as remember_states) of the last stored vote of each tracked box within `frames` frames
  /// before `frame`, box-major; 2 (unknown) for boxes without one. Returns how many boxes had one.
  std::size_t recall_states(const std::vector<std::int64_t>& box_ids, int grid, std::uint64_t frame, int frames,
                            std::vector<std::uint8_t>* states) const {
    if (!grid_ok(grid)) {
      states->clear();
      return 0;
    }
    const std::size_t cpb = static_cast<std::size_t>(grid) * static_cast<std::size_t>(grid);
    states->assign(box_ids.size() * cpb, 2);
    const auto window = static_cast<std::uint64_t>(std::max(frames, 0));
    std::size_t found = 0;
    for (std::size_t b = 0; b < box_ids.size(); ++b) {
      if (box_ids[b] < 0) continue;
      for (const BoxStates& m : states_) {
        if (m.id != box_ids[b] || m.frame >= frame || frame - m.frame > window) continue;
        std::copy(m.state, m.state + cpb, states->begin() + static_cast<std::ptrdiff_t>(b * cpb));
        ++found;
        break;
      }
    }
    return found;
  }

  void clear() {
    boxes_.clear();
    tracks_.clear();
    states_.clear();
  }
  std::size_t num_boxes() const { return boxes_.size(); }
  std::size_t num_tracks() const { return tracks_.size(); }

 private:
  static constexpr std::size_t kMaxCells = 64;  ///< SubBoxOptions::grid is at most 8
  static bool grid_ok(int grid) { return grid >= 1 && grid <= 8; }
  struct BoxCells {
    std::int64_t id = -1;
    std::uint64_t last_seen = 0;
    std::uint64_t last_dynamic[kMaxCells] = {};  ///< frame of the last own dynamic vote, 0 = never
  };
  struct TrackHistory {
    std::uint64_t first_seen = 0, last_seen = 0, last_flagged = 0;  ///< 0 = never
  };

  const BoxCells* find(std::int64_t id) const {
    if (id < 0) return nullptr;
    for (const BoxCells& m : boxes_)
      if (m.id == id) return &m;
    return nullptr;
  }
  BoxCells* find(std::int64_t id) { return const_cast<BoxCells*>(static_cast<const SubBoxMemory*>(this)->find(id)); }

  struct BoxStates {
    std::int64_t id = -1;
    std::uint64_t frame = 0;
    std::uint8_t state[kMaxCells] = {};
  };

  std::vector<BoxCells> boxes_;  ///< a handful of tracked boxes: a linear search is enough
  std::unordered_map<std::int64_t, TrackHistory> tracks_;
  std::vector<BoxStates> states_;  ///< remember_states
};

}  // namespace dyncull
