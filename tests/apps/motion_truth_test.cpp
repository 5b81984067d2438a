// dyncull_motion_truth's labeller (apps/truth/motion_truth.hpp) on a rendered sequence whose every pixel's
// motion is known: a textured wall, a square walking in front of it, a square creeping too slowly to tell
// (the unknown band), seen by a camera sliding sideways with its recorded poses off by a few millimetres.
#include <gtest/gtest.h>

#ifdef DYNCULL_HAS_OPENCV

#include "../../apps/truth/motion_truth.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

namespace {

using namespace dyncull;

/// Value noise on a 1 cm grid: texture that flow can follow and that never repeats within the view.
class Texture {
 public:
  explicit Texture(std::uint32_t seed) : values_(kCells * kCells) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(30.f, 225.f);
    for (float& v : values_) v = u(rng);
  }
  float at(double x, double y) const {
    const double gx = x / 0.01 + kCells / 2.0, gy = y / 0.01 + kCells / 2.0;
    const int i = static_cast<int>(std::floor(gx)), j = static_cast<int>(std::floor(gy));
    const double a = gx - i, b = gy - j;
    auto v = [&](int ii, int jj) {
      return values_[static_cast<std::size_t>(((jj % kCells + kCells) % kCells) * kCells + (ii % kCells + kCells) % kCells)];
    };
    return static_cast<float>((1 - a) * (1 - b) * v(i, j) + a * (1 - b) * v(i + 1, j) + (1 - a) * b * v(i, j + 1) +
                              a * b * v(i + 1, j + 1));
  }

 private:
  static constexpr int kCells = 512;
  std::vector<float> values_;
};

/// A square at depth z whose left edge is at x0 + speed * frame (metres, world frame).
struct Square {
  double x0, y0, size, z, speed_m_per_frame;
  bool contains(double x, double y, int frame) const {
    const double left = x0 + speed_m_per_frame * frame;
    return x >= left && x < left + size && y >= y0 && y < y0 + size;
  }
};

struct RenderedSequence {
  std::vector<truth::TruthFrame> frames;
  std::vector<cv::Mat> region;  ///< 0 wall, 1 walking square, 2 creeping square
  PinholeCamera<double> camera{525, 525, 159.5, 119.5, 320, 240};
};

/// The camera slides 5 mm a frame along x; the recorded poses carry 2 mm of noise per axis.
RenderedSequence render(int num_frames) {
  RenderedSequence s;
  const Texture wall(1), walker(2), creeper(3);
  const Square walking{-0.55, -0.15, 0.3, 1.5, 0.012};  // 4 frames: 4.8 cm, about 17 px at 1.5 m
  const Square creeping{0.25, -0.10, 0.2, 1.5, 0.0021};  // 4 frames: 8.4 mm, about 2.9 px
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.002);
  for (int f = 0; f < num_frames; ++f) {
    const double cam_x = 0.005 * f;
    truth::TruthFrame frame;
    frame.gray = cv::Mat(s.camera.height, s.camera.width, CV_8UC1);
    frame.depth_m = cv::Mat(s.camera.height, s.camera.width, CV_32FC1);
    cv::Mat region(s.camera.height, s.camera.width, CV_8UC1);
    for (int v = 0; v < s.camera.height; ++v) {
      for (int u = 0; u < s.camera.width; ++u) {
        const double rx = (u - s.camera.cx) / s.camera.fx, ry = (v - s.camera.cy) / s.camera.fy;
        const double x = cam_x + rx * 1.5, y = ry * 1.5;  // both squares at 1.5 m, the wall at 2.5 m
        float grey, z;
        std::uint8_t r = 0;
        if (walking.contains(x, y, f)) {
          grey = walker.at(x - walking.speed_m_per_frame * f, y), z = 1.5f, r = 1;
        } else if (creeping.contains(x, y, f)) {
          grey = creeper.at(x - creeping.speed_m_per_frame * f, y), z = 1.5f, r = 2;
        } else {
          grey = wall.at(cam_x + rx * 2.5, ry * 2.5), z = 2.5f;
        }
        frame.gray.at<std::uint8_t>(v, u) = cv::saturate_cast<std::uint8_t>(grey);
        frame.depth_m.at<float>(v, u) = z;
        region.at<std::uint8_t>(v, u) = r;
      }
    }
    frame.has_pose = true;
    frame.world_from_cam.t = Vec3<double>(cam_x + noise(rng), noise(rng), noise(rng));
    s.frames.push_back(frame);
    s.region.push_back(region);
  }
  return s;
}

/// Labels of pixels of one region: [static, moving, unknown].
std::array<int, 3> count(const cv::Mat& labels, const cv::Mat& region, std::uint8_t which) {
  std::array<int, 3> n{0, 0, 0};
  for (int v = 0; v < labels.rows; ++v)
    for (int u = 0; u < labels.cols; ++u) {
      if (region.at<std::uint8_t>(v, u) != which) continue;
      const std::uint8_t l = labels.at<std::uint8_t>(v, u);
      ++n[l == truth::kStatic ? 0 : l == truth::kMoving ? 1 : 2];
    }
  return n;
}

TEST(MotionTruth, WalkerMovingWallStaticCreeperUnknown) {
  RenderedSequence s = render(13);
  truth::MotionLabeller labeller;
  const truth::FrameTruth t = labeller.label(s.frames, 6, s.camera);
  ASSERT_TRUE(t.note.empty()) << t.note;
  ASSERT_EQ(t.corrections.size(), 2u);
  for (const truth::PoseCorrection& c : t.corrections) {
    EXPECT_TRUE(c.fitted) << "the pose refinement absorbs millimetres of noise";
    EXPECT_LT(c.static_median_px, 0.5);
  }
  const std::array<int, 3> wall = count(t.labels, s.region[6], 0);
  const std::array<int, 3> walker = count(t.labels, s.region[6], 1);
  const std::array<int, 3> creeper = count(t.labels, s.region[6], 2);
  // The wall: static where known, and most of it known (its edges against the squares are not).
  EXPECT_LT(wall[1], (wall[0] + wall[1]) / 100) << "wall labelled moving";
  EXPECT_GT(wall[0], (wall[0] + wall[1] + wall[2]) * 7 / 10);
  // The walker: moving where known, and most of it known.
  EXPECT_LT(walker[0], (walker[0] + walker[1]) / 50) << "walker labelled static";
  EXPECT_GT(walker[1], (walker[0] + walker[1] + walker[2]) / 2);
  // The creeper moves about 2.9 px in 4 frames, between the thresholds (2 and 4 px): mostly unknown, never mostly moving.
  EXPECT_GT(creeper[2], creeper[0] + creeper[1]) << "static " << creeper[0] << " moving " << creeper[1];
}

TEST(MotionTruth, FrameWithoutDepthOrPoseIsUnknownWithItsReason) {
  RenderedSequence s = render(9);
  s.frames[4].depth_m.release();
  s.frames[5].has_pose = false;
  truth::MotionLabeller labeller;
  const truth::FrameTruth no_depth = labeller.label(s.frames, 4, s.camera);
  EXPECT_EQ(no_depth.note, "no depth");
  EXPECT_EQ(cv::countNonZero(no_depth.labels != truth::kUnknown), 0);
  const truth::FrameTruth no_pose = labeller.label(s.frames, 5, s.camera);
  EXPECT_EQ(no_pose.note, "no ground-truth pose");
  EXPECT_EQ(cv::countNonZero(no_pose.labels != truth::kUnknown), 0);
  // Frame 1 has only frame 5 (no pose) at +4 and nothing at -3: no neighbour.
  const truth::FrameTruth alone = labeller.label(s.frames, 1, s.camera);
  EXPECT_EQ(alone.note, "no neighbour with a pose");
  EXPECT_EQ(cv::countNonZero(alone.labels != truth::kUnknown), 0);
  EXPECT_EQ(alone.with_depth, static_cast<std::size_t>(s.camera.width * s.camera.height));
  // A frame index outside the sequence, and depth of another size, are named, not read.
  EXPECT_EQ(labeller.label(s.frames, 9, s.camera).note, "no grey frame 9");
  s.frames[7].depth_m = cv::Mat(10, 10, CV_32FC1, cv::Scalar(1.f));
  EXPECT_EQ(labeller.label(s.frames, 7, s.camera).note, "depth is not CV_32F metres of the grey frame's size");
}

// At the sequence's ends one neighbour is enough.
TEST(MotionTruth, FirstFrameUsesTheNeighbourAfterIt) {
  RenderedSequence s = render(5);
  truth::MotionLabeller labeller;
  const truth::FrameTruth t = labeller.label(s.frames, 0, s.camera);
  EXPECT_EQ(t.corrections.size(), 1u);
  const std::array<int, 3> walker = count(t.labels, s.region[0], 1);
  EXPECT_GT(walker[1], (walker[0] + walker[1] + walker[2]) / 2);
}

// Moving pixels whose flow is untextured (a blank square) are not called moving without depth's word:
// a blank square sliding over a blank wall at the same depth is unknown, not moving.
TEST(MotionTruth, UntexturedPixelsNeedDepthToBeMoving) {
  RenderedSequence s = render(9);
  for (truth::TruthFrame& f : s.frames) f.gray.setTo(128);
  truth::MotionLabeller labeller;
  const truth::FrameTruth t = labeller.label(s.frames, 4, s.camera);
  EXPECT_EQ(count(t.labels, s.region[4], 0)[1], 0) << "blank wall labelled moving";
}

// A static point is seen at its static place in a neighbour, or hidden behind what is seen there; depth
// farther than the point there means it left. With flow unable to say "moving" (moving_px out of reach),
// depth alone labels the bands the walker leaves (17 px of its 105 px each way), and never the wall the
// walker hides in the neighbours.
TEST(MotionTruth, DepthSeenBehindItsStaticPlaceIsMoving) {
  RenderedSequence s = render(13);
  truth::MotionTruthOptions options;
  options.moving_px = 100;
  truth::MotionLabeller labeller(options);
  const truth::FrameTruth t = labeller.label(s.frames, 6, s.camera);
  const std::array<int, 3> walker = count(t.labels, s.region[6], 1);
  const std::array<int, 3> wall = count(t.labels, s.region[6], 0);
  EXPECT_GT(walker[1], (walker[0] + walker[1] + walker[2]) / 10);
  EXPECT_EQ(walker[0], 0) << "walker labelled static";
  EXPECT_LT(wall[1], (wall[0] + wall[1]) / 200) << "wall labelled moving";
}

// On a blank image flow is zero everywhere; a pose refinement fitted on it would take the camera's motion
// for noise and call the untextured walker static. The refinement needs textured matches, so here it is
// refused and the walker is never static.
TEST(MotionTruth, PoseIsNotRefinedOnUntexturedFlow) {
  RenderedSequence s = render(9);
  for (truth::TruthFrame& f : s.frames) f.gray.setTo(128);
  truth::MotionLabeller labeller;
  const truth::FrameTruth t = labeller.label(s.frames, 4, s.camera);
  for (const truth::PoseCorrection& c : t.corrections) EXPECT_FALSE(c.fitted);
  EXPECT_EQ(count(t.labels, s.region[4], 1)[0], 0) << "walker labelled static";
}

}  // namespace

#else
TEST(MotionTruth, NeedsOpenCv) { GTEST_SKIP() << "dyncull_motion_truth needs the OpenCV adapter (OpenCV 4 not found)"; }
#endif
