// The multi-view stage (stages/multiview.hpp) on its own: keyframe points compared with the current depth
// (RTD-SLAM §III.A), the moving region grown over the depth image and read at each feature, the region
// limited to the candidates when static features are not overridden, and each input it can lack.
#include "dyncull/culling/stages/listed.hpp"

#include "support/stage_context.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace dyncull {
namespace {

template <class T>
class MultiViewStageTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(MultiViewStageTest, Scalars, );  // trailing comma: clang -Wpedantic rejects an empty variadic

/// A wall at 2 m seen from the same pose as a stored keyframe; since then an object came in at 1 m over
/// columns 20-39, rows 10-29. Keyframe points (with their depth then, 2 m) at (30, 20) in the object's
/// area and at (50, 40), (10, 40) on the wall. Features: 0 (25, 15), 3 (35, 25) and 4 (22, 12) on the
/// object; 1 (45, 15) and 2 (30, 35) on the wall.
template <class T>
struct KeyframeScene {
  test::StageFrame<T> f{64, 48};
  KeyframeRing<T> keyframes{4};
  KeyframeScene() {
    f.fill_depth(2.f);
    f.paint_depth(20, 10, 40, 30, 1.f);
    for (auto xy : {std::pair<int, int>{25, 15}, {45, 15}, {30, 35}, {35, 25}, {22, 12}}) f.add(T(xy.first), T(xy.second));
    const std::vector<Vec2<T>> points{Vec2<T>(T(30), T(20)), Vec2<T>(T(50), T(40)), Vec2<T>(T(10), T(40))};
    const std::vector<T> depths(3, T(2));
    EXPECT_EQ(keyframes.push(f.cam_from_world, points, depths), Status::Ok);
  }
  void check(const PipelineOptions<T>& o, detail::PipelineWork<T>* w, PipelineResult<T>* r) const {
    detail::run_listed_stage(f.frame(), o, detail::StageContext<T>{*w, keyframes}, &test::multiview_marks(w), r);
  }
};

template <class T>
PipelineOptions<T> multiview_on() {
  PipelineOptions<T> o;
  o.multiview.enabled = true;  // tau_d 0.4 m, region growing within 0.2 m of the seed
  return o;
}

TYPED_TEST(MultiViewStageTest, FeaturesInTheGrownRegionAreFlagged) {
  using T = TypeParam;
  const KeyframeScene<T> s;
  const auto o = multiview_on<T>();
  detail::PipelineWork<T> w;
  PipelineResult<T> r = test::fresh_result(o, s.f.size());
  const auto work_before = test::parts_of(w);
  const auto result_before = test::parts_of(r);
  s.check(o, &w, &r);

  ASSERT_TRUE(r.multiview.ran()) << r.multiview.reason;
  ASSERT_TRUE(test::multiview_marks(&w).ok);
  // Keyframe point (30, 20) projects to itself at 2 m; the depth there is now 1 m: 2 - 1 > 0.4, moving.
  // Grown over the 1 m patch (20 x 20 pixels), it holds features 0, 3 and 4.
  EXPECT_EQ(test::multiview_marks(&w).marks, (std::vector<std::uint8_t>{1, 0, 0, 1, 1}));
  EXPECT_EQ(r.multiview.num_dynamic, 3u);
  std::size_t set = 0;
  for (std::uint8_t p : test::multiview_marks(&w).work.mask.pixels) set += p != 0;
  EXPECT_EQ(set, 400u);
  test::expect_only_changed(work_before, test::parts_of(w), {"multiview"});
  test::expect_only_changed(result_before, test::parts_of(r), {"multiview"});
}

TYPED_TEST(MultiViewStageTest, EachMissingInputIsNamedAndNothingIsFlagged) {
  using T = TypeParam;
  const auto o = multiview_on<T>();
  // Each reason named by a word of the input it lacked (or of what it found nothing to do with).
  auto expect_skipped = [](const detail::PipelineWork<T>& w, const PipelineResult<T>& r, const char* why) {
    EXPECT_FALSE(test::multiview_marks(&w).ok);
    EXPECT_FALSE(r.multiview.ran());
    EXPECT_TRUE(r.multiview.enabled);
    EXPECT_NE(r.multiview.reason.find(why), std::string::npos) << r.multiview.reason;
    EXPECT_EQ(test::multiview_marks(&w).marks, std::vector<std::uint8_t>(5, 0));
  };
  {
    KeyframeScene<T> s;
    s.f.with_pose = false;
    detail::PipelineWork<T> w;
    PipelineResult<T> r = test::fresh_result(o, s.f.size());
    s.check(o, &w, &r);
    expect_skipped(w, r, "cam_from_world");
  }
  {
    KeyframeScene<T> s;
    s.keyframes.clear();
    detail::PipelineWork<T> w;
    PipelineResult<T> r = test::fresh_result(o, s.f.size());
    s.check(o, &w, &r);
    expect_skipped(w, r, "keyframe");
  }
  {
    KeyframeScene<T> s;
    s.f.depth.clear();
    detail::PipelineWork<T> w;
    PipelineResult<T> r = test::fresh_result(o, s.f.size());
    s.check(o, &w, &r);
    expect_skipped(w, r, "depth");
  }
  {
    KeyframeScene<T> s;
    auto far = o;
    far.multiview.max_reference_depth_m = T(1);  // every keyframe point (2 m) is gated out
    detail::PipelineWork<T> w;
    PipelineResult<T> r = test::fresh_result(far, s.f.size());
    s.check(far, &w, &r);
    expect_skipped(w, r, "no keyframe point could be compared");
  }
}

TYPED_TEST(MultiViewStageTest, DisabledFlagsNothing) {
  using T = TypeParam;
  const KeyframeScene<T> s;
  const PipelineOptions<T> o;
  detail::PipelineWork<T> w;
  test::multiview_marks(&w).ok = true;  // a previous frame's
  PipelineResult<T> r = test::fresh_result(o, s.f.size());
  s.check(o, &w, &r);
  EXPECT_FALSE(r.multiview.enabled);
  EXPECT_FALSE(test::multiview_marks(&w).ok);
  EXPECT_EQ(test::multiview_marks(&w).marks, std::vector<std::uint8_t>(5, 0));
}

}  // namespace
}  // namespace dyncull
