// The last sub-box vote of each tracked box: which cell states are kept, for how long, in which box.
#include "dyncull/culling/subbox_memory.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

namespace dyncull {
namespace {

// One 3x3 vote result for `boxes` boxes with the given (dyn, static) counts in cell c of box 0.
SubBoxResult<float> votes_with(std::size_t boxes, std::size_t cell, std::uint32_t dyn, std::uint32_t stat) {
  SubBoxResult<float> r;
  r.dyn_count.assign(boxes * 9, 0);
  r.static_count.assign(boxes * 9, 0);
  r.cells.assign(boxes * 9, 0);
  r.dyn_count[cell] = dyn;
  r.static_count[cell] = stat;
  return r;
}

// The last vote's cell states, for a frame whose own baseline is too short to vote: dynamic (voted, merged or
// whole box), static by a unanimous vote, or unknown; per tracked box, within a window.
TEST(SubBoxMemory, LastVoteStatesAreRecalledPerTrackedBoxWithinTheWindow) {
  SubBoxMemory memory;
  const SubBoxOptions<float> options;  // sigma1 0.5, min_points 2
  const std::vector<std::int64_t> ids = {4, 8};
  std::vector<std::uint8_t> states;
  SubBoxResult<float> v = votes_with(2, 0, 0, 5);  // box 4, cell 0: static with evidence
  v.dyn_count[1] = 4;                              // cell 1: voted dynamic
  v.cells[1] = 1;
  v.cells[2] = 1;  // cell 2: merged (no votes of its own)
  v.static_count[9 + 3] = 6;  // box 8, cell 3: static
  v.dyn_count[9 + 4] = 1;     // box 8, cell 4: static by a split vote (1 of 5 flagged)
  v.static_count[9 + 4] = 4;
  memory.remember_states(ids, v, options, 20, 2);
  EXPECT_EQ(memory.recall_states(ids, 3, 20, 2, &states), 0u) << "not this frame's own vote";
  for (std::uint64_t f : {21u, 22u}) {
    ASSERT_EQ(memory.recall_states(ids, 3, f, 2, &states), 2u) << f;
    ASSERT_EQ(states.size(), 18u);
    EXPECT_EQ(states[0], 0);
    EXPECT_EQ(states[1], 1);
    EXPECT_EQ(states[2], 1);
    for (std::size_t c = 3; c < 9; ++c) EXPECT_EQ(states[c], 2) << c << ": no evidence";
    EXPECT_EQ(states[9 + 3], 0);
    EXPECT_EQ(states[9 + 4], 2) << "a split static vote is not trusted";
  }
  EXPECT_EQ(memory.recall_states(ids, 3, 23, 2, &states), 0u) << "3 frames later";
  for (std::uint8_t c : states) EXPECT_EQ(c, 2);
  // Boxes without an id or never stored are unknown; the box order is the caller's.
  EXPECT_EQ(memory.recall_states({-1, 8, 5}, 3, 21, 2, &states), 1u);
  EXPECT_EQ(states[0], 2);
  EXPECT_EQ(states[9 + 3], 0);
  EXPECT_EQ(states[18 + 3], 2);
  // A later vote replaces the states; storing forgets boxes older than the window; clear() empties it.
  memory.remember_states(std::vector<std::int64_t>{8}, votes_with(1, 3, 3, 0), options, 30, 2);
  EXPECT_EQ(memory.recall_states(ids, 3, 31, 2, &states), 1u);
  EXPECT_EQ(states[9 + 3], 1);
  memory.clear();
  EXPECT_EQ(memory.recall_states(ids, 3, 31, 2, &states), 0u);
}

// With the last vote's states the refinement keeps the static cells and culls the object's features in the
// dynamic and unknown cells (the box rule's decision where there is no vote).
TEST(SubBoxMemory, ApplyingStatesKeepsStaticCellsAndCullsTheObjectElsewhere) {
  const std::vector<Box<float>> boxes = {{0, 0, 90, 90}, {200, 200, 100, 100}};  // the second is invalid
  // Cell 0 (top left): features 0-1; cell 4 (centre): 2-3; cell 8 (bottom right): 4-5; feature 6 outside.
  const std::vector<Vec2<float>> pts = {{10, 10}, {12, 14}, {45, 45}, {50, 40}, {80, 80}, {85, 70}, {150, 10}};
  const std::vector<FeatureLabel> geo = {FeatureLabel::Dynamic, FeatureLabel::Static,  FeatureLabel::Static,
                                         FeatureLabel::Static,  FeatureLabel::Static,  FeatureLabel::Static,
                                         FeatureLabel::Dynamic};
  std::vector<std::uint8_t> states(18, 2);
  states[0] = 0;
  states[4] = 1;
  const std::vector<std::uint8_t> in_object = {1, 1, 1, 0, 1, 1, 1};
  SubBoxOptions<float> options;
  SubBoxResult<float> r;
  apply_subbox_states(pts, geo, boxes, states, options, &r, in_object);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.num_invalid_boxes, 1u);
  EXPECT_EQ(r.labels[0], FeatureLabel::Static) << "static cell, although flagged itself";
  EXPECT_EQ(r.labels[1], FeatureLabel::Static);
  EXPECT_EQ(r.labels[2], FeatureLabel::Dynamic);
  EXPECT_EQ(r.reasons[2], CullReason::SubBox);
  EXPECT_EQ(r.labels[3], FeatureLabel::Static) << "outside the object";
  EXPECT_EQ(r.labels[4], FeatureLabel::Dynamic) << "unknown cell: the box rule";
  EXPECT_EQ(r.labels[5], FeatureLabel::Dynamic);
  EXPECT_EQ(r.labels[6], FeatureLabel::Dynamic) << "outside the boxes, flagged: the geometric label stands";
  EXPECT_EQ(r.reasons[6], CullReason::Epipolar);
  EXPECT_EQ(r.num_rescued, 1u);
  EXPECT_EQ(r.num_dynamic, 4u);
  EXPECT_EQ(r.votes[0].num_dynamic_cells, 8);
  EXPECT_EQ(r.dyn_count[4] + r.static_count[4], 0u) << "nothing was voted";
  options.grid = 9;
  apply_subbox_states(pts, geo, boxes, states, options, &r);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_EQ(r.labels.size(), pts.size());
}

}  // namespace
}  // namespace dyncull
