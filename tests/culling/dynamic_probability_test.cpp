// DLD-SLAM §3.4 on synthetic flow with known truth: a still and a walking person, a pushed chair, a tv
// with a flow glitch, a person that stops, and camera motions where each flow model wins.
#include "dyncull/culling/dynamic_probability.hpp"
#include "dyncull/core/box.hpp"
#include "dyncull/core/camera.hpp"
#include "dyncull/core/random.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>
#include <vector>

namespace {
using namespace dyncull;

template <class T>
class DynamicProbability : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(DynamicProbability, Scalars, );

template <class T>
struct Frame {
  std::vector<Vec2<T>> prev, curr;
  std::vector<MotionLevel> levels;
  std::vector<int> group;  // scene object of each feature
  void add(Random& rng, int n, const Box<double>& region, MotionLevel level, Vec2<double> flow, double noise, int g) {
    for (int i = 0; i < n; ++i) {
      const Vec2<double> p(rng.uniform(region.x0, region.x1), rng.uniform(region.y0, region.y1));
      const Vec2<double> q = p + flow + noise * Vec2<double>(rng.normal(), rng.normal());
      prev.push_back(p.cast<T>());
      curr.push_back(q.cast<T>());
      levels.push_back(level);
      group.push_back(g);
    }
  }
  std::size_t count(const DynamicProbabilityResult<T>& r, int g, FeatureLabel l) const {
    std::size_t c = 0;
    for (std::size_t i = 0; i < group.size(); ++i) c += group[i] == g && r.labels[i] == l;
    return c;
  }
};

enum Group { kBackground, kStillPerson, kWalkingPerson, kPushedChair, kStillChair, kTvSet };

TYPED_TEST(DynamicProbability, StillPersonStaticWalkingPersonDynamic) {
  using T = TypeParam;
  Random rng(11);
  Frame<T> f;
  const Vec2<double> camera_flow(2.0, 1.0);  // small camera motion: the mean-flow model holds
  const double noise = 0.3;                  // LK noise, px per axis
  f.add(rng, 300, Box<double>{0, 0, 640, 480}, MotionLevel::Ignore, camera_flow, noise, kBackground);
  f.add(rng, 60, Box<double>{50, 100, 150, 400}, MotionLevel::High, camera_flow, noise, kStillPerson);
  f.add(rng, 60, Box<double>{300, 100, 400, 400}, MotionLevel::High, camera_flow + Vec2<double>(6, 0), noise,
        kWalkingPerson);
  f.add(rng, 30, Box<double>{450, 300, 520, 400}, MotionLevel::Medium, camera_flow + Vec2<double>(0, 4), noise,
        kPushedChair);
  f.add(rng, 30, Box<double>{530, 300, 600, 400}, MotionLevel::Medium, camera_flow, noise, kStillChair);
  const DynamicProbabilityResult<T> r =
      dynamic_probability(f.prev, f.curr, f.levels, DynamicProbabilityOptions<T>{});
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_FALSE(r.used_fallback);
  EXPECT_EQ(r.num_reference, 300u);
  EXPECT_NEAR(r.reference_flow.x(), T(2), T(0.1));
  EXPECT_NEAR(r.reference_flow.y(), T(1), T(0.1));
  // t = max(1.5, median + 3 * 1.4826 MAD): the floor dominates at 0.3 px noise.
  EXPECT_GE(r.motion_threshold_px, T(1.5));
  EXPECT_LT(r.motion_threshold_px, T(2.0));
  // Movers are 4-6 px off the camera flow, far above t: recall 1. Still features exceed 1.5 px
  // residual with probability exp(-1.5^2 / (2 * 0.3^2)) ~ 4e-6 each: no false positives.
  EXPECT_EQ(f.count(r, kWalkingPerson, FeatureLabel::Dynamic), 60u);
  EXPECT_EQ(f.count(r, kStillPerson, FeatureLabel::Dynamic), 0u);
  EXPECT_EQ(f.count(r, kPushedChair, FeatureLabel::Dynamic), 30u);
  EXPECT_EQ(f.count(r, kStillChair, FeatureLabel::Dynamic), 0u);
  EXPECT_EQ(f.count(r, kBackground, FeatureLabel::Dynamic), 0u);  // not in a mask: never culled here
  EXPECT_EQ(r.num_masked, 180u);
  EXPECT_EQ(r.num_dynamic, 90u);
  for (std::size_t i = 0; i < f.group.size(); ++i) {
    if (f.group[i] == kStillPerson) {
      EXPECT_NEAR(r.probability[i], T(0.4), T(1e-6));
    }
    if (f.group[i] == kWalkingPerson) {
      EXPECT_NEAR(r.probability[i], T(0.8), T(1e-6));
    }
    if (f.group[i] == kPushedChair) {
      EXPECT_NEAR(r.probability[i], T(0.6), T(1e-6));
    }
    if (r.labels[i] == FeatureLabel::Dynamic) {
      EXPECT_EQ(r.reasons[i], CullReason::Probability);
    }
  }
}

TYPED_TEST(DynamicProbability, TemporalTermFromTheTrackStore) {
  using T = TypeParam;
  // Frame by frame: background + one person (tracks 1000..1019) + one tv (tracks 2000..2009).
  TrackStateStore store;
  auto run = [&](Vec2<double> person_motion, Vec2<double> tv_motion) {
    Random rng(3);
    Frame<T> f;
    f.add(rng, 100, Box<double>{0, 0, 640, 480}, MotionLevel::Ignore, {1, 0}, 0.2, kBackground);
    f.add(rng, 20, Box<double>{100, 100, 200, 400}, MotionLevel::High, Vec2<double>(1, 0) + person_motion, 0.2,
          kWalkingPerson);
    f.add(rng, 10, Box<double>{400, 50, 500, 150}, MotionLevel::Low, Vec2<double>(1, 0) + tv_motion, 0.2, kTvSet);
    std::vector<std::int64_t> ids(f.group.size(), -1);
    for (std::size_t i = 100; i < 120; ++i) ids[i] = 1000 + std::int64_t(i);
    for (std::size_t i = 120; i < 130; ++i) ids[i] = 2000 + std::int64_t(i);
    DynamicProbabilityOptions<T> o;
    store.begin_frame();
    const auto r = dynamic_probability(f.prev, f.curr, f.levels, o, EgoMotion<T>{}, &store, &ids);
    return std::make_pair(f.count(r, kWalkingPerson, FeatureLabel::Dynamic), f.count(r, kTvSet, FeatureLabel::Dynamic));
  };
  EXPECT_EQ(run({5, 0}, {0, 0}), std::make_pair(std::size_t(20), std::size_t(0)));  // walking
  EXPECT_EQ(run({0, 0}, {4, 0}), std::make_pair(std::size_t(20), std::size_t(0)));  // stopped: K keeps it one frame; tv glitch: not enough
  EXPECT_EQ(run({0, 0}, {4, 0}), std::make_pair(std::size_t(0), std::size_t(10)));  // still person static; tv moved twice: dynamic
  EXPECT_EQ(run({0, 0}, {0, 0}), std::make_pair(std::size_t(0), std::size_t(0)));
  // Tracks unseen for more than max_age frames are forgotten.
  EXPECT_GT(store.size(), 0u);
  store.begin_frame();
  store.begin_frame();
  EXPECT_EQ(store.size(), 0u);
}

TYPED_TEST(DynamicProbability, FallbackWhenTooFewStaticFeatures) {
  using T = TypeParam;
  Random rng(5);
  Frame<T> f;
  f.add(rng, 3, Box<double>{0, 0, 640, 480}, MotionLevel::Ignore, {1, 1}, 0.1, kBackground);
  f.add(rng, 40, Box<double>{100, 100, 500, 400}, MotionLevel::High, {1, 1}, 0.1, kStillPerson);
  f.add(rng, 10, Box<double>{100, 100, 500, 400}, MotionLevel::High, {9, 1}, 0.1, kWalkingPerson);
  const auto r = dynamic_probability(f.prev, f.curr, f.levels, DynamicProbabilityOptions<T>{});
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r.used_fallback);
  EXPECT_FALSE(r.reason.empty());
  EXPECT_EQ(r.num_reference, 53u);
  EXPECT_EQ(r.motion_threshold_px, T(3));
  EXPECT_NEAR(r.reference_flow.x(), T(1), T(0.2));  // the median ignores the minority of movers
  EXPECT_EQ(f.count(r, kWalkingPerson, FeatureLabel::Dynamic), 10u);
  EXPECT_EQ(f.count(r, kStillPerson, FeatureLabel::Dynamic), 0u);
}

// A result and scratch reused after a fallback frame and a bad frame give what a fresh call gives.
TYPED_TEST(DynamicProbability, OutParameterFormMatchesAFreshResultWhenReused) {
  using T = TypeParam;
  Random rng(5);
  Frame<T> fallback, f;
  fallback.add(rng, 3, Box<double>{0, 0, 640, 480}, MotionLevel::Ignore, {1, 1}, 0.1, kBackground);
  fallback.add(rng, 80, Box<double>{100, 100, 500, 400}, MotionLevel::High, {9, 1}, 0.1, kWalkingPerson);
  f.add(rng, 100, Box<double>{0, 0, 640, 480}, MotionLevel::Ignore, {2, 1}, 0.3, kBackground);
  f.add(rng, 20, Box<double>{300, 100, 400, 400}, MotionLevel::High, {8, 1}, 0.3, kWalkingPerson);
  const DynamicProbabilityOptions<T> o;
  DynamicProbabilityResult<T> out;
  DynamicProbabilityScratch<T> scratch;
  dynamic_probability(fallback.prev, fallback.curr, fallback.levels, o, EgoMotion<T>{}, nullptr, nullptr, &out,
                      &scratch);
  ASSERT_TRUE(out.used_fallback);
  dynamic_probability(f.prev, fallback.curr, f.levels, o, EgoMotion<T>{}, nullptr, nullptr, &out, &scratch);
  ASSERT_EQ(out.status, Status::InvalidInput);
  dynamic_probability(f.prev, f.curr, f.levels, o, EgoMotion<T>{}, nullptr, nullptr, &out, &scratch);
  const DynamicProbabilityResult<T> fresh = dynamic_probability(f.prev, f.curr, f.levels, o);
  EXPECT_EQ(out.status, fresh.status);
  EXPECT_EQ(out.reason, fresh.reason);
  EXPECT_EQ(out.used_fallback, fresh.used_fallback);
  EXPECT_EQ(out.labels, fresh.labels);
  EXPECT_EQ(out.reasons, fresh.reasons);
  EXPECT_EQ(out.probability, fresh.probability);
  EXPECT_EQ(out.moving, fresh.moving);
  EXPECT_EQ(out.temporal, fresh.temporal);
  EXPECT_EQ(out.reference_flow, fresh.reference_flow);
  EXPECT_EQ(out.motion_threshold_px, fresh.motion_threshold_px);
  EXPECT_EQ(out.num_reference, fresh.num_reference);
  EXPECT_EQ(out.num_masked, fresh.num_masked);
  EXPECT_EQ(out.num_dynamic, fresh.num_dynamic);
  EXPECT_EQ(out.num_no_flow, fresh.num_no_flow);
}

TYPED_TEST(DynamicProbability, BadInputIsReportedNotCrashed) {
  using T = TypeParam;
  std::vector<Vec2<T>> a(5, Vec2<T>::Zero()), b(4, Vec2<T>::Zero());
  std::vector<MotionLevel> l(5, MotionLevel::High);
  EXPECT_EQ(dynamic_probability(a, b, l, DynamicProbabilityOptions<T>{}).status, Status::InvalidInput);
  DynamicProbabilityOptions<T> o;
  o.weight_motion = T(0.9);
  EXPECT_EQ(dynamic_probability(a, a, l, o).status, Status::InvalidInput);
  EgoMotion<T> e;
  e.model = FlowModel::Homography;
  e.matrix(0, 0) = std::numeric_limits<T>::quiet_NaN();
  EXPECT_EQ(dynamic_probability(a, a, l, DynamicProbabilityOptions<T>{}, e).status, Status::NonFinite);
  // Lost tracks (NaN): M = 0, counted.
  std::vector<Vec2<T>> c = a;
  c[0].x() = std::numeric_limits<T>::quiet_NaN();
  const auto r = dynamic_probability(a, c, l, DynamicProbabilityOptions<T>{});
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.num_no_flow, 1u);
  EXPECT_EQ(r.moving[0], 0);
  // Empty frame.
  const std::vector<Vec2<T>> none;
  EXPECT_TRUE(dynamic_probability(none, none, std::vector<MotionLevel>{}, DynamicProbabilityOptions<T>{}).ok());
}

// Scene points at random depths seen by a moving camera; movers add image motion of their own.
struct EgoScene {
  PinholeCamera<double> cam = PinholeCamera<double>::tum_fr3();
  std::vector<Vec2<double>> prev, curr;
  std::vector<MotionLevel> levels;
  std::vector<int> mover;
  void add(Random& rng, int n, const Rigid3<double>& cam2_from_cam1, double zmin, double zmax, Vec2<double> own,
           MotionLevel level) {
    for (int i = 0; i < n; ++i) {
      const Vec2<double> p(rng.uniform(20, 620), rng.uniform(20, 460));
      const Vec3<double> X = cam.backproject(p, rng.uniform(zmin, zmax));
      const Vec2<double> q = cam.project(cam2_from_cam1.apply(X)) + own + 0.2 * Vec2<double>(rng.normal(), rng.normal());
      prev.push_back(p);
      curr.push_back(q);
      levels.push_back(level);
      mover.push_back(own.norm() > 0);
    }
  }
  template <class T>
  double recall(const DynamicProbabilityResult<T>& r) const {
    std::size_t tp = 0, pos = 0;
    for (std::size_t i = 0; i < mover.size(); ++i) {
      pos += mover[i];
      tp += mover[i] && r.labels[i] == FeatureLabel::Dynamic;
    }
    return double(tp) / double(pos);
  }
  template <class T>
  std::size_t false_positives(const DynamicProbabilityResult<T>& r) const {
    std::size_t fp = 0;
    for (std::size_t i = 0; i < mover.size(); ++i) fp += !mover[i] && r.labels[i] == FeatureLabel::Dynamic;
    return fp;
  }
};

TEST(DynamicProbabilityEgo, RotatingCameraNeedsTheHomographyModel) {
  // 3 degrees about the optical axis: background flow up to ~21 px, varying over the image.
  Rigid3<double> c2_c1;
  c2_c1.R = Eigen::AngleAxisd(3.0 * Constants<double>::deg_to_rad(), Vec3<double>::UnitZ()).toRotationMatrix();
  Random rng(21);
  EgoScene s;
  s.add(rng, 300, c2_c1, 1, 5, {0, 0}, MotionLevel::Ignore);
  s.add(rng, 40, c2_c1, 1, 5, {0, 0}, MotionLevel::High);   // still person
  s.add(rng, 40, c2_c1, 1, 5, {4, 0}, MotionLevel::High);   // walking person
  const DynamicProbabilityOptions<double> o;
  const auto mean = dynamic_probability(s.prev, s.curr, s.levels, o);
  EgoMotion<double> h;
  h.model = FlowModel::Homography;
  h.matrix = s.cam.K() * c2_c1.R * s.cam.K().inverse();  // pure rotation: x2 ~ K R K^-1 x1
  const auto hom = dynamic_probability(s.prev, s.curr, s.levels, o, h);
  std::printf("[ ego ] rotation 3 deg: mean-flow t=%.2f px recall %.2f fp %zu | homography t=%.2f px recall %.2f fp %zu\n",
              mean.motion_threshold_px, s.recall(mean), s.false_positives(mean), hom.motion_threshold_px,
              s.recall(hom), s.false_positives(hom));
  EXPECT_EQ(s.recall(hom), 1.0);
  EXPECT_EQ(s.false_positives(hom), 0u);
  EXPECT_LT(s.recall(mean), 0.5);  // the background's own spread hides a 4 px mover
}

TEST(DynamicProbabilityEgo, ForwardMotionNeedsTheEpipolarModelSidewaysMoverNeedsMeanFlow) {
  Random rng(22);
  const PinholeCamera<double> cam = PinholeCamera<double>::tum_fr3();
  auto fundamental = [&](const Rigid3<double>& c2_c1) {
    Mat3<double> tx;
    const Vec3<double>& t = c2_c1.t;
    tx << 0, -t.z(), t.y(), t.z(), 0, -t.x(), -t.y(), t.x(), 0;
    const Mat3<double> Kinv = cam.K().inverse();
    return Mat3<double>(Kinv.transpose() * tx * c2_c1.R * Kinv);
  };
  {
    // Walking forward 10 cm through a deep room: radial flow of every size. A person crosses
    // vertically (off the epipolar lines, which are radial).
    Rigid3<double> c2_c1;
    c2_c1.t = Vec3<double>(0, 0, -0.10);
    EgoScene s;
    s.add(rng, 300, c2_c1, 0.8, 6, {0, 0}, MotionLevel::Ignore);
    s.add(rng, 40, c2_c1, 0.8, 6, {0, 0}, MotionLevel::High);
    EgoScene movers;
    movers.add(rng, 40, c2_c1, 0.8, 6, {0, 4}, MotionLevel::High);
    for (std::size_t i = 0; i < movers.prev.size(); ++i) {
      // Keep only movers whose own motion is across the radial epipolar line (|cos| < 0.5).
      const Vec2<double> radial = (movers.prev[i] - Vec2<double>(cam.cx, cam.cy)).normalized();
      if (std::abs(radial.y()) > 0.5) continue;
      s.prev.push_back(movers.prev[i]);
      s.curr.push_back(movers.curr[i]);
      s.levels.push_back(MotionLevel::High);
      s.mover.push_back(1);
    }
    EgoMotion<double> e;
    e.model = FlowModel::Fundamental;
    e.matrix = fundamental(c2_c1);
    const auto epi = dynamic_probability(s.prev, s.curr, s.levels, DynamicProbabilityOptions<double>{}, e);
    const auto mean = dynamic_probability(s.prev, s.curr, s.levels, DynamicProbabilityOptions<double>{});
    std::printf("[ ego ] forward 10 cm: mean-flow t=%.2f recall %.2f fp %zu | epipolar t=%.2f recall %.2f fp %zu\n",
                mean.motion_threshold_px, s.recall(mean), s.false_positives(mean), epi.motion_threshold_px,
                s.recall(epi), s.false_positives(epi));
    EXPECT_GE(s.recall(epi), 0.95);
    EXPECT_EQ(s.false_positives(epi), 0u);
    EXPECT_LT(s.recall(mean), 0.5);  // radial background flow of every size hides the crossing person
  }
  {
    // Sideways camera motion over a flat wall; a person walks sideways too: the motion stays on
    // its (horizontal) epipolar line, so only the mean-flow model sees it.
    Rigid3<double> c2_c1;
    c2_c1.t = Vec3<double>(-0.02, 0, 0);
    EgoScene s;
    s.add(rng, 300, c2_c1, 3, 3, {0, 0}, MotionLevel::Ignore);
    s.add(rng, 40, c2_c1, 3, 3, {0, 0}, MotionLevel::High);
    s.add(rng, 40, c2_c1, 3, 3, {6, 0}, MotionLevel::High);
    EgoMotion<double> e;
    e.model = FlowModel::Fundamental;
    e.matrix = fundamental(c2_c1);
    const auto epi = dynamic_probability(s.prev, s.curr, s.levels, DynamicProbabilityOptions<double>{}, e);
    const auto mean = dynamic_probability(s.prev, s.curr, s.levels, DynamicProbabilityOptions<double>{});
    std::printf("[ ego ] sideways 2 cm: mean-flow recall %.2f fp %zu | epipolar recall %.2f fp %zu\n", s.recall(mean),
                s.false_positives(mean), s.recall(epi), s.false_positives(epi));
    EXPECT_EQ(s.recall(mean), 1.0);
    EXPECT_EQ(s.false_positives(mean), 0u);
    EXPECT_LT(s.recall(epi), 0.1);
  }
}
}  // namespace
