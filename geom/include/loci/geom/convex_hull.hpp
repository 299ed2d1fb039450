// The convex hull of a set of points in the plane, and the nearest point of a hull to a point
// outside it.
//
// convex_hull() is Andrew's monotone chain (1979): the points sorted by x then y, a lower and
// an upper chain built by dropping every point that does not turn left. The turns are decided
// by the exact orientation predicate (predicates.hpp), so the hull holds every input point and
// its vertices are input points, whatever the rounding of nearby coordinates: a lower bound on
// the distance to the set taken from the hull is a true one. Cost O(n log n) for the sort;
// hull_candidates() first drops the points strictly inside the polygon of the eight extreme
// points (Akl and Toussaint, 1978), which for the linework of a map layer leaves few.
//
// nearest_vertex() answers, in O(h) for a hull of h vertices, whether the point of the hull
// nearest to p is one of its vertices, and which: then, because the vertex is one of the
// points and every point lies in the hull, the distance from p to the whole set is the
// distance to that vertex, found without reading the set. It says so only when the floating
// tests leave no doubt (rounding is bounded, not assumed away); otherwise hull_lower_bound()
// bounds the distance from below, and the caller measures the set itself.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>
#include <vector>

#include "loci/geom/box.hpp"
#include "loci/geom/point.hpp"
#include "loci/geom/predicates.hpp"
#include "loci/geom/segment.hpp"

namespace loci {

// Appends to `out` the vertices of the convex hull of `points`, counterclockwise from the
// least point by (x, y), with no three collinear: one vertex for a single distinct point, the
// two ends for collinear points, none for none. Sorts `points` in place; coordinates must be
// finite. Allocates only when `out` grows.
inline void convex_hull(std::span<Point2> points, std::vector<Point2>& out) {
  auto less = [](const Point2& a, const Point2& b) {
    return a[0] < b[0] || (a[0] == b[0] && a[1] < b[1]);
  };
  std::sort(points.begin(), points.end(), less);
  const auto end = std::unique(points.begin(), points.end());
  const std::size_t n = std::size_t(end - points.begin());
  if (n <= 2) {
    out.insert(out.end(), points.begin(), end);
    return;
  }
  const std::size_t base = out.size();
  // Lower chain left to right, then upper chain right to left; each keeps only left turns.
  auto turns_left = [&](const Point2& p) {
    return orientation(out[out.size() - 2], out.back(), p) == Orientation::counterclockwise;
  };
  for (std::size_t i = 0; i < n; ++i) {
    while (out.size() >= base + 2 && !turns_left(points[i]))
      out.pop_back();
    out.push_back(points[i]);
  }
  const std::size_t lower = out.size();
  for (std::size_t i = n - 1; i-- > 0;) {
    while (out.size() > lower && !turns_left(points[i]))
      out.pop_back();
    out.push_back(points[i]);
  }
  out.pop_back();  // the first point again
}

// The same, as a vector of its own.
inline std::vector<Point2> convex_hull(std::span<Point2> points) {
  std::vector<Point2> hull;
  convex_hull(points, hull);
  return hull;
}

// The polygon of a point set's extreme points in x, y, x + y and x - y (Akl and Toussaint):
// each extreme is one of the points, so the polygon lies in their hull and a point strictly
// inside it is no vertex of the hull. Strictness is decided by the exact predicate.
class ExtremesPolygon {
 public:
  explicit ExtremesPolygon(std::span<const Point2> points) {
    if (points.empty()) return;
    // Extremes in the directions at 45-degree steps, counterclockwise from -y.
    Point2 e[8];
    std::fill(e, e + 8, points[0]);
    double k[8];
    keys(points[0], k);
    for (const Point2& p : points) {
      double q[8];
      keys(p, q);
      for (int d = 0; d < 8; ++d)
        if (q[d] > k[d]) k[d] = q[d], e[d] = p;
    }
    // The distinct extremes in order form a convex polygon (counterclockwise, possibly with
    // collinear vertices); fewer than three distinct ones bound no area.
    for (int d = 0; d < 8; ++d)
      if (m_ == 0 || !(e[d] == ring_[m_ - 1])) ring_[m_++] = e[d];
    while (m_ > 1 && ring_[m_ - 1] == ring_[0])
      --m_;
    ring_[m_] = ring_[0];
  }
  // Whether p lies strictly inside (never, when the extremes bound no area).
  bool strictly_inside(const Point2& p) const {
    if (m_ < 3) return false;
    for (int i = 0; i < m_; ++i)
      if (orientation(ring_[i], ring_[i + 1], p) != Orientation::counterclockwise) return false;
    return true;
  }
  // Whether the closed box lies strictly inside (its four corners do: the polygon is convex).
  bool strictly_inside(const Box<2>& b) const {
    return strictly_inside(b.min) && strictly_inside(b.max) &&
           strictly_inside(Point2{b.min[0], b.max[1]}) &&
           strictly_inside(Point2{b.max[0], b.min[1]});
  }

 private:
  static void keys(const Point2& p, double* k) {
    k[0] = -p[1];
    k[1] = p[0] - p[1];
    k[2] = p[0];
    k[3] = p[0] + p[1];
    k[4] = p[1];
    k[5] = p[1] - p[0];
    k[6] = -p[0];
    k[7] = -p[0] - p[1];
  }
  Point2 ring_[9];
  int m_ = 0;
};

// Appends to `out` the points of `points` that can be vertices of their convex hull: all but
// those strictly inside their ExtremesPolygon.
inline void hull_candidates(std::span<const Point2> points, std::vector<Point2>& out) {
  const ExtremesPolygon inner(points);
  for (const Point2& p : points)
    if (!inner.strictly_inside(p)) out.push_back(p);
}

// The vertex of `hull` (as convex_hull() gives it, at least one vertex) nearest to p, its
// squared distance, and whether it is certainly the point of the hull nearest to p: p - v
// lies in the cone of outward normals at v, which the two edges at v bound. Certain means the
// signs of both dot products are beyond their rounding error; a p on the normal through an
// edge's end, or inside the hull, is not certified. For a set whose hull this is and which
// holds its vertices (points, or segments between points), d2 bounds the set's squared
// distance from above, and is that distance when certified.
struct NearestVertex {
  std::size_t index = 0;
  double d2 = INFINITY;
  bool certified = false;
};

inline NearestVertex nearest_vertex(std::span<const Point2> hull, const Point2& p) {
  NearestVertex n;
  const std::size_t h = hull.size();
  double least = INFINITY;  // in a register, not through n
  std::size_t at = 0;
  for (std::size_t i = 0; i < h; ++i) {
    const double dx = p[0] - hull[i][0], dy = p[1] - hull[i][1];
    const double d2 = dx * dx + dy * dy;
    if (d2 < least) least = d2, at = i;
  }
  n.d2 = least;
  n.index = at;
  if (h <= 1) {
    n.certified = h == 1;
    return n;
  }
  const Point2& v = hull[n.index];
  const double px = p[0] - v[0], py = p[1] - v[1];
  // (p - v) . (w - v) < 0 for both neighbours w, beyond the error of the floating dot: each
  // difference is rounded once (relative error eps), each product and the sum once more, so
  // the computed value is within 4 eps of the sum of the products' magnitudes (3e-300 for
  // what underflow loses).
  auto away = [&](const Point2& w) {
    const double wx = w[0] - v[0], wy = w[1] - v[1];
    const double a = px * wx, b = py * wy;
    const double dot = a + b;
    return dot < -(8.9e-16 * (std::fabs(a) + std::fabs(b)) + 3e-300);
  };
  n.certified = away(hull[(n.index + h - 1) % h]) && away(hull[(n.index + 1) % h]);
  return n;
}

// Whether p lies strictly outside `hull` (as convex_hull() gives it), decided exactly: for a
// polygon, on the outer side of one of its edges; for two vertices, off the segment between
// them; for one, elsewhere. Always true for an empty hull.
inline bool strictly_outside(std::span<const Point2> hull, const Point2& p) {
  const std::size_t h = hull.size();
  if (h == 0) return true;
  if (h == 1) return !(p == hull[0]);
  if (h == 2) {
    const Point2 &a = hull[0], &b = hull[1];
    return orientation(a, b, p) != Orientation::collinear || p[0] < std::min(a[0], b[0]) ||
           p[0] > std::max(a[0], b[0]) || p[1] < std::min(a[1], b[1]) ||
           p[1] > std::max(a[1], b[1]);
  }
  for (std::size_t i = 0; i < h; ++i)
    if (orientation(hull[i], hull[i + 1 < h ? i + 1 : 0], p) == Orientation::clockwise) return true;
  return false;
}

// A lower bound on the squared distance from p to the hull: 0 when p lies in it (decided
// exactly), else the least squared distance to its edges rounded down by a bound on their
// rounding error. Infinity for an empty hull (no set to be near). Only the edges that p may
// lie outside of are measured: the hull's nearest point to an outside p lies on one of them
// (p is strictly outside an edge through it, and at a vertex, of one of the two edges there).
inline double hull_lower_bound(std::span<const Point2> hull, const Point2& p) {
  const std::size_t h = hull.size();
  if (h == 0) return INFINITY;
  double least = INFINITY, reach = 0;
  bool outside = h <= 2;
  for (std::size_t i = 0; i < (h <= 2 ? 1 : h); ++i) {
    const Point2& a = hull[i];
    const Point2& b = hull[i + 1 < h ? i + 1 : 0];
    if (h >= 3) {
      // The floating orientation with its error bound (predicates.hpp): clearly inside this
      // edge's line skips it.
      const double left = (b[0] - a[0]) * (p[1] - a[1]);
      const double right = (b[1] - a[1]) * (p[0] - a[0]);
      const double det = left - right;
      const double bound = 3.3306690738754716e-16 * (std::fabs(left) + std::fabs(right));
      if (det > bound) continue;
      outside = outside || -det > bound || orientation(a, b, p) == Orientation::clockwise;
    }
    least = std::min(least, squared_distance(p, Segment2{a, b}));
    reach = std::max(reach, std::fabs(a[0]) + std::fabs(a[1]) + std::fabs(b[0]) + std::fabs(b[1]));
  }
  if (!outside) return 0.0;
  // Each measured edge's distance is within detail::distance_rounding of the truth.
  const double e =
      std::sqrt(least) - (1e-14 * (std::fabs(p[0]) + std::fabs(p[1]) + reach) + 1e-150);
  return e > 0 ? e * e * (1 - 1e-15) : 0.0;
}

}  // namespace loci
