// The exact part of segment intersection (see segment_intersection.hpp): the case analysis by
// orientation signs, and the crossing point in GMP rationals through CGAL's number types.
#include "loci/geom/segment_intersection.hpp"

#include <CGAL/Gmpq.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <utility>

namespace loci {

namespace {

bool lex_less(const Point<2>& p, const Point<2>& q) {
  return p[0] < q[0] || (p[0] == q[0] && p[1] < q[1]);
}

SegmentIntersection at(const Point<2>& p) {
  return {SegmentMeet::point, p, p};
}

// Both segments on one line (or degenerate): the overlap of their lexicographic extents.
SegmentIntersection collinear_overlap(const Segment<2>& s, const Segment<2>& t) {
  auto ordered = [](const Segment<2>& g) {
    return lex_less(g.b, g.a) ? std::pair{g.b, g.a} : std::pair{g.a, g.b};
  };
  const auto [s0, s1] = ordered(s);
  const auto [t0, t1] = ordered(t);
  const Point<2> lo = lex_less(s0, t0) ? t0 : s0;
  const Point<2> hi = lex_less(s1, t1) ? s1 : t1;
  if (lex_less(hi, lo)) return {};
  if (lo == hi) return at(lo);
  return {SegmentMeet::overlap, lo, hi};
}

}  // namespace

namespace {

// The double nearest to q (ties to the even one, as IEEE rounding does).
double nearest_double(const CGAL::Gmpq& q) {
  const std::pair<double, double> iv = CGAL::to_interval(q);  // [lo, hi], at most one ulp
  if (iv.first == iv.second) return iv.first;
  const CGAL::Gmpq below = q - CGAL::Gmpq(iv.first), above = CGAL::Gmpq(iv.second) - q;
  if (below != above) return below < above ? iv.first : iv.second;
  return (std::bit_cast<std::uint64_t>(iv.first) & 1) == 0 ? iv.first : iv.second;
}

}  // namespace

namespace detail {

Point<2> crossing_point(const Segment<2>& s, const Segment<2>& t) {
  using Q = CGAL::Gmpq;
  const Q sx = s.a[0], sy = s.a[1];
  const Q dx = Q(s.b[0]) - sx, dy = Q(s.b[1]) - sy;
  const Q ex = Q(t.b[0]) - t.a[0], ey = Q(t.b[1]) - t.a[1];
  const Q denom = dx * ey - dy * ex;
  const Q u = ((Q(t.a[0]) - sx) * ey - (Q(t.a[1]) - sy) * ex) / denom;
  return {nearest_double(sx + u * dx), nearest_double(sy + u * dy)};
}

}  // namespace detail

SegmentIntersection intersection(const Segment<2>& s, const Segment<2>& t) {
  if (!intersects(s.box(), t.box())) return {};
  const bool s_point = s.a == s.b, t_point = t.a == t.b;
  if (s_point && t_point) return s.a == t.a ? at(s.a) : SegmentIntersection{};
  if (s_point)
    return orientation(t.a, t.b, s.a) == Orientation::collinear ? at(s.a) : SegmentIntersection{};
  if (t_point)
    return orientation(s.a, s.b, t.a) == Orientation::collinear ? at(t.a) : SegmentIntersection{};
  const int o1 = sign(orientation(s.a, s.b, t.a));
  const int o2 = sign(orientation(s.a, s.b, t.b));
  if (o1 == 0 && o2 == 0) return collinear_overlap(s, t);
  const int o3 = sign(orientation(t.a, t.b, s.a));
  const int o4 = sign(orientation(t.a, t.b, s.b));
  if (o1 * o2 > 0 || o3 * o4 > 0) return {};
  // Not collinear: the lines meet in one point. If an endpoint lies on the other segment's
  // line, that endpoint is the point (the bounding boxes and signs place it on the segment).
  if (o1 == 0) return at(t.a);
  if (o2 == 0) return at(t.b);
  if (o3 == 0) return at(s.a);
  if (o4 == 0) return at(s.b);
  Point<2> p = detail::crossing_point(s, t);
  // Rounding cannot leave the true point's box, but keep the promise explicit.
  const Box<2> both{{std::max(std::min(s.a[0], s.b[0]), std::min(t.a[0], t.b[0])),
                     std::max(std::min(s.a[1], s.b[1]), std::min(t.a[1], t.b[1]))},
                    {std::min(std::max(s.a[0], s.b[0]), std::max(t.a[0], t.b[0])),
                     std::min(std::max(s.a[1], s.b[1]), std::max(t.a[1], t.b[1]))}};
  for (int a = 0; a < 2; ++a)
    p[a] = std::clamp(p[a], both.min[a], both.max[a]);
  return at(p);
}

}  // namespace loci
