/// @file mask.hpp
/// 8-bit image masks. dyncull's convention: non-zero = set (dynamic / culled), 0 = clear (static).
/// Note DynaSLAM's and TUM Mask R-CNN files use the opposite (0 = person); convert at the border.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace dyncull {

/// Non-owning mask view (mutable), rows `stride` bytes apart (0 means width).
struct MaskView {
  std::uint8_t* data = nullptr;
  int width = 0;
  int height = 0;
  std::ptrdiff_t stride = 0;

  bool empty() const { return data == nullptr || width <= 0 || height <= 0; }
  std::ptrdiff_t row_stride() const { return stride > 0 ? stride : width; }
  std::uint8_t* row(int v) const { return data + static_cast<std::ptrdiff_t>(v) * row_stride(); }
  std::uint8_t& at(int u, int v) const { return row(v)[u]; }
  bool in_bounds(int u, int v) const { return u >= 0 && v >= 0 && u < width && v < height; }
  /// True when (u, v) is inside and set; false outside the image.
  bool test(int u, int v) const { return in_bounds(u, v) && row(v)[u] != 0; }
};

/// Non-owning read-only mask view.
struct ConstMaskView {
  const std::uint8_t* data = nullptr;
  int width = 0;
  int height = 0;
  std::ptrdiff_t stride = 0;

  ConstMaskView() = default;
  ConstMaskView(const std::uint8_t* d, int w, int h, std::ptrdiff_t s = 0) : data(d), width(w), height(h), stride(s) {}
  ConstMaskView(const MaskView& m) : data(m.data), width(m.width), height(m.height), stride(m.stride) {}  // NOLINT

  bool empty() const { return data == nullptr || width <= 0 || height <= 0; }
  std::ptrdiff_t row_stride() const { return stride > 0 ? stride : width; }
  const std::uint8_t* row(int v) const { return data + static_cast<std::ptrdiff_t>(v) * row_stride(); }
  bool in_bounds(int u, int v) const { return u >= 0 && v >= 0 && u < width && v < height; }
  bool test(int u, int v) const { return in_bounds(u, v) && row(v)[u] != 0; }
};

/// Owning mask, contiguous rows.
struct Mask {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;

  Mask() = default;
  Mask(int w, int h, std::uint8_t value = 0)
      : width(w), height(h), pixels(static_cast<std::size_t>(w > 0 ? w : 0) * static_cast<std::size_t>(h > 0 ? h : 0), value) {}
  void reset(int w, int h, std::uint8_t value = 0) {
    width = w;
    height = h;
    pixels.assign(static_cast<std::size_t>(w > 0 ? w : 0) * static_cast<std::size_t>(h > 0 ? h : 0), value);
  }
  MaskView view() { return MaskView{pixels.data(), width, height, width}; }
  ConstMaskView view() const { return ConstMaskView{pixels.data(), width, height, width}; }
  bool test(int u, int v) const { return view().test(u, v); }
  std::size_t count() const {
    std::size_t n = 0;
    for (std::uint8_t p : pixels) n += (p != 0);
    return n;
  }
};

}  // namespace dyncull
