// AxisParallelWindowTree: windowing for layers made only of horizontal and vertical segments
// (street grids, cadastral lines, rasters turned into outlines, VLSI wiring). It reports every
// segment that meets a closed axis-parallel window; segments along an edge, ending on one, or
// through a corner count.
//
// Method (de Berg, Cheong, van Kreveld and Overmars, "Computational Geometry", 3rd ed.,
// chapters 10.1 and 10.2). A segment meets the window W either with an endpoint in W, or with
// both endpoints outside; in the second case a horizontal segment spans W's whole width, so
// it crosses W's left edge, and a vertical one crosses W's bottom edge. So:
//   1. the 2n endpoints sit in a KdTree and a window query on it reports the first kind,
//      each segment through its first endpoint inside W (as SegmentWindowTree does);
//   2. the horizontal segments sit in a centered interval tree on their x-intervals
//      (Edelsbrunner, 1980): a node takes the median x of its segments' endpoints, keeps the
//      segments whose x-interval contains it and passes those wholly left or right of it to
//      its two subtrees. Instead of the book's two sorted lists, a node keeps its segments in
//      two priority search trees, one on (left end x, y) and one on (right end x, y), so
//      that the vertical query segment {qx} x [y1, y2] is answered on one root-to-leaf path:
//      qx < mid asks the left-end tree for x <= qx and goes left, qx > mid asks the right-end
//      tree for x >= qx and goes right, qx == mid takes every stored segment with y in range
//      and stops. The walk for W's left edge reports the horizontal segments of the second
//      kind, after a filter that drops those with an endpoint in W (already reported);
//   3. the vertical segments sit in the same structure built on (y, x), walked for W's
//      bottom edge.
// A zero-length segment is in neither tree; its endpoint reports it. Everything is decided by
// comparing coordinates, so the answer is exact with no epsilon. The priority search trees of
// all nodes share two flat arrays (each node owns a contiguous run), and the interval tree's
// nodes live in one array addressed by 32-bit indices.
//
// Input must be axis-parallel: any other segment is refused at build() with an
// InvalidGeometry naming it (SegmentWindowTree takes arbitrary segments). Segment i of
// build() is reported with id i; visitors are called as `bool visit(Id id, const
// Segment<2>& s)` and return false to stop.
//
// Invariants (checked by validate()): every node's stored segments contain its mid and lie
// strictly inside the x-range its ancestors leave it; each horizontal (vertical) segment is
// stored once, in both trees of one node of the horizontal (vertical) tree, with its own
// coordinates; the priority search trees are in heap and split order; the endpoint tree holds
// 2n points.
//
// Complexity: build O(n log n); memory O(n), about 230 bytes per segment of which the endpoint
// tree takes half. The crossing part of a query costs O(log^2 n + k); the endpoint part is a
// k-d tree window query, O(sqrt(n) + k) in the worst case (the book's range tree would give
// O(log^2 n + k) at the price of O(n log n) memory).
// Thread-safety: immutable after build; any number of concurrent queries.
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "loci/geom/box.hpp"
#include "loci/geom/error.hpp"
#include "loci/geom/segment.hpp"
#include "loci/index/centered_interval_tree.hpp"
#include "loci/index/detail/scratch.hpp"
#include "loci/index/detail/segment_endpoints.hpp"
#include "loci/index/kd_tree.hpp"
#include "loci/index/query.hpp"

namespace loci {

class AxisParallelWindowTree {
 public:
  AxisParallelWindowTree() = default;
  AxisParallelWindowTree(const AxisParallelWindowTree&) = default;
  AxisParallelWindowTree& operator=(const AxisParallelWindowTree&) = default;
  // Moving leaves `other` empty, as if default-constructed.
  AxisParallelWindowTree(AxisParallelWindowTree&& other) noexcept : AxisParallelWindowTree() {
    swap(other);
  }
  AxisParallelWindowTree& operator=(AxisParallelWindowTree&& other) noexcept {
    AxisParallelWindowTree(std::move(other)).swap(*this);
    return *this;
  }

  // Segment i gets id i. Throws InvalidGeometry on a NaN or infinite coordinate or a segment
  // that is neither horizontal nor vertical, InvalidArgument for 2^31 - 1 segments or more.
  static AxisParallelWindowTree build(std::span<const Segment<2>> segments) {
    AxisParallelWindowTree t;
    t.ends_ = detail::SegmentEndpoints<KdTree<2>>(
        segments, "AxisParallelWindowTree", [](std::size_t i, const Segment<2>& s) {
          if (s.a[0] != s.b[0] && s.a[1] != s.b[1])
            throw InvalidGeometry("segment " + std::to_string(i) + " is not axis-parallel: " +
                                  to_string(s.a) + " - " + to_string(s.b));
        });
    t.horizontal_ = CenteredIntervalTree(segments, false);
    t.vertical_ = CenteredIntervalTree(segments, true);
    return t;
  }

  std::size_t size() const { return ends_.segments().size(); }
  bool empty() const { return size() == 0; }
  const Segment<2>& segment(Id id) const { return ends_.segment(id); }
  std::size_t memory_bytes() const {
    return ends_.memory_bytes() + horizontal_.memory_bytes() + vertical_.memory_bytes();
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
    ends_.validate("AxisParallelWindowTree");
    horizontal_.validate(ends_.segments(), "AxisParallelWindowTree invalid: horizontal tree");
    vertical_.validate(ends_.segments(), "AxisParallelWindowTree invalid: vertical tree");
  }

 private:
  void swap(AxisParallelWindowTree& other) noexcept {
    std::swap(ends_, other.ends_);
    std::swap(horizontal_, other.horizontal_);
    std::swap(vertical_, other.vertical_);
  }
  detail::SegmentEndpoints<KdTree<2>> ends_;  // the segments, and their endpoints in a kd-tree
  CenteredIntervalTree horizontal_;           // walked along the window's left edge
  CenteredIntervalTree vertical_;             // on (y, x): walked along the bottom edge
};

template <SegmentVisitor Visit>
QueryStats AxisParallelWindowTree::query(const Box<2>& w, Visit&& visit) const {
  check_box(w, "query window");
  QueryStats s;
  if (empty()) return s;
  if (!ends_.report_inside(w, s, visit)) return s;

  // The walks also meet segments with an endpoint in W; those were reported above.
  auto crossing = [&](std::size_t i) {
    const Segment<2>& g = ends_.segments()[i];
    if (intersects(w, g.a) || intersects(w, g.b)) return true;
    ++s.results;
    return bool(visit(Id(i), g));
  };
  detail::Scratch<std::uint32_t> scratch;
  if (!horizontal_.stab(w.min[0], w.min[1], w.max[1], *scratch, s, crossing)) return s;
  vertical_.stab(w.min[1], w.min[0], w.max[0], *scratch, s, crossing);
  return s;
}

}  // namespace loci
