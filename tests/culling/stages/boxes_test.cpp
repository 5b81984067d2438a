// The boxes stage (stages/boxes.hpp) on its own: the detection filter's padding and confidence, the split
// into dynamic-class regions, the box tracker carrying missed boxes, and what it reports without input.
#include "dyncull/culling/stages/boxes.hpp"

#include "support/stage_context.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

namespace dyncull {
namespace {

template <class T>
class BoxesStageTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(BoxesStageTest, Scalars, );  // trailing comma: clang -Wpedantic rejects an empty variadic

template <class T>
void expect_box(const Detection<T>& d, int class_id, double x0, double y0, double x1, double y1) {
  EXPECT_EQ(d.class_id, class_id);
  EXPECT_EQ(d.box.x0, T(x0));
  EXPECT_EQ(d.box.y0, T(y0));
  EXPECT_EQ(d.box.x1, T(x1));
  EXPECT_EQ(d.box.y1, T(y1));
}

/// A TV (low level), a person (high), a cup below the confidence threshold (medium) and a chair (medium).
template <class T>
test::StageFrame<T> living_room() {
  test::StageFrame<T> f(640, 480);
  f.add(T(150), T(200));
  f.detect(62, T(50), T(50), T(150), T(150));
  f.detect(0, T(100), T(100), T(200), T(300));
  f.detect(41, T(400), T(400), T(420), T(420), T(0.2));
  f.detect(56, T(300), T(200), T(380), T(300), T(0.8));
  return f;
}

TYPED_TEST(BoxesStageTest, FilterPadsKeepsConfidentBoxesAndSplitsTheDynamicClasses) {
  using T = TypeParam;
  const auto f = living_room<T>();
  const PipelineOptions<T> o;  // filter on (5 px padding, confidence 0.4; person 0.25), no tracker
  BoxTracker<T> tracker;
  detail::PipelineWork<T> w;
  PipelineResult<T> r = test::fresh_result(o, f.size());
  const auto work_before = test::parts_of(w);
  const auto result_before = test::parts_of(r);
  detail::collect_boxes(f.frame(), o, &tracker, &w.regions, &r);

  EXPECT_TRUE(r.detections.ran()) << r.detections.reason;
  EXPECT_FALSE(r.tracker.enabled);
  // The cup (0.2 < 0.4) is dropped; the others grow by 5 px on each side, in input order.
  ASSERT_EQ(w.regions.boxes.size(), 3u);
  expect_box(w.regions.boxes[0], 62, 45, 45, 155, 155);
  expect_box(w.regions.boxes[1], 0, 95, 95, 205, 305);
  expect_box(w.regions.boxes[2], 56, 295, 195, 385, 305);
  // Person (high) and chair (medium) are the dynamic-class regions; the TV is not.
  ASSERT_EQ(w.regions.dyn_boxes.size(), 2u);
  expect_box(w.regions.dyn_boxes[0], 0, 95, 95, 205, 305);
  expect_box(w.regions.dyn_boxes[1], 56, 295, 195, 385, 305);
  EXPECT_EQ(w.regions.dyn_box_source, (std::vector<std::int32_t>{1, 2}));
  EXPECT_EQ(w.regions.box_track_id, (std::vector<std::int64_t>{-1, -1, -1}));
  EXPECT_EQ(w.regions.dyn_box_track_id, (std::vector<std::int64_t>{-1, -1}));

  test::expect_only_changed(work_before, test::parts_of(w), {"regions"});
  test::expect_only_changed(result_before, test::parts_of(r), {"detections"});
}

TYPED_TEST(BoxesStageTest, TrackerCarriesMissedDynamicBoxesGrownAndKeepsTheirIds) {
  using T = TypeParam;
  auto f = living_room<T>();
  PipelineOptions<T> o;
  o.tracker.enabled = true;  // grows a carried box by 10 px a frame, keeps it 2 frames
  BoxTracker<T> tracker;
  detail::PipelineWork<T> w;
  PipelineResult<T> r = test::fresh_result(o, f.size());
  detail::collect_boxes(f.frame(), o, &tracker, &w.regions, &r);
  ASSERT_TRUE(r.tracker.ran()) << r.tracker.reason;
  // Tracked boxes first (person, chair: new tracks), then the untracked TV.
  ASSERT_EQ(w.regions.boxes.size(), 3u);
  expect_box(w.regions.boxes[0], 0, 95, 95, 205, 305);
  expect_box(w.regions.boxes[1], 56, 295, 195, 385, 305);
  expect_box(w.regions.boxes[2], 62, 45, 45, 155, 155);
  ASSERT_EQ(w.regions.box_track_id.size(), 3u);
  const std::int64_t person = w.regions.box_track_id[0], chair = w.regions.box_track_id[1];
  EXPECT_GE(person, 0);
  EXPECT_GE(chair, 0);
  EXPECT_NE(person, chair);
  EXPECT_EQ(w.regions.box_track_id[2], -1);
  EXPECT_EQ(w.regions.dyn_box_source, (std::vector<std::int32_t>{0, 1}));

  // Next frame the detector sees only the TV: person and chair are carried, still (one detection, no
  // velocity), grown by 10 px on each side.
  f.detections.erase(f.detections.begin() + 1, f.detections.end());
  PipelineResult<T> r2 = test::fresh_result(o, f.size());
  const auto work_before = test::parts_of(w);
  const auto result_before = test::parts_of(r2);
  detail::collect_boxes(f.frame(), o, &tracker, &w.regions, &r2);
  ASSERT_TRUE(r2.tracker.ran()) << r2.tracker.reason;
  ASSERT_EQ(w.regions.boxes.size(), 3u);
  expect_box(w.regions.boxes[0], 0, 85, 85, 215, 315);
  expect_box(w.regions.boxes[1], 56, 285, 185, 395, 315);
  expect_box(w.regions.boxes[2], 62, 45, 45, 155, 155);
  EXPECT_EQ(w.regions.box_track_id, (std::vector<std::int64_t>{person, chair, -1}));
  EXPECT_EQ(w.regions.dyn_box_track_id, (std::vector<std::int64_t>{person, chair}));
  test::expect_only_changed(work_before, test::parts_of(w), {"regions"});
  test::expect_only_changed(result_before, test::parts_of(r2), {"detections", "tracker"});
}

TYPED_TEST(BoxesStageTest, WithoutDetectionsTheFilterSaysSoAndNoRegionIsLeft) {
  using T = TypeParam;
  auto f = living_room<T>();
  f.with_detections = false;
  const PipelineOptions<T> o;
  BoxTracker<T> tracker;
  detail::PipelineWork<T> w;
  w.regions.boxes.resize(4);  // a previous frame's boxes: not carried into this one
  w.regions.dyn_boxes.resize(2);
  PipelineResult<T> r = test::fresh_result(o, f.size());
  detail::collect_boxes(f.frame(), o, &tracker, &w.regions, &r);
  test::expect_lacks_input(r.detections, "detections");
  EXPECT_TRUE(w.regions.boxes.empty());
  EXPECT_TRUE(w.regions.dyn_boxes.empty());
  EXPECT_TRUE(w.regions.dyn_box_track_id.empty());
}

TYPED_TEST(BoxesStageTest, DisabledFilterPassesTheBoxesAsDrawn) {
  using T = TypeParam;
  const auto f = living_room<T>();
  PipelineOptions<T> o;
  o.detections.enabled = false;
  BoxTracker<T> tracker;
  detail::PipelineWork<T> w;
  PipelineResult<T> r = test::fresh_result(o, f.size());
  detail::collect_boxes(f.frame(), o, &tracker, &w.regions, &r);
  EXPECT_FALSE(r.detections.enabled);
  EXPECT_FALSE(r.detections.ran());
  // All four, unpadded, the low-confidence cup included (a medium-level region).
  ASSERT_EQ(w.regions.boxes.size(), 4u);
  expect_box(w.regions.boxes[1], 0, 100, 100, 200, 300);
  ASSERT_EQ(w.regions.dyn_boxes.size(), 3u);
  EXPECT_EQ(w.regions.dyn_box_source, (std::vector<std::int32_t>{1, 2, 3}));
  expect_box(w.regions.dyn_boxes[1], 41, 400, 400, 420, 420);
}

}  // namespace
}  // namespace dyncull
