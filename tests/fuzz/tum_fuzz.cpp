// libFuzzer target: TUM trajectory text (eval/trajectory.hpp) in float and double, strict and
// skipping, under a comma-decimal C locale when one is installed; every accepted trajectory is
// finite, its rotations orthonormal, and it survives a write / read round trip.
#include "dyncull/eval/trajectory.hpp"

#include "fuzz_input.hpp"

#include <clocale>
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

namespace {

using namespace dyncull;

template <class T>
void check(std::string_view text, bool skip) {
  eval::TrajectoryReadOptions options;
  options.skip_invalid_poses = skip;
  const eval::TrajectoryReadResult<T> r = eval::parse_tum_trajectory<T>(text, "fuzz", options);
  // Reasons are bounded whatever the input: a 32-character quote, never the whole token or line.
  DYNCULL_FUZZ_CHECK(r.reason.size() < 300);
  DYNCULL_FUZZ_CHECK(r.reason.find('\0') == std::string::npos);
  DYNCULL_FUZZ_CHECK(r.first_skipped.size() < 300);
  DYNCULL_FUZZ_CHECK((r.num_skipped == 0) == r.first_skipped.empty());
  DYNCULL_FUZZ_CHECK(r.trajectory.stamps.size() == r.trajectory.poses.size());
  if (!r.ok()) {
    DYNCULL_FUZZ_CHECK(r.status == Status::ParseError);
    DYNCULL_FUZZ_CHECK(r.trajectory.empty());
    DYNCULL_FUZZ_CHECK(!r.reason.empty());
    return;
  }
  DYNCULL_FUZZ_CHECK(skip || r.num_skipped == 0);
  for (std::size_t i = 0; i < r.trajectory.size(); ++i) {
    DYNCULL_FUZZ_CHECK(std::isfinite(r.trajectory.stamps[i]));
    const Rigid3<T>& p = r.trajectory.poses[i];
    DYNCULL_FUZZ_CHECK(p.t.allFinite() && p.R.allFinite());
    const Mat3<T> e = p.R.transpose() * p.R - Mat3<T>::Identity();
    DYNCULL_FUZZ_CHECK(e.cwiseAbs().maxCoeff() < T(1e-3));
  }
  std::string written;
  const eval::WriteResult w = eval::format_tum_trajectory(r.trajectory, &written);
  DYNCULL_FUZZ_CHECK(w.ok());
  const eval::TrajectoryReadResult<T> back = eval::parse_tum_trajectory<T>(written, "written");
  DYNCULL_FUZZ_CHECK(back.ok());
  DYNCULL_FUZZ_CHECK(back.num_skipped == 0);
  DYNCULL_FUZZ_CHECK(back.trajectory.size() == r.trajectory.size());
  for (std::size_t i = 0; i < back.trajectory.size(); ++i)
    DYNCULL_FUZZ_CHECK(back.trajectory.poses[i].t == r.trajectory.poses[i].t);  // max_digits10: lossless
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // The parser must not depend on the C locale: run under a comma-decimal one when available.
  if (!std::setlocale(LC_ALL, "de_DE.UTF-8")) std::fprintf(stderr, "tum_fuzz: de_DE.UTF-8 not installed, C locale\n");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  check<double>(text, true);
  check<double>(text, false);
  check<float>(text, true);
  // Single numbers: the grammar never reads past the token and its result is a double.
  if (size <= 600) {
    double v = 0;
    const text::NumberStatus st = text::parse_python_float(text, &v);
    DYNCULL_FUZZ_CHECK(st != text::NumberStatus::TooLong || size > text::kMaxNumberChars);
    const std::string q = text::quote_token(text);
    DYNCULL_FUZZ_CHECK(q.size() <= 4 * text::kQuotedTokenChars + 32);
  }
  return 0;
}
