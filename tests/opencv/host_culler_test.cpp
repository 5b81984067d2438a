// Tests of opencv/host_culler.hpp (library dyncull::culler): settings from the environment with bad values
// named; a bad detections folder refused with the folder or file named; boxes looked up by timestamp within
// the tolerance; stock culls nothing, box_only removes exactly the features in boxes of its classes; the
// culler mode gives a mask parallel to the keys and logs every frame (a frame without a detections file
// says so); a frame id that goes back resets the culler; cull_orb_slam_frame keeps an ORB-SLAM-style
// Frame's parallel arrays, N, map points, outliers and grid in step.
#include "dyncull/opencv/host_culler.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace dyncull {
namespace {

namespace fs = std::filesystem;
using cv_adapter::HostCuller;

const double kStamp0 = 1548339823.22687;

class TempDir {
 public:
  explicit TempDir(const std::string& name) : path_(fs::temp_directory_path() / ("dyncull_host_culler_" + name)) {
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  std::string str() const { return path_.string(); }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  fs::path path_;
};

// One NNNNNN.json in the real files' schema: a person box and a chair box per frame.
void write_frame(const TempDir& dir, int id, double stamp, const std::string& detections) {
  char name[32];
  std::snprintf(name, sizeof name, "%06d.json", id);
  std::ofstream out(dir.file(name));
  out.precision(15);
  out << "{\"frame_id\": " << id << ", \"timestamp\": " << stamp << ", \"image_path\": \"rgb/x.png\", "
      << "\"detections\": [" << detections << "]}\n";
}

const char* kPersonAndChair =
    "{\"class_id\": 0, \"class_name\": \"person\", \"confidence\": 0.9, \"bbox\": [100.0, 100.0, 200.0, 300.0]},"
    "{\"class_id\": 56, \"class_name\": \"chair\", \"confidence\": 0.8, \"bbox\": [400.0, 200.0, 500.0, 400.0]}";

void write_two_frames(const TempDir& dir) {
  write_frame(dir, 0, kStamp0, kPersonAndChair);
  write_frame(dir, 1, kStamp0 + 1.0 / 30, "");
}

HostCuller::Settings settings_for(HostCuller::Mode mode, const TempDir& dir) {
  HostCuller::Settings s;
  s.mode = mode;
  s.detections_dir = dir.str();
  return s;
}

std::string thrown_message(const HostCuller::Settings& s) {
  try {
    HostCuller culler(s);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "<nothing thrown>";
}

struct Env {
  Env(const char* name, const char* value) : name_(name) { value ? setenv(name, value, 1) : unsetenv(name); }
  ~Env() { unsetenv(name_); }
  const char* name_;
};

TEST(HostCullerSettings, UnsetIsStockAndADetectionsFolderMeansCuller) {
  Env mode("DYNCULL_MODE", nullptr), dir("DYNCULL_DETECTIONS", nullptr);
  EXPECT_EQ(HostCuller::environment_settings().mode, HostCuller::Mode::Stock);
  Env dir2("DYNCULL_DETECTIONS", "somewhere");
  const HostCuller::Settings s = HostCuller::environment_settings();
  EXPECT_EQ(s.mode, HostCuller::Mode::Culler);
  EXPECT_EQ(s.detections_dir, "somewhere");
  EXPECT_EQ(s.preset, "recommended");
}

TEST(HostCullerSettings, ReadsEveryVariable) {
  Env mode("DYNCULL_MODE", "box_only"), tol("DYNCULL_STAMP_TOLERANCE", "0.02"), classes("DYNCULL_BOX_CLASSES", "0,2"),
      preset("DYNCULL_PRESET", "dld_slam"), log("DYNCULL_LOG", "frames.csv");
  const HostCuller::Settings s = HostCuller::environment_settings();
  EXPECT_EQ(s.mode, HostCuller::Mode::BoxOnly);
  EXPECT_DOUBLE_EQ(s.stamp_tolerance_s, 0.02);
  EXPECT_EQ(s.box_only_classes, (std::vector<int>{0, 2}));
  EXPECT_EQ(s.preset, "dld_slam");
  EXPECT_EQ(s.log_path, "frames.csv");
}

TEST(HostCullerSettings, BadValuesAreNamed) {
  {
    Env mode("DYNCULL_MODE", "cull");
    EXPECT_THROW(HostCuller::environment_settings(), std::invalid_argument);
    try {
      HostCuller::environment_settings();
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("DYNCULL_MODE='cull': expected stock, box_only or culler"), std::string::npos)
          << e.what();
    }
  }
  {
    Env tol("DYNCULL_STAMP_TOLERANCE", "-1");
    EXPECT_THROW(HostCuller::environment_settings(), std::invalid_argument);
  }
  {
    Env classes("DYNCULL_BOX_CLASSES", "0,,person");
    EXPECT_THROW(HostCuller::environment_settings(), std::invalid_argument);
  }
}

TEST(HostCullerDetections, AMissingOrBadFolderIsRefusedWithItsName) {
  TempDir dir("bad");
  HostCuller::Settings s = settings_for(HostCuller::Mode::Culler, dir);
  s.detections_dir = dir.file("no_such_folder");
  EXPECT_NE(thrown_message(s).find("no_such_folder: no such directory"), std::string::npos) << thrown_message(s);
  s.detections_dir = dir.str();
  EXPECT_NE(thrown_message(s).find("no 000000.json"), std::string::npos) << thrown_message(s);
  std::ofstream(dir.file("000000.json")) << "{\"frame_id\": 0, \"timestamp\": 1.0, \"detections\": [}";
  EXPECT_NE(thrown_message(s).find("000000.json"), std::string::npos) << thrown_message(s);
  s.detections_dir.clear();
  EXPECT_NE(thrown_message(s).find("DYNCULL_DETECTIONS is not set"), std::string::npos) << thrown_message(s);
}

TEST(HostCullerDetections, StockNeedsNoFolder) {
  HostCuller::Settings s;
  s.detections_dir = "no_such_folder";
  EXPECT_NO_THROW(HostCuller culler(s));
}

TEST(HostCullerDetections, BoxesAreFoundByStampWithinTheTolerance) {
  TempDir dir("stamps");
  write_two_frames(dir);
  HostCuller culler(settings_for(HostCuller::Mode::BoxOnly, dir));
  std::vector<DetectedBox> boxes;  // dyncull::DetectedBox (culling/culler.hpp)
  ASSERT_TRUE(culler.detections_for(kStamp0 + 0.004, &boxes));
  ASSERT_EQ(boxes.size(), 2u);
  EXPECT_EQ(boxes[0].class_id, 0);
  EXPECT_FLOAT_EQ(boxes[0].x1, 200.f);
  EXPECT_FLOAT_EQ(boxes[1].y1, 400.f);
  ASSERT_TRUE(culler.detections_for(kStamp0 + 1.0 / 30, &boxes));
  EXPECT_TRUE(boxes.empty());  // a file with no boxes: the detector saw nothing
  EXPECT_FALSE(culler.detections_for(kStamp0 + 0.016, &boxes));  // between two frames: no file
}

struct Keys {
  std::vector<cv::KeyPoint> keys;
  cv::Mat descriptors;
};

// Keypoints inside the person box (150, 200), inside the chair box (450, 300) and outside both.
Keys three_keys() {
  Keys k;
  k.keys = {cv::KeyPoint(150.f, 200.f, 31.f), cv::KeyPoint(450.f, 300.f, 31.f), cv::KeyPoint(320.f, 50.f, 31.f)};
  k.descriptors = cv::Mat(3, 32, CV_8U);
  cv::randu(k.descriptors, 0, 256);
  return k;
}

cv::Mat camera_K() { return (cv::Mat_<float>(3, 3) << 540.f, 0.f, 320.f, 0.f, 540.f, 240.f, 0.f, 0.f, 1.f); }

TEST(HostCullerModes, StockReturnsNoMaskAndBoxOnlyRemovesItsClassesBoxes) {
  TempDir dir("modes");
  write_two_frames(dir);
  const Keys k = three_keys();
  HostCuller stock(HostCuller::Settings{});
  EXPECT_EQ(stock.cull(kStamp0, 0, camera_K(), cv::Mat(), cv::Size(640, 480), k.keys, k.keys, k.descriptors, cv::Mat(),
                       cv::Mat()),
            nullptr);
  HostCuller box_only(settings_for(HostCuller::Mode::BoxOnly, dir));
  const std::vector<std::uint8_t>* keep = box_only.cull(kStamp0, 0, camera_K(), cv::Mat(), cv::Size(640, 480), k.keys,
                                                        k.keys, k.descriptors, cv::Mat(), cv::Mat());
  ASSERT_NE(keep, nullptr);
  EXPECT_EQ(*keep, (std::vector<std::uint8_t>{0, 1, 1}));  // the chair is not a person
  keep = box_only.cull(kStamp0 + 1.0 / 30, 1, camera_K(), cv::Mat(), cv::Size(640, 480), k.keys, k.keys, k.descriptors,
                       cv::Mat(), cv::Mat());
  EXPECT_EQ(*keep, (std::vector<std::uint8_t>{1, 1, 1}));
  EXPECT_EQ(box_only.stats().frames, 2u);
  EXPECT_EQ(box_only.stats().frames_without_detections, 0u);
  EXPECT_NE(box_only.summary().find("mode box_only, 2 frames"), std::string::npos) << box_only.summary();
}

std::vector<std::string> lines_of(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> out;
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

TEST(HostCullerModes, CullerMasksEveryFrameAndLogsFramesWithoutDetections) {
  TempDir dir("culler");
  write_two_frames(dir);
  HostCuller::Settings s = settings_for(HostCuller::Mode::Culler, dir);
  s.log_path = dir.file("frames.csv");
  const Keys k = three_keys();
  const cv::Mat depth(480, 640, CV_32F, cv::Scalar(2.f));
  {
    HostCuller culler(s);
    const double stamps[] = {kStamp0, kStamp0 + 1.0 / 30, kStamp0 + 0.5};  // the last has no file
    for (unsigned long id = 0; id < 3; ++id) {
      const std::vector<std::uint8_t>* keep = culler.cull(stamps[id], id, camera_K(), cv::Mat(), cv::Size(640, 480),
                                                          k.keys, k.keys, k.descriptors, depth, cv::Mat());
      ASSERT_NE(keep, nullptr);
      EXPECT_EQ(keep->size(), k.keys.size());
    }
    EXPECT_EQ(culler.stats().frames_without_detections, 1u);
    EXPECT_EQ(culler.stats().restarts, 0u);
    culler.cull(kStamp0, 0, camera_K(), cv::Mat(), cv::Size(640, 480), k.keys, k.keys, k.descriptors, depth, cv::Mat());
    EXPECT_EQ(culler.stats().restarts, 1u);  // the host's frame counter went back: a new map
  }
  const std::vector<std::string> log = lines_of(s.log_path);
  ASSERT_EQ(log.size(), 5u);
  EXPECT_EQ(log[0], "stamp,mode,status,reason,features,kept,boxes,ms");
  EXPECT_EQ(log[1].rfind("1548339823.226870,culler,", 0), 0u) << log[1];
  EXPECT_NE(log[1].find(",3,"), std::string::npos) << log[1];
  EXPECT_NE(log[3].find("no detections file for this stamp"), std::string::npos) << log[3];
  EXPECT_NE(log[3].find(",none,"), std::string::npos) << log[3];
}

TEST(HostCullerModes, AnUnwritableLogIsRefused) {
  TempDir dir("log");
  write_two_frames(dir);
  HostCuller::Settings s = settings_for(HostCuller::Mode::BoxOnly, dir);
  s.log_path = dir.file("no_such_folder/frames.csv");
  EXPECT_NE(thrown_message(s).find("cannot open for writing"), std::string::npos) << thrown_message(s);
}

// The members of ORB-SLAM2's Frame that cull_orb_slam_frame touches, with a 2 x 2 grid over 640 x 480.
struct FakeFrame {
  double mTimeStamp = kStamp0;
  unsigned long mnId = 0;
  int N = 0;
  std::vector<cv::KeyPoint> mvKeys, mvKeysUn;
  cv::Mat mDescriptors;
  std::vector<float> mvuRight, mvDepth;
  std::vector<int*> mvpMapPoints;
  std::vector<bool> mvbOutlier;
  std::vector<std::size_t> mGrid[2][2];
  bool PosInGrid(const cv::KeyPoint& kp, int& x, int& y) const {
    x = kp.pt.x < 320.f ? 0 : 1;
    y = kp.pt.y < 240.f ? 0 : 1;
    return true;
  }
};

TEST(HostCullerFrame, CompactsEveryParallelArrayAndRebuildsTheGrid) {
  TempDir dir("frame");
  write_two_frames(dir);
  HostCuller culler(settings_for(HostCuller::Mode::BoxOnly, dir));
  const Keys k = three_keys();
  FakeFrame f;
  f.mvKeys = f.mvKeysUn = k.keys;
  f.mDescriptors = k.descriptors.clone();
  f.mvuRight = {1.f, 2.f, 3.f};
  f.mvDepth = {10.f, 20.f, 30.f};
  f.N = 3;
  f.mvpMapPoints.assign(3, nullptr);
  f.mvbOutlier.assign(3, false);
  f.mGrid[0][0] = {0, 1, 2};  // stale cells must go
  const int n = cv_adapter::cull_orb_slam_frame(culler, f, cv::Size(640, 480), cv::Mat(), camera_K(), cv::Mat(), cv::Mat());
  EXPECT_EQ(n, 2);
  EXPECT_EQ(f.N, 2);
  ASSERT_EQ(f.mvKeys.size(), 2u);
  EXPECT_FLOAT_EQ(f.mvKeys[0].pt.x, 450.f);
  EXPECT_EQ(f.mvKeysUn.size(), 2u);
  EXPECT_EQ(f.mvuRight, (std::vector<float>{2.f, 3.f}));
  EXPECT_EQ(f.mvDepth, (std::vector<float>{20.f, 30.f}));
  ASSERT_EQ(f.mDescriptors.rows, 2);
  EXPECT_EQ(cv::norm(f.mDescriptors.row(1), k.descriptors.row(2), cv::NORM_HAMMING), 0.0);
  EXPECT_EQ(f.mvpMapPoints.size(), 2u);
  EXPECT_EQ(f.mvbOutlier.size(), 2u);
  EXPECT_TRUE(f.mGrid[0][0].empty());
  EXPECT_EQ(f.mGrid[1][1], (std::vector<std::size_t>{0}));  // (450, 300)
  EXPECT_EQ(f.mGrid[1][0], (std::vector<std::size_t>{1}));  // (320, 50)
}

TEST(HostCullerFrame, StockLeavesTheFrameAlone) {
  HostCuller culler(HostCuller::Settings{});
  const Keys k = three_keys();
  FakeFrame f;
  f.mvKeys = f.mvKeysUn = k.keys;
  f.mDescriptors = k.descriptors;
  f.N = 3;
  EXPECT_EQ(cv_adapter::cull_orb_slam_frame(culler, f, cv::Size(640, 480), cv::Mat(), camera_K(), cv::Mat(), cv::Mat()), 3);
  EXPECT_EQ(f.mvKeys.size(), 3u);
}

}  // namespace
}  // namespace dyncull
