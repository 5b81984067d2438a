// Status names are part of every reason string users grep their logs for: they must be distinct,
// stable and usable at compile time.
#include "dyncull/core/status.hpp"

#include <gtest/gtest.h>

#include <set>
#include <string>

namespace dyncull {
namespace {

constexpr Status kAll[] = {Status::Ok,           Status::TooFewPoints, Status::Degenerate,
                           Status::NonFinite,    Status::NotConverged, Status::InvalidInput,
                           Status::Skipped,      Status::IoError,      Status::ParseError,
                           Status::MissingInput};

TEST(Status, NamesAreDistinctLowerCaseAndKnown) {
  std::set<std::string> names;
  for (Status s : kAll) {
    const std::string name = to_string(s);
    EXPECT_NE(name, "unknown");
    EXPECT_FALSE(name.empty());
    for (char c : name) EXPECT_FALSE(c >= 'A' && c <= 'Z') << name;
    names.insert(name);
  }
  EXPECT_EQ(names.size(), sizeof(kAll) / sizeof(kAll[0]));
}

TEST(Status, OkIsZeroAndNamesAreStable) {
  static_assert(static_cast<int>(Status::Ok) == 0, "Ok must be the zero value (value-initialised results are Ok)");
  static_assert(to_string(Status::Ok)[0] == 'o', "to_string is usable in constant expressions");
  EXPECT_STREQ(to_string(Status::Ok), "ok");
  EXPECT_STREQ(to_string(Status::Degenerate), "degenerate");
  EXPECT_STREQ(to_string(Status::Skipped), "skipped");
  EXPECT_STREQ(to_string(Status::MissingInput), "missing input");
  EXPECT_STREQ(to_string(static_cast<Status>(99)), "unknown");
}

}  // namespace
}  // namespace dyncull
