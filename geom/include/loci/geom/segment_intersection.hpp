// Where two closed 2D segments meet: nowhere, at one point, or along a collinear overlap.
//
// The kind of answer is decided exactly, by the exact orientation predicate (predicates.hpp),
// never by a floating epsilon: near-parallel segments that a tolerance would call crossing (or
// not) are decided as the real numbers decide. Touching counts, as everywhere in loci.
//
// The points reported:
// - an overlap is given by its two ends, which are always input endpoints (exact);
// - a touch at an endpoint (a T-junction, a shared vertex, a zero-length segment lying on the
//   other) reports that endpoint (exact);
// - a proper crossing (each segment strictly on both sides of the other's line) reports the
//   crossing point computed in exact rational arithmetic and rounded to the nearest double
//   in each coordinate: the true point, to double precision. The rounded point may fall a
//   fraction of an ulp off both lines; it always lies in the intersection of the two
//   segments' bounding boxes.
#pragma once

#include <cstdint>

#include "loci/geom/segment.hpp"

namespace loci {

enum class SegmentMeet : std::uint8_t { none, point, overlap };

struct SegmentIntersection {
  SegmentMeet kind = SegmentMeet::none;
  Point<2> a{};  // the point (point), or the overlap's lexicographically smaller end
  Point<2> b{};  // the overlap's other end; equal to a for a point
  friend bool operator==(const SegmentIntersection&, const SegmentIntersection&) = default;
};

SegmentIntersection intersection(const Segment<2>& s, const Segment<2>& t);

namespace detail {
// The crossing point of the lines through two properly crossing segments, exactly computed
// and rounded to the nearest doubles.
Point<2> crossing_point(const Segment<2>& s, const Segment<2>& t);
}  // namespace detail

}  // namespace loci
