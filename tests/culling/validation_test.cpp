// Tests of culling/validation.hpp: the range check fails on NaN and infinities, the reason names the field,
// and a nested struct's validate() is called with its name as the prefix of the reason.
#include "dyncull/culling/validation.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <string>

namespace dyncull {
namespace {

struct WithValidate {
  double value = 1;
  Status validate(std::string* reason) const {
    return value > 0 ? Status::Ok : detail::invalid_option(reason, "value", "must be positive");
  }
};
struct WithoutValidate {};

TEST(OptionValidation, FiniteInRejectsNanInfinityAndOutOfRange) {
  EXPECT_TRUE(detail::finite_in(0.5f, 0.0, 1.0));
  EXPECT_TRUE(detail::finite_in(1, 0.0, 1.0));
  EXPECT_FALSE(detail::finite_in(std::numeric_limits<double>::quiet_NaN(), 0.0, 1.0));
  EXPECT_FALSE(detail::finite_in(std::numeric_limits<float>::infinity(), 0.0, 1e300));
  EXPECT_FALSE(detail::finite_in(-0.1, 0.0, 1.0));
  EXPECT_FALSE(detail::finite_in(2.0, 0.0, 1.0));
}

TEST(OptionValidation, InvalidOptionNamesTheFieldAndAcceptsNoReason) {
  std::string reason;
  EXPECT_EQ(detail::invalid_option(&reason, "eps_m", "must be positive"), Status::InvalidInput);
  EXPECT_EQ(reason, "eps_m must be positive");
  EXPECT_EQ(detail::invalid_option(nullptr, "eps_m", "must be positive"), Status::InvalidInput);
}

TEST(OptionValidation, NestedValidateIsPrefixedWithItsName) {
  std::string reason;
  EXPECT_EQ(detail::validate_nested(WithValidate{}, "depth_mask", &reason), Status::Ok);
  EXPECT_TRUE(reason.empty());
  EXPECT_EQ(detail::validate_nested(WithValidate{-1}, "depth_mask", &reason), Status::InvalidInput);
  EXPECT_EQ(reason, "depth_mask.value must be positive");
  EXPECT_EQ(detail::validate_nested(WithoutValidate{}, "levels", &reason), Status::Ok);
}

}  // namespace
}  // namespace dyncull
