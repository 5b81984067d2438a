// Tests of host/live_detection.hpp (library dyncull::host) without a network: a stand-in detector that
// finds one box per frame at a position given by the frame's number (written into its first pixel) and
// can be held, slowed or made to fail. The asynchronous hand-over waits once, on the first frame, for
// its own boxes (bounded), then gives the newest finished boxes with their age in frames, moved by their velocity;
// a detector slower than the frames never holds the tracking thread; the synchronous form gives each
// frame's own boxes; a failed or throwing detector culls without boxes, with the reason. Then the host
// with a live detector (the log's box age), a bad DYNCULL_DETECTOR refused at start with the variable and
// file named, and the real Darknet model (DYNCULL_DATA_DIR) on the stored colour samples.
#include "dyncull/host/host_culler.hpp"
#include "dyncull/host/live_detection.hpp"

#include <gtest/gtest.h>

#include "support/real_data.hpp"

#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <atomic>
#include <chrono>
#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <numeric>
#include <sstream>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#ifdef __linux__
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

namespace dyncull {
namespace {

namespace fs = std::filesystem;
using host::LiveBoxes;
using host::LiveDetection;
using host::LiveDetectionOptions;

// A frame carrying its number in its first pixel (0..255).
cv::Mat numbered_frame(int number) {
  cv::Mat m(48, 64, CV_8UC3, cv::Scalar(0, 0, 0));
  m.at<cv::Vec3b>(0, 0)[0] = static_cast<unsigned char>(number);
  return m;
}

// The calling thread's own nice value on Linux (per thread there), else -100.
int thread_nice() {
#ifdef __linux__
  return getpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)));
#else
  return -100;
#endif
}

// One person box 100 px wide whose left edge is 10 px per frame number: a walker moving right at 10 px per frame.
// `hold` keeps detections waiting until release(); `delay_ms` slows each; `fail_from` fails from that
// frame on (`throw_instead`: throws).
class StandIn : public host::FrameDetector {
 public:
  struct Control {
    std::mutex mutex;
    std::condition_variable cv;
    bool hold = false;
    int delay_ms = 0;
    int fail_from = 1 << 30;
    bool throw_instead = false;
    std::vector<int> seen;
    int entered = 0;         // detections started (before the hold)
    int detector_nice = -100;  // the detecting thread's nice value (Linux), or -100
    void release() {
      std::lock_guard<std::mutex> lock(mutex);
      hold = false;
      cv.notify_all();
    }
  };
  explicit StandIn(Control* c) : c_(c) {}
  bool detect(const cv::Mat& frame, std::vector<DetectedBox>* boxes, std::string* reason) override {
    const int number = frame.at<cv::Vec3b>(0, 0)[0];
    {
      std::unique_lock<std::mutex> lock(c_->mutex);
      ++c_->entered;
      c_->detector_nice = thread_nice();
      c_->cv.notify_all();
      c_->cv.wait(lock, [this] { return !c_->hold; });
      c_->seen.push_back(number);
    }
    if (c_->delay_ms > 0) std::this_thread::sleep_for(std::chrono::milliseconds(c_->delay_ms));
    if (number >= c_->fail_from) {
      if (c_->throw_instead) throw std::runtime_error("stand-in detector exploded");
      *reason = "stand-in detector failed";
      return false;
    }
    const float x = 10.f * static_cast<float>(number);
    boxes->assign(1, DetectedBox(x, 10.f, x + 100.f, 40.f, 0, 0.9f));
    return true;
  }

 private:
  Control* c_;
};

std::unique_ptr<host::FrameDetector> stand_in(StandIn::Control* c) {
  return std::unique_ptr<host::FrameDetector>(new StandIn(c));
}

void wait_finished(const LiveDetection& live, std::size_t n) {
  for (int k = 0; k < 10000 && live.finished() < n; ++k) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  ASSERT_GE(live.finished(), n);
}

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// The host builds its first map from the first frame: that frame waits for its own boxes, once.
TEST(LiveDetection, TheFirstFrameWaitsForItsOwnBoxes) {
  StandIn::Control c;
  c.delay_ms = 40;
  LiveDetectionOptions o;
  o.grow_px_per_frame = 0;
  LiveDetection live(stand_in(&c), o);
  const LiveBoxes& first = live.frame(0, numbered_frame(0));
  EXPECT_EQ(first.age_frames, 0);
  ASSERT_EQ(first.boxes.size(), 1u);
  EXPECT_TRUE(first.reason.empty()) << first.reason;
  const auto start = std::chrono::steady_clock::now();
  const LiveBoxes& second = live.frame(1, numbered_frame(1));  // the detector is busy for 40 ms: no wait
  EXPECT_LT(ms_since(start), 30.0);
  EXPECT_EQ(second.age_frames, 1);
}

// A detector that does not finish: the first frame waits first_frame_wait_ms, then goes on without boxes,
// and no later frame waits.
TEST(LiveDetection, NoBoxesBeforeTheFirstDetectionFinishes) {
  StandIn::Control c;
  c.hold = true;
  LiveDetectionOptions o;
  o.grow_px_per_frame = 0;
  o.first_frame_wait_ms = 100;
  LiveDetection live(stand_in(&c), o);
  auto start = std::chrono::steady_clock::now();
  const LiveBoxes& b = live.frame(0, numbered_frame(0));
  EXPECT_GE(ms_since(start), 90.0);
  EXPECT_LT(ms_since(start), 1000.0);
  EXPECT_TRUE(b.boxes.empty());
  EXPECT_EQ(b.age_frames, -1);
  EXPECT_FALSE(b.failed);
  EXPECT_NE(b.reason.find("no detection finished yet"), std::string::npos) << b.reason;
  start = std::chrono::steady_clock::now();
  EXPECT_TRUE(live.frame(1, numbered_frame(1)).boxes.empty());
  EXPECT_LT(ms_since(start), 30.0);
  c.release();
}

TEST(LiveDetection, BoxesFromAnOlderFrameCarryTheirAge) {
  StandIn::Control c;
  LiveDetectionOptions o;
  o.grow_px_per_frame = 2;
  LiveDetection live(stand_in(&c), o);
  live.frame(0, numbered_frame(0));
  wait_finished(live, 1);
  {
    std::lock_guard<std::mutex> lock(c.mutex);
    c.hold = true;  // frame 3 is offered while the detector is held
  }
  const LiveBoxes& b = live.frame(3, numbered_frame(3));
  EXPECT_EQ(b.age_frames, 3);
  ASSERT_EQ(b.boxes.size(), 1u);
  // One detection: no velocity yet, so the box stays where frame 0 saw it, grown by 2 px per frame of age.
  EXPECT_FLOAT_EQ(b.boxes[0].x0, 0.f - 6.f);
  EXPECT_FLOAT_EQ(b.boxes[0].x1, 100.f + 6.f);
  c.release();
}

TEST(LiveDetection, TheNewestFrameOfferedWinsAndBoxesMoveWithTheirVelocity) {
  StandIn::Control c;
  LiveDetectionOptions o;
  o.grow_px_per_frame = 0;
  LiveDetection live(stand_in(&c), o);
  live.frame(0, numbered_frame(0));
  wait_finished(live, 1);
  {
    std::lock_guard<std::mutex> lock(c.mutex);
    c.hold = true;
  }
  live.frame(1, numbered_frame(1));  // taken by the detector, which waits
  {
    std::unique_lock<std::mutex> lock(c.mutex);
    ASSERT_TRUE(c.cv.wait_for(lock, std::chrono::seconds(5), [&c] { return c.entered == 2; }));
  }
  live.frame(2, numbered_frame(2));  // offered while busy, then replaced
  live.frame(3, numbered_frame(3));
  c.release();
  wait_finished(live, 3);
  const LiveBoxes& b = live.frame(5, numbered_frame(5));
  {
    std::lock_guard<std::mutex> lock(c.mutex);
    EXPECT_EQ(std::count(c.seen.begin(), c.seen.end(), 2), 0) << "frame 2 was replaced by frame 3";
  }
  // Adopted detections: frame 0 (x0 = 0), then frame 3 (x0 = 30; frame 1's result was replaced by it before
  // the tracker looked): 10 px per frame, age 2 -> x0 = 50.
  EXPECT_EQ(b.age_frames, 2);
  ASSERT_EQ(b.boxes.size(), 1u);
  EXPECT_FLOAT_EQ(b.boxes[0].x0, 50.f);
  EXPECT_FLOAT_EQ(b.boxes[0].x1, 150.f);
}

// A detector five times slower than the frames: every frame() after the first returns at once with the
// newest boxes.
TEST(LiveDetection, ADetectorSlowerThanTheFramesNeverHoldsTracking) {
  StandIn::Control c;
  c.delay_ms = 50;
  LiveDetection live(stand_in(&c), LiveDetectionOptions());
  double slowest_ms = 0;
  long oldest = 0;
  for (int t = 0; t < 40; ++t) {
    const cv::Mat frame = numbered_frame(t);
    const auto start = std::chrono::steady_clock::now();
    const LiveBoxes& b = live.frame(t, frame);
    if (t > 0) slowest_ms = std::max(slowest_ms, ms_since(start));  // the first frame waits for its boxes
    if (b.age_frames >= 0) oldest = std::max(oldest, b.age_frames);
    if (t > 15) {
      EXPECT_GE(b.age_frames, 1) << "frame " << t;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  // Waiting for a detection would take up to 50 ms; the hand-over is a copy of a small frame and a swap.
  // 30 ms leaves room for a loaded machine's scheduling.
  EXPECT_LT(slowest_ms, 30.0) << "the tracking thread waited for the detector";
  EXPECT_GE(live.finished(), 3u);
  EXPECT_LT(live.finished(), 35u);  // frames were skipped: the detector takes the newest, never each one
  EXPECT_GE(oldest, 2);             // boxes older than the previous frame: the detector is behind
}

#ifdef __linux__
// On two cores the detector shares the CPU with tracking and mapping: its thread runs at the lowest
// priority so that tracking's time per frame does not grow with it; the tracking thread keeps its own.
TEST(LiveDetection, TheDetectorThreadYieldsTheCpuToTracking) {
  StandIn::Control c;
  const int tracking_nice = thread_nice();
  LiveDetection live(stand_in(&c), LiveDetectionOptions());
  live.frame(0, numbered_frame(0));
  wait_finished(live, 1);
  std::lock_guard<std::mutex> lock(c.mutex);
  EXPECT_EQ(c.detector_nice, 19);
  EXPECT_EQ(thread_nice(), tracking_nice);
}
#endif

TEST(LiveDetection, SynchronousGivesEachFramesOwnBoxes) {
  StandIn::Control c;
  LiveDetectionOptions o;
  o.synchronous = true;
  LiveDetection live(stand_in(&c), o);
  for (int t = 0; t < 4; ++t) {
    const LiveBoxes& b = live.frame(t, numbered_frame(t));
    EXPECT_EQ(b.age_frames, 0);
    ASSERT_EQ(b.boxes.size(), 1u);
    EXPECT_FLOAT_EQ(b.boxes[0].x0, 10.f * t);
  }
  EXPECT_EQ(live.finished(), 4u);
}

TEST(LiveDetection, AFailingOrThrowingDetectorCullsWithoutBoxes) {
  for (bool throws : {false, true}) {
    StandIn::Control c;
    c.fail_from = 1;
    c.throw_instead = throws;
    LiveDetectionOptions o;
    o.synchronous = true;
    LiveDetection live(stand_in(&c), o);
    EXPECT_EQ(live.frame(0, numbered_frame(0)).boxes.size(), 1u);
    const LiveBoxes& b = live.frame(1, numbered_frame(1));
    EXPECT_TRUE(b.failed);
    EXPECT_TRUE(b.boxes.empty());
    EXPECT_NE(b.reason.find(throws ? "stand-in detector exploded" : "stand-in detector failed"), std::string::npos)
        << b.reason;
    EXPECT_NE(b.reason.find("culled without boxes"), std::string::npos) << b.reason;
    EXPECT_EQ(live.failures(), 1u);
  }
}

TEST(LiveDetection, AnEmptyOrOddFrameIsNotOffered) {
  StandIn::Control c;
  LiveDetectionOptions o;
  o.synchronous = true;
  LiveDetection live(stand_in(&c), o);
  const LiveBoxes& b = live.frame(0, cv::Mat());
  EXPECT_NE(b.reason.find("not given to the detector"), std::string::npos) << b.reason;
  live.frame(1, cv::Mat(4, 4, CV_32FC1, cv::Scalar(0)));
  EXPECT_EQ(live.finished(), 0u);
}

// The host with a live detector: the log says the boxes' age, and box_only culls with carried boxes.
TEST(LiveDetectionHost, TheLogRecordsTheBoxesAge) {
  const fs::path dir = fs::temp_directory_path() / "dyncull_live_host";
  fs::remove_all(dir);
  fs::create_directories(dir);
  StandIn::Control c;
  host::HostSettings s;
  s.mode = host::Mode::BoxOnly;
  s.detector_sync = true;
  s.log_path = (dir / "frames.csv").string();
  {
    host::HostCuller culler(s, stand_in(&c));
    ASSERT_TRUE(culler.ok()) << culler.reason();
    const std::vector<cv::KeyPoint> keys = {cv::KeyPoint(15.f, 20.f, 7.f), cv::KeyPoint(160.f, 20.f, 7.f)};
    const cv::Mat descriptors(2, 32, CV_8U, cv::Scalar(1)), K = cv::Mat::eye(3, 3, CV_64F), none;
    const cv::Mat frame = numbered_frame(0);
    host::HostFrame f;
    f.K = &K;
    f.distortion = f.depth = f.predicted_Tcw = &none;
    f.image = &frame;
    f.keys = f.keys_un = &keys;
    f.descriptors = &descriptors;
    const std::vector<std::uint8_t>* keep = culler.cull(f);
    ASSERT_NE(keep, nullptr);
    EXPECT_EQ(*keep, (std::vector<std::uint8_t>{0, 1}));
    EXPECT_NE(culler.summary().find("live detector (waited for)"), std::string::npos) << culler.summary();
  }
  std::ifstream in(s.log_path);
  std::string header, line;
  std::getline(in, header);
  std::getline(in, line);
  EXPECT_EQ(header, "stamp,mode,status,reason,features,kept,boxes,box_age,ms");
  EXPECT_NE(line.find(",box_only,ok,,2,1,1,0,"), std::string::npos) << line;
  fs::remove_all(dir);
}

// A bad DYNCULL_DETECTOR stops the host at start with the variable, the file and the reason.
TEST(LiveDetectionHost, ABadDetectorIsRefusedAtStartNamingTheFile) {
  const fs::path dir = fs::temp_directory_path() / "dyncull_bad_detector";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "not_a_model.cfg") << "this is not a Darknet cfg\n";
  std::ofstream(dir / "empty.weights") << "";
  std::ofstream(dir / "junk.weights") << std::string(4096, 'x');
  const struct {
    std::string spec, expected;
  } cases[] = {
      {(dir / "missing.cfg").string() + "," + (dir / "missing.weights").string(), "missing.cfg: no such file"},
      {"/dev/zero", "/dev/zero: not a regular file"},
      {(dir / "not_a_model.cfg").string() + "," + (dir / "junk.weights").string(), "not_a_model.cfg: "},
      {(dir / "model.onnx").string(), "model.onnx: no such file"},
      {"only.cfg,", "expected CFG,WEIGHTS"},
  };
  std::vector<std::pair<std::string, std::string>> all;
  for (const auto& c : cases) all.emplace_back(c.spec, c.expected);
  // Unreadable weights beside the real cfg (when the data is there): empty, and a directory.
  std::string no_data;
  const std::string root = dyncull::test::real_data_dir(&no_data);
  const fs::path cfg = fs::path(root) / "models" / "yolo-fastest-1.1-xl" / "yolo-fastest-1.1-xl.cfg";
  if (!root.empty() && fs::exists(cfg)) {
    fs::create_directories(dir / "folder.weights");
    all.emplace_back(cfg.string() + "," + (dir / "empty.weights").string(), "empty.weights: empty file");
    all.emplace_back(cfg.string() + "," + (dir / "folder.weights").string(), "folder.weights: not a regular file");
    all.emplace_back(cfg.string() + "," + (dir / "missing.weights").string(), "missing.weights: no such file");
  }
  for (const auto& c : all) {
    host::HostSettings s;
    s.mode = host::Mode::Culler;
    s.detector = c.first;
    host::HostCuller culler(s);
    EXPECT_FALSE(culler.ok()) << c.first;
    EXPECT_EQ(culler.reason().rfind("DYNCULL_DETECTOR=", 0), 0u) << culler.reason();
    EXPECT_NE(culler.reason().find(c.second), std::string::npos) << culler.reason();
  }
  fs::remove_all(dir);
}

// The real Darknet model (Yolo-Fastest 1.1 XL) on the ten stored colour frames, asynchronously as the host
// runs it, one frame at a time: the first frame's own boxes, then at every frame the previous frame's
// (age 1), with a person where the stored detections of that frame have one.
TEST(LiveDetectionRealModel, FindsPeopleOnTheStoredColourSamples) {
  std::string why_not;
  const std::string root = dyncull::test::real_data_dir(&why_not);
  if (root.empty()) GTEST_SKIP() << why_not;
  const fs::path model = fs::path(root) / "models" / "yolo-fastest-1.1-xl";
  const fs::path samples = fs::path(root) / "bonn" / "crowd_part1" / "rgb_samples";
  if (!fs::exists(model) || !fs::exists(samples)) GTEST_SKIP() << model << " or " << samples << " is missing: skipped";
  std::string reason;
  std::unique_ptr<host::FrameDetector> yolo = host::open_yolo_detector(
      (model / "yolo-fastest-1.1-xl.cfg").string() + "," + (model / "yolo-fastest-1.1-xl.weights").string(), &reason);
  ASSERT_TRUE(yolo) << reason;
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(samples))
    if (e.path().extension() == ".png") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  ASSERT_EQ(files.size(), 10u);
  LiveDetection live(std::move(yolo), LiveDetectionOptions());
  // The stored detections (detections/, same model offline) have people on the last five samples only
  // (frames 250 to 450 of the part): boxes arriving at frame t are frame t - 1's.
  int finished = 0, agree = 0;
  for (std::size_t t = 0; t < files.size(); ++t) {
    const cv::Mat bgr = cv::imread(files[t].string(), cv::IMREAD_COLOR);
    ASSERT_EQ(bgr.type(), CV_8UC3) << files[t];
    if (t > 0) wait_finished(live, t);  // a slow camera: each frame's detection finishes before the next
    const LiveBoxes& b = live.frame(static_cast<long>(t), bgr);
    EXPECT_FALSE(b.failed) << b.reason;
    if (b.age_frames < 0) continue;
    ++finished;
    // The first frame waits for its own boxes; then the previous frame's (each finished before the next).
    EXPECT_EQ(b.age_frames, t == 0 ? 0 : 1);
    const bool person = std::any_of(b.boxes.begin(), b.boxes.end(), [](const DetectedBox& x) { return x.class_id == 0; });
    const bool stored_person = static_cast<long>(t) - b.age_frames >= 5;
    if (person == stored_person) ++agree;
    std::printf("frame %zu: %zu boxes (person: %d), age %ld, %.1f ms\n", t, b.boxes.size(), int(person), b.age_frames,
                b.detector_ms);
  }
  EXPECT_EQ(finished, 10);
  EXPECT_GE(agree, 9) << "frames whose live boxes agree with the stored ones on a person, of 10";
  EXPECT_EQ(live.failures(), 0u);
}


// Frames [first, first + count) of the Bonn crowd part's colour list, each with the depth map nearest in
// time (within 0.02 s), and K from camera.txt; `skip` says what is missing.
struct BonnFrames {
  std::vector<std::string> colour, depth;
  std::vector<double> stamps;
  cv::Mat K;
  std::string data_dir;  ///< DYNCULL_DATA_DIR
  std::string skip;
};

std::vector<std::pair<double, std::string>> tum_list(const fs::path& path) {
  std::vector<std::pair<double, std::string>> out;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ss(line);
    double stamp = 0;
    std::string file;
    if (ss >> stamp >> file) out.emplace_back(stamp, file);
  }
  return out;
}

BonnFrames bonn_frames(std::size_t first, std::size_t count) {
  BonnFrames b;
  b.data_dir = dyncull::test::real_data_dir(&b.skip);
  if (b.data_dir.empty()) return b;
  const fs::path seq = fs::path(b.data_dir) / "bonn" / "crowd_part1";
  if (!fs::exists(seq / "rgb_color.txt")) {
    b.skip = (seq / "rgb_color.txt").string() + " is missing: skipped";
    return b;
  }
  std::map<std::string, double> camera;
  std::ifstream in(seq / "camera.txt");
  std::string key;
  double value = 0;
  while (in >> key >> value) camera[key] = value;
  b.K = (cv::Mat_<double>(3, 3) << camera["fx"], 0, camera["cx"], 0, camera["fy"], camera["cy"], 0, 0, 1);
  const auto colour = tum_list(seq / "rgb_color.txt"), depth = tum_list(seq / "depth.txt");
  for (std::size_t i = first; i < colour.size() && b.colour.size() < count; ++i) {
    const auto nearest = std::min_element(depth.begin(), depth.end(), [&](const auto& a, const auto& c) {
      return std::fabs(a.first - colour[i].first) < std::fabs(c.first - colour[i].first);
    });
    if (nearest == depth.end() || std::fabs(nearest->first - colour[i].first) > 0.02) continue;
    b.colour.push_back((seq / colour[i].second).string());
    b.depth.push_back((seq / nearest->second).string());
    b.stamps.push_back(colour[i].first);
  }
  return b;
}

// The host as the ORB-SLAM2 patch runs it, on 60 Bonn colour frames where people walk, at 30 Hz (ORB
// features on the grey image, raw depth, the colour image to the detector): asynchronously, a frame costs
// the tracking thread the culling alone, and its boxes are a few frames old; waited for, it costs the
// detection too.
TEST(LiveDetectionRealModel, TheHostCullsTheBonnFramesWithoutWaitingForTheDetector) {
  const BonnFrames b = bonn_frames(250, 60);
  if (!b.skip.empty()) GTEST_SKIP() << b.skip;
  const fs::path model = fs::path(b.data_dir) / "models" / "yolo-fastest-1.1-xl";
  if (!fs::exists(model)) GTEST_SKIP() << model << " is missing: skipped";
  ASSERT_EQ(b.colour.size(), 60u);
  const cv::Ptr<cv::ORB> orb = cv::ORB::create(1000);
  double host_ms[2] = {0, 0}, culled[2] = {0, 0};
  std::size_t with_boxes[2] = {0, 0}, newer_boxes[2] = {0, 0};
  host::HostCuller::Stats stats[2];
  for (int sync = 0; sync < 2; ++sync) {
    host::HostSettings s;
    s.mode = host::Mode::Culler;
    s.detector = (model / "yolo-fastest-1.1-xl.cfg").string() + "," + (model / "yolo-fastest-1.1-xl.weights").string();
    s.detector_sync = sync == 1;
    host::HostCuller culler(s);
    ASSERT_TRUE(culler.ok()) << culler.reason();
    double previous_age = 0;
    const auto begin = std::chrono::steady_clock::now();
    for (std::size_t t = 0; t < b.colour.size(); ++t) {
      // Frames at the camera's 30 Hz, as rgbd_tum replays them (a frame late is not waited for).
      std::this_thread::sleep_until(begin + std::chrono::microseconds(33333 * static_cast<long long>(t)));
      const cv::Mat colour = cv::imread(b.colour[t], cv::IMREAD_COLOR), depth = cv::imread(b.depth[t], cv::IMREAD_UNCHANGED);
      ASSERT_EQ(colour.type(), CV_8UC3) << b.colour[t];
      ASSERT_EQ(depth.type(), CV_16UC1) << b.depth[t];
      cv::Mat grey, descriptors;
      cv::cvtColor(colour, grey, cv::COLOR_BGR2GRAY);
      std::vector<cv::KeyPoint> keys;
      orb->detectAndCompute(grey, cv::noArray(), keys, descriptors);
      const cv::Mat none;
      host::HostFrame f;
      f.stamp = b.stamps[t];
      f.frame_id = t;
      f.K = &b.K;
      f.distortion = f.predicted_Tcw = &none;
      f.image = &colour;
      f.keys = f.keys_un = &keys;
      f.descriptors = &descriptors;
      f.depth = &depth;
      const double age_before = culler.stats().box_age_frames;
      const auto start = std::chrono::steady_clock::now();
      const std::vector<std::uint8_t>* keep = culler.cull(f);
      host_ms[sync] += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
      const double frame_age = culler.stats().box_age_frames - age_before;
      if (t > 0 && frame_age < previous_age) ++newer_boxes[sync];  // boxes of a newer detection arrived
      previous_age = frame_age;
      ASSERT_NE(keep, nullptr);
      culled[sync] += static_cast<double>(std::count(keep->begin(), keep->end(), std::uint8_t(0)));
    }
    stats[sync] = culler.stats();
    with_boxes[sync] = culler.stats().frames - culler.stats().frames_without_detections;
    host_ms[sync] /= static_cast<double>(b.colour.size());
    culled[sync] /= static_cast<double>(b.colour.size());
  }
  const auto age = [&](int k) { return stats[k].frames_with_age ? stats[k].box_age_frames / double(stats[k].frames_with_age) : 0.0; };
  const auto detector_ms = [&](int k) { return stats[k].frames_with_age ? stats[k].detector_ms / double(stats[k].frames_with_age) : 0.0; };
  std::printf("asynchronous: %.1f ms per frame in the tracking thread, boxes on %zu of 60 frames, mean age %.2f frames, "
              "detection %.1f ms, %.0f features culled per frame\n", host_ms[0], with_boxes[0], age(0), detector_ms(0), culled[0]);
  std::printf("waited for:   %.1f ms per frame in the tracking thread, boxes on %zu of 60 frames, mean age %.2f frames, "
              "detection %.1f ms, %.0f features culled per frame\n", host_ms[1], with_boxes[1], age(1), detector_ms(1), culled[1]);
  EXPECT_EQ(with_boxes[1], 60u);
  EXPECT_DOUBLE_EQ(age(1), 0.0);
  EXPECT_EQ(with_boxes[0], 60u);  // the first frame waits for its own boxes
  EXPECT_GT(age(0), 0.5);
  // The detector thread runs at the lowest priority, so on a busy machine its boxes age; but the hand-over
  // goes on: newer boxes arrive again and again (a stalled one would carry the first frame's to the end).
  EXPECT_GE(newer_boxes[0], 2u);
  EXPECT_EQ(newer_boxes[1], 0u);  // waited for: every frame's own boxes, age 0
  // The tracking thread does not pay for the detection: less than half of what waiting for it costs.
  EXPECT_LT(host_ms[0], 0.5 * host_ms[1]);
  EXPECT_GT(culled[0], 0.0);
  EXPECT_GT(culled[1], 0.0);
}

}  // namespace
}  // namespace dyncull
