// A front end that tracks its features itself (KLT in a VIO or RGB-D front end, say) and keeps each
// track's 3-D point hands them to cull_frame, the expert entry, in its own types: no OpenCV, no library to
// link, Eigen and dyncull's headers only (a program is header-only throughout or links dyncull::pipeline,
// never both: docs/design.md). The synthetic walking scene stands in for the camera and the tracker.
#include <dyncull/culling/presets.hpp>
#include <dyncull/sim/scene.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

struct HostFeature {  // the host's keypoint: dyncull reads its x and y members in place
  float x, y;
};
struct HostPoint {  // the host's map point of a track (world frame), NaN where it has none
  float x, y, z;
};

// The host's tracks, parallel arrays: last frame's and this frame's positions, map points and ids.
struct Tracks {
  std::vector<HostFeature> prev, cur;
  std::vector<HostPoint> points;
  std::vector<std::int64_t> ids;
  std::vector<std::uint8_t> tracked;  // 0: born this frame, no previous position
};

// Stand-in for the host's tracker: each feature follows its surface point into frame i (the scene knows
// where a walker carried it) and is dropped when it leaves the view or is hidden; new features fill a grid.
void track(const dyncull::sim::Scene& scene, int i, const dyncull::sim::FrameData& frame, Tracks* t,
           std::int64_t* next_id) {
  const dyncull::PinholeCamera<double> camera = scene.camera();
  const dyncull::Rigid3<double> cam_from_world = scene.world_from_cam(i).inverse();
  Tracks next;
  for (std::size_t k = 0; k < t->cur.size(); ++k) {
    dyncull::Vec3<double> then, now, seen, unused;
    if (!scene.surface_point(i - 1, t->cur[k].x, t->cur[k].y, i, &then, &now)) continue;
    const dyncull::Vec3<double> p = cam_from_world.apply(now);
    const dyncull::Vec2<double> uv = camera.project(p);
    if (p.z() <= 0 || !scene.surface_point(i, uv.x(), uv.y(), i, &seen, &unused) || (seen - now).norm() > 0.01)
      continue;  // out of view or occluded
    next.prev.push_back(t->cur[k]);
    next.cur.push_back({float(uv.x()), float(uv.y())});
    next.points.push_back(t->points[k]);
    next.ids.push_back(t->ids[k]);
    next.tracked.push_back(1);
  }
  const int cell = 24, cols = (frame.width + cell - 1) / cell, rows = (frame.height + cell - 1) / cell;
  std::vector<std::uint8_t> occupied(std::size_t(cols) * rows, 0);
  for (const HostFeature& p : next.cur) occupied[std::size_t(int(p.y) / cell) * cols + int(p.x) / cell] = 1;
  const float nan = std::nanf("");
  for (int v = cell / 2; v + cell / 2 <= frame.height; v += cell)
    for (int u = cell / 2; u + cell / 2 <= frame.width; u += cell) {
      if (occupied[std::size_t(v / cell) * cols + u / cell]) continue;
      const float z = frame.depth_m[std::size_t(v) * frame.width + u];
      const dyncull::Vec3<double> X = scene.world_from_cam(i).apply(camera.backproject({double(u), double(v)}, z));
      next.prev.push_back({nan, nan});
      next.cur.push_back({float(u), float(v)});
      next.points.push_back(z > 0 ? HostPoint{float(X.x()), float(X.y()), float(X.z())} : HostPoint{nan, nan, nan});
      next.ids.push_back((*next_id)++);
      next.tracked.push_back(0);
    }
  *t = next;
}

int main() {
  dyncull::sim::SceneOptions scene_options;
  scene_options.num_frames = 30;
  const dyncull::sim::Scene scene(scene_options);
  dyncull::sim::FrameData frame;
  Tracks tracks;
  std::int64_t next_id = 0;
  std::size_t moving = 0, moving_culled = 0, still = 0, still_kept = 0;

  const dyncull::PipelineOptions<float> options = dyncull::presets::recommended<float>();
  dyncull::PipelineState<float> state;  // keeps the box tracker, track history and keyframes
  for (int i = 0; i < scene_options.num_frames; ++i) {
    scene.render(i, &frame);
    track(scene, i, frame, &tracks, &next_id);
    const dyncull::Rigid3<float> cam_from_world = scene.world_from_cam(i).inverse().cast<float>();  // your motion model

    dyncull::CullingFrame<float, std::vector<HostFeature>, std::vector<HostFeature>, float, std::vector<HostPoint>> f;
    f.keypoints = &tracks.cur;
    f.prev_keypoints = &tracks.prev;
    f.track_valid = tracks.tracked;
    f.track_ids = &tracks.ids;
    f.points_3d = &tracks.points;
    f.detections = &frame.detections;  // your detector's boxes (pixels, COCO class, score)
    f.depth = dyncull::DepthView<float>{frame.depth_m.data(), frame.width, frame.height};
    f.camera = scene.camera().cast<float>();
    f.cam_from_world = &cam_from_world;
    f.evidence_frames = 1;  // positions one frame apart
    const dyncull::PipelineResult<float>& r = dyncull::cull_frame(f, options, &state);

    // r.keep is the mask for every parallel array of the host; here it is scored against the scene's truth.
    for (std::size_t k = 0; k < r.keep.size(); ++k) {
      const int u = std::min(int(std::lround(tracks.cur[k].x)), frame.width - 1);
      const int v = std::min(int(std::lround(tracks.cur[k].y)), frame.height - 1);
      const bool truly_moving = frame.moving[std::size_t(v) * frame.width + u] != 0;
      moving += truly_moving;
      moving_culled += truly_moving && !r.keep[k];
      still += !truly_moving;
      still_kept += !truly_moving && r.keep[k];
    }
  }
  const dyncull::PipelineResult<float>& last = state.result;
  std::printf("header_only: %zu of %zu features on movers culled, %zu of %zu static ones kept; last status %s%s%s\n",
              moving_culled, moving, still_kept, still, dyncull::to_string(last.status),
              last.reason.empty() ? "" : ": ", last.reason.c_str());
  // Most movers' features go, nearly all static ones stay: otherwise something is wrong.
  return moving_culled * 2 > moving && still_kept * 10 > still * 9 ? 0 : 1;
}
