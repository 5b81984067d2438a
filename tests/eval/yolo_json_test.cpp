// The per-frame detection JSON reader: the real files' fields, strict JSON with reasons naming file
// and position, bounds, locale independence; and on the real YOLOv8n streams of TUM fr3 (through
// DYNCULL_DATA_DIR) what the box tracker and the detection filter do with their one-frame dropouts.
#include "dyncull/eval/yolo_json.hpp"

#include "dyncull/culling/box_tracker.hpp"
#include "dyncull/culling/detections.hpp"

#include <gtest/gtest.h>

#include "support/real_data.hpp"
#include "support/special_files.hpp"

#include <clocale>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

namespace {

using namespace dyncull;
using namespace dyncull::eval;

template <class T>
class YoloJsonTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(YoloJsonTest, Scalars, );

// Shaped like the real files: extra keys (class_name, is_dynamic, mask_bbox_shape, image_path, ...).
const char* kFrame = R"({
  "frame_id": 12,
  "timestamp": 1341845688.561749,
  "image_path": "rgb/1341845688.561749.png",
  "detections": [
    {
      "class_id": 0,
      "class_name": "person",
      "confidence": 0.8825,
      "bbox": [199.3, 172.5, 536.2, 463.5],
      "is_dynamic": true,
      "mask_bbox_shape": [480, 640]
    },
    {"class_id": 62, "class_name": "tv \"LCD\" \u00e9", "confidence": 0.8356, "bbox": [283.2, 147.1, 417.1, 242.3],
     "is_dynamic": false, "extra": {"nested": [1, 2.5e-3, -0.0, null, [], {}]}}
  ],
  "num_detections": 2,
  "num_dynamic": 1
}
)";

TYPED_TEST(YoloJsonTest, ReadsTheFieldsOfARealFrame) {
  using T = TypeParam;
  const YoloJsonFrame<T> f = parse_yolo_json<T>(kFrame, "000012.json");
  ASSERT_TRUE(f.ok()) << f.reason;
  EXPECT_EQ(f.frame_id, 12);
  EXPECT_DOUBLE_EQ(f.timestamp, 1341845688.561749);
  ASSERT_EQ(f.detections.size(), 2u);
  EXPECT_EQ(f.detections[0].class_id, 0);
  EXPECT_EQ(f.detections[0].confidence, T(0.8825));
  EXPECT_EQ(f.detections[0].box.x0, T(199.3));
  EXPECT_EQ(f.detections[0].box.y0, T(172.5));
  EXPECT_EQ(f.detections[0].box.x1, T(536.2));
  EXPECT_EQ(f.detections[0].box.y1, T(463.5));
  EXPECT_EQ(f.detections[1].class_id, 62);
  EXPECT_EQ(f.detections[1].box.y1, T(242.3));

  const YoloJsonFrame<T> empty = parse_yolo_json<T>(R"({"detections":[],"timestamp":-1e-2,"frame_id":0})");
  ASSERT_TRUE(empty.ok()) << empty.reason;
  EXPECT_TRUE(empty.detections.empty());
  EXPECT_DOUBLE_EQ(empty.timestamp, -0.01);
}

TYPED_TEST(YoloJsonTest, MalformedInputIsAParseErrorNamingFileAndPosition) {
  using T = TypeParam;
  const std::string ok_head = R"({"frame_id": 0, "timestamp": 1.5, "detections": [)";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "one JSON object"},
      {"[]", "one JSON object"},
      {R"({"frame_id": 0, "timestamp": 1.5})", "missing \"detections\""},
      {R"({"timestamp": 1.5, "detections": []})", "missing \"frame_id\""},
      {R"({"frame_id": 0, "detections": []})", "missing \"timestamp\""},
      {R"({"frame_id": 0, "frame_id": 1, "timestamp": 1, "detections": []})", "duplicate key \"frame_id\""},
      {R"({"frame_id": 0, "timestamp": 1, "detections": [],})", "expected a string key"},
      {R"({"frame_id": 0.5, "timestamp": 1, "detections": []})", "frame_id must be an integer"},
      {R"({"frame_id": -3, "timestamp": 1, "detections": []})", "frame_id must be an integer"},
      {R"({"frame_id": 01, "timestamp": 1, "detections": []})", "leading zero"},
      {R"({"frame_id": 0, "timestamp": NaN, "detections": []})", "NaN or Infinity"},
      {R"({"frame_id": 0, "timestamp": -Infinity, "detections": []})", "NaN or Infinity"},
      {R"({"frame_id": 0, "timestamp": 1e400, "detections": []})", "out of range"},
      {R"({"frame_id": 0, "timestamp": 1., "detections": []})", "digits after '.'"},
      {R"({"frame_id": 0, "timestamp": "1", "detections": []})", "timestamp must be a number"},
      {R"({"frame_id": 0, "timestamp": 1, "detections": {}})", "\"detections\" must be an array"},
      {R"({"frame_id": 0, "timestamp": 1, "detections": []} x)", "after the JSON object"},
      {R"({"frame_id": 0, "timestamp": 1, "detections": [])", "expected ',' or '}'"},
      {R"({"frame_id": 0, "timestamp": 1, "detections": [], "a": "open)", "unterminated string"},
      {R"({"frame_id": 0, "timestamp": 1, "detections": [], "a": "\q"})", "bad escape"},
      {R"({"frame_id": 0, "timestamp": 1, "detections": [], "a": "\u12G4"})", "bad \\u escape"},
      {"{\"frame_id\": 0, \"timestamp\": 1, \"detections\": [], \"a\": \"tab\there\"}", "control character"},
      {R"({"frame_id": 0, "timestamp": 1, "detections": [], "a": tru})", "unexpected"},
      {ok_head + R"({"class_id": 0, "confidence": 0.5}]})", "detections[0] has no \"bbox\""},
      {ok_head + R"({"class_id": 0, "bbox": [1, 2, 3, 4]}]})", "detections[0] has no \"confidence\""},
      {ok_head + R"({"confidence": 0.5, "bbox": [1, 2, 3, 4]}]})", "detections[0] has no \"class_id\""},
      {ok_head + R"({"class_id": 1.5, "confidence": 0.5, "bbox": [1, 2, 3, 4]}]})", "class_id must be an integer"},
      {ok_head + R"({"class_id": -1, "confidence": 0.5, "bbox": [1, 2, 3, 4]}]})", "class_id must be an integer"},
      {ok_head + R"({"class_id": 0, "confidence": 0.5, "bbox": [1, 2, 3]}]})", "bbox must be an array of 4 numbers"},
      {ok_head + R"({"class_id": 0, "confidence": 0.5, "bbox": [1, 2, 3, 4, 5]}]})", "bbox must be an array of 4"},
      {ok_head + R"({"class_id": 0, "confidence": 0.5, "bbox": [1, 2, "3", 4]}]})", "bbox[2] must be a number"},
      {ok_head + R"({"class_id": 0, "confidence": 0.5, "bbox": [1, 2, 3, 4]} {}]})", "expected ',' or ']'"},
      {ok_head + R"(7])", "detections[0] must be an object"},
  };
  for (const auto& [text, why] : cases) {
    const YoloJsonFrame<T> f = parse_yolo_json<T>(text, "000007.json");
    EXPECT_EQ(f.status, Status::ParseError) << text;
    EXPECT_NE(f.reason.find("000007.json: byte "), std::string::npos) << f.reason;
    EXPECT_NE(f.reason.find(why), std::string::npos) << "input: " << text << "\nreason: " << f.reason;
    EXPECT_TRUE(f.detections.empty());
  }
}

TYPED_TEST(YoloJsonTest, ReasonGivesLineAndColumnOfTheFault) {
  using T = TypeParam;
  const std::string text = "{\n  \"frame_id\": 3,\n  \"timestamp\": 1x\n}";
  const YoloJsonFrame<T> f = parse_yolo_json<T>(text, "a.json");
  ASSERT_EQ(f.status, Status::ParseError);
  EXPECT_NE(f.reason.find("a.json: byte 35 (line 3, column 17)"), std::string::npos) << f.reason;
}

TYPED_TEST(YoloJsonTest, BadEscapeOfAControlByteIsShownNotCopied) {
  // A NUL or control byte after a backslash is named by its code: reasons stay printable text.
  for (char c : {'\0', '\x01', '\n', '\x7f', '\xff'}) {
    std::string text = "{\" \\";
    text += c;
    text += "\": 1}";
    const YoloJsonFrame<TypeParam> f = parse_yolo_json<TypeParam>(text, "esc.json");
    EXPECT_EQ(f.status, Status::ParseError);
    EXPECT_NE(f.reason.find("bad escape"), std::string::npos) << f.reason;
    for (char r : f.reason) EXPECT_TRUE(r >= 0x20 && r < 0x7f) << static_cast<int>(static_cast<unsigned char>(r));
  }
  const YoloJsonFrame<TypeParam> q = parse_yolo_json<TypeParam>("{\"\\q\": 1}", "esc.json");
  EXPECT_NE(q.reason.find("bad escape \\'q'"), std::string::npos) << q.reason;
}

TEST(YoloJson, FloatRangeIsCheckedOnlyForFloat) {
  const std::string text = R"({"frame_id": 0, "timestamp": 1, "detections": [{"class_id": 0, "confidence": 1e39, "bbox": [1, 2, 3, 4]}]})";
  const auto f = parse_yolo_json<float>(text, "f.json");
  EXPECT_EQ(f.status, Status::ParseError);
  EXPECT_NE(f.reason.find("out of range for float"), std::string::npos) << f.reason;
  EXPECT_TRUE(parse_yolo_json<double>(text).ok());
}

TYPED_TEST(YoloJsonTest, BoundsOnSizeDepthCountAndStringLength) {
  using T = TypeParam;
  YoloJsonOptions o;
  o.max_bytes = 100;
  const YoloJsonFrame<T> big = parse_yolo_json<T>(kFrame, "big.json", o);
  EXPECT_EQ(big.status, Status::ParseError);
  EXPECT_NE(big.reason.find("over the limit of 100"), std::string::npos) << big.reason;

  std::string deep = R"({"frame_id": 0, "timestamp": 1, "detections": [], "a": )";
  for (int k = 0; k < 100000; ++k) deep += '[';  // would overflow an unbounded recursion's stack
  const YoloJsonFrame<T> d = parse_yolo_json<T>(deep, "deep.json");
  EXPECT_EQ(d.status, Status::ParseError);
  EXPECT_NE(d.reason.find("nesting deeper than 32"), std::string::npos) << d.reason;

  YoloJsonOptions few;
  few.max_detections = 1;
  const YoloJsonFrame<T> many = parse_yolo_json<T>(kFrame, "many.json", few);
  EXPECT_EQ(many.status, Status::ParseError);
  EXPECT_NE(many.reason.find("more than 1 detections"), std::string::npos) << many.reason;

  YoloJsonOptions short_strings;
  short_strings.max_string_chars = 8;
  const YoloJsonFrame<T> s = parse_yolo_json<T>(kFrame, "s.json", short_strings);
  EXPECT_EQ(s.status, Status::ParseError);
  EXPECT_NE(s.reason.find("string longer than 8"), std::string::npos) << s.reason;
}

TYPED_TEST(YoloJsonTest, NumbersIgnoreTheCLocale) {
  using T = TypeParam;
  const char* locales[] = {"de_DE.UTF-8", "de_DE.utf8", "fr_FR.UTF-8", "C.UTF-8"};
  const std::string previous = std::setlocale(LC_NUMERIC, nullptr);
  bool switched = false;
  for (const char* l : locales) switched = switched || std::setlocale(LC_NUMERIC, l) != nullptr;
  const YoloJsonFrame<T> f = parse_yolo_json<T>(kFrame);
  std::setlocale(LC_NUMERIC, previous.c_str());
  ASSERT_TRUE(f.ok()) << f.reason;
  EXPECT_EQ(f.detections[0].confidence, T(0.8825));
  if (!switched) std::printf("note: no other locale installed; parsed in the C locale only\n");
}

TYPED_TEST(YoloJsonTest, ReadsADirectoryOfFramesAndChecksTheirNumbers) {
  using T = TypeParam;
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(::testing::TempDir()) / ("dyncull_yolo_json_" + std::string(text::scalar_name<T>()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  auto write = [&](const char* name, const std::string& text) { std::ofstream(dir / name, std::ios::binary) << text; };
  write("000000.json", R"({"frame_id": 0, "timestamp": 10.0, "detections": []})");
  write("000001.json", R"({"frame_id": 1, "timestamp": 10.5, "detections": [{"class_id": 0, "confidence": 0.9, "bbox": [1, 2, 30, 40]}]})");
  write("000003.json", R"({"frame_id": 3, "timestamp": 11.5, "detections": []})");  // after a gap: not read
  const YoloJsonSequence<T> seq = read_yolo_json_sequence<T>(dir.string());
  ASSERT_TRUE(seq.ok()) << seq.reason;
  ASSERT_EQ(seq.frames.size(), 2u);
  EXPECT_DOUBLE_EQ(seq.frames[1].timestamp, 10.5);
  ASSERT_EQ(seq.frames[1].detections.size(), 1u);
  EXPECT_EQ(seq.frames[1].detections[0].box.x1, T(30));

  write("000002.json", R"({"frame_id": 7, "timestamp": 11.0, "detections": []})");
  const YoloJsonSequence<T> wrong = read_yolo_json_sequence<T>(dir.string());
  EXPECT_EQ(wrong.status, Status::ParseError);
  EXPECT_NE(wrong.reason.find("000002.json: frame_id 7 differs from the file's number 2"), std::string::npos)
      << wrong.reason;
  EXPECT_EQ(wrong.frames.size(), 2u);

  const YoloJsonFrame<T> missing = read_yolo_json<T>((dir / "nope.json").string());
  EXPECT_EQ(missing.status, Status::IoError);
  EXPECT_NE(missing.reason.find("nope.json: no such file"), std::string::npos) << missing.reason;
  const YoloJsonFrame<T> directory = read_yolo_json<T>(dir.string());
  EXPECT_EQ(directory.status, Status::IoError) << directory.reason;
  const YoloJsonSequence<T> none = read_yolo_json_sequence<T>((dir / "empty").string());
  EXPECT_EQ(none.status, Status::IoError);
  fs::remove_all(dir);
}

// A directory has no size: tellg() gave -1 as 9223372036854775807 bytes "over the limit".
TEST(YoloJson, DirectoryIsNamedAsADirectoryNotAsASize) {
  test::ScratchDir dir;
  const YoloJsonFrame<float> f = read_yolo_json<float>(dir.str());
  EXPECT_EQ(f.status, Status::IoError);
  EXPECT_EQ(f.reason, dir.str() + ": is a directory, not a regular file");
  std::filesystem::create_directories(dir / "seq/000000.json");
  const YoloJsonSequence<float> s = read_yolo_json_sequence<float>(dir / "seq");
  EXPECT_EQ(s.status, Status::IoError);
  EXPECT_EQ(s.reason, dir / "seq/000000.json" + ": is a directory, not a regular file");
}

TEST(YoloJson, FifoAndDeviceAreRefusedPromptly) {
  test::ScratchDir dir;
  std::filesystem::create_directories(dir / "seq");
  const std::string fifo = dir / "seq/000000.json";
  if (!test::make_fifo(fifo)) return;
  YoloJsonFrame<double> f;
  EXPECT_TRUE(test::returns_promptly([&] { f = read_yolo_json<double>(fifo); }, fifo)) << "blocked on a FIFO";
  EXPECT_EQ(f.status, Status::IoError);
  EXPECT_EQ(f.reason, fifo + ": is a FIFO (named pipe), not a regular file");
  YoloJsonSequence<double> s;
  EXPECT_TRUE(test::returns_promptly([&] { s = read_yolo_json_sequence<double>(dir / "seq"); }, fifo))
      << "blocked on a FIFO";
  EXPECT_EQ(s.status, Status::IoError);
  EXPECT_EQ(s.reason, fifo + ": is a FIFO (named pipe), not a regular file");
  f = read_yolo_json<double>("/dev/zero");
  EXPECT_EQ(f.reason, "/dev/zero: is a character device, not a regular file");
}

TEST(YoloJson, IntegerFieldsTakeIntegralValuesAndNameTheirRangeAndWhy) {
  const YoloJsonFrame<float> big = parse_yolo_json<float>(R"({"frame_id": 1e15, "timestamp": 1, "detections": []})");
  ASSERT_TRUE(big.ok()) << big.reason;
  EXPECT_EQ(big.frame_id, 1000000000000000LL);
  const YoloJsonFrame<float> real = parse_yolo_json<float>(R"({"frame_id": 12.0, "timestamp": 1, "detections": []})");
  ASSERT_TRUE(real.ok()) << real.reason;
  EXPECT_EQ(real.frame_id, 12);
  const YoloJsonFrame<float> over = parse_yolo_json<float>(R"({"frame_id": 1e16, "timestamp": 1, "detections": []})", "f.json");
  EXPECT_EQ(over.status, Status::ParseError);
  EXPECT_EQ(over.reason,
            "f.json: byte 13 (line 1, column 14): frame_id must be an integer in [0, 1000000000000000] (a frame number "
            "up to 10^15, exact in the double a JSON number is read as), got '1e16'");
  const YoloJsonFrame<float> cls = parse_yolo_json<float>(
      R"({"frame_id": 0, "timestamp": 1, "detections": [{"class_id": 2e6, "confidence": 0.5, "bbox": [1, 2, 3, 4]}]})");
  EXPECT_NE(cls.reason.find("detections[0].class_id must be an integer in [0, 1000000] (a detector class index), got '2e6'"),
            std::string::npos)
      << cls.reason;
}

// ---------------------------------------------------------------------------------------------
// Real streams
// ---------------------------------------------------------------------------------------------

TEST(YoloJsonReal, ReadsEveryFrameOfTheFourRealStreams) {
  std::string why_not;
  const std::string root = dyncull::test::real_data_dir(&why_not);
  if (root.empty()) GTEST_SKIP() << why_not;
  const std::pair<const char*, std::size_t> streams[] = {
      {"fr3_walking_xyz", 859}, {"fr3_walking_static", 743}, {"fr3_sitting_static", 707}, {"fr3_sitting_xyz", 1261}};
  for (const auto& [name, frames] : streams) {
    const auto seq = read_yolo_json_sequence<float>(root + "/tum/" + name + "/yolov8n");
    ASSERT_TRUE(seq.ok()) << seq.reason;
    EXPECT_EQ(seq.frames.size(), frames) << name;
    std::size_t people = 0;
    for (std::size_t k = 1; k < seq.frames.size(); ++k) {
      EXPECT_GT(seq.frames[k].timestamp, seq.frames[k - 1].timestamp) << name << " frame " << k;
      for (const auto& d : seq.frames[k].detections) {
        people += d.class_id == 0 ? 1 : 0;
        EXPECT_GE(d.confidence, 0.45f);  // the run's confidence threshold
        EXPECT_LT(d.box.x0, d.box.x1);
        EXPECT_LE(d.box.x1, 640.5f);
        EXPECT_LE(d.box.y1, 480.5f);
      }
    }
    EXPECT_GT(people, frames / 2) << name;
  }
}

bool any_overlap(const std::vector<Detection<float>>& dets, const Box<float>& box, int cls, float min_iou) {
  for (const auto& d : dets)
    if (d.class_id == cls && iou(d.box, box) >= min_iou) return true;
  return false;
}

// A person seen in the frames before and after but not in between is a one-frame dropout; the
// tracker should bridge it with a carried box. A carried box with no real detection of its class
// overlapping it in the next frame either is carried falsely (the object left or the detector
// lost it for longer).
TEST(YoloJsonReal, BoxTrackerBridgesOneFramePersonDropoutsOnWalkingXyz) {
  std::string why_not;
  const std::string root = dyncull::test::real_data_dir(&why_not);
  if (root.empty()) GTEST_SKIP() << why_not;
  const auto seq = read_yolo_json_sequence<float>(root + "/tum/fr3_walking_xyz/yolov8n");
  ASSERT_TRUE(seq.ok()) << seq.reason;
  const int w = 640, h = 480;
  constexpr float kSame = 0.3f;  // IoU of the same person in consecutive frames (the tracker's min_iou)
  BoxTracker<float> tracker;
  const DetectionOptions<float> filter_options;
  std::vector<std::vector<Detection<float>>> raw, carried;
  std::size_t rejected = 0;
  for (const auto& f : seq.frames) {
    const DetectionsResult<float> kept = filter_detections(f.detections, w, h, filter_options);
    ASSERT_TRUE(kept.ok()) << kept.reason;
    rejected += kept.num_input - kept.num_kept;
    const BoxTrackerResult<float> t = tracker.update(kept.detections, w, h);
    ASSERT_TRUE(t.ok()) << t.reason;
    raw.push_back(f.detections);
    carried.emplace_back();
    for (std::size_t k = 0; k < t.boxes.size(); ++k)
      if (t.carried[k]) carried.back().push_back(t.boxes[k]);
  }
  std::size_t dropouts = 0, bridged = 0, carried_boxes = 0, carried_person = 0, false_carries = 0,
              false_person_carries = 0;
  for (std::size_t i = 1; i + 1 < raw.size(); ++i) {
    for (const auto& before : raw[i - 1]) {
      if (before.class_id != 0 || !any_overlap(raw[i + 1], before.box, 0, kSame) || any_overlap(raw[i], before.box, 0, kSame))
        continue;
      ++dropouts;
      bridged += any_overlap(carried[i], before.box, 0, kSame) ? 1 : 0;
    }
  }
  for (std::size_t i = 0; i < carried.size(); ++i) {
    for (const auto& c : carried[i]) {
      ++carried_boxes;
      carried_person += c.class_id == 0 ? 1 : 0;
      const bool next_has_it = i + 1 < raw.size() && any_overlap(raw[i + 1], c.box, c.class_id, kSame);
      false_carries += next_has_it ? 0 : 1;
      false_person_carries += !next_has_it && c.class_id == 0 ? 1 : 0;
    }
  }
  std::printf("walking_xyz: %zu frames, %zu boxes rejected by the filter; %zu one-frame person dropouts, %zu bridged; "
              "%zu carried boxes (%zu person), %zu carried falsely (%zu person)\n",
              raw.size(), rejected, dropouts, bridged, carried_boxes, carried_person, false_carries, false_person_carries);
  // The real stream has ~1.4 % one-frame person dropouts (12 of 859 frames with the definition above).
  EXPECT_GE(dropouts, 8u);
  EXPECT_LE(dropouts, 20u);
  // Every one-frame dropout of a person moving less than the IoU gate allows is bridged; allow one
  // whose person moved too far to be associated.
  EXPECT_GE(bridged + 1, dropouts);
  // A person box carried falsely comes from a person leaving the view or lost for two frames or
  // more (at most the 2 frames the tracker carries after each loss): 28 on this stream, under 3 %
  // of its 1048 person boxes.
  EXPECT_LT(false_person_carries, 50u);
  // The desk objects (keyboard, mouse, bottle) flicker: detected in about half of the frames, so
  // most of their carried boxes find no detection in the next frame either. They are static in the
  // sequence, so the carried box is still on the object; the count says how often that happens.
  EXPECT_GT(false_carries - false_person_carries, 300u);
}

}  // namespace
