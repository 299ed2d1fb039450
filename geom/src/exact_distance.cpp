// The exact fallbacks of accurate_squared_distance and compare_distance (see segment.hpp).
//
// Every double is a rational, and the squared distance from a point to a segment is a
// rational function of the coordinates: |w|^2 before the segment's start (w = p - a, v = b - a,
// w.v <= 0), |p - b|^2 beyond its end (w.v >= v.v), and (w x v)^2 / v.v in between. CGAL's
// exact rationals evaluate those without error; only the final conversion rounds.
#include <CGAL/Exact_rational.h>

#include <limits>
#include <utility>

#include "loci/geom/segment.hpp"

namespace loci::detail {

namespace {

using Q = CGAL::Exact_rational;

// The exact squared distance as numerator / denominator (denominator 1 off the interior).
std::pair<Q, Q> exact_squared_distance(const Point<2>& p, const Segment<2>& s) {
  const Q ax(s.a[0]), ay(s.a[1]), bx(s.b[0]), by(s.b[1]), px(p[0]), py(p[1]);
  const Q vx = bx - ax, vy = by - ay, wx = px - ax, wy = py - ay;
  const Q dot = wx * vx + wy * vy, vv = vx * vx + vy * vy;
  if (CGAL::is_zero(vv) || !CGAL::is_positive(dot)) return {wx * wx + wy * wy, Q(1)};
  if (dot >= vv) {
    const Q ux = px - bx, uy = py - by;
    return {ux * ux + uy * uy, Q(1)};
  }
  const Q cross = wx * vy - wy * vx;
  return {cross * cross, vv};
}

}  // namespace

double squared_distance_exact(const Point<2>& p, const Segment<2>& s) {
  const auto [num, den] = exact_squared_distance(p, s);
  if (CGAL::is_zero(num)) return 0.0;
  const double d2 = CGAL::to_double(num / den);
  // A positive distance too small for a double still reads as positive.
  return d2 > 0 ? d2 : std::numeric_limits<double>::denorm_min();
}

int compare_distance_exact(const Point<2>& p, const Segment<2>& s, double d) {
  const auto [num, den] = exact_squared_distance(p, s);
  const Q dd(d);
  return int(CGAL::compare(num, dd * dd * den));
}

}  // namespace loci::detail
