/// @file subbox_memory.hpp
/// The last sub-box vote (DFD-SLAM, Qian et al. 2024, Algorithm 1) of each tracked box, kept for a frame
/// whose baseline is too short to vote: a seated person's still legs stay static where its last vote said
/// so, instead of the box rule culling the whole person. No paper equation of its own.
#pragma once

#include "dyncull/core/flags.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/culling/labels.hpp"
#include "dyncull/culling/subbox_refine.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace dyncull {

/// Last sub-box votes per tracked box, owned by the caller (PipelineState holds one). Frames are counted
/// by the caller (any increasing counter); boxes are identified by their box-tracker id, and boxes without
/// an id (-1) have none.
class SubBoxMemory {
 public:
  /// Stores the final state of every cell of this frame's vote per tracked box, for a later frame whose
  /// own baseline is too short to vote (SubBoxStageOptions::min_evidence_frames): 1 dynamic (voted, merged
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

  void clear() { states_.clear(); }
  std::size_t num_boxes() const { return states_.size(); }

 private:
  static constexpr std::size_t kMaxCells = 64;  ///< SubBoxOptions::grid is at most 8
  static bool grid_ok(int grid) { return grid >= 1 && grid <= 8; }
  struct BoxStates {
    std::int64_t id = -1;
    std::uint64_t frame = 0;
    std::uint8_t state[kMaxCells] = {};
  };

  std::vector<BoxStates> states_;  ///< a handful of tracked boxes: a linear search is enough
};

}  // namespace dyncull
