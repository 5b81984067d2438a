// The inputs stage (stages/inputs.hpp) on its own: every stage report reset and enabled as the options
// say, and a frame refused (every keypoint kept, the reason naming the input) when it cannot be culled.
#include "dyncull/culling/stages/inputs.hpp"

#include "support/stage_context.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

namespace dyncull {
namespace {

template <class T>
class InputsStageTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(InputsStageTest, Scalars, );  // trailing comma: clang -Wpedantic rejects an empty variadic

TYPED_TEST(InputsStageTest, BeginFrameResetsEveryReportAndEnablesItFromTheOptions) {
  using T = TypeParam;
  PipelineResult<T> r;
  // A previous frame's outcome.
  for (StageReport* st : {&r.detections, &r.tracker, &r.box_rule, &r.depth_mask, &r.probability,
                          &r.moving_consistency, &r.reprojection, &r.coherent_motion, &r.subbox, &r.multiview,
                          &r.static_history}) {
    st->status = Status::Ok;
    st->reason = "last frame";
    st->num_dynamic = 5;
  }
  r.status = Status::InvalidInput;
  r.reason = "last frame";
  r.guard = GuardAction::Undone;
  r.guard_restored = 3;
  r.history_kept = 2;
  r.unsheltered = 1;
  PipelineOptions<T> o;
  o.tracker.enabled = true;
  o.subbox.enabled = false;
  o.multiview.enabled = true;
  o.static_history.enabled = true;
  detail::begin_frame(o, &r);

  EXPECT_EQ(r.status, Status::Ok);
  EXPECT_TRUE(r.reason.empty());
  EXPECT_EQ(r.guard, GuardAction::None);
  EXPECT_EQ(r.guard_restored, 0u);
  EXPECT_EQ(r.history_kept, 0u);
  EXPECT_EQ(r.unsheltered, 0u);
  for (const StageReport* st : {&r.detections, &r.tracker, &r.box_rule, &r.depth_mask, &r.probability,
                                &r.moving_consistency, &r.reprojection, &r.coherent_motion, &r.subbox, &r.multiview,
                                &r.static_history}) {
    EXPECT_EQ(st->status, Status::Skipped);
    EXPECT_TRUE(st->reason.empty()) << st->reason;
    EXPECT_EQ(st->num_dynamic, 0u);
  }
  // Defaults (filter, box rule, moving consistency) and the four switched above.
  EXPECT_TRUE(r.detections.enabled);
  EXPECT_TRUE(r.tracker.enabled);
  EXPECT_TRUE(r.box_rule.enabled);
  EXPECT_FALSE(r.depth_mask.enabled);
  EXPECT_FALSE(r.probability.enabled);
  EXPECT_TRUE(r.moving_consistency.enabled);
  EXPECT_FALSE(r.reprojection.enabled);
  EXPECT_FALSE(r.coherent_motion.enabled);
  EXPECT_FALSE(r.subbox.enabled);
  EXPECT_TRUE(r.multiview.enabled);
  EXPECT_TRUE(r.static_history.enabled);
}

/// Five keypoints with tracks, a depth image and a detection.
template <class T>
test::StageFrame<T> five_features() {
  test::StageFrame<T> f(64, 48);
  f.fill_depth(2.f);
  for (int i = 0; i < 5; ++i) f.add(T(10 + 8 * i), T(20), T(9 + 8 * i), T(20));
  f.detect(0, T(5), T(5), T(30), T(40));
  return f;
}

/// The frame was refused: every keypoint Static and kept, the reason naming `field`.
template <class T>
void expect_refused(const PipelineResult<T>& r, std::size_t n, const char* field) {
  EXPECT_NE(r.status, Status::Ok);
  EXPECT_NE(r.reason.find(field), std::string::npos) << r.reason;
  EXPECT_EQ(r.num_features, n);
  EXPECT_EQ(r.labels, std::vector<FeatureLabel>(n, FeatureLabel::Static));
  EXPECT_EQ(r.reasons, std::vector<CullReason>(n, CullReason::None));
  EXPECT_EQ(r.keep, std::vector<std::uint8_t>(n, 1));
  EXPECT_EQ(r.num_static, n);
  EXPECT_EQ(r.num_dynamic, 0u);
  EXPECT_EQ(r.trace.size(), n);
}

template <class T>
bool accept(const test::StageFrame<T>& f, const PipelineOptions<T>& o, PipelineResult<T>* r) {
  detail::begin_frame(o, r);
  return detail::accept_inputs(f.frame(), o, r);
}

TYPED_TEST(InputsStageTest, AValidFrameIsAcceptedWithEveryKeypointStaticSoFar) {
  using T = TypeParam;
  const auto f = five_features<T>();
  const PipelineOptions<T> o;
  PipelineResult<T> r;
  ASSERT_TRUE(accept(f, o, &r)) << r.reason;
  EXPECT_EQ(r.status, Status::Ok);
  EXPECT_EQ(r.num_features, 5u);
  EXPECT_EQ(r.labels, std::vector<FeatureLabel>(5, FeatureLabel::Static));
  EXPECT_EQ(r.reasons, std::vector<CullReason>(5, CullReason::None));
}

TYPED_TEST(InputsStageTest, FrameWithoutKeypointsHasNothingToLabel) {
  using T = TypeParam;
  const PipelineOptions<T> o;
  PipelineResult<T> r;
  r.labels.assign(3, FeatureLabel::Dynamic);  // a previous frame's
  r.keep.assign(3, 0);
  CullingFrame<T, std::vector<Vec2<T>>> frame;
  detail::begin_frame(o, &r);
  EXPECT_FALSE(detail::accept_inputs(frame, o, &r));
  EXPECT_NE(r.status, Status::Ok);
  EXPECT_NE(r.reason.find("keypoints"), std::string::npos) << r.reason;
  EXPECT_TRUE(r.labels.empty());
  EXPECT_TRUE(r.keep.empty());
  EXPECT_EQ(r.num_features, 0u);
}

TYPED_TEST(InputsStageTest, InvalidOptionsOrDepthRefuseTheFrameNamingTheField) {
  using T = TypeParam;
  auto f = five_features<T>();
  PipelineOptions<T> o;
  o.guard.min_fraction = 2;
  PipelineResult<T> r;
  EXPECT_FALSE(accept(f, o, &r));
  expect_refused(r, 5, "invalid options: guard.min_fraction");

  const PipelineOptions<T> valid;
  auto frame = f.frame();
  frame.depth.units_per_metre = -1.f;
  detail::begin_frame(valid, &r);
  EXPECT_FALSE(detail::accept_inputs(frame, valid, &r));
  expect_refused(r, 5, "units_per_metre");
}

TYPED_TEST(InputsStageTest, PerKeypointInputsOfAnotherLengthRefuseTheFrame) {
  using T = TypeParam;
  const PipelineOptions<T> o;
  PipelineResult<T> r;
  {
    auto f = five_features<T>();
    f.track_valid = {1, 1, 1};
    EXPECT_FALSE(accept(f, o, &r));
    expect_refused(r, 5, "track_valid");
  }
  {
    auto f = five_features<T>();
    f.prev_keypoints.pop_back();
    EXPECT_FALSE(accept(f, o, &r));
    expect_refused(r, 5, "prev_keypoints");
  }
  {
    auto f = five_features<T>();
    f.track_ids = {1, 2};
    EXPECT_FALSE(accept(f, o, &r));
    expect_refused(r, 5, "track_ids");
  }
  {
    auto f = five_features<T>();
    f.points_3d.assign(6, Vec3<T>(T(0), T(0), T(1)));
    EXPECT_FALSE(accept(f, o, &r));
    expect_refused(r, 5, "points_3d");
  }
  {
    // Inputs not given are not checked: they are missing, which the stages needing them report.
    auto f = five_features<T>();
    f.with_tracks = false;
    f.with_detections = false;
    f.depth.clear();
    EXPECT_TRUE(accept(f, o, &r)) << r.reason;
  }
}

}  // namespace
}  // namespace dyncull
