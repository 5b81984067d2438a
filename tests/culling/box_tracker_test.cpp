#include "dyncull/culling/box_tracker.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace {
using namespace dyncull;

template <class T>
class BoxTrackerT : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(BoxTrackerT, Scalars, );

template <class T>
Detection<T> person_at(T x) {
  return Detection<T>{Box<T>{x, T(100), x + T(80), T(400)}, 0, T(0.9)};
}

TYPED_TEST(BoxTrackerT, MissedDetectionIsCarriedForwardThenDropped) {
  using T = TypeParam;
  BoxTracker<T> tracker;  // grow 10 px per frame, drop after 2 missed frames
  const int W = 640, H = 480;
  // The person walks 6 px per frame to the right for three frames.
  for (int f = 0; f < 3; ++f) {
    const auto r = tracker.update({person_at(T(100 + 6 * f))}, W, H);
    ASSERT_TRUE(r.ok());
    ASSERT_EQ(r.boxes.size(), 1u);
    EXPECT_EQ(r.carried[0], 0);
    EXPECT_EQ(r.track_id[0], 0);
  }
  EXPECT_EQ(tracker.tracks()[0].hits, 3);
  EXPECT_NEAR(tracker.tracks()[0].velocity.x(), T(4.5), T(1e-4));  // EMA 0.5 of 0, 6, 6
  // Detector misses: carried with its velocity and grown.
  auto r = tracker.update({}, W, H);
  ASSERT_EQ(r.boxes.size(), 1u);
  EXPECT_EQ(r.carried[0], 1);
  EXPECT_EQ(r.num_carried, 1u);
  EXPECT_NEAR(r.boxes[0].box.x0, T(112 + 4.5 - 10), T(1e-4));
  EXPECT_NEAR(r.boxes[0].box.x1, T(192 + 4.5 + 10), T(1e-4));
  EXPECT_NEAR(r.boxes[0].box.y0, T(90), T(1e-4));
  r = tracker.update({}, W, H);
  ASSERT_EQ(r.boxes.size(), 1u);
  EXPECT_NEAR(r.boxes[0].box.x0, T(112 + 9 - 20), T(1e-4));
  r = tracker.update({}, W, H);  // third miss: dropped
  EXPECT_TRUE(r.boxes.empty());
  EXPECT_EQ(r.num_dropped, 1u);
  EXPECT_TRUE(tracker.tracks().empty());
  // A new detection starts a new track.
  r = tracker.update({person_at(T(300))}, W, H);
  EXPECT_EQ(r.num_new, 1u);
  EXPECT_EQ(r.track_id[0], 1);
}

// One result reused over a sequence (tracks, misses, drops, an invalid box) reads as fresh results do.
TYPED_TEST(BoxTrackerT, OutParameterFormMatchesFreshResultsOverASequence) {
  using T = TypeParam;
  const T nan = std::numeric_limits<T>::quiet_NaN();
  const std::vector<std::vector<Detection<T>>> frames = {
      {person_at(T(100)), person_at(T(400))},
      {person_at(T(106)), Detection<T>{Box<T>{nan, T(0), T(1), T(1)}, 0, T(1)}},
      {},
      {},
      {},
      {person_at(T(300))}};
  BoxTracker<T> reused, fresh;
  BoxTrackerResult<T> out;
  for (const auto& dets : frames) {
    reused.update(dets, 640, 480, &out);
    const BoxTrackerResult<T> want = fresh.update(dets, 640, 480);
    EXPECT_EQ(out.status, want.status);
    EXPECT_EQ(out.reason, want.reason);
    ASSERT_EQ(out.boxes.size(), want.boxes.size());
    for (std::size_t i = 0; i < out.boxes.size(); ++i) EXPECT_EQ(out.boxes[i].box.x0, want.boxes[i].box.x0);
    EXPECT_EQ(out.carried, want.carried);
    EXPECT_EQ(out.track_id, want.track_id);
    EXPECT_EQ(out.num_matched, want.num_matched);
    EXPECT_EQ(out.num_new, want.num_new);
    EXPECT_EQ(out.num_carried, want.num_carried);
    EXPECT_EQ(out.num_dropped, want.num_dropped);
  }
  reused.update({}, 0, 480, &out);
  EXPECT_EQ(out.status, Status::InvalidInput);
  EXPECT_TRUE(out.boxes.empty());
}

TYPED_TEST(BoxTrackerT, RedetectionContinuesTheTrack) {
  using T = TypeParam;
  BoxTracker<T> tracker;
  tracker.update({person_at(T(100))}, 640, 480);
  tracker.update({person_at(T(110))}, 640, 480);
  tracker.update({}, 640, 480);  // missed once
  const auto r = tracker.update({person_at(T(130))}, 640, 480);
  ASSERT_EQ(r.boxes.size(), 1u);
  EXPECT_EQ(r.num_matched, 1u);
  EXPECT_EQ(r.track_id[0], 0);
  EXPECT_EQ(r.carried[0], 0);
  // Velocity from the last real detection over the gap: (130 - 110) / 2 = 10 px per frame.
  EXPECT_NEAR(tracker.tracks()[0].velocity.x(), T(0.5) * T(5) + T(0.5) * T(10), T(1e-4));
}

TYPED_TEST(BoxTrackerT, ClassesBoundsAndBadInput) {
  using T = TypeParam;
  BoxTracker<T> tracker;
  tracker.update({person_at(T(100))}, 640, 480);
  Detection<T> chair = person_at(T(100));
  chair.class_id = 56;
  auto r = tracker.update({chair}, 640, 480);  // same place, other class: new track, person carried
  EXPECT_EQ(r.num_new, 1u);
  EXPECT_EQ(r.num_carried, 1u);
  EXPECT_EQ(r.boxes.size(), 2u);
  // A box that leaves the image is dropped, not carried.
  BoxTracker<T> edge;
  edge.update({Detection<T>{Box<T>{T(600), T(100), T(639), T(200)}, 0, T(1)}}, 640, 480);
  edge.update({Detection<T>{Box<T>{T(660), T(100), T(700), T(200)}, 0, T(1)}}, 640, 480);
  EXPECT_EQ(edge.tracks().size(), 2u);
  r = edge.update({}, 640, 480);
  EXPECT_EQ(r.num_dropped, 1u);  // the off-image one
  for (const auto& d : r.boxes) EXPECT_LE(d.box.x1, T(639));
  // Invalid detections are ignored with a reason; a bad image size changes nothing.
  const T nan = std::numeric_limits<T>::quiet_NaN();
  BoxTracker<T> t2;
  r = t2.update({Detection<T>{Box<T>{nan, T(0), T(10), T(10)}, 0, T(1)}}, 640, 480);
  EXPECT_TRUE(r.ok());
  EXPECT_FALSE(r.reason.empty());
  EXPECT_TRUE(t2.tracks().empty());
  EXPECT_EQ(t2.update({person_at(T(1))}, 0, 480).status, Status::InvalidInput);
  EXPECT_TRUE(t2.tracks().empty());
  t2.update({person_at(T(1))}, 640, 480);
  t2.reset();
  EXPECT_TRUE(t2.tracks().empty());
}

TYPED_TEST(BoxTrackerT, OptionsAreValidatedWithTheFieldNamed) {
  using T = TypeParam;
  std::string why = "unchanged";
  EXPECT_EQ(BoxTrackerOptions<T>{}.validate(&why), Status::Ok);
  EXPECT_TRUE(why.empty());
  const T nan = std::numeric_limits<T>::quiet_NaN(), inf = std::numeric_limits<T>::infinity();
  struct Case {
    const char* field;
    BoxTrackerOptions<T> o;
  };
  std::vector<Case> cases;
  auto add = [&](const char* field, auto spoil) {
    BoxTrackerOptions<T> o;
    spoil(o);
    cases.push_back({field, o});
  };
  add("grow_px_per_frame", [&](BoxTrackerOptions<T>& o) { o.grow_px_per_frame = nan; });
  add("grow_px_per_frame", [&](BoxTrackerOptions<T>& o) { o.grow_px_per_frame = inf; });
  add("grow_px_per_frame", [&](BoxTrackerOptions<T>& o) { o.grow_px_per_frame = T(-1); });
  add("max_missed_frames", [&](BoxTrackerOptions<T>& o) { o.max_missed_frames = -1; });
  add("max_missed_frames", [&](BoxTrackerOptions<T>& o) { o.max_missed_frames = 1 << 30; });
  for (const Case& c : cases) {
    EXPECT_EQ(c.o.validate(&why), Status::InvalidInput) << c.field;
    EXPECT_NE(why.find(c.field), std::string::npos) << why;
    BoxTracker<T> tracker(c.o);
    const BoxTrackerResult<T> r = tracker.update({person_at(T(100))}, 640, 480);
    EXPECT_EQ(r.status, Status::InvalidInput) << c.field;
    EXPECT_NE(r.reason.find(c.field), std::string::npos) << r.reason;
    EXPECT_TRUE(r.boxes.empty());
    EXPECT_TRUE(tracker.tracks().empty());  // state untouched
  }
}

// Whatever the detections (NaN, inverted, huge finite, off the image), every box the tracker
// carries is valid and inside the image, and the tracks stay bounded.
TYPED_TEST(BoxTrackerT, CarriedBoxesStayValidOnAwkwardDetections) {
  using T = TypeParam;
  const T big = std::numeric_limits<T>::max(), nan = std::numeric_limits<T>::quiet_NaN();
  const T values[] = {T(0), T(100), T(639), T(-50), T(700), T(5e9), -T(5e9), big, -big, nan};
  std::uint64_t state = 1;
  auto pick = [&]() {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return values[(state >> 33) % (sizeof(values) / sizeof(values[0]))];
  };
  BoxTracker<T> tracker;
  for (int frame = 0; frame < 200; ++frame) {
    std::vector<Detection<T>> dets;
    for (int d = 0; d < 4; ++d) dets.push_back(Detection<T>{Box<T>{pick(), pick(), pick(), pick()}, d % 2, T(1)});
    if (frame % 3 == 0) dets.push_back(person_at(T(frame % 500)));
    const BoxTrackerResult<T> r = tracker.update(dets, 640, 480);
    ASSERT_TRUE(r.ok()) << r.reason;
    ASSERT_EQ(r.boxes.size(), r.carried.size());
    for (std::size_t b = 0; b < r.boxes.size(); ++b) {
      if (!r.carried[b]) continue;
      const Box<T>& box = r.boxes[b].box;
      EXPECT_TRUE(box.valid()) << "frame " << frame;
      EXPECT_GE(box.x0, T(0));
      EXPECT_GE(box.y0, T(0));
      EXPECT_LE(box.x1, T(639));
      EXPECT_LE(box.y1, T(479));
    }
    EXPECT_LE(tracker.tracks().size(), 5u * 3u);  // at most max_missed_frames + 1 generations of 5
  }
}
}  // namespace
