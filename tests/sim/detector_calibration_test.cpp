// The Calibrated detector model against the real YOLOv8n streams of TUM fr3 (through DYNCULL_DATA_DIR):
// the same statistics computed the same way on both (frame-to-frame box-edge motion on still seated
// people, one-frame person dropouts, person-box area, classes reported), within stated tolerances.
#include "dyncull/eval/yolo_json.hpp"
#include "dyncull/sim/scene.hpp"

#include <gtest/gtest.h>

#include "support/real_data.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

namespace {

using dyncull::Box;
using dyncull::Detection;
using namespace dyncull::sim;

using Frames = std::vector<std::vector<Detection<float>>>;

struct StreamStats {
  double person_area = 0;       // mean over frames of the summed person-box area / image area
  double edge_median_px = 0;    // |edge(t+1) - edge(t)| over the 4 edges of matched person boxes
  double edge_p90_px = 0;
  double dropout_rate = 0;      // frames where a person seen before and after is missing / frames
  double person_confidence = 0;  // median confidence of the person boxes
  std::map<int, double> class_frames;  // class -> fraction of frames reporting it
};

float box_iou(const Box<float>& a, const Box<float>& b) { return dyncull::iou(a, b); }

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5)];
}

// Person boxes of consecutive frames are the same person at IoU > 0.5 (edge motion; seated people
// overlap themselves far more) and at IoU > 0.3 across a gap (dropouts: the box tracker's gate).
StreamStats stream_stats(const Frames& frames, int width, int height) {
  StreamStats s;
  const std::size_t n = frames.size();
  auto people = [&](std::size_t i) {
    std::vector<Box<float>> out;
    for (const auto& d : frames[i])
      if (d.class_id == 0) out.push_back(d.box);
    return out;
  };
  auto has_match = [](const std::vector<Box<float>>& boxes, const Box<float>& b, float min_iou) {
    for (const auto& c : boxes)
      if (box_iou(b, c) > min_iou) return true;
    return false;
  };
  std::vector<double> edges, confidences;
  std::size_t dropouts = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto p = people(i);
    double area = 0;
    for (const auto& b : p) area += static_cast<double>((b.x1 - b.x0) * (b.y1 - b.y0));
    s.person_area += area / (static_cast<double>(width) * height);
    std::map<int, int> seen;
    for (const auto& d : frames[i]) {
      seen[d.class_id] = 1;
      if (d.class_id == 0) confidences.push_back(d.confidence);
    }
    for (const auto& [c, one] : seen) s.class_frames[c] += one;
    if (i + 1 < n) {
      const auto q = people(i + 1);
      for (const auto& b : p) {
        const Box<float>* best = nullptr;
        float best_iou = 0.5f;
        for (const auto& c : q)
          if (box_iou(b, c) > best_iou) best_iou = box_iou(b, c), best = &c;
        if (best == nullptr) continue;
        for (double e : {b.x0 - best->x0, b.y0 - best->y0, b.x1 - best->x1, b.y1 - best->y1}) edges.push_back(std::abs(e));
      }
    }
    if (i > 0 && i + 1 < n) {
      const auto before = people(i - 1), after = people(i + 1);
      for (const auto& b : before) {
        if (has_match(after, b, 0.3f) && !has_match(p, b, 0.3f)) {
          ++dropouts;
          break;
        }
      }
    }
  }
  s.person_area /= static_cast<double>(n);
  for (auto& [c, f] : s.class_frames) f /= static_cast<double>(n);
  s.edge_median_px = quantile(edges, 0.5);
  s.edge_p90_px = quantile(edges, 0.9);
  s.dropout_rate = static_cast<double>(dropouts) / static_cast<double>(n);
  s.person_confidence = quantile(confidences, 0.5);
  return s;
}

void print(const char* name, const StreamStats& s) {
  std::printf("%-26s person area %.3f  edge median %.2f px  p90 %.2f px  one-frame dropouts %.4f  person conf %.2f\n"
              "  classes:", name, s.person_area, s.edge_median_px, s.edge_p90_px, s.dropout_rate, s.person_confidence);
  for (const auto& [c, f] : s.class_frames) std::printf(" %d:%.2f", c, f);
  std::printf("\n");
}

SceneOptions sitting_scene(std::uint64_t seed, int frames) {
  SceneOptions o;
  o.seed = seed;
  o.num_frames = frames;
  o.motion = CameraMotion::Static;
  o.depth_noise = false;
  o.actors.walking_people = 0;
  o.actors.sitting_person = false;
  o.actors.pushed_chair = false;
  o.actors.desk_people = 2;
  o.actors.desk_clutter = true;
  use_calibrated_detector(&o);
  return o;
}

Frames sim_detections(const SceneOptions& o) {
  const Scene scene(o);
  EXPECT_TRUE(scene.ok()) << scene.reason();
  Frames out;
  FrameData f;
  for (int i = 0; i < scene.num_frames(); ++i) {
    scene.render(i, &f);
    out.push_back(f.detections);
  }
  return out;
}

Frames real_detections(const std::string& root, const char* sequence) {
  const auto seq = dyncull::eval::read_yolo_json_sequence<float>(root + "/tum/" + sequence + "/yolov8n");
  EXPECT_TRUE(seq.ok()) << seq.reason;
  Frames out;
  for (const auto& f : seq.frames) out.push_back(f.detections);
  return out;
}

TEST(SimDetectorCalibration, CalibratedModelMatchesTheRealYoloStreams) {
  std::string why_not;
  const std::string root = dyncull::test::real_data_dir(&why_not);
  if (root.empty()) GTEST_SKIP() << why_not;
  const StreamStats real_sitting = stream_stats(real_detections(root, "fr3_sitting_static"), 640, 480);
  print("real sitting_static", real_sitting);
  double real_dropout_max = 0;
  std::map<int, double> real_classes;  // class -> largest fraction of frames over the four streams
  for (const char* name : {"fr3_walking_xyz", "fr3_walking_static", "fr3_sitting_static", "fr3_sitting_xyz"}) {
    const StreamStats s = name == std::string("fr3_sitting_static") ? real_sitting
                                                                     : stream_stats(real_detections(root, name), 640, 480);
    if (name != std::string("fr3_sitting_static")) print((std::string("real ") + (name + 4)).c_str(), s);
    real_dropout_max = std::max(real_dropout_max, s.dropout_rate);
    for (const auto& [c, f] : s.class_frames) real_classes[c] = std::max(real_classes[c], f);
  }

  // Two seeds of the sitting scene, 150 frames (5 s) each: enough for stable quantiles (over 2000
  // edge steps) at a test's cost.
  Frames sim;
  for (std::uint64_t seed : {3u, 4u}) {
    const Frames f = sim_detections(sitting_scene(seed, 150));
    sim.insert(sim.end(), f.begin(), f.end());
  }
  const StreamStats s = stream_stats(sim, 640, 480);
  print("sim sitting (calibrated)", s);

  // Edge motion on still seated people: the four real streams give medians 1.0-1.7 px and 90th
  // percentiles 5.8-9.6 px (the walking ones include walkers); the sim is held to the seated
  // stream's within a third of a pixel on the median and 1.5 px on the tail.
  EXPECT_NEAR(s.edge_median_px, real_sitting.edge_median_px, 0.35);
  EXPECT_NEAR(s.edge_p90_px, real_sitting.edge_p90_px, 1.5);
  // Heavy tail: the 90th percentile is several times the median, as on every real stream (5-6x);
  // a Gaussian jitter gives about 2.4x.
  EXPECT_GT(s.edge_p90_px, 3.5 * s.edge_median_px);
  // Person-box area: real 0.546 on sitting_static; the sim's two desk people within 0.04 (the real
  // streams differ by more: 0.46 on sitting_xyz).
  EXPECT_NEAR(s.person_area, real_sitting.person_area, 0.04);
  // One-frame person dropouts: the real streams have 0-1.4 % of frames; the sim is held below the
  // largest real rate plus a margin for its 300 frames (one dropout is 0.33 %), and must have some.
  EXPECT_LE(s.dropout_rate, real_dropout_max + 0.007);
  EXPECT_GT(s.dropout_rate, 0.0);
  // Person confidence: the real streams' medians are 0.87-0.89; within 0.03.
  EXPECT_NEAR(s.person_confidence, real_sitting.person_confidence, 0.03);
  // Classes: everything the sim reports is a class the real detector reports on these sequences
  // (book aside: the sim's desk has one as the data's description lists, the four streams show none).
  for (const auto& [c, f] : s.class_frames) {
    if (c == CocoClass::kBook) continue;
    EXPECT_TRUE(real_classes.count(c)) << "class " << c << " reported by the sim in " << f << " of frames, never by YOLOv8n";
  }
  // ... and the classes the real detector reports in at least a fifth of a stream's frames (person,
  // tv, chair, keyboard, mouse, bottle) are reported by the sim too; people and monitors in almost
  // every frame as on the real streams (tv in 97-100 %).
  auto sim_frames = [&](int c) { return s.class_frames.count(c) ? s.class_frames.at(c) : 0.0; };
  for (const auto& [c, f] : real_classes) {
    if (f >= 0.2) {
      EXPECT_GT(sim_frames(c), 0.05) << "class " << c;
    }
  }
  EXPECT_GT(sim_frames(CocoClass::kPerson), 0.97);
  EXPECT_GT(sim_frames(CocoClass::kTv), 0.95);
}

TEST(SimDetectorCalibration, GaussianModelIsTodaysAndCalibratedIsDeterministic) {
  SceneOptions o = sitting_scene(5, 4);
  o.width = 160;
  o.height = 120;
  o.min_detection_pixels = 20;
  const Frames a = sim_detections(o), b = sim_detections(o);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].size(), b[i].size());
    for (std::size_t k = 0; k < a[i].size(); ++k) {
      EXPECT_EQ(a[i][k].box.x0, b[i][k].box.x0);
      EXPECT_EQ(a[i][k].confidence, b[i][k].confidence);
    }
  }
  // Calibrated confidences follow the class (people about 0.87, desk objects about 0.62), never
  // below the detector's threshold.
  for (const auto& frame : a)
    for (const auto& d : frame) EXPECT_GE(d.confidence, o.detector.min_confidence);
  EXPECT_EQ(std::string(to_string(DetectorModel::Calibrated)), "calibrated");
  EXPECT_EQ(SceneOptions{}.detector.model, DetectorModel::Gaussian);
}

TEST(SimDetectorCalibration, BadDetectorOptionsAreNamed) {
  const std::pair<void (*)(SceneOptions*), const char*> cases[] = {
      {[](SceneOptions* o) { o->detector.tail_probability = 1.5; }, "detector.tail_probability"},
      {[](SceneOptions* o) { o->detector.tail_scale = -1; }, "detector.tail_scale"},
      {[](SceneOptions* o) { o->detector.object_miss_rate = std::nan(""); }, "detector.object_miss_rate"},
      {[](SceneOptions* o) { o->detector.confidence_sd = -0.1; }, "detector.confidence_sd"},
      {[](SceneOptions* o) { o->detector.border_confidence_drop = 2; }, "detector.border_confidence_drop"},
      {[](SceneOptions* o) { o->detector.min_confidence = 1; }, "detector.min_confidence"},
      {[](SceneOptions* o) { o->detector.model = static_cast<DetectorModel>(9); }, "detector.model"},
  };
  for (const auto& [set, field] : cases) {
    SceneOptions o;
    set(&o);
    std::string why;
    EXPECT_EQ(o.validate(&why), dyncull::Status::InvalidInput) << field;
    EXPECT_NE(why.find(field), std::string::npos) << why;
  }
  use_calibrated_detector(nullptr);  // must not crash
}

}  // namespace
