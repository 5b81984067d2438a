// The TUM-format sequence reader (eval/sequence.hpp): rgb / depth association as associate.py, missing
// files reported and run without depth, camera.txt and command-line intrinsics, detections by stamp; and
// the real Bonn crowd_part1 folder through DYNCULL_DATA_DIR (skipped loudly without it).
#include "dyncull/eval/sequence.hpp"
#include "support/real_data.hpp"
#include "support/special_files.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace {

using namespace dyncull;
namespace fs = std::filesystem;

class SequenceFolder : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("dyncull_sequence_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "rgb");
    fs::create_directories(dir_ / "depth");
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  void write(const std::string& name, const std::string& text) const { std::ofstream(path(name)) << text; }
  // rgb.txt and depth.txt listing these stamps, with the image files created unless `missing` names them.
  void lists(const std::vector<std::string>& rgb, const std::vector<std::string>& depth,
             const std::vector<std::string>& missing = {}) const {
    std::string r = "# color images\n# timestamp filename\n", d = "# depth maps\n# timestamp filename\n";
    auto touch = [&](const std::string& file) {
      if (std::find(missing.begin(), missing.end(), file) == missing.end()) write(file, "png");
    };
    for (const std::string& t : rgb) {
      r += t + " rgb/" + t + ".png\n";
      touch("rgb/" + t + ".png");
    }
    for (const std::string& t : depth) {
      d += t + " depth/" + t + ".png\n";
      touch("depth/" + t + ".png");
    }
    write("rgb.txt", r);
    write("depth.txt", d);
  }

  fs::path dir_;
};

TEST_F(SequenceFolder, AssociationIsGreedyByDifferenceEachStampOnce) {
  // Depth 1.012 is nearest to both rgb 1.000 (0.012 s) and 1.015 (0.003 s): associate.py gives it to the
  // closer pair only, so rgb 1.000 has no depth although a depth image lies within 0.02 s of it.
  // rgb 2.000 has depth 2.030 beyond the window; rgb 3.000 pairs with 3.019 (inside the window).
  lists({"1.000", "1.015", "2.000", "3.000"}, {"1.012", "2.030", "3.019"});
  const eval::SequenceIndex s = eval::read_sequence(dir_.string());
  ASSERT_TRUE(s.ok()) << s.reason;
  ASSERT_EQ(s.frames.size(), 4u);
  EXPECT_FALSE(s.frames[0].has_depth());
  EXPECT_EQ(s.frames[1].depth_path, "depth/1.012.png");
  EXPECT_FALSE(s.frames[2].has_depth());
  EXPECT_EQ(s.frames[3].depth_path, "depth/3.019.png");
  EXPECT_EQ(s.frames_without_depth, 2u);
  ASSERT_EQ(s.notes.count, 2u);
  EXPECT_NE(s.notes.first[0].find("rgb.txt:3: frame 0 (rgb/1.000.png) has no depth within 0.02 s"), std::string::npos)
      << s.notes.first[0];
  EXPECT_TRUE(s.groundtruth_path.empty());
}

TEST_F(SequenceFolder, ListsAreSortedAndARepeatedStampKeepsTheLaterLine) {
  write("rgb/a.png", "png");
  write("rgb/b.png", "png");
  write("rgb/c.png", "png");
  write("depth/d.png", "png");
  write("rgb.txt", "2.0 rgb/b.png\n1.0 rgb/a.png\n2.0 rgb/c.png\n");
  write("depth.txt", "1.001 depth/d.png\n");
  const eval::SequenceIndex s = eval::read_sequence(dir_.string());
  ASSERT_TRUE(s.ok()) << s.reason;
  ASSERT_EQ(s.frames.size(), 2u);
  EXPECT_EQ(s.frames[0].image_path, "rgb/a.png");
  EXPECT_EQ(s.frames[1].image_path, "rgb/c.png");
  EXPECT_NE(s.notes.first[0].find("rgb.txt:1: same stamp as line 3"), std::string::npos) << s.notes.first[0];
}

TEST_F(SequenceFolder, MissingDepthFileRunsWithoutDepthAndMissingImageIsLeftOut) {
  lists({"1.000", "1.033", "1.066"}, {"1.001", "1.034", "1.067"}, {"depth/1.034.png", "rgb/1.066.png"});
  const eval::SequenceIndex s = eval::read_sequence(dir_.string());
  ASSERT_TRUE(s.ok()) << s.reason;
  ASSERT_EQ(s.frames.size(), 2u);
  EXPECT_TRUE(s.frames[0].has_depth());
  EXPECT_FALSE(s.frames[1].has_depth());
  EXPECT_EQ(s.missing_images, 1u);
  EXPECT_EQ(s.missing_depth, 1u);
  EXPECT_EQ(s.frames_without_depth, 1u);
  std::string all;
  for (const std::string& n : s.notes.first) all += n + "\n";
  EXPECT_NE(all.find("rgb.txt:5: rgb/1.066.png does not exist"), std::string::npos) << all;
  EXPECT_NE(all.find("depth.txt:4: depth/1.034.png does not exist"), std::string::npos) << all;
}

TEST_F(SequenceFolder, BadListsNameFileAndLine) {
  lists({"1.0"}, {"1.0"});
  write("rgb.txt", "# header\n1.0 rgb/1.0.png\nabc rgb/1.0.png\n");
  eval::SequenceIndex s = eval::read_sequence(dir_.string());
  EXPECT_EQ(s.status, Status::ParseError);
  EXPECT_NE(s.reason.find("rgb.txt:3: timestamp 'abc' is not a finite number"), std::string::npos) << s.reason;

  write("rgb.txt", "1.0\n");
  s = eval::read_sequence(dir_.string());
  EXPECT_NE(s.reason.find("rgb.txt:1: expected 'timestamp filename'"), std::string::npos) << s.reason;

  eval::SequenceOptions o;
  o.max_line_chars = 64;
  write("rgb.txt", "1.0 rgb/1.0.png\n1.1 " + std::string(200, 'x') + "\n");
  s = eval::read_sequence(dir_.string(), o);
  EXPECT_EQ(s.status, Status::ParseError);
  EXPECT_NE(s.reason.find("rgb.txt:2: line longer than 64 characters"), std::string::npos) << s.reason;

  fs::remove(path("depth.txt"));
  fs::create_directories(path("depth.txt"));
  write("rgb.txt", "1.0 rgb/1.0.png\n");
  s = eval::read_sequence(dir_.string());
  EXPECT_EQ(s.status, Status::IoError);
  EXPECT_NE(s.reason.find("depth.txt: is a directory, not a regular file"), std::string::npos) << s.reason;

  s = eval::read_sequence(path("nowhere"));
  EXPECT_EQ(s.status, Status::IoError);
}

TEST_F(SequenceFolder, EmptyDepthListRunsEveryFrameWithoutDepth) {
  lists({"1.0", "2.0"}, {});
  const eval::SequenceIndex s = eval::read_sequence(dir_.string());
  ASSERT_TRUE(s.ok()) << s.reason;
  EXPECT_EQ(s.frames_without_depth, 2u);
  write("rgb.txt", "# nothing\n");
  EXPECT_EQ(eval::read_sequence(dir_.string()).status, Status::TooFewPoints);
}

TEST_F(SequenceFolder, CameraFileWithDistortionAndDepthScale) {
  write("camera.txt", "# intrinsics\nfx 542.8\nfy 542.5\ncx 315.5\ncy 237.7\nk1 0.1\np2 -0.002\ndepth_units_per_metre 1000\n");
  const eval::CameraResult c = eval::read_camera_file(path("camera.txt"));
  ASSERT_TRUE(c.ok()) << c.reason;
  EXPECT_DOUBLE_EQ(c.camera.fx, 542.8);
  EXPECT_DOUBLE_EQ(c.camera.fy, 542.5);
  EXPECT_DOUBLE_EQ(c.camera.cx, 315.5);
  EXPECT_DOUBLE_EQ(c.camera.cy, 237.7);
  EXPECT_DOUBLE_EQ(c.camera.distortion[0], 0.1);
  EXPECT_DOUBLE_EQ(c.camera.distortion[3], -0.002);
  EXPECT_TRUE(c.camera.has_distortion());
  EXPECT_DOUBLE_EQ(c.camera.depth_units_per_metre, 1000);
}

TEST_F(SequenceFolder, BadCameraFilesNameFileLineAndKey) {
  auto reason_of = [&](const std::string& text) {
    write("camera.txt", text);
    const eval::CameraResult c = eval::read_camera_file(path("camera.txt"));
    EXPECT_FALSE(c.ok());
    return c.reason;
  };
  EXPECT_NE(reason_of("fx 500\nfy 500\ncx 320\n").find("camera.txt: no cy"), std::string::npos);
  EXPECT_NE(reason_of("fx 500\nfy 500\ncx 320\ncy 240\nfocal 3\n").find("camera.txt:5: unknown key 'focal'"),
            std::string::npos);
  EXPECT_NE(reason_of("fx 500\nfy nan\n").find("camera.txt:2: fy: 'nan' is not a finite number"), std::string::npos);
  EXPECT_NE(reason_of("fx 500\nfx 501\n").find("camera.txt:2: fx repeats line 1"), std::string::npos);
  EXPECT_NE(reason_of("fx 500 1\n").find("camera.txt:1: expected 'key value'"), std::string::npos);
  EXPECT_NE(reason_of("fx -5\nfy 500\ncx 320\ncy 240\n").find("camera.txt: focal lengths fx, fy must be finite and positive"), std::string::npos);
  EXPECT_NE(reason_of("fx 5\nfy 5\ncx 3\ncy 2\ndepth_units_per_metre 0\n").find("camera.txt: depth units per metre = 0 is outside [1e-3, 1e6]"),
            std::string::npos);
  fs::create_directories(path("camdir"));
  EXPECT_EQ(eval::read_camera_file(path("camdir")).status, Status::IoError);
  EXPECT_EQ(eval::read_camera_file(path("absent.txt")).status, Status::IoError);
}

TEST(SequenceCamera, FromCommandLineListOrTumName) {
  eval::CameraResult c = eval::camera_from_spec("525,526,319.5,239.5");
  ASSERT_TRUE(c.ok()) << c.reason;
  EXPECT_DOUBLE_EQ(c.camera.fy, 526);
  EXPECT_DOUBLE_EQ(c.camera.depth_units_per_metre, 5000);
  EXPECT_FALSE(c.camera.has_distortion());
  c = eval::camera_from_spec("525,526,319.5,239.5,0.1,0,0,0,0.01");
  ASSERT_TRUE(c.ok()) << c.reason;
  EXPECT_DOUBLE_EQ(c.camera.distortion[4], 0.01);
  EXPECT_NE(eval::camera_from_spec("525,526,319.5").reason.find("3 numbers given"), std::string::npos);
  EXPECT_NE(eval::camera_from_spec("525,526,319.5,x").reason.find("value 4 'x'"), std::string::npos);
  c = eval::camera_from_spec("fr1");
  ASSERT_TRUE(c.ok()) << c.reason;
  EXPECT_DOUBLE_EQ(c.camera.fx, 517.3);
  c = eval::camera_from_spec("rgbd_dataset_freiburg2_desk");
  ASSERT_TRUE(c.ok()) << c.reason;
  EXPECT_DOUBLE_EQ(c.camera.cx, 325.1);
  c = eval::camera_from_spec("fr3");
  ASSERT_TRUE(c.ok()) << c.reason;
  EXPECT_DOUBLE_EQ(c.camera.fy, 539.2);
  c = eval::camera_from_spec("kinect");
  EXPECT_EQ(c.status, Status::InvalidInput);
  EXPECT_NE(c.reason.find("names none of TUM's cameras"), std::string::npos) << c.reason;
}

// A NUL byte ends a file name early: ".\0..." is no path to the current folder but text, refused as text.
TEST(SequenceCamera, SpecWithANulByteIsNoPath) {
  const eval::CameraResult c = eval::camera_from_spec(std::string(".\0kinect", 8));
  EXPECT_EQ(c.status, Status::InvalidInput);
  EXPECT_EQ(c.reason.find("is a directory"), std::string::npos) << c.reason;
  EXPECT_LT(c.reason.size(), 600u);
  EXPECT_NE(text::regular_file_problem(std::string("camera.txt\0x", 12)).find("contains a NUL byte"), std::string::npos);
}

// A camera no lens has runs to the end with a wrong answer: refused where it enters, naming the value.
TEST_F(SequenceFolder, AbsurdCamerasAreRefusedNamingTheValue) {
  auto file_reason = [&](const std::string& text) {
    write("camera.txt", text);
    const eval::CameraResult c = eval::read_camera_file(path("camera.txt"));
    EXPECT_EQ(c.status, Status::InvalidInput) << text;
    return c.reason;
  };
  const std::string ok = "fy 500\ncx 320\ncy 240\n";
  EXPECT_NE(file_reason("fx 1e-300\n" + ok).find("camera.txt: fx = 1e-300 px is outside [0.64, 6.4e+06]"),
            std::string::npos);
  EXPECT_NE(file_reason("fx 500\nfy 500\ncx -1e300\ncy 240\n").find("cx = -1e+300 px is more than one image width"),
            std::string::npos);
  EXPECT_NE(file_reason("fx 500\n" + ok + "k1 1e300\n").find("distortion k1 = 1e+300 is outside [-1000, 1000]"),
            std::string::npos);
  EXPECT_NE(file_reason("fx 500\n" + ok + "p2 3\n").find("distortion p2 = 3 is outside [-1, 1]"), std::string::npos);
  EXPECT_NE(file_reason("fx 500\n" + ok + "depth_units_per_metre 1e-300\n").find("depth units per metre = 1e-300"),
            std::string::npos);
  EXPECT_NE(file_reason("fx 500\n" + ok + "width 64\nheight 48\n").find("cx = 320 px is more than one image width"),
            std::string::npos);
  for (const char* spec : {"1e-300,500,320,240", "500,500,-1e300,240", "500,500,320,240,1e300,0,0,0,0"}) {
    const eval::CameraResult c = eval::camera_from_spec(spec);
    EXPECT_EQ(c.status, Status::InvalidInput) << spec;
    EXPECT_NE(c.reason.find("outside"), std::string::npos) << c.reason;
  }
  eval::SequenceCamera camera = eval::camera_from_spec("500,500,320,240").camera;
  EXPECT_EQ(camera.validate(), Status::Ok);
  camera.width = 64;  // the images turned out smaller: a caller checks again
  std::string why;
  EXPECT_EQ(camera.validate(&why), Status::InvalidInput);
  EXPECT_NE(why.find("cx = 320"), std::string::npos) << why;
}

// camera.txt keys and the --camera spec are user text: escaped and cut in reasons.
TEST_F(SequenceFolder, CameraKeysAndSpecsAreQuotedInReasons) {
  write("camera.txt", "fx 500\n\x1b[31m" + std::string(8000, 'k') + " 3\n");
  const eval::CameraResult c = eval::read_camera_file(path("camera.txt"));
  EXPECT_EQ(c.status, Status::ParseError);
  EXPECT_EQ(c.reason.find('\x1b'), std::string::npos) << c.reason;
  EXPECT_LT(c.reason.size(), 400u) << c.reason.size();
  EXPECT_NE(c.reason.find("unknown key '\\x1b[31mkkk"), std::string::npos) << c.reason;
  const std::string spec = "500,500,320\x1b]0;title\x07" + std::string(8000, '9');
  for (const std::string& s : {spec, "1e-300,500,320,240," + std::string(8000, '0') + ",0,0,0,0",
                               std::string("no\ncamera\x1b") + std::string(8000, 'x')}) {
    const eval::CameraResult r = eval::camera_from_spec(s);
    EXPECT_FALSE(r.ok());
    EXPECT_LT(r.reason.size(), 400u) << r.reason;
    for (char ch : r.reason) EXPECT_TRUE(ch >= 0x20 && ch < 0x7f) << r.reason;
  }
}

// camera.txt has a size cap of its own, and kernel files are refused like every other reader's.
TEST_F(SequenceFolder, CameraFilesFollowTheFileOpeningRule) {
  write("camera.txt", "fx 500\nfy 500\ncx 320\ncy 240\n" + std::string(text::kMaxCameraFileBytes, '#'));
  eval::CameraResult c = eval::read_camera_file(path("camera.txt"));
  EXPECT_EQ(c.status, Status::IoError);
  EXPECT_NE(c.reason.find("over the limit of 65536"), std::string::npos) << c.reason;
  c = eval::camera_from_spec("/proc/self/pagemap");
  EXPECT_EQ(c.status, Status::IoError);
  EXPECT_NE(c.reason.find("under /proc"), std::string::npos) << c.reason;
  c = eval::camera_from_spec("/dev/zero");
  EXPECT_EQ(c.status, Status::IoError);
}

// A detections folder holding more files than the sequence needs: the files are read in name order
// until every frame has its file (the later ones here are not even JSON), nothing is called missing, and
// the files not read are counted in a note. More files than max_frames is refused, not cut.
TEST_F(SequenceFolder, JsonDetectionsFolderIsReadOnlyAsFarAsTheFramesNeed) {
  lists({"10.000", "10.033", "10.066"}, {"10.001", "10.034", "10.067"});
  fs::create_directories(path("det"));
  const char* stamps[] = {"10.000", "10.033", "10.066", "10.100"};
  for (int k = 0; k < 4; ++k)
    write("det/00000" + std::to_string(k) + ".json",
          std::string("{\"frame_id\": ") + std::to_string(k) + ", \"timestamp\": " + stamps[k] +
              ", \"image_path\": \"x.png\", \"detections\": []}");
  for (int k = 4; k < 30; ++k) write("det/0000" + std::string(k < 10 ? "0" : "") + std::to_string(k) + ".json", "later");
  const eval::SequenceIndex s = eval::read_sequence(dir_.string());
  ASSERT_TRUE(s.ok()) << s.reason;
  const eval::SequenceDetections d = eval::read_sequence_detections(path("det"), s, 640, 480);
  ASSERT_TRUE(d.ok()) << d.reason;
  EXPECT_EQ(d.has_file, (std::vector<std::uint8_t>{1, 1, 1}));
  EXPECT_EQ(d.frames_with_file, 3u);
  EXPECT_EQ(d.files_unmatched, 1u);  // 10.100, read to see the frames were done
  std::string all;
  for (const std::string& n : d.notes.first) all += n + "\n";
  EXPECT_NE(all.find("26 files after 000003.json not read: every frame has its detections file"), std::string::npos)
      << all;
  EXPECT_EQ(all.find("have no detections file"), std::string::npos) << all;
  eval::SequenceOptions few;
  few.max_frames = 10;
  const eval::SequenceDetections capped = eval::read_sequence_detections(path("det"), s, 640, 480, few);
  EXPECT_EQ(capped.status, Status::ParseError);
  EXPECT_NE(capped.reason.find("more than 10 detection files"), std::string::npos) << capped.reason;
}

TEST_F(SequenceFolder, JsonDetectionsMatchFramesByTimestamp) {
  lists({"10.000", "10.033", "10.066"}, {"10.001", "10.034", "10.067"});
  fs::create_directories(path("det"));
  auto json = [](int id, const char* stamp, const char* boxes) {
    return std::string("{\"frame_id\": ") + std::to_string(id) + ", \"timestamp\": " + stamp +
           ", \"image_path\": \"x.png\", \"detections\": [" + boxes + "]}";
  };
  // File numbers need not follow the frames: the stamp decides. 10.066 has no file; 99.0 matches no frame.
  write("det/000000.json", json(0, "10.033", "{\"class_id\": 0, \"confidence\": 0.9, \"bbox\": [100, 50, 200, 300]}"));
  write("det/000001.json", json(1, "10.000", ""));
  write("det/000002.json", json(2, "99.0", ""));
  write("det/_summary.json", "not json at all");
  const eval::SequenceIndex s = eval::read_sequence(dir_.string());
  ASSERT_TRUE(s.ok()) << s.reason;
  const eval::SequenceDetections d = eval::read_sequence_detections(path("det"), s, 640, 480);
  ASSERT_TRUE(d.ok()) << d.reason;
  ASSERT_EQ(d.per_frame.size(), 3u);
  EXPECT_TRUE(d.per_frame[0].empty());
  ASSERT_EQ(d.per_frame[1].size(), 1u);
  EXPECT_EQ(d.per_frame[1][0].class_id, 0);
  EXPECT_NEAR(d.per_frame[1][0].box.x0, 95.0f, 1e-4f);  // the default filter pads by 5 px
  EXPECT_EQ(d.has_file, (std::vector<std::uint8_t>{1, 1, 0}));
  EXPECT_EQ(d.files_unmatched, 1u);
  std::string all;
  for (const std::string& n : d.notes.first) all += n + "\n";
  EXPECT_NE(all.find("000002.json: timestamp matches no frame"), std::string::npos) << all;
  EXPECT_NE(all.find("1 of 3 frames have no detections file"), std::string::npos) << all;

  write("det/000003.json", "{\"frame_id\": 3, \"timestamp\": }");
  const eval::SequenceDetections bad = eval::read_sequence_detections(path("det"), s, 640, 480);
  EXPECT_EQ(bad.status, Status::ParseError);
  EXPECT_NE(bad.reason.find("000003.json"), std::string::npos) << bad.reason;
}

TEST_F(SequenceFolder, YoloTextByStampOrStemAndBadLinesNamed) {
  lists({"10.000", "10.033"}, {"10.001", "10.034"});
  write("yolo.txt", "# stamp class cx cy w h conf\n10.000 0 0.5 0.5 0.25 0.5 0.9\n10.033 0 0.5 0.5 0.25 0.5 0.9\n"
                    "10.033 56 0.2 0.2 0.1 0.1 0.8\n55.0 0 0.5 0.5 0.2 0.2 0.9\n");
  const eval::SequenceIndex s = eval::read_sequence(dir_.string());
  ASSERT_TRUE(s.ok()) << s.reason;
  eval::SequenceDetections d = eval::read_sequence_detections(path("yolo.txt"), s, 640, 480);
  ASSERT_TRUE(d.ok()) << d.reason;
  EXPECT_EQ(d.per_frame[0].size(), 1u);
  EXPECT_EQ(d.per_frame[1].size(), 2u);
  EXPECT_EQ(d.files_unmatched, 1u);

  fs::create_directories(path("labels"));
  write("labels/10.033.txt", "0 0.5 0.5 0.25 0.5 0.9\n0 0.5 zero 0.2 0.2\n");
  d = eval::read_sequence_detections(path("labels"), s, 640, 480);
  EXPECT_EQ(d.status, Status::ParseError);
  EXPECT_NE(d.reason.find("10.033.txt:2:"), std::string::npos) << d.reason;

  EXPECT_EQ(eval::read_sequence_detections(path("nothing"), s, 640, 480).status, Status::IoError);
}

TEST_F(SequenceFolder, YoloBoxTheFilterCannotUseIsCountedAndNamed) {
  lists({"10.000", "10.033"}, {"10.001", "10.034"});
  // 1e400 parses as infinity: the line is well formed, the box is not usable.
  write("yolo.txt", "10.000 0 0.5 0.5 0.25 0.5 0.9\n10.033 0 0.5 0.5 1e400 0.5 0.9\n");
  const eval::SequenceIndex s = eval::read_sequence(dir_.string());
  ASSERT_TRUE(s.ok()) << s.reason;
  const eval::SequenceDetections d = eval::read_sequence_detections(path("yolo.txt"), s, 640, 480);
  ASSERT_TRUE(d.ok()) << d.reason;
  EXPECT_EQ(d.boxes_read, 2u);
  EXPECT_EQ(d.boxes_dropped, 1u);
  EXPECT_TRUE(d.per_frame[1].empty());
  std::string all;
  for (const std::string& n : d.notes.first) all += n + "\n";
  EXPECT_NE(all.find("yolo.txt:2: box dropped"), std::string::npos) << all;
}

TEST_F(SequenceFolder, FifosAndDevicesAreRefusedPromptly) {
  lists({"10.000", "10.033"}, {"10.001", "10.034"});
  const eval::SequenceIndex s = eval::read_sequence(dir_.string());
  ASSERT_TRUE(s.ok()) << s.reason;
  const std::string fifo = path("dets.txt");
  if (!test::make_fifo(fifo)) return;
  eval::SequenceDetections d;
  EXPECT_TRUE(test::returns_promptly([&] { d = eval::read_sequence_detections(fifo, s, 640, 480); }, fifo));
  EXPECT_EQ(d.status, Status::IoError);
  EXPECT_NE(d.reason.find("is a FIFO"), std::string::npos) << d.reason;
  EXPECT_EQ(eval::read_sequence_detections("/dev/zero", s, 640, 480).status, Status::IoError);

  fs::remove(path("rgb.txt"));
  const std::string rgb = path("rgb.txt");
  if (!test::make_fifo(rgb)) return;
  eval::SequenceIndex blocked;
  EXPECT_TRUE(test::returns_promptly([&] { blocked = eval::read_sequence(dir_.string()); }, rgb));
  EXPECT_EQ(blocked.status, Status::IoError);
  EXPECT_NE(blocked.reason.find("rgb.txt: is a FIFO"), std::string::npos) << blocked.reason;
}

// The real sequence: 464 frames of Bonn crowd (Palazzolo et al. 2019), a person first detected at frame
// 57. Three depth files of the span are not published (stamps 1548339819.855, 826.762, 834.304), yet
// associate.py's rule still pairs every grey frame: the depth clock drifts against the rgb clock (depth -
// rgb goes from +14 ms to -17 ms over 7 s), and each unpublished frame sits where that offset wraps, so
// the neighbours pair 16.7 ms apart instead of leaving a frame alone.
TEST(SequenceBonnCrowd, IndexesTheRealFolder) {
  std::string why_not;
  const std::string root = dyncull::test::real_data_dir(&why_not);
  if (root.empty()) GTEST_SKIP() << why_not;
  const std::string dir = root + "/bonn/crowd_part1";
  if (!fs::is_directory(dir)) GTEST_SKIP() << dir << " does not exist: the real-sequence test did not run";
  const eval::SequenceIndex s = eval::read_sequence(dir);
  ASSERT_TRUE(s.ok()) << s.reason;
  EXPECT_EQ(s.frames.size(), 464u);
  EXPECT_EQ(s.missing_images, 0u);
  EXPECT_EQ(s.missing_depth, 0u);
  EXPECT_EQ(s.frames_without_depth, 0u);
  double worst_dt = 0;
  for (const eval::SequenceFrame& f : s.frames) worst_dt = std::max(worst_dt, std::abs(f.depth_timestamp - f.timestamp));
  EXPECT_GT(worst_dt, 0.016);
  EXPECT_LT(worst_dt, 0.0175);
  EXPECT_FALSE(s.groundtruth_path.empty());

  const eval::CameraResult c = eval::read_camera_file(dir + "/camera.txt");
  ASSERT_TRUE(c.ok()) << c.reason;
  EXPECT_DOUBLE_EQ(c.camera.fx, 542.822841);
  EXPECT_DOUBLE_EQ(c.camera.cy, 237.756098);
  EXPECT_DOUBLE_EQ(c.camera.depth_units_per_metre, 5000);
  EXPECT_FALSE(c.camera.has_distortion());

  const eval::SequenceDetections d = eval::read_sequence_detections(dir + "/detections", s, 640, 480);
  ASSERT_TRUE(d.ok()) << d.reason;
  EXPECT_EQ(d.frames_with_file, 464u);
  EXPECT_EQ(d.files_unmatched, 0u);
  std::size_t first_person = s.frames.size();
  for (std::size_t i = 0; i < d.per_frame.size() && first_person == s.frames.size(); ++i)
    for (const Detection<float>& b : d.per_frame[i])
      if (b.class_id == 0) first_person = i;
  EXPECT_EQ(first_person, 57u);
}

}  // namespace
