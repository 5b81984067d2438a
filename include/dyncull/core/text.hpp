/// @file text.hpp
/// Locale-independent, bounded number parsing for dyncull's text readers (TUM trajectories, YOLO
/// labels): the grammar of Python's float() (no paper equation; both formats are written by Python).
#pragma once

#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <system_error>

namespace dyncull::text {

/// Longest number token accepted: the longest double that printf("%.9f") writes is 319 characters.
constexpr std::size_t kMaxNumberChars = 512;
/// Longest data line accepted by the line readers (comment lines are skipped whatever their length).
constexpr std::size_t kMaxLineChars = 8192;
/// Characters of a bad token quoted in a reason.
constexpr std::size_t kQuotedTokenChars = 32;

enum class NumberStatus : std::uint8_t { Ok = 0, Empty, TooLong, Invalid };

namespace detail {
inline bool is_digit(char c) { return c >= '0' && c <= '9'; }
inline bool iequals(std::string_view a, const char* lower) {
  std::size_t i = 0;
  for (; i < a.size() && lower[i] != '\0'; ++i) {
    const char c = (a[i] >= 'A' && a[i] <= 'Z') ? static_cast<char>(a[i] - 'A' + 'a') : a[i];
    if (c != lower[i]) return false;
  }
  return i == a.size() && lower[i] == '\0';
}

/// inf / infinity / nan in any case (after the sign) into `out`; false for any other word.
inline bool parse_float_word(std::string_view body, bool negative, double* out) {
  if (iequals(body, "inf") || iequals(body, "infinity")) {
    *out = negative ? -std::numeric_limits<double>::infinity() : std::numeric_limits<double>::infinity();
    return true;
  }
  if (iequals(body, "nan")) {
    *out = std::numeric_limits<double>::quiet_NaN();
    return true;
  }
  return false;
}

/// A number token read from position j on, its digits copied without underscores into buf for from_chars
/// (which never consults the locale), with what telling overflow from underflow needs.
struct PythonFloatDigits {
  std::string_view token;
  std::size_t j;                      // next character of token
  char buf[kMaxNumberChars + 1];
  std::size_t n = 0;                  // characters in buf
  std::size_t num_int = 0;            // integer digits
  std::ptrdiff_t first_nonzero = -1;  // position of the first non-zero mantissa digit
  std::size_t num_mantissa = 0;
  long long exponent = 0;             // saturated: only its sign matters

  PythonFloatDigits(std::string_view t, std::size_t start) : token(t), j(start) {}

  bool at_digit() const { return j < token.size() && is_digit(token[j]); }

  /// digitpart ::= digit (["_"] digit)*; counts the digits as mantissa digits when `mantissa`.
  bool digitpart(bool mantissa) {
    const std::size_t size = token.size();
    if (!at_digit()) return false;
    while (j < size) {
      if (is_digit(token[j])) {
        if (mantissa) {
          if (first_nonzero < 0 && token[j] != '0') first_nonzero = static_cast<std::ptrdiff_t>(num_mantissa);
          ++num_mantissa;
        }
        buf[n++] = token[j++];
      } else if (token[j] == '_' && j + 1 < size && is_digit(token[j + 1])) {
        ++j;
      } else if (token[j] == '_') {
        return false;
      } else {
        break;
      }
    }
    return true;
  }

  /// Integer digits, then an optional '.' and fraction digits; at least one digit in all.
  bool mantissa() {
    bool has_digits = false;
    if (at_digit()) {
      if (!digitpart(true)) return false;
      num_int = num_mantissa;
      has_digits = true;
    }
    if (j < token.size() && token[j] == '.') {
      buf[n++] = token[j++];
      if (at_digit()) {
        if (!digitpart(true)) return false;
        has_digits = true;
      }
    }
    return has_digits;
  }

  /// An optional exponent: e/E, an optional sign, digits.
  bool exponent_part() {
    if (!(j < token.size() && (token[j] == 'e' || token[j] == 'E'))) return true;
    buf[n++] = token[j++];
    bool exp_negative = false;
    if (j < token.size() && (token[j] == '+' || token[j] == '-')) {
      exp_negative = token[j] == '-';
      buf[n++] = token[j++];
    }
    const std::size_t exp_start = n;
    if (!digitpart(false)) return false;
    for (std::size_t k = exp_start; k < n; ++k) {
      if (exponent < 1000000000LL) exponent = exponent * 10 + (buf[k] - '0');  // saturates: only the sign matters
    }
    if (exp_negative) exponent = -exponent;
    return true;
  }

  /// +-inf or +-0 for a value out of the double range: the decimal magnitude of the leading digit says which.
  double out_of_range_value(bool negative) const {
    const long long magnitude =
        static_cast<long long>(num_int) - 1 - static_cast<long long>(first_nonzero < 0 ? 0 : first_nonzero) + exponent;
    const double big = magnitude > 0 ? std::numeric_limits<double>::infinity() : 0.0;
    return negative ? -big : big;
  }
};
}  // namespace detail

/// One number as Python's float() reads it, whatever the C or C++ locale: [sign] then digits with
/// single underscores between them ("1_000"), an optional '.' and fraction, an optional exponent
/// (e/E, sign, digits), or inf / infinity / nan in any case. Values beyond the double range become
/// +-inf, values below it +-0, as in Python. ASCII digits only; no surrounding whitespace; at most
/// kMaxNumberChars characters (TooLong otherwise: the token is never copied).
inline NumberStatus parse_python_float(std::string_view token, double* out) {
  if (token.empty()) return NumberStatus::Empty;
  if (token.size() > kMaxNumberChars) return NumberStatus::TooLong;
  const bool negative = token[0] == '-';
  const std::size_t sign_chars = (token[0] == '+' || token[0] == '-') ? 1 : 0;
  if (detail::parse_float_word(token.substr(sign_chars), negative, out)) return NumberStatus::Ok;
  detail::PythonFloatDigits d(token, sign_chars);
  if (negative) d.buf[d.n++] = '-';
  if (!d.mantissa() || !d.exponent_part() || d.j != token.size()) return NumberStatus::Invalid;
  double value = 0;
  const std::from_chars_result res = std::from_chars(d.buf, d.buf + d.n, value);
  if (res.ec == std::errc::result_out_of_range) {
    value = d.out_of_range_value(negative);
  } else if (res.ec != std::errc() || res.ptr != d.buf + d.n) {
    return NumberStatus::Invalid;
  }
  *out = value;
  return NumberStatus::Ok;
}

/// User text for a reason: the one quoting rule of every reader and command line (tokens, keys,
/// arguments, paths). At most `max_chars` characters; bytes outside printable ASCII, the backslash and
/// (when quoting) the single quote as `\xHH`, so terminal escapes, NULs and newlines never reach the
/// reason; then "... (N bytes)" when cut. `quoted` wraps it in single quotes ('x,5').
inline std::string quote_token(std::string_view token, std::size_t max_chars = kQuotedTokenChars, bool quoted = true) {
  static const char* const kHex = "0123456789abcdef";
  std::string out = quoted ? "'" : "";
  const std::size_t start = out.size();
  std::size_t shown = 0;  // bytes of token shown; an escaped byte takes four of the max_chars characters
  for (; shown < token.size(); ++shown) {
    const unsigned char c = static_cast<unsigned char>(token[shown]);
    const bool plain = c >= 0x20 && c < 0x7f && !(quoted && c == '\'') && c != '\\';
    if (out.size() - start + (plain ? 1 : 4) > max_chars) break;
    if (plain) {
      out += static_cast<char>(c);
    } else {
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
    }
  }
  if (quoted) out += '\'';
  if (shown < token.size()) out += "... (" + std::to_string(token.size()) + " bytes)";
  return out;
}

/// Characters of a path shown in a reason (longer ones are cut as quote_token says).
constexpr std::size_t kQuotedPathChars = 1024;

/// A path for the "path:line: why" of a reason: quote_token's escaping without the quotes.
inline std::string quote_path(std::string_view path) { return quote_token(path, kQuotedPathChars, false); }

/// A real number read from user text as an integer: true and `*out` set when `v` is an integer in
/// [lo, hi]; false (`*out` untouched) for NaN, Inf, a fraction or a value outside, so nothing is ever
/// converted out of range. The test runs in double before the conversion.
inline bool integer_in_range(double v, long long lo, long long hi, long long* out) {
  if (!(v >= static_cast<double>(lo) && v <= static_cast<double>(hi)) || v != std::floor(v)) return false;
  // lo and hi may round outward in double (|x| > 2^53): clamp after converting a value known to fit in 2^63.
  if (!(std::abs(v) < 9223372036854775808.0)) return false;
  const long long n = static_cast<long long>(v);  // checked: integral and |v| < 2^63 above
  if (n < lo || n > hi) return false;
  *out = n;
  return true;
}

/// Name of a floating-point scalar type in reasons.
template <class T>
constexpr const char* scalar_name() {
  return sizeof(T) == sizeof(float) ? "float" : (sizeof(T) == sizeof(double) ? "double" : "long double");
}

/// Whether a double fits T's finite range (non-finite values pass: they are reported as such).
template <class T>
bool fits_scalar(double v) {
  return !std::isfinite(v) || std::abs(v) <= static_cast<double>(std::numeric_limits<T>::max());
}

}  // namespace dyncull::text
