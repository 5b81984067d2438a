/// @file trajectory.hpp
/// TUM RGB-D trajectory files (`timestamp tx ty tz qx qy qz qw`) and timestamp association exactly as
/// the TUM benchmark's associate.py (all pairs with |dt| < 0.02 s, greedy by |dt|, each stamp once).
#pragma once

#include "dyncull/core/status.hpp"
#include "dyncull/core/types.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <limits>
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
  /// Lines whose values contain NaN/Inf or whose quaternion is (near) zero are skipped and counted,
  /// as evaluate_rpe.py's read_trajectory does; false turns them into a ParseError.
  bool skip_invalid_poses = true;
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
  int stamp_decimals = 6;  ///< TUM writes microseconds
  int value_digits = 0;    ///< significant digits of tx..qw; 0 = max_digits10 of T (lossless round trip)
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

/// Parses TUM text. `source` names the text in error messages ("path:line: ...").
template <class T>
TrajectoryReadResult<T> parse_tum_trajectory(std::string_view text, const std::string& source = "<memory>",
                                             const TrajectoryReadOptions& options = {});

/// Reads a TUM file; IoError when it cannot be opened, ParseError with "path:line: ..." otherwise.
template <class T = double>
TrajectoryReadResult<T> read_tum_trajectory(const std::string& path, const TrajectoryReadOptions& options = {});

/// TUM text of a trajectory (qw >= 0, one line per pose, no header).
template <class T>
std::string format_tum_trajectory(const Trajectory<T>& trajectory, const TrajectoryWriteOptions& options = {});

template <class T>
WriteResult write_tum_trajectory(const std::string& path, const Trajectory<T>& trajectory,
                                 const TrajectoryWriteOptions& options = {});

/// associate.py: every (a, b) with |a - (b + offset)| < max_difference is a candidate; candidates are
/// sorted by (difference, a, b) and taken greedily so each stamp is used once. Equal stamps within one
/// list count as one stamp, the later entry winning (Python dict semantics). Non-finite stamps are
/// ignored. TooFewPoints when nothing associates; InvalidInput for a non-positive max difference.
/// Cost: O((n + m) log(n + m) + k log k) for k candidates (TUM's script is O(n m)).
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

inline bool is_separator(char c) { return c == ' ' || c == '\t' || c == ',' || c == '\r' || c == '\v' || c == '\f'; }

/// One number as Python's float() would accept it in a TUM file (decimal, exponent, nan, inf).
inline bool parse_double(std::string_view token, double* out) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty()) return false;
  const char* begin = token.data();
  const char* end = begin + token.size();
  const auto res = std::from_chars(begin, end, *out);
  return res.ec == std::errc() && res.ptr == end;
}

}  // namespace detail

template <class T>
TrajectoryReadResult<T> parse_tum_trajectory(std::string_view text, const std::string& source,
                                             const TrajectoryReadOptions& options) {
  TrajectoryReadResult<T> result;
  std::size_t line_number = 0;
  std::size_t pos = 0;
  std::string_view tokens[9];
  while (pos <= text.size()) {
    std::size_t eol = text.find('\n', pos);
    if (eol == std::string_view::npos) eol = text.size();
    const std::string_view line = text.substr(pos, eol - pos);
    pos = eol + 1;
    ++line_number;
    const std::string where = source + ":" + std::to_string(line_number) + ": ";

    std::size_t num_tokens = 0;
    std::size_t k = 0;
    while (k < line.size() && detail::is_separator(line[k])) ++k;
    if (k == line.size() || line[k] == '#') {
      if (eol == text.size()) break;
      continue;  // blank line or comment
    }
    while (k < line.size()) {
      const std::size_t start = k;
      while (k < line.size() && !detail::is_separator(line[k])) ++k;
      if (num_tokens < 9) tokens[num_tokens] = line.substr(start, k - start);
      ++num_tokens;
      while (k < line.size() && detail::is_separator(line[k])) ++k;
    }
    if (num_tokens != 8) {
      result.status = Status::ParseError;
      result.reason = where + "expected 8 values (timestamp tx ty tz qx qy qz qw), found " + std::to_string(num_tokens);
      result.trajectory.clear();
      return result;
    }
    double v[8];
    static const char* const kNames[8] = {"timestamp", "tx", "ty", "tz", "qx", "qy", "qz", "qw"};
    for (int c = 0; c < 8; ++c) {
      if (!detail::parse_double(tokens[c], &v[c])) {
        result.status = Status::ParseError;
        result.reason = where + kNames[c] + " '" + std::string(tokens[c]) + "' is not a number";
        result.trajectory.clear();
        return result;
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
    }
    if (!invalid.empty()) {
      if (!options.skip_invalid_poses) {
        result.status = Status::ParseError;
        result.reason = where + invalid;
        result.trajectory.clear();
        return result;
      }
      if (result.num_skipped == 0) result.first_skipped = where + invalid;
      ++result.num_skipped;
      if (eol == text.size()) break;
      continue;
    }
    // Rotation in double from the normalised quaternion (transform44 in evaluate_rpe.py), then cast.
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    Rigid3<double> pose;
    pose.R = q.normalized().toRotationMatrix();
    pose.t = Vec3<double>(v[1], v[2], v[3]);
    result.trajectory.push_back(v[0], pose.template cast<T>());
    if (eol == text.size()) break;
  }
  return result;
}

template <class T>
TrajectoryReadResult<T> read_tum_trajectory(const std::string& path, const TrajectoryReadOptions& options) {
  std::ifstream file(path, std::ios::in | std::ios::binary);
  if (!file) {
    TrajectoryReadResult<T> result;
    result.status = Status::IoError;
    result.reason = path + ": cannot open for reading";
    return result;
  }
  std::ostringstream buffer;
  buffer << file.rdbuf();
  if (file.bad()) {
    TrajectoryReadResult<T> result;
    result.status = Status::IoError;
    result.reason = path + ": read error";
    return result;
  }
  const std::string text = buffer.str();
  return parse_tum_trajectory<T>(text, path, options);
}

template <class T>
std::string format_tum_trajectory(const Trajectory<T>& trajectory, const TrajectoryWriteOptions& options) {
  const int digits = options.value_digits > 0 ? options.value_digits : std::numeric_limits<T>::max_digits10;
  const int decimals = options.stamp_decimals >= 0 ? options.stamp_decimals : 6;
  std::string out;
  out.reserve(trajectory.size() * 128);
  char line[512];
  const std::size_t n = std::min(trajectory.stamps.size(), trajectory.poses.size());
  for (std::size_t i = 0; i < n; ++i) {
    const Rigid3<T>& p = trajectory.poses[i];
    Eigen::Quaternion<double> q(p.R.template cast<double>());
    q.normalize();
    if (q.w() < 0) q.coeffs() = -q.coeffs();  // one of the two equivalent signs, deterministically
    const int len = std::snprintf(line, sizeof(line), "%.*f %.*g %.*g %.*g %.*g %.*g %.*g %.*g\n", decimals,
                                  trajectory.stamps[i], digits, static_cast<double>(p.t.x()), digits,
                                  static_cast<double>(p.t.y()), digits, static_cast<double>(p.t.z()), digits, q.x(),
                                  digits, q.y(), digits, q.z(), digits, q.w());
    if (len > 0) out.append(line, static_cast<std::size_t>(std::min<int>(len, static_cast<int>(sizeof(line)) - 1)));
  }
  return out;
}

template <class T>
WriteResult write_tum_trajectory(const std::string& path, const Trajectory<T>& trajectory,
                                 const TrajectoryWriteOptions& options) {
  WriteResult result;
  if (trajectory.stamps.size() != trajectory.poses.size()) {
    result.status = Status::InvalidInput;
    result.reason = path + ": trajectory has " + std::to_string(trajectory.stamps.size()) + " stamps but " +
                    std::to_string(trajectory.poses.size()) + " poses";
    return result;
  }
  std::ofstream file(path, std::ios::out | std::ios::binary | std::ios::trunc);
  if (!file) {
    result.status = Status::IoError;
    result.reason = path + ": cannot open for writing";
    return result;
  }
  file << "# timestamp tx ty tz qx qy qz qw\n" << format_tum_trajectory(trajectory, options);
  file.flush();
  if (!file) {
    result.status = Status::IoError;
    result.reason = path + ": write error";
  }
  return result;
}

inline AssociationResult associate(const double* first, std::size_t num_first, const double* second,
                                   std::size_t num_second, const AssociationOptions& options) {
  AssociationResult result;
  if (!(options.max_difference_s > 0.0) || !std::isfinite(options.max_difference_s) ||
      !std::isfinite(options.offset_s)) {
    result.status = Status::InvalidInput;
    result.reason = "associate: max_difference_s must be positive and finite, offset_s finite";
    return result;
  }
  std::vector<std::uint32_t> a;
  std::vector<std::uint32_t> b;
  result.num_duplicates_first = detail::sorted_unique_stamp_order(first, num_first, &a);
  result.num_duplicates_second = detail::sorted_unique_stamp_order(second, num_second, &b);

  struct Candidate {
    double diff;
    std::uint64_t ab;  // (position in a) << 32 | (position in b): sorted positions, so ordering them orders the stamps
  };
  std::vector<Candidate> candidates;
  candidates.reserve(a.size() + b.size());
  const double offset = options.offset_s;
  const double max_diff = options.max_difference_s;
  std::size_t lo = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double ta = first[a[i]];
    // Window start: b stamps are sorted, so (b + offset) - ta is non-decreasing in b's position.
    while (lo < b.size() && (second[b[lo]] + offset) - ta <= -max_diff) ++lo;
    for (std::size_t j = lo; j < b.size(); ++j) {
      const double shifted = second[b[j]] + offset;
      if (shifted - ta >= max_diff) break;
      const double diff = std::abs(ta - shifted);  // the exact expression associate.py tests
      if (diff < max_diff) {
        candidates.push_back(Candidate{diff, (static_cast<std::uint64_t>(i) << 32) | static_cast<std::uint64_t>(j)});
      }
    }
  }
  // Python sorts the tuples (diff, a, b): ties on diff go to the earlier first stamp, then second.
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) {
    return x.diff < y.diff || (x.diff == y.diff && x.ab < y.ab);
  });
  std::vector<std::uint8_t> used_a(a.size(), 0);
  std::vector<std::uint8_t> used_b(b.size(), 0);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> matches;  // (position in a, position in b)
  for (const Candidate& c : candidates) {
    const std::uint32_t ia = static_cast<std::uint32_t>(c.ab >> 32);
    const std::uint32_t ib = static_cast<std::uint32_t>(c.ab & 0xffffffffu);
    if (used_a[ia] || used_b[ib]) continue;
    used_a[ia] = 1;
    used_b[ib] = 1;
    matches.emplace_back(ia, ib);
  }
  std::sort(matches.begin(), matches.end());
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
