// Narrow phase: exact overlap tests and contact intervals for pairs of convex shapes.
//
// A broad phase (index/broadphase/) reports the pairs whose boxes meet. The narrow phase decides
// which of those pairs really touch, and when two moving shapes first meet. The shapes are
// circles (spheres in 3D), axis-aligned boxes and, in 2D, convex polygons, gathered in the
// variant Shape<D>. std::visit dispatches a pair of shapes to its test: this is the collision
// dispatcher table of a physics engine (Bullet's, for one), written as overloads:
//
//                circle / sphere    box                polygon
//     circle     sphere-sphere      sphere-box         circle-polygon
//     box        (symmetric)        box-box            polygon-polygon (the box as a polygon)
//     polygon    (symmetric)        (symmetric)        polygon-polygon
//
// Overlap is closed: touching counts, as everywhere in loci.
// - polygon-polygon and box-polygon use the separating-axis theorem, decided with the exact
//   orientation predicate of predicates.hpp. Two convex polygons are disjoint exactly when
//   every vertex of one lies strictly outside some edge of the other (the candidate axes are
//   the edge normals). A point or a segment (a polygon of 1 or 2 vertices) has the two sides
//   of its line as edges. When every vertex of both lies on one line, no edge normal can
//   separate them, and their bounding boxes (compared first) decide. Nothing is rounded: the
//   answer is the answer for the real numbers.
// - box-box compares coordinates (box.hpp), exactly.
// - circles and spheres compare squared distances in double (to the other centre, to the box,
//   to the polygon's edges) with the squared radius. This is exact up to a few ulps of
//   |d|^2 - r^2, so a pair that is exactly tangent may go either way.
//
// Contact interval. Shapes given at time 0 with velocities va and vb are at x + v t at time t.
// The times in [t0, t1] when they meet form one closed interval, because the relative motion
// is a line and the Minkowski difference of two convex shapes is convex. The result is the
// ContactInterval of swept.hpp; its `enter` is the time of impact.
// - sphere-sphere and box-box: sphere_contact and box_contact of swept.hpp.
// - polygon-polygon and box-polygon: the separating-axis theorem over time. A translation
//   leaves the edge normals unchanged, so the pair is apart at time t exactly when it is apart
//   along one of them. On each axis the two projections overlap over an interval of t (two
//   linear inequalities, the ones box_contact solves on the coordinate axes). The contact
//   interval is the intersection of those intervals. This is exact for translating convex
//   polygons: their Minkowski difference is a convex polygon whose edge normals are among
//   these axes. A point or a segment against a point or a segment also gets the coordinate
//   axes, since their difference may be a segment or a point (whose bounding box, on its
//   line, is itself).
// - circle-polygon: the centre, moving relative to the polygon, meets the polygon grown by the
//   radius. That grown shape is the union of the polygon, a rectangle of height r on the outer
//   side of each edge (the edge offset by r), and a disc of radius r at each vertex. Each part
//   is convex, and its interval comes from clipping against half-planes or from
//   sphere_contact. Their union is convex, so the contact is [earliest entry, latest exit].
// - sphere-box: the squared distance from the moving centre to the box is a convex,
//   piecewise-quadratic function of t. Its pieces are separated by the times when the centre
//   crosses the plane of a face (at most 2 D of them). On each piece it is the squared distance
//   to a point in the subspace of the axes where the centre is outside the box, which
//   sphere_contact solves.
//   Times carry the rounding of a few operations: a relative error of a few ulps away from
//   grazing contact, where the roots are ill-conditioned by nature (tests/broadphase/
//   test_narrow_phase.cpp holds them to 1e-9 time units against a bisected simulation).
//
// Input. Sphere and ConvexPolygon check their arguments when made; a ConvexPolygon may be given
// clockwise or counter-clockwise, and repeated consecutive vertices (a closing vertex equal to
// the first) and collinear ones are dropped. Box arguments are checked at every call of the
// functions below (box-box overlap included when it comes through Shape; box.hpp's own
// intersects(Box, Box) checks nothing). A bad shape throws InvalidGeometry: NaN, infinite or
// beyond 1e150 (kMaxCoordinate, so that squares stay finite), a negative radius, a polygon
// with no vertex, not convex or winding more than once. Velocities and times throw
// InvalidArgument for the same faults, or when t0 > t1.
//
// Cost: every test allocates nothing. Polygon tests take O(n m) orientation tests for n and m
// vertices (fine for the small polygons of a simulation), and contact intervals take O(n + m)
// projections per axis. A ConvexPolygon owns its vertices (one allocation, when it is made).
// All functions are pure, and shapes are immutable values, so any thread may test any pair.
#pragma once

#include <algorithm>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <initializer_list>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "loci/geom/box.hpp"
#include "loci/geom/error.hpp"
#include "loci/geom/motion.hpp"
#include "loci/geom/point.hpp"
#include "loci/geom/predicates.hpp"
#include "loci/geom/segment.hpp"
#include "loci/geom/swept.hpp"

namespace loci {

namespace detail {

// Throws InvalidGeometry naming `what` for a NaN, infinite or too large coordinate.
template <int D>
void check_shape_point(const Point<D>& p, const char* what) {
  check_point(p, what);
  if (!within_coordinate_range(p))
    throw InvalidGeometry(std::string(what) + " has a coordinate beyond 1e150: " + to_string(p));
}

template <int D>
void check_shape_box(const Box<D>& b) {
  check_box(b, "box");
  if (!within_coordinate_range(b.min) || !within_coordinate_range(b.max))
    throw InvalidGeometry("box has a coordinate beyond 1e150: " + to_string(b));
}

// Velocities and the time window of a contact query.
template <int D>
void check_contact_arguments(const Point<D>& va, const Point<D>& vb, double t0, double t1) {
  for (const Point<D>* v : {&va, &vb})
    if (!is_finite(*v) || !within_coordinate_range(*v))
      throw InvalidArgument("velocity is NaN, infinite or beyond 1e150: " + to_string(*v));
  if (!(std::fabs(t0) <= kMaxCoordinate && std::fabs(t1) <= kMaxCoordinate))
    throw InvalidArgument("contact time window is NaN, infinite or beyond 1e150");
  if (t0 > t1)
    throw InvalidArgument("contact time window is inverted: t0 = " + std::to_string(t0) +
                          " > t1 = " + std::to_string(t1));
}

template <int D>
Point<D> minus(const Point<D>& a, const Point<D>& b) {
  Point<D> d{};
  for (int k = 0; k < D; ++k)
    d[k] = a[k] - b[k];
  return d;
}

inline double dot(const Point<2>& a, const Point<2>& b) {
  return a[0] * b[0] + a[1] * b[1];
}

// Lexicographic order: the order along any line, for points on it.
inline bool lex_less(const Point<2>& a, const Point<2>& b) {
  return a[0] < b[0] || (a[0] == b[0] && a[1] < b[1]);
}

// The right-hand normal of the direction e: the outward normal of an edge of a
// counter-clockwise polygon (not normalized).
inline Point<2> outward(const Point<2>& e) {
  return {e[1], -e[0]};
}

}  // namespace detail

// A closed ball: a circle in 2D, a sphere in 3D. A radius of 0 is a point.
template <int D>
class Sphere {
 public:
  static constexpr int dimension = D;

  Sphere() = default;
  // Throws InvalidGeometry for a NaN, infinite or too large centre or radius, or a negative
  // radius.
  Sphere(const Point<D>& center, double radius) : center_(center), radius_(radius) {
    detail::check_shape_point(center, kWhat);
    if (!(radius >= 0 && radius <= kMaxCoordinate))
      throw InvalidGeometry(std::string(kWhat) + " radius must be in [0, 1e150], not " +
                            std::to_string(radius));
  }

  const Point<D>& center() const { return center_; }
  double radius() const { return radius_; }
  Box<D> box() const {
    Box<D> b{center_, center_};
    for (int k = 0; k < D; ++k) {
      b.min[k] -= radius_;
      b.max[k] += radius_;
    }
    return b;
  }

  friend bool operator==(const Sphere&, const Sphere&) = default;

 private:
  static constexpr const char* kWhat = D == 2 ? "circle" : "sphere";

  Point<D> center_{};
  double radius_ = 0;
};

using Circle = Sphere<2>;
using Sphere3 = Sphere<3>;

// A closed convex polygon in 2D, its vertices kept counter-clockwise, with no two equal and no
// three consecutive ones collinear. One vertex is a point; two are a segment.
class ConvexPolygon {
 public:
  // The vertices in order, clockwise or counter-clockwise. Repeats of a vertex next to itself
  // (a closing vertex equal to the first included) and vertices on the straight line between
  // their neighbours are dropped; vertices all on one line make the segment between the two
  // extreme ones. Throws InvalidGeometry for no vertex, a NaN, infinite or too large coordinate,
  // a turn in the wrong direction, a spike that doubles back, or a boundary that winds around
  // more than once (a pentagram).
  explicit ConvexPolygon(std::span<const Point2> vertices) {
    if (vertices.empty()) throw InvalidGeometry("convex polygon has no vertex");
    for (std::size_t i = 0; i < vertices.size(); ++i) {
      const std::string what = "convex polygon vertex " + std::to_string(i);
      detail::check_shape_point(vertices[i], what.c_str());
    }
    for (const Point2& p : vertices)
      if (v_.empty() || !(p == v_.back())) v_.push_back(p);
    while (v_.size() > 1 && v_.front() == v_.back())
      v_.pop_back();
    if (v_.size() >= 3) normalize();
    box_ = Box2::empty();
    for (const Point2& p : v_)
      box_.expand(p);
  }
  ConvexPolygon(std::initializer_list<Point2> vertices)
      : ConvexPolygon(std::span<const Point2>(vertices.begin(), vertices.size())) {}

  // Counter-clockwise, as described above.
  std::span<const Point2> vertices() const { return v_; }
  std::size_t size() const { return v_.size(); }
  const Box2& box() const { return box_; }

  friend bool operator==(const ConvexPolygon& a, const ConvexPolygon& b) { return a.v_ == b.v_; }

 private:
  // For three or more distinct vertices: makes them counter-clockwise and strictly convex, or
  // throws.
  void normalize() {
    const std::size_t n = v_.size();
    int turn = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const int o = sign(orientation(v_[(i + n - 1) % n], v_[i], v_[(i + 1) % n]));
      if (o == 0) continue;
      if (turn != 0 && o != turn)
        throw InvalidGeometry("convex polygon is not convex: it turns both ways (at vertex " +
                              std::to_string(i) + " " + to_string(v_[i]) + ")");
      turn = o;
    }
    if (turn == 0) {  // all on one line: the segment between the extremes
      const auto [lo, hi] = std::minmax_element(v_.begin(), v_.end(), detail::lex_less);
      v_ = {*lo, *hi};
      return;
    }
    if (turn < 0) std::reverse(v_.begin(), v_.end());
    std::vector<Point2> kept;
    kept.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
      const Point2& prev = v_[(i + n - 1) % n];
      const Point2& next = v_[(i + 1) % n];
      if (orientation(prev, v_[i], next) != Orientation::collinear) {
        kept.push_back(v_[i]);
      } else if (!same_direction(detail::minus(v_[i], prev), detail::minus(next, v_[i]))) {
        throw InvalidGeometry("convex polygon is not convex: its boundary doubles back at " +
                              to_string(v_[i]));
      }
    }
    v_.swap(kept);
    // Every turn is now strictly left and less than a half turn, so the edge directions go
    // round monotonically; they cross the direction +x once per time round.
    std::size_t rounds = 0;
    const std::size_t m = v_.size();
    for (std::size_t i = 0; i < m; ++i) {
      const Point2 e = detail::minus(v_[(i + 1) % m], v_[i]);
      const Point2 f = detail::minus(v_[(i + 2) % m], v_[(i + 1) % m]);
      rounds += !upper(e) && upper(f);
    }
    if (rounds != 1)
      throw InvalidGeometry("convex polygon is not simple: its boundary winds " +
                            std::to_string(rounds) + " times around");
  }

  // Direction angle in [0, pi). Exact: the sign of a difference of doubles is exact.
  static bool upper(const Point2& e) { return e[1] > 0 || (e[1] == 0 && e[0] > 0); }
  // For parallel nonzero vectors.
  static bool same_direction(const Point2& a, const Point2& b) {
    return (a[0] > 0) == (b[0] > 0) && (a[0] < 0) == (b[0] < 0) && (a[1] > 0) == (b[1] > 0) &&
           (a[1] < 0) == (b[1] < 0);
  }

  std::vector<Point2> v_;
  Box2 box_ = Box2::empty();
};

// The shapes of the narrow phase: one alternative per row of the table above.
template <int D>
struct ShapeTypes;
template <>
struct ShapeTypes<2> {
  using type = std::variant<Circle, Box2, ConvexPolygon>;
};
template <>
struct ShapeTypes<3> {
  using type = std::variant<Sphere3, Box3>;
};
template <int D>
using Shape = typename ShapeTypes<D>::type;
using Shape2 = Shape<2>;
using Shape3 = Shape<3>;

namespace detail {

// A box's corners as a convex polygon (counter-clockwise, no repeats): 4 corners, or 2 for a
// box of no width or no height, or 1 for a point.
struct BoxCorners {
  Point2 v[4];
  std::size_t n = 0;
  explicit BoxCorners(const Box2& b) {
    const bool wide = b.min[0] < b.max[0], tall = b.min[1] < b.max[1];
    v[n++] = b.min;
    if (wide) v[n++] = {b.max[0], b.min[1]};
    if (wide && tall) v[n++] = b.max;
    if (tall) v[n++] = {b.min[0], b.max[1]};
  }
  std::span<const Point2> span() const { return {v, n}; }
};

// Whether every vertex of q lies strictly outside (to the right of) one edge of p; p is
// counter-clockwise, and a segment's two directions are both its edges.
inline bool outside_an_edge(std::span<const Point2> p, std::span<const Point2> q) {
  const std::size_t n = p.size();
  if (n < 2) return false;
  for (std::size_t i = 0; i < n; ++i) {
    const Point2& a = p[i];
    const Point2& b = p[i + 1 == n ? 0 : i + 1];
    bool out = true;
    for (const Point2& x : q)
      if (orientation(a, b, x) != Orientation::clockwise) {
        out = false;
        break;
      }
    if (out) return true;
  }
  return false;
}

// Exact overlap of two convex polygons (counter-clockwise, 1, 2 or more vertices) whose
// bounding boxes meet.
inline bool polygons_intersect(std::span<const Point2> p, std::span<const Point2> q) {
  if (outside_an_edge(p, q) || outside_an_edge(q, p)) return false;
  // Not apart along an edge normal. That settles it unless all the vertices lie on one line
  // (two points or segments), where being apart along the line is being apart on a coordinate
  // axis, which the bounding boxes have ruled out.
  return true;
}

// Closed overlap of the circle (c, r) with a convex polygon.
inline bool circle_polygon_intersect(const Point2& c, double r, std::span<const Point2> p) {
  const std::size_t n = p.size();
  if (n >= 3 && !outside_an_edge(p, std::span<const Point2>(&c, 1))) return true;
  const double rr = r * r;
  if (n == 1) return squared_distance(c, p[0]) <= rr;
  const std::size_t edges = n == 2 ? 1 : n;
  for (std::size_t i = 0; i < edges; ++i)
    if (squared_distance(c, Segment<2>{p[i], p[(i + 1) % n]}) <= rr) return true;
  return false;
}

inline ContactInterval to_contact(const LinearSpan& s) {
  return s.empty() ? ContactInterval::none() : ContactInterval{s.lo, s.hi};
}

// Keeps in `span` the times when the projections on the axis `n` overlap: p moves with
// velocity w relative to q.
inline void clip_axis(const Point2& n, std::span<const Point2> p, std::span<const Point2> q,
                      const Point2& w, LinearSpan& span) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  double pmin = inf, pmax = -inf, qmin = inf, qmax = -inf;
  for (const Point2& x : p) {
    const double d = dot(n, x);
    pmin = std::min(pmin, d);
    pmax = std::max(pmax, d);
  }
  for (const Point2& x : q) {
    const double d = dot(n, x);
    qmin = std::min(qmin, d);
    qmax = std::max(qmax, d);
  }
  const double s = dot(n, w);
  span.keep(pmin - qmax, s, 0);   // pmin + s t <= qmax
  span.keep(qmin - pmax, -s, 0);  // qmin <= pmax + s t
}

// The edge normals of `axes` (a segment has one) as axes for clip_axis.
inline void clip_edges(std::span<const Point2> axes, std::span<const Point2> p,
                       std::span<const Point2> q, const Point2& w, LinearSpan& span) {
  const std::size_t n = axes.size();
  const std::size_t edges = n < 2 ? 0 : n == 2 ? 1 : n;
  for (std::size_t i = 0; i < edges && !span.empty(); ++i)
    clip_axis(outward(minus(axes[(i + 1) % n], axes[i])), p, q, w, span);
}

// The separating-axis theorem over time: times in [t0, t1] when p, moving with velocity w
// relative to q, meets q.
inline ContactInterval polygons_contact(std::span<const Point2> p, std::span<const Point2> q,
                                        const Point2& w, double t0, double t1) {
  LinearSpan span{t0, t1};
  clip_edges(p, p, q, w, span);
  clip_edges(q, p, q, w, span);
  if (p.size() <= 2 && q.size() <= 2) {
    // The difference may be a segment or a point. On its line, its bounding box is it: the
    // coordinate axes complete the set.
    clip_axis({1, 0}, p, q, w, span);
    clip_axis({0, 1}, p, q, w, span);
  }
  return to_contact(span);
}

// Times in [t0, t1] when the circle of radius r, centred at c at time 0 and moving with
// velocity w relative to the polygon p, meets p: the centre against p grown by r.
inline ContactInterval circle_polygon_contact(const Point2& c, double r, std::span<const Point2> p,
                                              const Point2& w, double t0, double t1) {
  double enter = std::numeric_limits<double>::infinity(), exit = -enter;
  auto take = [&](const ContactInterval& in) {
    if (in.empty()) return;
    enter = std::min(enter, in.enter);
    exit = std::max(exit, in.exit);
  };
  const std::size_t n = p.size();
  if (n >= 3) {  // the polygon itself: inside every edge's half-plane
    LinearSpan in{t0, t1};
    for (std::size_t i = 0; i < n && !in.empty(); ++i) {
      const Point2 normal = outward(minus(p[(i + 1) % n], p[i]));
      in.keep(dot(minus(c, p[i]), normal), dot(w, normal), 0);
    }
    take(to_contact(in));
  }
  if (n >= 2) {  // the rectangle on the outer side of each edge (both sides of a segment)
    const std::size_t edges = n == 2 ? 2 : n;
    for (std::size_t i = 0; i < edges; ++i) {
      const Point2& a = p[i];
      const Point2 e = minus(p[(i + 1) % n], a);
      const Point2 normal = outward(e);
      const Point2 ca = minus(c, a);
      const double len2 = dot(e, e);
      // Height above the edge's line and position along the edge, both scaled by |e|.
      const double h = dot(ca, normal), hv = dot(w, normal);
      const double g = dot(ca, e), gv = dot(w, e);
      LinearSpan s{t0, t1};
      s.keep(-h, -hv, 0);                      // h + hv t >= 0
      s.keep(h - r * std::sqrt(len2), hv, 0);  // h + hv t <= r |e|
      s.keep(-g, -gv, 0);                      // g + gv t >= 0
      s.keep(g - len2, gv, 0);                 // g + gv t <= |e|^2
      take(to_contact(s));
    }
  }
  const Point2 still{0, 0};
  for (const Point2& v : p)  // the disc at each vertex
    take(sphere_contact(c, r, w, v, 0.0, still, t0, t1));
  if (!(enter <= exit)) return ContactInterval::none();
  return {enter, exit};
}

// Times in [t0, t1] when the sphere of radius r, centred at c at time 0 and moving with
// velocity w relative to the box b, meets b.
template <int D>
ContactInterval sphere_box_contact(const Point<D>& c, double r, const Box<D>& b, const Point<D>& w,
                                   double t0, double t1) {
  // Pieces of [t0, t1] between the times the centre crosses a face plane.
  double cut[2 * D + 2];
  int m = 0;
  cut[m++] = t0;
  for (int k = 0; k < D; ++k) {
    if (w[k] == 0) continue;
    for (const double bound : {b.min[k], b.max[k]}) {
      const double t = (bound - c[k]) / w[k];
      if (t > t0 && t < t1) cut[m++] = t;
    }
  }
  cut[m++] = t1;
  std::sort(cut, cut + m);
  const Point<D> origin{};
  // On a piece, the centre is outside the box on a fixed set of axes. On one axis, the
  // distance is linear in t (solved as such, since the quadratic's double root would cost half
  // the digits); on more, it is the distance of the point d + v t to the origin, d and v
  // keeping those axes.
  auto piece = [&](int i) {
    const double lo = cut[i], hi = cut[i + 1], mid = 0.5 * lo + 0.5 * hi;
    Point<D> d{}, v{};
    int outside = 0, axis = 0;
    for (int k = 0; k < D; ++k) {
      const double x = c[k] + w[k] * mid;
      if (x < b.min[k] || x > b.max[k]) {
        d[k] = c[k] - (x < b.min[k] ? b.min[k] : b.max[k]);
        v[k] = w[k];
        ++outside, axis = k;
      }
    }
    if (outside >= 2) return sphere_contact(d, r, v, origin, 0.0, origin, lo, hi);
    LinearSpan span{lo, hi};
    if (outside == 1) {
      span.keep(d[axis] - r, v[axis], 0);    // d + v t <= r
      span.keep(-d[axis] - r, -v[axis], 0);  // -r <= d + v t
    }
    return to_contact(span);
  };
  // The distance is convex in t: the pieces in contact are consecutive.
  for (int i = 0; i + 1 < m; ++i) {
    const ContactInterval first = piece(i);
    if (first.empty()) continue;
    for (int j = m - 2; j > i; --j) {
      const ContactInterval last = piece(j);
      if (!last.empty()) return {first.enter, last.exit};
    }
    return first;
  }
  return ContactInterval::none();
}

}  // namespace detail

// ---- Overlap -----------------------------------------------------------------------------

template <int D>
bool intersects(const Sphere<D>& a, const Sphere<D>& b) {
  const double r = a.radius() + b.radius();
  return squared_distance(a.center(), b.center()) <= r * r;
}

// Throws InvalidGeometry for a bad box.
template <int D>
bool intersects(const Sphere<D>& s, const Box<D>& b) {
  detail::check_shape_box(b);
  return squared_distance(s.center(), b) <= s.radius() * s.radius();
}
template <int D>
bool intersects(const Box<D>& b, const Sphere<D>& s) {
  return intersects(s, b);
}

inline bool intersects(const Circle& c, const ConvexPolygon& p) {
  return detail::circle_polygon_intersect(c.center(), c.radius(), p.vertices());
}
inline bool intersects(const ConvexPolygon& p, const Circle& c) {
  return intersects(c, p);
}

inline bool intersects(const ConvexPolygon& p, const ConvexPolygon& q) {
  return intersects(p.box(), q.box()) && detail::polygons_intersect(p.vertices(), q.vertices());
}

// Throws InvalidGeometry for a bad box.
inline bool intersects(const Box2& b, const ConvexPolygon& p) {
  detail::check_shape_box(b);
  return intersects(b, p.box()) &&
         detail::polygons_intersect(detail::BoxCorners(b).span(), p.vertices());
}
inline bool intersects(const ConvexPolygon& p, const Box2& b) {
  return intersects(b, p);
}

// Any pair of shapes, dispatched on both alternatives. Throws InvalidGeometry for a bad box.
inline bool intersects(const Shape2& a, const Shape2& b);
inline bool intersects(const Shape3& a, const Shape3& b);

namespace detail {
// One cell of the dispatch table: the overload for the pair, with boxes checked.
template <class X, class Y>
bool intersects_cell(const X& x, const Y& y) {
  return intersects(x, y);
}
template <int D>
bool intersects_cell(const Box<D>& x, const Box<D>& y) {
  check_shape_box(x);
  check_shape_box(y);
  return intersects(x, y);
}
template <class Variant>
bool shapes_intersect(const Variant& a, const Variant& b) {
  return std::visit([](const auto& x, const auto& y) { return intersects_cell(x, y); }, a, b);
}
}  // namespace detail

inline bool intersects(const Shape2& a, const Shape2& b) {
  return detail::shapes_intersect(a, b);
}
inline bool intersects(const Shape3& a, const Shape3& b) {
  return detail::shapes_intersect(a, b);
}

// ---- Contact intervals and time of impact --------------------------------------------------
//
// contact_interval(a, va, b, vb, t0, t1): the times in [t0, t1] when a, at x + va t, meets b,
// at x + vb t (both given at time 0); empty when they never meet. Throws InvalidArgument for a
// bad velocity or window, InvalidGeometry for a bad box.

template <int D>
ContactInterval contact_interval(const Sphere<D>& a, const Point<D>& va, const Sphere<D>& b,
                                 const Point<D>& vb, double t0, double t1) {
  detail::check_contact_arguments(va, vb, t0, t1);
  return sphere_contact(a.center(), a.radius(), va, b.center(), b.radius(), vb, t0, t1);
}

template <int D>
ContactInterval contact_interval(const Box<D>& a, const Point<D>& va, const Box<D>& b,
                                 const Point<D>& vb, double t0, double t1) {
  detail::check_contact_arguments(va, vb, t0, t1);
  detail::check_shape_box(a);
  detail::check_shape_box(b);
  return box_contact(a, va, b, vb, t0, t1);
}

template <int D>
ContactInterval contact_interval(const Sphere<D>& s, const Point<D>& vs, const Box<D>& b,
                                 const Point<D>& vb, double t0, double t1) {
  detail::check_contact_arguments(vs, vb, t0, t1);
  detail::check_shape_box(b);
  return detail::sphere_box_contact(s.center(), s.radius(), b, detail::minus(vs, vb), t0, t1);
}
template <int D>
ContactInterval contact_interval(const Box<D>& b, const Point<D>& vb, const Sphere<D>& s,
                                 const Point<D>& vs, double t0, double t1) {
  return contact_interval(s, vs, b, vb, t0, t1);
}

inline ContactInterval contact_interval(const Circle& c, const Point2& vc, const ConvexPolygon& p,
                                        const Point2& vp, double t0, double t1) {
  detail::check_contact_arguments(vc, vp, t0, t1);
  return detail::circle_polygon_contact(c.center(), c.radius(), p.vertices(), detail::minus(vc, vp),
                                        t0, t1);
}
inline ContactInterval contact_interval(const ConvexPolygon& p, const Point2& vp, const Circle& c,
                                        const Point2& vc, double t0, double t1) {
  return contact_interval(c, vc, p, vp, t0, t1);
}

inline ContactInterval contact_interval(const ConvexPolygon& p, const Point2& vp,
                                        const ConvexPolygon& q, const Point2& vq, double t0,
                                        double t1) {
  detail::check_contact_arguments(vp, vq, t0, t1);
  return detail::polygons_contact(p.vertices(), q.vertices(), detail::minus(vp, vq), t0, t1);
}

inline ContactInterval contact_interval(const Box2& b, const Point2& vb, const ConvexPolygon& p,
                                        const Point2& vp, double t0, double t1) {
  detail::check_contact_arguments(vb, vp, t0, t1);
  detail::check_shape_box(b);
  return detail::polygons_contact(detail::BoxCorners(b).span(), p.vertices(), detail::minus(vb, vp),
                                  t0, t1);
}
inline ContactInterval contact_interval(const ConvexPolygon& p, const Point2& vp, const Box2& b,
                                        const Point2& vb, double t0, double t1) {
  return contact_interval(b, vb, p, vp, t0, t1);
}

// Any pair of shapes, dispatched on both alternatives.
inline ContactInterval contact_interval(const Shape2& a, const Point2& va, const Shape2& b,
                                        const Point2& vb, double t0, double t1) {
  return std::visit(
      [&](const auto& x, const auto& y) { return contact_interval(x, va, y, vb, t0, t1); }, a, b);
}
inline ContactInterval contact_interval(const Shape3& a, const Point3& va, const Shape3& b,
                                        const Point3& vb, double t0, double t1) {
  return std::visit(
      [&](const auto& x, const auto& y) { return contact_interval(x, va, y, vb, t0, t1); }, a, b);
}

// The first time in [t0, t1] when a (velocity va) and b (velocity vb) meet: t0 when they
// already touch then, nullopt when they never meet. Throws as contact_interval does.
template <class A, class B, int D>
requires requires(const A& a, const B& b, const Point<D>& v) {
  { contact_interval(a, v, b, v, 0.0, 0.0) } -> std::same_as<ContactInterval>;
}
std::optional<double> time_of_impact(const A& a, const Point<D>& va, const B& b, const Point<D>& vb,
                                     double t0, double t1) {
  const ContactInterval c = contact_interval(a, va, b, vb, t0, t1);
  if (c.empty()) return std::nullopt;
  return c.enter;
}

}  // namespace loci
