// Every pair of intersecting segments, within one set of linework or between two, with where
// they meet: the "which roads cross which rivers" and "where does this coastline cross itself"
// questions, on the segments of lines and polygon rings.
//
// Method: a sort-and-sweep join of the segments' boxes (sweep_join.hpp) gives the candidate
// pairs, and the exact segment intersection (geom/segment_intersection.hpp) decides each one,
// so the answer is exact: touching counts, collinear overlaps are reported with their two
// ends, near-parallel segments are decided as the real numbers decide. On map linework the
// boxes of short segments overlap rarely, so the sweep costs little more than its sort and the
// exact test runs on few candidates.
//
// Within one set, consecutive segments of a line or ring always share their common vertex; the
// caller's `adjacent(i, j)` names such pairs, and a pair of adjacent segments is reported only
// when they meet somewhere else too (a spike that doubles back along itself is a collinear
// overlap and is reported). Visitors are called as `bool visit(Id i, Id j, const
// SegmentIntersection& x)` with indices into the inputs (i < j within one set) and return
// false to stop. Thread-safety: pure functions of their inputs.
#pragma once

#include <span>
#include <vector>

#include "loci/geom/segment_intersection.hpp"
#include "loci/index/query.hpp"
#include "loci/index/sweep_join.hpp"

namespace loci {

template <class F>
concept IntersectionVisitor = Visitor<F, Id, Id, const SegmentIntersection&>;

namespace detail {
inline std::vector<Box<2>> segment_boxes(std::span<const Segment<2>> segs) {
  std::vector<Box<2>> boxes(segs.size());
  for (std::size_t i = 0; i < segs.size(); ++i) {
    check_segment(segs[i], ("segment " + std::to_string(i)).c_str());
    boxes[i] = segs[i].box();
  }
  return boxes;
}

// True when adjacent segments s and t meet only at a vertex they share.
inline bool only_at_shared_vertex(const Segment<2>& s, const Segment<2>& t,
                                  const SegmentIntersection& x) {
  if (x.kind != SegmentMeet::point) return false;
  return (x.a == s.a || x.a == s.b) && (x.a == t.a || x.a == t.b);
}
}  // namespace detail

// All intersecting pairs i < j of `segs` except adjacent ones meeting only at their shared
// vertex. `stats.entries_tested` counts the exact tests. Throws InvalidGeometry on a NaN or
// infinite coordinate.
template <class Adjacent, IntersectionVisitor Visit>
QueryStats segment_intersections(std::span<const Segment<2>> segs, Adjacent&& adjacent,
                                 Visit&& visit) {
  const std::vector<Box<2>> boxes = detail::segment_boxes(segs);
  QueryStats stats;
  const QueryStats sweep = self_join(boxes, [&](Id i, Id j) {
    ++stats.entries_tested;
    const SegmentIntersection x = intersection(segs[i], segs[j]);
    if (x.kind == SegmentMeet::none) return true;
    if (adjacent(i, j) && detail::only_at_shared_vertex(segs[i], segs[j], x)) return true;
    ++stats.results;
    return bool(visit(i, j, x));
  });
  stats.nodes_visited = sweep.entries_tested;  // box pairs the sweep compared
  return stats;
}

// All intersecting pairs (i of a, j of b). Throws InvalidGeometry on a NaN or infinite
// coordinate.
template <IntersectionVisitor Visit>
QueryStats segment_intersections(std::span<const Segment<2>> a, std::span<const Segment<2>> b,
                                 Visit&& visit) {
  const std::vector<Box<2>> boxes_a = detail::segment_boxes(a), boxes_b = detail::segment_boxes(b);
  QueryStats stats;
  const QueryStats sweep = join(boxes_a, boxes_b, [&](Id i, Id j) {
    ++stats.entries_tested;
    const SegmentIntersection x = intersection(a[i], b[j]);
    if (x.kind == SegmentMeet::none) return true;
    ++stats.results;
    return bool(visit(i, j, x));
  });
  stats.nodes_visited = sweep.entries_tested;
  return stats;
}

}  // namespace loci
