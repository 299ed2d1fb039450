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
// Decided exactly; called only when the floating filter cannot decide.
Orientation orientation_exact(double ax, double ay, double bx, double by, double cx, double cy);
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

inline int sign(Orientation o) {
  return static_cast<int>(o);
}

}  // namespace loci
