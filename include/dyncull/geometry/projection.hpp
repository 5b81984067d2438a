/// @file projection.hpp
/// Batch pinhole projection and back-projection, depth image to point cloud with dynamic pixels masked
/// out (Zhu et al. 2024, eq. 5-6, with fy for y: the paper's eq. 6 divides y by fx, a typo), voxel downsampling.
#pragma once

#include "dyncull/core/camera.hpp"
#include "dyncull/core/depth.hpp"
#include "dyncull/core/mask.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/core/traits.hpp"
#include "dyncull/core/types.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace dyncull {

/// Projects world points through cam_from_world into pixels[0, n). Points with camera depth z <= 0,
/// non-finite coordinates or a pixel that is not finite (z -> 0+ or far off-axis: x / z overflows) get
/// NaN pixels and valid[i] = 0 (valid and depth_m may be null).
/// Returns the number of valid projections. pixels must hold world.size() elements.
template <class T, class Points3>
std::size_t project_points(const PinholeCamera<T>& camera, const Rigid3<T>& cam_from_world, const Points3& world,
                           Vec2<T>* pixels, std::uint8_t* valid = nullptr, T* depth_m = nullptr) {
  static_assert(is_point_container_v<Points3> && PointTraits<container_point_t<Points3>>::dim == 3,
                "project_points: world must be a container of 3-D points");
  const std::size_t n = static_cast<std::size_t>(world.size());
  const Mat3<T> R = cam_from_world.R;
  const Vec3<T> t = cam_from_world.t;
  const T fx = camera.fx, fy = camera.fy, cx = camera.cx, cy = camera.cy;
  const T nan = std::numeric_limits<T>::quiet_NaN();
  std::size_t count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3<T> p = R * to_vec3<T>(world[i]) + t;
    const T iz = T(1) / p(2);
    const Vec2<T> q(fx * p(0) * iz + cx, fy * p(1) * iz + cy);
    // The pixel's own finiteness also covers a non-finite p: NaN / Inf propagate into q.
    const bool ok = p(2) > T(0) && std::isfinite(p(2)) && std::isfinite(q(0)) && std::isfinite(q(1));
    pixels[i] = ok ? q : Vec2<T>(nan, nan);
    if (valid) valid[i] = static_cast<std::uint8_t>(ok);
    if (depth_m) depth_m[i] = p(2);
    count += ok;
  }
  return count;
}

/// Back-projects pixels at depths (metres along the optical axis) into camera-frame points (eq. 6:
/// x = (u - cx) z / fx, y = (v - cy) z / fy). Depth <= 0, non-finite input or a point that overflows
/// (degenerate intrinsics) gives a NaN point.
/// Returns the number of finite points. out must hold pixels.size() elements.
template <class T, class Points2>
std::size_t backproject_points(const PinholeCamera<T>& camera, const Points2& pixels, const T* depths_m,
                               Vec3<T>* out) {
  static_assert(is_point_container_v<Points2>, "backproject_points: pixels must be a container of 2-D points");
  const std::size_t n = static_cast<std::size_t>(pixels.size());
  const T ifx = T(1) / camera.fx, ify = T(1) / camera.fy;
  const T nan = std::numeric_limits<T>::quiet_NaN();
  std::size_t count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const T z = depths_m[i];
    const T u = point_x<T>(pixels[i]), v = point_y<T>(pixels[i]);
    const Vec3<T> p((u - camera.cx) * z * ifx, (v - camera.cy) * z * ify, z);
    const bool ok = z > T(0) && p.allFinite();  // NaN / Inf in u, v or z propagate into p
    out[i] = ok ? p : Vec3<T>(nan, nan, nan);
    count += ok;
  }
  return count;
}

/// A point cloud from a depth image, in the camera frame.
template <class T>
struct DepthCloud {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }
  std::vector<Vec3<T>> points;
  std::vector<std::uint32_t> pixel_index;  ///< v * width + u of each point (to look up colour or labels)
  std::size_t num_excluded = 0;            ///< sampled pixels dropped by the exclude mask
  std::size_t num_missing = 0;             ///< sampled pixels without a depth measurement
};

namespace detail {

/// False, with the reason, when depth_to_points cannot run on these inputs (see its contract).
template <class T, class Raw>
bool depth_to_points_inputs_ok(const DepthView<Raw>& depth, const PinholeCamera<T>& camera, ConstMaskView exclude,
                               int stride, std::string* why) {
  auto fail = [&](std::string reason) {
    *why = std::move(reason);
    return false;
  };
  if (depth.empty()) return fail("empty depth image");
  if (depth.validate(why) != Status::Ok) return false;
  if (stride < 1) return fail("stride must be >= 1");
  if (!camera.valid() || !std::isfinite(camera.fx) || !std::isfinite(camera.fy))
    return fail("invalid camera intrinsics (fx, fy must be positive and finite, cx, cy finite)");
  if (camera.width != depth.width || camera.height != depth.height)
    return fail("camera is " + std::to_string(camera.width) + "x" + std::to_string(camera.height) +
                " but the depth image is " + std::to_string(depth.width) + "x" + std::to_string(depth.height));
  if (!exclude.empty() && (exclude.width != depth.width || exclude.height != depth.height))
    return fail("exclude mask size differs from the depth image");
  if (static_cast<std::uint64_t>(depth.width) * static_cast<std::uint64_t>(depth.height) > (std::uint64_t{1} << 32))
    return fail("the image has more than 2^32 pixels, beyond the 32-bit pixel_index");
  return true;
}

/// x / z of every sampled column into x_over_z, and the largest |x / z|, |y / z| over the sampled grid
/// (at least 1); false, with the reason, when a ray overflows T.
template <class T>
bool sampled_rays(const PinholeCamera<T>& camera, int stride, std::size_t rows, std::vector<T>* x_over_z,
                  T* max_ray_out, std::string* why) {
  T max_ray = T(0);
  for (std::size_t c = 0; c < x_over_z->size(); ++c) {
    (*x_over_z)[c] = (T(c * static_cast<std::size_t>(stride)) - camera.cx) / camera.fx;
    max_ray = std::max(max_ray, std::abs((*x_over_z)[c]));
  }
  // The rows' rays are largest at the first and last sampled row.
  const T y_first = (T(0) - camera.cy) / camera.fy;
  const T y_last = (T((rows - 1) * static_cast<std::size_t>(stride)) - camera.cy) / camera.fy;
  if (!std::isfinite(max_ray)) {
    *why = "camera fx so small that (u - cx) / fx overflows";
    return false;
  }
  if (!std::isfinite(y_first) || !std::isfinite(y_last)) {
    *why = "camera fy so small that (v - cy) / fy overflows";
    return false;
  }
  *max_ray_out = std::max({max_ray, std::abs(y_first), std::abs(y_last), T(1)});
  return true;
}

/// The largest depth accepted: depth.max_m, capped so that no point's ray * z overflows T (the cap
/// joins the range test, at no per-pixel cost).
template <class T, class Raw>
float capped_max_depth(const DepthView<Raw>& depth, T max_ray) {
  const double z_cap = static_cast<double>(std::numeric_limits<T>::max()) / static_cast<double>(max_ray);
  return static_cast<double>(depth.max_m) < z_cap ? depth.max_m : static_cast<float>(std::min(
      z_cap * (1.0 - 1e-6), static_cast<double>(std::numeric_limits<float>::max())));
}

}  // namespace detail

/// Depth image -> camera-frame points for every stride-th pixel in u and v that has a measurement
/// (DepthView::depth_m() > 0) and is not set in `exclude` (dynamic pixels; empty = keep all).
/// Depths pass through DepthView::to_metres(), which is float: double clouds carry float-precision
/// depth (1e-7 relative, far below any sensor's noise). Reuses out's buffers. InvalidInput for an empty
/// or invalid depth view (DepthView::validate), stride < 1, an invalid camera or one whose rays (u - cx) / fx
/// overflow T, an exclude mask / camera whose size differs from the depth image, or an image of more than
/// 2^32 pixels (pixel_index is 32-bit). A depth whose point would overflow T counts as missing: every
/// returned point is finite.
template <class T, class Raw>
Status depth_to_points(const DepthView<Raw>& depth, const PinholeCamera<T>& camera, ConstMaskView exclude,
                       int stride, DepthCloud<T>* out) {
  out->num_excluded = 0;
  out->num_missing = 0;
  out->status = Status::Ok;
  out->reason.clear();
  auto fail = [&](const std::string& why) {
    out->points.clear();
    out->pixel_index.clear();
    out->status = Status::InvalidInput;
    out->reason = "depth_to_points: " + why;
    return out->status;
  };
  std::string why;
  if (!detail::depth_to_points_inputs_ok(depth, camera, exclude, stride, &why)) return fail(why);
  const int w = depth.width, h = depth.height;
  const std::size_t cols = static_cast<std::size_t>((w + stride - 1) / stride);
  const std::size_t rows = static_cast<std::size_t>((h + stride - 1) / stride);
  // Sized for every sampled pixel, written branch-free at slot k (a rejected pixel is overwritten by
  // the next one), trimmed at the end: no per-pixel capacity checks, no reallocation once warm.
  out->points.resize(cols * rows);
  out->pixel_index.resize(cols * rows);
  Vec3<T>* P = out->points.data();
  std::uint32_t* I = out->pixel_index.data();
  std::vector<T> x_over_z(cols);
  T max_ray = T(0);
  if (!detail::sampled_rays(camera, stride, rows, &x_over_z, &max_ray, &why)) return fail(why);
  // Multiply by the inverse scale: equal to DepthView::to_metres() up to one ulp. NaN fails every
  // comparison and +inf fails d <= max_m, so the range test also rejects non-finite raw values.
  const float inv_units = 1.f / depth.units_per_metre;
  const float min_m = depth.min_m;
  const float max_m = detail::capped_max_depth(depth, max_ray);
  const bool use_mask = !exclude.empty();
  std::size_t k = 0, excluded = 0, missing = 0;
  for (int v = 0; v < h; v += stride) {
    const Raw* drow = depth.row(v);
    const std::uint8_t* mrow = use_mask ? exclude.row(v) : nullptr;
    const T y_over_z = (T(v) - camera.cy) / camera.fy;  // eq. 6 with fy (the paper's fx is a typo)
    const std::uint32_t base = static_cast<std::uint32_t>(v) * static_cast<std::uint32_t>(w);
    std::size_t c = 0;
    for (int u = 0; u < w; u += stride, ++c) {
      // Bitwise & and | on 0/1 values: no short-circuit branches to mispredict on holes and mask edges.
      const unsigned masked = mrow != nullptr ? static_cast<unsigned>(mrow[u] != 0) : 0u;
      const float d = static_cast<float>(drow[u]) * inv_units;
      const unsigned measured = static_cast<unsigned>(d > 0.f) & static_cast<unsigned>(d >= min_m) &
                                static_cast<unsigned>(d <= max_m);
      const T z = static_cast<T>(d);
      P[k] = Vec3<T>(x_over_z[c] * z, y_over_z * z, z);
      I[k] = base + static_cast<std::uint32_t>(u);
      k += measured & (masked ^ 1u);
      excluded += masked;
      missing += (masked ^ 1u) & (measured ^ 1u);
    }
  }
  out->points.resize(k);
  out->pixel_index.resize(k);
  out->num_excluded = excluded;
  out->num_missing = missing;
  return Status::Ok;
}

/// Contract #5 form: returns the cloud by value.
template <class T, class Raw>
DepthCloud<T> depth_to_points(const DepthView<Raw>& depth, const PinholeCamera<T>& camera,
                              ConstMaskView exclude = {}, int stride = 1) {
  DepthCloud<T> cloud;
  depth_to_points(depth, camera, exclude, stride, &cloud);
  return cloud;
}

/// Voxel-grid downsampling: one point per occupied cubic voxel of side voxel_size_m, the centroid
/// of its points (as Open3D's VoxelDownSample), ordered by voxel. Keeps its sort buffer between calls
/// so repeated use does not allocate once warm.
template <class T>
class VoxelDownsampler {
 public:
  /// Non-finite input points are skipped. InvalidInput when voxel_size_m <= 0 or the cloud spans
  /// more than 2^21 voxels along an axis (voxel too small for the extent).
  template <class Points>
  Status run(const Points& in, T voxel_size_m, std::vector<Vec3<T>>* out, std::string* reason = nullptr) {
    static_assert(is_point_container_v<Points> && PointTraits<container_point_t<Points>>::dim == 3,
                  "voxel_downsample: input must be a container of 3-D points");
    out->clear();
    auto fail = [&](const char* why) {
      if (reason) *reason = why;
      return Status::InvalidInput;
    };
    if (!(voxel_size_m > T(0)) || !std::isfinite(voxel_size_m)) return fail("voxel_size_m must be finite and > 0");
    const std::size_t n = static_cast<std::size_t>(in.size());
    Vec3<T> lo = Vec3<T>::Constant(std::numeric_limits<T>::max());
    Vec3<T> hi = Vec3<T>::Constant(std::numeric_limits<T>::lowest());
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3<T> p = to_vec3<T>(in[i]);
      if (!p.allFinite()) continue;
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    if (!(hi(0) >= lo(0))) return Status::Ok;  // no finite point: empty output
    const T inv = T(1) / voxel_size_m;
    constexpr double kMaxCells = double(1u << 21);
    if (static_cast<double>((hi - lo).maxCoeff()) * static_cast<double>(inv) >= kMaxCells - 1)
      return fail("voxel_size_m too small for the cloud's extent (more than 2^21 voxels per axis)");
    keys_.clear();
    keys_.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3<T> p = to_vec3<T>(in[i]);
      if (!p.allFinite()) continue;
      const Vec3<T> c = ((p - lo) * inv).array().floor();
      const std::uint64_t key = (static_cast<std::uint64_t>(c(0)) << 42) | (static_cast<std::uint64_t>(c(1)) << 21) |
                                static_cast<std::uint64_t>(c(2));
      keys_.emplace_back(key, static_cast<std::uint32_t>(i));
    }
    std::sort(keys_.begin(), keys_.end());
    for (std::size_t a = 0; a < keys_.size();) {
      std::size_t b = a;
      Vec3<double> sum = Vec3<double>::Zero();  // double sums: float centroids of dense voxels stay exact
      while (b < keys_.size() && keys_[b].first == keys_[a].first) {
        sum += to_vec3<T>(in[keys_[b].second]).template cast<double>();
        ++b;
      }
      Vec3<double> mean = sum / static_cast<double>(b - a);
      if (!mean.allFinite()) {  // the sum of coordinates near the double limit overflowed: sum offsets
        const Vec3<double> base = to_vec3<T>(in[keys_[a].second]).template cast<double>();
        Vec3<double> off = Vec3<double>::Zero();
        for (std::size_t k = a; k < b; ++k) off += to_vec3<T>(in[keys_[k].second]).template cast<double>() - base;
        mean = base + off / static_cast<double>(b - a);
      }
      out->push_back(mean.template cast<T>());
      a = b;
    }
    return Status::Ok;
  }

 private:
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keys_;
};

/// One-shot voxel downsampling (see VoxelDownsampler).
template <class T, class Points>
Status voxel_downsample(const Points& in, T voxel_size_m, std::vector<Vec3<T>>* out, std::string* reason = nullptr) {
  VoxelDownsampler<T> d;
  return d.run(in, voxel_size_m, out, reason);
}

}  // namespace dyncull
