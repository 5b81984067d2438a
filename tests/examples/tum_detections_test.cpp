// The dynamic_vo demo's YOLO detections for a TUM directory (examples/vo/sources.hpp): one file of
// "<rgb stem> class cx cy w h [conf]" lines or a directory of <rgb stem>.txt files. A malformed line
// fails the open with "file:line: reason" for the first few and the count.
#include <gtest/gtest.h>

#ifdef DYNCULL_HAS_OPENCV

#include "../../examples/vo/sources.hpp"
#include "support/special_files.hpp"

#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace {

using namespace dyncull;

class TumDetections : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("dyncull_tum_detections_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_ / "rgb");
    std::filesystem::create_directories(dir_ / "depth");
    std::filesystem::create_directories(dir_ / "labels");
    const cv::Mat rgb(48, 64, CV_8UC3, cv::Scalar(10, 20, 30));
    const cv::Mat depth(48, 64, CV_16UC1, cv::Scalar(5000));
    ASSERT_TRUE(cv::imwrite((dir_ / "rgb/1.000000.png").string(), rgb));
    ASSERT_TRUE(cv::imwrite((dir_ / "rgb/2.000000.png").string(), rgb));
    ASSERT_TRUE(cv::imwrite((dir_ / "depth/1.000000.png").string(), depth));
    ASSERT_TRUE(cv::imwrite((dir_ / "depth/2.000000.png").string(), depth));
    std::ofstream(dir_ / "rgb.txt") << "1.000000 rgb/1.000000.png\n2.000000 rgb/2.000000.png\n";
    std::ofstream(dir_ / "depth.txt") << "1.000000 depth/1.000000.png\n2.000000 depth/2.000000.png\n";
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  bool open(const std::string& detections, std::string* error) {
    return source_.open(dir_.string(), detections, PinholeCamera<double>{50, 50, 31.5, 23.5, 64, 48}, error);
  }

  std::filesystem::path dir_;
  vo::TumSource source_;
};

TEST_F(TumDetections, MalformedLinesInOneFileFailWithFileLineAndCount) {
  const std::string file = (dir_ / "dets.txt").string();
  std::ofstream(file) << "# stem class cx cy w h conf\n"
                         "1.000000 0 0.5 0.5 0.25 0.5 0.9\n"
                         "1.000000 0 0,5 0,5 0,25 0,5\n"  // line 3
                         "2.000000\n"                     // line 4: key only
                         "2.000000 0 0.5 0.5 0.25 0.5 0.9 7\n";  // line 5
  std::string error;
  EXPECT_FALSE(open(file, &error));
  EXPECT_NE(error.find("3 malformed detection lines"), std::string::npos) << error;
  EXPECT_NE(error.find(file + ":3: cx '0,5' is not a number"), std::string::npos) << error;
  EXPECT_NE(error.find(file + ":4: "), std::string::npos) << error;
  EXPECT_NE(error.find(file + ":5: expected 5 or 6 fields"), std::string::npos) << error;
  EXPECT_EQ(source_.bad_detection_lines(), 3u);
}

TEST_F(TumDetections, MalformedLineInADirectoryFileFailsAtOpen) {
  std::ofstream(dir_ / "labels/1.000000.txt") << "0 0.5 0.5 0.25 0.5 0.9\n";
  std::ofstream(dir_ / "labels/2.000000.txt") << "0 0.5 0.5 0.25 0.5 0.9\n\n56 x 0.5 0.1 0.1\n";
  std::string error;
  EXPECT_FALSE(open((dir_ / "labels").string(), &error));
  EXPECT_NE(error.find("1 malformed detection line"), std::string::npos) << error;
  EXPECT_NE(error.find((dir_ / "labels/2.000000.txt").string() + ":3: cx 'x' is not a number"), std::string::npos)
      << error;
}

TEST_F(TumDetections, CleanFilesLoadPerFrame) {
  std::ofstream(dir_ / "labels/1.000000.txt") << "0 0.5 0.5 0.25 0.5 0.9\n";  // no file for frame 2
  std::string error;
  ASSERT_TRUE(open((dir_ / "labels").string(), &error)) << error;
  EXPECT_EQ(source_.bad_detection_lines(), 0u);
  vo::SequenceFrame f;
  ASSERT_TRUE(source_.load(0, &f, &error)) << error;
  ASSERT_EQ(f.detections.size(), 1u);
  EXPECT_NEAR(f.detections[0].box.centre().x(), 32.0, 1.0);
  ASSERT_TRUE(source_.load(1, &f, &error)) << error;
  EXPECT_TRUE(f.detections.empty());

  const std::string file = (dir_ / "dets.txt").string();
  std::ofstream(file) << "2.000000 0 0.5 0.5 0.25 0.5 0.9\n2.000000 1 0.25 0.25 0.1 0.1\n";
  vo::TumSource single;
  ASSERT_TRUE(single.open(dir_.string(), file, PinholeCamera<double>{50, 50, 31.5, 23.5, 64, 48}, &error)) << error;
  ASSERT_TRUE(single.load(1, &f, &error)) << error;
  EXPECT_EQ(f.detections.size(), 2u);
}

TEST_F(TumDetections, MissingOrDirectoryPathsAreErrors) {
  std::string error;
  EXPECT_FALSE(open((dir_ / "nope.txt").string(), &error));
  EXPECT_NE(error.find("nope.txt"), std::string::npos) << error;
  std::filesystem::create_directories(dir_ / "labels/1.000000.txt");  // a directory where a label file belongs
  EXPECT_FALSE(open((dir_ / "labels").string(), &error));
  EXPECT_NE(error.find("1.000000.txt"), std::string::npos) << error;
}

TEST_F(TumDetections, ImageListsAreCheckedLineByLine) {
  std::string error;
  std::filesystem::remove(dir_ / "rgb.txt");
  std::filesystem::create_directories(dir_ / "rgb.txt");
  EXPECT_FALSE(open("", &error));
  EXPECT_NE(error.find("rgb.txt: is a directory"), std::string::npos) << error;
  std::filesystem::remove_all(dir_ / "rgb.txt");
  std::ofstream(dir_ / "rgb.txt") << "# color\n1.000000 rgb/1.000000.png\n2,000000 rgb/2.000000.png\n";
  EXPECT_FALSE(open("", &error));
  EXPECT_NE(error.find("rgb.txt:3: timestamp '2,000000' is not a number"), std::string::npos) << error;
  std::ofstream(dir_ / "rgb.txt") << "1.000000 rgb/1.000000.png\r\n2.000000\n";
  EXPECT_FALSE(open("", &error));
  EXPECT_NE(error.find("rgb.txt:2: expected 'timestamp filename'"), std::string::npos) << error;
  std::ofstream(dir_ / "rgb.txt") << "1.000000 rgb/1.000000.png\r\n";  // CRLF: the file name has no '\r'
  ASSERT_TRUE(open("", &error)) << error;
  vo::SequenceFrame f;
  EXPECT_TRUE(source_.load(0, &f, &error)) << error;
}

// A FIFO blocks a reader that opens it until a writer comes; /dev/zero never ends. Both are refused
// by their kind before any read, naming the path.
TEST_F(TumDetections, FifosAndDevicesAreRefusedPromptly) {
  const std::string fifo = (dir_ / "dets.txt").string();
  if (!test::make_fifo(fifo)) return;
  std::string error;
  bool opened = true;
  EXPECT_TRUE(test::returns_promptly([&] { opened = open(fifo, &error); }, fifo)) << "blocked on --detections";
  EXPECT_FALSE(opened);
  EXPECT_EQ(error, "detections " + fifo + ": is a FIFO (named pipe), not a regular file");
  EXPECT_FALSE(open("/dev/zero", &error));
  EXPECT_EQ(error, "detections /dev/zero: is a character device, not a regular file");

  std::filesystem::remove(dir_ / "rgb.txt");
  const std::string rgb = (dir_ / "rgb.txt").string();
  if (!test::make_fifo(rgb)) return;
  EXPECT_TRUE(test::returns_promptly([&] { opened = open("", &error); }, rgb)) << "blocked on rgb.txt";
  EXPECT_FALSE(opened);
  EXPECT_EQ(error, rgb + ": is a FIFO (named pipe), not a regular file");

  // An image the list names: imread would block on it.
  std::filesystem::remove(dir_ / "rgb.txt");
  std::ofstream(dir_ / "rgb.txt") << "1.000000 rgb/pipe.png\n";
  const std::string image = (dir_ / "rgb/pipe.png").string();
  if (!test::make_fifo(image)) return;
  ASSERT_TRUE(open("", &error)) << error;
  vo::SequenceFrame f;
  bool loaded = true;
  EXPECT_TRUE(test::returns_promptly([&] { loaded = source_.load(0, &f, &error); }, image)) << "blocked on an image";
  EXPECT_FALSE(loaded);
  EXPECT_NE(error.find("rgb/pipe.png: is a FIFO"), std::string::npos) << error;
}

// A box that parses but the filter drops (1e400 is inf, as in Python) is not dropped unseen: open()
// succeeds and its note gives the count by reason and file:line.
TEST_F(TumDetections, BoxesTheFilterDropsAreCountedAndNamed) {
  const std::string file = (dir_ / "dets.txt").string();
  std::ofstream(file) << "1.000000 0 0.5 0.5 0.25 0.5 0.9\n"
                         "1.000000 0 1e400 0.5 0.25 0.5 0.9\n"
                         "2.000000 0 0.5 0.5 0.25 0.5 0.01\n";
  std::string error;
  ASSERT_TRUE(open(file, &error)) << error;
  EXPECT_EQ(source_.dropped_boxes(), 2u);
  EXPECT_EQ(source_.detection_note(),
            "detections " + file + ": 2 of 3 boxes dropped by the detection filter (1 non-finite coordinates, "
            "1 confidence below the class threshold)\n  " + file + ":2: non-finite coordinates\n  " + file +
            ":3: confidence below the class threshold");
  std::ofstream(file) << "1.000000 0 0.5 0.5 0.25 0.5 0.9\n";
  ASSERT_TRUE(open(file, &error)) << error;
  EXPECT_EQ(source_.dropped_boxes(), 0u);
  EXPECT_EQ(source_.detection_note(), "");
}

}  // namespace

#else
TEST(TumDetections, NeedsOpenCv) { GTEST_SKIP() << "built without OpenCV"; }
#endif
