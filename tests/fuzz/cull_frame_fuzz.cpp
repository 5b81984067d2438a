// libFuzzer target: cull_frame (culling/pipeline.hpp) on frames decoded from the input, for float
// and double: keypoints with NaN / Inf / huge values, tracks of matching or mismatched length, random
// boxes and classes, random depth (uint16 sensor units with float, metres with double; random
// units_per_metre), a pose, a preset with random option values (through
// PipelineOptions::validate()), several frames on one state. Checks the contract: an Ok result labels
// every keypoint Static or Dynamic with keep = (Static) and consistent counts; a non-Ok one has a reason.
#include "dyncull/culling/pipeline.hpp"
#include "dyncull/culling/presets.hpp"

#include "fuzz_input.hpp"

#include <algorithm>
#include <cstdint>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace {

using namespace dyncull;

template <class O, class = void>
struct has_validate : std::false_type {};
template <class O>
struct has_validate<O, std::void_t<decltype(std::declval<const O&>().validate(static_cast<std::string*>(nullptr)))>>
    : std::true_type {};

// track_valid is a raw pointer (one flag per keypoint) or a sized view, depending on the pipeline version.
template <class View>
void set_flags(View& dst, const std::vector<std::uint8_t>& flags) {
  if constexpr (std::is_pointer<View>::value) {
    dst = flags.data();
  } else {
    dst = View(flags);
  }
}

// Metres as the view's raw type: uint16 TUM units (x 5000, clamped, NaN -> 0 = no measurement) or float as is.
template <class Raw>
Raw raw_depth(double m) {
  if constexpr (std::is_floating_point<Raw>::value) {
    return static_cast<Raw>(m);
  } else {
    const double units = m * 5000.0;
    return static_cast<Raw>(units >= 0 && units <= 65535 ? units : (units > 65535 ? 65535 : 0));
  }
}

template <class T>
PipelineOptions<T> preset(int k) {
  switch (k) {
    case 0: return presets::none<T>();
    case 1: return presets::dld_slam<T>();
    case 2: return presets::rtd_slam<T>();
    case 3: return presets::zhu_2024<T>();
    case 4: return presets::dfd_slam<T>();
    case 5: return presets::zhang_2023<T>();
    default: return presets::recommended<T>();
  }
}

// Random values for a few options of every stage; validate() decides whether they are usable.
template <class T>
void perturb(fuzz::Input& in, PipelineOptions<T>* o) {
  const int count = in.range(0, 6);
  for (int c = 0; c < count; ++c) {
    switch (in.range(0, 35)) {
      case 0: o->tracker.enabled = in.flag(); break;
      case 1: o->depth_mask.enabled = in.flag(); break;
      case 2: o->probability.enabled = in.flag(); break;
      case 3: o->reprojection.enabled = in.flag(); break;
      case 4: o->subbox.enabled = in.flag(); break;
      case 5: o->multiview.enabled = in.flag(); break;
      case 6: o->coherent_motion.enabled = in.flag(); break;
      case 7: o->candidates = static_cast<CandidatePolicy>(in.range(0, 3)); break;
      case 8: o->detections.box_padding_px = in.scalar<T>(-200, 200); break;
      case 9: o->detections.min_confidence = in.scalar<T>(-1, 2); break;
      case 10: o->guard.min_fraction = in.value(-1, 2); break;
      case 11: o->guard.min_survivors = in.u32(); break;
      case 12: o->multiview.max_reference_keyframes = in.flag() ? in.u8() : static_cast<std::size_t>(in.u64()); break;
      case 13: o->edge_evidence.radius_px = static_cast<int>(in.u32()); break;
      case 14: o->coherent_motion.min_median_px = in.scalar<T>(-1, 10); break;
      case 15: o->edge_evidence.enabled = in.flag(); break;
      case 16: o->subbox.min_evidence_frames = in.range(-5, 100); break;
      case 17: o->moving_consistency.max_ransac_iterations = in.range(0, 200); break;
      case 18: o->reprojection.max_ransac_iterations = in.range(0, 200); break;
      case 19: o->depth_mask.eps_m = in.value(-1, 5); break;
      case 20: o->depth_mask.min_valid_fraction = in.value(-1, 2); break;
      case 21: o->depth_mask.max_object_depth_extent_m = in.value(-1, 1e13); break;
      case 22: o->subbox.grid = in.range(-2, 12); break;
      case 23: o->subbox.dilation_radius_px = static_cast<int>(in.u32()); break;
      case 24: o->subbox.sigma1 = in.scalar<T>(-1, 2); break;
      case 25: o->multiview.search_radius_px = static_cast<int>(in.u32()); break;
      case 26: o->multiview.depth_threshold_m = in.scalar<T>(-1, 2); break;
      case 27: o->moving_consistency.max_epipolar_distance_px = in.scalar<T>(-1, 10); break;
      case 28: o->moving_consistency.refit_iterations = static_cast<int>(in.u32()); break;
      case 29: o->reprojection.max_residual_px = in.scalar<T>(-1, 10); break;
      case 30: o->tracker.max_missed_frames = in.range(-5, 100); break;
      case 31: o->static_history.min_frames = in.range(-5, 20); break;
      case 32: o->depth_mask.assign_overlaps_by_depth = in.flag(); break;
      case 33: o->depth_mask.head_band_fraction = in.value(-1, 2); break;
      case 34: o->depth_mask.head_band_depth_tolerance_m = in.value(-1, 5); break;
      default: o->depth_mask.low_override_by_depth = in.flag(); break;
    }
  }
}

template <class T, class Raw>
void run(fuzz::Input& in) {
  PipelineOptions<T> options = preset<T>(in.range(0, 6));
  // RANSAC on random tracks runs to its iteration cap (10000 by default, 90 % of the time here): a
  // lower cap gives several times more inputs per second; the sampling loop is not what this checks.
  for (std::size_t* cap : {&options.moving_consistency.max_ransac_iterations, &options.reprojection.max_ransac_iterations})
    *cap = std::min<std::size_t>(*cap, 200);
  bool options_valid = true;
  if constexpr (has_validate<PipelineOptions<T>>::value) {
    perturb(in, &options);
    options_valid = options.validate() == Status::Ok;
  }
  PipelineState<T> state(static_cast<std::size_t>(in.range(0, 4)));
  const int frames = in.range(1, 3);
  std::vector<Vec2<T>> kp, prev;
  std::vector<Vec3<T>> points;
  std::vector<std::int64_t> ids;
  std::vector<std::uint8_t> valid;
  std::vector<Detection<T>> dets;
  std::vector<Raw> depth;
  for (int f = 0; f < frames && !in.empty(); ++f) {
    const int W = in.range(1, 96), H = in.range(1, 96);
    PinholeCamera<T> cam;
    cam.width = W;
    cam.height = H;
    if (in.flag()) {
      cam.fx = in.scalar<T>(1, 2000);
      cam.fy = in.scalar<T>(1, 2000);
      cam.cx = in.scalar<T>(0, W);
      cam.cy = in.scalar<T>(0, H);
    } else {
      cam.fx = cam.fy = T(50);
      cam.cx = T(W) / 2;
      cam.cy = T(H) / 2;
    }
    const std::size_t n = static_cast<std::size_t>(in.range(0, 200));
    kp.resize(n);
    for (auto& p : kp) p = Vec2<T>(in.scalar<T>(-5, W + 5), in.scalar<T>(-5, H + 5));
    const int tracks = in.range(0, 3);  // 0 none, 1 parallel, 2 one short, 3 one long
    prev.resize(tracks == 0 ? 0 : (tracks == 2 && n > 0 ? n - 1 : (tracks == 3 ? n + 1 : n)));
    for (std::size_t i = 0; i < prev.size(); ++i) {
      const bool moved = in.flag();
      prev[i] = i < n && !moved ? kp[i] : Vec2<T>(in.scalar<T>(-5, W + 5), in.scalar<T>(-5, H + 5));
    }
    CullingFrame<T, std::vector<Vec2<T>>, std::vector<Vec2<T>>, Raw> frame;
    frame.keypoints = &kp;
    frame.prev_keypoints = tracks ? &prev : nullptr;
    if (in.flag()) {
      // A sized view can be given the wrong length (then InvalidInput); a raw pointer cannot.
      const bool sized = !std::is_pointer<decltype(frame.track_valid)>::value;
      valid.resize(sized && in.u8() == 0 ? n + 1 : n);
      for (auto& v : valid) v = in.u8() & 1;
      set_flags(frame.track_valid, valid);
    }
    if (in.flag()) {
      ids.resize(n);
      for (auto& id : ids) id = static_cast<std::int64_t>(in.range(-2, 50));
      frame.track_ids = &ids;
    }
    if (in.flag()) {
      points.resize(n);
      for (auto& p : points) p = Vec3<T>(in.scalar<T>(-5, 5), in.scalar<T>(-5, 5), in.scalar<T>(-1, 10));
      frame.points_3d = &points;
    }
    dets.resize(static_cast<std::size_t>(in.range(0, 6)));
    for (auto& d : dets) {
      const T x0 = in.scalar<T>(-10, W + 10), y0 = in.scalar<T>(-10, H + 10);
      d.box = Box<T>{x0, y0, x0 + in.scalar<T>(-5, W), y0 + in.scalar<T>(-5, H)};
      d.class_id = in.range(-3, 90);
      d.confidence = in.scalar<T>(0, 1);
    }
    frame.detections = in.flag() ? &dets : nullptr;
    if (in.flag()) {
      depth.resize(static_cast<std::size_t>(W) * static_cast<std::size_t>(H));
      const int mode = in.range(0, 2);  // constant, two layers, per-pixel random
      const Raw base = raw_depth<Raw>(in.value(0, 8));
      const Raw near = raw_depth<Raw>(in.value(0, 8));
      for (std::size_t i = 0; i < depth.size(); ++i)
        depth[i] = mode == 0 ? base : mode == 1 ? ((i % static_cast<std::size_t>(W)) < static_cast<std::size_t>(W / 2) ? near : base)
                                                 : raw_depth<Raw>(in.value(0, 8));
      frame.depth.data = depth.data();
      if (!std::is_floating_point<Raw>::value) frame.depth.units_per_metre = 5000.f;  // TUM
      if (in.u8() == 0) frame.depth.units_per_metre = static_cast<float>(in.value(-1, 10000));
      frame.depth.width = W;
      frame.depth.height = H;
      if (in.flag()) frame.depth.min_m = static_cast<float>(in.value(0, 1));
      if (in.flag()) frame.depth.max_m = static_cast<float>(in.value(0, 1e30));
    }
    Rigid3<T> pose;
    if (in.flag()) {
      Eigen::Quaternion<T> q(in.scalar<T>(-1, 1), in.scalar<T>(-1, 1), in.scalar<T>(-1, 1), in.scalar<T>(-1, 1));
      if (q.coeffs().allFinite() && q.norm() > T(1e-3)) pose.R = q.normalized().toRotationMatrix();
      pose.t = Vec3<T>(in.scalar<T>(-1, 1), in.scalar<T>(-1, 1), in.scalar<T>(-1, 1));
      frame.cam_from_world = &pose;
    }
    frame.is_keyframe = in.flag();
    frame.evidence_frames = in.range(0, 3);

    if (!options_valid) {
      // cull_frame validates its options itself: it must refuse them, never run on them.
      const PipelineResult<T>& r = cull_frame(frame, options, &state);
      DYNCULL_FUZZ_CHECK(r.status == Status::InvalidInput && !r.reason.empty());
      return;
    }
    const PipelineResult<T>& r = cull_frame(frame, options, &state);
    if (!r.labelled()) {  // MissingInput still labels every feature: checked below
      DYNCULL_FUZZ_CHECK(!r.reason.empty());
      continue;
    }
    DYNCULL_FUZZ_CHECK(r.num_features == n);
    DYNCULL_FUZZ_CHECK(r.labels.size() == n && r.reasons.size() == n && r.keep.size() == n);
    std::size_t num_static = 0;
    for (std::size_t i = 0; i < n; ++i) {
      DYNCULL_FUZZ_CHECK(r.labels[i] == FeatureLabel::Static || r.labels[i] == FeatureLabel::Dynamic);
      DYNCULL_FUZZ_CHECK(r.keep[i] == (r.labels[i] == FeatureLabel::Static ? 1 : 0));
      num_static += r.keep[i];
    }
    DYNCULL_FUZZ_CHECK(r.num_static == num_static && r.num_dynamic == n - num_static);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::Input in(data, size);
  if (in.flag()) {
    run<float, std::uint16_t>(in);  // raw sensor units
  } else {
    run<double, float>(in);         // metres
  }
  return 0;
}
