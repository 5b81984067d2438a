/// @file dynamic_vo.cpp
/// dynamic_vo: RGB-D visual odometry (ORB + LK, PnP-RANSAC against the keyframe's depth) run with
/// every dyncull culling preset and with no culling, on the synthetic walking sequences or a TUM
/// directory; prints ATE (DLD-SLAM eq. 6-7), the improvement (m - n) / m (Zhu et al. 2024 eq. 7) and label quality.
/// --family / --scene pick the scene (sim/families.hpp, sim/scene_keys.hpp); --suite runs every family.

#include "dyncull/sim/families.hpp"
#include "dyncull/sim/scene_keys.hpp"

#include "vo/ablation.hpp"
#include "vo/culling.hpp"
#include "vo/dataset.hpp"
#include "vo/figures.hpp"
#include "vo/frontend.hpp"
#include "vo/report.hpp"
#include "vo/runner.hpp"
#include "vo/sources.hpp"

#include <algorithm>
#include <atomic>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <system_error>
#include <thread>
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
  std::string tum, detections;  // tum: the --dataset folder (--tum is its older name)
  std::string camera;           // --camera: camera.txt, fx,fy,cx,cy[,k1,k2,p1,p2,k3] or a TUM name
  std::string detector;         // --detector CFG,WEIGHTS or MODEL.onnx: boxes found live (vo/live_detector.hpp)
  std::string truth;            // --truth: a dyncull_motion_truth folder for --dataset
  std::vector<std::string> strategies;  // empty: no culling + every preset
  bool list = false;
  bool diagnose = false;
  bool sequences_set = false, seeds_set = false;
  int depth_edge_radius_px = vo::FrontEndOptions{}.depth_edge_radius_px;
  std::vector<std::string> families = {"walking"};  // scene families (sim/families.hpp)
  bool families_set = false;
  std::string scene;  // key=value,... applied on top of each family
  int jobs = 1;       // sequences run in parallel
  std::string tum_trajectories;  // directory of TUM fr3_* directories (default $DYNCULL_DATA_DIR/tum)
  bool suite = false;
};

/// The suite's sequence length: 7 families x 4 motions x 3 seeds stay within about 10 minutes on 2 cores.
constexpr int kSuiteFrames = 150;

void usage(const char* argv0) {
  std::printf(
      "usage: %s [options]\n"
      "  Runs an RGB-D visual odometry front end with each dyncull culling preset and with no culling,\n"
      "  then prints ATE RMSE, improvement over no culling, label precision/recall and timings.\n"
      "options:\n"
      "  --frames N          frames per sequence (default 300; --quick: 60)\n"
      "  --sequences LIST    synthetic sequences, comma separated: static,xyz,rpy,halfsphere (default all),\n"
      "                      or a TUM fr3 recording's camera motion, e.g. fr3_walking_xyz, fr3_sitting_static\n"
      "                      (its groundtruth.txt under --tum-trajectories; seed s starts it 7 (s - 1) s in)\n"
      "  --tum-trajectories DIR  directory of the fr3_* recordings (default $DYNCULL_DATA_DIR/tum)\n"
      "  --seeds LIST        scene seeds, comma separated (default 1,2,3). Every sequence runs once per seed\n"
      "                      and, with several, a summary gives the median ATE and pooled labels per strategy\n"
      "                      (with --dataset: the front end's PnP-RANSAC seeds, default one run; with several,\n"
      "                      ATE and RPE are the median over the runs and the ATE's range is given)\n"
      "  --dataset DIR       run on a real RGB-D sequence in TUM format (rgb.txt, depth.txt, optional\n"
      "                      groundtruth.txt, camera.txt, detections/) instead of the synthetic sequences:\n"
      "                      every frame unless --frames; writes dataset_summary.csv (ATE, RPE over 1 s, lost\n"
      "                      frames, culls in person boxes / outside boxes, times), the trajectories, the\n"
      "                      plots' data (NAME_poses.csv, NAME_frames.csv: scripts/figures.py draws them)\n"
      "                      and a strip of annotated frames. --tum DIR is the same\n"
      "  --camera SPEC       intrinsics for --dataset: a camera.txt (fx fy cx cy [k1 k2 p1 p2 k3]\n"
      "                      [depth_units_per_metre] as 'key value' lines), fx,fy,cx,cy[,k1,k2,p1,p2,k3], or\n"
      "                      fr1 / fr2 / fr3 (default: DIR/camera.txt, else TUM's by the folder's name)\n"
      "  --detections PATH   boxes for --dataset (default DIR/detections when present; 'none': no boxes):\n"
      "                      a folder of per-frame JSON (frame_id, timestamp, detections[] with class_id,\n"
      "                      confidence, bbox [x1, y1, x2, y2]) matched by timestamp, a folder of YOLO\n"
      "                      <rgb stem>.txt files, or one file of '<rgb timestamp> class cx cy w h [conf]'\n"
      "                      lines (normalised coordinates). A malformed file or line is fatal (exit 1) and\n"
      "                      named as file:line: reason. Boxes that parse but are invalid (NaN, zero size,\n"
      "                      outside the image) are dropped by the detection filter\n"
      "  --truth DIR         per-pixel motion truth for --dataset (dyncull_motion_truth --dataset DIR --out\n"
      "                      TRUTH_DIR): adds each strategy's precision and recall of culling the features\n"
      "                      on moving pixels (over features on pixels the truth knows) and runs the oracle\n"
      "%s"
      "  --strategies LIST   subset of strategies, comma separated (default: none + every preset + culler +\n"
      "                      oracle; --list). culler: the recommended preset through the stateful culler as a\n"
      "                      host runs it (ORB descriptors at the tracked keypoints, its own keyframe\n"
      "                      matching and keyframes; culling time includes the ORB descriptors).\n"
      "                      recommended_no_false_culls / recommended_no_misses (sim only, when\n"
      "                      named): the recommended preset with its false culls / missed movers undone by\n"
      "                      the truth, to measure what each kind of error costs the pose\n"
      "  --list              print the strategies and exit\n"
      "  --out DIR           output directory (default ./dynamic_vo_out)\n"
      "  --quick             fewer frames, for smoke tests\n"
      "  --depth-edge-radius N  front end: no new corner within N px of a depth step above 5 %% (default 1;\n"
      "                      larger N drops corners whose LK window straddles an occlusion edge)\n"
      "  --diagnose          also print, per strategy, where its labels come from (sim instance, truth,\n"
      "                      decision, deciding stage; on --dataset with --truth: truth, decision, stage)\n"
      "  --family LIST       scene families, comma separated (default walking; see below). Each runs with\n"
      "                      every sequence and seed; with several, a per-family summary table is printed\n"
      "                      and written (family_summary.md, family_summary.csv)\n"
      "  --scene K=V[,K=V]   scene keys set on top of each family (keys below), e.g.\n"
      "                      --scene actors.walking_speed_mps=0.9,miss_rate=0.2,trajectory.xyz_amplitude_m=0.2:0.1:0.2\n"
      "                      (motion, seed and num_frames are set per run by --sequences, --seeds, --frames)\n"
      "  --suite             every family x static,xyz,rpy,halfsphere x seeds 1,2,3 at %d frames (unless\n"
      "                      --family / --sequences / --seeds / --frames say otherwise); prints the summary only\n"
      "  --jobs N            sequences run in parallel on N threads (default 1)\n"
      "\nscene families (--family):\n%s"
      "\nscene keys (--scene; vectors as x:y or x:y:z):\n%s",
      argv0, vo::live_detector_help(), kSuiteFrames, sim::format_scene_families().c_str(), sim::format_scene_keys().c_str());
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
    std::fprintf(stderr, "dynamic_vo: %s needs an integer in [%ld, %ld], got %s\n", option.c_str(), lo, hi,
                 text::quote_token(v).c_str());
    return false;
  }
  *out = static_cast<int>(n);
  return true;
}

/// The --seeds list: 64-bit integers, at least one. False, after printing why.
bool parse_seeds(const std::string& v, std::vector<std::uint64_t>* seeds) {
  seeds->clear();
  for (const std::string& item : split(v)) {
    // Exact: from_chars refuses what does not fit (strtoull would saturate 2^64 to 2^64 - 1).
    std::uint64_t seed = 0;
    const std::from_chars_result r = std::from_chars(item.data(), item.data() + item.size(), seed);
    if (r.ec != std::errc() || r.ptr != item.data() + item.size()) {
      std::fprintf(stderr, "dynamic_vo: --seeds needs integers in [0, 18446744073709551615] (64-bit seeds), got %s\n",
                   text::quote_token(item).c_str());
      return false;
    }
    seeds->push_back(seed);
  }
  if (seeds->empty()) {
    std::fprintf(stderr, "dynamic_vo: --seeds needs at least one seed\n");
    return false;
  }
  return true;
}

/// The --family list: known family names, at least one. False, after printing why.
bool check_families(const std::vector<std::string>& families) {
  for (const std::string& name : families) {
    std::string reason;
    if (!sim::find_scene_family(name, nullptr, &reason)) {
      std::fprintf(stderr, "dynamic_vo: --family: %s\n", reason.c_str());
      return false;
    }
  }
  if (families.empty()) {
    std::fprintf(stderr, "dynamic_vo: --family needs at least one family\n");
    return false;
  }
  return true;
}

/// The options' combined rules and defaults once every option is read: --detector and --truth need
/// --dataset, the trajectories default to DYNCULL_DATA_DIR/tum, --suite and --quick set families and
/// frames, and the --scene assignments must apply to every family. False, after printing why.
bool complete_args(Args* a) {
  if (!a->detector.empty() && (a->tum.empty() || !a->detections.empty())) {
    std::fprintf(stderr, "dynamic_vo: --detector runs on a recorded sequence (--dataset DIR) and replaces --detections\n");
    return false;
  }
  if (!a->truth.empty() && a->tum.empty()) {
    std::fprintf(stderr, "dynamic_vo: --truth scores a recorded sequence (--dataset DIR)\n");
    return false;
  }
  if (a->tum_trajectories.empty()) {
    const char* data = std::getenv("DYNCULL_DATA_DIR");
    if (data != nullptr && *data != '\0') a->tum_trajectories = std::string(data) + "/tum";
  }
  if (a->suite) {
    if (!a->families_set) {
      a->families.clear();
      for (const sim::SceneFamily& f : sim::scene_families()) a->families.push_back(f.name);
      a->families_set = true;
    }
    if (!a->frames_set && !a->quick) a->frames = kSuiteFrames;
  }
  if (a->quick && !a->frames_set) a->frames = 60;
  // A bad key or value stops here, before any run: the message names the key and what it expects.
  for (const std::string& name : a->families) {
    sim::SceneFamily f;
    sim::find_scene_family(name, &f);
    std::string reason;
    if (sim::apply_scene_assignments(&f.options, a->scene, &reason) != Status::Ok) {
      std::fprintf(stderr, "dynamic_vo: --scene (family %s): %s\n", name.c_str(), reason.c_str());
      return false;
    }
  }
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
      a->sequences_set = true;
    } else if (arg == "--seeds") {
      if (!value(&v)) return false;
      a->seeds_set = true;
      if (!parse_seeds(v, &a->seeds)) return false;
    } else if (arg == "--depth-edge-radius") {
      if (!value(&v) || !parse_int(arg, v, 1, 32, &a->depth_edge_radius_px)) return false;
    } else if (arg == "--strategies") {
      if (!value(&v)) return false;
      a->strategies = split(v);
    } else if (arg == "--out") {
      if (!value(&a->out)) return false;
    } else if (arg == "--tum" || arg == "--dataset") {
      if (!value(&a->tum)) return false;
    } else if (arg == "--camera") {
      if (!value(&a->camera)) return false;
    } else if (arg == "--detections") {
      if (!value(&a->detections)) return false;
    } else if (arg == "--detector") {
      if (!value(&a->detector)) return false;
    } else if (arg == "--truth") {
      if (!value(&a->truth)) return false;
    } else if (arg == "--family") {
      if (!value(&v)) return false;
      a->families = split(v);
      a->families_set = true;
      if (!check_families(a->families)) return false;
    } else if (arg == "--scene") {
      if (!value(&v)) return false;
      a->scene += (a->scene.empty() ? "" : ",") + v;
    } else if (arg == "--jobs") {
      if (!value(&v) || !parse_int(arg, v, 1, 64, &a->jobs)) return false;
    } else if (arg == "--tum-trajectories") {
      if (!value(&a->tum_trajectories)) return false;
    } else if (arg == "--suite") {
      a->suite = true;
    } else if (arg == "--quick") {
      a->quick = true;
    } else if (arg == "--diagnose") {
      a->diagnose = true;
    } else if (arg == "--list") {
      a->list = true;
    } else {
      std::fprintf(stderr, "dynamic_vo: unknown option %s (try --help)\n", text::quote_token(arg).c_str());
      return false;
    }
  }
  return complete_args(a);
}

bool motion_from_name(const std::string& name, sim::CameraMotion* m) {
  sim::CameraMotion motion{};
  if (!sim::camera_motion_from_string(name, &motion) || motion == sim::CameraMotion::Recorded) return false;
  *m = motion;
  return true;
}

/// A sequence named after a TUM fr3 directory ("fr3_walking_xyz") follows that recording's ground truth.
bool is_recorded(const std::string& name) { return name.rfind("fr3_", 0) == 0; }

/// Loads <dir>/<name>/groundtruth.txt as the recorded camera motion; false with a reason.
bool load_recorded(const std::string& dir, const std::string& name, sim::TrajectoryOptions* t, std::string* error) {
  if (dir.empty()) {
    *error = "sequence " + text::quote_token(name) + " needs the TUM trajectories: set DYNCULL_DATA_DIR or give --tum-trajectories DIR";
    return false;
  }
  const std::string path = dir + "/" + name + "/groundtruth.txt";
  const eval::TrajectoryReadResult<double> gt = eval::read_tum_trajectory<double>(path);
  if (!gt.ok() || gt.trajectory.size() < 2) {
    *error = "sequence " + text::quote_token(name) + ": " + (gt.ok() ? text::quote_path(path) + " has fewer than 2 poses" : gt.reason);
    return false;
  }
  t->recorded_stamps_s = gt.trajectory.stamps;
  t->recorded_poses = gt.trajectory.poses;
  return true;
}

/// One synthetic sequence of the run: a family's scene with one motion and seed.
struct SimJob {
  std::string family, sequence, name;
  std::uint64_t seed = 0;
  sim::SceneOptions options;
};

// One annotated frame per family for the summary strip: the middle drawn frame of its first xyz sequence
// (else its first sequence), so the strip shows every family under the same camera motion.
std::vector<vo::StripFrame> family_frames(const std::vector<vo::SequenceReport>& reports) {
  std::vector<std::string> families;
  std::vector<vo::StripFrame> out;
  for (const auto& r : reports)
    if (std::find(families.begin(), families.end(), r.family) == families.end()) families.push_back(r.family);
  for (const std::string& family : families) {
    std::vector<std::string> frames;
    for (int pass = 0; pass < 2 && frames.empty(); ++pass) {
      for (const auto& r : reports) {
        if (r.family != family || (pass == 0 && r.sequence != "xyz")) continue;
        for (const std::string& f : r.files)
          if (f.find("_frame") != std::string::npos) frames.push_back(f);
        if (!frames.empty()) break;
      }
    }
    if (!frames.empty()) out.push_back({frames[frames.size() / 2], family + ": green kept, red culled"});
  }
  return out;
}

/// dynamic_vo --dataset DIR: the real sequence with every chosen strategy; prints and writes the summary.
int run_dataset_command(const Args& args, const std::vector<vo::StrategySpec>& chosen, vo::RunnerOptions ro,
                        int argc, char** argv) {
  const auto t0 = std::chrono::steady_clock::now();
  vo::DatasetOptions o;
  o.dir = args.tum;
  o.detections = args.detections;
  o.camera = args.camera;
  o.truth_dir = args.truth;
  o.strategies = chosen;
  if (args.seeds_set) o.pnp_seeds = args.seeds;
  if (!args.frames_set && !args.quick) ro.max_frames = std::numeric_limits<int>::max();  // the whole sequence
  o.runner = ro;
  vo::DatasetRun run;
  std::string error;
  // Opened first: a bad model is named before the sequence is read.
  vo::LiveDetector live;
  if (!args.detector.empty()) {
    if (!live.open(args.detector, o.sequence.detection_filter, &error)) {
      std::fprintf(stderr, "dynamic_vo: %s\n", error.c_str());
      return 1;
    }
    o.live_detector = &live;
  }
  if (!vo::run_dataset(o, &run, &error)) {
    std::fprintf(stderr, "dynamic_vo: %s\n", error.c_str());
    return 1;
  }
  if (live.enabled()) std::printf("%s\n", live.summary().c_str());
  std::printf("camera: %s; detections: %s\n", run.camera_source.c_str(),
              run.detections_path.empty() ? "none" : run.detections_path.c_str());
  for (const std::string& n : run.notes) std::printf("note: %s\n", n.c_str());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::ostringstream cmd;
  for (int i = 0; i < argc; ++i) cmd << (i ? " " : "") << argv[i];
  const std::string md = vo::dataset_summary_md(run, cmd.str(), seconds);
  std::printf("\n%s", md.c_str());
  std::ofstream(args.out + "/dataset_summary.md") << md;
  std::ofstream(args.out + "/results.md") << vo::format_table({run.report}, cmd.str(), seconds);
  if (args.diagnose)
    for (const auto& r : run.report.runs)
      if (r.spec.culls)
        std::printf("\n%s: truth decision reason count (features on pixels the truth knows)\n%s", r.spec.name.c_str(),
                    r.breakdown.format().c_str());
  std::printf("\nwrote %s/dataset_summary.md\nwrote %s/results.md\n", args.out.c_str(), args.out.c_str());
  for (const std::string& f : run.files) std::printf("wrote %s\n", f.c_str());
  return 0;
}

/// The strategies to run: the default set, or the named ones behind the reference run "none" (the
/// improvement column needs it). False, after printing why, for an unknown name.
bool choose_strategies(const std::vector<std::string>& names, const std::vector<vo::StrategySpec>& all,
                       std::vector<vo::StrategySpec>* chosen) {
  if (names.empty()) {
    for (const auto& s : all)
      if (s.in_default) chosen->push_back(s);
    return true;
  }
  for (const std::string& name : names) {
    bool found = false;
    for (const auto& s : all) {
      if (s.name == name) {
        chosen->push_back(s);
        found = true;
      }
    }
    if (!found) {
      std::fprintf(stderr, "dynamic_vo: unknown strategy %s (try --list)\n", text::quote_token(name).c_str());
      return false;
    }
  }
  if (chosen->empty() || chosen->front().name != "none") chosen->insert(chosen->begin(), all.front());
  return true;
}

/// The recordings the recorded sequences follow, each loaded once. False, after printing why, for a
/// recording that cannot be read or a sequence name that is neither a motion nor a recording.
bool load_recordings(const Args& args, std::map<std::string, sim::TrajectoryOptions>* recorded) {
  for (const std::string& seq : args.sequences) {
    sim::CameraMotion m{};
    if (is_recorded(seq)) {
      std::string error;
      if (!load_recorded(args.tum_trajectories, seq, &(*recorded)[seq], &error)) {
        std::fprintf(stderr, "dynamic_vo: %s\n", error.c_str());
        return false;
      }
    } else if (!motion_from_name(seq, &m)) {
      std::fprintf(stderr, "dynamic_vo: unknown sequence %s (static, xyz, rpy, halfsphere, fr3_<TUM sequence>)\n",
                   text::quote_token(seq).c_str());
      return false;
    }
  }
  return true;
}

/// The job of one family's scene (`options`, the --scene assignments applied) with one sequence and seed.
SimJob make_sim_job(const Args& args, const std::string& family, const sim::SceneOptions& options,
                    const std::string& seq, std::uint64_t seed,
                    const std::map<std::string, sim::TrajectoryOptions>& recorded) {
  SimJob job;
  job.family = family;
  job.sequence = seq;
  job.seed = seed;
  job.options = options;
  job.options.num_frames = args.frames;
  job.options.seed = seed;
  if (is_recorded(seq)) {
    // The recording replaces the synthetic motion; each seed starts it 7 s later (wrapped so the
    // run fits), so seeds see different parts of the real trajectory.
    const sim::TrajectoryOptions& rec = recorded.at(seq);
    job.options.motion = sim::CameraMotion::Recorded;
    job.options.trajectory.recorded_stamps_s = rec.recorded_stamps_s;
    job.options.trajectory.recorded_poses = rec.recorded_poses;
    const double span = rec.recorded_stamps_s.back() - rec.recorded_stamps_s.front() -
                        args.frames / job.options.fps;
    job.options.trajectory.recorded_start_s = span > 0 ? std::fmod(7.0 * static_cast<double>(seed - 1), span) : 0.0;
  } else {
    motion_from_name(seq, &job.options.motion);
  }
  job.name = (args.families_set ? family + "-" : std::string()) + seq +
             (args.seeds.size() > 1 ? "-s" + std::to_string(seed) : std::string());
  return job;
}

/// Every family x sequence x seed of the run, in that order.
std::vector<SimJob> make_sim_jobs(const Args& args, const std::map<std::string, sim::TrajectoryOptions>& recorded) {
  std::vector<SimJob> jobs;
  for (const std::string& family : args.families) {
    sim::SceneFamily f;
    sim::find_scene_family(family, &f);
    sim::apply_scene_assignments(&f.options, args.scene);  // checked in parse_args
    for (const std::string& seq : args.sequences)
      for (const std::uint64_t seed : args.seeds)
        jobs.push_back(make_sim_job(args, family, f.options, seq, seed, recorded));
  }
  return jobs;
}

/// Runs the jobs on `num_threads` threads (each takes the next job not started); the reports in job
/// order. False, after printing the first job's error in job order, when a job failed.
bool run_sim_jobs(const std::vector<SimJob>& jobs, const std::vector<vo::StrategySpec>& chosen,
                  const vo::RunnerOptions& ro, bool quiet, int num_threads, std::vector<vo::SequenceReport>* reports) {
  std::vector<vo::SequenceReport> done(jobs.size());
  std::vector<std::string> errors(jobs.size());
  std::atomic<std::size_t> next{0}, finished{0};
  auto worker = [&]() {
    for (std::size_t k = next++; k < jobs.size(); k = next++) {
      const auto started = std::chrono::steady_clock::now();
      vo::SimSource source(jobs[k].options);
      vo::SequenceReport& rep = done[k];
      rep.family = jobs[k].family;
      rep.sequence = jobs[k].sequence;
      rep.seed = jobs[k].seed;
      try {
        if (!vo::run_sequence(jobs[k].name, source, chosen, ro, &rep, &errors[k])) continue;
        vo::evaluate_against_recorded_truth(&rep, ro);
      } catch (const std::exception& e) {  // a worker thread's exception would abort the process
        errors[k] = jobs[k].name + ": stopped by an unexpected error: " + e.what();
        continue;
      }
      if (quiet)
        std::printf("[%zu/%zu] %s: %.0f s\n", ++finished, jobs.size(), jobs[k].name.c_str(),
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
      std::fflush(stdout);
    }
  };
  std::vector<std::thread> threads;
  const int n_threads = std::min<int>(num_threads, static_cast<int>(jobs.size()));
  for (int t = 1; t < n_threads; ++t) threads.emplace_back(worker);
  worker();
  for (std::thread& t : threads) t.join();
  for (std::size_t k = 0; k < jobs.size(); ++k) {
    if (!errors[k].empty()) {
      std::fprintf(stderr, "dynamic_vo: %s\n", errors[k].c_str());
      return false;
    }
    reports->push_back(std::move(done[k]));
  }
  return true;
}

/// The families' summary (Markdown and CSV) and the frame strip, written under args.out; returns the
/// summary and appends the figures written to `figures`.
std::string write_family_summary(const Args& args, const std::vector<vo::SequenceReport>& reports,
                                 const std::string& cmd, double seconds, std::vector<std::string>* figures) {
  const std::vector<vo::FamilyStrategySummary> rows = vo::summarise_families(reports);
  std::string summary = vo::format_family_summary(rows);
  summary += "\nCommand: `" + cmd + "` (" + vo::fmt(seconds, "%.0f") + " s, " + std::to_string(args.frames) +
             " frames a sequence)\n";
  std::ofstream(args.out + "/family_summary.md") << summary;
  std::ofstream(args.out + "/family_summary.csv") << vo::family_summary_csv(rows);
  if (vo::write_frame_strip(args.out + "/frame_strip.png", family_frames(reports))) figures->push_back("frame_strip.png");
  return summary;
}

/// Prints the truth decision reasons (and recall by speed) of every culling run, for --diagnose.
void print_diagnosis(const std::vector<vo::SequenceReport>& reports) {
  for (const auto& r : reports)
    for (const auto& run : r.runs)
      if (run.spec.culls)
        std::printf("\n%s / %s: instance truth decision reason count\n%s%s", r.name.c_str(), run.spec.name.c_str(),
                    run.breakdown.format().c_str(), run.recall_by_speed.format().c_str());
}

/// Prints and writes the synthetic run's results: the table (results.md), with several families their
/// summary; lists the files written.
void report_sim_run(const Args& args, const std::vector<vo::SequenceReport>& reports, const std::string& cmd,
                    double seconds) {
  std::string table = vo::format_table(reports, cmd, seconds);
  const bool several_families = args.tum.empty() && args.families.size() > 1;
  if (args.tum.empty() && args.seeds.size() > 1 && !several_families) table += "\n" + vo::format_seed_summary(reports);
  std::string summary;
  std::vector<std::string> figures;
  if (args.tum.empty() && args.families_set) {
    summary = write_family_summary(args, reports, cmd, seconds, &figures);
    table = summary + "\n" + table;
  }
  // Several families: the summary alone on screen (the per-sequence table is in results.md).
  std::printf("\n%s", several_families ? summary.c_str() : table.c_str());
  if (args.diagnose) print_diagnosis(reports);
  const std::string md = args.out + "/results.md";
  std::ofstream(md) << table;
  std::printf("\nwrote %s\n", md.c_str());
  if (!summary.empty())
    std::printf("wrote %s/family_summary.md\nwrote %s/family_summary.csv\n", args.out.c_str(), args.out.c_str());
  for (const std::string& f : figures) std::printf("wrote %s/%s\n", args.out.c_str(), f.c_str());
  std::size_t files = 0;
  for (const auto& r : reports) {
    for (const auto& f : r.files) {
      if (!several_families) std::printf("wrote %s\n", f.c_str());
      ++files;
    }
  }
  if (several_families) std::printf("wrote %zu trajectory files and images under %s\n", files, args.out.c_str());
}

}  // namespace

// Every failure has a reason and a status; an exception reaching here (OpenCV refusing an input the
// checks above missed) still ends with a message and exit 1, never an abort.
int main(int argc, char** argv) try {
  Args args;
  if (!parse_args(argc, argv, &args)) return 2;

  std::vector<vo::StrategySpec> all = vo::all_strategies();
  for (const vo::StrategySpec& s : vo::ablation_strategies()) all.push_back(s);
  if (args.list) {
    for (const auto& s : all)
      std::printf("%-26s %s%s%s\n", s.name.c_str(), s.description.c_str(),
                  s.needs_detections ? " [needs detections]" : "", s.in_default ? "" : " [only when named]");
    return 0;
  }
  std::vector<vo::StrategySpec> chosen;
  if (!choose_strategies(args.strategies, all, &chosen)) return 2;

  std::error_code ec;
  std::filesystem::create_directories(args.out, ec);
  if (ec) {
    std::fprintf(stderr, "dynamic_vo: cannot create %s: %s\n", text::quote_path(args.out).c_str(), ec.message().c_str());
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
    if (args.families_set || !args.scene.empty())
      std::printf("--family / --scene set the synthetic scene: ignored with --dataset.\n");
    return run_dataset_command(args, chosen, ro, argc, argv);
  }
  std::map<std::string, sim::TrajectoryOptions> recorded;  // the recordings, loaded once
  if (!load_recordings(args, &recorded)) return 2;
  const std::vector<SimJob> jobs = make_sim_jobs(args, recorded);
  // Several families: one line per finished sequence instead of the per-frame progress.
  const bool quiet = args.families.size() > 1;
  if (quiet) ro.print_progress = false;
  if (!run_sim_jobs(jobs, chosen, ro, quiet, args.jobs, &reports)) return 1;

  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::ostringstream cmd;
  for (int i = 0; i < argc; ++i) cmd << (i ? " " : "") << argv[i];
  report_sim_run(args, reports, cmd.str(), seconds);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "dynamic_vo: stopped by an unexpected error: %s\n", e.what());
  return 1;
}
