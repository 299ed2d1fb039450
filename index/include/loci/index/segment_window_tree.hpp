// SegmentWindowTree: the windowing structure for map segments. Given the segments of a layer,
// it reports every segment that meets an axis-parallel query window, including segments that
// cross the window with no endpoint inside it, with exact predicates (no epsilon anywhere).
//
// Method (de Berg, Cheong, van Kreveld and Overmars, "Computational Geometry", 3rd ed.,
// chapter 10, "Windowing"). A segment meets the closed window W either with an endpoint in W,
// or by crossing W's boundary, and then it meets one of W's four edges. So:
//   1. the 2n endpoints sit in a KdTree and a window query on it reports the first kind;
//   2. an "x-slab tree" answers "which segments meet the vertical query segment {x} x [y1, y2]"
//      for the left and right edges, and the same structure built on swapped coordinates
//      answers it for the bottom and top edges.
// The slab tree is a segment tree on the segments' x-intervals (elementary slots as in
// SegmentTree): a segment stored at a node spans the node's whole x-slab. Within one slab,
// segments that do not cross there are totally ordered from bottom to top, so the ones met by
// the vertical query segment are a contiguous run found by binary search. The book assumes
// non-crossing segments; real layers may cross, so each node's list is split greedily into
// chains in which every segment is verified, exactly, to lie on or above the previous one
// throughout the slab (the two do not intersect, or they only share an endpoint and are not
// collinear). A planar layer gives one chain per node; crossing data gives a few more. The
// binary search and the reporting test use the exact orientation predicate of the query
// point against the segment, so a segment through a window corner or along an edge is found.
// A vertical segment is left out of the x-slab tree (it is found through a bottom or top edge
// or through an endpoint) and a horizontal one out of the swapped tree, symmetrically.
//
// Every segment is reported once: through an endpoint (the first endpoint inside W), else
// through the first edge, in the order left, right, bottom, top, whose slab tree holds it.
// Segment i of build() is reported with id i; visitors are called as
// `bool visit(Id id, const Segment<2>& s)` and return false to stop.
//
// Complexity: O(n log n) memory and build (O(n log^2 n) worst case); a query costs
// O(c log^2 n + k) for k hits and c chains per node (c = 1 for a planar layer).
// Thread-safety: immutable after build; any number of concurrent queries.
#pragma once

#include <algorithm>
#include <bit>
#include <concepts>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "loci/geom/box.hpp"
#include "loci/geom/error.hpp"
#include "loci/geom/segment.hpp"
#include "loci/index/detail/segment_endpoints.hpp"
#include "loci/index/kd_tree.hpp"
#include "loci/index/query.hpp"
#include "loci/index/slab_tree.hpp"

namespace loci {

class SegmentWindowTree {
 public:
  SegmentWindowTree() = default;
  SegmentWindowTree(const SegmentWindowTree&) = default;
  SegmentWindowTree& operator=(const SegmentWindowTree&) = default;
  // Moving leaves `other` empty, as if default-constructed.
  SegmentWindowTree(SegmentWindowTree&& other) noexcept : SegmentWindowTree() { swap(other); }
  SegmentWindowTree& operator=(SegmentWindowTree&& other) noexcept {
    SegmentWindowTree(std::move(other)).swap(*this);
    return *this;
  }

  // Segment i gets id i. Throws InvalidGeometry on a NaN or infinite coordinate.
  static SegmentWindowTree build(std::span<const Segment<2>> segments) {
    SegmentWindowTree t;
    t.ends_ = detail::SegmentEndpoints<KdTree<2>>(segments, "SegmentWindowTree",
                                                  [](std::size_t, auto&) {});
    t.by_x_ = SlabTree(segments, false);
    t.by_y_ = SlabTree(segments, true);
    return t;
  }

  std::size_t size() const { return ends_.segments().size(); }
  bool empty() const { return size() == 0; }
  const Segment<2>& segment(Id id) const { return ends_.segment(id); }
  std::size_t memory_bytes() const {
    return ends_.memory_bytes() + by_x_.memory_bytes() + by_y_.memory_bytes();
  }

  // Calls visit(id, segment) once for every segment meeting the closed window; stops when it
  // returns false. Throws InvalidGeometry on a bad window.
  template <SegmentVisitor Visit>
  QueryStats query(const Box<2>& w, Visit&& visit) const;
  std::vector<Id> query(const Box<2>& w) const {
    return collect_ids([&](auto&& v) { return query(w, v); });
  }

  // Throws loci::Error describing the first broken invariant.
  void validate() const {
    ends_.validate("SegmentWindowTree");
    by_x_.validate("SegmentWindowTree");
    by_y_.validate("SegmentWindowTree");
  }

 private:
  void swap(SegmentWindowTree& other) noexcept {
    std::swap(ends_, other.ends_);
    std::swap(by_x_, other.by_x_);
    std::swap(by_y_, other.by_y_);
  }
  detail::SegmentEndpoints<KdTree<2>> ends_;  // the segments, and their endpoints in a kd-tree
  SlabTree by_x_;                             // for the left and right edges
  SlabTree by_y_;                             // on (y, x): for the bottom and top edges
};

template <SegmentVisitor Visit>
QueryStats SegmentWindowTree::query(const Box<2>& w, Visit&& visit) const {
  check_box(w, "query window");
  QueryStats s;
  if (empty()) return s;
  // 1. segments with an endpoint inside: reported through the first such endpoint
  if (!ends_.report_inside(w, s, visit)) return s;
  const auto segs = ends_.segments();

  // 2. segments crossing the boundary with both endpoints outside, through the first edge
  const Segment<2> left{{w.min[0], w.min[1]}, {w.min[0], w.max[1]}};
  const Segment<2> right{{w.max[0], w.min[1]}, {w.max[0], w.max[1]}};
  const Segment<2> bottom{{w.min[0], w.min[1]}, {w.max[0], w.min[1]}};
  auto outside = [&](const Segment<2>& g) { return !intersects(w, g.a) && !intersects(w, g.b); };
  auto report = [&](std::size_t i) {
    ++s.results;
    return bool(visit(Id(i), segs[i]));
  };
  if (!by_x_.stab(
          w.min[0], w.min[1], w.max[1],
          [&](std::size_t i) { return !outside(segs[i]) || report(i); }, s))
    return s;
  if (!by_x_.stab(
          w.max[0], w.min[1], w.max[1],
          [&](std::size_t i) {
            const Segment<2>& g = segs[i];
            return !outside(g) || intersects(g, left) || report(i);
          },
          s))
    return s;
  // an edge's slab tree may not hold a segment that meets it (axis-parallel ones)
  auto earlier_x = [&](std::size_t i) {
    const Segment<2>& g = segs[i];
    return by_x_.holds(i) && (intersects(g, left) || intersects(g, right));
  };
  if (!by_y_.stab(
          w.min[1], w.min[0], w.max[0],
          [&](std::size_t i) { return !outside(segs[i]) || earlier_x(i) || report(i); }, s))
    return s;
  by_y_.stab(
      w.max[1], w.min[0], w.max[0],
      [&](std::size_t i) {
        return !outside(segs[i]) || earlier_x(i) || intersects(segs[i], bottom) || report(i);
      },
      s);
  return s;
}

}  // namespace loci
