// The exact tests on a point inside a segment (see segment.hpp): the point s.a + t (s.b - s.a)
// has rational coordinates whenever the inputs are doubles, which CGAL's exact rationals hold
// without error.
#include <CGAL/Exact_rational.h>

#include <algorithm>

#include "loci/geom/predicates.hpp"
#include "loci/geom/segment.hpp"

namespace loci {

namespace {
using Q = CGAL::Exact_rational;

Q coordinate_at(const Segment<2>& s, double t, int axis) {
  const Q a(s.a[axis]);
  return a + Q(t) * (Q(s.b[axis]) - a);
}
}  // namespace

int compare_coordinate_at(const Segment<2>& s, double t, int axis, double v) {
  // For t in [0, 1] the coordinate lies between the ends': v outside that range, both ends on
  // v, or one end on it, decide without rationals.
  if (t >= 0 && t <= 1) {
    const double lo = std::min(s.a[axis], s.b[axis]), hi = std::max(s.a[axis], s.b[axis]);
    if (v < lo) return 1;
    if (v > hi) return -1;
    if (lo == hi) return 0;
    // An end at v: the coordinate moves away from it at once.
    if (s.a[axis] == v) return t == 0 ? 0 : s.b[axis] > v ? 1 : -1;
    if (s.b[axis] == v) return t == 1 ? 0 : s.a[axis] > v ? 1 : -1;
  }
  return int(CGAL::compare(coordinate_at(s, t, axis), Q(v)));
}

Orientation orientation_at(const Point<2>& a, const Point<2>& b, const Segment<2>& s, double t) {
  // The orientation is affine along s: (1 - t) o(s.a) + t o(s.b). For t in [0, 1], ends on one
  // side (or both on the line) decide, and so does an end on the line with t away from it.
  if (t >= 0 && t <= 1) {
    const Orientation oa = orientation(a, b, s.a), ob = orientation(a, b, s.b);
    if (oa == ob) return oa;
    if (oa == Orientation::collinear && t > 0) return ob;
    if (ob == Orientation::collinear && t < 1) return oa;
  }
  const Q px = coordinate_at(s, t, 0), py = coordinate_at(s, t, 1);
  const Q ax(a[0]), ay(a[1]);
  const Q det = (Q(b[0]) - ax) * (py - ay) - (Q(b[1]) - ay) * (px - ax);
  const int sign = int(CGAL::sign(det));
  return sign > 0   ? Orientation::counterclockwise
         : sign < 0 ? Orientation::clockwise
                    : Orientation::collinear;
}

}  // namespace loci
