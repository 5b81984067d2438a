// Bad input to cull_frame: options out of range (PipelineOptions::validate and its nested structs),
// per-keypoint inputs of the wrong length, huge depths through the recommended preset, and random frames
// with NaN / Inf / huge values: a non-Ok status with a reason, or defined labels and a parallel keep mask.
// Missing input: a frame without an input an enabled stage needs says MissingInput, naming both.
#include "dyncull/core/random.hpp"
#include "dyncull/culling/pipeline.hpp"
#include "dyncull/culling/presets.hpp"

#include "support/culling_frames.hpp"
#include "support/culling_scenes.hpp"

#include <gtest/gtest.h>

#include <climits>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace dyncull {
namespace {

template <class T>
class PipelineInputsTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(PipelineInputsTest, Scalars, );  // trailing comma: clang -Wpedantic rejects an empty variadic

using test::detections_of;
using test::frame_of;  // the scene's frame as a front end would pass it (no 3-D points)

template <class T>
void expect_nothing_culled(const PipelineResult<T>& r, std::size_t n, const char* field) {
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.reason.find(field), std::string::npos) << r.reason;
  ASSERT_EQ(r.labels.size(), n);
  ASSERT_EQ(r.keep.size(), n);
  for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(r.keep[i], 1);
  EXPECT_EQ(r.num_static, n);
}

TYPED_TEST(PipelineInputsTest, EveryPresetValidates) {
  using T = TypeParam;
  std::string why;
  // One preset at a time: g++ -O3 warns (maybe-uninitialized) on an initializer list of eight option structs.
  using Preset = PipelineOptions<T> (*)();
  const Preset all[] = {presets::none<T>,     presets::dld_slam<T>,   presets::rtd_slam<T>,
                        presets::zhu_2024<T>, presets::dfd_slam<T>,   presets::zhang_2023<T>,
                        presets::recommended<T>, [] { return PipelineOptions<T>{}; }};
  for (const Preset make : all) EXPECT_EQ(make().validate(&why), Status::Ok) << why;
}

TYPED_TEST(PipelineInputsTest, NestedReasonNamesTheStageAndTheField) {
  using T = TypeParam;
  std::string why;
  PipelineOptions<T> o = presets::recommended<T>();
  o.depth_mask.eps_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(o.validate(&why), Status::InvalidInput);
  EXPECT_EQ(why, "depth_mask.eps_m must be finite and in [0, 1e4] m");
  o = presets::recommended<T>();
  o.moving_consistency.refit_iterations = 1000000;
  EXPECT_EQ(o.validate(&why), Status::InvalidInput);
  EXPECT_NE(why.find("moving_consistency.refit_iterations"), std::string::npos) << why;
  o = presets::recommended<T>();
  o.subbox.dilation_radius_px = INT_MAX;
  EXPECT_EQ(o.validate(&why), Status::InvalidInput);
  EXPECT_NE(why.find("subbox.dilation_radius_px"), std::string::npos) << why;
}

TYPED_TEST(PipelineInputsTest, HugeReferenceKeyframeCountIsInvalidInputNotAnException) {
  using T = TypeParam;
  const auto s = test::make_culling_scene<T>();
  const auto dets = detections_of(s);
  PipelineOptions<T> o = presets::rtd_slam<T>();
  PipelineState<T> state;
  auto frame = frame_of(s, dets);
  frame.is_keyframe = true;
  cull_frame(frame, o, &state);  // stores a keyframe
  ASSERT_FALSE(state.keyframes.empty());
  o.multiview.max_reference_keyframes = std::numeric_limits<std::size_t>::max();
  frame.is_keyframe = false;
  const PipelineResult<T>* r = nullptr;
  EXPECT_NO_THROW(r = &cull_frame(frame, o, &state));
  ASSERT_NE(r, nullptr);
  expect_nothing_culled(*r, s.size(), "multiview.max_reference_keyframes");
  o.multiview.max_reference_keyframes = MultiViewStageOptions<T>::kMaxReferenceKeyframes;
  EXPECT_NO_THROW(r = &cull_frame(frame, o, &state));
  EXPECT_TRUE(r->ok()) << r->reason;
}

TYPED_TEST(PipelineInputsTest, SurvivorFractionOutOfRangeIsInvalidInputEvenWithTheGuardOff) {
  using T = TypeParam;
  const auto s = test::make_culling_scene<T>();
  const auto dets = detections_of(s);
  for (bool guard : {true, false})
    for (double fraction : {-1.0, std::numeric_limits<double>::quiet_NaN(), 1e30}) {
      PipelineOptions<T> o = presets::recommended<T>();
      o.guard.enabled = guard;
      o.guard.min_fraction = fraction;
      PipelineState<T> state;
      expect_nothing_culled(cull_frame(frame_of(s, dets), o, &state), s.size(), "guard.min_fraction");
    }
}

TYPED_TEST(PipelineInputsTest, EdgeEvidenceRadiusIsBounded) {
  using T = TypeParam;
  const auto s = test::make_culling_scene<T>();
  const auto dets = detections_of(s);
  for (int radius : {INT_MAX, 100000000, -1, 0}) {
    PipelineOptions<T> o = presets::recommended<T>();
    o.edge_evidence.radius_px = radius;
    PipelineState<T> state;
    expect_nothing_culled(cull_frame(frame_of(s, dets), o, &state), s.size(), "edge_evidence.radius_px");
  }
}

TYPED_TEST(PipelineInputsTest, TrackValidOfTheWrongLengthIsInvalidInput) {
  using T = TypeParam;
  const auto s = test::make_culling_scene<T>();
  const auto dets = detections_of(s);
  const PipelineOptions<T> o = presets::recommended<T>();
  PipelineState<T> state;
  auto frame = frame_of(s, dets);
  const std::vector<std::uint8_t> short_flags(s.size() / 2, 1);
  frame.track_valid = short_flags;
  expect_nothing_culled(cull_frame(frame, o, &state), s.size(), "track_valid");
  const std::vector<std::uint8_t> none;
  frame.track_valid = none;  // given but empty: a mismatch too
  expect_nothing_culled(cull_frame(frame, o, &state), s.size(), "track_valid");
  frame.track_valid = FlagView(nullptr, s.size());  // a count without flags
  expect_nothing_culled(cull_frame(frame, o, &state), s.size(), "track_valid");
  // Flags of the right length, or none at all, run the pipeline (labelled: this frame has no points_3d
  // or track_ids, which the preset's reprojection check and static history say they lack).
  frame.track_valid = s.track_valid;
  EXPECT_TRUE(cull_frame(frame, o, &state).labelled());
  frame.track_valid = nullptr;
  EXPECT_TRUE(cull_frame(frame, o, &state).labelled());
}

// Per-keypoint inputs of another length than the keypoints: the frame is refused with both sizes named.
TYPED_TEST(PipelineInputsTest, PerKeypointInputsOfAnotherLengthAreInvalidInputNamingBothSizes) {
  using T = TypeParam;
  const auto s = test::make_culling_scene<T>();
  const auto dets = detections_of(s);
  const std::string n = std::to_string(s.size());
  const std::vector<Vec2<T>> prev(s.prev_keypoints.begin(), s.prev_keypoints.begin() + 10);
  const std::vector<Vec3<T>> points(s.prev_points_world.begin(), s.prev_points_world.begin() + 10);
  const std::vector<std::int64_t> ids(10, 1);
  PipelineState<T> state;
  auto frame = frame_of(s, dets);
  frame.prev_keypoints = &prev;
  frame.track_valid = nullptr;
  expect_nothing_culled(cull_frame(frame, presets::recommended<T>(), &state), s.size(),
                        ("prev_keypoints has 10 positions for " + n + " keypoints").c_str());
  frame = frame_of(s, dets);
  frame.points_3d = &points;
  expect_nothing_culled(cull_frame(frame, presets::recommended<T>(), &state), s.size(),
                        ("points_3d has 10 points for " + n + " keypoints").c_str());
  frame = frame_of(s, dets);
  frame.track_ids = &ids;
  expect_nothing_culled(cull_frame(frame, presets::recommended<T>(), &state), s.size(),
                        ("track_ids has 10 ids for " + n + " keypoints").c_str());
}

/// Everything a frame can give, for the missing-input tests: one input at a time is then taken away.
template <class T>
struct FullFrame {
  test::CullingScene<T> scene = test::make_culling_scene<T>();
  std::vector<Detection<T>> dets = detections_of(scene);
  std::vector<std::int64_t> ids;
  test::SceneKeyframe<T> keyframe = test::make_scene_keyframe<T>(test::SceneConfig{}, 8, 600);
  FullFrame() {
    ids.resize(scene.size());
    for (std::size_t i = 0; i < ids.size(); ++i) ids[i] = static_cast<std::int64_t>(i);
  }
  CullingFrame<T, std::vector<Vec2<T>>> frame() const {
    auto f = frame_of(scene, dets);
    f.track_ids = &ids;
    f.points_3d = &scene.prev_points_world;
    return f;
  }
  /// A state holding one reference keyframe (or none).
  void prime(PipelineState<T>* state, bool with_keyframe) const {
    state->reset();
    if (with_keyframe) state->keyframes.push(keyframe.cam_from_world, keyframe.keypoints, keyframe.depth_m);
  }
};

/// The "stage: input" entries a frame without `input` must report under `o` (none: the preset does not
/// need it), from the stages the options enable.
template <class T>
std::vector<std::string> expected_missing(const PipelineOptions<T>& o, const std::string& input) {
  std::vector<std::string> out;
  if (input == "detections") {
    if (o.detections.enabled) {
      out.push_back("detections: no detections given");
    } else if (o.box_rule.enabled) {
      out.push_back("box_rule: no detections given");
    }
  } else if (input == "depth") {
    if (o.depth_mask.enabled) out.push_back("depth_mask: no depth given");
    if (o.multiview.enabled) out.push_back("multiview: no depth given");
  } else if (input == "prev_keypoints") {
    if (o.probability.enabled) out.push_back("probability: no prev_keypoints given");
    if (o.moving_consistency.enabled) out.push_back("moving_consistency: no prev_keypoints given");
  } else if (input == "points_3d") {
    if (o.reprojection.enabled) out.push_back("reprojection: no points_3d given");
  } else if (input == "cam_from_world") {
    if (o.multiview.enabled) out.push_back("multiview: no cam_from_world given");
  } else if (input == "keyframe") {
    if (o.multiview.enabled) out.push_back("multiview: no reference keyframe stored yet");
  } else if (input == "track_ids") {
    if (o.static_history.enabled) out.push_back("static_history: no track_ids given");
  }
  return out;
}

// For the recommended preset and each paper's, and for each input a stage of it needs: the full frame is
// Ok; without the input the frame is MissingInput, its reason names each stage (as its option) and the
// input, and the stage reports say so; the labels stay defined. An input no enabled stage needs changes
// nothing. Detections given as an empty vector (a frame without people) are not missing.
TYPED_TEST(PipelineInputsTest, AFrameLackingAStagesInputSaysWhichStageAndInput) {
  using T = TypeParam;
  const FullFrame<T> full;
  const std::size_t n = full.scene.size();
  const std::vector<Detection<T>> no_people;
  const std::vector<std::pair<const char*, PipelineOptions<T>>> presets_to_test = {
      {"recommended", presets::recommended<T>()}, {"none", presets::none<T>()},
      {"dld_slam", presets::dld_slam<T>()},       {"rtd_slam", presets::rtd_slam<T>()},
      {"zhu_2024", presets::zhu_2024<T>()},       {"dfd_slam", presets::dfd_slam<T>()},
      {"zhang_2023", presets::zhang_2023<T>()}};
  std::size_t missing_cases = 0;
  for (const auto& [name, o] : presets_to_test) {
    PipelineState<T> state;
    full.prime(&state, true);
    const PipelineResult<T>& all = cull_frame(full.frame(), o, &state);
    EXPECT_EQ(all.status, Status::Ok) << name << ": " << all.reason;
    EXPECT_TRUE(all.labelled()) << name;

    for (const std::string input :
         {"detections", "depth", "prev_keypoints", "points_3d", "cam_from_world", "keyframe", "track_ids"}) {
      auto frame = full.frame();
      if (input == "detections") frame.detections = nullptr;
      if (input == "depth") frame.depth = DepthView<float>{};
      if (input == "prev_keypoints") {
        frame.prev_keypoints = nullptr;
        frame.track_valid = nullptr;
      }
      if (input == "points_3d") frame.points_3d = nullptr;
      if (input == "cam_from_world") frame.cam_from_world = nullptr;
      if (input == "track_ids") frame.track_ids = nullptr;
      full.prime(&state, input != "keyframe");
      const PipelineResult<T>& r = cull_frame(frame, o, &state);
      const std::vector<std::string> expected = expected_missing(o, input);
      ASSERT_EQ(r.labels.size(), n) << name << " without " << input;
      EXPECT_TRUE(r.labelled()) << name << " without " << input << ": " << r.reason;
      if (expected.empty()) {
        EXPECT_EQ(r.status, Status::Ok) << name << " without " << input << ": " << r.reason;
        continue;
      }
      ++missing_cases;
      EXPECT_EQ(r.status, Status::MissingInput) << name << " without " << input << ": " << r.reason;
      for (const std::string& e : expected)
        EXPECT_NE(r.reason.find(e), std::string::npos) << name << " without " << input << ": " << r.reason;
      for (const StageReport* st : {&r.detections, &r.box_rule, &r.depth_mask, &r.probability, &r.moving_consistency,
                                    &r.reprojection, &r.multiview, &r.static_history})
        EXPECT_TRUE(st->status != Status::MissingInput || st->enabled) << name << " without " << input;
      for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(r.keep[i], r.labels[i] == FeatureLabel::Static ? 1 : 0);
    }

    // A frame without people: detections given, none in it.
    auto frame = full.frame();
    frame.detections = &no_people;
    full.prime(&state, true);
    const PipelineResult<T>& empty = cull_frame(frame, o, &state);
    EXPECT_EQ(empty.status, Status::Ok) << name << ": " << empty.reason;
  }
  EXPECT_GE(missing_cases, 15u) << "preset-stage-input cases that lacked an input";
}

// A stage switched off by its option is not missing anything, whatever the frame lacks.
TYPED_TEST(PipelineInputsTest, ADisabledStageIsNotMissingInput) {
  using T = TypeParam;
  const FullFrame<T> full;
  PipelineOptions<T> o = presets::recommended<T>();
  o.moving_consistency.enabled = false;
  o.probability.enabled = false;
  auto frame = full.frame();
  frame.prev_keypoints = nullptr;
  frame.track_valid = nullptr;
  PipelineState<T> state;
  full.prime(&state, true);
  const PipelineResult<T>& r = cull_frame(frame, o, &state);
  EXPECT_EQ(r.status, Status::Ok) << r.reason;
  EXPECT_EQ(r.moving_consistency.status, Status::Skipped);
}

TYPED_TEST(PipelineInputsTest, InvalidDepthViewIsInvalidInput) {
  using T = TypeParam;
  const auto s = test::make_culling_scene<T>();
  const auto dets = detections_of(s);
  auto frame = frame_of(s, dets);
  frame.depth.units_per_metre = -1.f;
  PipelineState<T> state;
  expect_nothing_culled(cull_frame(frame, presets::recommended<T>(), &state), s.size(), "units_per_metre");
}

// Units no depth sensor has (a denormal float passed every check, and no depth read as valid) and a
// range that holds no depth are refused at entry, naming the field.
TYPED_TEST(PipelineInputsTest, DepthUnitsNoSensorHasAndANonPositiveMaxDepthAreInvalidInput) {
  using T = TypeParam;
  const auto s = test::make_culling_scene<T>();
  const auto dets = detections_of(s);
  PipelineOptions<T> o = presets::recommended<T>();
  o.depth_mask.enabled = true;
  for (float units : {1e-40f, 1e-9f, 1e-4f, 1e7f, 1e9f}) {
    auto frame = frame_of(s, dets);
    frame.depth.units_per_metre = units;
    PipelineState<T> state;
    expect_nothing_culled(cull_frame(frame, o, &state), s.size(), "units_per_metre");
  }
  for (float max_m : {0.f, -1.f}) {
    auto frame = frame_of(s, dets);
    frame.depth.max_m = max_m;
    PipelineState<T> state;
    expect_nothing_culled(cull_frame(frame, o, &state), s.size(), "max_m");
  }
  auto frame = frame_of(s, dets);
  frame.depth.units_per_metre = 1e6f;  // the bounds themselves are sensors' units
  PipelineState<T> state;
  EXPECT_TRUE(cull_frame(frame, o, &state).labelled()) << state.result.reason;
  frame.depth.units_per_metre = 1e-3f;
  EXPECT_TRUE(cull_frame(frame, o, &state).labelled()) << state.result.reason;
}

TYPED_TEST(PipelineInputsTest, ZeroReferenceKeyframesIsInvalidInput) {
  using T = TypeParam;
  const FullFrame<T> full;
  PipelineOptions<T> o = presets::recommended<T>();
  o.multiview.enabled = true;
  o.multiview.max_reference_keyframes = 0;
  std::string why;
  EXPECT_EQ(o.validate(&why), Status::InvalidInput);
  EXPECT_EQ(why, "multiview.max_reference_keyframes must be in [1, 64]");
  PipelineState<T> state;
  full.prime(&state, true);
  expect_nothing_culled(cull_frame(full.frame(), o, &state), full.scene.size(), "multiview.max_reference_keyframes");
  o.multiview.max_reference_keyframes = 1;
  full.prime(&state, true);
  EXPECT_EQ(cull_frame(full.frame(), o, &state).status, Status::Ok) << state.result.reason;
}

// The frame status is the worst of its enabled stages': a stage that ran but could not do its job gives
// the frame its status and its name, outranking a missing input; the other stages' labels stand.
TYPED_TEST(PipelineInputsTest, AStageThatCouldNotDoItsJobGivesTheFrameItsStatusAndName) {
  using T = TypeParam;
  const FullFrame<T> full;
  const std::size_t n = full.scene.size();
  PipelineOptions<T> o = presets::recommended<T>();
  o.depth_mask.enabled = true;
  o.multiview.enabled = true;
  PipelineState<T> state;
  full.prime(&state, true);
  const PipelineResult<T>& good = cull_frame(full.frame(), o, &state);
  ASSERT_EQ(good.status, Status::Ok) << good.reason;
  EXPECT_TRUE(good.reason.empty()) << good.reason;
  const std::size_t culled_when_good = good.num_dynamic;
  ASSERT_GT(culled_when_good, 0u);

  // The only keyframe has no depth: no keyframe point can be compared (multiview: TooFewPoints).
  const std::vector<T> no_depth(full.keyframe.depth_m.size(), T(0));
  state.reset();
  state.keyframes.push(full.keyframe.cam_from_world, full.keyframe.keypoints, no_depth);
  const PipelineResult<T>& mv = cull_frame(full.frame(), o, &state);
  EXPECT_EQ(mv.multiview.status, Status::TooFewPoints);
  EXPECT_EQ(mv.status, Status::TooFewPoints) << mv.reason;
  EXPECT_NE(mv.reason.find("multiview: no keyframe point could be compared"), std::string::npos) << mv.reason;
  EXPECT_TRUE(mv.labelled());
  ASSERT_EQ(mv.keep.size(), n);
  EXPECT_GT(mv.num_dynamic, 0u) << "the other stages still cull";

  // TUM units with a range no 16-bit value reaches (the depth masks: InvalidInput), and no points_3d for
  // the reprojection check (MissingInput): the failure sets the status, both are named.
  const std::vector<std::uint16_t> raw = full.scene.depth_tum();
  const auto f = full.frame();
  CullingFrame<T, std::vector<Vec2<T>>, std::vector<Vec2<T>>, std::uint16_t> tum;
  tum.keypoints = f.keypoints;
  tum.prev_keypoints = f.prev_keypoints;
  tum.track_valid = f.track_valid;
  tum.track_ids = f.track_ids;
  tum.detections = f.detections;
  tum.camera = f.camera;
  tum.cam_from_world = f.cam_from_world;
  tum.depth = tum_depth_view(raw.data(), full.scene.width, full.scene.height, 20.f);
  ASSERT_EQ(tum.depth.validate(), Status::Ok);
  o.multiview.enabled = false;
  full.prime(&state, true);
  const PipelineResult<T>& dm = cull_frame(tum, o, &state);
  EXPECT_EQ(dm.depth_mask.status, Status::InvalidInput);
  EXPECT_EQ(dm.status, Status::InvalidInput) << dm.reason;
  EXPECT_NE(dm.reason.find("depth_mask: depth min_m and max_m leave no raw depth value valid"), std::string::npos)
      << dm.reason;
  EXPECT_NE(dm.reason.find("reprojection: no points_3d given"), std::string::npos) << dm.reason;
  EXPECT_TRUE(dm.labelled());
  ASSERT_EQ(dm.keep.size(), n);
  EXPECT_GT(dm.num_dynamic, 0u) << "the box rule still culls";
}

TYPED_TEST(PipelineInputsTest, HugeFloatDepthThroughTheRecommendedPreset) {
  using T = TypeParam;
  auto s = test::make_culling_scene<T>();
  const auto dets = detections_of(s);
  // Far surfaces at 1e20 m (finite floats; the view's max_m is 1e30): every box's histogram bins them.
  for (std::size_t k = 0; k < s.depth.size(); k += 3) s.depth[k] = 1e20f;
  PipelineState<T> state;
  const PipelineResult<T>& r = cull_frame(frame_of(s, dets), presets::recommended<T>(), &state);
  ASSERT_TRUE(r.labelled()) << r.reason;  // MissingInput: no points_3d or track_ids in this frame
  ASSERT_EQ(r.labels.size(), s.size());
  for (FeatureLabel l : r.labels) EXPECT_TRUE(l == FeatureLabel::Static || l == FeatureLabel::Dynamic);
}

/// A random value: mostly in [lo, hi), sometimes NaN, +-Inf, huge or negative.
template <class T>
T wild(Random& rng, double lo, double hi) {
  switch (rng.index(14)) {
    case 0: return std::numeric_limits<T>::quiet_NaN();
    case 1: return std::numeric_limits<T>::infinity();
    case 2: return -std::numeric_limits<T>::infinity();
    case 3: return std::numeric_limits<T>::max() * T(rng.uniform(-1, 1));
    case 4: return T(rng.uniform(-1e10, 1e10));
    default: return T(rng.uniform(lo, hi));
  }
}

TYPED_TEST(PipelineInputsTest, PropertyRandomFramesGiveAStatusOrDefinedLabels) {
  using T = TypeParam;
  Random rng(77);
  const PipelineOptions<T> bases[] = {presets::recommended<T>(), presets::dld_slam<T>(), presets::rtd_slam<T>(),
                                      presets::dfd_slam<T>(), presets::zhang_2023<T>()};
  const int w = 80, h = 60;
  PinholeCamera<T> camera;
  camera.width = w;
  camera.height = h;
  camera.fx = camera.fy = T(70);
  camera.cx = T(39.5);
  camera.cy = T(29.5);
  std::size_t checked = 0, stages_ran = 0;  // frames whose labels were checked; stages that ran in them
  for (int trial = 0; trial < 300; ++trial) {
    PipelineOptions<T> o = bases[rng.index(5)];
    o.moving_consistency.max_ransac_iterations = 50;
    o.reprojection.max_ransac_iterations = 50;
    switch (rng.index(8)) {  // now and then one absurd option
      case 0: o.guard.min_fraction = wild<double>(rng, 0, 1); break;
      case 1: o.depth_mask.max_object_depth_extent_m = wild<double>(rng, 0, 20); break;
      case 2: o.subbox.dilation_radius_px = static_cast<int>(rng.index(4)) * (INT_MAX / 3); break;
      case 3: o.multiview.max_reference_keyframes = rng.index(2) ? std::numeric_limits<std::size_t>::max() : rng.index(5); break;
      case 4: o.multiview.search_radius_px = static_cast<int>(rng.index(3)) * (INT_MAX / 2); break;
      default: break;
    }
    // A camera moving sideways past random 3-D points (the stages have real evidence to work on), with
    // one value in ten replaced by a wild one, and boxes of a person, a chair or a TV (now and then wild).
    Rigid3<T> pose;
    pose.t = Vec3<T>(rng.index(10) == 0 ? wild<T>(rng, -0.1, 0.1) : T(-0.08), T(0), T(0));
    const std::size_t n = rng.index(150);
    std::vector<Vec2<T>> kp(n), prev(n);
    std::vector<Vec3<T>> pts(n);
    std::vector<std::uint8_t> valid(n);
    std::vector<std::int64_t> ids(n);
    for (std::size_t i = 0; i < n; ++i) {
      pts[i] = Vec3<T>(T(rng.uniform(-1, 1)), T(rng.uniform(-0.7, 0.7)), T(rng.uniform(1, 4)));
      prev[i] = camera.project(pts[i]);
      kp[i] = camera.project(pose.apply(pts[i]));
      if (rng.index(10) == 0) kp[i] = Vec2<T>(wild<T>(rng, 0, w), wild<T>(rng, 0, h));
      if (rng.index(10) == 0) prev[i] = Vec2<T>(wild<T>(rng, 0, w), wild<T>(rng, 0, h));
      if (rng.index(10) == 0) pts[i] = Vec3<T>(wild<T>(rng, -1, 1), wild<T>(rng, -1, 1), wild<T>(rng, 0.5, 4));
      valid[i] = static_cast<std::uint8_t>(rng.index(10) != 0);
      ids[i] = static_cast<std::int64_t>(i);
    }
    std::vector<Detection<T>> dets(rng.index(4));
    const int classes[] = {0, 0, 56, 62};
    for (auto& d : dets) {
      const bool odd = rng.index(6) == 0;
      const T x0 = odd ? wild<T>(rng, -10, w) : T(rng.uniform(0, w / 2)), y0 = odd ? wild<T>(rng, -10, h) : T(rng.uniform(0, h / 2));
      d.box = Box<T>{x0, y0, x0 + (odd ? wild<T>(rng, 0, w) : T(rng.uniform(5, w / 2))),
                     y0 + (odd ? wild<T>(rng, 0, h) : T(rng.uniform(5, h / 2)))};
      d.class_id = odd ? static_cast<int>(rng.index(90)) - 5 : classes[rng.index(4)];
      d.confidence = odd ? wild<T>(rng, 0, 1) : T(0.9);
    }
    std::vector<float> depth(static_cast<std::size_t>(w * h));
    for (float& z : depth) z = rng.index(20) == 0 ? wild<float>(rng, 0, 6) : float(rng.uniform(0.5, 5));
    CullingFrame<T, std::vector<Vec2<T>>> frame;
    frame.keypoints = &kp;
    frame.prev_keypoints = &prev;
    frame.track_valid = valid;
    frame.track_ids = &ids;
    frame.points_3d = rng.index(2) ? &pts : nullptr;
    frame.detections = &dets;
    frame.depth = DepthView<float>{depth.data(), w, h, 0, 1.f, 0.f, 1e30f};
    frame.camera = camera;
    frame.cam_from_world = &pose;
    frame.evidence_frames = static_cast<int>(rng.index(4));
    PipelineState<T> state;
    for (int repeat = 0; repeat < 2; ++repeat) {
      frame.is_keyframe = repeat == 0;  // the second frame has a keyframe for the multi-view check
      const PipelineResult<T>* r = nullptr;
      ASSERT_NO_THROW(r = &cull_frame(frame, o, &state)) << trial;
      ASSERT_EQ(r->labels.size(), n) << trial;
      ASSERT_EQ(r->keep.size(), n) << trial;
      if (!r->labelled()) {
        EXPECT_FALSE(r->reason.empty()) << trial;
        continue;
      }
      ++checked;
      for (const StageReport* st : {&r->depth_mask, &r->moving_consistency, &r->reprojection, &r->subbox, &r->multiview})
        stages_ran += st->ran();
      for (std::size_t i = 0; i < n; ++i) {
        EXPECT_TRUE(r->labels[i] == FeatureLabel::Static || r->labels[i] == FeatureLabel::Dynamic) << trial;
        EXPECT_EQ(r->keep[i], r->labels[i] == FeatureLabel::Static ? 1 : 0) << trial;
      }
      EXPECT_EQ(r->num_static + r->num_dynamic, n) << trial;
    }
  }
  EXPECT_GT(checked, 300u) << "frames that reached the label checks";
  EXPECT_GT(stages_ran, 200u) << "geometric and depth stages that ran";
}

}  // namespace
}  // namespace dyncull
