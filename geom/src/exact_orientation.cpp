// The exact fallback of loci::orientation (see predicates.hpp).
//
// The determinant (bx - ax)(cy - ay) - (by - ay)(cx - ax) is evaluated without error as an
// expansion (Shewchuk's arithmetic): each difference is split into its rounded value and the
// exact rounding error (TwoDiff), each product of such pairs into four exact products of two
// doubles each (TwoProduct with a fused multiply-add), and the sixteen terms are summed into a
// nonoverlapping expansion whose largest component carries the sign of the exact sum. That is
// exact as long as no product underflows or overflows; for inputs small or large enough to
// risk it, CGAL's exact kernel decides instead.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Exact_rational.h>

#include <array>
#include <cmath>
#include <tuple>

#include "loci/geom/predicates.hpp"

namespace loci::detail {

namespace {

Orientation cgal_orientation(double ax, double ay, double bx, double by, double cx, double cy) {
  using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
  using P = Kernel::Point_2;
  switch (CGAL::orientation(P(ax, ay), P(bx, by), P(cx, cy))) {
    case CGAL::LEFT_TURN:
      return Orientation::counterclockwise;
    case CGAL::RIGHT_TURN:
      return Orientation::clockwise;
    default:
      return Orientation::collinear;
  }
}

}  // namespace

Orientation orientation_exact(double ax, double ay, double bx, double by, double cx, double cy) {
  // A point repeated: the determinant is exactly zero.
  if ((ax == bx && ay == by) || (ax == cx && ay == cy) || (bx == cx && by == cy))
    return Orientation::collinear;
  const Pair dx1 = two_diff(bx, ax), dy2 = two_diff(cy, ay);
  const Pair dy1 = two_diff(by, ay), dx2 = two_diff(cx, ax);
  // Rounding errors of products below 2^-969 may be lost to underflow, and products of
  // differences beyond 2^500 (or a difference of coordinates near the largest double, which
  // overflows) would overflow: leave such inputs to the slow exact kernel.
  constexpr double kTiny = 0x1p-480, kHuge = 0x1p+500;
  for (const Pair& d : {dx1, dy2, dy1, dx2})
    if ((d.hi != 0 && std::fabs(d.hi) < kTiny) || (d.lo != 0 && std::fabs(d.lo) < kTiny) ||
        !(std::fabs(d.hi) <= kHuge))
      return cgal_orientation(ax, ay, bx, by, cx, cy);
  std::array<double, 16> terms;
  int n = 0;
  for (const auto& [p, q, s] : {std::tuple{dx1, dy2, 1.0}, std::tuple{dy1, dx2, -1.0}}) {
    for (const double u : {p.hi, p.lo})
      for (const double v : {q.hi, q.lo}) {
        const Pair t = two_product(u, v);
        terms[n++] = s * t.hi;
        terms[n++] = s * t.lo;
      }
  }
  // Grow a nonoverlapping expansion term by term (Shewchuk's GROW-EXPANSION, zeros dropped).
  std::array<double, 17> e;
  int m = 0;
  for (const double t : terms) {
    double q = t;
    int k = 0;
    for (int i = 0; i < m; ++i) {
      const Pair s = two_sum(q, e[i]);
      if (s.lo != 0) e[k++] = s.lo;
      q = s.hi;
    }
    if (q != 0) e[k++] = q;
    m = k;
  }
  if (m == 0) return Orientation::collinear;
  return e[m - 1] > 0 ? Orientation::counterclockwise : Orientation::clockwise;
}

Orientation crossing_orientation_exact(const Point<2>& a, const Point<2>& b, const Point<2>& c,
                                       const Point<2>& d, const Point<2>& p, const Point<2>& q) {
  using Q = CGAL::Exact_rational;
  // (Q is returned by value: gmpxx's expression templates would outlive their operands.)
  const auto det = [](const Point<2>& u, const Point<2>& w, const Point<2>& x) -> Q {
    return (Q(w[0]) - Q(u[0])) * (Q(x[1]) - Q(u[1])) - (Q(w[1]) - Q(u[1])) * (Q(x[0]) - Q(u[0]));
  };
  const Q oa = det(c, d, a), ob = det(c, d, b), pa = det(p, q, a), pb = det(p, q, b);
  const Q num = oa * pb - ob * pa, den = oa - ob;
  const int s = int(CGAL::sign(num)) * int(CGAL::sign(den));
  return static_cast<Orientation>(s);
}

}  // namespace loci::detail
