// Box<D>: a closed axis-aligned box [min, max] in D dimensions.
//
// Closed means that boxes sharing only an edge or a corner intersect, and that a point on the
// boundary is inside: the semantics every loci query shares (DESIGN.md section 4). A box with
// min == max on some axis is valid (a point or a segment's box); a box with min > max on some
// axis is only valid as the empty box, which intersects nothing and is the identity of
// expand().
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "loci/geom/point.hpp"

namespace loci {

template <int D>
struct Box {
  static constexpr int dimension = D;

  Point<D> min;
  Point<D> max;

  static constexpr Box empty() {
    Box b{};
    for (int i = 0; i < D; ++i) {
      b.min[i] = std::numeric_limits<double>::infinity();
      b.max[i] = -std::numeric_limits<double>::infinity();
    }
    return b;
  }
  static constexpr Box of_point(const Point<D>& p) { return Box{p, p}; }

  constexpr bool is_empty() const {
    for (int i = 0; i < D; ++i)
      if (!(min[i] <= max[i])) return true;
    return false;
  }

  constexpr void expand(const Point<D>& p) {
    for (int i = 0; i < D; ++i) {
      min[i] = std::min(min[i], p[i]);
      max[i] = std::max(max[i], p[i]);
    }
  }
  constexpr void expand(const Box& b) {
    for (int i = 0; i < D; ++i) {
      min[i] = std::min(min[i], b.min[i]);
      max[i] = std::max(max[i], b.max[i]);
    }
  }

  constexpr double extent(int axis) const { return max[axis] - min[axis]; }
  constexpr double center(int axis) const { return 0.5 * (min[axis] + max[axis]); }
  constexpr Point<D> center() const {
    Point<D> p{};
    for (int i = 0; i < D; ++i)
      p[i] = center(i);
    return p;
  }
  // Area (D = 2) or volume (D = 3).
  constexpr double content() const {
    double v = 1;
    for (int i = 0; i < D; ++i)
      v *= extent(i);
    return v;
  }
  // Sum of the edge lengths along each axis: the R*-tree's "margin" up to a constant factor.
  constexpr double margin() const {
    double m = 0;
    for (int i = 0; i < D; ++i)
      m += extent(i);
    return m;
  }

  friend constexpr bool operator==(const Box&, const Box&) = default;
};

using Box2 = Box<2>;
using Box3 = Box<3>;

template <int D>
constexpr Box<D> merged(Box<D> a, const Box<D>& b) {
  a.expand(b);
  return a;
}

template <int D>
constexpr bool intersects(const Box<D>& a, const Box<D>& b) {
  for (int i = 0; i < D; ++i)
    if (a.max[i] < b.min[i] || b.max[i] < a.min[i]) return false;
  return true;
}

template <int D>
constexpr bool intersects(const Box<D>& a, const Point<D>& p) {
  for (int i = 0; i < D; ++i)
    if (p[i] < a.min[i] || a.max[i] < p[i]) return false;
  return true;
}

// `outer` contains `inner` (closed: equal boxes contain each other).
template <int D>
constexpr bool contains(const Box<D>& outer, const Box<D>& inner) {
  for (int i = 0; i < D; ++i)
    if (inner.min[i] < outer.min[i] || outer.max[i] < inner.max[i]) return false;
  return true;
}

template <int D>
constexpr bool within(const Box<D>& inner, const Box<D>& outer) {
  return contains(outer, inner);
}

// b grown by d >= 0 on every side, its bounds rounded outward, so that every point within
// distance d of b lies in it.
template <int D>
Box<D> outset(const Box<D>& b, double d) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  Box<D> g = b;
  for (int i = 0; i < D; ++i) {
    g.min[i] = std::nextafter(b.min[i] - d, -inf);
    g.max[i] = std::nextafter(b.max[i] + d, inf);
  }
  return g;
}

// Content of the intersection of a and b (0 when they are disjoint or only touch).
template <int D>
constexpr double overlap(const Box<D>& a, const Box<D>& b) {
  double v = 1;
  for (int i = 0; i < D; ++i) {
    const double lo = std::max(a.min[i], b.min[i]);
    const double hi = std::min(a.max[i], b.max[i]);
    if (hi <= lo) return 0;
    v *= hi - lo;
  }
  return v;
}

// Squared Euclidean distance from p to the nearest point of b (0 inside).
template <int D>
constexpr double squared_distance(const Point<D>& p, const Box<D>& b) {
  double s = 0;
  for (int i = 0; i < D; ++i) {
    double d = 0;
    if (p[i] < b.min[i])
      d = b.min[i] - p[i];
    else if (p[i] > b.max[i])
      d = p[i] - b.max[i];
    s += d * d;
  }
  return s;
}

// Squared MINMAXDIST (Roussopoulos, Kelley, Vincent, SIGMOD 1995): when every face of b holds a
// point of some set (b is that set's bounding box), the set has a point at most this far from
// p. Per axis k, the face nearer to p along k, at its corner farthest from p; the least of
// those. b must not be empty. Rounded like any sum of squares: a caller that prunes by it
// allows a few units in the last place.
template <int D>
constexpr double squared_minmax_distance(const Point<D>& p, const Box<D>& b) {
  double near[D], far[D];
  for (int i = 0; i < D; ++i) {
    const double lo = p[i] - b.min[i], hi = p[i] - b.max[i];
    near[i] = std::min(lo * lo, hi * hi);
    far[i] = std::max(lo * lo, hi * hi);
  }
  double best = std::numeric_limits<double>::infinity();
  for (int k = 0; k < D; ++k) {
    double s = 0;
    for (int i = 0; i < D; ++i)
      s += i == k ? near[i] : far[i];
    best = std::min(best, s);
  }
  return best;
}

template <int D>
std::string to_string(const Box<D>& b) {
  std::string s = "[";
  s += to_string(b.min);
  s += " .. ";
  s += to_string(b.max);
  return s += ']';
}

// The largest magnitude of a coordinate of b: the scale its coordinates' rounding is
// relative to (infinite for the empty box).
template <int D>
inline double magnitude(const Box<D>& b) {
  double m = 0;
  for (int i = 0; i < D; ++i)
    m = std::max({m, std::fabs(b.min[i]), std::fabs(b.max[i])});
  return m;
}

// Finite coordinates and min <= max on every axis.
template <int D>
constexpr bool is_valid(const Box<D>& b) {
  for (int i = 0; i < D; ++i)
    if (!(std::isfinite(b.min[i]) && std::isfinite(b.max[i]) && b.min[i] <= b.max[i])) return false;
  return true;
}

namespace detail {
// check_box's refusal, out of the callers' way.
template <int D>
[[gnu::cold, gnu::noinline]] void refuse_box(const Box<D>& b, const char* what) {
  if (!is_finite(b.min) || !is_finite(b.max))
    throw InvalidGeometry(std::string(what) + " has a NaN or infinite coordinate: " + to_string(b));
  for (int i = 0; i < D; ++i)
    if (b.min[i] > b.max[i])
      throw InvalidGeometry(std::string(what) + " is inverted (min > max on axis " +
                            std::to_string(i) + "): " + to_string(b));
}
}  // namespace detail

// Throws InvalidGeometry naming `what` for a NaN/infinite coordinate or an inverted box.
template <int D>
inline void check_box(const Box<D>& b, const char* what = "box") {
  if (!is_valid(b)) [[unlikely]]
    detail::refuse_box(b, what);
}

}  // namespace loci
