/// @file kdtree.hpp
/// Static 3-D k-d tree for exact nearest-neighbour queries (Friedman-Bentley-Finkel 1977; the
/// correspondence search of point-to-point ICP). Built once, allocation-free queries.
#pragma once

#include "dyncull/core/status.hpp"
#include "dyncull/core/traits.hpp"
#include "dyncull/core/types.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace dyncull {

/// Exact nearest-neighbour k-d tree over 3-D points of scalar T. Points are copied into leaf order
/// (structure of arrays), so the caller's container need not outlive the tree. Splits at the median
/// of the widest axis; leaves hold at most leaf_size points. Non-finite points are left out.
template <class T>
class KdTree3 {
 public:
  static constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

  KdTree3() = default;
  template <class Points>
  explicit KdTree3(const Points& points, int leaf_size = 12) {
    build(points, leaf_size);
  }

  /// (Re)builds from any container of 3-D points (PointTraits). Returns Ok, TooFewPoints when no
  /// finite point remains (queries then return kNone), or InvalidInput for leaf_size < 1 or a container
  /// of 2^32 - 1 points or more (indices are 32-bit; kNone is reserved).
  template <class Points>
  Status build(const Points& points, int leaf_size = 12) {
    static_assert(is_point_container_v<Points> && PointTraits<container_point_t<Points>>::dim == 3,
                  "KdTree3: points must be a container of 3-D points");
    xs_.clear();
    ys_.clear();
    zs_.clear();
    ids_.clear();
    nodes_.clear();
    if (leaf_size < 1) return Status::InvalidInput;
    leaf_size_ = static_cast<std::uint32_t>(leaf_size);
    const std::size_t n = static_cast<std::size_t>(points.size());
    if (n >= static_cast<std::size_t>(kNone)) return Status::InvalidInput;
    std::vector<std::uint32_t> order;
    std::vector<T> px, py, pz;
    order.reserve(n);
    px.reserve(n);
    py.reserve(n);
    pz.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
      const T x = point_x<T>(points[i]), y = point_y<T>(points[i]), z = point_z<T>(points[i]);
      if (!(std::isfinite(x) && std::isfinite(y) && std::isfinite(z))) continue;
      order.push_back(static_cast<std::uint32_t>(px.size()));
      ids_.push_back(static_cast<std::uint32_t>(i));
      px.push_back(x);
      py.push_back(y);
      pz.push_back(z);
    }
    if (order.empty()) return Status::TooFewPoints;
    nodes_.reserve(2 * (order.size() / leaf_size_ + 1));
    const T* coords[3] = {px.data(), py.data(), pz.data()};
    build_node(order.data(), 0, static_cast<std::uint32_t>(order.size()), coords);
    // Leaf order, structure of arrays: a leaf scan reads three short contiguous runs.
    const std::vector<std::uint32_t> original_ids = ids_;
    xs_.resize(order.size());
    ys_.resize(order.size());
    zs_.resize(order.size());
    for (std::size_t k = 0; k < order.size(); ++k) {
      xs_[k] = px[order[k]];
      ys_[k] = py[order[k]];
      zs_[k] = pz[order[k]];
      ids_[k] = original_ids[order[k]];
    }
    return Status::Ok;
  }

  std::size_t size() const { return xs_.size(); }
  bool empty() const { return xs_.empty(); }

  /// Index (in the container given to build) of the point nearest to q with squared distance
  /// < max_dist_sq, or kNone. *dist_sq receives the squared distance (unchanged when kNone).
  std::uint32_t nearest(const Vec3<T>& q, T* dist_sq, T max_dist_sq = std::numeric_limits<T>::infinity()) const {
    return nearest_impl(q(0), q(1), q(2), max_dist_sq, kNone, dist_sq);
  }

  /// As nearest(), seeded with a candidate (a leaf-order slot from a previous query, see
  /// nearest_slot()): its distance bounds the search, which prunes most of the tree when the
  /// query moved little (ICP iterations). Returns a leaf-order slot; ids via id_of_slot().
  std::uint32_t nearest_slot(const Vec3<T>& q, T* dist_sq, T max_dist_sq, std::uint32_t hint_slot) const {
    return nearest_impl_slot(q(0), q(1), q(2), max_dist_sq, hint_slot, dist_sq);
  }
  std::uint32_t id_of_slot(std::uint32_t slot) const { return ids_[slot]; }
  Vec3<T> point_of_slot(std::uint32_t slot) const { return Vec3<T>(xs_[slot], ys_[slot], zs_[slot]); }

 private:
  struct Node {
    T split = T(0);
    std::uint32_t begin = 0;  // leaf: first slot; inner: index of the right child (left is this + 1)
    std::uint32_t end = 0;    // leaf: one past the last slot
    std::uint8_t axis = 3;    // 0, 1, 2 for inner nodes, 3 for leaves
  };

  std::uint32_t build_node(std::uint32_t* order, std::uint32_t begin, std::uint32_t end, const T* const* coords) {
    const std::uint32_t self = static_cast<std::uint32_t>(nodes_.size());
    nodes_.emplace_back();
    if (end - begin <= leaf_size_) {
      nodes_[self].begin = begin;
      nodes_[self].end = end;
      nodes_[self].axis = 3;
      return self;
    }
    T lo[3], hi[3];
    for (int a = 0; a < 3; ++a) lo[a] = hi[a] = coords[a][order[begin]];
    for (std::uint32_t k = begin + 1; k < end; ++k)
      for (int a = 0; a < 3; ++a) {
        const T v = coords[a][order[k]];
        lo[a] = std::min(lo[a], v);
        hi[a] = std::max(hi[a], v);
      }
    int axis = 0;
    for (int a = 1; a < 3; ++a)
      if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
    if (!(hi[axis] > lo[axis])) {  // all points identical: one (oversized) leaf
      nodes_[self].begin = begin;
      nodes_[self].end = end;
      nodes_[self].axis = 3;
      return self;
    }
    const std::uint32_t mid = begin + (end - begin) / 2;
    const T* c = coords[axis];
    std::nth_element(order + begin, order + mid, order + end,
                     [c](std::uint32_t i, std::uint32_t j) { return c[i] < c[j]; });
    const T split = c[order[mid]];
    build_node(order, begin, mid, coords);
    const std::uint32_t right = build_node(order, mid, end, coords);
    nodes_[self].split = split;
    nodes_[self].begin = right;
    nodes_[self].axis = static_cast<std::uint8_t>(axis);
    return self;
  }

  std::uint32_t nearest_impl(T qx, T qy, T qz, T max_dist_sq, std::uint32_t hint, T* dist_sq) const {
    const std::uint32_t slot = nearest_impl_slot(qx, qy, qz, max_dist_sq, hint, dist_sq);
    return slot == kNone ? kNone : ids_[slot];
  }

  std::uint32_t nearest_impl_slot(T qx, T qy, T qz, T max_dist_sq, std::uint32_t hint, T* dist_sq) const {
    if (nodes_.empty() || !(max_dist_sq > T(0))) return kNone;
    T best = max_dist_sq;
    std::uint32_t best_slot = kNone;
    if (hint != kNone && hint < xs_.size()) {
      const T dx = xs_[hint] - qx, dy = ys_[hint] - qy, dz = zs_[hint] - qz;
      const T d = dx * dx + dy * dy + dz * dz;
      if (d < best) {
        best = d;
        best_slot = hint;
      }
    }
    const T q[3] = {qx, qy, qz};
    // Explicit stack of (node, lower bound on the squared distance to its cell); depth <= 64 for any
    // realistic size since the median split halves each range.
    struct Item {
      std::uint32_t node;
      T bound;
    };
    Item stack[128];
    int top = 0;
    stack[top++] = Item{0, T(0)};
    while (top > 0) {
      const Item item = stack[--top];
      if (item.bound >= best) continue;
      std::uint32_t node = item.node;
      for (;;) {
        const Node& nd = nodes_[node];
        if (nd.axis == 3) {
          const T* xs = xs_.data();
          const T* ys = ys_.data();
          const T* zs = zs_.data();
          for (std::uint32_t k = nd.begin; k < nd.end; ++k) {
            const T dx = xs[k] - qx, dy = ys[k] - qy, dz = zs[k] - qz;
            const T d = dx * dx + dy * dy + dz * dz;
            if (d < best) {
              best = d;
              best_slot = k;
            }
          }
          break;
        }
        const T diff = q[nd.axis] - nd.split;
        const std::uint32_t near = diff < T(0) ? node + 1 : nd.begin;
        const std::uint32_t far = diff < T(0) ? nd.begin : node + 1;
        const T far_bound = diff * diff;
        if (far_bound < best && top < 128) stack[top++] = Item{far, far_bound};
        node = near;
      }
    }
    if (best_slot != kNone) *dist_sq = best;
    return best_slot;
  }

  std::vector<T> xs_, ys_, zs_;
  std::vector<std::uint32_t> ids_;
  std::vector<Node> nodes_;
  std::uint32_t leaf_size_ = 12;
};

}  // namespace dyncull
