// Sub-box memory: which cells are remembered, for how long, in which box, and which tracks they may cull.
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

TEST(SubBoxMemory, ACellVotedDynamicIsRememberedForTheWindowInItsTrackedBoxOnly) {
  SubBoxMemory memory;
  const SubBoxOptions<float> options;  // sigma1 0.5, min_points 2
  const std::vector<std::int64_t> ids = {7, 9};
  std::vector<std::uint8_t> cells;
  memory.remember(ids, votes_with(2, 1, 3, 1), options, 10, 15);  // frame 10: box 7's cell 1 dynamic (3 of 4)
  memory.recall(ids, 3, 10, 15, &cells);
  EXPECT_EQ(cells[1], 0) << "this frame's own vote is the vote's business, not the memory's";
  for (std::uint64_t f = 11; f <= 25; ++f) {
    memory.recall(ids, 3, f, 15, &cells);
    EXPECT_EQ(cells[1], 1) << "frame " << f;
    EXPECT_EQ(cells[9 + 1], 0) << "box 9 never voted";
    memory.remember(ids, votes_with(2, 1, 0, 5), options, f, 15);  // static votes do not erase it
  }
  memory.recall(ids, 3, 26, 15, &cells);
  EXPECT_EQ(cells[1], 0) << "16 frames later";
  // Other ids, and boxes without an id, have no memory.
  memory.remember(ids, votes_with(2, 4, 5, 0), options, 30, 15);
  memory.recall({9, 7, -1}, 3, 31, 15, &cells);
  ASSERT_EQ(cells.size(), 27u);
  EXPECT_EQ(cells[4], 0);
  EXPECT_EQ(cells[9 + 4], 1);
  EXPECT_EQ(cells[18 + 4], 0);
}

TEST(SubBoxMemory, OnlyOwnVotesAreRemembered) {
  SubBoxMemory memory;
  SubBoxOptions<float> options;
  const std::vector<std::int64_t> ids = {1};
  std::vector<std::uint8_t> cells;
  // Below sigma1 (1 of 3), too few points (1 of 1), and a cell set by merging or the whole-box rule
  // (cells[] = 1 without the counts): none is remembered.
  SubBoxResult<float> v = votes_with(1, 0, 1, 2);
  v.dyn_count[2] = 1;
  v.cells.assign(9, 1);
  memory.remember(ids, v, options, 5, 15);
  memory.recall(ids, 3, 6, 15, &cells);
  for (std::uint8_t c : cells) EXPECT_EQ(c, 0);
  options.min_points = 1;
  memory.remember(ids, v, options, 6, 15);
  memory.recall(ids, 3, 7, 15, &cells);
  EXPECT_EQ(cells[2], 1);
  EXPECT_EQ(cells[0], 0);
}

TEST(SubBoxMemory, RememberedCellsCullRecentlyFlaggedAndYoungTracksOnly) {
  SubBoxMemory memory;
  std::vector<std::uint8_t> eligible;
  const std::vector<std::int64_t> tracks = {100, 200};
  // Frame 1: track 100 flagged, 200 not; both are new (young) anyway.
  std::vector<FeatureLabel> geo = {FeatureLabel::Dynamic, FeatureLabel::Static};
  memory.update_tracks(tracks, geo, 1, 15, &eligible);
  EXPECT_EQ(eligible, (std::vector<std::uint8_t>{1, 1}));
  geo = {FeatureLabel::Static, FeatureLabel::Candidate};
  for (std::uint64_t f = 2; f <= 16; ++f) {
    memory.update_tracks(tracks, geo, f, 15, &eligible);
    EXPECT_EQ(eligible, (std::vector<std::uint8_t>{1, 1})) << "frame " << f;
  }
  // Frame 17: 100's flag and 200's first sighting are 16 frames back, out of the window.
  geo = {FeatureLabel::Static, FeatureLabel::Dynamic};
  memory.update_tracks(tracks, geo, 17, 15, &eligible);
  EXPECT_EQ(eligible, (std::vector<std::uint8_t>{0, 1})) << "200 is flagged now";
  geo = {FeatureLabel::Static, FeatureLabel::Static};
  memory.update_tracks(tracks, geo, 32, 15, &eligible);
  EXPECT_EQ(eligible, (std::vector<std::uint8_t>{0, 1}));
  memory.update_tracks(tracks, geo, 33, 15, &eligible);
  EXPECT_EQ(eligible, (std::vector<std::uint8_t>{0, 0}));
  // A new track is eligible at once; one unseen for longer than the window is forgotten.
  memory.update_tracks({300}, std::vector<FeatureLabel>{FeatureLabel::Static}, 49, 15, &eligible);
  EXPECT_EQ(eligible, (std::vector<std::uint8_t>{1}));
  EXPECT_EQ(memory.num_tracks(), 1u);
  // Without geometric labels nothing is flagged, and a new memory is empty.
  memory.update_tracks({300}, nullptr, 65, 15, &eligible);
  EXPECT_EQ(eligible, (std::vector<std::uint8_t>{0}));
  memory.clear();
  EXPECT_EQ(memory.num_tracks(), 0u);
  EXPECT_EQ(memory.num_boxes(), 0u);
}

// The refinement applies remembered cells to eligible features in the object only, and they neither merge
// nor count towards the whole-box rule.
// Given geometric labels hold one per track: a short array is named with both sizes, nothing is read or
// recorded, and no track is eligible.
TEST(SubBoxMemory, ShortGeometricLabelsAreInvalidInputAndNotRead) {
  SubBoxMemory memory;
  std::vector<std::uint8_t> eligible;
  const std::vector<std::int64_t> tracks = {100, 200, 300};
  const std::vector<FeatureLabel> short_geo = {FeatureLabel::Dynamic};
  std::string reason;
  EXPECT_EQ(memory.update_tracks(tracks, short_geo, 1, 15, &eligible, &reason), Status::InvalidInput);
  EXPECT_EQ(reason, "geometric has 1 entries for 3 tracks");
  EXPECT_EQ(eligible, (std::vector<std::uint8_t>{0, 0, 0}));
  EXPECT_EQ(memory.num_tracks(), 0u);
  const std::vector<FeatureLabel> geo(3, FeatureLabel::Static);
  EXPECT_EQ(memory.update_tracks(tracks, geo, 1, 15, &eligible, &reason), Status::Ok);
  EXPECT_EQ(memory.num_tracks(), 3u);
}

TEST(SubBoxMemory, RefinementAppliesRememberedCellsToEligibleFeaturesInTheObject) {
  const std::vector<Box<float>> boxes = {{0, 0, 90, 90}};
  // Cell 0 (top left) holds features 0-2, cell 4 (centre) features 3-5; all geometric-static.
  const std::vector<Vec2<float>> pts = {{10, 10}, {12, 14}, {20, 5}, {45, 45}, {50, 40}, {40, 50}};
  const std::vector<FeatureLabel> geo(pts.size(), FeatureLabel::Static);
  std::vector<std::uint8_t> extra(9, 0);
  extra[0] = 1;
  const std::vector<std::uint8_t> eligible = {1, 0, 1, 1, 1, 1};
  const std::vector<std::uint8_t> in_object = {1, 1, 0, 1, 1, 1};
  SubBoxResult<float> r;
  refine_subboxes(pts, geo, boxes, SubBoxOptions<float>{}, &r, in_object, nullptr, extra,
                  eligible);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.labels[0], FeatureLabel::Dynamic);
  EXPECT_EQ(r.reasons[0], CullReason::SubBox);
  EXPECT_EQ(r.labels[1], FeatureLabel::Static) << "not eligible";
  EXPECT_EQ(r.labels[2], FeatureLabel::Static) << "outside the object";
  for (std::size_t i = 3; i < 6; ++i) EXPECT_EQ(r.labels[i], FeatureLabel::Static) << "no merge from a remembered cell";
  EXPECT_EQ(r.cells[0], 0) << "the vote itself is unchanged";
  EXPECT_EQ(r.votes[0].num_dynamic_cells, 0);
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
  EXPECT_EQ(r.labels[6], FeatureLabel::Dynamic) << "outside the boxes, flagged (keep_geometric_outside_boxes)";
  EXPECT_EQ(r.reasons[6], CullReason::Epipolar);
  EXPECT_EQ(r.num_rescued, 1u);
  EXPECT_EQ(r.num_dynamic, 4u);
  EXPECT_EQ(r.votes[0].num_dynamic_cells, 8);
  EXPECT_EQ(r.dyn_count[4] + r.static_count[4], 0u) << "nothing was voted";
  options.keep_geometric_outside_boxes = false;
  apply_subbox_states(pts, geo, boxes, states, options, &r, in_object);
  EXPECT_EQ(r.labels[6], FeatureLabel::Static);
  options.grid = 9;
  apply_subbox_states(pts, geo, boxes, states, options, &r);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_EQ(r.labels.size(), pts.size());
}

}  // namespace
}  // namespace dyncull
