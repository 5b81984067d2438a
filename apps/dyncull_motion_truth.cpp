// dyncull_motion_truth: per-pixel motion truth of a real RGB-D sequence with ground-truth poses
// (truth/motion_truth.hpp; method and thresholds in docs/motion_truth.md), and the same labeller
// scored on the scene families, where the simulator knows every pixel.
//
//   dyncull_motion_truth --dataset DIR --out TRUTH_DIR [--frames N]
//       TRUTH_DIR/NNNNNN.png (0 static, 255 moving, 128 unknown; NNNNNN = the frame's index in rgb.txt),
//       TRUTH_DIR/index.txt ("stamp file" lines), TRUTH_DIR/summary.md; with DIR/detections also the share
//       of known pixels outside every person box labelled moving, and a strip of where they are.
//   dyncull_motion_truth --families LIST|all --out DIR [--frames N] [--jitter-mm X] [--jitter-deg Y]
//       precision and recall of "moving" on the known pixels, per family (sim_accuracy.csv / .md).
#include "dyncull/sim/families.hpp"
#include "dyncull/sim/scene.hpp"

#include "truth/motion_truth.hpp"
#include "vo/dataset.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace dyncull;

struct Args {
  std::string dataset, out;
  std::vector<std::string> families;
  int frames = 0;  // 0: the whole sequence (--dataset) or kSimFrames (--families)
  /// Independent pose noise per frame and axis added to the sim's ground truth: on the Bonn crowd
  /// sequence the labeller refines the ground-truth relative pose of frames 4 apart by a median 7.0 mm
  /// and 0.22 deg, the median difference of two such noises (2.18 sigma) at 3.2 mm and 0.10 deg.
  double jitter_mm = 3.2, jitter_deg = 0.10;
  truth::MotionTruthOptions labeller;
};

constexpr int kSimFrames = 40;

int usage(const char* why, int exit_code = 2) {
  std::fprintf(stderr,
               "dyncull_motion_truth: %s\n"
               "usage: dyncull_motion_truth --dataset DIR --out TRUTH_DIR [--frames N] [--window K]\n"
               "       dyncull_motion_truth --families LIST|all --out DIR [--frames N] [--jitter-mm X] "
               "[--jitter-deg Y] [--window K]\n"
               "  --window K      neighbours K frames before and after (default 4)\n"
               "  --static-px X   static below X px of residual in every neighbour (default 2)\n"
               "  --moving-px X   moving above X px in every neighbour that sees the pixel (default 4)\n",
               why);
  return exit_code;
}

bool parse_number(const std::string& s, double lo, double hi, double* out) {
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (end == s.c_str() || *end != '\0' || !(v >= lo && v <= hi)) return false;
  *out = v;
  return true;
}

bool parse_int(const std::string& s, long lo, long hi, int* out) {
  char* end = nullptr;
  const long v = std::strtol(s.c_str(), &end, 10);
  if (end == s.c_str() || *end != '\0' || v < lo || v > hi) return false;
  *out = static_cast<int>(v);
  return true;
}

/// --families NAME,NAME or all.
void add_families(const std::string& list, std::vector<std::string>* out) {
  std::stringstream ss(list);
  for (std::string f; std::getline(ss, f, ',');) {
    if (f == "all")
      for (const sim::SceneFamily& s : sim::scene_families()) out->push_back(s.name);
    else if (!f.empty())
      out->push_back(f);
  }
}

int parse_args(int argc, char** argv, Args* a) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") return usage("per-pixel motion truth of a real RGB-D sequence", -1);
    if (i + 1 >= argc) return usage((arg + " needs a value").c_str());
    const std::string v = argv[++i];
    bool ok = true;
    if (arg == "--dataset") a->dataset = v;
    else if (arg == "--out") a->out = v;
    else if (arg == "--families") add_families(v, &a->families);
    else if (arg == "--frames") ok = parse_int(v, 2, 100000, &a->frames);
    else if (arg == "--window") ok = parse_int(v, 1, 30, &a->labeller.window_frames);
    else if (arg == "--static-px") ok = parse_number(v, 0.1, 100, &a->labeller.static_px);
    else if (arg == "--moving-px") ok = parse_number(v, 0.1, 100, &a->labeller.moving_px);
    else if (arg == "--jitter-mm") ok = parse_number(v, 0, 100, &a->jitter_mm);
    else if (arg == "--jitter-deg") ok = parse_number(v, 0, 10, &a->jitter_deg);
    else ok = false;
    if (!ok) return usage(("unknown option or bad value: " + text::quote_token(arg) + " " + text::quote_token(v)).c_str());
  }
  if (a->out.empty()) return usage("--out is required");
  if (a->dataset.empty() == a->families.empty()) return usage("give either --dataset or --families");
  return 0;
}

/// The pose at `stamp` interpolated between the two ground-truth poses around it (rotation by slerp);
/// false when the stamp is more than 20 ms from the trajectory's ends.
bool pose_at(const eval::Trajectory<double>& gt, double stamp, Rigid3<double>* out) {
  const auto it = std::lower_bound(gt.stamps.begin(), gt.stamps.end(), stamp);
  const std::size_t hi = static_cast<std::size_t>(it - gt.stamps.begin());
  if (hi == 0 || hi == gt.size()) {
    const std::size_t k = hi == 0 ? 0 : gt.size() - 1;
    if (gt.empty() || std::abs(gt.stamps[k] - stamp) > 0.02) return false;
    *out = gt.poses[k];
    return true;
  }
  const double a = (stamp - gt.stamps[hi - 1]) / (gt.stamps[hi] - gt.stamps[hi - 1]);
  const Eigen::Quaterniond q0(gt.poses[hi - 1].R), q1(gt.poses[hi].R);
  out->R = q0.slerp(a, q1).toRotationMatrix();
  out->t = (1 - a) * gt.poses[hi - 1].t + a * gt.poses[hi].t;
  return true;
}

std::string frame_file(std::size_t i) {
  char name[32];
  std::snprintf(name, sizeof name, "%06zu.png", i);
  return name;
}

/// The labels over the grey frame: moving red, static green, unknown left grey; person boxes in white,
/// moving pixels outside every person box in yellow.
cv::Mat overlay(const cv::Mat& gray, const cv::Mat& labels, const std::vector<Detection<float>>& boxes,
                const cv::Mat& outside_people) {
  cv::Mat bgr;
  cv::cvtColor(gray, bgr, cv::COLOR_GRAY2BGR);
  cv::Mat tint = bgr.clone();
  tint.setTo(cv::Scalar(60, 200, 60), labels == truth::kStatic);
  tint.setTo(cv::Scalar(40, 40, 230), labels == truth::kMoving);
  tint.setTo(cv::Scalar(0, 230, 255), outside_people);
  cv::addWeighted(bgr, 0.45, tint, 0.55, 0, bgr);
  for (const Detection<float>& d : boxes)
    if (d.class_id == vo::BoxCullCounts::kPersonClass)
      cv::rectangle(bgr, cv::Point2f(d.box.x0, d.box.y0), cv::Point2f(d.box.x1, d.box.y1), cv::Scalar(255, 255, 255), 2);
  return bgr;
}

/// 255 inside some person box.
cv::Mat in_person_boxes(cv::Size size, const std::vector<Detection<float>>& boxes) {
  cv::Mat inside(size, CV_8UC1, cv::Scalar(0));
  for (const Detection<float>& d : boxes)
    if (d.class_id == vo::BoxCullCounts::kPersonClass)
      cv::rectangle(inside, cv::Point2f(d.box.x0, d.box.y0), cv::Point2f(d.box.x1, d.box.y1), cv::Scalar(255), cv::FILLED);
  return inside;
}

/// 255 where a moving pixel lies outside every person box.
cv::Mat moving_outside_people(const cv::Mat& labels, const std::vector<Detection<float>>& boxes) {
  return (labels == truth::kMoving) & ~in_person_boxes(labels.size(), boxes);
}

struct Totals {
  std::size_t with_depth = 0, known = 0, moving = 0;
  std::size_t known_outside_people = 0, moving_outside_people = 0;
  std::vector<double> correction_mm, correction_deg, static_px;
  std::size_t pairs = 0, pairs_fitted = 0;
  void add(const truth::FrameTruth& f) {
    with_depth += f.with_depth;
    known += f.known;
    moving += f.moving;
    for (const truth::PoseCorrection& c : f.corrections) {
      ++pairs;
      if (!c.fitted) continue;
      ++pairs_fitted;
      correction_mm.push_back(1000 * c.translation_m);
      correction_deg.push_back(c.rotation_deg);
      static_px.push_back(c.static_median_px);
    }
  }
};

double share(std::size_t a, std::size_t b) { return b ? static_cast<double>(a) / static_cast<double>(b) : 0.0; }

/// Opens the dataset (images, depth, ground truth; no boxes) and loads its frames with their poses.
bool load_frames(const Args& args, vo::DatasetSource* source, std::vector<truth::TruthFrame>* frames,
                 std::string* error) {
  vo::DatasetOptions options;
  options.dir = args.dataset;
  options.detections = "none";  // the labeller uses no boxes
  if (!source->open(options, error)) return false;
  if (source->index().groundtruth_path.empty()) {
    *error = args.dataset + ": no groundtruth.txt";
    return false;
  }
  const eval::TrajectoryReadResult<double> gt = eval::read_tum_trajectory<double>(source->index().groundtruth_path);
  if (!gt.ok()) {
    *error = gt.reason;
    return false;
  }
  const int n = args.frames > 0 ? std::min(args.frames, source->size()) : source->size();
  frames->assign(static_cast<std::size_t>(n), truth::TruthFrame{});
  for (int i = 0; i < n; ++i) {
    vo::SequenceFrame f;
    if (!source->load(i, &f, error)) return false;
    truth::TruthFrame& t = (*frames)[static_cast<std::size_t>(i)];
    t.gray = f.gray.clone();
    if (cv::countNonZero(f.depth_m) > 0) t.depth_m = f.depth_m.clone();
    t.has_pose = pose_at(gt.trajectory, f.timestamp, &t.world_from_cam);
  }
  return true;
}

/// The summary's lines on the known pixels outside every person box, and the strip of the four frames
/// with the most of them labelled moving.
std::string outside_boxes_report(const Args& args, const std::vector<truth::TruthFrame>& frames,
                                 const eval::SequenceDetections& boxes, const Totals& totals,
                                 std::vector<std::pair<std::size_t, int>> outside_by_frame) {
  std::ostringstream md;
  md << "- known pixels outside every person box labelled moving: "
     << vo::fmt(100 * share(totals.moving_outside_people, totals.known_outside_people), "%.2f %%") << "\n";
  std::sort(outside_by_frame.rbegin(), outside_by_frame.rend());
  std::vector<vo::StripFrame> strip;
  for (std::size_t k = 0; k < outside_by_frame.size() && k < 4; ++k) {
    const std::size_t i = static_cast<std::size_t>(outside_by_frame[k].second);
    const cv::Mat labels = cv::imread(args.out + "/" + frame_file(i), cv::IMREAD_GRAYSCALE);
    const std::vector<Detection<float>>& b = boxes.per_frame[i];
    const std::string path = args.out + "/outside_boxes_" + frame_file(i);
    cv::imwrite(path, overlay(frames[i].gray, labels, b, moving_outside_people(labels, b)));
    strip.push_back({path, "frame " + std::to_string(i) + ": " + std::to_string(outside_by_frame[k].first) +
                               " moving px outside person boxes (yellow)"});
  }
  if (vo::write_frame_strip(args.out + "/outside_boxes_strip.png", strip, 360, 2, 16))
    md << "\n![moving pixels outside person boxes](outside_boxes_strip.png)\n";
  return md.str();
}

int label_dataset(const Args& args) {
  vo::DatasetSource source;
  std::vector<truth::TruthFrame> frames;
  std::string error;
  if (!load_frames(args, &source, &frames, &error))
    return std::fprintf(stderr, "dyncull_motion_truth: %s\n", error.c_str()), 1;
  // Boxes only to report where the moving pixels fall, never to decide.
  const std::string det_dir = args.dataset + "/detections";
  const bool has_dir = std::filesystem::exists(det_dir);
  const eval::SequenceDetections boxes =
      has_dir ? eval::read_sequence_detections(det_dir, source.index(), source.camera().width, source.camera().height)
              : eval::SequenceDetections{};
  const bool has_boxes = has_dir && boxes.ok();
  std::filesystem::create_directories(args.out);
  std::ofstream index(args.out + "/index.txt");
  index << "# motion truth: stamp file (0 static, 255 moving, 128 unknown)\n";
  truth::MotionLabeller labeller(args.labeller);
  Totals totals;
  std::vector<std::pair<std::size_t, int>> outside_by_frame;  // moving pixels outside person boxes, frame
  const auto t0 = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const truth::FrameTruth f = labeller.label(frames, static_cast<int>(i), source.camera());
    totals.add(f);
    cv::imwrite(args.out + "/" + frame_file(i), f.labels);
    char stamp[32];
    std::snprintf(stamp, sizeof stamp, "%.6f", source.index().frames[i].timestamp);
    index << stamp << " " << frame_file(i) << "\n";
    if (!has_boxes) continue;
    const cv::Mat outside_people = ~in_person_boxes(f.labels.size(), boxes.per_frame[i]);
    const cv::Mat known_outside = (f.labels != truth::kUnknown) & outside_people;
    const std::size_t m = static_cast<std::size_t>(cv::countNonZero((f.labels == truth::kMoving) & outside_people));
    totals.known_outside_people += static_cast<std::size_t>(cv::countNonZero(known_outside));
    totals.moving_outside_people += m;
    outside_by_frame.emplace_back(m, static_cast<int>(i));
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::ostringstream md;
  auto med = [](std::vector<double> v) { return truth::detail::median(std::move(v)); };
  md << "Motion truth of `" << args.dataset << "`: " << frames.size() << " frames in " << vo::fmt(seconds, "%.0f")
     << " s.\n\n"
     << "- pixels with depth labelled known: " << vo::fmt(100 * share(totals.known, totals.with_depth), "%.1f %%") << "\n"
     << "- known pixels labelled moving: " << vo::fmt(100 * share(totals.moving, totals.known), "%.1f %%") << "\n"
     << "- ground-truth pose refined on " << totals.pairs_fitted << " of " << totals.pairs
     << " neighbour pairs; median refinement " << vo::fmt(med(totals.correction_mm), "%.1f") << " mm and "
     << vo::fmt(med(totals.correction_deg), "%.3f") << " deg; median static residual after it "
     << vo::fmt(med(totals.static_px), "%.2f") << " px\n";
  if (has_boxes) md << outside_boxes_report(args, frames, boxes, totals, outside_by_frame);
  else if (has_dir) md << "- detections not read (" << boxes.reason << "): no report on the person boxes\n";
  std::ofstream(args.out + "/summary.md") << md.str();
  std::printf("%s", md.str().c_str());
  return 0;
}

/// Small independent pose noise: the error the ground truth is assumed to have.
Rigid3<double> jittered(const Rigid3<double>& pose, double sigma_m, double sigma_deg, std::mt19937_64* rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  const Vec3<double> axis_angle(n(*rng), n(*rng), n(*rng));
  const double angle = sigma_deg * 3.14159265358979323846 / 180.0;
  Rigid3<double> noise;
  const Vec3<double> w = axis_angle * angle;
  if (w.norm() > 0) noise.R = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
  noise.t = Vec3<double>(n(*rng), n(*rng), n(*rng)) * sigma_m;
  return pose * noise;
}

/// A surface moving this much a frame moves 8 mm in the 4-frame window, 2.8 px at 1.5 m; slower ones
/// fall near or under the static threshold (2 px), where the labeller calls them static by design.
constexpr double kSlowSurfaceM = 0.002;

struct Accuracy {
  std::size_t tp = 0, fp = 0, fn = 0, tn = 0, with_depth = 0, known = 0;
  std::size_t tp_fast = 0, fn_fast = 0;  ///< of the surfaces moving at least kSlowSurfaceM a frame
  double precision() const { return share(tp, tp + fp); }
  double recall() const { return share(tp, tp + fn); }
  double recall_fast() const { return share(tp_fast, tp_fast + fn_fast); }
};

Accuracy score_family(const sim::SceneFamily& family, const Args& args) {
  sim::SceneOptions o = family.options;
  o.num_frames = args.frames > 0 ? args.frames : kSimFrames;
  o.motion = sim::CameraMotion::Xyz;
  o.seed = 1;
  sim::Scene scene(o);
  std::mt19937_64 rng(7);
  std::vector<truth::TruthFrame> frames(static_cast<std::size_t>(o.num_frames));
  std::vector<cv::Mat> moving(frames.size()), motion_m(frames.size());
  sim::FrameData d;
  for (int i = 0; i < o.num_frames; ++i) {
    scene.render(i, &d);
    truth::TruthFrame& f = frames[static_cast<std::size_t>(i)];
    f.gray = cv::Mat(d.height, d.width, CV_8UC1, d.gray.data()).clone();
    f.depth_m = cv::Mat(d.height, d.width, CV_32FC1, d.depth_m.data()).clone();
    f.has_pose = true;
    f.world_from_cam = jittered(d.world_from_cam, args.jitter_mm / 1000, args.jitter_deg, &rng);
    moving[static_cast<std::size_t>(i)] = cv::Mat(d.height, d.width, CV_8UC1, d.moving.data()).clone();
    motion_m[static_cast<std::size_t>(i)] = cv::Mat(d.height, d.width, CV_32FC1, d.motion_m.data()).clone();
  }
  truth::MotionLabeller labeller(args.labeller);
  Accuracy a;
  for (int i = 0; i < o.num_frames; ++i) {
    const truth::FrameTruth f = labeller.label(frames, i, scene.camera());
    a.with_depth += f.with_depth;
    a.known += f.known;
    const cv::Mat& m = moving[static_cast<std::size_t>(i)];
    const cv::Mat& speed = motion_m[static_cast<std::size_t>(i)];
    for (int v = 0; v < m.rows; ++v)
      for (int u = 0; u < m.cols; ++u) {
        const std::uint8_t l = f.labels.at<std::uint8_t>(v, u);
        if (l == truth::kUnknown) continue;
        const bool says = l == truth::kMoving, is = m.at<std::uint8_t>(v, u) != 0;
        (says ? (is ? a.tp : a.fp) : (is ? a.fn : a.tn)) += 1;
        if (is && speed.at<float>(v, u) >= kSlowSurfaceM) (says ? a.tp_fast : a.fn_fast) += 1;
      }
  }
  return a;
}

int score_families(const Args& args) {
  std::filesystem::create_directories(args.out);
  std::ostringstream csv, md;
  csv << "family,precision,recall,recall_2mm,known_share,moving_share,tp,fp,fn,tn\n";
  md << "| family | precision | recall | recall, surfaces moving >= 2 mm a frame | known / with depth | moving / known "
        "|\n|---|---|---|---|---|---|\n";
  for (const std::string& name : args.families) {
    sim::SceneFamily family;
    std::string why;
    if (!sim::find_scene_family(name, &family, &why))
      return std::fprintf(stderr, "dyncull_motion_truth: %s\n", why.c_str()), 2;
    const Accuracy a = score_family(family, args);
    csv << name << "," << vo::fmt(a.precision(), "%.4f") << "," << vo::fmt(a.recall(), "%.4f") << ","
        << vo::fmt(a.recall_fast(), "%.4f") << "," << vo::fmt(share(a.known, a.with_depth), "%.4f") << ","
        << vo::fmt(share(a.tp + a.fp, a.known), "%.4f") << ","
        << a.tp << "," << a.fp << "," << a.fn << "," << a.tn << "\n";
    md << "| " << name << " | " << vo::fmt(a.precision(), "%.3f") << " | " << vo::fmt(a.recall(), "%.3f") << " | "
       << vo::fmt(a.recall_fast(), "%.3f") << " | " << vo::fmt(100 * share(a.known, a.with_depth), "%.1f %%") << " | "
       << vo::fmt(100 * share(a.tp + a.fp, a.known), "%.1f %%") << " |\n";
    std::printf("%s", md.str().substr(md.str().rfind("| " + name)).c_str());
    std::fflush(stdout);
  }
  std::ofstream(args.out + "/sim_accuracy.csv") << csv.str();
  std::ofstream(args.out + "/sim_accuracy.md") << md.str();
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  if (const int stop = parse_args(argc, argv, &args)) return stop < 0 ? 0 : stop;
  return args.dataset.empty() ? score_families(args) : label_dataset(args);
}
