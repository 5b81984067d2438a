/// @file report.hpp
/// The logic of the dyncull_eval tool: command-line parsing, ATE (+ RPE) on two TUM files, and the
/// TUM-script-style text or JSON report. Kept in a header so tests run it without executing a binary.
#pragma once

#include "dyncull/core/status.hpp"
#include "dyncull/core/text.hpp"
#include "dyncull/eval/ate.hpp"
#include "dyncull/eval/rpe.hpp"
#include "dyncull/eval/sequence.hpp"
#include "dyncull/eval/statistics.hpp"
#include "dyncull/eval/trajectory.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

namespace dyncull::eval {

/// Options of `dyncull_eval GROUNDTRUTH ESTIMATE [...]`.
struct EvalCommandLine {
  std::string groundtruth_path;
  std::string estimate_path;
  bool rpe = false;                          ///< --rpe: also compute RPE
  double delta = 1.0;                        ///< --delta N
  DeltaUnit delta_unit = DeltaUnit::Seconds; ///< --delta-unit frames|seconds|metres|degrees|radians
  bool estimate_scale = false;               ///< --scale: Sim(3) alignment (monocular)
  double max_difference_s = 0.02;            ///< --max-difference S
  double offset_s = 0.0;                     ///< --offset S (added to the estimate's stamps)
  bool json = false;                         ///< --json
  std::string poses_csv;                     ///< --poses-csv FILE: each pair, aligned, for plots
  bool associate_lists = false;              ///< --associate: the two files are "timestamp file" lists
  bool help = false;                         ///< -h / --help
};

struct ParseArgsResult {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }
  EvalCommandLine args;
};

/// Everything dyncull_eval prints.
struct EvalReport {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }
  EvalCommandLine args;
  std::size_t groundtruth_poses = 0, estimate_poses = 0;
  std::size_t groundtruth_skipped = 0, estimate_skipped = 0;  ///< NaN / zero-quaternion lines
  AteResult<double> ate;
  RpeResult<double> rpe;  ///< computed when args.rpe
  double rpe_scale = 1.0; ///< fixed scale applied to the estimate's relative motions (ATE scale with --scale)
  Trajectory<double> groundtruth, estimate;  ///< as read, for format_poses_csv
};

inline std::string eval_usage(const std::string& program = "dyncull_eval") {
  return "usage: " + program +
         " GROUNDTRUTH ESTIMATE [--rpe] [--delta N] [--delta-unit frames|seconds|metres|degrees|radians]\n"
         "       [--scale] [--max-difference S] [--offset S] [--json] [--poses-csv FILE]\n"
         "       " + program + " --associate FIRST_LIST SECOND_LIST [--max-difference S] [--offset S]\n"
         "\n"
         "Evaluates an estimated trajectory against ground truth, both TUM files\n"
         "(timestamp tx ty tz qx qy qz qw; '#' comments). Numbers equal the TUM benchmark scripts'.\n"
         "\n"
         "  ATE (always): evaluate_ate.py. Stamps associated as associate.py (|dt| < max difference,\n"
         "      greedy by |dt|, each stamp once), estimate aligned onto ground truth by Horn/Umeyama,\n"
         "      position error: rmse, mean, median, std (population), min, max and the pair count.\n"
         "  --rpe              also RPE: evaluate_rpe.py --fixed_delta --delta N --delta_unit U, every pair\n"
         "                     used (never TUM's random subsampling or its all-pairs default mode)\n"
         "  --delta N          RPE step (default 1)\n"
         "  --delta-unit U     frames | seconds | metres | degrees | radians (default seconds, as TUM's\n"
         "                     --fixed_delta; f, s, m, deg, rad also accepted)\n"
         "  --scale            fit a Sim(3) (scale too) in ATE, for monocular estimates; RPE then scales the\n"
         "                     estimate's motions by that fitted scale. NOTE: the TUM scripts' --scale is a\n"
         "                     FIXED factor given by the user, not a fit; this option is not that one.\n"
         "  --max-difference S association window in seconds (default 0.02)\n"
         "  --offset S         time offset added to the estimate's stamps (default 0)\n"
         "  --json             machine-readable output\n"
         "  --associate        pair two 'timestamp file' lists (rgb.txt, depth.txt) as TUM's associate.py and\n"
         "                     print 'stamp file stamp file' per pair, in the first list's stamp order\n"
         "  --poses-csv FILE   also write each associated pair (stamp, ground-truth position, aligned estimate\n"
         "                     position, error) as CSV: the data of trajectory and error-over-time plots\n"
         "  -h, --help         this text\n"
         "\n"
         "Exit status: 0 ok, 1 evaluation failed (bad file: the message gives file:line), 2 bad arguments.\n";
}

namespace detail {
/// A finite number in Python's float() grammar, whatever the C locale (strtod would read "0,5" under a
/// comma-decimal locale and reject "0.5").
inline bool parse_number_arg(const std::string& arg, double* out) {
  double v = 0.0;
  if (dyncull::text::parse_python_float(arg, &v) != text::NumberStatus::Ok || !std::isfinite(v)) return false;
  *out = v;
  return true;
}

inline bool parse_delta_unit(const std::string& text, DeltaUnit* out) {
  if (text == "frames" || text == "frame" || text == "f") {
    *out = DeltaUnit::Frames;
  } else if (text == "seconds" || text == "second" || text == "s") {
    *out = DeltaUnit::Seconds;
  } else if (text == "metres" || text == "meters" || text == "m") {
    *out = DeltaUnit::Metres;
  } else if (text == "degrees" || text == "deg") {
    *out = DeltaUnit::Degrees;
  } else if (text == "radians" || text == "rad") {
    *out = DeltaUnit::Radians;
  } else {
    return false;
  }
  return true;
}

inline std::string json_escape(const std::string& s) {
  std::string out;
  out.reserve(s.size() + 2);
  for (char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof(buf), "\\u%04x", static_cast<unsigned>(static_cast<unsigned char>(c)));
      out += buf;
    } else {
      out += c;
    }
  }
  return out;
}

/// Shortest text that parses back to the same double (JSON has no NaN: null instead).
inline std::string json_double(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.17g", v);
  return buf;
}

inline std::string printf_line(const char* format, double v) {
  char buf[128];
  std::snprintf(buf, sizeof(buf), format, v);
  return buf;
}

inline std::string json_stats(const ErrorStatistics<double>& s) {
  return "{\"rmse\": " + json_double(s.rmse) + ", \"mean\": " + json_double(s.mean) + ", \"median\": " +
         json_double(s.median) + ", \"std\": " + json_double(s.std) + ", \"min\": " + json_double(s.min) +
         ", \"max\": " + json_double(s.max) + "}";
}

/// The six lines evaluate_*.py --verbose prints for one error sequence (%f, as the scripts).
inline std::string text_stats(const std::string& prefix, const ErrorStatistics<double>& s, const char* unit) {
  const std::string tail = std::string(" ") + unit + "\n";
  return prefix + ".rmse " + printf_line("%f", s.rmse) + tail + prefix + ".mean " + printf_line("%f", s.mean) + tail +
         prefix + ".median " + printf_line("%f", s.median) + tail + prefix + ".std " + printf_line("%f", s.std) +
         tail + prefix + ".min " + printf_line("%f", s.min) + tail + prefix + ".max " + printf_line("%f", s.max) +
         tail;
}
}  // namespace detail

/// Parses argv[1..argc). InvalidInput with a readable reason on unknown options, missing values or
/// a wrong number of positional arguments (-h / --help sets args.help and is always Ok).
inline ParseArgsResult parse_eval_args(int argc, const char* const* argv) {
  ParseArgsResult result;
  EvalCommandLine& a = result.args;
  int positional = 0;
  auto fail = [&result](const std::string& why) {
    result.status = Status::InvalidInput;
    result.reason = why;
    return result;
  };
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&](std::string* out) {
      if (i + 1 >= argc) return false;
      *out = argv[++i];
      return true;
    };
    std::string v;
    if (arg == "-h" || arg == "--help") {
      a.help = true;
      return result;
    } else if (arg == "--rpe") {
      a.rpe = true;
    } else if (arg == "--scale") {
      a.estimate_scale = true;
    } else if (arg == "--json") {
      a.json = true;
    } else if (arg == "--delta") {
      if (!value(&v) || !detail::parse_number_arg(v, &a.delta) || !(a.delta > 0)) {
        return fail("--delta needs a positive number");
      }
    } else if (arg == "--delta-unit") {
      if (!value(&v) || !detail::parse_delta_unit(v, &a.delta_unit)) {
        return fail("--delta-unit needs one of frames, seconds, metres, degrees, radians");
      }
    } else if (arg == "--max-difference") {
      if (!value(&v) || !detail::parse_number_arg(v, &a.max_difference_s) || !(a.max_difference_s > 0)) {
        return fail("--max-difference needs a positive number of seconds");
      }
    } else if (arg == "--associate") {
      a.associate_lists = true;
    } else if (arg == "--poses-csv") {
      if (!value(&a.poses_csv) || a.poses_csv.empty()) return fail("--poses-csv needs a file name");
    } else if (arg == "--offset") {
      if (!value(&v) || !detail::parse_number_arg(v, &a.offset_s)) return fail("--offset needs a number of seconds");
    } else if (arg.size() > 1 && arg[0] == '-') {
      return fail("unknown option " + text::quote_token(arg));
    } else {
      if (positional == 0) a.groundtruth_path = arg;
      if (positional == 1) a.estimate_path = arg;
      ++positional;
    }
  }
  if (positional != 2) {
    return fail("expected 2 files (GROUNDTRUTH ESTIMATE), got " + std::to_string(positional));
  }
  return result;
}

/// Reads both files and evaluates. On failure the reason is the first problem found, with
/// "path:line: ..." for malformed files.
inline EvalReport run_eval(const EvalCommandLine& args) {
  EvalReport report;
  report.args = args;
  const auto gt = read_tum_trajectory<double>(args.groundtruth_path);
  if (!gt.ok()) {
    report.status = gt.status;
    report.reason = gt.reason;
    return report;
  }
  const auto est = read_tum_trajectory<double>(args.estimate_path);
  if (!est.ok()) {
    report.status = est.status;
    report.reason = est.reason;
    return report;
  }
  report.groundtruth_poses = gt.trajectory.size();
  report.estimate_poses = est.trajectory.size();
  report.groundtruth_skipped = gt.num_skipped;
  report.estimate_skipped = est.num_skipped;
  report.groundtruth = gt.trajectory;
  report.estimate = est.trajectory;

  AteOptions ate_options;
  ate_options.association.max_difference_s = args.max_difference_s;
  ate_options.association.offset_s = args.offset_s;
  ate_options.estimate_scale = args.estimate_scale;
  report.ate = evaluate_ate(gt.trajectory, est.trajectory, ate_options);
  if (!report.ate.ok()) {
    report.status = report.ate.status;
    report.reason = text::quote_path(args.estimate_path) + " vs " + text::quote_path(args.groundtruth_path) + ": " + report.ate.reason;
    return report;
  }
  if (args.rpe) {
    RpeOptions rpe_options;
    rpe_options.delta = args.delta;
    rpe_options.delta_unit = args.delta_unit;
    rpe_options.offset_s = args.offset_s;
    report.rpe_scale = args.estimate_scale ? report.ate.groundtruth_from_estimate.scale : 1.0;
    rpe_options.scale = report.rpe_scale;
    report.rpe = evaluate_rpe(gt.trajectory, est.trajectory, rpe_options);
    if (!report.rpe.ok()) {
      report.status = report.rpe.status;
      report.reason = text::quote_path(args.estimate_path) + " vs " + text::quote_path(args.groundtruth_path) + ": " + report.rpe.reason;
    }
  }
  return report;
}

/// dyncull_eval --associate: the pairs of two "timestamp file" lists (args.groundtruth_path and
/// args.estimate_path), as TUM's associate.py pairs them (associate()), one "stamp file stamp file" line
/// each (%.6f stamps). A list that cannot be read is its status and "path:line: ..." reason; lists with
/// no pair within the window are TooFewPoints.
struct ListAssociation {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }
  std::string text;
};

inline ListAssociation associate_lists(const EvalCommandLine& args) {
  ListAssociation result;
  std::vector<detail::ListEntry> first, second;
  for (auto [path, list] : {std::pair{&args.groundtruth_path, &first}, std::pair{&args.estimate_path, &second}}) {
    result.status = detail::read_list(*path, SequenceOptions{}, list, &result.reason);
    if (!result.ok()) return result;
  }
  auto stamps = [](const std::vector<detail::ListEntry>& list) {
    std::vector<double> out;
    for (const detail::ListEntry& e : list) out.push_back(e.timestamp);
    return out;
  };
  AssociationOptions options;
  options.max_difference_s = args.max_difference_s;
  options.offset_s = args.offset_s;
  const AssociationResult pairs = associate(stamps(first), stamps(second), options);
  if (!pairs.ok()) {
    result.status = pairs.status;
    result.reason = text::quote_path(args.groundtruth_path) + " and " + text::quote_path(args.estimate_path) + ": " + pairs.reason;
    return result;
  }
  char buffer[64];
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const detail::ListEntry &a = first[pairs.first[k]], &b = second[pairs.second[k]];
    std::snprintf(buffer, sizeof buffer, "%.6f ", a.timestamp);
    result.text += buffer + a.path;
    std::snprintf(buffer, sizeof buffer, " %.6f ", b.timestamp);
    result.text += buffer + b.path + "\n";
  }
  return result;
}

/// The ATE's pairs in ground-truth stamp order as CSV, `stamp,gt_x,gt_y,gt_z,x,y,z,error_m`: the
/// ground truth's stamp and position, the estimate's position after the ATE's alignment, and the
/// distance between them (metres, %.6f). A report without an ATE gives the header alone.
inline std::string format_poses_csv(const EvalReport& r) {
  std::string out = "stamp,gt_x,gt_y,gt_z,x,y,z,error_m\n";
  if (!r.ate.ok()) return out;
  char line[256];
  for (std::size_t k = 0; k < r.ate.groundtruth_index.size(); ++k) {
    const std::size_t g = r.ate.groundtruth_index[k], e = r.ate.estimate_index[k];
    const Vec3<double> truth = r.groundtruth.poses[g].t;
    const Vec3<double> aligned = r.ate.groundtruth_from_estimate.apply(r.estimate.poses[e].t);
    std::snprintf(line, sizeof(line), "%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f\n", r.groundtruth.stamps[g], truth.x(),
                  truth.y(), truth.z(), aligned.x(), aligned.y(), aligned.z(), (aligned - truth).norm());
    out += line;
  }
  return out;
}

/// TUM-script lines (evaluate_ate.py / evaluate_rpe.py --verbose names and %f format), preceded by
/// '#' lines giving the files, pose counts and every option used.
inline std::string format_report_text(const EvalReport& r) {
  const EvalCommandLine& a = r.args;
  std::string out;
  out += "# groundtruth " + a.groundtruth_path + " (" + std::to_string(r.groundtruth_poses) + " poses, " +
         std::to_string(r.groundtruth_skipped) + " invalid lines skipped)\n";
  out += "# estimate " + a.estimate_path + " (" + std::to_string(r.estimate_poses) + " poses, " +
         std::to_string(r.estimate_skipped) + " invalid lines skipped)\n";
  out += "# ate: association |dt| < " + detail::printf_line("%g", a.max_difference_s) + " s, offset " +
         detail::printf_line("%g", a.offset_s) + " s, alignment " +
         (a.estimate_scale ? "Sim(3) (fitted scale)" : "SE(3)") + "\n";
  out += "compared_pose_pairs " + std::to_string(r.ate.num_pairs) + " pairs\n";
  out += detail::text_stats("absolute_translational_error", r.ate.error_m, "m");
  if (a.estimate_scale) out += "alignment_scale " + detail::printf_line("%f", r.ate.groundtruth_from_estimate.scale) + "\n";
  if (a.rpe) {
    out += "# rpe: fixed delta " + detail::printf_line("%g", a.delta) + " " + to_string(a.delta_unit) +
           ", all pairs, estimate motion scale " + detail::printf_line("%g", r.rpe_scale) + ", " +
           std::to_string(r.rpe.num_dropped_gap) + " pairs dropped (ground-truth gap > " +
           detail::printf_line("%g", r.rpe.max_gap_s) + " s)\n";
    out += "compared_pose_pairs " + std::to_string(r.rpe.num_pairs) + " pairs\n";
    out += detail::text_stats("translational_error", r.rpe.translation_m, "m");
    out += detail::text_stats("rotational_error", r.rpe.rotation_deg, "deg");
  }
  return out;
}

/// One JSON object with full-precision numbers (%.17g), the options and the pair counts.
inline std::string format_report_json(const EvalReport& r) {
  const EvalCommandLine& a = r.args;
  std::string out = "{\n";
  out += "  \"status\": \"" + std::string(to_string(r.status)) + "\",\n";
  if (!r.ok()) out += "  \"reason\": \"" + detail::json_escape(r.reason) + "\",\n";
  out += "  \"groundtruth\": {\"path\": \"" + detail::json_escape(a.groundtruth_path) +
         "\", \"poses\": " + std::to_string(r.groundtruth_poses) +
         ", \"skipped_lines\": " + std::to_string(r.groundtruth_skipped) + "},\n";
  out += "  \"estimate\": {\"path\": \"" + detail::json_escape(a.estimate_path) +
         "\", \"poses\": " + std::to_string(r.estimate_poses) +
         ", \"skipped_lines\": " + std::to_string(r.estimate_skipped) + "},\n";
  out += "  \"options\": {\"max_difference_s\": " + detail::json_double(a.max_difference_s) +
         ", \"offset_s\": " + detail::json_double(a.offset_s) + ", \"alignment\": \"" +
         (a.estimate_scale ? "sim3" : "se3") + "\", \"rpe\": " + (a.rpe ? "true" : "false") +
         ", \"delta\": " + detail::json_double(a.delta) + ", \"delta_unit\": \"" + to_string(a.delta_unit) + "\"},\n";
  out += "  \"ate\": {\"pairs\": " + std::to_string(r.ate.num_pairs) +
         ", \"scale\": " + detail::json_double(r.ate.groundtruth_from_estimate.scale) +
         ", \"error_m\": " + detail::json_stats(r.ate.error_m) + "}";
  if (a.rpe) {
    out += ",\n  \"rpe\": {\"pairs\": " + std::to_string(r.rpe.num_pairs) +
           ", \"dropped_gap\": " + std::to_string(r.rpe.num_dropped_gap) +
           ", \"max_gap_s\": " + detail::json_double(r.rpe.max_gap_s) +
           ", \"motion_scale\": " + detail::json_double(r.rpe_scale) +
           ",\n          \"trans_m\": " + detail::json_stats(r.rpe.translation_m) +
           ",\n          \"rot_deg\": " + detail::json_stats(r.rpe.rotation_deg) + "}";
  }
  out += "\n}\n";
  return out;
}

}  // namespace dyncull::eval
