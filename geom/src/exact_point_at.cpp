// The exact tests on a point inside a segment (see segment.hpp): the point s.a + t (s.b - s.a)
// has rational coordinates whenever the inputs are doubles, which CGAL's exact rationals hold
// without error.
#include <CGAL/Exact_rational.h>

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
  return int(CGAL::compare(coordinate_at(s, t, axis), Q(v)));
}

Orientation orientation_at(const Point<2>& a, const Point<2>& b, const Segment<2>& s, double t) {
  const Q px = coordinate_at(s, t, 0), py = coordinate_at(s, t, 1);
  const Q ax(a[0]), ay(a[1]);
  const Q det = (Q(b[0]) - ax) * (py - ay) - (Q(b[1]) - ay) * (px - ax);
  const int sign = int(CGAL::sign(det));
  return sign > 0   ? Orientation::counterclockwise
         : sign < 0 ? Orientation::clockwise
                    : Orientation::collinear;
}

}  // namespace loci
