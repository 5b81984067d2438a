/// @file status.hpp
/// Why an algorithm did or did not produce a result. Every result struct in dyncull carries a
/// Status plus a human-readable reason; bad input is reported here, never by crashing or throwing.
#pragma once

/// constexpr where C++14 allows a switch in it; inline in the C++11 headers' users (culling/culler.hpp).
#if __cplusplus >= 201402L
#define DYNCULL_CONSTEXPR14 constexpr
#else
#define DYNCULL_CONSTEXPR14 inline
#endif

namespace dyncull {

/// Outcome of a call. Ok is the only success value; the others name the first reason found.
enum class Status {
  Ok = 0,
  TooFewPoints,   ///< fewer usable inputs than the method needs
  Degenerate,     ///< geometry does not determine the model (collinear, coplanar, parallel, ...)
  NonFinite,      ///< NaN / Inf in the input that could not be skipped
  NotConverged,   ///< an iterative method stopped at its iteration limit
  InvalidInput,   ///< option or argument out of its documented range
  Skipped,        ///< the step did not run (missing pose, no depth, disabled) — not an error
  IoError,        ///< a file could not be read or written
  ParseError,     ///< a file was read but a line could not be parsed
  MissingInput,   ///< an enabled step lacked an input it needs; the result is from the steps that ran
};

/// Stable lower-case name of a status, for logs and reasons.
DYNCULL_CONSTEXPR14 const char* to_string(Status status) noexcept {
  switch (status) {
    case Status::Ok: return "ok";
    case Status::TooFewPoints: return "too few points";
    case Status::Degenerate: return "degenerate";
    case Status::NonFinite: return "non-finite input";
    case Status::NotConverged: return "not converged";
    case Status::InvalidInput: return "invalid input";
    case Status::Skipped: return "skipped";
    case Status::IoError: return "i/o error";
    case Status::ParseError: return "parse error";
    case Status::MissingInput: return "missing input";
  }
  return "unknown";
}

}  // namespace dyncull
