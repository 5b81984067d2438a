#include "dyncull/culling/detections.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <vector>

namespace {
using namespace dyncull;

template <class T>
class Detections : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(Detections, Scalars, );

// Tolerance: a few ulps of a 640-pixel coordinate.
template <class T>
T tol() {
  return T(640) * T(8) * std::numeric_limits<T>::epsilon();
}

TYPED_TEST(Detections, NormalisedCentreSizeToCorners) {
  using T = TypeParam;
  // RTD-SLAM eq. 1-2: X1 = (x - w/2) W, X2 = (x + w/2) W, Y1 = (y - h/2) H, Y2 = (y + h/2) H.
  const Box<T> b = yolo_to_pixel_box(YoloBox<T>{0, T(0.5), T(0.5), T(0.2), T(0.4)}, 640, 480);
  EXPECT_NEAR(b.x0, T(256), tol<T>());
  EXPECT_NEAR(b.x1, T(384), tol<T>());
  EXPECT_NEAR(b.y0, T(144), tol<T>());
  EXPECT_NEAR(b.y1, T(336), tol<T>());
}

TYPED_TEST(Detections, PaddingAndClipping) {
  using T = TypeParam;
  DetectionOptions<T> o;  // 5 px padding by default
  const std::vector<YoloBox<T>> in = {{0, T(0.5), T(0.5), T(0.2), T(0.4), T(0.9)},
                                      {0, T(0.05), T(0.9), T(0.2), T(0.4), T(0.9)}};  // sticks out left and bottom
  const DetectionsResult<T> r = convert_yolo_detections(in, 640, 480, o);
  ASSERT_TRUE(r.ok()) << r.reason;
  ASSERT_EQ(r.detections.size(), 2u);
  EXPECT_NEAR(r.detections[0].box.x0, T(251), tol<T>());
  EXPECT_NEAR(r.detections[0].box.y1, T(341), tol<T>());
  EXPECT_EQ(r.detections[1].box.x0, T(0));
  EXPECT_EQ(r.detections[1].box.y1, T(479));
  EXPECT_NEAR(r.detections[1].box.x1, T(0.15 * 640 + 5), tol<T>());
  EXPECT_EQ(r.detections[0].class_id, 0);
  EXPECT_EQ(r.num_kept, 2u);
  EXPECT_TRUE(r.reason.empty());
}

TYPED_TEST(Detections, LetterboxIsUndone) {
  using T = TypeParam;
  // 640x480 image letterboxed into 640x640: scale 1, 80 px bars top and bottom.
  const Letterbox<T> lb = Letterbox<T>::centred(640, 480, 640, 640);
  EXPECT_NEAR(lb.scale, T(1), tol<T>());
  EXPECT_NEAR(lb.pad_y, T(80), tol<T>());
  EXPECT_NEAR(lb.pad_x, T(0), tol<T>());
  // A box at image rows [100, 300], cols [200, 400] seen in the tensor at rows [180, 380].
  const YoloBox<T> yb{0, T(300) / T(640), T(280) / T(640), T(200) / T(640), T(200) / T(640)};
  const Box<T> b = yolo_to_pixel_box(yb, 640, 480, lb);
  EXPECT_NEAR(b.x0, T(200), tol<T>());
  EXPECT_NEAR(b.x1, T(400), tol<T>());
  EXPECT_NEAR(b.y0, T(100), tol<T>());
  EXPECT_NEAR(b.y1, T(300), tol<T>());
  // 1280x720 into 640x640: scale 0.5, pad_y (640 - 360) / 2 = 140.
  const Letterbox<T> lb2 = Letterbox<T>::centred(1280, 720, 640, 640);
  EXPECT_NEAR(lb2.scale, T(0.5), tol<T>());
  EXPECT_NEAR(lb2.pad_y, T(140), tol<T>());
  const Box<T> b2 = yolo_to_pixel_box(YoloBox<T>{0, T(0.5), T(0.5), T(0.25), T(0.25)}, 1280, 720, lb2);
  EXPECT_NEAR(b2.x0, T(480), tol<T>());  // (240 - 0) / 0.5
  EXPECT_NEAR(b2.y0, T(200), tol<T>());  // (240 - 140) / 0.5
}

TYPED_TEST(Detections, InvalidBoxesAreRejectedWithAReason) {
  using T = TypeParam;
  const T nan = std::numeric_limits<T>::quiet_NaN();
  const std::vector<YoloBox<T>> in = {
      {0, nan, T(0.5), T(0.1), T(0.1), T(0.9)},          // non-finite
      {0, T(0.5), T(0.5), T(0), T(0.1), T(0.9)},         // w = 0
      {0, T(0.5), T(0.5), T(0.1), T(-0.1), T(0.9)},      // h < 0
      {0, T(1.5), T(0.5), T(0.2), T(0.2), T(0.9)},       // entirely right of the image
      {0, T(0.5), T(-0.3), T(0.2), T(0.2), T(0.9)},      // entirely above
      {-1, T(0.5), T(0.5), T(0.2), T(0.2), T(0.9)},      // bad class
      {0, T(0.5), T(0.5), T(0.2), T(0.2), T(0.9)}};      // good
  const DetectionsResult<T> r = convert_yolo_detections(in, 640, 480, DetectionOptions<T>{});
  ASSERT_TRUE(r.ok());
  ASSERT_EQ(r.rejections.size(), in.size());
  EXPECT_EQ(r.rejections[0], BoxRejection::NonFinite);
  EXPECT_EQ(r.rejections[1], BoxRejection::NonPositiveSize);
  EXPECT_EQ(r.rejections[2], BoxRejection::NonPositiveSize);
  EXPECT_EQ(r.rejections[3], BoxRejection::OutsideImage);
  EXPECT_EQ(r.rejections[4], BoxRejection::OutsideImage);
  EXPECT_EQ(r.rejections[5], BoxRejection::BadClass);
  EXPECT_EQ(r.rejections[6], BoxRejection::None);
  ASSERT_EQ(r.detections.size(), 1u);
  EXPECT_EQ(r.source_index[0], 6);
  EXPECT_EQ(r.num_outside, 2u);
  EXPECT_EQ(r.num_invalid, 4u);
  EXPECT_NE(r.reason.find("6 of 7"), std::string::npos) << r.reason;

  const DetectionsResult<T> bad = convert_yolo_detections(in, 0, 480, DetectionOptions<T>{});
  EXPECT_EQ(bad.status, Status::InvalidInput);
  EXPECT_TRUE(bad.detections.empty());
}

TYPED_TEST(Detections, ClassDependentConfidence) {
  using T = TypeParam;
  DetectionOptions<T> o;  // person 0.25, others 0.4
  const std::vector<YoloBox<T>> in = {{0, T(0.5), T(0.5), T(0.2), T(0.2), T(0.3)},    // person kept
                                      {56, T(0.5), T(0.5), T(0.2), T(0.2), T(0.3)},   // chair dropped
                                      {56, T(0.5), T(0.5), T(0.2), T(0.2), T(0.5)},   // chair kept
                                      {62, T(0.5), T(0.5), T(0.2), T(0.2), T(0.3)}};  // tv dropped
  const DetectionsResult<T> r = convert_yolo_detections(in, 640, 480, o);
  EXPECT_EQ(r.rejections[0], BoxRejection::None);
  EXPECT_EQ(r.rejections[1], BoxRejection::LowConfidence);
  EXPECT_EQ(r.rejections[2], BoxRejection::None);
  EXPECT_EQ(r.rejections[3], BoxRejection::LowConfidence);
  EXPECT_EQ(r.num_low_confidence, 2u);
}

TYPED_TEST(Detections, PixelBoxesAreFilteredTheSameWay) {
  using T = TypeParam;
  DetectionOptions<T> o;
  o.box_padding_px = T(0);
  const std::vector<Detection<T>> in = {{Box<T>{T(-50), T(10), T(100), T(500)}, 0, T(0.9)},
                                        {Box<T>{T(700), T(10), T(800), T(50)}, 0, T(0.9)},
                                        {Box<T>{T(10), T(10), T(5), T(50)}, 0, T(0.9)}};
  const DetectionsResult<T> r = filter_detections(in, 640, 480, o);
  ASSERT_EQ(r.detections.size(), 1u);
  EXPECT_EQ(r.detections[0].box.x0, T(0));
  EXPECT_EQ(r.detections[0].box.y1, T(479));
  EXPECT_EQ(r.rejections[1], BoxRejection::OutsideImage);
  EXPECT_EQ(r.rejections[2], BoxRejection::NonPositiveSize);
}

// A result reused from a frame with rejections, then from a bad image size, gives what a fresh call gives.
TYPED_TEST(Detections, OutParameterFormMatchesAFreshResultWhenReused) {
  using T = TypeParam;
  DetectionOptions<T> o;
  o.box_padding_px = T(0);
  const std::vector<Detection<T>> first = {{Box<T>{T(-50), T(10), T(100), T(500)}, 0, T(0.9)},
                                           {Box<T>{T(700), T(10), T(800), T(50)}, 0, T(0.9)},
                                           {Box<T>{T(10), T(10), T(5), T(50)}, 0, T(0.9)}};
  const std::vector<Detection<T>> second = {{Box<T>{T(20), T(30), T(200), T(300)}, 0, T(0.9)}};
  DetectionsResult<T> out;
  filter_detections(first, 640, 480, o, &out);
  ASSERT_FALSE(out.reason.empty());
  filter_detections(first, 0, 480, o, &out);
  ASSERT_EQ(out.status, Status::InvalidInput);
  for (int w : {640, 0}) {
    filter_detections(second, w, 480, o, &out);
    const DetectionsResult<T> fresh = filter_detections(second, w, 480, o);
    EXPECT_EQ(out.status, fresh.status);
    EXPECT_EQ(out.reason, fresh.reason);
    ASSERT_EQ(out.detections.size(), fresh.detections.size());
    for (std::size_t i = 0; i < out.detections.size(); ++i) EXPECT_EQ(out.detections[i].box.x1, fresh.detections[i].box.x1);
    EXPECT_EQ(out.source_index, fresh.source_index);
    EXPECT_EQ(out.rejections, fresh.rejections);
    EXPECT_EQ(out.num_input, fresh.num_input);
    EXPECT_EQ(out.num_kept, fresh.num_kept);
    EXPECT_EQ(out.num_outside, fresh.num_outside);
    EXPECT_EQ(out.num_invalid, fresh.num_invalid);
  }
}

// Negative padding shrinks boxes (for detectors that draw them loose); a box it empties is dropped
// as NonPositiveSize, one it moves off the image as OutsideImage, and neither is counted as kept.
TYPED_TEST(Detections, NegativePaddingThatInvertsABoxDropsIt) {
  using T = TypeParam;
  DetectionOptions<T> o;
  o.box_padding_px = T(-100);
  const std::vector<Detection<T>> in = {{Box<T>{T(10), T(10), T(30), T(30)}, 0, T(0.9)},      // inverted
                                        {Box<T>{T(100), T(100), T(400), T(400)}, 0, T(0.9)},  // shrunk
                                        {Box<T>{T(50), T(50), T(250), T(250)}, 0, T(0.9)},    // a point
                                        {Box<T>{T(-400), T(10), T(50), T(300)}, 0, T(0.9)}};  // off the left edge
  const DetectionsResult<T> r = filter_detections(in, 640, 480, o);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.rejections[0], BoxRejection::NonPositiveSize);
  EXPECT_EQ(r.rejections[1], BoxRejection::None);
  EXPECT_EQ(r.rejections[2], BoxRejection::NonPositiveSize);
  EXPECT_EQ(r.rejections[3], BoxRejection::OutsideImage);
  ASSERT_EQ(r.num_kept, 1u);
  ASSERT_EQ(r.detections.size(), 1u);
  EXPECT_EQ(r.source_index[0], 1);
  EXPECT_EQ(r.detections[0].box.x0, T(200));
  EXPECT_EQ(r.detections[0].box.x1, T(300));
  for (const Detection<T>& d : r.detections) EXPECT_TRUE(d.box.valid());
  // The same through the YOLO path.
  const std::vector<YoloBox<T>> yolo = {{0, T(0.5), T(0.5), T(0.05), T(0.05), T(0.9)}};
  const DetectionsResult<T> y = convert_yolo_detections(yolo, 640, 480, o);
  EXPECT_EQ(y.rejections[0], BoxRejection::NonPositiveSize);
  EXPECT_TRUE(y.detections.empty());
}

TYPED_TEST(Detections, OptionsAreValidatedWithTheFieldNamed) {
  using T = TypeParam;
  std::string why = "unchanged";
  EXPECT_EQ(DetectionOptions<T>{}.validate(&why), Status::Ok);
  EXPECT_TRUE(why.empty());
  struct Case {
    const char* field;
    void (*spoil)(DetectionOptions<T>*);
  };
  const Case cases[] = {
      {"box_padding_px", [](DetectionOptions<T>* o) { o->box_padding_px = std::numeric_limits<T>::quiet_NaN(); }},
      {"box_padding_px", [](DetectionOptions<T>* o) { o->box_padding_px = -std::numeric_limits<T>::infinity(); }},
      {"min_confidence", [](DetectionOptions<T>* o) { o->min_confidence = std::numeric_limits<T>::quiet_NaN(); }},
      {"min_confidence", [](DetectionOptions<T>* o) { o->min_confidence = T(1.5); }},
      {"min_confidence", [](DetectionOptions<T>* o) { o->min_confidence = T(-0.1); }},
      {"min_confidence_person", [](DetectionOptions<T>* o) { o->min_confidence_person = std::numeric_limits<T>::quiet_NaN(); }},
  };
  const std::vector<YoloBox<T>> yolo = {{0, T(0.5), T(0.5), T(0.2), T(0.2), T(0.9)}};
  const std::vector<Detection<T>> px = {{Box<T>{T(10), T(10), T(100), T(100)}, 0, T(0.9)}};
  for (const Case& c : cases) {
    DetectionOptions<T> o;
    c.spoil(&o);
    EXPECT_EQ(o.validate(&why), Status::InvalidInput) << c.field;
    EXPECT_NE(why.find(c.field), std::string::npos) << why;
    const DetectionsResult<T> a = convert_yolo_detections(yolo, 640, 480, o);
    EXPECT_EQ(a.status, Status::InvalidInput) << c.field;
    EXPECT_NE(a.reason.find(c.field), std::string::npos) << a.reason;
    EXPECT_TRUE(a.detections.empty());
    const DetectionsResult<T> b = filter_detections(px, 640, 480, o);
    EXPECT_EQ(b.status, Status::InvalidInput) << c.field;
    EXPECT_NE(b.reason.find(c.field), std::string::npos) << b.reason;
    EXPECT_TRUE(b.detections.empty());
  }
  // Thresholds of 0 and 1 and huge finite padding are fine.
  DetectionOptions<T> edge;
  edge.min_confidence = T(0);
  edge.min_confidence_person = T(1);
  edge.box_padding_px = T(1e30);
  EXPECT_EQ(edge.validate(), Status::Ok);
  const DetectionsResult<T> all = filter_detections(px, 640, 480, edge);
  ASSERT_EQ(all.detections.size(), 0u);  // person threshold 1 > 0.9
  edge.min_confidence_person = T(0);
  const DetectionsResult<T> whole = filter_detections(px, 640, 480, edge);
  ASSERT_EQ(whole.detections.size(), 1u);
  EXPECT_EQ(whole.detections[0].box.x0, T(0));
  EXPECT_EQ(whole.detections[0].box.x1, T(639));
}

// The letterbox belongs to the detector's output: the YOLO conversion refuses a broken one, naming it.
TYPED_TEST(Detections, LetterboxIsValidatedWithTheFieldNamed) {
  using T = TypeParam;
  struct Case {
    const char* field;
    void (*spoil)(Letterbox<T>*);
  };
  const Case cases[] = {
      {"letterbox.scale", [](Letterbox<T>* lb) { lb->scale = T(0); }},
      {"letterbox.scale", [](Letterbox<T>* lb) { lb->scale = std::numeric_limits<T>::quiet_NaN(); }},
      {"letterbox.pad_x", [](Letterbox<T>* lb) { lb->pad_x = std::numeric_limits<T>::infinity(); }},
      {"letterbox.input_height", [](Letterbox<T>* lb) { lb->input_height = 0; }},
  };
  const std::vector<YoloBox<T>> yolo = {{0, T(0.5), T(0.5), T(0.2), T(0.2), T(0.9)}};
  for (const Case& c : cases) {
    Letterbox<T> lb = Letterbox<T>::centred(640, 480, 640, 640);
    c.spoil(&lb);
    const DetectionsResult<T> a = convert_yolo_detections(yolo, 640, 480, DetectionOptions<T>{}, lb);
    EXPECT_EQ(a.status, Status::InvalidInput) << c.field;
    EXPECT_NE(a.reason.find(c.field), std::string::npos) << a.reason;
    EXPECT_TRUE(a.detections.empty());
  }
  const DetectionsResult<T> boxed =
      convert_yolo_detections(yolo, 640, 480, DetectionOptions<T>{}, Letterbox<T>::centred(640, 480, 640, 640));
  ASSERT_TRUE(boxed.ok()) << boxed.reason;
  EXPECT_EQ(boxed.detections.size(), 1u);
}

TEST(YoloParser, ParsesLinesAndReportsLineNumbers) {
  const std::string text =
      "# detections of frame 1\n"
      "0 0.5 0.5 0.2 0.4 0.87\n"
      "\n"
      "56 0.1 0.2 0.05 0.1\r\n"
      "0 0.5 0.5 0.2\n"            // line 5: too few fields
      "x 0.5 0.5 0.2 0.4\n"        // line 6: not a number
      "1.5 0.5 0.5 0.2 0.4\n"      // line 7: non-integer class
      "0 0.5 0.5 0.2 0.4 0.9 7\n"  // line 8: too many fields
      "62 0.7 0.3 0.1 0.1 0.55";   // line 9, no trailing newline
  const YoloParseResult<double> r = parse_yolo_lines<double>(text);
  EXPECT_EQ(r.status, Status::ParseError);
  ASSERT_EQ(r.boxes.size(), 3u);
  EXPECT_EQ(r.line_of_box, (std::vector<int>{2, 4, 9}));
  EXPECT_EQ(r.boxes[0].class_id, 0);
  EXPECT_DOUBLE_EQ(r.boxes[0].confidence, 0.87);
  EXPECT_DOUBLE_EQ(r.boxes[1].confidence, 1.0);  // no confidence column
  EXPECT_DOUBLE_EQ(r.boxes[1].w, 0.05);
  EXPECT_EQ(r.boxes[2].class_id, 62);
  ASSERT_EQ(r.errors.size(), 4u);
  EXPECT_EQ(r.errors[0].line, 5);
  EXPECT_EQ(r.errors[1].line, 6);
  EXPECT_EQ(r.errors[2].line, 7);
  EXPECT_EQ(r.errors[3].line, 8);
  EXPECT_NE(r.reason.find("line 5"), std::string::npos) << r.reason;
}

TEST(YoloParser, CleanFileAndNanValues) {
  const YoloParseResult<float> ok = parse_yolo_lines<float>("0 0.5 0.5 0.2 0.4\n1 0.2 0.2 0.1 0.1\n");
  EXPECT_TRUE(ok.ok()) << ok.reason;
  EXPECT_EQ(ok.boxes.size(), 2u);
  EXPECT_TRUE(parse_yolo_lines<float>("").ok());
  // "nan" parses as a number; the converter then rejects the box, so the line number is kept.
  const YoloParseResult<float> n = parse_yolo_lines<float>("0 nan 0.5 0.2 0.4\n");
  ASSERT_EQ(n.boxes.size(), 1u);
  const DetectionsResult<float> c = convert_yolo_detections(n.boxes, 640, 480, DetectionOptions<float>{});
  EXPECT_EQ(c.rejections[0], BoxRejection::NonFinite);
}
}  // namespace
