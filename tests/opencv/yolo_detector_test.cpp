// The YOLO detector on OpenCV DNN: the real Yolo-Fastest-1.1-XL network reproduces the stored boxes of
// the Bonn crowd frames (DYNCULL_DATA_DIR), the YOLOv5 / YOLOv8 / Darknet output decoding on hand-built
// tensors, and bad models, options and frames giving a status and a reason instead of an exception.
#include "dyncull/eval/yolo_json.hpp"
#include "dyncull/opencv/yolo_detector.hpp"

#include "support/counting_allocator.hpp"
#include "support/real_data.hpp"
#include "support/special_files.hpp"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace {

using namespace dyncull;
using cv_adapter::YoloDetector;
using cv_adapter::YoloDetectorOptions;
using cv_adapter::YoloDetectorResult;
using cv_adapter::YoloHead;
using cv_adapter::YoloInputGeometry;

namespace fs = std::filesystem;

// ------------------------------------------------------------------------------------------------
// Helpers
// ------------------------------------------------------------------------------------------------

/// A scratch directory removed at the end of the test.
struct TempDir {
  fs::path path;
  TempDir() {
    path = fs::temp_directory_path() /
           ("dyncull_yolo_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::string file(const std::string& name, const std::string& text) const {
    const std::string p = (path / name).string();
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }
};

/// Darknet weights: header (version 0.2.0, 64-bit "seen") then the floats in layer order.
std::string darknet_weights(const std::vector<float>& values) {
  std::string bytes;
  const std::int32_t version[3] = {0, 2, 0};
  const std::uint64_t seen = 0;
  bytes.append(reinterpret_cast<const char*>(version), sizeof version);
  bytes.append(reinterpret_cast<const char*>(&seen), sizeof seen);
  bytes.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(float));
  return bytes;
}

/// A 1x1 convolution over a 32x32 RGB input, filters outputs, linear: biases then weights.
std::string one_conv_cfg(int filters) {
  return "[net]\nwidth=32\nheight=32\nchannels=3\n\n[convolutional]\nfilters=" + std::to_string(filters) +
         "\nsize=1\nstride=1\npad=0\nactivation=linear\n";
}

/// A tiny but real Darknet YOLO net: one 1x1 convolution into a [yolo] head of 3 anchors and 2 classes.
/// With zero weights every logit is its bias; the biases make every cell predict class 1 at about 0.5.
struct TinyYoloNet {
  std::string cfg, weights;
  explicit TinyYoloNet(const TempDir& dir) {
    const int classes = 2, filters = 3 * (5 + classes);
    cfg = dir.file("tiny.cfg", one_conv_cfg(filters) +
                                   "\n[yolo]\nmask=0,1,2\nanchors=10,14,23,27,37,58\nclasses=2\nnum=3\n");
    std::vector<float> values(static_cast<std::size_t>(filters) * 4, 0.f);  // biases, then 3 weights each
    for (int a = 0; a < 3; ++a) {
      values[static_cast<std::size_t>(a * 7 + 4)] = 3.f;   // objectness logit: sigmoid 0.95
      values[static_cast<std::size_t>(a * 7 + 5)] = -3.f;  // class 0
      values[static_cast<std::size_t>(a * 7 + 6)] = 0.f;   // class 1: sigmoid 0.5
    }
    weights = dir.file("tiny.weights", darknet_weights(values));
  }
  YoloDetectorOptions options() const {
    YoloDetectorOptions o;
    o.model = cfg;
    o.weights = weights;
    o.input_width = o.input_height = 32;
    o.num_classes = 2;
    return o;
  }
};

// A minimal ONNX writer (protobuf wire format) for tiny YOLOv5 / YOLOv8-shaped networks: a 1x1 Conv on a
// 1x3x32x32 "images" input whose zero weights make every output its bias, reshaped to the export's layout.
namespace onnx {
std::string varint(std::uint64_t v) {
  std::string out;
  do {
    const std::uint8_t byte = static_cast<std::uint8_t>(v & 0x7f);
    v >>= 7;
    out.push_back(static_cast<char>(byte | (v ? 0x80 : 0)));
  } while (v);
  return out;
}
std::string field_varint(int field, std::int64_t v) {
  return varint(static_cast<std::uint64_t>(field) << 3) + varint(static_cast<std::uint64_t>(v));
}
std::string field_bytes(int field, const std::string& bytes) {
  return varint((static_cast<std::uint64_t>(field) << 3) | 2) + varint(bytes.size()) + bytes;
}
template <class T>
std::string raw(const std::vector<T>& values) {
  return std::string(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}
std::string tensor(const std::string& name, const std::vector<std::int64_t>& dims, int data_type, const std::string& raw_data) {
  std::string t;
  for (const std::int64_t d : dims) t += field_varint(1, d);
  return t + field_varint(2, data_type) + field_bytes(8, name) + field_bytes(9, raw_data);
}
std::string ints_attribute(const std::string& name, const std::vector<std::int64_t>& values) {
  std::string a = field_bytes(1, name);
  for (const std::int64_t v : values) a += field_varint(8, v);
  return a + field_varint(20, 7);  // AttributeProto.INTS
}
std::string node(const std::string& op, const std::vector<std::string>& inputs, const std::string& output,
                 const std::vector<std::string>& attributes = {}) {
  std::string n;
  for (const std::string& i : inputs) n += field_bytes(1, i);
  n += field_bytes(2, output) + field_bytes(3, output + "_node") + field_bytes(4, op);
  for (const std::string& a : attributes) n += field_bytes(5, a);
  return n;
}
std::string value_info(const std::string& name, const std::vector<std::int64_t>& dims) {
  std::string shape;
  for (const std::int64_t d : dims) shape += field_bytes(1, field_varint(1, d));
  const std::string tensor_type = field_varint(1, 1) + field_bytes(2, shape);  // FLOAT
  return field_bytes(1, name) + field_bytes(2, field_bytes(1, tensor_type));
}
/// `channels` conv outputs with these biases, reshaped to [1, channels, 1024]; transposed to
/// [1, 1024, channels] when `transpose` (YOLOv5's layout); `reshape` false leaves the 4-D conv map.
/// `raw_map_output`: the conv map is a graph output too (as older YOLOv5 exports keep their raw maps).
std::string yolo_model(const std::vector<float>& biases, bool transpose, bool reshape = true, bool raw_map_output = false) {
  const std::int64_t channels = static_cast<std::int64_t>(biases.size());
  std::string graph;
  graph += field_bytes(1, node("Conv", {"images", "W", "B"}, reshape ? "conv" : "output0",
                               {ints_attribute("kernel_shape", {1, 1}), ints_attribute("strides", {1, 1}),
                                ints_attribute("pads", {0, 0, 0, 0})}));
  if (reshape) graph += field_bytes(1, node("Reshape", {"conv", "shape"}, transpose ? "flat" : "output0"));
  if (reshape && transpose) graph += field_bytes(1, node("Transpose", {"flat"}, "output0", {ints_attribute("perm", {0, 2, 1})}));
  graph += field_bytes(2, "tiny_yolo");
  graph += field_bytes(5, tensor("W", {channels, 3, 1, 1}, 1, raw(std::vector<float>(static_cast<std::size_t>(channels) * 3, 0.f))));
  graph += field_bytes(5, tensor("B", {channels}, 1, raw(biases)));
  graph += field_bytes(5, tensor("shape", {3}, 7, raw(std::vector<std::int64_t>{1, channels, -1})));
  graph += field_bytes(11, value_info("images", {1, 3, 32, 32}));
  const std::vector<std::int64_t> out = !reshape ? std::vector<std::int64_t>{1, channels, 32, 32}
                                                 : (transpose ? std::vector<std::int64_t>{1, 1024, channels}
                                                              : std::vector<std::int64_t>{1, channels, 1024});
  if (raw_map_output) graph += field_bytes(12, value_info("conv", {1, channels, 32, 32}));
  graph += field_bytes(12, value_info("output0", out));
  return field_varint(1, 7) + field_bytes(7, graph) + field_bytes(8, field_bytes(1, "") + field_varint(2, 11));
}
}  // namespace onnx

/// One hand-built anchor: input-pixel box, objectness (YOLOv5 only) and class scores.
struct Anchor {
  float cx, cy, w, h, objectness;
  std::vector<std::pair<int, float>> scores;  // class id, score; others 0
};

cv::Mat yolov5_output(const std::vector<Anchor>& anchors, int classes) {
  const int shape[3] = {1, static_cast<int>(anchors.size()), 5 + classes};
  cv::Mat m(3, shape, CV_32F, cv::Scalar(0));
  for (std::size_t a = 0; a < anchors.size(); ++a) {
    float* p = m.ptr<float>() + a * static_cast<std::size_t>(5 + classes);
    p[0] = anchors[a].cx;
    p[1] = anchors[a].cy;
    p[2] = anchors[a].w;
    p[3] = anchors[a].h;
    p[4] = anchors[a].objectness;
    for (const auto& s : anchors[a].scores) p[5 + s.first] = s.second;
  }
  return m;
}

/// YOLOv8's transposed layout: field-major [1, 4 + C, N], no objectness.
cv::Mat yolov8_output(const std::vector<Anchor>& anchors, int classes) {
  const int n = static_cast<int>(anchors.size());
  const int shape[3] = {1, 4 + classes, n};
  cv::Mat m(3, shape, CV_32F, cv::Scalar(0));
  float* p = m.ptr<float>();
  for (int a = 0; a < n; ++a) {
    p[0 * n + a] = anchors[static_cast<std::size_t>(a)].cx;
    p[1 * n + a] = anchors[static_cast<std::size_t>(a)].cy;
    p[2 * n + a] = anchors[static_cast<std::size_t>(a)].w;
    p[3 * n + a] = anchors[static_cast<std::size_t>(a)].h;
    for (const auto& s : anchors[static_cast<std::size_t>(a)].scores) p[(4 + s.first) * n + a] = s.second;
  }
  return m;
}

const Detection<float>* find_class(const YoloDetectorResult& r, int class_id) {
  for (const auto& d : r.detections)
    if (d.class_id == class_id) return &d;
  return nullptr;
}

void expect_box(const Detection<float>& d, float x0, float y0, float x1, float y1) {
  EXPECT_NEAR(d.box.x0, x0, 1e-3f);
  EXPECT_NEAR(d.box.y0, y0, 1e-3f);
  EXPECT_NEAR(d.box.x1, x1, 1e-3f);
  EXPECT_NEAR(d.box.y1, y1, 1e-3f);
}

// A person (two overlapping candidates) and a chair overlapping it, a low-objectness candidate and one
// off the image. 416 x 416 input, 640 x 480 frame, plain resize: x scales by 640/416, y by 480/416.
std::vector<Anchor> person_and_chair() {
  return {
      {208, 208, 104, 208, 0.9f, {{0, 0.8f}}},           // person 0.72: x 240..400, y 120..360
      {212, 210, 104, 208, 0.9f, {{0, 0.7f}}},           // person 0.63, IoU ~0.95 with the first: suppressed
      {230, 230, 80, 120, 0.5f, {{56, 0.6f}, {0, 0.1f}}},  // chair 0.30 on the person: kept (NMS per class)
      {100, 100, 50, 50, 0.4f, {{2, 0.5f}}},             // car 0.20 < 0.25: objectness x class drops it
      {500, 500, 40, 40, 0.9f, {{3, 0.9f}}},             // entirely off the image: empty after clipping
      {410, 410, 40, 40, 0.9f, {{4, 0.9f}}},             // over the bottom-right corner: clipped
  };
}

// ------------------------------------------------------------------------------------------------
// Output decoding (no network)
// ------------------------------------------------------------------------------------------------

void check_person_and_chair(const YoloDetectorResult& r, bool v8) {
  ASSERT_TRUE(r.ok()) << r.reason;
  const float sx = 640.f / 416.f, sy = 480.f / 416.f;
  const Detection<float>* person = find_class(r, 0);
  ASSERT_NE(person, nullptr);
  EXPECT_NEAR(person->confidence, v8 ? 0.8f : 0.72f, 1e-6f);
  expect_box(*person, 156 * sx, 104 * sy, 260 * sx, 312 * sy);
  const Detection<float>* chair = find_class(r, 56);
  ASSERT_NE(chair, nullptr) << "a chair overlapping a person survives: NMS is per class";
  EXPECT_NEAR(chair->confidence, v8 ? 0.6f : 0.3f, 1e-6f);
  const Detection<float>* clipped = find_class(r, 4);
  ASSERT_NE(clipped, nullptr);
  expect_box(*clipped, 390 * sx, 390 * sy, 639.f, 479.f);
  EXPECT_EQ(find_class(r, 3), nullptr);
  EXPECT_EQ(r.num_dropped_empty, 1u);
  if (v8) {
    // No objectness: the car's class score 0.5 is its confidence.
    ASSERT_NE(find_class(r, 2), nullptr);
    EXPECT_EQ(r.detections.size(), 4u);
  } else {
    EXPECT_EQ(find_class(r, 2), nullptr) << "objectness 0.4 x class 0.5 = 0.2 is below 0.25";
    EXPECT_EQ(r.detections.size(), 3u);
  }
  EXPECT_EQ(std::count_if(r.detections.begin(), r.detections.end(), [](const auto& d) { return d.class_id == 0; }), 1)
      << "the second person candidate is suppressed";
}

TEST(YoloDecode, Yolov5ConfidenceIsObjectnessTimesClassScoreWithNmsPerClassAndClipping) {
  YoloDetectorOptions o;
  cv_adapter::YoloDecodeScratch scratch;
  YoloDetectorResult r;
  cv_adapter::decode_yolo_outputs({yolov5_output(person_and_chair(), 80)}, YoloHead::YoloV5,
                                  YoloInputGeometry::plain(640, 480, 416, 416), o, &scratch, &r);
  check_person_and_chair(r, false);
  EXPECT_EQ(r.num_candidates, 5u);  // the car is below the threshold before NMS
}

TEST(YoloDecode, Yolov8TransposedLayoutUsesTheClassScoreAsConfidence) {
  YoloDetectorOptions o;
  cv_adapter::YoloDecodeScratch scratch;
  YoloDetectorResult r;
  cv_adapter::decode_yolo_outputs({yolov8_output(person_and_chair(), 80)}, YoloHead::YoloV8,
                                  YoloInputGeometry::plain(640, 480, 416, 416), o, &scratch, &r);
  check_person_and_chair(r, true);
}

TEST(YoloDecode, DarknetRowsAreNormalisedWithScoresAlreadyTimesObjectness) {
  // OpenCV's region layer: cx, cy, w, h in [0, 1] of the input, objectness, class x objectness.
  cv::Mat out(2, 85, CV_32F, cv::Scalar(0));
  const float row0[] = {0.5f, 0.5f, 0.25f, 0.5f, 0.9f};
  std::copy(row0, row0 + 5, out.ptr<float>(0));
  out.at<float>(0, 5 + 0) = 0.72f;
  const float row1[] = {0.5f, 0.5f, 0.25f, 0.5f, 0.3f};
  std::copy(row1, row1 + 5, out.ptr<float>(1));
  out.at<float>(1, 5 + 7) = 0.24f;  // below the threshold
  YoloDetectorOptions o;
  cv_adapter::YoloDecodeScratch scratch;
  YoloDetectorResult r;
  cv_adapter::decode_yolo_outputs({out}, YoloHead::Darknet, YoloInputGeometry::plain(640, 480, 416, 416), o, &scratch, &r);
  ASSERT_TRUE(r.ok()) << r.reason;
  ASSERT_EQ(r.detections.size(), 1u);
  EXPECT_EQ(r.detections[0].class_id, 0);
  EXPECT_NEAR(r.detections[0].confidence, 0.72f, 1e-6f) << "not multiplied by the objectness a second time";
  expect_box(r.detections[0], 240.f, 120.f, 400.f, 360.f);  // the normalised box times 640 x 480
}

TEST(YoloDecode, ReapplyObjectnessMultipliesDarknetScoresByTheObjectnessAgain) {
  cv::Mat out(1, 85, CV_32F, cv::Scalar(0));
  const float row[] = {0.5f, 0.5f, 0.25f, 0.5f, 0.9f};
  std::copy(row, row + 5, out.ptr<float>(0));
  out.at<float>(0, 5 + 0) = 0.72f;
  YoloDetectorOptions o;
  o.reapply_objectness = true;
  cv_adapter::YoloDecodeScratch scratch;
  YoloDetectorResult r;
  cv_adapter::decode_yolo_outputs({out}, YoloHead::Darknet, YoloInputGeometry::plain(640, 480, 416, 416), o, &scratch, &r);
  ASSERT_EQ(r.detections.size(), 1u);
  EXPECT_NEAR(r.detections[0].confidence, 0.648f, 1e-6f);
  out.at<float>(0, 4) = 0.3f;  // 0.3 x 0.72 = 0.216 < 0.25
  cv_adapter::decode_yolo_outputs({out}, YoloHead::Darknet, YoloInputGeometry::plain(640, 480, 416, 416), o, &scratch, &r);
  EXPECT_TRUE(r.detections.empty());
}

TEST(YoloDecode, LetterboxGeometryMapsInputPixelsBackToTheFrame) {
  const YoloInputGeometry g = YoloInputGeometry::letterbox(640, 480, 416, 416);
  EXPECT_DOUBLE_EQ(g.offset_x, 0);
  EXPECT_DOUBLE_EQ(g.offset_y, 52);  // 640 x 480 -> 416 x 312, centred
  EXPECT_EQ(g.scaled_width(), 416);
  EXPECT_EQ(g.scaled_height(), 312);
  YoloDetectorOptions o;
  cv_adapter::YoloDecodeScratch scratch;
  YoloDetectorResult r;
  cv_adapter::decode_yolo_outputs({yolov5_output({{208, 208, 104, 104, 1.f, {{0, 0.9f}}}}, 80)}, YoloHead::YoloV5, g, o,
                                  &scratch, &r);
  ASSERT_TRUE(r.ok()) << r.reason;
  ASSERT_EQ(r.detections.size(), 1u);
  expect_box(r.detections[0], 240.f, 160.f, 400.f, 320.f);  // (156 - 52) / 0.65 = 160
}

TEST(YoloDecode, OutputThatIsNotTheNamedHeadIsInvalidInputNamingTheShape) {
  YoloDetectorOptions o;
  cv_adapter::YoloDecodeScratch scratch;
  YoloDetectorResult r;
  const auto geometry = YoloInputGeometry::plain(640, 480, 416, 416);
  cv_adapter::decode_yolo_outputs({yolov8_output(person_and_chair(), 80)}, YoloHead::YoloV5, geometry, o, &scratch, &r);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.reason.find("[1, 84, 6]"), std::string::npos) << r.reason;
  EXPECT_TRUE(r.detections.empty());

  const int four_d[4] = {1, 3, 8, 8};
  cv_adapter::decode_yolo_outputs({cv::Mat(4, four_d, CV_32F, cv::Scalar(0))}, YoloHead::Darknet, geometry, o, &scratch, &r);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.reason.find("not a darknet head"), std::string::npos) << r.reason;

  cv_adapter::decode_yolo_outputs({cv::Mat(2, 85, CV_64F, cv::Scalar(0))}, YoloHead::Darknet, geometry, o, &scratch, &r);
  EXPECT_EQ(r.status, Status::InvalidInput) << "a CV_64F output is not read as floats";

  cv_adapter::decode_yolo_outputs({}, YoloHead::Darknet, geometry, o, &scratch, &r);
  EXPECT_EQ(r.status, Status::InvalidInput);

  cv_adapter::decode_yolo_outputs({yolov5_output(person_and_chair(), 80)}, YoloHead::YoloV5,
                                  YoloInputGeometry::plain(0, 480, 416, 416), o, &scratch, &r);
  EXPECT_EQ(r.status, Status::InvalidInput) << "a zero-width frame";

  o.nms_iou = 1.5f;
  cv_adapter::decode_yolo_outputs({yolov5_output(person_and_chair(), 80)}, YoloHead::YoloV5, geometry, o, &scratch, &r);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.reason.find("nms_iou"), std::string::npos) << r.reason;
}

// The decoder's own buffers are reused: a frame without candidates allocates nothing after warm-up, and
// one with candidates allocates only inside cv::dnn::NMSBoxes (a few times per class present).
TEST(YoloDecode, ReusesItsBuffersAfterWarmUp) {
  const std::vector<cv::Mat> busy = {yolov5_output(person_and_chair(), 80)};
  std::vector<Anchor> faint = person_and_chair();
  for (Anchor& a : faint) a.objectness = 0.01f;
  const std::vector<cv::Mat> quiet = {yolov5_output(faint, 80)};
  const auto geometry = YoloInputGeometry::plain(640, 480, 416, 416);
  YoloDetectorOptions o;
  cv_adapter::YoloDecodeScratch scratch;
  YoloDetectorResult r;
  cv_adapter::decode_yolo_outputs(busy, YoloHead::YoloV5, geometry, o, &scratch, &r);  // warm-up
  ASSERT_EQ(r.detections.size(), 3u);

  std::size_t before = test::allocations();
  cv_adapter::decode_yolo_outputs(quiet, YoloHead::YoloV5, geometry, o, &scratch, &r);
  EXPECT_EQ(test::allocations() - before, 0u);
  EXPECT_TRUE(r.detections.empty());

  before = test::allocations();
  cv_adapter::decode_yolo_outputs(busy, YoloHead::YoloV5, geometry, o, &scratch, &r);
  const std::size_t decode = test::allocations() - before;
  EXPECT_EQ(r.detections.size(), 3u);

  // NMSBoxes alone on the same class sizes (person 2 candidates; chair, class 3, class 4 one each).
  std::vector<cv::Rect2d> boxes;
  std::vector<float> scores;
  std::vector<int> kept;
  boxes.reserve(2), scores.reserve(2), kept.reserve(2);
  before = test::allocations();
  for (const std::size_t n : {2, 1, 1, 1}) {
    boxes.assign(n, cv::Rect2d(0, 0, 10, 10));
    scores.assign(n, 0.5f);
    cv::dnn::NMSBoxes(boxes, scores, 0.f, 0.45f, kept);
  }
  const std::size_t nms = test::allocations() - before;
  EXPECT_EQ(decode, nms) << "allocations beyond NMSBoxes' own";
  RecordProperty("allocations_per_frame_4_classes", static_cast<int>(decode));
}

TEST(YoloDecode, NonFiniteCandidatesAreSkipped) {
  std::vector<Anchor> anchors = {{NAN, 208, 104, 208, 0.9f, {{0, 0.9f}}}, {208, 208, 104, 208, NAN, {{1, 0.9f}}},
                                 {208, 208, INFINITY, 208, 0.9f, {{2, 0.9f}}}};
  YoloDetectorOptions o;
  cv_adapter::YoloDecodeScratch scratch;
  YoloDetectorResult r;
  cv_adapter::decode_yolo_outputs({yolov5_output(anchors, 80)}, YoloHead::YoloV5,
                                  YoloInputGeometry::plain(640, 480, 416, 416), o, &scratch, &r);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_TRUE(r.detections.empty());
}

// ------------------------------------------------------------------------------------------------
// Opening models and running frames (no data needed)
// ------------------------------------------------------------------------------------------------

TEST(YoloDetectorOpen, MissingModelFileIsAnIoErrorNamingThePath) {
  TempDir dir;
  YoloDetectorOptions o;
  o.model = (dir.path / "absent.cfg").string();
  o.weights = dir.file("w.weights", "x");
  YoloDetector d;
  const auto r = d.open(o);
  EXPECT_EQ(r.status, Status::IoError);
  EXPECT_NE(r.reason.find("absent.cfg"), std::string::npos) << r.reason;
  EXPECT_FALSE(d.ok());
}

TEST(YoloDetectorOpen, MissingWeightsFileIsAnIoErrorNamingThePath) {
  TempDir dir;
  YoloDetectorOptions o;
  o.model = dir.file("net.cfg", one_conv_cfg(4));
  o.weights = (dir.path / "absent.weights").string();
  YoloDetector d;
  const auto r = d.open(o);
  EXPECT_EQ(r.status, Status::IoError);
  EXPECT_NE(r.reason.find("absent.weights"), std::string::npos) << r.reason;
}

TEST(YoloDetectorOpen, CfgWithoutWeightsIsInvalidInput) {
  TempDir dir;
  YoloDetectorOptions o;
  o.model = dir.file("net.cfg", one_conv_cfg(4));
  YoloDetector d;
  const auto r = d.open(o);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.reason.find("needs its .weights"), std::string::npos) << r.reason;
}

TEST(YoloDetectorOpen, UnknownModelExtensionAndOnnxWithWeightsAreInvalidInput) {
  TempDir dir;
  YoloDetectorOptions o;
  o.model = dir.file("net.pb", "x");
  YoloDetector d;
  EXPECT_EQ(d.open(o).status, Status::InvalidInput);
  EXPECT_NE(d.opened().reason.find("unknown model type"), std::string::npos) << d.opened().reason;
  o.model = dir.file("net.onnx", "x");
  o.weights = dir.file("net.weights", "x");
  EXPECT_EQ(d.open(o).status, Status::InvalidInput);
  EXPECT_NE(d.opened().reason.find("ONNX"), std::string::npos) << d.opened().reason;
  o.model.clear();
  EXPECT_EQ(d.open(o).status, Status::InvalidInput);
}

TEST(YoloDetectorOpen, GarbageCfgIsAParseErrorNotAnException) {
  TempDir dir;
  YoloDetectorOptions o;
  o.model = dir.file("garbage.cfg", "this is not [a darknet\x01 cfg]\n[convolutional]\nfilters=banana\n");
  o.weights = dir.file("garbage.weights", "\x01\x02\x03");
  YoloDetector d;
  cv_adapter::YoloOpenResult r;
  EXPECT_NO_THROW(r = d.open(o));
  EXPECT_EQ(r.status, Status::ParseError) << r.reason;
  EXPECT_NE(r.reason.find("garbage.cfg"), std::string::npos) << r.reason;
  EXPECT_FALSE(d.ok());
}

TEST(YoloDetectorOpen, GarbageOnnxIsAParseErrorNotAnException) {
  TempDir dir;
  YoloDetectorOptions o;
  o.model = dir.file("garbage.onnx", "not a protobuf at all");
  YoloDetector d;
  cv_adapter::YoloOpenResult r;
  EXPECT_NO_THROW(r = d.open(o));
  EXPECT_EQ(r.status, Status::ParseError) << r.reason;
}

TEST(YoloDetectorOpen, NetworkWithoutAYoloHeadIsInvalidInputNamingTheShape) {
  TempDir dir;
  YoloDetectorOptions o;
  o.model = dir.file("conv.cfg", one_conv_cfg(4));
  o.weights = dir.file("conv.weights", darknet_weights(std::vector<float>(4 + 4 * 3, 0.1f)));
  o.input_width = o.input_height = 32;
  YoloDetector d;
  const auto r = d.open(o);
  EXPECT_EQ(r.status, Status::InvalidInput) << r.reason;
  EXPECT_NE(r.reason.find("not a YOLO head"), std::string::npos) << r.reason;
  EXPECT_NE(r.reason.find("[1, 4, 32, 32]"), std::string::npos) << r.reason;
  EXPECT_FALSE(d.ok());
}

TEST(YoloDetectorOpen, ClassCountDifferentFromTheHeadsIsInvalidInput) {
  TempDir dir;
  TinyYoloNet net(dir);
  YoloDetectorOptions o = net.options();
  o.num_classes = 80;
  YoloDetector d;
  const auto r = d.open(o);
  EXPECT_EQ(r.status, Status::InvalidInput) << r.reason;
  EXPECT_NE(r.reason.find("[3072, 7]"), std::string::npos) << r.reason;
}

// The real model's files, read whole, for corrupt copies written into a test's scratch directory.
bool real_model(std::string* cfg, std::string* weights, std::string* why_not) {
  const std::string root = dyncull::test::real_data_dir(why_not);
  if (root.empty()) return false;
  const fs::path dir = fs::path(root) / "models" / "yolo-fastest-1.1-xl";
  std::ifstream c(dir / "yolo-fastest-1.1-xl.cfg", std::ios::binary), w(dir / "yolo-fastest-1.1-xl.weights", std::ios::binary);
  if (!c || !w) return (*why_not = dir.string() + " has no yolo-fastest-1.1-xl.cfg / .weights", false);
  cfg->assign(std::istreambuf_iterator<char>(c), std::istreambuf_iterator<char>());
  weights->assign(std::istreambuf_iterator<char>(w), std::istreambuf_iterator<char>());
  return true;
}

// Weights that do not fit the cfg's layers (cut, padded, another network's, /dev/zero) are refused at
// open, naming both sizes; the intact copy opens.
TEST(YoloDetectorOpen, WeightsWhoseSizeDoesNotFitTheCfgAreRefused) {
  std::string cfg, weights, why_not;
  if (!real_model(&cfg, &weights, &why_not)) GTEST_SKIP() << why_not;
  TempDir dir;
  YoloDetectorOptions o;
  o.model = dir.file("net.cfg", cfg);
  o.weights = dir.file("intact.weights", weights);
  YoloDetector d;
  ASSERT_TRUE(d.open(o).ok()) << d.opened().reason;
  const std::string copies[] = {weights.substr(0, weights.size() / 2), weights.substr(0, weights.size() - 4),
                                weights + std::string(4, '\0'), weights + weights};
  for (const std::string& corrupt : copies) {
    o.weights = dir.file("corrupt.weights", corrupt);
    const auto r = d.open(o);
    EXPECT_EQ(r.status, Status::InvalidInput) << corrupt.size() << " bytes";
    EXPECT_NE(r.reason.find(std::to_string(corrupt.size()) + " bytes, where the layers of"), std::string::npos) << r.reason;
    EXPECT_NE(r.reason.find("need " + std::to_string(weights.size())), std::string::npos) << r.reason;
    EXPECT_FALSE(d.ok());
  }
  fs::create_symlink("/dev/zero", dir.path / "zero.weights");
  o.weights = (dir.path / "zero.weights").string();
  EXPECT_EQ(d.open(o).status, Status::IoError);
  EXPECT_NE(d.opened().reason.find("character device"), std::string::npos) << d.opened().reason;
  o.weights = "/proc/self/pagemap";
  EXPECT_EQ(d.open(o).status, Status::IoError);
}

// A [yolo] head fed by a convolution of the wrong width: its outputs cannot be the head's.
TEST(YoloDetectorOpen, HeadNotFedByItsAnchorsTimesClassesFiltersIsRefused) {
  std::string cfg, weights, why_not;
  if (!real_model(&cfg, &weights, &why_not)) GTEST_SKIP() << why_not;
  TempDir dir;
  const std::size_t classes = cfg.rfind("classes=80");
  ASSERT_NE(classes, std::string::npos);
  std::string other = cfg;
  other.replace(classes, 10, "classes=20");
  YoloDetectorOptions o;
  o.model = dir.file("net.cfg", other);
  o.weights = dir.file("net.weights", weights);
  o.num_classes = 20;
  YoloDetector d;
  const auto r = d.open(o);
  EXPECT_EQ(r.status, Status::ParseError) << r.reason;
  EXPECT_NE(r.reason.find("[yolo]: is fed by 255 filters, its 3 anchors of 20 classes need a convolution of 75"),
            std::string::npos)
      << r.reason;
}

// Model files that are FIFOs or devices are refused without blocking or reading.
TEST(YoloDetectorOpen, ModelFilesThatAreFifosOrDevicesAreRefusedWithoutBlocking) {
  TempDir dir;
  TinyYoloNet net(dir);
  const std::string fifo = (dir.path / "pipe.cfg").string();
  if (!test::make_fifo(fifo)) return;
  YoloDetector d;
  YoloDetectorOptions o = net.options();
  o.model = fifo;
  cv_adapter::YoloOpenResult r;
  EXPECT_TRUE(test::returns_promptly([&] { r = d.open(o); }, fifo));
  EXPECT_EQ(r.status, Status::IoError);
  EXPECT_NE(r.reason.find("FIFO"), std::string::npos) << r.reason;
  o = net.options();
  o.weights = fifo;
  EXPECT_TRUE(test::returns_promptly([&] { r = d.open(o); }, fifo));
  EXPECT_EQ(r.status, Status::IoError);
  fs::create_symlink("/dev/zero", dir.path / "zero.cfg");
  o = net.options();
  o.model = (dir.path / "zero.cfg").string();
  EXPECT_EQ(d.open(o).status, Status::IoError);
  EXPECT_TRUE(d.open(net.options()).ok()) << d.opened().reason;
}

TEST(YoloDetectorOpen, BadOptionsAreInvalidInputNamingTheField) {
  TempDir dir;
  TinyYoloNet net(dir);
  YoloDetector d;
  YoloDetectorOptions o = net.options();
  o.input_width = 0;
  EXPECT_EQ(d.open(o).status, Status::InvalidInput);
  EXPECT_NE(d.opened().reason.find("input_width"), std::string::npos);
  o = net.options();
  o.min_confidence = NAN;
  EXPECT_EQ(d.open(o).status, Status::InvalidInput);
  EXPECT_NE(d.opened().reason.find("min_confidence"), std::string::npos);
  o = net.options();
  o.head = YoloHead::YoloV8;
  EXPECT_EQ(d.open(o).status, Status::InvalidInput) << "a Darknet cfg with a YOLOv8 head";
}

TEST(YoloDetectorRun, TinyDarknetNetDetectsOnColourAndGreyFramesAndReopens) {
  TempDir dir;
  TinyYoloNet net(dir);
  YoloDetector d;
  const auto opened = d.open(net.options());
  ASSERT_TRUE(opened.ok()) << opened.reason;
  EXPECT_EQ(opened.head, YoloHead::Darknet);
  EXPECT_EQ(opened.num_outputs, 1);
  EXPECT_EQ(opened.num_anchors, 32 * 32 * 3);

  const cv::Mat bgr(48, 64, CV_8UC3, cv::Scalar(30, 90, 200));
  const YoloDetectorResult& r = d.detect(bgr);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_FALSE(r.converted_from_grey);
  // Every cell predicts class 1 at 0.95 x 0.5: many candidates, NMS leaves fewer, all clipped to the frame.
  EXPECT_EQ(r.num_candidates, 32u * 32u * 3u);
  ASSERT_FALSE(r.detections.empty());
  EXPECT_LT(r.detections.size(), r.num_candidates);
  for (const auto& det : r.detections) {
    EXPECT_EQ(det.class_id, 1);
    EXPECT_NEAR(det.confidence, 0.95257f * 0.5f, 1e-3f);
    EXPECT_GE(det.box.x0, 0.f);
    EXPECT_GE(det.box.y0, 0.f);
    EXPECT_LE(det.box.x1, 63.f);
    EXPECT_LE(det.box.y1, 47.f);
    EXPECT_GT(det.box.x1, det.box.x0);
    EXPECT_GT(det.box.y1, det.box.y0);
  }
  const std::size_t colour_count = r.detections.size();

  const cv::Mat grey(48, 64, CV_8UC1, cv::Scalar(100));
  const YoloDetectorResult& g = d.detect(grey);
  ASSERT_TRUE(g.ok()) << g.reason;
  EXPECT_TRUE(g.converted_from_grey);
  EXPECT_EQ(g.detections.size(), colour_count) << "the zero-weight net ignores the pixels";

  YoloDetectorOptions letterboxed = net.options();
  letterboxed.resize = cv_adapter::YoloResize::Letterbox;
  ASSERT_TRUE(d.open(letterboxed).ok()) << d.opened().reason;
  const YoloDetectorResult& l = d.detect(bgr);
  ASSERT_TRUE(l.ok()) << l.reason;
  EXPECT_FALSE(l.detections.empty());
}

TEST(YoloDetectorRun, EmptyAndWrongTypeFramesAreInvalidInputWithoutDetections) {
  TempDir dir;
  TinyYoloNet net(dir);
  YoloDetector d;
  ASSERT_TRUE(d.open(net.options()).ok()) << d.opened().reason;
  ASSERT_FALSE(d.detect(cv::Mat(48, 64, CV_8UC3, cv::Scalar(0))).detections.empty());

  const YoloDetectorResult& empty = d.detect(cv::Mat());
  EXPECT_EQ(empty.status, Status::InvalidInput);
  EXPECT_NE(empty.reason.find("empty"), std::string::npos) << empty.reason;
  EXPECT_TRUE(empty.detections.empty());

  for (const int type : {CV_32FC1, CV_8UC4, CV_16UC3, CV_8UC2}) {
    const YoloDetectorResult& bad = d.detect(cv::Mat(48, 64, type, cv::Scalar(0)));
    EXPECT_EQ(bad.status, Status::InvalidInput) << "type " << type;
    EXPECT_NE(bad.reason.find("CV_8UC3"), std::string::npos) << bad.reason;
    EXPECT_TRUE(bad.detections.empty());
  }
}

TEST(YoloDetectorRun, DetectorThatFailedToOpenRefusesFrames) {
  YoloDetector never_opened;
  EXPECT_EQ(never_opened.detect(cv::Mat(48, 64, CV_8UC3)).status, Status::InvalidInput);
  EXPECT_NE(never_opened.detect(cv::Mat(48, 64, CV_8UC3)).reason.find("not open"), std::string::npos);

  YoloDetector failed;
  YoloDetectorOptions o;
  o.model = "absent.cfg";
  o.weights = "absent.weights";
  EXPECT_FALSE(failed.open(o).ok());
  const YoloDetectorResult& r = failed.detect(cv::Mat(48, 64, CV_8UC3));
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.reason.find("absent.cfg"), std::string::npos) << r.reason;
}

TEST(YoloDetectorOnnx, Yolov8ExportIsRecognisedAndDecodedWithoutObjectness) {
  TempDir dir;
  std::vector<float> biases(84, 0.f);
  biases[0] = 16, biases[1] = 16, biases[2] = 8, biases[3] = 8;  // every anchor: the input's centre, 8 x 8 px
  biases[4 + 0] = 0.9f;                                           // person 0.9
  biases[4 + 56] = 0.2f;                                          // chair below the threshold
  YoloDetectorOptions o;
  o.model = dir.file("v8.onnx", onnx::yolo_model(biases, false));
  o.input_width = o.input_height = 32;
  YoloDetector d;
  const auto opened = d.open(o);
  ASSERT_TRUE(opened.ok()) << opened.reason;
  EXPECT_EQ(opened.head, YoloHead::YoloV8);
  EXPECT_EQ(opened.num_anchors, 1024);
  const YoloDetectorResult& r = d.detect(cv::Mat(48, 64, CV_8UC3, cv::Scalar(10, 20, 30)));
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.num_candidates, 1024u);
  ASSERT_EQ(r.detections.size(), 1u) << "1024 identical boxes, one after NMS";
  EXPECT_EQ(r.detections[0].class_id, 0);
  EXPECT_NEAR(r.detections[0].confidence, 0.9f, 1e-6f);
  expect_box(r.detections[0], 24.f, 18.f, 40.f, 30.f);  // (12..20) x 64/32, (12..20) x 48/32
}

TEST(YoloDetectorOnnx, Yolov5ExportIsRecognisedAndItsConfidenceIsObjectnessTimesClass) {
  TempDir dir;
  std::vector<float> biases(85, 0.f);
  biases[0] = 16, biases[1] = 16, biases[2] = 8, biases[3] = 8;
  biases[4] = 0.5f;        // objectness
  biases[5 + 3] = 0.8f;    // motorbike: 0.5 x 0.8 = 0.4
  YoloDetectorOptions o;
  o.model = dir.file("v5.onnx", onnx::yolo_model(biases, true));
  o.input_width = o.input_height = 32;
  o.resize = cv_adapter::YoloResize::Letterbox;
  YoloDetector d;
  const auto opened = d.open(o);
  ASSERT_TRUE(opened.ok()) << opened.reason;
  EXPECT_EQ(opened.head, YoloHead::YoloV5);
  const YoloDetectorResult& r = d.detect(cv::Mat(48, 64, CV_8UC3, cv::Scalar(10, 20, 30)));
  ASSERT_TRUE(r.ok()) << r.reason;
  ASSERT_EQ(r.detections.size(), 1u);
  EXPECT_EQ(r.detections[0].class_id, 3);
  EXPECT_NEAR(r.detections[0].confidence, 0.4f, 1e-6f);
  // Letterbox 64 x 48 -> 32 x 24 at offset (0, 4): x (12..20) x 2, y (12 - 4 .. 20 - 4) x 2.
  expect_box(r.detections[0], 24.f, 16.f, 40.f, 32.f);
}

TEST(YoloDetectorOnnx, ExportWithARawMapBesideTheHeadRunsOnTheHeadOutput) {
  TempDir dir;
  std::vector<float> biases(84, 0.f);
  biases[0] = 16, biases[1] = 16, biases[2] = 8, biases[3] = 8;
  biases[4 + 0] = 0.9f;
  YoloDetectorOptions o;
  o.model = dir.file("v8_raw.onnx", onnx::yolo_model(biases, false, true, true));
  o.input_width = o.input_height = 32;
  YoloDetector d;
  const auto opened = d.open(o);
  ASSERT_TRUE(opened.ok()) << opened.reason;
  EXPECT_EQ(opened.head, YoloHead::YoloV8);
  EXPECT_EQ(opened.num_outputs, 1);
  const YoloDetectorResult& r = d.detect(cv::Mat(48, 64, CV_8UC3, cv::Scalar(0)));
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.detections.size(), 1u);
}

TEST(YoloDetectorOnnx, ExportWhoseOutputIsNotAYoloHeadIsInvalidInputNamingTheShape) {
  TempDir dir;
  YoloDetectorOptions o;
  o.model = dir.file("conv.onnx", onnx::yolo_model(std::vector<float>(84, 0.f), false, false));
  o.input_width = o.input_height = 32;
  YoloDetector d;
  const auto r = d.open(o);
  EXPECT_EQ(r.status, Status::InvalidInput) << r.reason;
  EXPECT_NE(r.reason.find("[1, 84, 32, 32]"), std::string::npos) << r.reason;
  EXPECT_FALSE(d.ok());
}

// ------------------------------------------------------------------------------------------------
// The real network against the stored detections of the Bonn crowd frames
// ------------------------------------------------------------------------------------------------

struct BonnSample {
  std::string image;
  eval::YoloJsonFrame<float> expected;
};

/// Greedy one-to-one matching of same-class boxes within `px` pixels per corner and `conf` confidence.
/// Returns the unmatched boxes of each side as text.
std::string unmatched(const std::vector<Detection<float>>& a, const std::vector<Detection<float>>& b, float px,
                      float conf) {
  std::vector<bool> used(b.size(), false);
  std::string out;
  for (const auto& d : a) {
    bool found = false;
    for (std::size_t k = 0; k < b.size() && !found; ++k) {
      const auto& e = b[k];
      if (used[k] || e.class_id != d.class_id) continue;
      if (std::abs(d.box.x0 - e.box.x0) <= px && std::abs(d.box.y0 - e.box.y0) <= px &&
          std::abs(d.box.x1 - e.box.x1) <= px && std::abs(d.box.y1 - e.box.y1) <= px &&
          std::abs(d.confidence - e.confidence) <= conf) {
        used[k] = true;
        found = true;
      }
    }
    if (!found) {
      char line[160];
      std::snprintf(line, sizeof line, "  class %d conf %.4f [%.1f, %.1f, %.1f, %.1f]\n", d.class_id, d.confidence,
                    d.box.x0, d.box.y0, d.box.x1, d.box.y1);
      out += line;
    }
  }
  return out;
}

/// The ten RGB samples, their stored detections (matched by the rgb timestamp both carry: rgb_samples/
/// <stamp>.png and detections/NNNNNN.json's "timestamp") and the model files; `skip` says what is missing.
struct BonnData {
  std::string skip, error;
  std::vector<BonnSample> samples;
  std::vector<cv::Mat> frames;
  YoloDetectorOptions options;  ///< the stored boxes' preprocessing
};

BonnData load_bonn() {
  BonnData data;
  const fs::path root = dyncull::test::real_data_dir(&data.skip);
  if (root.empty()) return data;
  const fs::path seq = root / "bonn" / "crowd_part1";
  const fs::path model = root / "models" / "yolo-fastest-1.1-xl";
  for (const fs::path& p : {seq / "rgb_samples", seq / "detections", model / "yolo-fastest-1.1-xl.cfg",
                            model / "yolo-fastest-1.1-xl.weights"}) {
    if (!fs::exists(p)) {
      data.skip = p.string() + " is missing: real-detector test skipped";
      return data;
    }
  }
  const auto stored = eval::read_yolo_json_sequence<float>((seq / "detections").string());
  if (!stored.ok()) {
    data.error = stored.reason;
    return data;
  }
  for (const auto& entry : fs::directory_iterator(seq / "rgb_samples")) {
    if (entry.path().extension() != ".png") continue;
    const double stamp = std::stod(entry.path().stem().string());
    const auto it = std::find_if(stored.frames.begin(), stored.frames.end(),
                                 [&](const auto& f) { return std::abs(f.timestamp - stamp) < 1e-4; });
    if (it == stored.frames.end()) {
      data.error = entry.path().string() + " has no stored detections with its timestamp";
      return data;
    }
    data.samples.push_back({entry.path().string(), *it});
  }
  std::sort(data.samples.begin(), data.samples.end(), [](const auto& a, const auto& b) { return a.image < b.image; });
  for (const auto& s : data.samples) {
    data.frames.push_back(cv::imread(s.image, cv::IMREAD_COLOR));
    if (data.frames.back().size() != cv::Size(640, 480)) {
      data.error = s.image + ": not a 640 x 480 colour image";
      return data;
    }
  }
  // Plain resize to 416 x 416, RGB, 1/255, confidence >= 0.25, NMS per class at IoU 0.45.
  YoloDetectorOptions& o = data.options;
  o.model = (model / "yolo-fastest-1.1-xl.cfg").string();
  o.weights = (model / "yolo-fastest-1.1-xl.weights").string();
  o.input_width = o.input_height = 416;
  o.resize = cv_adapter::YoloResize::Plain;
  o.min_confidence = 0.25f;
  o.nms_iou = 0.45f;
  return data;
}

#define LOAD_BONN_OR_SKIP(data)                  \
  const BonnData data = load_bonn();             \
  if (!data.skip.empty()) GTEST_SKIP() << data.skip; \
  ASSERT_TRUE(data.error.empty()) << data.error; \
  ASSERT_EQ(data.samples.size(), 10u)

// The stored confidences are objectness^2 x class score: whoever made them applied the YOLOv5 formula to
// OpenCV's Darknet rows, whose class scores already include the objectness. With that formula the boxes
// and confidences are reproduced exactly, both ways.
TEST(YoloDetectorBonn, ReproducesTheStoredYoloFastestBoxesOnTheTenRgbFramesAndTimesThem) {
  LOAD_BONN_OR_SKIP(data);
  YoloDetectorOptions o = data.options;
  o.reapply_objectness = true;
  YoloDetector detector;
  const auto opened = detector.open(o);
  ASSERT_TRUE(opened.ok()) << opened.reason;
  EXPECT_EQ(opened.head, YoloHead::Darknet);
  EXPECT_EQ(opened.num_outputs, 2);
  detector.detect(data.frames[0]);  // warm-up outside the timing

  std::size_t total = 0;
  double seconds = 0;
  for (std::size_t k = 0; k < data.samples.size(); ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    const YoloDetectorResult& r = detector.detect(data.frames[k]);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const std::string& image = data.samples[k].image;
    ASSERT_TRUE(r.ok()) << image << ": " << r.reason;
    const auto& expected = data.samples[k].expected.detections;
    EXPECT_EQ(r.detections.size(), expected.size()) << image;
    const std::string extra = unmatched(r.detections, expected, 1.f, 0.01f);
    const std::string missing = unmatched(expected, r.detections, 1.f, 0.01f);
    EXPECT_TRUE(extra.empty()) << image << ": detected but not stored:\n" << extra;
    EXPECT_TRUE(missing.empty()) << image << ": stored but not detected:\n" << missing;
    total += expected.size();
  }
  EXPECT_GE(total, 20u) << "the frames hold people, chairs and monitors";
  const double mean_ms = 1000.0 * seconds / static_cast<double>(data.samples.size());
  std::printf("yolo-fastest-1.1-xl at 416 x 416 on OpenCV DNN (CPU): %.1f ms per frame (mean of %zu), %zu boxes\n",
              mean_ms, data.samples.size(), total);
  RecordProperty("mean_ms_per_frame", std::to_string(mean_ms));
}

// With YOLO's own confidence (objectness x class score, once) every stored box is found again (IoU >= 0.9:
// NMS may keep a neighbouring candidate once the scores change) with a confidence at least as high, and
// more boxes clear the 0.25 threshold.
TEST(YoloDetectorBonn, YoloConfidenceFindsEveryStoredBoxWithAtLeastItsConfidence) {
  LOAD_BONN_OR_SKIP(data);
  YoloDetector detector;
  ASSERT_TRUE(detector.open(data.options).ok()) << detector.opened().reason;
  std::size_t stored = 0, found = 0;
  for (std::size_t k = 0; k < data.samples.size(); ++k) {
    const YoloDetectorResult& r = detector.detect(data.frames[k]);
    ASSERT_TRUE(r.ok()) << r.reason;
    found += r.detections.size();
    for (const auto& e : data.samples[k].expected.detections) {
      ++stored;
      const bool matched = std::any_of(r.detections.begin(), r.detections.end(), [&](const auto& d) {
        return d.class_id == e.class_id && iou(d.box, e.box) >= 0.9f && d.confidence >= e.confidence - 0.01f;
      });
      EXPECT_TRUE(matched) << data.samples[k].image << ": class " << e.class_id << " conf " << e.confidence;
    }
  }
  EXPECT_GT(found, stored);
}

// The sequence's rgb/ frames are the luminance of the colour frames. The detector was trained on colour;
// on these ten frames grey costs other classes' boxes (chairs, monitors) but finds the people again:
// every colour person box has a grey one at IoU >= 0.5 (measured 12 of 12; 37 boxes in colour, 33 grey).
TEST(YoloDetectorBonn, GreyFramesOfTheSequenceFindThePeopleOfTheirColourOriginals) {
  LOAD_BONN_OR_SKIP(data);
  YoloDetector detector;
  ASSERT_TRUE(detector.open(data.options).ok()) << detector.opened().reason;
  const fs::path rgb_dir = fs::path(data.samples[0].image).parent_path().parent_path() / "rgb";
  std::size_t colour_people = 0, grey_people = 0, people_found = 0, colour_all = 0, grey_all = 0;
  for (std::size_t k = 0; k < data.samples.size(); ++k) {
    const fs::path grey_path = rgb_dir / fs::path(data.samples[k].image).filename();
    const cv::Mat grey = cv::imread(grey_path.string(), cv::IMREAD_UNCHANGED);
    if (grey.empty()) GTEST_SKIP() << grey_path.string() << " is missing: grey comparison skipped";
    ASSERT_EQ(grey.type(), CV_8UC1) << grey_path.string();
    const YoloDetectorResult colour = detector.detect(data.frames[k]);
    const YoloDetectorResult& g = detector.detect(grey);
    ASSERT_TRUE(colour.ok() && g.ok()) << colour.reason << g.reason;
    EXPECT_TRUE(g.converted_from_grey);
    for (const auto& c : colour.detections) {
      if (c.class_id != 0) continue;
      ++colour_people;
      people_found += std::any_of(g.detections.begin(), g.detections.end(),
                                  [&](const auto& d) { return d.class_id == 0 && iou(d.box, c.box) >= 0.5f; });
    }
    for (const auto& d : g.detections) grey_people += d.class_id == 0;
    colour_all += colour.detections.size();
    grey_all += g.detections.size();
  }
  std::printf("ten Bonn frames, colour vs grey: %zu vs %zu person boxes (%zu colour ones found in grey), %zu vs %zu boxes\n",
              colour_people, grey_people, people_found, colour_all, grey_all);
  RecordProperty("person_boxes_colour", static_cast<int>(colour_people));
  RecordProperty("person_boxes_grey", static_cast<int>(grey_people));
  RecordProperty("boxes_colour", static_cast<int>(colour_all));
  RecordProperty("boxes_grey", static_cast<int>(grey_all));
  EXPECT_GE(colour_people, 10u);
  EXPECT_EQ(people_found, colour_people);
  EXPECT_LT(grey_all, colour_all);
}

}  // namespace
