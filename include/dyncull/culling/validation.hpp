/// @file validation.hpp
/// Small helpers behind the validate() methods of the culling options structs (no paper equation):
/// range checks that fail on NaN, and the call of a nested struct's validate() when it has one.
#pragma once

#include "dyncull/core/status.hpp"

#include <cmath>
#include <string>
#include <type_traits>
#include <utility>

namespace dyncull {
namespace detail {

/// InvalidInput with `field` + `why` as the reason (reason may be nullptr).
inline Status invalid_option(std::string* reason, const char* field, const char* why) {
  if (reason) *reason = std::string(field) + " " + why;
  return Status::InvalidInput;
}

/// lo <= x <= hi and finite (false for NaN).
template <class X>
bool finite_in(X x, double lo, double hi) {
  const double d = static_cast<double>(x);
  return std::isfinite(d) && d >= lo && d <= hi;
}

template <class O, class = void>
struct has_validate : std::false_type {};
template <class O>
struct has_validate<O, std::void_t<decltype(std::declval<const O&>().validate(static_cast<std::string*>(nullptr)))>>
    : std::true_type {};

/// Runs o.validate() when the struct has one; the reason is prefixed with `name` and a dot.
template <class O>
Status validate_nested(const O& o, const char* name, std::string* reason) {
  if constexpr (has_validate<O>::value) {
    std::string why;
    const Status s = o.validate(&why);
    if (s != Status::Ok) {
      if (reason) *reason = std::string(name) + "." + why;
      return s;
    }
  } else {
    (void)o;
    (void)name;
    (void)reason;
  }
  return Status::Ok;
}

}  // namespace detail
}  // namespace dyncull
