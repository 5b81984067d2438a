/// @file stage_context.hpp
/// Small hand-built frames for the culling stages' own tests (culling/stages/*.hpp, run in order by
/// pipeline.hpp), and a byte digest of each part of the per-frame context (stages/context.hpp) and of each
/// stage report, so a test can check that a stage wrote only its own output.
#pragma once

#include "dyncull/culling/stages/context.hpp"
#include "dyncull/culling/stages/listed.hpp"
#include "dyncull/culling/stages/inputs.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <map>
#include <ostream>
#include <string>
#include <type_traits>
#include <vector>

namespace dyncull {

// Labels and reasons by name in GoogleTest's failure messages (found by argument-dependent lookup).
inline void PrintTo(FeatureLabel label, std::ostream* os) { *os << to_string(label); }
inline void PrintTo(CullReason reason, std::ostream* os) { *os << to_string(reason); }

namespace test {

/// The multi-view stage's output in a frame's buffers.
template <class T>
detail::StageMarks<MultiViewStage<T>>& multiview_marks(detail::PipelineWork<T>* w) {
  return w->template marks_of<MultiViewStage<T>>();
}
template <class T>
const detail::StageMarks<MultiViewStage<T>>& multiview_marks(const detail::PipelineWork<T>* w) {
  return w->template marks_of<MultiViewStage<T>>();
}

/// One frame drawn by hand: owns every input a CullingFrame points to. Depth in float metres, 0 = none.
template <class T>
struct StageFrame {
  PinholeCamera<T> camera;
  std::vector<Vec2<T>> keypoints, prev_keypoints;
  std::vector<std::uint8_t> track_valid;  ///< empty: not given
  std::vector<std::int64_t> track_ids;    ///< empty: not given
  std::vector<Vec3<T>> points_3d;         ///< empty: not given
  std::vector<Detection<T>> detections;
  bool with_detections = true;
  bool with_tracks = true;
  std::vector<float> depth;  ///< empty: no depth image
  Rigid3<T> cam_from_world;
  bool with_pose = true;
  int evidence_frames = 0;

  /// A width x height camera (focal length 500 px, principal point at the centre).
  explicit StageFrame(int width = 64, int height = 48) {
    camera.width = width;
    camera.height = height;
    camera.fx = camera.fy = T(500);
    camera.cx = T(width) / T(2);
    camera.cy = T(height) / T(2);
  }
  std::size_t size() const { return keypoints.size(); }
  /// A feature at (x, y) tracked from (px, py).
  void add(T x, T y, T px, T py) {
    keypoints.emplace_back(x, y);
    prev_keypoints.emplace_back(px, py);
  }
  void add(T x, T y) { add(x, y, x, y); }
  void detect(int class_id, T x0, T y0, T x1, T y1, T confidence = T(0.9)) {
    detections.push_back(Detection<T>{Box<T>{x0, y0, x1, y1}, class_id, confidence});
  }
  /// Fills the depth image with `background_m`.
  void fill_depth(float background_m) {
    depth.assign(static_cast<std::size_t>(camera.width) * static_cast<std::size_t>(camera.height), background_m);
  }
  /// Sets depth `metres` over columns [c0, c1) and rows [r0, r1).
  void paint_depth(int c0, int r0, int c1, int r1, float metres) {
    for (int v = r0; v < r1; ++v)
      for (int u = c0; u < c1; ++u) depth[static_cast<std::size_t>(v) * camera.width + u] = metres;
  }
  DepthView<float> depth_view() const {
    if (depth.empty()) return DepthView<float>{};
    return DepthView<float>{depth.data(), camera.width, camera.height, 0, 1.f, 0.f, 1e30f};
  }

  CullingFrame<T, std::vector<Vec2<T>>> frame() const {
    CullingFrame<T, std::vector<Vec2<T>>> f;
    f.keypoints = &keypoints;
    f.prev_keypoints = with_tracks ? &prev_keypoints : nullptr;
    if (!track_valid.empty()) f.track_valid = track_valid;
    f.track_ids = track_ids.empty() ? nullptr : &track_ids;
    f.points_3d = points_3d.empty() ? nullptr : &points_3d;
    f.detections = with_detections ? &detections : nullptr;
    f.depth = depth_view();
    f.camera = camera;
    f.cam_from_world = with_pose ? &cam_from_world : nullptr;
    f.evidence_frames = evidence_frames;
    return f;
  }
};

/// A result as the frame's first stage leaves it for the others: n features labelled Static, every
/// report reset and enabled as `options` say.
template <class T>
PipelineResult<T> fresh_result(const PipelineOptions<T>& options, std::size_t n) {
  PipelineResult<T> r;
  detail::begin_frame(options, &r);
  r.num_features = n;
  r.labels.assign(n, FeatureLabel::Static);
  r.reasons.assign(n, CullReason::None);
  return r;
}

/// An enabled stage that did not run for lack of an input of the frame, and whose reason names that input
/// (as CullingFrame names it).
inline void expect_lacks_input(const StageReport& stage, const char* input) {
  EXPECT_TRUE(stage.enabled);
  EXPECT_FALSE(stage.ran());
  EXPECT_NE(stage.status, Status::Ok);
  EXPECT_NE(stage.reason.find(input), std::string::npos) << stage.reason;
}

/// Appends the bytes of values (no padding in any type passed here).
class Bytes {
 public:
  template <class X>
  Bytes& add(const X& x) {
    static_assert(std::is_trivially_copyable<X>::value, "plain values only");
    const auto* p = reinterpret_cast<const char*>(&x);
    s_.append(p, sizeof(X));
    return *this;
  }
  Bytes& add(const std::string& x) {
    add(x.size());
    s_ += x;
    return *this;
  }
  template <class X>
  Bytes& add(const std::vector<X>& v) {
    add(v.size());
    for (const X& x : v) add(x);
    return *this;
  }
  template <class T>
  Bytes& add(const Detection<T>& d) {
    return add(d.box.x0).add(d.box.y0).add(d.box.x1).add(d.box.y1).add(d.class_id).add(d.confidence);
  }
  template <class T>
  Bytes& add(const Vec2<T>& p) {
    return add(p.x()).add(p.y());
  }
  Bytes& add(const Mask& m) { return add(m.width).add(m.height).add(m.pixels); }
  const std::string& str() const { return s_; }

 private:
  std::string s_;
};

using Parts = std::map<std::string, std::string>;

/// Each part of the per-frame context, as bytes.
template <class T>
Parts parts_of(const detail::PipelineWork<T>& w) {
  Parts p;
  const auto& g = w.regions;
  p["regions"] = Bytes()
                     .add(g.boxes)
                     .add(g.dyn_boxes)
                     .add(g.untracked_boxes)
                     .add(g.dyn_box_source)
                     .add(g.box_track_id)
                     .add(g.dyn_box_track_id)
                     .str();
  const auto& s = w.semantic;
  p["semantic"] = Bytes()
                      .add(s.rule.status)
                      .add(s.rule.labels)
                      .add(s.rule.reasons)
                      .add(s.rule.box_index)
                      .add(s.rule_ok)
                      .add(s.labels)
                      .add(s.reasons)
                      .add(s.in_dyn_box)
                      .add(s.in_object)
                      .add(s.object_box_bits)
                      .add(s.masks)
                      .add(s.head_band_box)
                      .str();
  const auto& pr = w.probability;
  p["probability"] = Bytes().add(pr.ok).add(pr.labels).add(pr.reasons).add(pr.levels).add(pr.prev).str();
  const auto& ge = w.geometric;
  p["geometric"] = Bytes()
                       .add(ge.moving.status)
                       .add(ge.moving.labels)
                       .add(ge.moving.distance_px)
                       .add(ge.reprojection.status)
                       .add(ge.reprojection.labels)
                       .add(ge.reprojection.residual_px)
                       .add(ge.labels)
                       .add(ge.source)
                       .add(ge.ok)
                       .add(ge.fit_outside_boxes)
                       .str();
  const auto& v = w.votes;
  p["votes"] = Bytes()
                   .add(v.coherent.status)
                   .add(v.evidence)
                   .add(v.coherent_ran)
                   .add(v.coherent_eligible)
                   .add(v.remembered_cells)
                   .add(v.subbox.status)
                   .add(v.subbox.labels)
                   .add(v.subbox.reasons)
                   .add(v.subbox.cells)
                   .add(v.ok)
                   .str();
  const auto& m = w.template marks_of<MultiViewStage<T>>();
  p["multiview"] =
      Bytes().add(m.work.check.labels).add(m.work.mask).add(m.work.ref_index).add(m.marks).add(m.ok).str();
  p["history"] = Bytes().add(w.still_frames).add(w.history_kept).add(w.keypoint_depth).str();
  return p;
}

/// Each stage report of a frame's result, and the frame's own outcome ("frame"), as bytes.
template <class T>
Parts parts_of(const PipelineResult<T>& r) {
  Parts p;
  auto report = [](const StageReport& st) {
    return Bytes().add(st.enabled).add(st.status).add(st.reason).add(st.num_dynamic).str();
  };
  p["detections"] = report(r.detections);
  p["tracker"] = report(r.tracker);
  p["box_rule"] = report(r.box_rule);
  p["depth_mask"] = report(r.depth_mask);
  p["probability"] = report(r.probability);
  p["moving_consistency"] = report(r.moving_consistency);
  p["reprojection"] = report(r.reprojection);
  p["coherent_motion"] = report(r.coherent_motion);
  p["subbox"] = report(r.subbox);
  p["multiview"] = report(r.multiview);
  p["static_history"] = report(r.static_history);
  p["unsheltered"] = Bytes().add(r.unsheltered).str();
  p["frame"] = Bytes()
                   .add(r.status)
                   .add(r.reason)
                   .add(r.labels)
                   .add(r.reasons)
                   .add(r.keep)
                   .add(r.num_features)
                   .add(r.num_static)
                   .add(r.num_dynamic)
                   .add(r.history_kept)
                   .add(r.guard)
                   .add(r.guard_restored)
                   .str();
  return p;
}

/// Every part of `after` equals `before` except those named in `own`.
inline void expect_only_changed(const Parts& before, const Parts& after, std::initializer_list<const char*> own) {
  ASSERT_EQ(before.size(), after.size());
  for (const auto& kv : before) {
    bool mine = false;
    for (const char* o : own) mine = mine || kv.first == o;
    if (mine) continue;
    EXPECT_TRUE(after.at(kv.first) == kv.second) << "the stage wrote " << kv.first;
  }
}

}  // namespace test
}  // namespace dyncull
