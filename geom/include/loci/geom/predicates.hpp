// Exact geometric predicates.
//
// orientation(a, b, c) tells on which side of the directed line a->b the point c lies, with
// the correct sign for every input of finite doubles: it is computed in floating point with
// Shewchuk's static error bound (the "A" bound of "Adaptive Precision Floating-Point
// Arithmetic and Fast Robust Geometric Predicates", 1997) and, only when the result is too
// close to zero to trust, decided again by CGAL's exact-predicates kernel. The fast path stays
// inline; the exact path lives in one compiled file so that CGAL's headers are paid for once.
#pragma once

#include <cmath>

#include "loci/geom/point.hpp"

namespace loci {

enum class Orientation : int { clockwise = -1, collinear = 0, counterclockwise = 1 };

namespace detail {
// Error-free transformations (Shewchuk's TwoDiff, TwoSum and TwoProduct): the rounded result
// and its rounding error, whose sum is the exact result.
struct Pair {
  double hi, lo;  // hi + lo exactly
};
inline Pair two_diff(double a, double b) {
  const double x = a - b;
  const double bv = a - x;
  const double av = x + bv;
  return {x, (a - av) + (bv - b)};
}
inline Pair two_sum(double a, double b) {
  const double x = a + b;
  const double bv = x - a;
  const double av = x - bv;
  return {x, (a - av) + (b - bv)};
}
inline Pair two_product(double a, double b) {
  const double x = a * b;
  return {x, std::fma(a, b, -x)};
}

// Decided exactly; called only when the floating filter cannot decide.
Orientation orientation_exact(double ax, double ay, double bx, double by, double cx, double cy);
// Decided exactly in rationals; called only when the floating filter cannot decide.
Orientation crossing_orientation_exact(const Point<2>& a, const Point<2>& b, const Point<2>& c,
                                       const Point<2>& d, const Point<2>& p, const Point<2>& q);
}  // namespace detail

inline Orientation orientation(const Point<2>& a, const Point<2>& b, const Point<2>& c) {
  const double left = (b[0] - a[0]) * (c[1] - a[1]);
  const double right = (b[1] - a[1]) * (c[0] - a[0]);
  const double det = left - right;
  // (3 + 16 eps) * eps with eps = 2^-53, bounding the rounding error of det relative to
  // |left| + |right|.
  constexpr double kErrBound = 3.3306690738754716e-16;
  const double bound = kErrBound * (std::fabs(left) + std::fabs(right));
  if (det > bound) return Orientation::counterclockwise;
  if (-det > bound) return Orientation::clockwise;
  return detail::orientation_exact(a[0], a[1], b[0], b[1], c[0], c[1]);
}

// orientation(p, q, x) for x the crossing of the segment a-b with the line through c and d,
// without computing x (which a double may not hold): a and b must lie strictly on either side
// of that line. Exact for every input of finite doubles, filtered as orientation is.
inline Orientation crossing_orientation(const Point<2>& a, const Point<2>& b, const Point<2>& c,
                                        const Point<2>& d, const Point<2>& p, const Point<2>& q) {
  // With oa, ob the orientations of a and b against c-d and pa, pb against p-q (each a
  // determinant), x = a + t (b - a) for t = oa / (oa - ob), and orientation(p, q, x) has the
  // sign of (oa pb - ob pa) / (oa - ob), oa - ob having the sign of oa.
  struct Det {
    double v, m;  // the rounded determinant and |left| + |right|
  };
  const auto det = [](const Point<2>& u, const Point<2>& w, const Point<2>& x) {
    const double left = (w[0] - u[0]) * (x[1] - u[1]);
    const double right = (w[1] - u[1]) * (x[0] - u[0]);
    return Det{left - right, std::fabs(left) + std::fabs(right)};
  };
  const Det oa = det(c, d, a), ob = det(c, d, b), pa = det(p, q, a), pb = det(p, q, b);
  const double num = oa.v * pb.v - ob.v * pa.v;
  // Each determinant is off by at most 3.4e-16 of its m (orientation's bound), the products
  // and their difference round once each: the numerator is off by less than 1e-15 of
  // oa.m pb.m + ob.m pa.m. Below 2^-900 underflow may have lost terms, and the sign of oa
  // must be sure: otherwise decided exactly.
  const double bound = 2e-15 * (oa.m * pb.m + ob.m * pa.m);
  if (bound > 0x1p-900 && std::fabs(oa.v) > 3.3306690738754716e-16 * oa.m) {
    const int s = oa.v > 0 ? 1 : -1;
    if (num > bound) return static_cast<Orientation>(s);
    if (-num > bound) return static_cast<Orientation>(-s);
  }
  return detail::crossing_orientation_exact(a, b, c, d, p, q);
}

inline int sign(Orientation o) {
  return static_cast<int>(o);
}

}  // namespace loci
