/// @file views.hpp
/// Read-only views of a host's per-keypoint arrays: pixel positions (pointer, count, stride) and rows of
/// binary descriptors. Build plumbing of the culler's plain-view interface (culling/culler.hpp), no paper
/// equation. C++11, standard library only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

namespace dyncull {

/// Read-only (u, v) pixel positions: point i's x at data + i * stride_bytes, its y right after it, both
/// float or double. Built by points_view() from a contiguous container (cv::KeyPoint, cv::Point2f/d, Eigen
/// 2-vectors, any struct with float/double x, y) or by hand from a pointer and a count. `given` tells an
/// absent input from an empty one.
struct PointsView {
  const void* data;
  std::size_t count;
  std::size_t stride_bytes;  ///< 0 means two packed scalars
  bool is_double;
  bool given;

  PointsView() : data(nullptr), count(0), stride_bytes(0), is_double(false), given(false) {}
  PointsView(const void* data_, std::size_t count_, std::size_t stride_bytes_, bool is_double_, bool given_)
      : data(data_), count(count_), stride_bytes(stride_bytes_), is_double(is_double_), given(given_) {}

  static PointsView of(const float* xy, std::size_t n, std::size_t stride_bytes_ = 0) {
    return PointsView(xy, n, stride_bytes_, false, true);
  }
  static PointsView of(const double* xy, std::size_t n, std::size_t stride_bytes_ = 0) {
    return PointsView(xy, n, stride_bytes_, true, true);
  }
  std::size_t stride() const { return stride_bytes ? stride_bytes : (is_double ? 2 * sizeof(double) : 2 * sizeof(float)); }
  double x(std::size_t i) const { return read(i, 0); }
  double y(std::size_t i) const { return read(i, 1); }

 private:
  double read(std::size_t i, std::size_t k) const {
    const unsigned char* p = static_cast<const unsigned char*>(data) + i * stride();
    if (is_double) {
      double v;
      std::memcpy(&v, p + k * sizeof(double), sizeof v);
      return v;
    }
    float v;
    std::memcpy(&v, p + k * sizeof(float), sizeof v);
    return static_cast<double>(v);
  }
};

namespace detail {
// The address of a point's x and y: a `pt` member (cv::KeyPoint) first, then x / y data members
// (cv::Point2f, plain structs), then data() (Eigen 2-vectors). The int / long / ... argument ranks them.
template <class P> auto x_address(const P& p, int) -> decltype(&p.pt.x) { return &p.pt.x; }
template <class P>
auto x_address(const P& p, long) ->
    typename std::enable_if<std::is_member_object_pointer<decltype(&P::x)>::value, decltype(&p.x)>::type {
  return &p.x;
}
template <class P> auto x_address(const P& p, ...) -> decltype(p.data()) { return p.data(); }
template <class P> auto y_address(const P& p, int) -> decltype(&p.pt.y) { return &p.pt.y; }
template <class P>
auto y_address(const P& p, long) ->
    typename std::enable_if<std::is_member_object_pointer<decltype(&P::y)>::value, decltype(&p.y)>::type {
  return &p.y;
}
template <class P> auto y_address(const P& p, ...) -> decltype(p.data()) { return p.data() + 1; }
}  // namespace detail

/// PointsView over a contiguous container (std::vector, std::array) of points whose x and y are adjacent
/// float or double members (cv::KeyPoint's pt, cv::Point2f/d, Eigen 2-vectors). The container must outlive
/// the view and not be resized while the view is used.
template <class Container>
PointsView points_view(const Container& points) {
  typedef typename std::decay<decltype(*points.data())>::type P;
  typedef typename std::remove_cv<typename std::remove_pointer<decltype(detail::x_address(std::declval<const P&>(), 0))>::type>::type S;
  static_assert(std::is_same<S, float>::value || std::is_same<S, double>::value,
                "dyncull::points_view: point coordinates must be float or double");
  PointsView v;
  v.given = true;
  v.is_double = std::is_same<S, double>::value;
  v.count = static_cast<std::size_t>(points.size());
  v.stride_bytes = sizeof(P);
  if (v.count == 0) return v;
  const P& first = points.data()[0];
  const S* x = detail::x_address(first, 0);
  const S* y = detail::y_address(first, 0);
  v.data = x;
  // x and y must be adjacent (every type above lays them out so); anything else is read as no points.
  if (y != x + 1) v.data = nullptr, v.count = 0;
  return v;
}

/// Read-only rows of binary descriptors: row i starts at data + i * stride_bytes and has row_bytes bytes
/// (ORB: 32). A cv::Mat of descriptors is DescriptorRows(m.ptr(0), m.rows, m.step, m.cols). Anything with
/// the members data, rows, row_bytes and stride() (core/compact.hpp's RowsView) converts.
struct DescriptorRows {
  const std::uint8_t* data;
  std::size_t rows;
  std::size_t stride_bytes;  ///< 0 means row_bytes
  std::size_t row_bytes;

  DescriptorRows() : data(nullptr), rows(0), stride_bytes(0), row_bytes(32) {}
  DescriptorRows(const std::uint8_t* data_, std::size_t rows_, std::size_t stride_bytes_ = 0,
                 std::size_t row_bytes_ = 32)
      : data(data_), rows(rows_), stride_bytes(stride_bytes_), row_bytes(row_bytes_) {}
  template <class R, class = decltype(std::declval<const R&>().stride()),
            class = decltype(std::declval<const R&>().row_bytes), class = decltype(std::declval<const R&>().rows),
            class = decltype(std::declval<const R&>().data)>
  DescriptorRows(const R& view)  // NOLINT: implicit on purpose, RowsView reads as DescriptorRows
      : data(view.data), rows(view.rows), stride_bytes(view.stride()), row_bytes(view.row_bytes) {}

  std::size_t stride() const { return stride_bytes ? stride_bytes : row_bytes; }
  const std::uint8_t* row(std::size_t i) const { return data + i * stride(); }
};

}  // namespace dyncull
