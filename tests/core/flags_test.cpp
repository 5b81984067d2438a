// Per-feature flag views carry their count: a kernel can check them before reading, and a pointer without a
// count does not convert.
#include "dyncull/core/flags.hpp"

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

namespace dyncull {
namespace {

static_assert(!std::is_convertible<const std::uint8_t*, FlagView>::value, "a pointer alone must not convert");
static_assert(!std::is_constructible<FlagView, const std::uint8_t*>::value, "a pointer alone must not construct");
static_assert(!std::is_convertible<const std::uint32_t*, BoxBitsView>::value, "a pointer alone must not convert");
static_assert(std::is_convertible<const std::vector<std::uint8_t>&, FlagView>::value, "a vector converts");
static_assert(std::is_convertible<std::nullptr_t, FlagView>::value, "nullptr converts: not given");
static_assert(!std::is_convertible<const std::vector<std::uint32_t>&, FlagView>::value, "element types must match");

TEST(FlagView, DefaultAndNullptrAreNotGivenAndFitAnyCount) {
  const FlagView none, null = nullptr;
  for (const FlagView& v : {none, null}) {
    EXPECT_FALSE(v.given);
    EXPECT_FALSE(v.holds(0));
    EXPECT_FALSE(v.holds(3));
    std::string why = "untouched";
    EXPECT_TRUE(detail::flags_fit(v, 3, "valid", "points", &why));
    EXPECT_EQ(why, "untouched");
  }
}

TEST(FlagView, AVectorIsGivenWithItsSizeAndReadsItsFlags) {
  const std::vector<std::uint8_t> flags{1, 0, 1};
  const FlagView v = flags;
  EXPECT_TRUE(v.given);
  EXPECT_EQ(v.size, 3u);
  EXPECT_EQ(v.data, flags.data());
  EXPECT_TRUE(v.holds(3));
  EXPECT_FALSE(v.holds(2));
  EXPECT_FALSE(v.holds(4));
  EXPECT_EQ(v[0], 1);
  EXPECT_EQ(v[1], 0);
  // An empty vector is given: it holds no flags for ten points, not "all valid".
  const std::vector<std::uint8_t> empty;
  const FlagView e = empty;
  EXPECT_TRUE(e.given);
  EXPECT_TRUE(e.holds(0));
  EXPECT_FALSE(e.holds(10));
}

TEST(FlagView, AMismatchNamesTheParameterAndBothSizes) {
  const std::vector<std::uint8_t> flags(5, 1);
  std::string why;
  EXPECT_FALSE(detail::flags_fit(FlagView(flags), 10, "in_box", "tracks", &why));
  EXPECT_EQ(why, "in_box has 5 entries for 10 tracks");
  EXPECT_TRUE(detail::flags_fit(FlagView(flags), 5, "in_box", "tracks", &why));
  EXPECT_FALSE(detail::flags_fit(FlagView(nullptr, 4), 4, "valid", "points", &why));
  EXPECT_EQ(why, "valid is a null pointer with a count of 4 (4 points)");
  EXPECT_TRUE(detail::flags_fit(FlagView(nullptr, 0), 0, "valid", "points", &why));
  EXPECT_FALSE(detail::flags_fit(FlagView(flags), 10, "in_box", "tracks", nullptr));
}

TEST(BoxBitsView, HoldsPerFeatureBitSets) {
  const std::vector<std::uint32_t> bits{1u, 6u};
  const BoxBitsView v = bits;
  EXPECT_TRUE(v.holds(2));
  EXPECT_EQ(v[1], 6u);
  std::string why;
  EXPECT_FALSE(detail::flags_fit(v, 3, "object_box_bits", "points", &why));
  EXPECT_EQ(why, "object_box_bits has 2 entries for 3 points");
}

}  // namespace
}  // namespace dyncull
