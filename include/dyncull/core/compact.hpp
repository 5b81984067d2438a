/// @file compact.hpp
/// Removes the culled features from a host's parallel per-keypoint arrays with a keep mask, in place and
/// stably: std::vectors of anything and rows of descriptor bytes. Sizes are checked before anything moves,
/// so a forgotten array fails loudly instead of drifting out of step. C++11, standard library only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <utility>
#include <vector>

namespace dyncull {

/// Mutable rows of bytes: row i at data + i * stride(), row_bytes of it used. A descriptor matrix is
/// RowsView(m.ptr(0), m.cols * m.elemSize(), m.step, m.rows) (opencv/culler.hpp does this for a cv::Mat).
/// compact() moves the kept rows up and sets `rows` to their count; the host then shrinks its matrix.
struct RowsView {
  std::uint8_t* data;
  std::size_t row_bytes;
  std::size_t stride_bytes;  ///< 0 means row_bytes
  std::size_t rows;

  RowsView() : data(nullptr), row_bytes(0), stride_bytes(0), rows(0) {}
  RowsView(std::uint8_t* data_, std::size_t row_bytes_, std::size_t stride_bytes_, std::size_t rows_)
      : data(data_), row_bytes(row_bytes_), stride_bytes(stride_bytes_), rows(rows_) {}
  std::size_t stride() const { return stride_bytes ? stride_bytes : row_bytes; }
};

namespace detail {

inline std::size_t compact_size(const RowsView& r) { return r.rows; }
template <class V, class A>
std::size_t compact_size(const std::vector<V, A>& v) {
  return v.size();
}

/// The memory an argument owns, as addresses [begin, end): a vector by its object and, separately, its
/// elements; a RowsView by the bytes its rows span (its object is a copy, second span empty). Two
/// arguments alias when any of their spans overlap: the same vector twice, a view over a vector's own
/// elements, a vector that is an element of another, or an array that is the keep mask itself.
struct ByteSpan {
  std::uintptr_t begin, end;
};
struct ArgumentSpans {
  ByteSpan object, elements;
};
inline ByteSpan span_of(const void* p, std::size_t bytes) {
  if (p == nullptr || bytes == 0) return ByteSpan{0, 0};
  const std::uintptr_t b = reinterpret_cast<std::uintptr_t>(p);
  return ByteSpan{b, b + bytes};
}
template <class V, class A>
ArgumentSpans byte_spans(const std::vector<V, A>& v) {
  return ArgumentSpans{span_of(&v, sizeof(v)), span_of(v.data(), v.size() * sizeof(V))};
}
template <class A>
ArgumentSpans byte_spans(const std::vector<bool, A>& v) {  // packed bits: no element address to take
  return ArgumentSpans{span_of(&v, sizeof(v)), ByteSpan{0, 0}};
}
inline ArgumentSpans byte_spans(const RowsView& r) {
  if (r.data == nullptr || r.rows == 0 || r.row_bytes == 0) return ArgumentSpans{ByteSpan{0, 0}, ByteSpan{0, 0}};
  // Bounded by rows_usable, which compact checks first.
  return ArgumentSpans{span_of(r.data, (r.rows - 1) * r.stride() + r.row_bytes), ByteSpan{0, 0}};
}

/// Rows compaction can move: reachable (non-null data), not overlapping each other, and the whole span
/// inside the address space. Vectors always are.
template <class V, class A>
bool rows_usable(const std::vector<V, A>&) {
  return true;
}
inline bool rows_usable(const RowsView& r) {
  if (r.rows == 0 || r.row_bytes == 0) return true;  // nothing moves
  if (r.data == nullptr || r.row_bytes > r.stride()) return false;
  const std::uintptr_t room = UINTPTR_MAX - reinterpret_cast<std::uintptr_t>(r.data);
  return r.row_bytes <= room && (r.rows - 1) <= (room - r.row_bytes) / r.stride();
}

inline bool overlap(const ByteSpan& x, const ByteSpan& y) {
  return x.begin < x.end && y.begin < y.end && x.begin < y.end && y.begin < x.end;
}
inline bool overlap(const ArgumentSpans& x, const ArgumentSpans& y) {
  return overlap(x.object, y.object) || overlap(x.object, y.elements) || overlap(x.elements, y.object) ||
         overlap(x.elements, y.elements);
}
/// True when no two of the arguments (the keep mask first) share memory.
inline bool arguments_disjoint(const ArgumentSpans* spans, std::size_t count) {
  for (std::size_t a = 0; a < count; ++a)
    for (std::size_t b = a + 1; b < count; ++b)
      if (overlap(spans[a], spans[b])) return false;
  return true;
}

inline void compact_one(const std::vector<std::uint8_t>& keep, RowsView& r, std::size_t count) {
  const std::size_t stride = r.stride();
  std::size_t j = 0;
  for (std::size_t i = 0; i < keep.size(); ++i) {
    if (!keep[i]) continue;
    if (i != j && r.row_bytes > 0) std::memmove(r.data + j * stride, r.data + i * stride, r.row_bytes);
    ++j;
  }
  r.rows = count;
}
template <class V, class A>
void compact_one(const std::vector<std::uint8_t>& keep, std::vector<V, A>& v, std::size_t count) {
  std::size_t j = 0;
  for (std::size_t i = 0; i < keep.size(); ++i) {
    if (!keep[i]) continue;
    if (i != j) v[j] = std::move(v[i]);
    ++j;
  }
  v.erase(v.begin() + static_cast<std::ptrdiff_t>(count), v.end());
}

}  // namespace detail

/// Keeps element i of every array (std::vector of anything, or RowsView) where keep[i] != 0, in order, and
/// returns their count. Returns -1 and touches nothing when an array has another size than keep, a
/// RowsView with rows has null data, row_bytes above its stride or a span past the address space, or two
/// arguments share memory: the same vector twice, overlapping rows, a RowsView over a vector's own
/// elements, or an array that is `keep` itself (or views its bytes). RowsView arguments may be temporaries.
template <class... Arrays>
long compact(const std::vector<std::uint8_t>& keep, Arrays&&... arrays) {
  const std::size_t n = keep.size();
  const std::size_t sizes[] = {n, detail::compact_size(arrays)...};
  const bool usable[] = {true, detail::rows_usable(arrays)...};
  for (std::size_t a = 1; a <= sizeof...(Arrays); ++a)
    if (sizes[a] != n || !usable[a]) return -1;
  // Spans after the usability check: a RowsView's span is computed only when it fits the address space.
  const detail::ArgumentSpans spans[] = {detail::byte_spans(keep), detail::byte_spans(arrays)...};
  if (!detail::arguments_disjoint(spans, 1 + sizeof...(Arrays))) return -1;
  std::size_t count = 0;
  for (std::size_t i = 0; i < n; ++i) count += keep[i] != 0;
  const int expand[] = {0, (detail::compact_one(keep, arrays, count), 0)...};
  (void)expand;
  return static_cast<long>(count);
}

}  // namespace dyncull
