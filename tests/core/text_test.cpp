// The number grammar every dyncull text reader shares: Python's float(), in any locale, bounded.

#include "dyncull/core/text.hpp"

#include "support/locale.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

namespace dyncull::text {
namespace {

double parsed(std::string_view token) {
  double v = -12345;
  EXPECT_EQ(parse_python_float(token, &v), NumberStatus::Ok) << std::string(token);
  return v;
}

NumberStatus status_of(std::string_view token) {
  double v = 0;
  return parse_python_float(token, &v);
}

TEST(ParsePythonFloat, AcceptsWhatPythonFloatAccepts) {
  EXPECT_EQ(parsed("0.5"), 0.5);
  EXPECT_EQ(parsed("-2"), -2.0);
  EXPECT_EQ(parsed("+3.25"), 3.25);
  EXPECT_EQ(parsed(".5"), 0.5);
  EXPECT_EQ(parsed("5."), 5.0);
  EXPECT_EQ(parsed("1e3"), 1000.0);
  EXPECT_EQ(parsed("1_000.5"), 1000.5);
  EXPECT_EQ(parsed("1e400"), std::numeric_limits<double>::infinity());
  EXPECT_EQ(parsed("-1e400"), -std::numeric_limits<double>::infinity());
  EXPECT_EQ(parsed("1e-400"), 0.0);
  EXPECT_EQ(parsed("inf"), std::numeric_limits<double>::infinity());
  EXPECT_EQ(parsed("-Infinity"), -std::numeric_limits<double>::infinity());
  EXPECT_TRUE(std::isnan(parsed("nan")));
  EXPECT_TRUE(std::isnan(parsed("NaN")));
}

TEST(ParsePythonFloat, RejectsWhatPythonFloatRejects) {
  for (const char* bad : {"+-5", "--1", "0,5", "1__0", "_1", "1_", "1e", "e5", "0x10", "1.2.3", "infinite", "5 ",
                          "abc"})
    EXPECT_EQ(status_of(bad), NumberStatus::Invalid) << bad;
  EXPECT_EQ(status_of(""), NumberStatus::Empty);
  EXPECT_EQ(status_of(std::string(kMaxNumberChars + 1, '1')), NumberStatus::TooLong);
}

TEST(ParsePythonFloat, IgnoresTheProcessLocale) {
  test::CommaDecimalLocale locale;
  if (!locale.active()) GTEST_SKIP() << "no comma-decimal locale installed (scripts/install-deps.sh generates de_DE.UTF-8)";
  EXPECT_EQ(parsed("0.5"), 0.5);
  EXPECT_EQ(status_of("0,5"), NumberStatus::Invalid);
}

TEST(QuoteToken, IsBoundedAndEscapesBytesOutsidePrintableAscii) {
  EXPECT_EQ(quote_token("abc"), "'abc'");
  EXPECT_EQ(quote_token(std::string_view("a\0b", 3)), "'a\\x00b'");
  EXPECT_EQ(quote_token("it's"), "'it\\x27s'");
  const std::string long_token(1000, 'x');
  const std::string q = quote_token(long_token);
  EXPECT_EQ(q, "'" + std::string(kQuotedTokenChars, 'x') + "'... (1000 bytes)");
}

TEST(QuoteToken, PathsAreEscapedTheSameWayWithoutQuotes) {
  EXPECT_EQ(quote_path("data/rgb.txt"), "data/rgb.txt");
  EXPECT_EQ(quote_path("it's\x1b[2J"), "it's\\x1b[2J");
  EXPECT_EQ(quote_token("a\\b"), "'a\\x5cb'");
  const std::string long_path(5000, 'p');
  EXPECT_EQ(quote_path(long_path), std::string(kQuotedPathChars, 'p') + "... (5000 bytes)");
}

TEST(QuoteToken, EscapedBytesCountTowardTheBound) {
  // Each byte outside printable ASCII shows as four characters: a path of such bytes stops at the bound.
  const std::string binary_path(400, '\xd1');
  const std::string shown = quote_path(binary_path);
  EXPECT_EQ(shown, [] {
    std::string s;
    for (std::size_t i = 0; i < kQuotedPathChars / 4; ++i) s += "\\xd1";
    return s + "... (400 bytes)";
  }());
  EXPECT_EQ(quote_token("ab\x01" "cd", 6), "'ab\\x01'... (5 bytes)");
}

TEST(IntegerInRange, ConvertsOnlyIntegersInsideTheBounds) {
  long long n = -7;
  EXPECT_TRUE(integer_in_range(1e15, 0, 1000000000000000LL, &n));
  EXPECT_EQ(n, 1000000000000000LL);
  EXPECT_TRUE(integer_in_range(-3.0, -5, 5, &n));
  EXPECT_EQ(n, -3);
  n = -7;
  for (double bad : {1e15 + 1, 0.5, -1.0, std::nan(""), HUGE_VAL, -HUGE_VAL, 1e300, 9223372036854775808.0})
    EXPECT_FALSE(integer_in_range(bad, 0, 1000000000000000LL, &n)) << bad;
  // Bounds that round up in double never let 2^63 through.
  EXPECT_FALSE(integer_in_range(9223372036854775808.0, 0, std::numeric_limits<long long>::max(), &n));
  EXPECT_EQ(n, -7);
}

TEST(FitsScalar, NamesTheRangeOfEachType) {
  EXPECT_TRUE(fits_scalar<float>(3e38));
  EXPECT_FALSE(fits_scalar<float>(1e39));
  EXPECT_TRUE(fits_scalar<double>(1e39));
  EXPECT_TRUE(fits_scalar<float>(std::numeric_limits<double>::infinity()));  // reported as non-finite instead
  EXPECT_STREQ(scalar_name<float>(), "float");
  EXPECT_STREQ(scalar_name<double>(), "double");
}

}  // namespace
}  // namespace dyncull::text
