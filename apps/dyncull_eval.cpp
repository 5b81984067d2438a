// dyncull_eval: TUM-exact ATE / RPE of an estimated trajectory against ground truth.
//   dyncull_eval GROUNDTRUTH ESTIMATE [--rpe] [--delta N] [--delta-unit frames|seconds] [--scale]
//                [--max-difference S] [--json] [--poses-csv FILE]
//   dyncull_eval --associate FIRST_LIST SECOND_LIST [--max-difference S]   (rgb.txt / depth.txt pairs)
// The logic lives in dyncull/eval/report.hpp (tested there); this file only wires it to stdio.
#include "dyncull/eval/report.hpp"

#include <cstdio>
#include <string>

namespace {
bool write_text(const std::string& path, const std::string& text) {
  std::FILE* file = std::fopen(path.c_str(), "w");
  if (file == nullptr) return false;
  const bool written = std::fputs(text.c_str(), file) >= 0;
  return std::fclose(file) == 0 && written;
}
}  // namespace

int main(int argc, char** argv) {
  using namespace dyncull::eval;
  const std::string program = argc > 0 ? argv[0] : "dyncull_eval";
  const ParseArgsResult parsed = parse_eval_args(argc, argv);
  if (!parsed.ok()) {
    std::fprintf(stderr, "%s: %s\n\n%s", program.c_str(), parsed.reason.c_str(), eval_usage(program).c_str());
    return 2;
  }
  if (parsed.args.help) {
    std::fputs(eval_usage(program).c_str(), stdout);
    return 0;
  }
  if (parsed.args.associate_lists) {
    const ListAssociation pairs = associate_lists(parsed.args);
    if (!pairs.ok()) {
      std::fprintf(stderr, "%s: %s\n", program.c_str(), pairs.reason.c_str());
      return 1;
    }
    std::fputs(pairs.text.c_str(), stdout);
    return 0;
  }
  const EvalReport report = run_eval(parsed.args);
  if (!report.ok()) {
    std::fprintf(stderr, "%s: %s\n", program.c_str(), report.reason.c_str());
    if (parsed.args.json) std::fputs(format_report_json(report).c_str(), stdout);
    return 1;
  }
  if (!parsed.args.poses_csv.empty()) {
    if (!write_text(parsed.args.poses_csv, format_poses_csv(report))) {
      std::fprintf(stderr, "%s: cannot write %s\n", program.c_str(), parsed.args.poses_csv.c_str());
      return 1;
    }
  }
  const std::string text = parsed.args.json ? format_report_json(report) : format_report_text(report);
  std::fputs(text.c_str(), stdout);
  return 0;
}
