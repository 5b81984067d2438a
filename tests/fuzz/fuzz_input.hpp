// Decodes libFuzzer bytes into values for the fuzz targets: integers, flags, and floating-point
// values that are mostly in a given range and otherwise NaN, +-Inf, huge or raw bit patterns.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>

namespace dyncull::fuzz {

class Input {
 public:
  Input(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  bool empty() const { return pos_ >= size_; }
  std::uint8_t u8() { return pos_ < size_ ? data_[pos_++] : 0; }
  std::uint16_t u16() { return static_cast<std::uint16_t>(u8() | (u8() << 8)); }
  std::uint32_t u32() { return static_cast<std::uint32_t>(u16()) | (static_cast<std::uint32_t>(u16()) << 16); }
  std::uint64_t u64() { return static_cast<std::uint64_t>(u32()) | (static_cast<std::uint64_t>(u32()) << 32); }
  bool flag() { return (u8() & 1) != 0; }
  /// An integer in [lo, hi].
  int range(int lo, int hi) {
    const std::uint64_t span = static_cast<std::uint64_t>(static_cast<std::int64_t>(hi) - lo) + 1;
    return static_cast<int>(lo + static_cast<std::int64_t>(u32() % span));
  }
  /// Uniform in [0, 1].
  double unit() { return u16() / 65535.0; }
  /// Mostly uniform in [lo, hi]; one value in four is special (NaN, +-Inf, huge, the ends, raw bits).
  double value(double lo, double hi) {
    const std::uint8_t k = u8();
    switch (k % 32) {
      case 0: return std::numeric_limits<double>::quiet_NaN();
      case 1: return std::numeric_limits<double>::infinity();
      case 2: return -std::numeric_limits<double>::infinity();
      case 3: return 1e30;
      case 4: return -5e9;
      case 5: return 5e9;
      case 6: return lo;
      case 7: return hi;
      case 8: {
        const std::uint64_t bits = u64();
        double d;
        std::memcpy(&d, &bits, sizeof(d));
        return d;
      }
      default: return lo + (hi - lo) * unit();
    }
  }
  /// value() in T: a finite double beyond T's range becomes +-inf (what an IEEE conversion gives).
  template <class T>
  T scalar(double lo, double hi) {
    const double v = value(lo, hi);
    const double max = static_cast<double>(std::numeric_limits<T>::max());
    if (std::isfinite(v) && std::abs(v) > max) return v > 0 ? std::numeric_limits<T>::infinity() : -std::numeric_limits<T>::infinity();
    return static_cast<T>(v);
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

/// Stops the fuzzer with a message when an invariant of a result does not hold.
#define DYNCULL_FUZZ_CHECK(cond)                                                                  \
  do {                                                                                            \
    if (!(cond)) {                                                                                \
      std::fprintf(stderr, "%s:%d: fuzz invariant failed: %s\n", __FILE__, __LINE__, #cond);      \
      std::abort();                                                                               \
    }                                                                                             \
  } while (0)

}  // namespace dyncull::fuzz
