/// @file flags.hpp
/// Non-owning views of per-feature flags (and per-feature box bit sets) that carry their count, so a
/// kernel checks them against its points before reading one. No paper equation: the input contract.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace dyncull {

/// Per-element values of a parallel input with their count. Built from a std::vector (implicitly) or a
/// pointer and a count: then `given`, and a kernel checks `size` against its points (an empty vector for
/// ten points is a mismatch, not "no flags"). Default or nullptr: not given. A pointer alone does not
/// convert: a count is needed to check it.
template <class Flag>
struct ArrayView {
  const Flag* data = nullptr;
  std::size_t size = 0;
  bool given = false;

  constexpr ArrayView() = default;
  constexpr ArrayView(std::nullptr_t) {}  // NOLINT(google-explicit-constructor): nullptr means "not given"
  constexpr ArrayView(const Flag* values, std::size_t count) : data(values), size(count), given(true) {}
  ArrayView(const std::vector<Flag>& values)  // NOLINT(google-explicit-constructor)
      : data(values.data()), size(values.size()), given(true) {}
  ArrayView(const Flag* values) = delete;  // a pointer without its count cannot be checked

  /// Given, and readable for n entries.
  constexpr bool holds(std::size_t n) const { return given && size == n && (data != nullptr || n == 0); }
  constexpr Flag operator[](std::size_t i) const { return data[i]; }
};

/// Per-feature flags (nonzero: set).
using FlagView = ArrayView<std::uint8_t>;
/// Per-feature bit sets (bit b: the feature lies in box b).
using BoxBitsView = ArrayView<std::uint32_t>;

namespace detail {
/// True when `view` is not given or holds n entries; else false with `reason` naming the parameter and both
/// sizes, e.g. "valid has 5 flags for 10 keypoints".
template <class Flag>
bool flags_fit(const ArrayView<Flag>& view, std::size_t n, const char* name, const char* elements,
               std::string* reason) {
  if (!view.given || view.holds(n)) return true;
  if (reason) {
    *reason = view.data == nullptr && view.size > 0
                  ? std::string(name) + " is a null pointer with a count of " + std::to_string(view.size) + " (" +
                        std::to_string(n) + " " + elements + ")"
                  : std::string(name) + " has " + std::to_string(view.size) + " entries for " + std::to_string(n) +
                        " " + elements;
  }
  return false;
}
}  // namespace detail

}  // namespace dyncull
