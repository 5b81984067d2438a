/// @file dynamic_vo.cpp
/// dynamic_vo: RGB-D visual odometry (ORB + LK, PnP-RANSAC against the keyframe's depth) run with
/// every dyncull culling preset and with no culling, on the synthetic walking sequences or a TUM
/// directory; prints ATE (000 eq. 6-7), the improvement (m - n) / m (002 eq. 7) and label quality.

#include "vo/culling.hpp"
#include "vo/frontend.hpp"
#include "vo/report.hpp"
#include "vo/runner.hpp"
#include "vo/sources.hpp"

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace dyncull;

struct Args {
  int frames = 300;
  bool frames_set = false;
  std::vector<std::string> sequences = {"static", "xyz", "rpy", "halfsphere"};
  std::vector<std::uint64_t> seeds = {1, 2, 3};  // scene seeds (SceneOptions::seed); several: median summary
  std::string out = "dynamic_vo_out";
  bool quick = false;
  std::string tum, detections;
  std::vector<std::string> strategies;  // empty: no culling + every preset
  bool list = false;
  bool diagnose = false;
  int depth_edge_radius_px = vo::FrontEndOptions{}.depth_edge_radius_px;
};

void usage(const char* argv0) {
  std::printf(
      "usage: %s [options]\n"
      "  Runs an RGB-D visual odometry front end with each dyncull culling preset and with no culling,\n"
      "  then prints ATE RMSE, improvement over no culling, label precision/recall and timings.\n"
      "options:\n"
      "  --frames N          frames per sequence (default 300; --quick: 60)\n"
      "  --sequences LIST    synthetic sequences, comma separated: static,xyz,rpy,halfsphere (default all)\n"
      "  --seeds LIST        scene seeds, comma separated (default 1,2,3). Every sequence runs once per seed\n"
      "                      and, with several, a summary gives the median ATE and pooled labels per strategy\n"
      "  --tum DIR           run on a TUM RGB-D directory (rgb.txt, depth.txt, optional groundtruth.txt)\n"
      "                      instead of the synthetic sequences\n"
      "  --detections PATH   YOLO detections for --tum: a directory of <rgb stem>.txt files or one file of\n"
      "                      '<rgb timestamp> class cx cy w h [conf]' lines (normalised coordinates).\n"
      "                      A malformed line is fatal (exit 1): the count and the first few are\n"
      "                      printed as file:line: reason. Boxes that parse but are invalid (NaN, zero\n"
      "                      size, outside the image) are dropped by the detection filter\n"
      "  --strategies LIST   subset of strategies, comma separated (default: none + every preset + oracle;\n"
      "                      --list). recommended_no_false_culls / recommended_no_misses (sim only, when\n"
      "                      named): the recommended preset with its false culls / missed movers undone by\n"
      "                      the truth, to measure what each kind of error costs the pose\n"
      "  --list              print the strategies and exit\n"
      "  --out DIR           output directory (default ./dynamic_vo_out)\n"
      "  --quick             fewer frames, for smoke tests\n"
      "  --depth-edge-radius N  front end: no new corner within N px of a depth step above 5 %% (default 1;\n"
      "                      larger N drops corners whose LK window straddles an occlusion edge)\n"
      "  --diagnose          also print, per strategy, where its labels come from (sim instance, truth,\n"
      "                      decision, deciding stage)\n",
      argv0);
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

/// Integer option value in [lo, hi]; otherwise prints why and returns false.
bool parse_int(const std::string& option, const std::string& v, long lo, long hi, int* out) {
  char* end = nullptr;
  const long n = std::strtol(v.c_str(), &end, 10);
  if (end == v.c_str() || *end != '\0' || n < lo || n > hi) {
    std::fprintf(stderr, "dynamic_vo: %s needs an integer in [%ld, %ld], got '%s'\n", option.c_str(), lo, hi, v.c_str());
    return false;
  }
  *out = static_cast<int>(n);
  return true;
}

bool parse_args(int argc, char** argv, Args* a) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&](std::string* out) {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "dynamic_vo: %s needs a value\n", arg.c_str());
        return false;
      }
      *out = argv[++i];
      return true;
    };
    std::string v;
    if (arg == "--help" || arg == "-h") {
      usage(argv[0]);
      std::exit(0);
    } else if (arg == "--frames") {
      if (!value(&v) || !parse_int(arg, v, 2, 100000, &a->frames)) return false;
      a->frames_set = true;
    } else if (arg == "--sequences") {
      if (!value(&v)) return false;
      a->sequences = split(v);
    } else if (arg == "--seeds") {
      if (!value(&v)) return false;
      a->seeds.clear();
      for (const std::string& item : split(v)) {
        char* end = nullptr;
        const unsigned long long seed = std::strtoull(item.c_str(), &end, 10);
        if (end == item.c_str() || *end != '\0' || item[0] == '-') {
          std::fprintf(stderr, "dynamic_vo: --seeds needs non-negative integers, got '%s'\n", item.c_str());
          return false;
        }
        a->seeds.push_back(static_cast<std::uint64_t>(seed));
      }
      if (a->seeds.empty()) {
        std::fprintf(stderr, "dynamic_vo: --seeds needs at least one seed\n");
        return false;
      }
    } else if (arg == "--depth-edge-radius") {
      if (!value(&v) || !parse_int(arg, v, 1, 32, &a->depth_edge_radius_px)) return false;
    } else if (arg == "--strategies") {
      if (!value(&v)) return false;
      a->strategies = split(v);
    } else if (arg == "--out") {
      if (!value(&a->out)) return false;
    } else if (arg == "--tum") {
      if (!value(&a->tum)) return false;
    } else if (arg == "--detections") {
      if (!value(&a->detections)) return false;
    } else if (arg == "--quick") {
      a->quick = true;
    } else if (arg == "--diagnose") {
      a->diagnose = true;
    } else if (arg == "--list") {
      a->list = true;
    } else {
      std::fprintf(stderr, "dynamic_vo: unknown option '%s' (try --help)\n", arg.c_str());
      return false;
    }
  }
  if (a->quick && !a->frames_set) a->frames = 60;
  return true;
}

bool motion_from_name(const std::string& name, sim::CameraMotion* m) {
  if (name == "static") *m = sim::CameraMotion::Static;
  else if (name == "xyz") *m = sim::CameraMotion::Xyz;
  else if (name == "rpy") *m = sim::CameraMotion::Rpy;
  else if (name == "halfsphere") *m = sim::CameraMotion::Halfsphere;
  else return false;
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  if (!parse_args(argc, argv, &args)) return 2;

  std::vector<vo::StrategySpec> all = vo::all_strategies();
  if (args.list) {
    for (const auto& s : all)
      std::printf("%-26s %s%s%s\n", s.name.c_str(), s.description.c_str(),
                  s.needs_detections ? " [needs detections]" : "", s.in_default ? "" : " [only when named]");
    return 0;
  }
  std::vector<vo::StrategySpec> chosen;
  if (args.strategies.empty()) {
    for (const auto& s : all)
      if (s.in_default) chosen.push_back(s);
  } else {
    for (const std::string& name : args.strategies) {
      bool found = false;
      for (const auto& s : all) {
        if (s.name == name) {
          chosen.push_back(s);
          found = true;
        }
      }
      if (!found) {
        std::fprintf(stderr, "dynamic_vo: unknown strategy '%s' (try --list)\n", name.c_str());
        return 2;
      }
    }
    // The improvement column needs the reference run.
    if (chosen.empty() || chosen.front().name != "none") chosen.insert(chosen.begin(), all.front());
  }

  std::error_code ec;
  std::filesystem::create_directories(args.out, ec);
  if (ec) {
    std::fprintf(stderr, "dynamic_vo: cannot create %s: %s\n", args.out.c_str(), ec.message().c_str());
    return 1;
  }

  vo::RunnerOptions ro;
  ro.out_dir = args.out;
  ro.max_frames = args.frames;
  ro.diagnose = args.diagnose;
  ro.front_end.depth_edge_radius_px = args.depth_edge_radius_px;
  std::vector<vo::SequenceReport> reports;
  const auto t0 = std::chrono::steady_clock::now();

  if (!args.tum.empty()) {
    vo::TumSource source;
    std::string error;
    if (!source.open(args.tum, args.detections, vo::tum_camera_for(args.tum), &error)) {
      std::fprintf(stderr, "dynamic_vo: %s\n", error.c_str());
      return 1;
    }
    // A TUM directory has no per-pixel motion truth: the oracle and the truth-repaired strategies cannot run there.
    std::vector<vo::StrategySpec> run;
    if (!source.has_detections())
      std::printf("No detections given (--detections): running only the strategies that need none.\n");
    for (const auto& s : chosen)
      if (!s.needs_truth() && (source.has_detections() || !s.needs_detections)) run.push_back(s);
    std::string name = std::filesystem::path(args.tum).filename().string();
    if (name.empty()) name = std::filesystem::path(args.tum).parent_path().filename().string();
    vo::SequenceReport rep;
    if (!vo::run_sequence(name, source, run, ro, &rep, &error)) {
      std::fprintf(stderr, "dynamic_vo: %s\n", error.c_str());
      return 1;
    }
    if (!vo::evaluate_against_file(args.tum + "/groundtruth.txt", &rep, ro)) {
      std::printf("%s: no usable groundtruth.txt, ATE not computed (%s)\n", name.c_str(), rep.truth_note.c_str());
    }
    reports.push_back(std::move(rep));
  } else {
    for (const std::string& seq : args.sequences) {
      sim::SceneOptions so;
      if (!motion_from_name(seq, &so.motion)) {
        std::fprintf(stderr, "dynamic_vo: unknown sequence '%s' (static, xyz, rpy, halfsphere)\n", seq.c_str());
        return 2;
      }
    }
    for (const std::string& seq : args.sequences) {
      for (const std::uint64_t seed : args.seeds) {
        sim::SceneOptions so;
        motion_from_name(seq, &so.motion);
        so.num_frames = args.frames;
        so.seed = seed;
        vo::SimSource source(so);
        vo::SequenceReport rep;
        rep.sequence = seq;
        rep.seed = seed;
        std::string error;
        const std::string name = args.seeds.size() > 1 ? seq + "-s" + std::to_string(seed) : seq;
        if (!vo::run_sequence(name, source, chosen, ro, &rep, &error)) {
          std::fprintf(stderr, "dynamic_vo: %s\n", error.c_str());
          return 1;
        }
        vo::evaluate_against_recorded_truth(&rep, ro);
        reports.push_back(std::move(rep));
      }
    }
  }

  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::ostringstream cmd;
  for (int i = 0; i < argc; ++i) cmd << (i ? " " : "") << argv[i];
  std::string table = vo::format_table(reports, cmd.str(), seconds);
  if (args.tum.empty() && args.seeds.size() > 1) table += "\n" + vo::format_seed_summary(reports);
  std::printf("\n%s", table.c_str());
  if (args.diagnose) {
    for (const auto& r : reports)
      for (const auto& run : r.runs)
        if (run.spec.culls)
          std::printf("\n%s / %s: instance truth decision reason count\n%s%s", r.name.c_str(), run.spec.name.c_str(),
                      run.breakdown.format().c_str(), run.recall_by_speed.format().c_str());
  }
  const std::string md = args.out + "/results.md";
  std::ofstream(md) << table;
  std::printf("\nwrote %s\n", md.c_str());
  for (const auto& r : reports)
    for (const auto& f : r.files) std::printf("wrote %s\n", f.c_str());
  return 0;
}
