// Tests of host/host_culler.hpp (library dyncull::host): settings from the environment with bad values
// named, every start-up setting (the preset too) checked when the host is made and a bad one stopping the
// process at start; a bad detections folder refused with the folder or file named, and the folder read by
// frame index (gaps allowed); boxes looked up by timestamp within the tolerance; stock culls nothing,
// box_only removes exactly the features in boxes of its classes; the culler mode gives a mask parallel to
// the keys and logs every frame (a frame without a detections file says so); a frame id that goes back
// resets the culler; the log is a regular file of one host, one field per value; cull_orb_slam_frame keeps
// an ORB-SLAM-style Frame's parallel arrays, N, map points, outliers and grid in step, and passes a frame
// uncut, logged as such, for each bad input.
#include "dyncull/host/host_culler.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace dyncull {
namespace {

namespace fs = std::filesystem;
using host::HostCuller;
using host::HostSettings;
using host::Mode;

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

HostSettings settings_for(Mode mode, const TempDir& dir) {
  HostSettings s;
  s.mode = mode;
  s.detections_dir = dir.str();
  return s;
}

// The reason a host made from `s` gives for not starting ("<started>" when it starts).
std::string start_reason(const HostSettings& s) {
  HostCuller culler(s);
  return culler.ok() ? std::string("<started>") : culler.reason();
}

struct Env {
  Env(const char* name, const char* value) : name_(name) { value ? setenv(name, value, 1) : unsetenv(name); }
  ~Env() { unsetenv(name_); }
  const char* name_;
};

TEST(HostCullerSettings, UnsetIsStockAndADetectionsFolderMeansCuller) {
  Env mode("DYNCULL_MODE", nullptr), dir("DYNCULL_DETECTIONS", nullptr);
  EXPECT_EQ(HostSettings::from_environment().mode, Mode::Stock);
  Env dir2("DYNCULL_DETECTIONS", "somewhere");
  const HostSettings s = HostSettings::from_environment();
  EXPECT_EQ(s.mode, Mode::Culler);
  EXPECT_EQ(s.detections_dir, "somewhere");
  EXPECT_EQ(s.preset, "recommended");
}

TEST(HostCullerSettings, ReadsEveryVariable) {
  Env mode("DYNCULL_MODE", "box_only"), tol("DYNCULL_STAMP_TOLERANCE", "0.02"), classes("DYNCULL_BOX_CLASSES", "0,2"),
      preset("DYNCULL_PRESET", "dld_slam"), log("DYNCULL_LOG", "frames.csv");
  const HostSettings s = HostSettings::from_environment();
  EXPECT_EQ(s.mode, Mode::BoxOnly);
  EXPECT_DOUBLE_EQ(s.stamp_tolerance_s, 0.02);
  EXPECT_EQ(s.box_only_classes, (std::vector<int>{0, 2}));
  EXPECT_EQ(s.preset, "dld_slam");
  EXPECT_EQ(s.log_path, "frames.csv");
  EXPECT_TRUE(s.ok()) << s.reason;
  EXPECT_TRUE(s.detector.empty());
  EXPECT_FALSE(s.detector_sync);
  EXPECT_FALSE(s.frames_rgb);
}

TEST(HostCullerSettings, ADetectorMeansCullerAndItsFlagsAreRead) {
  Env mode("DYNCULL_MODE", nullptr), dir("DYNCULL_DETECTIONS", nullptr), detector("DYNCULL_DETECTOR", "yolo.cfg,yolo.weights"),
      sync("DYNCULL_DETECTOR_SYNC", "1"), rgb("DYNCULL_FRAMES_RGB", "1");
  const HostSettings s = HostSettings::from_environment();
  EXPECT_TRUE(s.ok()) << s.reason;
  EXPECT_EQ(s.mode, Mode::Culler);
  EXPECT_EQ(s.detector, "yolo.cfg,yolo.weights");
  EXPECT_TRUE(s.detector_sync);
  EXPECT_TRUE(s.frames_rgb);
}

// DYNCULL_OPENCV_THREADS sizes OpenCV's pool for the process when the host starts.
TEST(HostCullerSettings, OpenCvThreadsAreSetAtStart) {
  const int before = cv::getNumThreads();
  Env threads("DYNCULL_OPENCV_THREADS", "1");
  const HostSettings s = HostSettings::from_environment();
  ASSERT_TRUE(s.ok()) << s.reason;
  EXPECT_EQ(s.opencv_threads, 1);
  {
    HostCuller culler(s);
    ASSERT_TRUE(culler.ok()) << culler.reason();
    EXPECT_EQ(cv::getNumThreads(), 1);
  }
  cv::setNumThreads(before);
}

TEST(HostCullerSettings, BadValuesAreNamed) {
  const struct {
    const char *name, *value, *expected;
  } cases[] = {
      {"DYNCULL_MODE", "cull", "DYNCULL_MODE='cull': expected stock, box_only or culler"},
      {"DYNCULL_STAMP_TOLERANCE", "-1", "DYNCULL_STAMP_TOLERANCE='-1': expected a number of seconds in [0, 1]"},
      {"DYNCULL_STAMP_TOLERANCE", "1e300", "DYNCULL_STAMP_TOLERANCE='1e300'"},
      {"DYNCULL_BOX_CLASSES", "0,,person", "DYNCULL_BOX_CLASSES='0,,person'"},
      {"DYNCULL_DETECTOR_SYNC", "yes", "DYNCULL_DETECTOR_SYNC='yes': expected 0 or 1"},
      {"DYNCULL_FRAMES_RGB", "2", "DYNCULL_FRAMES_RGB='2': expected 0 or 1"},
      {"DYNCULL_OPENCV_THREADS", "0", "DYNCULL_OPENCV_THREADS='0': expected a number of threads from 1 to 64"},
      {"DYNCULL_OPENCV_THREADS", "2.5", "DYNCULL_OPENCV_THREADS='2.5'"},
  };
  for (const auto& c : cases) {
    Env e(c.name, c.value);
    const HostSettings s = HostSettings::from_environment();
    EXPECT_EQ(s.status, Status::InvalidInput) << c.name;
    EXPECT_NE(s.reason.find(c.expected), std::string::npos) << s.reason;
    EXPECT_NE(start_reason(s).find(c.expected), std::string::npos) << start_reason(s);  // and the host does not start
  }
}

// A preset is a start-up setting: checked when the host is made, not at the first frame of culling.
TEST(HostCullerSettings, ABadPresetStopsTheHostAtStart) {
  Env preset("DYNCULL_PRESET", "bogus"), mode("DYNCULL_MODE", "stock");
  const HostSettings s = HostSettings::from_environment();
  EXPECT_NE(start_reason(s).find("DYNCULL_PRESET='bogus': CullerOptions: preset 'bogus' is not one of"), std::string::npos)
      << start_reason(s);
}

TEST(HostCullerSettings, BothOrNeitherSourceOfBoxesIsRefused) {
  HostSettings s;
  s.mode = Mode::Culler;
  EXPECT_NE(start_reason(s).find("needs boxes: set DYNCULL_DETECTIONS"), std::string::npos) << start_reason(s);
  s.detections_dir = "somewhere";
  s.detector = "model.onnx";
  EXPECT_NE(start_reason(s).find("both set"), std::string::npos) << start_reason(s);
}

// The process's host: a bad setting ends the program at the first call, before any frame, naming it.
TEST(HostCullerSettingsDeathTest, EnvironmentCullerExitsAtStartNamingTheVariable) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(
      {
        setenv("DYNCULL_PRESET", "bogus", 1);
        host::environment_culler();
      },
      ::testing::ExitedWithCode(1), "dyncull: DYNCULL_PRESET='bogus'");
  EXPECT_EXIT(
      {
        setenv("DYNCULL_DETECTOR", "no_such_model.cfg,no_such.weights", 1);
        host::environment_culler();
      },
      ::testing::ExitedWithCode(1), "dyncull: DYNCULL_DETECTOR='no_such_model.cfg,no_such.weights': .*no_such_model.cfg");
}

TEST(HostCullerDetections, AMissingOrBadFolderIsRefusedWithItsName) {
  TempDir dir("bad");
  HostSettings s = settings_for(Mode::Culler, dir);
  s.detections_dir = dir.file("no_such_folder");
  EXPECT_NE(start_reason(s).find("no_such_folder: no such directory"), std::string::npos) << start_reason(s);
  s.detections_dir = dir.str();
  EXPECT_NE(start_reason(s).find("no NNNNNN.json file"), std::string::npos) << start_reason(s);
  std::ofstream(dir.file("000000.json")) << "{\"frame_id\": 0, \"timestamp\": 1.0, \"detections\": [}";
  EXPECT_NE(start_reason(s).find("000000.json"), std::string::npos) << start_reason(s);
  s.detections_dir.clear();
  EXPECT_NE(start_reason(s).find("needs boxes: set DYNCULL_DETECTIONS"), std::string::npos) << start_reason(s);
}

// Every NNNNNN.json is read, also after a missing number; the frame in the gap has no boxes.
TEST(HostCullerDetections, FilesAfterAGapAreRead) {
  TempDir dir("gap");
  write_frame(dir, 0, kStamp0, kPersonAndChair);
  write_frame(dir, 2, kStamp0 + 2.0 / 30, kPersonAndChair);
  write_frame(dir, 17, kStamp0 + 17.0 / 30, "");
  HostCuller culler(settings_for(Mode::BoxOnly, dir));
  ASSERT_TRUE(culler.ok()) << culler.reason();
  std::vector<DetectedBox> boxes;
  EXPECT_TRUE(culler.detections_for(kStamp0, &boxes));
  EXPECT_FALSE(culler.detections_for(kStamp0 + 1.0 / 30, &boxes));
  ASSERT_TRUE(culler.detections_for(kStamp0 + 2.0 / 30, &boxes));
  EXPECT_EQ(boxes.size(), 2u);
  EXPECT_TRUE(culler.detections_for(kStamp0 + 17.0 / 30, &boxes));
  // A file whose frame_id is not its number is refused, named.
  write_frame(dir, 5, kStamp0 + 5.0 / 30, "");
  std::ofstream(dir.file("000006.json")) << "{\"frame_id\": 7, \"timestamp\": 1.0, \"detections\": []}";
  EXPECT_NE(start_reason(settings_for(Mode::BoxOnly, dir)).find("000006.json: frame_id 7 differs"), std::string::npos)
      << start_reason(settings_for(Mode::BoxOnly, dir));
}

TEST(HostCullerDetections, StockNeedsNoFolder) {
  HostSettings s;
  s.detections_dir = "no_such_folder";
  EXPECT_EQ(start_reason(s), "<started>");
}

TEST(HostCullerDetections, BoxesAreFoundByStampWithinTheTolerance) {
  TempDir dir("stamps");
  write_two_frames(dir);
  HostCuller culler(settings_for(Mode::BoxOnly, dir));
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
const cv::Mat kGrey(480, 640, CV_8UC1, cv::Scalar(0));
const cv::Mat kNone;

const std::vector<std::uint8_t>* cull(HostCuller& culler, double stamp, unsigned long id, const Keys& k,
                                      const cv::Mat& depth = kNone, const cv::Mat& K = camera_K()) {
  host::HostFrame f;
  f.stamp = stamp;
  f.frame_id = id;
  f.K = &K;
  f.distortion = &kNone;
  f.image = &kGrey;
  f.keys = &k.keys;
  f.keys_un = &k.keys;
  f.descriptors = &k.descriptors;
  f.depth = &depth;
  f.predicted_Tcw = &kNone;
  return culler.cull(f);
}

TEST(HostCullerModes, StockReturnsNoMaskAndBoxOnlyRemovesItsClassesBoxes) {
  TempDir dir("modes");
  write_two_frames(dir);
  const Keys k = three_keys();
  HostCuller stock{HostSettings()};
  EXPECT_EQ(cull(stock, kStamp0, 0, k), nullptr);
  HostCuller box_only(settings_for(Mode::BoxOnly, dir));
  const std::vector<std::uint8_t>* keep = cull(box_only, kStamp0, 0, k);
  ASSERT_NE(keep, nullptr);
  EXPECT_EQ(*keep, (std::vector<std::uint8_t>{0, 1, 1}));  // the chair is not a person
  keep = cull(box_only, kStamp0 + 1.0 / 30, 1, k);
  ASSERT_NE(keep, nullptr);
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

std::size_t fields_of(const std::string& line) { return static_cast<std::size_t>(std::count(line.begin(), line.end(), ',')) + 1; }

const char* kLogHeader = "stamp,mode,status,reason,features,kept,boxes,box_age,ms";

TEST(HostCullerModes, CullerMasksEveryFrameAndLogsFramesWithoutDetections) {
  TempDir dir("culler");
  write_two_frames(dir);
  HostSettings s = settings_for(Mode::Culler, dir);
  s.log_path = dir.file("frames.csv");
  const Keys k = three_keys();
  const cv::Mat depth(480, 640, CV_32F, cv::Scalar(2.f));
  {
    HostCuller culler(s);
    ASSERT_TRUE(culler.ok()) << culler.reason();
    const double stamps[] = {kStamp0, kStamp0 + 1.0 / 30, kStamp0 + 0.5};  // the last has no file
    for (unsigned long id = 0; id < 3; ++id) {
      const std::vector<std::uint8_t>* keep = cull(culler, stamps[id], id, k, depth);
      ASSERT_NE(keep, nullptr);
      EXPECT_EQ(keep->size(), k.keys.size());
    }
    EXPECT_EQ(culler.stats().frames_without_detections, 1u);
    EXPECT_EQ(culler.stats().restarts, 0u);
    cull(culler, kStamp0, 0, k, depth);
    EXPECT_EQ(culler.stats().restarts, 1u);  // the host's frame counter went back: a new map
  }
  const std::vector<std::string> log = lines_of(s.log_path);
  ASSERT_EQ(log.size(), 5u);
  EXPECT_EQ(log[0], kLogHeader);
  EXPECT_EQ(log[1].rfind("1548339823.226870,culler,", 0), 0u) << log[1];
  EXPECT_NE(log[1].find(",3,"), std::string::npos) << log[1];
  EXPECT_NE(log[3].find("no detections file for this stamp"), std::string::npos) << log[3];
  EXPECT_NE(log[3].find(",none,"), std::string::npos) << log[3];
  for (const std::string& line : log) EXPECT_EQ(fields_of(line), 9u) << line;
}

TEST(HostCullerLog, AnUnwritableLogIsRefused) {
  TempDir dir("log");
  write_two_frames(dir);
  HostSettings s = settings_for(Mode::BoxOnly, dir);
  s.log_path = dir.file("no_such_folder/frames.csv");
  EXPECT_NE(start_reason(s).find("cannot open for writing"), std::string::npos) << start_reason(s);
}

// A device accepts the open but not the lines (/dev/full: every write fails): refused at start by kind.
TEST(HostCullerLog, ADeviceIsRefusedAsALog) {
  HostSettings s;
  s.log_path = "/dev/full";
  EXPECT_NE(start_reason(s).find("DYNCULL_LOG /dev/full: not a regular file"), std::string::npos) << start_reason(s);
  s.log_path = "/dev/null";
  EXPECT_NE(start_reason(s).find("not a regular file"), std::string::npos) << start_reason(s);
}

// Two hosts on one file would interleave and truncate each other's lines: the second is refused at start.
TEST(HostCullerLog, TwoHostsOnOneLogTheSecondIsRefused) {
  TempDir dir("two_logs");
  HostSettings s;
  s.log_path = dir.file("frames.csv");
  HostCuller first(s);
  ASSERT_TRUE(first.ok()) << first.reason();
  EXPECT_NE(start_reason(s).find("in use by another dyncull host"), std::string::npos) << start_reason(s);
  const Keys k = three_keys();
  for (unsigned long id = 0; id < 20; ++id) cull(first, kStamp0 + id, id, k);
  EXPECT_EQ(lines_of(s.log_path).size(), 21u);
}

// Any stamp is one field: 1e300 no longer cuts the line; NaN and infinities are written as such.
TEST(HostCullerLog, AnyStampIsOneField) {
  TempDir dir("stamps_log");
  HostSettings s;
  s.log_path = dir.file("frames.csv");
  {
    HostCuller culler(s);
    const Keys k = three_keys();
    const double stamps[] = {1e300, -1e300, std::numeric_limits<double>::quiet_NaN(),
                             std::numeric_limits<double>::infinity(), 5e-324};
    unsigned long id = 0;
    for (double stamp : stamps) cull(culler, stamp, id++, k);
  }
  const std::vector<std::string> log = lines_of(s.log_path);
  ASSERT_EQ(log.size(), 6u);
  for (const std::string& line : log) EXPECT_EQ(fields_of(line), 9u) << line;
  EXPECT_EQ(log[1].rfind("1.0000000000000001e+300,stock,ok,", 0), 0u) << log[1];
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

FakeFrame three_key_frame() {
  const Keys k = three_keys();
  FakeFrame f;
  f.mvKeys = f.mvKeysUn = k.keys;
  f.mDescriptors = k.descriptors.clone();
  f.mvuRight = {1.f, 2.f, 3.f};
  f.mvDepth = {10.f, 20.f, 30.f};
  f.N = 3;
  f.mvpMapPoints.assign(3, nullptr);
  f.mvbOutlier.assign(3, false);
  return f;
}

TEST(HostCullerFrame, CompactsEveryParallelArrayAndRebuildsTheGrid) {
  TempDir dir("frame");
  write_two_frames(dir);
  HostCuller culler(settings_for(Mode::BoxOnly, dir));
  FakeFrame f = three_key_frame();
  const cv::Mat descriptors = f.mDescriptors.clone();
  f.mGrid[0][0] = {0, 1, 2};  // stale cells must go
  const int n = host::cull_orb_slam_frame(culler, f, kGrey, cv::Mat(), camera_K(), cv::Mat(), cv::Mat());
  EXPECT_EQ(n, 2);
  EXPECT_EQ(f.N, 2);
  ASSERT_EQ(f.mvKeys.size(), 2u);
  EXPECT_FLOAT_EQ(f.mvKeys[0].pt.x, 450.f);
  EXPECT_EQ(f.mvKeysUn.size(), 2u);
  EXPECT_EQ(f.mvuRight, (std::vector<float>{2.f, 3.f}));
  EXPECT_EQ(f.mvDepth, (std::vector<float>{20.f, 30.f}));
  ASSERT_EQ(f.mDescriptors.rows, 2);
  EXPECT_EQ(cv::norm(f.mDescriptors.row(1), descriptors.row(2), cv::NORM_HAMMING), 0.0);
  EXPECT_EQ(f.mvpMapPoints.size(), 2u);
  EXPECT_EQ(f.mvbOutlier.size(), 2u);
  EXPECT_TRUE(f.mGrid[0][0].empty());
  EXPECT_EQ(f.mGrid[1][1], (std::vector<std::size_t>{0}));  // (450, 300)
  EXPECT_EQ(f.mGrid[1][0], (std::vector<std::size_t>{1}));  // (320, 50)
}

TEST(HostCullerFrame, StockLeavesTheFrameAlone) {
  HostCuller culler{HostSettings()};
  FakeFrame f = three_key_frame();
  EXPECT_EQ(host::cull_orb_slam_frame(culler, f, kGrey, cv::Mat(), camera_K(), cv::Mat(), cv::Mat()), 3);
  EXPECT_EQ(f.mvKeys.size(), 3u);
}

// A Frame whose arrays disagree is left as it is, and the log and the summary say it was not culled.
TEST(HostCullerFrame, ArraysThatDisagreeAreLoggedAsNotCulled) {
  TempDir dir("disagree");
  write_two_frames(dir);
  HostSettings s = settings_for(Mode::BoxOnly, dir);
  s.log_path = dir.file("frames.csv");
  {
    HostCuller culler(s);
    FakeFrame f = three_key_frame();
    f.mvDepth.pop_back();
    EXPECT_EQ(host::cull_orb_slam_frame(culler, f, kGrey, cv::Mat(), camera_K(), cv::Mat(), cv::Mat()), 3);
    EXPECT_EQ(f.mvKeys.size(), 3u);
    EXPECT_EQ(culler.stats().frames, 1u);
    EXPECT_EQ(culler.stats().frames_not_ok, 1u);
    EXPECT_DOUBLE_EQ(culler.stats().features_kept, 3.0);
    EXPECT_NE(culler.summary().find("features 3.0 -> 3.0 per frame"), std::string::npos) << culler.summary();
  }
  const std::vector<std::string> log = lines_of(s.log_path);
  ASSERT_EQ(log.size(), 2u);
  EXPECT_NE(log[1].find(",invalid input,frame arrays disagree: mvDepth has 2 entries; mvKeys 3"), std::string::npos)
      << log[1];
  EXPECT_NE(log[1].find(",3,3,"), std::string::npos) << log[1];
}

// Each bad input the host can pass reaches cull_orb_slam_frame without an exception leaving it: the frame
// passes uncut (or is culled as far as its inputs allow), and the log line names the input.
TEST(HostCullerFrame, EachBadInputPassesTheFrameUncutWithItsReason) {
  TempDir dir("bad_inputs");
  write_two_frames(dir);
  const cv::Mat nan_K = (cv::Mat_<double>(3, 3) << NAN, 0, 320, 0, 540, 240, 0, 0, 1);
  const cv::Mat wide(5, 3, CV_64F, cv::Scalar(0));
  const cv::Mat column = wide.col(1);  // a view: not continuous
  const cv::Mat depth_u8(480, 640, CV_8UC1, cv::Scalar(1));
  const cv::Mat pose3 = cv::Mat::eye(3, 3, CV_64F);
  const struct Case {
    const char* name;
    cv::Mat K, image, distortion, depth, pose;
    const char* reason;  // in the log line; empty: the frame is culled
  } cases[] = {
      {"K 2x2", cv::Mat::eye(2, 2, CV_64F), kGrey, kNone, kNone, kNone, "camera: "},
      {"K with NaN", nan_K, kGrey, kNone, kNone, kNone, "camera: "},
      {"K zero", cv::Mat::zeros(3, 3, CV_32F), kGrey, kNone, kNone, kNone, "camera: "},
      {"no image", camera_K(), kNone, kNone, kNone, kNone, "camera: "},
      {"distortion 3x3", camera_K(), kGrey, cv::Mat::zeros(3, 3, CV_64F), kNone, kNone, "distortion coefficients"},
      {"distortion column view", camera_K(), kGrey, column, kNone, kNone, ""},
      {"depth CV_8U", camera_K(), kGrey, kNone, depth_u8, kNone, "depth must be"},
      {"pose 3x3", camera_K(), kGrey, kNone, kNone, pose3, "predicted_Tcw must be"},
  };
  for (const Case& c : cases) {
    HostSettings s = settings_for(Mode::Culler, dir);
    s.log_path = dir.file("frames.csv");
    {
      HostCuller culler(s);
      ASSERT_TRUE(culler.ok()) << culler.reason();
      FakeFrame f = three_key_frame();
      const int n = host::cull_orb_slam_frame(culler, f, c.image, c.depth, c.K, c.distortion, c.pose);
      EXPECT_EQ(static_cast<std::size_t>(n), f.mvKeys.size()) << c.name;
      if (*c.reason) {
        EXPECT_EQ(n, 3) << c.name;
        EXPECT_EQ(culler.stats().frames_not_ok, 1u) << c.name;
      }
    }
    const std::vector<std::string> log = lines_of(s.log_path);
    ASSERT_EQ(log.size(), 2u) << c.name;
    if (*c.reason) {
      EXPECT_NE(log[1].find(",invalid input,"), std::string::npos) << c.name << ": " << log[1];
      EXPECT_NE(log[1].find(c.reason), std::string::npos) << c.name << ": " << log[1];
      EXPECT_NE(log[1].find(",3,3,"), std::string::npos) << c.name << ": " << log[1];
    }
  }
  // Descriptors of the wrong type and NaN keypoints, through the same helper.
  HostCuller culler(settings_for(Mode::Culler, dir));
  FakeFrame f = three_key_frame();
  f.mDescriptors.convertTo(f.mDescriptors, CV_32F);
  EXPECT_EQ(host::cull_orb_slam_frame(culler, f, kGrey, kNone, camera_K(), kNone, kNone), 3);
  FakeFrame g = three_key_frame();
  g.mvKeys[0].pt.x = g.mvKeysUn[0].pt.x = NAN;
  EXPECT_LE(host::cull_orb_slam_frame(culler, g, kGrey, kNone, camera_K(), kNone, kNone), 3);
  EXPECT_EQ(g.mvDepth.size(), static_cast<std::size_t>(g.N));
}

// Random bad inputs through cull_orb_slam_frame in every mode: K, distortion, image, depth and pose of
// random shapes, types and values (NaN, Inf, huge, tiny), descriptors of other types, keypoints with NaN,
// arrays of other lengths. Whatever comes in, the Frame's arrays agree with N afterwards, nothing is
// added, and the log has one line of nine fields per frame.
TEST(HostCullerFrame, RandomBadInputsNeverLeaveTheFrameInconsistent) {
  TempDir dir("random_inputs");
  write_two_frames(dir);
  cv::RNG rng(20261128);
  const double specials[] = {0.0, -1.0, 1e-300, 1e300, NAN, INFINITY, -INFINITY, 540.0, 320.0, 1.0};
  const auto value = [&]() { return rng.uniform(0, 3) == 0 ? specials[rng.uniform(0, 10)] : rng.uniform(-1000.0, 1000.0); };
  const int types[] = {CV_8UC1, CV_8UC3, CV_16UC1, CV_32FC1, CV_64FC1, CV_32FC2};
  const auto random_mat = [&](int max_side) {
    if (rng.uniform(0, 4) == 0) return cv::Mat();
    cv::Mat m(rng.uniform(1, max_side + 1), rng.uniform(1, max_side + 1), types[rng.uniform(0, 6)]);
    cv::Mat d;
    m.convertTo(d, CV_64F);
    for (int r = 0; r < m.rows; ++r)
      for (int c = 0; c < m.cols * m.channels(); ++c) d.ptr<double>(r)[c] = value();
    d.convertTo(m, m.type());
    return rng.uniform(0, 3) == 0 && m.cols > 1 ? cv::Mat(m.col(0)) : m;  // sometimes a view
  };
  for (Mode mode : {Mode::Culler, Mode::BoxOnly, Mode::Stock}) {
    HostSettings s = settings_for(mode, dir);
    s.log_path = dir.file("frames.csv");
    std::size_t frames = 0;
    {
      HostCuller culler(s);
      ASSERT_TRUE(culler.ok()) << culler.reason();
      for (int trial = 0; trial < 150; ++trial) {
        FakeFrame f = three_key_frame();
        f.mnId = static_cast<unsigned long>(trial);
        if (rng.uniform(0, 4) == 0) f.mvKeys[rng.uniform(0, 3)].pt.x = static_cast<float>(value());
        if (rng.uniform(0, 6) == 0) f.mvuRight.pop_back();
        if (rng.uniform(0, 6) == 0) f.mDescriptors.convertTo(f.mDescriptors, CV_32F);
        // The culler's camera is made at the first frame: a good K there, so later frames reach the culler.
        const cv::Mat K = trial > 0 && rng.uniform(0, 3) == 0 ? random_mat(4) : camera_K();
        const cv::Mat dist = trial > 0 ? random_mat(5) : cv::Mat();
        cv::Mat depth = rng.uniform(0, 2) ? random_mat(8) : cv::Mat();
        if (rng.uniform(0, 2) == 0) depth = cv::Mat(480, 640, rng.uniform(0, 2) ? CV_32FC1 : CV_16UC1, cv::Scalar(value()));
        const cv::Mat pose = rng.uniform(0, 2) ? random_mat(4) : cv::Mat();
        const cv::Mat image = rng.uniform(0, 4) == 0 ? random_mat(6) : kGrey;
        const int n = host::cull_orb_slam_frame(culler, f, image, depth, K, dist, pose);
        ++frames;
        ASSERT_EQ(n, f.N);
        ASSERT_LE(f.mvKeys.size(), 3u);
        if (f.mvuRight.size() == f.mvKeys.size()) {  // the arrays agreed: they still do
          EXPECT_EQ(f.mvKeysUn.size(), f.mvKeys.size());
          EXPECT_EQ(f.mvDepth.size(), f.mvKeys.size());
          EXPECT_EQ(static_cast<std::size_t>(f.mDescriptors.rows), f.mvKeys.size());
          EXPECT_EQ(static_cast<std::size_t>(f.N), f.mvKeys.size());
        } else {
          EXPECT_EQ(f.N, 3);  // disagreeing arrays: untouched
        }
      }
      EXPECT_EQ(culler.stats().frames, frames);
    }
    const std::vector<std::string> log = lines_of(s.log_path);
    ASSERT_EQ(log.size(), frames + 1) << to_string(mode);
    for (const std::string& line : log) EXPECT_EQ(fields_of(line), 9u) << line;
  }
}

// A reset the host asks for (ORB-SLAM3's Atlas starting a map) restarts the culler at the next frame, also
// when the frame counter goes on; before the first frame it counts nothing.
TEST(HostCullerModes, AResetRestartsTheCullerAtTheNextFrame) {
  TempDir dir("reset");
  write_two_frames(dir);
  const Keys k = three_keys();
  const cv::Mat depth(480, 640, CV_32F, cv::Scalar(2.f));
  HostCuller culler(settings_for(Mode::Culler, dir));
  ASSERT_TRUE(culler.ok()) << culler.reason();
  culler.reset();  // the Atlas's first map, before any frame
  ASSERT_NE(cull(culler, kStamp0, 0, k, depth), nullptr);
  EXPECT_EQ(culler.stats().restarts, 0u);
  culler.reset();
  culler.reset();  // two requests before one frame: one restart
  ASSERT_NE(cull(culler, kStamp0 + 1.0 / 30, 1, k, depth), nullptr);
  EXPECT_EQ(culler.stats().restarts, 1u);
  ASSERT_NE(cull(culler, kStamp0 + 2.0 / 30, 2, k, depth), nullptr);
  EXPECT_EQ(culler.stats().restarts, 1u);
  EXPECT_NE(culler.summary().find("1 restarts"), std::string::npos) << culler.summary();
}

// The members of ORB-SLAM3's Frame that cull_orb_slam_frame reads beyond ORB-SLAM2's: one camera
// (Nleft = Nright = -1, no left-right matches) unless a test sets them.
struct Vector3 {
  float x, y, z;
};
struct FakeFrame3 : FakeFrame {
  int Nleft = -1, Nright = -1;
  std::vector<int> mvLeftToRightMatch;
  std::vector<Vector3> mvStereo3Dpoints;
};

FakeFrame3 three_key_frame3() {
  FakeFrame3 f;
  static_cast<FakeFrame&>(f) = three_key_frame();
  return f;
}

// A pose as Sophus gives it: matrix() returns a 4x4 with rows(), cols() and operator()(r, c).
struct Matrix4 {
  float m[4][4];
  int rows() const { return 4; }
  int cols() const { return 4; }
  float operator()(int r, int c) const { return m[r][c]; }
};
struct FakeSE3 {
  float tz;
  Matrix4 matrix() const {
    Matrix4 out = {{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, tz}, {0, 0, 0, 1}}};
    return out;
  }
};

TEST(HostCullerFrame, AnOrbSlam3OneCameraFrameIsCulledWithASophusPose) {
  TempDir dir("orb3");
  write_two_frames(dir);
  HostCuller culler(settings_for(Mode::BoxOnly, dir));
  FakeFrame3 f = three_key_frame3();
  EXPECT_EQ(host::cull_orb_slam_frame(culler, f, kGrey, cv::Mat(), camera_K(), cv::Mat(), FakeSE3{0.5f}, true), 2);
  EXPECT_EQ(f.mvKeys.size(), 2u);
  EXPECT_EQ(f.mvDepth, (std::vector<float>{20.f, 30.f}));
  EXPECT_EQ(f.Nleft, -1);
  FakeFrame3 g = three_key_frame3();  // no pose known: the same culling
  g.mTimeStamp = kStamp0 + 1.0 / 30;
  g.mnId = 1;
  EXPECT_EQ(host::cull_orb_slam_frame(culler, g, kGrey, cv::Mat(), camera_K(), cv::Mat(), FakeSE3{0.f}, false), 3);
  EXPECT_EQ(culler.stats().frames_not_ok, 0u);
}

// The culler reads the pose the host predicts: a Sophus-like pose that is not rigid (a NaN) is refused by
// the culler, and the frame passes uncut with the reason.
TEST(HostCullerFrame, ASophusPoseReachesTheCuller) {
  const cv::Mat pose = host::detail::pose_matrix(FakeSE3{0.25f});
  ASSERT_EQ(pose.type(), CV_64F);
  ASSERT_EQ(pose.size(), cv::Size(4, 4));
  EXPECT_DOUBLE_EQ(pose.at<double>(2, 3), 0.25);
  EXPECT_DOUBLE_EQ(pose.at<double>(3, 3), 1.0);
  TempDir dir("orb3pose");
  write_two_frames(dir);
  HostSettings s = settings_for(Mode::Culler, dir);
  s.log_path = dir.file("frames.csv");
  {
    HostCuller culler(s);
    FakeFrame3 f = three_key_frame3();
    const cv::Mat depth(480, 640, CV_32F, cv::Scalar(2.f));
    EXPECT_EQ(host::cull_orb_slam_frame(culler, f, kGrey, depth, camera_K(), cv::Mat(),
                                        FakeSE3{std::numeric_limits<float>::quiet_NaN()}),
              3);
    EXPECT_EQ(f.mvKeys.size(), 3u);
    EXPECT_EQ(culler.stats().frames_not_ok, 1u);
  }
  const std::vector<std::string> log = lines_of(s.log_path);
  ASSERT_EQ(log.size(), 2u);
  EXPECT_NE(log[1].find(",non-finite input,cam_from_world has a NaN"), std::string::npos) << log[1];
}

// A two-camera frame (fisheye stereo: keys left then right, Nleft and Nright set) or a frame with
// left-right matches passes uncut, logged with the arrays named.
TEST(HostCullerFrame, AnOrbSlam3TwoCameraFrameIsLoggedAsNotCulled) {
  TempDir dir("orb3stereo");
  write_two_frames(dir);
  HostSettings s = settings_for(Mode::BoxOnly, dir);
  s.log_path = dir.file("frames.csv");
  {
    HostCuller culler(s);
    FakeFrame3 f = three_key_frame3();
    f.Nleft = 2;
    f.Nright = 1;
    EXPECT_EQ(host::cull_orb_slam_frame(culler, f, kGrey, cv::Mat(), camera_K(), cv::Mat(), FakeSE3{0.f}), 3);
    EXPECT_EQ(f.mvKeys.size(), 3u);
    FakeFrame3 g = three_key_frame3();
    g.mvLeftToRightMatch = {0, -1, 1};
    EXPECT_EQ(host::cull_orb_slam_frame(culler, g, kGrey, cv::Mat(), camera_K(), cv::Mat(), FakeSE3{0.f}), 3);
    EXPECT_EQ(g.mvKeys.size(), 3u);
    EXPECT_EQ(culler.stats().frames_not_ok, 2u);
  }
  const std::vector<std::string> log = lines_of(s.log_path);
  ASSERT_EQ(log.size(), 3u);
  EXPECT_NE(log[1].find("a two-camera frame (Nleft 2; Nright 1)"), std::string::npos) << log[1];
  EXPECT_NE(log[2].find("mvLeftToRightMatch 3"), std::string::npos) << log[2];
}

// The OpenCV camera reads distortion from any layout, also a column view of a larger matrix.
TEST(HostCullerFrame, CullerCameraReadsADistortionView) {
  cv::Mat wide(5, 3, CV_64F, cv::Scalar(0));
  for (int r = 0; r < 5; ++r) wide.at<double>(r, 1) = 0.01 * (r + 1);
  const CullerCamera c = cv_adapter::culler_camera(camera_K(), cv::Size(640, 480), wide.col(1));
  EXPECT_EQ(c.distortion, (std::vector<double>{0.01, 0.02, 0.03, 0.04, 0.05}));
}

}  // namespace
}  // namespace dyncull
