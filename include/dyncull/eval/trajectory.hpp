/// @file trajectory.hpp
/// TUM RGB-D trajectory files (`timestamp tx ty tz qx qy qz qw`) and timestamp association exactly as
/// the TUM benchmark's associate.py (all pairs with |dt| < 0.02 s, greedy by |dt|, each stamp once).
#pragma once

#include "dyncull/core/status.hpp"
#include "dyncull/core/text.hpp"
#include "dyncull/core/text_file.hpp"
#include "dyncull/core/types.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <functional>
#include <limits>
#include <queue>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

namespace dyncull::eval {

/// A stamped pose sequence in parallel arrays (stamps in seconds, poses world_from_cam: the TUM
/// convention, the camera's pose in the world frame). Order and duplicates are kept as given; the
/// evaluation functions sort by stamp and resolve duplicate stamps themselves.
template <class T>
struct Trajectory {
  std::vector<double> stamps;          ///< seconds; double whatever T is (1.3e9 s needs 53 bits)
  std::vector<Rigid3<T>> poses;        ///< world_from_cam

  std::size_t size() const { return stamps.size(); }
  bool empty() const { return stamps.empty(); }
  void clear() {
    stamps.clear();
    poses.clear();
  }
  void reserve(std::size_t n) {
    stamps.reserve(n);
    poses.reserve(n);
  }
  void push_back(double stamp, const Rigid3<T>& world_from_cam) {
    stamps.push_back(stamp);
    poses.push_back(world_from_cam);
  }
};

/// Parsing policy.
struct TrajectoryReadOptions {
  /// Lines whose values contain NaN/Inf (1e400 included), whose quaternion is (near) zero or whose
  /// translation is outside T's range are skipped and counted,
  /// as evaluate_rpe.py's read_trajectory does; false turns them into a ParseError.
  bool skip_invalid_poses = true;
  /// Lines read at most (comments and blank lines included); more is a ParseError. Bounds the memory
  /// of a file that is not a trajectory: a pose takes about 100 bytes, so 1,000,000 poses (2.8 hours
  /// at 100 Hz) take about 100 MB.
  std::size_t max_lines = 1000000;
};

template <class T>
struct TrajectoryReadResult {
  Status status = Status::Ok;
  std::string reason;  ///< "path:line: what is wrong" on ParseError, "path: why" on IoError
  bool ok() const { return status == Status::Ok; }
  Trajectory<T> trajectory;
  std::size_t num_skipped = 0;   ///< invalid pose lines skipped (see TrajectoryReadOptions)
  std::string first_skipped;     ///< "path:line: why" of the first skipped line, empty if none
};

struct TrajectoryWriteOptions {
  int stamp_decimals = 6;  ///< in [0, 9]; TUM writes microseconds
  int value_digits = 0;    ///< in [0, 17]: significant digits of tx..qw; 0 = max_digits10 of T (lossless round trip)
};

struct WriteResult {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }
};

/// Association policy (associate.py --offset / --max_difference).
struct AssociationOptions {
  double max_difference_s = 0.02;  ///< pairs need |t_first - (t_second + offset)| < this (strict, as TUM)
  double offset_s = 0.0;           ///< added to the second list's stamps

  /// Upper bound of max_difference_s: a wider window pairs poses seconds apart.
  static constexpr double kMaxDifferenceS = 10.0;

  /// Ok, or InvalidInput with a reason naming the field.
  Status validate(std::string* reason = nullptr) const {
    auto bad = [&](const char* why) {
      if (reason) *reason = why;
      return Status::InvalidInput;
    };
    if (!(max_difference_s > 0.0) || !(max_difference_s <= kMaxDifferenceS))
      return bad("AssociationOptions: max_difference_s must be in (0, 10] seconds");
    if (!std::isfinite(offset_s)) return bad("AssociationOptions: offset_s must be finite");
    if (reason) reason->clear();
    return Status::Ok;
  }
};

/// Matched index pairs into the two input stamp arrays, sorted by the first stamp (associate.py's
/// final matches.sort()).
struct AssociationResult {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }
  std::vector<std::uint32_t> first;
  std::vector<std::uint32_t> second;
  std::size_t num_duplicates_first = 0;   ///< entries ignored because a later entry had the same stamp
  std::size_t num_duplicates_second = 0;
  std::size_t size() const { return first.size(); }
};

/// Parses TUM text. `source` names the text in error messages ("path:line: ..."). Numbers follow
/// Python's float() whatever the locale (core/text.hpp): 1e400 is inf (the line is then skipped as
/// non-finite), "1_000" is 1000, "+-5" is an error. Separators: space, tab, comma. A data line longer
/// than text::kMaxLineChars or a number longer than text::kMaxNumberChars is a ParseError; reasons
/// quote at most 32 characters of a bad token, escaped (and `source` is escaped by text::quote_path).
/// More than options.max_lines lines is a ParseError. A translation outside T's range (1e39 for
/// float) is an invalid pose, skipped or rejected as TrajectoryReadOptions says.
template <class T>
TrajectoryReadResult<T> parse_tum_trajectory(std::string_view text, const std::string& source = "<memory>",
                                             const TrajectoryReadOptions& options = {});

/// Reads a TUM file line by line (text::LineReader: memory bounded by the line limit and
/// options.max_lines, whatever the file holds). IoError when the path is not a regular file (a
/// directory, a FIFO, a device such as /dev/zero: refused before reading) or cannot be opened or
/// read; ParseError with "path:line: ..." otherwise, the path escaped as text::quote_path does.
template <class T = double>
TrajectoryReadResult<T> read_tum_trajectory(const std::string& path, const TrajectoryReadOptions& options = {});

/// TUM text of a trajectory (qw >= 0, one line per pose, no header), in the C locale's number format
/// whatever the process locale. InvalidInput for options out of range or stamps/poses of different
/// sizes or a rotation that is not orthonormal (zero, scaled); NonFinite for a pose whose stamp,
/// translation or rotation is not finite. The whole call fails and `out` is left empty: never a file
/// with a gap the reader would skip.
template <class T>
WriteResult format_tum_trajectory(const Trajectory<T>& trajectory, std::string* out,
                                  const TrajectoryWriteOptions& options = {});

/// The same text, or "" when format_tum_trajectory above fails.
template <class T>
std::string format_tum_trajectory(const Trajectory<T>& trajectory, const TrajectoryWriteOptions& options = {});

template <class T>
WriteResult write_tum_trajectory(const std::string& path, const Trajectory<T>& trajectory,
                                 const TrajectoryWriteOptions& options = {});

/// associate.py: every (a, b) with |a - (b + offset)| < max_difference is a candidate; candidates are
/// sorted by (difference, a, b) and taken greedily so each stamp is used once. Equal stamps within one
/// list count as one stamp, the later entry winning (Python dict semantics). NonFinite when a stamp is
/// NaN or Inf (a file never gives one: the reader skips such lines), the reason naming the list, the
/// index, the value and how many there are; TooFewPoints when nothing associates; InvalidInput when
/// options.validate() fails.
/// Cost: memory O(n + m) whatever the window holds; time O((n + m) log(n + m)) (TUM's script is O(n m)
/// in both).
inline AssociationResult associate(const double* first, std::size_t num_first, const double* second,
                                   std::size_t num_second, const AssociationOptions& options = {});

inline AssociationResult associate(const std::vector<double>& first, const std::vector<double>& second,
                                   const AssociationOptions& options = {}) {
  return associate(first.data(), first.size(), second.data(), second.size(), options);
}

// ------------------------------------------------------------------------------------------------
// Implementation
// ------------------------------------------------------------------------------------------------
namespace detail {

/// Indices of the finite stamps sorted by stamp; of equal stamps only the last index is kept.
/// Returns the number of dropped duplicates.
inline std::size_t sorted_unique_stamp_order(const double* stamps, std::size_t n, std::vector<std::uint32_t>* order) {
  order->clear();
  order->reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (std::isfinite(stamps[i])) order->push_back(static_cast<std::uint32_t>(i));
  }
  // Stable sort keeps file order among equal stamps, so the last of a run is the last in the file.
  // Trajectory files are almost always written in time order: check before sorting.
  const auto by_stamp = [stamps](std::uint32_t a, std::uint32_t b) { return stamps[a] < stamps[b]; };
  if (!std::is_sorted(order->begin(), order->end(), by_stamp)) std::stable_sort(order->begin(), order->end(), by_stamp);
  std::size_t kept = 0;
  std::size_t dropped = 0;
  for (std::size_t k = 0; k < order->size(); ++k) {
    if (k + 1 < order->size() && stamps[(*order)[k + 1]] == stamps[(*order)[k]]) {
      ++dropped;
      continue;
    }
    (*order)[kept++] = (*order)[k];
  }
  order->resize(kept);
  return dropped;
}

/// Unused positions of a sorted list, found in amortised constant time: the nearest unused position at
/// or after (at or before) a given one, by union-find with path halving over two link arrays.
class UnusedPositions {
 public:
  explicit UnusedPositions(std::size_t n) : right_(n + 1), left_(n + 1) {
    for (std::size_t k = 0; k <= n; ++k) right_[k] = left_[k] = static_cast<std::uint32_t>(k);
  }
  /// The first unused position >= j, or n when there is none.
  std::uint32_t at_or_after(std::uint32_t j) { return find(&right_, j); }
  /// The last unused position <= j, or kNone when there is none.
  std::uint32_t at_or_before(std::uint32_t j) {
    const std::uint32_t k = find(&left_, j + 1);  // left_ is shifted by one: slot 0 means "none"
    return k == 0 ? kNone : k - 1;
  }
  void use(std::uint32_t j) {
    right_[j] = j + 1;
    left_[j + 1] = j;
  }
  static constexpr std::uint32_t kNone = 0xffffffffu;

 private:
  static std::uint32_t find(std::vector<std::uint32_t>* links, std::uint32_t k) {
    std::vector<std::uint32_t>& p = *links;
    while (p[k] != k) {
      p[k] = p[p[k]];
      k = p[k];
    }
    return k;
  }
  std::vector<std::uint32_t> right_, left_;
};

/// associate.py's greedy matching (every pair with |a - (b + offset)| < max_diff, taken in the order of
/// (difference, a, b), each stamp once) without listing the pairs: the next pair taken is the smallest
/// of each unused a's best unused b, kept in a heap and refreshed when its b is taken. |a - (b + offset)|
/// does not decrease as b moves away from a in the sorted list, so an a's best b is the nearest unused
/// one on either side (on the left, the first of a run of equal differences). `a` and `b` are positions
/// of sorted distinct stamps. Returns (position in a, position in b) pairs sorted by a. Memory O(n + m).
inline std::vector<std::pair<std::uint32_t, std::uint32_t>> greedy_nearest_pairs(
    const double* first, const std::vector<std::uint32_t>& a, const double* second,
    const std::vector<std::uint32_t>& b, double offset, double max_diff) {
  const std::uint32_t nb = static_cast<std::uint32_t>(b.size());
  const auto shifted = [&](std::uint32_t j) { return second[b[j]] + offset; };
  const auto diff_of = [&](std::uint32_t i, std::uint32_t j) { return std::abs(first[a[i]] - shifted(j)); };
  // split[i]: the first b position whose shifted stamp is >= a's stamp (both lists sorted).
  std::vector<std::uint32_t> split(a.size());
  for (std::uint32_t i = 0, j = 0; i < a.size(); ++i) {
    while (j < nb && shifted(j) < first[a[i]]) ++j;
    split[i] = j;
  }
  UnusedPositions unused(b.size());
  struct Best {
    double diff;
    std::uint32_t i, j;
    bool operator>(const Best& o) const {
      return diff > o.diff || (diff == o.diff && (i > o.i || (i == o.i && j > o.j)));
    }
  };
  // a's best unused b within the window, if any.
  const auto best_of = [&](std::uint32_t i, Best* out) {
    bool found = false;
    const std::uint32_t r = unused.at_or_after(split[i]);
    if (r < nb && diff_of(i, r) < max_diff) {
      *out = Best{diff_of(i, r), i, r};
      found = true;
    }
    std::uint32_t l = split[i] == 0 ? UnusedPositions::kNone : unused.at_or_before(split[i] - 1);
    if (l != UnusedPositions::kNone && diff_of(i, l) < max_diff) {
      const double d = diff_of(i, l);
      // Ties go to the smaller b: walk to the first of the unused b's at this same difference.
      for (std::uint32_t k; l > 0 && (k = unused.at_or_before(l - 1)) != UnusedPositions::kNone && diff_of(i, k) == d;)
        l = k;
      if (!found || !(d > out->diff)) *out = Best{d, i, l};  // equal difference: the left b is smaller
      found = true;
    }
    return found;
  };
  std::priority_queue<Best, std::vector<Best>, std::greater<Best>> heap;
  for (std::uint32_t i = 0; i < a.size(); ++i) {
    Best best{};
    if (best_of(i, &best)) heap.push(best);
  }
  std::vector<std::uint8_t> used_b(b.size(), 0);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> matches;
  while (!heap.empty()) {
    const Best top = heap.top();
    heap.pop();
    if (used_b[top.j]) {  // taken since: this a's best is now further away (never nearer)
      Best next{};
      if (best_of(top.i, &next)) heap.push(next);
      continue;
    }
    used_b[top.j] = 1;
    unused.use(top.j);
    matches.emplace_back(top.i, top.j);
  }
  std::sort(matches.begin(), matches.end());
  return matches;
}

inline bool is_separator(char c) { return c == ' ' || c == '\t' || c == ',' || c == '\r' || c == '\v' || c == '\f'; }

/// Appends `v` in C-locale %.*f (fixed) or %.*g (general) form: std::to_chars never consults the locale.
/// False (nothing appended) if it does not fit, which the validated precisions rule out.
inline bool append_number(std::string* out, double v, std::chars_format format, int precision) {
  char buf[400];  // fixed DBL_MAX with 9 decimals is 320 characters; precision is validated to <= 17
  const std::to_chars_result res = std::to_chars(buf, buf + sizeof(buf), v, format, precision);
  if (res.ec != std::errc()) return false;
  out->append(buf, static_cast<std::size_t>(res.ptr - buf));
  return true;
}

}  // namespace detail

namespace detail {

/// Reads one TUM line (`line` holds at most text::kMaxLineChars bytes of a line `line_chars` long) into
/// `result`. False when reading must stop: `result` then holds the ParseError, its reason starting with
/// where(). Blank and comment lines are skipped whatever their length.
template <class T, class Where>
bool add_tum_line(std::string_view line, std::size_t line_chars, const Where& where,
                  const TrajectoryReadOptions& options, TrajectoryReadResult<T>* result) {
  const auto fail = [&](const std::string& why) {
    result->status = Status::ParseError;
    result->reason = where() + why;
    result->trajectory.clear();
    return false;
  };
  std::string_view tokens[8];
  std::size_t num_tokens = 0;
  std::size_t k = 0;
  while (k < line.size() && is_separator(line[k])) ++k;
  if (k == line.size() && line_chars == line.size()) return true;  // blank line
  if (k < line.size() && line[k] == '#') return true;               // comment
  if (line_chars > text::kMaxLineChars) {
    return fail("line is " + std::to_string(line_chars) + " bytes long (limit " + std::to_string(text::kMaxLineChars) +
                ")");
  }
  while (k < line.size()) {
    const std::size_t start = k;
    while (k < line.size() && !is_separator(line[k])) ++k;
    if (num_tokens < 8) tokens[num_tokens] = line.substr(start, k - start);
    ++num_tokens;
    while (k < line.size() && is_separator(line[k])) ++k;
  }
  if (num_tokens != 8) {
    return fail("expected 8 values (timestamp tx ty tz qx qy qz qw), found " + std::to_string(num_tokens));
  }
  double v[8];
  static const char* const kNames[8] = {"timestamp", "tx", "ty", "tz", "qx", "qy", "qz", "qw"};
  for (int c = 0; c < 8; ++c) {
    const text::NumberStatus parsed = text::parse_python_float(tokens[c], &v[c]);
    if (parsed == text::NumberStatus::TooLong) {
      return fail(std::string(kNames[c]) + " " + text::quote_token(tokens[c]) + " is longer than " +
                  std::to_string(text::kMaxNumberChars) + " characters");
    }
    if (parsed != text::NumberStatus::Ok) {
      return fail(std::string(kNames[c]) + " " + text::quote_token(tokens[c]) + " is not a number");
    }
  }
  std::string invalid;
  bool finite = true;
  for (double x : v) finite = finite && std::isfinite(x);
  const double qnorm2 = v[4] * v[4] + v[5] * v[5] + v[6] * v[6] + v[7] * v[7];
  if (!finite) {
    invalid = "non-finite value";
  } else if (!(qnorm2 > 1e-12)) {
    // TUM skips all-zero quaternions (a common "lost tracking" marker); a near-zero one has no
    // meaningful direction either.
    invalid = "zero quaternion";
  } else {
    for (int c = 1; c < 4 && invalid.empty(); ++c) {
      // A finite double beyond T's range would become inf (undefined behaviour in the cast).
      if (!text::fits_scalar<T>(v[c])) {
        invalid = std::string(kNames[c]) + " " + text::quote_token(tokens[c]) + " is out of range for " +
                  text::scalar_name<T>();
      }
    }
  }
  if (!invalid.empty()) {
    if (!options.skip_invalid_poses) return fail(invalid);
    if (result->num_skipped == 0) result->first_skipped = where() + invalid;
    ++result->num_skipped;
    return true;
  }
  // Rotation in double from the normalised quaternion (transform44 in evaluate_rpe.py), then cast.
  const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
  Rigid3<double> pose;
  pose.R = q.normalized().toRotationMatrix();
  pose.t = Vec3<double>(v[1], v[2], v[3]);
  result->trajectory.push_back(v[0], pose.template cast<T>());
  return true;
}

}  // namespace detail

template <class T>
TrajectoryReadResult<T> parse_tum_trajectory(std::string_view text, const std::string& source,
                                             const TrajectoryReadOptions& options) {
  TrajectoryReadResult<T> result;
  const std::string shown = text::quote_path(source);
  std::size_t line_number = 0;
  const auto where = [&]() { return shown + ":" + std::to_string(line_number) + ": "; };
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t eol = text.find('\n', pos);
    if (eol == std::string_view::npos) eol = text.size();
    const std::string_view line = text.substr(pos, eol - pos);
    pos = eol + 1;
    if (line_number >= options.max_lines) {
      result.status = Status::ParseError;
      result.reason = shown + ": more than " + std::to_string(options.max_lines) + " lines";
      result.trajectory.clear();
      return result;
    }
    ++line_number;
    // What a LineReader would hand over: the first kMaxLineChars bytes and the length.
    if (!detail::add_tum_line(line.substr(0, text::kMaxLineChars), line.size(), where, options, &result)) return result;
  }
  return result;
}

template <class T>
TrajectoryReadResult<T> read_tum_trajectory(const std::string& path, const TrajectoryReadOptions& options) {
  TrajectoryReadResult<T> result;
  text::LineReaderOptions limits;
  limits.max_lines = options.max_lines;
  text::LineReader in;
  if (!in.open(path, limits)) {
    result.status = Status::IoError;
    result.reason = in.error();
    return result;
  }
  const auto where = [&]() { return text::line_location(in); };
  std::string_view line;
  for (text::LineStatus s; (s = in.next(&line)) != text::LineStatus::End;) {
    if (s == text::LineStatus::TooManyLines || s == text::LineStatus::ReadError) {
      result.status = s == text::LineStatus::ReadError ? Status::IoError : Status::ParseError;
      result.reason = in.error();
      result.trajectory.clear();
      return result;
    }
    if (!detail::add_tum_line(line, in.line_chars(), where, options, &result)) return result;
  }
  return result;
}

template <class T>
WriteResult format_tum_trajectory(const Trajectory<T>& trajectory, std::string* out,
                                  const TrajectoryWriteOptions& options) {
  WriteResult result;
  out->clear();
  if (options.value_digits < 0 || options.value_digits > 17) {
    result.status = Status::InvalidInput;
    result.reason = "value_digits must be in [0, 17] (0: max_digits10), got " + std::to_string(options.value_digits);
    return result;
  }
  if (options.stamp_decimals < 0 || options.stamp_decimals > 9) {
    result.status = Status::InvalidInput;
    result.reason = "stamp_decimals must be in [0, 9], got " + std::to_string(options.stamp_decimals);
    return result;
  }
  if (trajectory.stamps.size() != trajectory.poses.size()) {
    result.status = Status::InvalidInput;
    result.reason = "trajectory has " + std::to_string(trajectory.stamps.size()) + " stamps but " +
                    std::to_string(trajectory.poses.size()) + " poses";
    return result;
  }
  const int digits = options.value_digits > 0 ? options.value_digits : std::numeric_limits<T>::max_digits10;
  out->reserve(trajectory.size() * 128);
  for (std::size_t i = 0; i < trajectory.size(); ++i) {
    const Rigid3<T>& p = trajectory.poses[i];
    Eigen::Quaternion<double> q(p.R.template cast<double>());
    q.normalize();
    if (q.w() < 0) q.coeffs() = -q.coeffs();  // one of the two equivalent signs, deterministically
    // A NaN pose in a TUM file reads back as a skipped line, a silent gap in the evaluation: refuse it.
    const char* bad = !std::isfinite(trajectory.stamps[i]) ? "stamp"
                      : !p.t.allFinite()                    ? "translation"
                      : !(p.R.allFinite() && q.coeffs().allFinite()) ? "rotation"
                                                                      : nullptr;
    if (bad) {
      result.status = Status::NonFinite;
      result.reason = "pose " + std::to_string(i) + ": non-finite " + bad;
      out->clear();
      return result;
    }
    // The quaternion of a matrix that is not a rotation (zero, scaled) is meaningless, not an error.
    const Eigen::Matrix3d R = p.R.template cast<double>();
    if (!((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-2)) {
      result.status = Status::InvalidInput;
      result.reason = "pose " + std::to_string(i) + ": rotation is not orthonormal";
      out->clear();
      return result;
    }
    bool written = detail::append_number(out, trajectory.stamps[i], std::chars_format::fixed, options.stamp_decimals);
    const double values[7] = {static_cast<double>(p.t.x()), static_cast<double>(p.t.y()),
                              static_cast<double>(p.t.z()), q.x(), q.y(), q.z(), q.w()};
    for (double x : values) {
      out->push_back(' ');
      written = written && detail::append_number(out, x, std::chars_format::general, digits);
    }
    if (!written) {
      result.status = Status::InvalidInput;
      result.reason = "pose " + std::to_string(i) + ": a value does not fit the number format";
      out->clear();
      return result;
    }
    out->push_back('\n');
  }
  return result;
}

template <class T>
std::string format_tum_trajectory(const Trajectory<T>& trajectory, const TrajectoryWriteOptions& options) {
  std::string out;
  if (!format_tum_trajectory(trajectory, &out, options).ok()) out.clear();
  return out;
}

template <class T>
WriteResult write_tum_trajectory(const std::string& path, const Trajectory<T>& trajectory,
                                 const TrajectoryWriteOptions& options) {
  std::string text;
  WriteResult result = format_tum_trajectory(trajectory, &text, options);
  if (!result.ok()) {
    result.reason = text::quote_path(path) + ": " + result.reason;
    return result;  // nothing written
  }
  std::ofstream file(path, std::ios::out | std::ios::binary | std::ios::trunc);
  if (!file) {
    result.status = Status::IoError;
    result.reason = text::quote_path(path) + ": cannot open for writing";
    return result;
  }
  file << "# timestamp tx ty tz qx qy qz qw\n" << text;
  file.flush();
  if (!file) {
    result.status = Status::IoError;
    result.reason = text::quote_path(path) + ": write error";
  }
  return result;
}

inline AssociationResult associate(const double* first, std::size_t num_first, const double* second,
                                   std::size_t num_second, const AssociationOptions& options) {
  AssociationResult result;
  {
    std::string why;
    if (options.validate(&why) != Status::Ok) {
      result.status = Status::InvalidInput;
      result.reason = "associate: " + why;
      return result;
    }
  }
  // A non-finite stamp (a frame rate of 5e-324 Hz gives inf) would silently drop its pose.
  for (int list = 0; list < 2; ++list) {
    const double* stamps = list == 0 ? first : second;
    const std::size_t n = list == 0 ? num_first : num_second;
    std::size_t bad = 0, first_bad = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (std::isfinite(stamps[i])) continue;
      if (bad++ == 0) first_bad = i;
    }
    if (bad == 0) continue;
    std::ostringstream why;
    why << "associate: " << (list == 0 ? "first" : "second") << " list's stamp " << first_bad << " is "
        << stamps[first_bad] << " (" << bad << " of " << n << " stamps are not finite)";
    result.status = Status::NonFinite;
    result.reason = why.str();
    return result;
  }
  std::vector<std::uint32_t> a;
  std::vector<std::uint32_t> b;
  result.num_duplicates_first = detail::sorted_unique_stamp_order(first, num_first, &a);
  result.num_duplicates_second = detail::sorted_unique_stamp_order(second, num_second, &b);

  const std::vector<std::pair<std::uint32_t, std::uint32_t>> matches =
      detail::greedy_nearest_pairs(first, a, second, b, options.offset_s, options.max_difference_s);
  const double offset = options.offset_s;
  const double max_diff = options.max_difference_s;
  result.first.reserve(matches.size());
  result.second.reserve(matches.size());
  for (const auto& m : matches) {
    result.first.push_back(a[m.first]);
    result.second.push_back(b[m.second]);
  }
  if (matches.empty()) {
    result.status = Status::TooFewPoints;
    std::ostringstream why;
    why.precision(17);
    why << "associate: no stamp pairs closer than " << max_diff << " s (" << a.size() << " and " << b.size()
        << " distinct finite stamps";
    if (!a.empty() && !b.empty()) {
      why << "; first spans [" << first[a.front()] << ", " << first[a.back()] << "], second + offset spans ["
          << second[b.front()] + offset << ", " << second[b.back()] + offset << "]";
    }
    why << ")";
    result.reason = why.str();
  }
  return result;
}

}  // namespace dyncull::eval
