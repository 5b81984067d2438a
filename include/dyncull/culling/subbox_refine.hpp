/// @file subbox_refine.hpp
/// Sub-box refinement (DFD-SLAM, Qian et al. 2024, Algorithm 1): each detection box is split into 3 x 3 sub-boxes voted
/// dynamic or static by the geometric labels inside them (ratio = dyn / (dyn + static) vs sigma1).
#pragma once

#include "dyncull/core/box.hpp"
#include "dyncull/core/flags.hpp"
#include "dyncull/core/mask.hpp"
#include "dyncull/core/pixel.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/core/traits.hpp"
#include "dyncull/core/types.hpp"
#include "dyncull/culling/labels.hpp"
#include "dyncull/culling/validation.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace dyncull {

/// Options of Algorithm 1. The paper gives no values for sigma1, sigma2 beyond "the majority"; the
/// merge rule and the empty-sub-box rule are our choices (docs/algorithms.md).
template <class T>
struct SubBoxOptions {
  int grid = 3;                 ///< grid x grid sub-boxes per box (paper: 3; at most 8)
  T sigma1 = T(0.5);            ///< dynamic sub-box when dyn / (dyn + static) >= sigma1
  int sigma2 = 4;               ///< more than sigma2 dynamic sub-boxes (after merging) -> whole box dynamic
  std::size_t min_points = 2;   ///< sub-boxes with fewer labelled points carry no evidence ("empty")
  /// A static sub-box next to a dynamic one is merged into the dynamic set when it is empty or its
  /// ratio is at least merge_ratio. The paper merges every neighbour (merge_ratio = 0); 0.35 keeps
  /// sub-boxes whose points clearly agree on "static" (the legs of a person who only moves the upper
  /// body) even with the 15-25 % false flags that a 0.5 px in-box epipolar threshold gives on still parts.
  T merge_ratio = T(0.35);
  /// When an object mask is given, only features inside it vote: the floor and wall behind a person
  /// otherwise outvote the person in the border sub-boxes, and a walker crossing a chair's box makes
  /// the chair's sub-boxes dynamic. false: every labelled feature in the rectangle votes (the paper).
  bool object_mask_votes_only = false;
  /// Burden of proof on "static" (our extension; the paper calls a cell dynamic only on evidence): a cell
  /// not voted dynamic is still dynamic unless at least min_points labelled features vote in it and at most
  /// static_max_dynamic_ratio of them are flagged, so an empty or split cell keeps the box rule's
  /// "dynamic" (inside the object mask). Such cells take no part in merging or in the whole-box count.
  /// 0.3 tolerates the 15-25 % false flags of still parts noted at merge_ratio. refine_subboxes can
  /// limit it to some boxes (the pipeline: those of objects that move by themselves, not a chair).
  bool static_needs_evidence = false;
  T static_max_dynamic_ratio = T(0.3);
  int dilation_radius_px = 15;  ///< square dilation of the raster mask (DynaSLAM / RDS-SLAM use 15 px)

  /// InvalidInput naming the first field out of its range: grid in [1, 8]; sigma1, merge_ratio,
  /// static_max_dynamic_ratio finite and >= 0 (above 1 they switch their rule off); sigma2 >= 0;
  /// dilation_radius_px in [0, 1024].
  Status validate(std::string* reason = nullptr) const {
    using detail::finite_in;
    using detail::invalid_option;
    constexpr double kBig = 1e30;
    if (grid < 1 || grid > 8) return invalid_option(reason, "grid", "must be in [1, 8]");
    if (!finite_in(sigma1, 0, kBig)) return invalid_option(reason, "sigma1", "must be finite and >= 0");
    if (sigma2 < 0) return invalid_option(reason, "sigma2", "must be >= 0");
    if (!finite_in(merge_ratio, 0, kBig)) return invalid_option(reason, "merge_ratio", "must be finite and >= 0");
    if (!finite_in(static_max_dynamic_ratio, 0, kBig))
      return invalid_option(reason, "static_max_dynamic_ratio", "must be finite and >= 0");
    if (dilation_radius_px < 0 || dilation_radius_px > 1024)
      return invalid_option(reason, "dilation_radius_px", "must be in [0, 1024]");
    if (reason) reason->clear();
    return Status::Ok;
  }
};

/// Per-box vote. Cell (row, col) is cells[row * grid + col]; state 1 = dynamic.
struct SubBoxVote {
  bool whole_box = false;       ///< more than sigma2 dynamic sub-boxes: the whole box is dynamic
  int num_dynamic_cells = 0;    ///< after merging and static_needs_evidence (whole_box: grid*grid)
  int num_merged_cells = 0;     ///< static or empty cells merged because they touch a dynamic one
};

template <class T>
struct SubBoxResult {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }

  std::vector<FeatureLabel> labels;  ///< per feature: Static or Dynamic
  std::vector<CullReason> reasons;   ///< SubBox inside a dynamic sub-box, Epipolar outside boxes, else None
  std::vector<SubBoxVote> votes;     ///< per box
  int grid = 0;                      ///< the grid of the vote (cells below); 0 when nothing was voted
  std::vector<std::uint8_t> cells;   ///< per box grid*grid dynamic flags, box-major
  std::vector<std::uint32_t> dyn_count, static_count;  ///< per box grid*grid vote counts
  std::size_t num_dynamic = 0, num_static = 0;
  std::size_t num_rescued = 0;  ///< geometric Dynamic inside a box but in a static sub-box: made Static
  std::size_t num_added = 0;    ///< geometric Static made Dynamic by a dynamic sub-box
  std::size_t num_boxes = 0, num_whole_boxes = 0, num_invalid_boxes = 0;
};

namespace detail {
template <class T> const Box<T>& subbox_as_box(const Box<T>& b) { return b; }
template <class T> const Box<T>& subbox_as_box(const Detection<T>& d) { return d.box; }

/// Cell of (x, y) in box b, or -1 when outside. Cells split the box evenly in continuous coordinates.
/// Index in [0, grid) of position p in [lo, hi] split into grid equal parts. Differences of huge finite
/// coordinates overflow to Inf, so they fall back to halves; the index is clamped before the conversion.
template <class T>
int subbox_index(T p, T lo, T hi, int grid) {
  T span = hi - lo, off = p - lo;
  if (!std::isfinite(span)) {
    span = hi * T(0.5) - lo * T(0.5);
    off = p * T(0.5) - lo * T(0.5);
  }
  if (!(span > T(0))) return 0;
  T c = off * T(grid);
  c = std::isfinite(c) ? c / span : off / span * T(grid);
  return clamped_int(c, 0, grid - 1);
}

template <class T>
int subbox_cell(const Box<T>& b, int grid, T x, T y) {
  if (!(x >= b.x0 && x <= b.x1 && y >= b.y0 && y <= b.y1)) return -1;
  return subbox_index(y, b.y0, b.y1, grid) * grid + subbox_index(x, b.x0, b.x1, grid);
}

/// Corner k (0..grid) of the cells along [lo, hi]: lo + k (hi - lo) / grid, or the weighted form when the
/// width overflows (a finite box of +-3e38 in float).
template <class T>
T subbox_edge(T lo, T hi, int k, int grid) {
  const T w = (hi - lo) / T(grid);
  if (std::isfinite(w)) return lo + T(k) * w;
  const T t = T(k) / T(grid);
  return lo * (T(1) - t) + hi * t;
}

/// The vote of one cell from its counts (Algorithm 1 l. 3-12): 2 = empty (fewer than min_points labelled
/// features), 1 = dynamic (dyn / (dyn + static) >= sigma1), 0 = static.
template <class T>
std::uint8_t subbox_cell_vote(std::uint32_t dyn, std::uint32_t stat, const SubBoxOptions<T>& options) {
  const std::uint32_t total = dyn + stat;
  if (total < options.min_points || total == 0) return 2;
  return T(dyn) >= options.sigma1 * T(total) ? 1 : 0;
}

/// Whether feature i belongs to box b's object (no mask given: every feature does).
inline bool subbox_in_object(FlagView in_object, BoxBitsView box_bits, std::size_t i, std::size_t b) {
  if (box_bits.given && b < 32) return ((box_bits[i] >> b) & 1u) != 0;
  return !in_object.given || in_object[i] != 0;
}

/// Starts a result for n features and nb boxes: status Ok, every feature Static, counts zeroed.
template <class T>
void subbox_begin(SubBoxResult<T>* out, std::size_t n, std::size_t nb) {
  SubBoxResult<T>& r = *out;
  r.status = Status::Ok;
  r.reason.clear();
  r.labels.assign(n, FeatureLabel::Static);
  r.reasons.assign(n, CullReason::None);
  r.num_dynamic = r.num_static = r.num_rescued = r.num_added = 0;
  r.num_boxes = nb;
  r.num_whole_boxes = r.num_invalid_boxes = 0;
}

/// Refuses the frame into the result started by subbox_begin: InvalidInput with `why`, nothing voted
/// (every feature stays Static). Returns false, for the checks below.
template <class T>
bool subbox_refuse(SubBoxResult<T>* r, std::string why) {
  r->status = Status::InvalidInput;
  r->reason = std::move(why);
  r->votes.clear();
  r->cells.clear();
  r->grid = 0;
  return false;
}

/// options.validate() into the result started by subbox_begin (InvalidInput, every feature Static).
template <class T>
bool subbox_options_valid(const SubBoxOptions<T>& options, SubBoxResult<T>* r) {
  std::string why;
  if (options.validate(&why) == Status::Ok) return true;
  return subbox_refuse(r, "invalid options: " + why);
}

/// The per-feature views hold n entries and the per-box flags nb (those given); else InvalidInput into
/// the result started by subbox_begin, naming the view and both sizes (nothing read).
template <class T>
bool subbox_inputs_fit(std::size_t n, FlagView in_object_mask, BoxBitsView object_box_bits, std::size_t nb,
                       FlagView static_needs_evidence_boxes, SubBoxResult<T>* r) {
  std::string why;
  if (flags_fit(in_object_mask, n, "in_object_mask", "points", &why) &&
      flags_fit(object_box_bits, n, "object_box_bits", "points", &why) &&
      flags_fit(static_needs_evidence_boxes, nb, "static_needs_evidence_boxes", "boxes", &why))
    return true;
  return subbox_refuse(r, why);
}

/// The required geometric labels hold n entries; else InvalidInput into the result started by
/// subbox_begin, naming them and both sizes (nothing read).
template <class T>
bool subbox_geometric_fits(ArrayView<FeatureLabel> geometric, std::size_t n, SubBoxResult<T>* r) {
  std::string why;
  if (geometric.holds(n)) return true;
  if (geometric.given) flags_fit(geometric, n, "geometric", "points", &why);
  return subbox_refuse(r, geometric.given ? why : "geometric is required (" + std::to_string(n) + " points)");
}

/// Zeroed per-box votes and per-cell buffers for nb boxes of grid*grid cells; returns grid*grid.
template <class T>
std::size_t subbox_buffers(SubBoxResult<T>* out, std::size_t nb, int grid) {
  out->grid = grid;
  const std::size_t cells_per_box = static_cast<std::size_t>(grid) * static_cast<std::size_t>(grid);
  out->votes.assign(nb, SubBoxVote{});
  out->cells.assign(nb * cells_per_box, 0);
  out->dyn_count.assign(nb * cells_per_box, 0);
  out->static_count.assign(nb * cells_per_box, 0);
  return cells_per_box;
}

/// Feature labels from r.cells (Algorithm 1's last step): dynamic inside any dynamic cell (and the
/// object mask if given), static inside boxes otherwise. Fills labels, reasons and the counts of a result
/// started by subbox_begin; the caller has checked every view against the points (subbox_geometric_fits).
template <class T, class Points, class Boxes>
void subbox_label_features(const Points& points, ArrayView<FeatureLabel> geometric, const Boxes& boxes,
                           const SubBoxOptions<T>& options, SubBoxResult<T>* out, FlagView in_object_mask,
                           BoxBitsView object_box_bits) {
  SubBoxResult<T>& r = *out;
  const std::size_t n = static_cast<std::size_t>(points.size());
  const std::size_t nb = static_cast<std::size_t>(boxes.size());
  const int g = options.grid;
  const std::size_t cells_per_box = static_cast<std::size_t>(g) * static_cast<std::size_t>(g);
  for (std::size_t i = 0; i < n; ++i) {
    const T x = point_x<T>(points[i]), y = point_y<T>(points[i]);
    bool in_box = false, in_dynamic = false;
    for (std::size_t b = 0; b < nb && !in_dynamic; ++b) {
      const Box<T>& box = detail::subbox_as_box(boxes[b]);
      if (!box.valid()) continue;
      const int c = detail::subbox_cell(box, g, x, y);
      if (c < 0) continue;
      in_box = true;
      const std::size_t cell = b * cells_per_box + static_cast<std::size_t>(c);
      in_dynamic = r.cells[cell] != 0 && detail::subbox_in_object(in_object_mask, object_box_bits, i, b);
    }
    const bool geo_dyn = geometric[i] == FeatureLabel::Dynamic;
    if (!std::isfinite(x) || !std::isfinite(y)) {
      r.labels[i] = FeatureLabel::Dynamic;  // never trust a non-finite feature as static
      r.reasons[i] = CullReason::InvalidInput;
    } else if (in_dynamic) {
      r.labels[i] = FeatureLabel::Dynamic;
      r.reasons[i] = CullReason::SubBox;
      r.num_added += !geo_dyn;
    } else if (in_box) {
      r.num_rescued += geo_dyn;
    } else if (geo_dyn) {  // outside every box the geometric label stands
      r.labels[i] = FeatureLabel::Dynamic;
      r.reasons[i] = CullReason::Epipolar;
    }
    r.num_dynamic += r.labels[i] == FeatureLabel::Dynamic;
  }
  r.num_static = n - r.num_dynamic;
}
}  // namespace detail

namespace detail {

/// Algorithm 1's votes: every labelled feature counts (dynamic or static) in the cell of every box that
/// contains it (boxes may overlap); with object_mask_votes_only, only in its own object's boxes.
template <class T, class Points, class Boxes>
void subbox_count_votes(const Points& points, ArrayView<FeatureLabel> geometric, const Boxes& boxes,
                        const SubBoxOptions<T>& options, std::size_t cells_per_box, FlagView in_object_mask,
                        BoxBitsView object_box_bits, SubBoxResult<T>* r) {
  const std::size_t n = static_cast<std::size_t>(points.size());
  for (std::size_t b = 0; b < static_cast<std::size_t>(boxes.size()); ++b) {
    const Box<T>& box = subbox_as_box(boxes[b]);
    if (!box.valid()) {
      ++r->num_invalid_boxes;
      continue;
    }
    std::uint32_t* dc = r->dyn_count.data() + b * cells_per_box;
    std::uint32_t* sc = r->static_count.data() + b * cells_per_box;
    for (std::size_t i = 0; i < n; ++i) {
      if (options.object_mask_votes_only && !subbox_in_object(in_object_mask, object_box_bits, i, b)) continue;
      const int c = subbox_cell(box, options.grid, point_x<T>(points[i]), point_y<T>(points[i]));
      if (c < 0) continue;
      if (geometric[i] == FeatureLabel::Dynamic) ++dc[c];
      else if (geometric[i] == FeatureLabel::Static) ++sc[c];
    }
  }
}

/// Algorithm 1 line 14 in one pass against the voted states `st` (1 dynamic, 0 static, 2 empty), so
/// merging never chains: a cell touching a voted dynamic one (edge-sharing) becomes dynamic when
/// it is empty or its dynamic share reaches merge_ratio.
template <class T>
void subbox_merge(const std::uint8_t* st, const std::uint32_t* dc, const std::uint32_t* sc,
                  const SubBoxOptions<T>& options, std::uint8_t* cells, SubBoxVote* vote) {
  const int g = options.grid;
  for (int row = 0; row < g; ++row)
    for (int col = 0; col < g; ++col) {
      const std::size_t c = static_cast<std::size_t>(row * g + col);
      if (st[c] == 1) {
        cells[c] = 1;
        continue;
      }
      bool touches = false;
      for (int dr = -1; dr <= 1 && !touches; ++dr)
        for (int dcol = -1; dcol <= 1 && !touches; ++dcol) {
          if ((dr == 0) == (dcol == 0)) continue;  // the 4 edge-sharing neighbours only
          const int rr = row + dr, cc = col + dcol;
          if (rr < 0 || cc < 0 || rr >= g || cc >= g) continue;
          touches = st[static_cast<std::size_t>(rr * g + cc)] == 1;
        }
      const std::uint32_t total = dc[c] + sc[c];
      const bool weak = st[c] == 2 || T(dc[c]) >= options.merge_ratio * T(total);
      cells[c] = (touches && weak) ? 1 : 0;
      vote->num_merged_cells += cells[c];
    }
}

/// Box b's cells: voted, merged, the whole box by sigma2, and where static_needs_evidence applies
/// (`burden_on_static`) a static cell needs its own evidence (an empty cell, or one over
/// static_max_dynamic_ratio dynamic, is dynamic).
template <class T>
void subbox_decide_cells(std::size_t b, std::size_t cells_per_box, const SubBoxOptions<T>& options,
                         bool burden_on_static, SubBoxResult<T>* r) {
  std::uint8_t* cells = r->cells.data() + b * cells_per_box;
  const std::uint32_t* dc = r->dyn_count.data() + b * cells_per_box;
  const std::uint32_t* sc = r->static_count.data() + b * cells_per_box;
  std::uint8_t st[64] = {};  // voted states; merging reads these, so it never chains
  for (std::size_t c = 0; c < cells_per_box; ++c) st[c] = subbox_cell_vote(dc[c], sc[c], options);
  SubBoxVote& vote = r->votes[b];
  subbox_merge(st, dc, sc, options, cells, &vote);
  for (std::size_t c = 0; c < cells_per_box; ++c) vote.num_dynamic_cells += cells[c];
  if (vote.num_dynamic_cells > options.sigma2) {
    vote.whole_box = true;  // Algorithm 1's sigma2 rule: every cell of the box
    std::fill(cells, cells + cells_per_box, std::uint8_t{1});
    vote.num_dynamic_cells = static_cast<int>(cells_per_box);
    ++r->num_whole_boxes;
  }
  if (options.static_needs_evidence && burden_on_static && !vote.whole_box)
    for (std::size_t c = 0; c < cells_per_box; ++c) {
      if (cells[c]) continue;
      const std::uint32_t total = dc[c] + sc[c];
      if (st[c] == 2 || T(dc[c]) > options.static_max_dynamic_ratio * T(total)) {
        cells[c] = 1;
        ++vote.num_dynamic_cells;
      }
    }
}

}  // namespace detail

/// Runs Algorithm 1 on every box, writing into `out` (buffers reused across frames).
/// points: the features; geometric: their geometric labels (Dynamic / Static; Candidate = unlabelled,
/// not counted; required, one per point); boxes: container of Box<T> or Detection<T> (the boxes to
/// refine, e.g. person boxes);
/// in_object_mask: optional per-feature flag (object mask of DLD-SLAM §3.3): a feature in a dynamic sub-box
/// is Dynamic only if also in the object mask, as the paper keeps "the mask" inside dynamic sub-boxes.
/// object_box_bits: optional per-feature bit set (bit b: in box b's own object mask, as
/// DepthMaskResult::box_bits): box b then acts only on its own object's features, so a chair that a
/// walker's box overlaps is not culled by the walker's sub-box (boxes from the 33rd on use in_object_mask).
/// static_needs_evidence_boxes: optional per-box flag, the boxes options.static_needs_evidence applies to
/// (not given: every box); elsewhere a cell is dynamic only on its own vote.
/// Options failing SubBoxOptions::validate, or a given view whose size is not points.size() (boxes.size()
/// for the per-box flags), give InvalidInput (every feature Static, the view and both sizes named).
template <class T, class Points, class Boxes>
void refine_subboxes(const Points& points, ArrayView<FeatureLabel> geometric, const Boxes& boxes,
                     const SubBoxOptions<T>& options, SubBoxResult<T>* out,
                     FlagView in_object_mask = nullptr, BoxBitsView object_box_bits = nullptr,
                     FlagView static_needs_evidence_boxes = nullptr) {
  static_assert(is_point_container_v<Points>, "dyncull::refine_subboxes: points must hold points (see PointTraits)");
  SubBoxResult<T>& r = *out;
  const std::size_t n = static_cast<std::size_t>(points.size());
  const std::size_t nb = static_cast<std::size_t>(boxes.size());
  detail::subbox_begin(&r, n, nb);
  if (!detail::subbox_options_valid(options, &r)) return;
  if (!detail::subbox_geometric_fits(geometric, n, &r) ||
      !detail::subbox_inputs_fit(n, in_object_mask, object_box_bits, nb, static_needs_evidence_boxes, &r))
    return;
  const std::size_t cells_per_box = detail::subbox_buffers(&r, nb, options.grid);
  detail::subbox_count_votes(points, geometric, boxes, options, cells_per_box, in_object_mask, object_box_bits, &r);
  for (std::size_t b = 0; b < nb; ++b) {
    const bool burden_on_static = !static_needs_evidence_boxes.given || static_needs_evidence_boxes[b] != 0;
    if (detail::subbox_as_box(boxes[b]).valid()) detail::subbox_decide_cells(b, cells_per_box, options, burden_on_static, &r);
  }
  detail::subbox_label_features(points, geometric, boxes, options, &r, in_object_mask, object_box_bits);
  if (r.num_invalid_boxes > 0) r.reason = std::to_string(r.num_invalid_boxes) + " invalid box(es) ignored";
}

/// Convenience overload returning a fresh result.
template <class T, class Points, class Boxes>
SubBoxResult<T> refine_subboxes(const Points& points, ArrayView<FeatureLabel> geometric, const Boxes& boxes,
                                const SubBoxOptions<T>& options = {}, FlagView in_object_mask = nullptr,
                                BoxBitsView object_box_bits = nullptr, FlagView static_needs_evidence_boxes = nullptr) {
  SubBoxResult<T> r;
  refine_subboxes(points, geometric, boxes, options, &r, in_object_mask, object_box_bits, static_needs_evidence_boxes);
  return r;
}

/// Algorithm 1's last step with cell states given instead of voted (subbox_memory.hpp keeps them from an
/// earlier frame): per box grid*grid states, box-major, 0 = static with evidence, 1 = dynamic, 2 =
/// unknown; unknown cells act as dynamic (inside the object mask, as voted ones), so a box without a
/// remembered vote falls back to the box rule. The counts in `out` stay zero: nothing was voted.
/// `states` must hold boxes.size() * grid * grid entries, geometric (required) and the given per-feature
/// views points.size():
/// else InvalidInput (every feature Static, the view and both sizes named).
template <class T, class Points, class Boxes>
void apply_subbox_states(const Points& points, ArrayView<FeatureLabel> geometric, const Boxes& boxes, FlagView states,
                         const SubBoxOptions<T>& options, SubBoxResult<T>* out, FlagView in_object_mask = nullptr,
                         BoxBitsView object_box_bits = nullptr) {
  static_assert(is_point_container_v<Points>, "dyncull::apply_subbox_states: points must hold points (see PointTraits)");
  SubBoxResult<T>& r = *out;
  const std::size_t n = static_cast<std::size_t>(points.size());
  const std::size_t nb = static_cast<std::size_t>(boxes.size());
  const int g = options.grid;
  detail::subbox_begin(&r, n, nb);
  if (!detail::subbox_options_valid(options, &r)) return;
  const std::size_t cells = nb * static_cast<std::size_t>(g) * static_cast<std::size_t>(g);
  if (!states.holds(cells)) {  // required, unlike the other views
    detail::subbox_refuse(&r, "states has " + std::to_string(states.given ? states.size : 0) + " entries for " +
                                  std::to_string(cells) + " cells (boxes x grid x grid)");
    return;
  }
  if (!detail::subbox_geometric_fits(geometric, n, &r) ||
      !detail::subbox_inputs_fit(n, in_object_mask, object_box_bits, nb, nullptr, &r))
    return;
  const std::size_t cells_per_box = detail::subbox_buffers(&r, nb, g);
  for (std::size_t b = 0; b < nb; ++b) {
    if (!detail::subbox_as_box(boxes[b]).valid()) {
      ++r.num_invalid_boxes;
      continue;
    }
    for (std::size_t c = 0; c < cells_per_box; ++c) {
      r.cells[b * cells_per_box + c] = states[b * cells_per_box + c] != 0;
      r.votes[b].num_dynamic_cells += r.cells[b * cells_per_box + c];
    }
  }
  detail::subbox_label_features(points, geometric, boxes, options, &r, in_object_mask, object_box_bits);
  if (r.num_invalid_boxes > 0) r.reason = std::to_string(r.num_invalid_boxes) + " invalid box(es) ignored";
}

/// Square (Chebyshev) binary dilation of `mask` inside `roi` by `radius` pixels, two separable passes
/// with running counts: cost O(roi area), independent of the radius. Both passes walk rows, so the
/// vertical one is a contiguous, vectorisable add/subtract of whole rows. `scratch` is reused.
inline void dilate_square(MaskView mask, PixelRect roi, int radius, std::vector<std::uint16_t>* scratch) {
  if (mask.empty() || radius <= 0) return;
  roi.c0 = std::max(roi.c0, 0);
  roi.r0 = std::max(roi.r0, 0);
  roi.c1 = std::min(roi.c1, mask.width);
  roi.r1 = std::min(roi.r1, mask.height);
  if (roi.empty()) return;
  const int w = roi.width(), h = roi.height();
  // A radius beyond the roi's size reaches every roi pixel: same mask, bounded scratch and counts.
  radius = std::min(radius, std::max(w, h));
  const std::size_t uw = static_cast<std::size_t>(w);
  // Layout (uint16 words): h rows of horizontal results (0/1), one row of vertical window counts, then
  // an OR-doubling row buffer of w + 2r + 1 bytes (reached through a byte pointer: char may alias).
  const std::size_t span = uw + 2 * static_cast<std::size_t>(radius) + 1;
  const std::size_t need = uw * (static_cast<std::size_t>(h) + 1) + (span + 1) / 2 + 1;
  if (scratch->size() < need) scratch->resize(need);
  std::uint16_t* tmp = scratch->data();
  std::uint16_t* count = tmp + uw * static_cast<std::size_t>(h);
  std::uint8_t* orbuf = reinterpret_cast<std::uint8_t*>(count + uw);
  // Horizontal: tmp[x] = OR of row[x - r .. x + r]. The padded row is OR-doubled in place (after the
  // pass with step s, orbuf[i] = OR of 2s original bytes from i), log2(2r + 1) vectorised passes; the
  // window is then the OR of two overlapping power-of-two runs.
  std::size_t run = 1;
  while (run * 2 <= 2 * static_cast<std::size_t>(radius) + 1) run *= 2;
  const std::size_t second = 2 * static_cast<std::size_t>(radius) + 1 - run;
  for (int y = 0; y < h; ++y) {
    const std::uint8_t* row = mask.row(roi.r0 + y) + roi.c0;
    std::uint16_t* t = tmp + static_cast<std::size_t>(y) * uw;
    std::fill(orbuf, orbuf + radius, std::uint8_t(0));
    for (std::size_t x = 0; x < uw; ++x) orbuf[static_cast<std::size_t>(radius) + x] = row[x] != 0;
    std::fill(orbuf + radius + w, orbuf + span, std::uint8_t(0));
    for (std::size_t step = 1; step < run; step *= 2)
      for (std::size_t i = 0; i + step < span; ++i) orbuf[i] = static_cast<std::uint8_t>(orbuf[i] | orbuf[i + step]);
    for (std::size_t x = 0; x < uw; ++x) t[x] = static_cast<std::uint16_t>(orbuf[x] | orbuf[x + second]);
  }
  // Vertical: count[x] = set tmp rows within [y - r, y + r] (at most 2r + 1 <= 65535 for sane radii).
  std::fill(count, count + uw, std::uint16_t(0));
  for (int y = 0; y < std::min(radius, h); ++y) {
    const std::uint16_t* t = tmp + static_cast<std::size_t>(y) * uw;
    for (std::size_t x = 0; x < uw; ++x) count[x] = static_cast<std::uint16_t>(count[x] + t[x]);
  }
  for (int y = 0; y < h; ++y) {
    if (y + radius < h) {
      const std::uint16_t* add = tmp + static_cast<std::size_t>(y + radius) * uw;
      for (std::size_t x = 0; x < uw; ++x) count[x] = static_cast<std::uint16_t>(count[x] + add[x]);
    }
    if (y - radius - 1 >= 0) {
      const std::uint16_t* sub = tmp + static_cast<std::size_t>(y - radius - 1) * uw;
      for (std::size_t x = 0; x < uw; ++x) count[x] = static_cast<std::uint16_t>(count[x] - sub[x]);
    }
    std::uint8_t* out = mask.row(roi.r0 + y) + roi.c0;
    for (std::size_t x = 0; x < uw; ++x) out[x] = static_cast<std::uint8_t>(count[x] ? 255 : 0);
  }
}

/// Rasterises the final mask of Algorithm 1 into `mask` (cleared first; must be the image size):
/// the object mask (or the whole cell when object_mask is empty) inside every dynamic sub-box, then
/// dilated by options.dilation_radius_px (clamped to [0, 1024]). The cells are split on the grid the
/// vote used (result.grid), whatever options.grid says. Returns the number of set pixels; 0 (mask
/// cleared) when the result does not hold grid*grid cells for each of `boxes` (not a vote's result).
template <class T, class Boxes>
std::size_t subbox_mask(const SubBoxResult<T>& result, const Boxes& boxes, const SubBoxOptions<T>& options,
                        ConstMaskView object_mask, MaskView mask, std::vector<std::uint16_t>* scratch) {
  if (mask.empty()) return 0;
  for (int y = 0; y < mask.height; ++y) std::fill(mask.row(y), mask.row(y) + mask.width, std::uint8_t(0));
  const int g = result.grid;
  if (g < 1 || g > 8 || result.votes.size() != static_cast<std::size_t>(boxes.size())) return 0;
  const std::size_t cells_per_box = static_cast<std::size_t>(g) * static_cast<std::size_t>(g);
  if (result.cells.size() != result.votes.size() * cells_per_box) return 0;
  PixelRect bound{mask.width, mask.height, 0, 0};
  for (std::size_t b = 0; b < result.votes.size(); ++b) {
    const Box<T>& box = detail::subbox_as_box(boxes[b]);
    if (!box.valid()) continue;
    for (int c = 0; c < static_cast<int>(cells_per_box); ++c) {
      if (!result.cells[b * cells_per_box + static_cast<std::size_t>(c)]) continue;
      const int row = c / g, col = c % g;
      const Box<T> cell{detail::subbox_edge(box.x0, box.x1, col, g), detail::subbox_edge(box.y0, box.y1, row, g),
                        detail::subbox_edge(box.x0, box.x1, col + 1, g), detail::subbox_edge(box.y0, box.y1, row + 1, g)};
      const PixelRect pr = pixel_rect(cell, mask.width, mask.height);
      if (pr.empty()) continue;
      bound.c0 = std::min(bound.c0, pr.c0);
      bound.r0 = std::min(bound.r0, pr.r0);
      bound.c1 = std::max(bound.c1, pr.c1);
      bound.r1 = std::max(bound.r1, pr.r1);
      for (int y = pr.r0; y < pr.r1; ++y) {
        std::uint8_t* out = mask.row(y);
        if (object_mask.empty()) {
          std::fill(out + pr.c0, out + pr.c1, std::uint8_t(255));
        } else {
          const std::uint8_t* in = object_mask.in_bounds(0, y) ? object_mask.row(y) : nullptr;
          const int c1 = std::min(pr.c1, object_mask.width);
          for (int x = pr.c0; in && x < c1; ++x) out[x] = in[x] ? std::uint8_t(255) : out[x];
        }
      }
    }
  }
  if (bound.empty()) return 0;
  const int rad = std::min(std::max(0, options.dilation_radius_px), 1024);
  const PixelRect grown{std::max(0, bound.c0 - rad), std::max(0, bound.r0 - rad), std::min(mask.width, bound.c1 + rad),
                        std::min(mask.height, bound.r1 + rad)};
  dilate_square(mask, grown, rad, scratch);
  std::size_t set = 0;  // nothing is set outside the grown bound
  for (int y = grown.r0; y < grown.r1; ++y) {
    const std::uint8_t* row = mask.row(y);
    for (int x = grown.c0; x < grown.c1; ++x) set += row[x] != 0;
  }
  return set;
}

}  // namespace dyncull
