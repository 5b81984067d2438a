// YOLO label text ("class cx cy w h [conf]" per line): the number grammar, locale independence,
// bounded lines and tokens, and "source:line: reason" messages.
#include "dyncull/culling/detections.hpp"

#include <gtest/gtest.h>

#include "support/locale.hpp"

#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace {

using namespace dyncull;

template <class T>
class YoloParseTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(YoloParseTest, Scalars, );

using dyncull::test::CommaDecimalLocale;

TYPED_TEST(YoloParseTest, PointDecimalsParseAndCommaDecimalsFailUnderACommaLocale) {
  using T = TypeParam;
  CommaDecimalLocale locale;
  if (!locale.active()) GTEST_SKIP() << "no comma-decimal locale installed (locale-gen de_DE.UTF-8)";
  const YoloParseResult<T> good = parse_yolo_lines<T>("0 0.5 0.25 0.2 0.4 0.9\n", "dets.txt");
  ASSERT_TRUE(good.ok()) << good.reason;
  ASSERT_EQ(good.boxes.size(), 1u);
  EXPECT_EQ(good.boxes[0].cy, T(0.25));
  EXPECT_EQ(good.boxes[0].confidence, T(0.9));
  const YoloParseResult<T> comma = parse_yolo_lines<T>("0 0,5 0,25 0,2 0,4\n", "dets.txt");
  EXPECT_EQ(comma.status, Status::ParseError);
  EXPECT_TRUE(comma.boxes.empty());
  EXPECT_EQ(comma.reason.rfind("dets.txt:1: cx '0,5'", 0), 0u) << comma.reason;
}

TEST(YoloParse, ReasonNamesSourceLineAndFieldAndCountsEveryBadLine) {
  const std::string text =
      "0 0.5 0.5 0.2 0.4\n"
      "0 0.5 0.5 0.2\n"           // 2: too few fields
      "3 0.5 zz 0.2 0.4\n"        // 3: cy not a number
      "-1 0.5 0.5 0.2 0.4\n"      // 4: negative class
      "0 0.5 0.5 0.2 0.4 1 2\n";  // 5: too many fields
  const YoloParseResult<double> r = parse_yolo_lines<double>(text, "labels/0001.txt");
  EXPECT_EQ(r.status, Status::ParseError);
  EXPECT_EQ(r.boxes.size(), 1u);
  EXPECT_EQ(r.num_bad_lines, 4u);
  ASSERT_EQ(r.errors.size(), 4u);
  EXPECT_EQ(r.reason.rfind("labels/0001.txt:2: expected 5 or 6 fields", 0), 0u) << r.reason;
  EXPECT_NE(r.reason.find("(4 bad lines)"), std::string::npos) << r.reason;
  EXPECT_EQ(r.errors[1].message, "cy 'zz' is not a number");
  EXPECT_EQ(r.errors[2].line, 4);
  EXPECT_NE(r.errors[2].message.find("class"), std::string::npos);
  EXPECT_NE(r.errors[3].message.find("got 7"), std::string::npos) << r.errors[3].message;
  // Without a source the reason still names the line.
  EXPECT_EQ(parse_yolo_lines<double>(text).reason.rfind("line 2: ", 0), 0u);
}

TEST(YoloParse, ErrorListIsBoundedButTheCountIsNot) {
  std::string text;
  for (int i = 0; i < 1000; ++i) text += "bad line\n";
  const YoloParseResult<float> r = parse_yolo_lines<float>(text, "f");
  EXPECT_EQ(r.num_bad_lines, 1000u);
  EXPECT_EQ(r.errors.size(), kYoloMaxListedErrors);
}

TEST(YoloParse, NumbersFollowPythonFloat) {
  const YoloParseResult<double> r = parse_yolo_lines<double>("1_0 .5 5. 1e-1 2_5e-2 +1\n", "f");
  ASSERT_TRUE(r.ok()) << r.reason;
  ASSERT_EQ(r.boxes.size(), 1u);
  EXPECT_EQ(r.boxes[0].class_id, 10);
  EXPECT_EQ(r.boxes[0].cx, 0.5);
  EXPECT_EQ(r.boxes[0].h, 0.25);
  for (const char* bad : {"0 +-0.5 0.5 0.2 0.4", "0 0x1 0.5 0.2 0.4", "0 0.5_ 0.5 0.2 0.4", "0 1e 0.5 0.2 0.4",
                          "0 0.5 0.5 0.2 0.4 0.9x"}) {
    EXPECT_EQ(parse_yolo_lines<double>(bad).status, Status::ParseError) << bad;
  }
}

TYPED_TEST(YoloParseTest, ValuesOutOfRangeForTheScalarAreBadLines) {
  using T = TypeParam;
  const YoloParseResult<T> r = parse_yolo_lines<T>("0 0.5 0.5 1e39 0.4\n0 0.5 0.5 1e400 0.4\n", "f");
  if (sizeof(T) == sizeof(float)) {
    EXPECT_EQ(r.status, Status::ParseError);
    EXPECT_NE(r.reason.find("f:1: w"), std::string::npos) << r.reason;
    EXPECT_NE(r.reason.find("out of range for float"), std::string::npos) << r.reason;
    ASSERT_EQ(r.boxes.size(), 1u);
  } else {
    EXPECT_TRUE(r.ok()) << r.reason;
    ASSERT_EQ(r.boxes.size(), 2u);
    EXPECT_EQ(r.boxes[0].w, T(1e39));
  }
  // 1e400 overflows every scalar to infinity, as Python's float(): the converter rejects it as non-finite.
  EXPECT_TRUE(std::isinf(r.boxes.back().w));
}

TEST(YoloParse, LongTokensAndLinesAreBoundedErrors) {
  const std::string huge(1u << 20, '5');
  YoloParseResult<double> r = parse_yolo_lines<double>("0 0." + huge + " 0.5 0.2 0.4\n0 0.5 0.5 0.2 0.4\n", "f");
  EXPECT_EQ(r.status, Status::ParseError);
  EXPECT_EQ(r.boxes.size(), 1u);
  EXPECT_LT(r.reason.size(), 200u) << r.reason.substr(0, 300);
  EXPECT_EQ(r.reason.rfind("f:1: line", 0), 0u) << r.reason.substr(0, 300);
  r = parse_yolo_lines<double>("0 0." + std::string(600, '5') + " 0.5 0.2 0.4\n", "f");
  EXPECT_EQ(r.status, Status::ParseError);
  EXPECT_LT(r.reason.size(), 200u) << r.reason;
  EXPECT_EQ(r.reason.rfind("f:1: cx", 0), 0u) << r.reason;
  const std::string nul = std::string("0 0.5") + '\0' + " 0.5 0.2 0.4\n";
  r = parse_yolo_lines<double>(nul, "f");
  EXPECT_EQ(r.status, Status::ParseError);
  EXPECT_NE(r.reason.find("0.5\\x00"), std::string::npos) << r.reason;
  EXPECT_NE(r.reason.find("is not a number"), std::string::npos) << r.reason;
}

}  // namespace
