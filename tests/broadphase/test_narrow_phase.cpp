// The narrow phase against independent references, with fixed seeds.
//
// Overlap: polygons (boxes among them, as their corners) against exact segment intersection and
// point-in-polygon by orientations; circles and spheres against squared distances in GMP
// rationals. Polygons with small integer coordinates make exact touches and collinear edges
// common, where the answers must agree exactly. Circle answers may differ from the rational
// ones only within 1e-12 of tangency.
//
// Contact intervals: against a simulation that samples the pair every 0.02 time units over
// [0, 10] and bisects the first and last sampled contact to 1e-13. The computed entry must
// lie within kTol = 1e-9 of the bisected one, and never later than it by more than kTol
// (1e-7 for scenes moved 1e6 away, where a position carries an ulp of 1.2e-10); so must the
// exit. A contact that the samples miss must be shorter than a step. Shapes have sizes 0 to 2
// and relative speeds up to 4, so 1e-9 is about 1e6 times the rounding of the formulas.
#include <gtest/gtest.h>

#include <gmpxx.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "loci/geom/narrow_phase.hpp"
#include "loci/geom/segment.hpp"

namespace loci {
namespace {

using Poly = std::vector<Point2>;
constexpr double kTol = 1e-9;

// ---- References --------------------------------------------------------------------------

// A 2D shape as the references see it: a circle, or a convex polygon as a plain vertex list in
// either orientation (a box as its four corners, repeated when the box is flat).
struct Ref2 {
  bool circle = false;
  Point2 c{};
  double r = 0;
  Poly v;
};

Ref2 moved(const Ref2& s, const Point2& vel, double t) {
  Ref2 m = s;
  m.c = {s.c[0] + vel[0] * t, s.c[1] + vel[1] * t};
  for (Point2& p : m.v)
    p = {p[0] + vel[0] * t, p[1] + vel[1] * t};
  return m;
}

// Inside or on the boundary of a convex polygon of 3 or more vertices, either orientation.
bool ref_inside(const Poly& p, const Point2& x) {
  bool left = false, right = false;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Orientation o = orientation(p[i], p[(i + 1) % p.size()], x);
    left |= o == Orientation::counterclockwise;
    right |= o == Orientation::clockwise;
  }
  return !(left && right);
}

// A box's corners, each once: 4, or 2 for a flat box, or 1 for a point.
Poly box_corners(const Box2& b) {
  Poly c{b.min, {b.max[0], b.min[1]}, b.max, {b.min[0], b.max[1]}};
  c.erase(std::unique(c.begin(), c.end()), c.end());
  while (c.size() > 1 && c.front() == c.back())
    c.pop_back();
  return c;
}

std::vector<Segment2> ref_edges(const Poly& p) {
  if (p.size() == 1) return {{p[0], p[0]}};
  std::vector<Segment2> e;
  for (std::size_t i = 0; i < p.size(); ++i)
    e.push_back({p[i], p[(i + 1) % p.size()]});
  return e;
}

bool ref_polygons_meet(const Poly& p, const Poly& q) {
  for (const Segment2& e : ref_edges(p))
    for (const Segment2& f : ref_edges(q))
      if (intersects(e, f)) return true;
  return (p.size() >= 3 && ref_inside(p, q[0])) || (q.size() >= 3 && ref_inside(q, p[0]));
}

// Squared distance from c to the segment ab, in T (GMP rationals: exact; long double: fast).
template <class T>
T ref_segment_distance2(const Point2& c, const Point2& a, const Point2& b) {
  const T ex = T(b[0]) - T(a[0]), ey = T(b[1]) - T(a[1]);
  const T cx = T(c[0]) - T(a[0]), cy = T(c[1]) - T(a[1]);
  const T len2 = ex * ex + ey * ey;
  T t = 0;
  if (len2 > 0) {
    t = (cx * ex + cy * ey) / len2;
    if (t < 0) t = 0;
    if (t > 1) t = 1;
  }
  const T dx = cx - t * ex, dy = cy - t * ey;
  return dx * dx + dy * dy;
}

// Squared distance from the circle's centre to the other shape minus the squared reach (the
// sum of radii): <= 0 when they meet.
template <class T>
T ref_circle_margin(const Ref2& circ, const Ref2& o) {
  const T rr = o.circle ? T(circ.r) + T(o.r) : T(circ.r);
  if (o.circle) {
    const T dx = T(circ.c[0]) - T(o.c[0]), dy = T(circ.c[1]) - T(o.c[1]);
    return dx * dx + dy * dy - rr * rr;
  }
  if (o.v.size() >= 3 && ref_inside(o.v, circ.c)) return -rr * rr - 1;
  T best = ref_segment_distance2<T>(circ.c, o.v[0], o.v[0]);
  for (const Segment2& e : ref_edges(o.v)) {
    const T d = ref_segment_distance2<T>(circ.c, e.a, e.b);
    if (d < best) best = d;
  }
  return best - rr * rr;
}

template <class T>
bool ref_meet(const Ref2& a, const Ref2& b) {
  if (a.circle) return ref_circle_margin<T>(a, b) <= 0;
  if (b.circle) return ref_circle_margin<T>(b, a) <= 0;
  return ref_polygons_meet(a.v, b.v);
}

std::string describe(const Poly& p) {
  std::string s;
  for (const Point2& x : p)
    s += to_string(x) + " ";
  return s;
}

// ---- Random shapes -----------------------------------------------------------------------

class Gen {
 public:
  explicit Gen(std::uint64_t seed) : rng_(seed) {}
  double u(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng_); }
  int i(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }

  // Vertices of a convex polygon: 1 to 7 points on a circle, in either orientation.
  Poly polygon_vertices(const Point2& c) {
    for (;;) {
      const int n = i(1, 7);
      const double radius = u(0.2, 2);
      std::vector<double> angle(n);
      for (double& a : angle)
        a = u(0, 2 * M_PI);
      std::sort(angle.begin(), angle.end());
      Poly p;
      for (double a : angle)
        p.push_back({c[0] + radius * std::cos(a), c[1] + radius * std::sin(a)});
      if (i(0, 1)) std::reverse(p.begin(), p.end());
      try {
        (void)ConvexPolygon(p);  // rounding may leave a nearly straight vertex reflex
        return p;
      } catch (const InvalidGeometry&) {
      }
    }
  }

  // A random shape near c of the given kind (0 circle, 1 box, 2 polygon), with its reference.
  std::pair<Shape2, Ref2> shape(int kind, const Point2& c) {
    Ref2 ref;
    if (kind == 0) {
      ref.circle = true;
      ref.c = c;
      ref.r = i(0, 9) == 0 ? 0.0 : u(0.1, 2);
      return {Circle(c, ref.r), ref};
    }
    if (kind == 1) {
      const double hx = i(0, 7) == 0 ? 0.0 : u(0.1, 1.5), hy = i(0, 7) == 0 ? 0.0 : u(0.1, 1.5);
      const Box2 b{{c[0] - hx, c[1] - hy}, {c[0] + hx, c[1] + hy}};
      ref.v = box_corners(b);
      return {b, ref};
    }
    ref.v = polygon_vertices(c);
    return {ConvexPolygon(ref.v), ref};
  }

  // The convex hull of 1 to 6 random points of the integer grid [x, x + 4] x [y, y + 4]:
  // exact, with shared edges, collinear edges and touching vertices between two of them.
  Poly grid_polygon(int x, int y) {
    std::vector<Point2> pts;
    const int n = i(1, 6);
    for (int k = 0; k < n; ++k)
      pts.push_back({double(x + i(0, 4)), double(y + i(0, 4))});
    std::sort(pts.begin(), pts.end(), [](const Point2& a, const Point2& b) {
      return a[0] < b[0] || (a[0] == b[0] && a[1] < b[1]);
    });
    pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
    if (pts.size() < 3) return pts;
    Poly hull;  // monotone chain, collinear points dropped
    for (int pass = 0; pass < 2; ++pass) {
      const std::size_t start = hull.size();
      for (const Point2& p : pts) {
        while (hull.size() >= start + 2 &&
               orientation(hull[hull.size() - 2], hull.back(), p) != Orientation::counterclockwise)
          hull.pop_back();
        hull.push_back(p);
      }
      hull.pop_back();
      std::reverse(pts.begin(), pts.end());
    }
    if (hull.size() < 3) {  // all collinear: the two ends
      return {pts.back(), pts.front()};
    }
    if (i(0, 1)) std::reverse(hull.begin(), hull.end());
    return hull;
  }

 private:
  std::mt19937_64 rng_;
};

const char* kind_name(int k) {
  return k == 0 ? "circle" : k == 1 ? "box" : "polygon";
}

// ---- ConvexPolygon input -----------------------------------------------------------------

double signed_area(std::span<const Point2> p) {
  double a = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Point2& s = p[i];
    const Point2& t = p[(i + 1) % p.size()];
    a += s[0] * t[1] - t[0] * s[1];
  }
  return a / 2;
}

TEST(NarrowPhaseInput, ConvexPolygonNormalizesOrientationRepeatsAndStraightVertices) {
  const ConvexPolygon ccw{{0, 0}, {2, 0}, {2, 2}, {0, 2}};
  const ConvexPolygon cw{{0, 2}, {2, 2}, {2, 0}, {0, 0}};
  EXPECT_EQ(ccw.size(), 4u);
  EXPECT_GT(signed_area(ccw.vertices()), 0);
  EXPECT_GT(signed_area(cw.vertices()), 0);
  EXPECT_DOUBLE_EQ(signed_area(cw.vertices()), 4);
  // A closing vertex, a repeated vertex and a vertex in the middle of an edge are dropped.
  const ConvexPolygon messy{{0, 0}, {1, 0}, {2, 0}, {2, 0}, {2, 2}, {0, 2}, {0, 0}};
  EXPECT_EQ(messy.size(), 4u);
  EXPECT_DOUBLE_EQ(signed_area(messy.vertices()), 4);
  EXPECT_EQ(messy.box(), (Box2{{0, 0}, {2, 2}}));
  // Degenerate polygons: a point, a segment, collinear points making their extreme segment.
  EXPECT_EQ(ConvexPolygon({{3, 4}}).size(), 1u);
  EXPECT_EQ(ConvexPolygon({{3, 4}, {3, 4}, {3, 4}}).size(), 1u);
  EXPECT_EQ(ConvexPolygon({{0, 0}, {5, 5}}).size(), 2u);
  const ConvexPolygon line{{1, 1}, {3, 3}, {0, 0}, {2, 2}};
  ASSERT_EQ(line.size(), 2u);
  EXPECT_EQ(line.box(), (Box2{{0, 0}, {3, 3}}));
}

TEST(NarrowPhaseInput, ConvexPolygonRefusesBadInput) {
  EXPECT_THROW(ConvexPolygon(std::span<const Point2>()), InvalidGeometry);
  const double nan = std::nan(""), inf = std::numeric_limits<double>::infinity();
  EXPECT_THROW(ConvexPolygon({{0, 0}, {nan, 1}, {1, 1}}), InvalidGeometry);
  EXPECT_THROW(ConvexPolygon({{0, 0}, {1, inf}}), InvalidGeometry);
  EXPECT_THROW(ConvexPolygon({{0, 0}, {1e200, 1}, {0, 1}}), InvalidGeometry);
  // A reflex vertex (an arrowhead), a bow tie, a pentagram, a spike that doubles back.
  EXPECT_THROW(ConvexPolygon({{0, 0}, {2, 1}, {4, 0}, {2, 4}}), InvalidGeometry);
  EXPECT_THROW(ConvexPolygon({{0, 0}, {2, 2}, {2, 0}, {0, 2}}), InvalidGeometry);
  Poly star;
  for (int k = 0; k < 5; ++k)
    star.push_back({std::cos(4 * M_PI * k / 5), std::sin(4 * M_PI * k / 5)});
  EXPECT_THROW((ConvexPolygon(star)), InvalidGeometry);
  EXPECT_THROW(ConvexPolygon({{0, 0}, {4, 0}, {6, 0}, {4, 0}, {2, 3}}), InvalidGeometry);
  EXPECT_THROW(ConvexPolygon({{0, 0}, {4, 0}, {4, 4}, {0, 4}, {0, 0}, {4, 0}, {4, 4}, {0, 4}}),
               InvalidGeometry);
}

TEST(NarrowPhaseInput, RefusesBadArguments) {
  const double nan = std::nan(""), inf = std::numeric_limits<double>::infinity();
  EXPECT_THROW(Circle({0, 0}, -1), InvalidGeometry);
  EXPECT_THROW(Circle({0, 0}, nan), InvalidGeometry);
  EXPECT_THROW(Circle({nan, 0}, 1), InvalidGeometry);
  EXPECT_THROW(Sphere3({0, inf, 0}, 1), InvalidGeometry);
  const Circle c({0, 0}, 1);
  const ConvexPolygon p{{0, 0}, {1, 0}, {0, 1}};
  const Box2 inverted{{1, 1}, {0, 0}}, nan_box{{0, 0}, {nan, 1}};
  EXPECT_THROW(intersects(c, inverted), InvalidGeometry);
  EXPECT_THROW(intersects(nan_box, p), InvalidGeometry);
  EXPECT_THROW(intersects(Shape2(nan_box), Shape2(Box2{{0, 0}, {1, 1}})), InvalidGeometry);
  const Point2 zero{0, 0};
  EXPECT_THROW(contact_interval(c, Point2{nan, 0}, p, zero, 0, 1), InvalidArgument);
  EXPECT_THROW(contact_interval(p, zero, p, Point2{0, inf}, 0, 1), InvalidArgument);
  EXPECT_THROW(contact_interval(p, zero, p, zero, 1, 0), InvalidArgument);
  EXPECT_THROW(contact_interval(c, zero, c, zero, nan, 1), InvalidArgument);
  EXPECT_THROW(time_of_impact(Shape2(c), zero, Shape2(p), zero, 0, inf), InvalidArgument);
  EXPECT_THROW(contact_interval(inverted, zero, p, zero, 0, 1), InvalidGeometry);
  EXPECT_THROW(contact_interval(Box3{{0, 0, 0}, {nan, 1, 1}}, Point3{}, Sphere3({0, 0, 0}, 1),
                                Point3{}, 0, 1),
               InvalidGeometry);
}

// ---- Overlap -----------------------------------------------------------------------------

TEST(NarrowPhaseOverlap, TouchingCounts) {
  const ConvexPolygon sq{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  // Edge to edge, vertex to vertex, vertex on an edge; then a hair apart.
  EXPECT_TRUE(intersects(sq, ConvexPolygon{{1, 0}, {2, 0}, {2, 1}, {1, 1}}));
  EXPECT_TRUE(intersects(sq, ConvexPolygon{{1, 1}, {2, 1}, {2, 2}}));
  EXPECT_TRUE(intersects(sq, ConvexPolygon{{1, 0.5}, {2, 0}, {2, 1}}));
  const double gap = std::nextafter(1.0, 2.0);
  EXPECT_FALSE(intersects(sq, ConvexPolygon{{gap, 0}, {2, 0}, {2, 1}, {gap, 1}}));
  EXPECT_FALSE(intersects(sq, ConvexPolygon{{gap, 1}, {2, 1}, {2, 2}}));
  // A diagonal edge touched exactly by a vertex, and missed by one ulp.
  const ConvexPolygon tri{{0, 0}, {4, 0}, {0, 4}};
  EXPECT_TRUE(intersects(tri, ConvexPolygon{{2, 2}, {3, 3}, {2, 4}}));
  EXPECT_FALSE(intersects(tri, ConvexPolygon{{2, std::nextafter(2.0, 3.0)}, {3, 3}, {2, 4}}));
  // Identical shapes, a shape inside another.
  EXPECT_TRUE(intersects(tri, tri));
  EXPECT_TRUE(intersects(tri, ConvexPolygon{{1, 1}, {1.5, 1}, {1, 1.5}}));
  // Circles touching a box face, a box corner, a polygon edge, another circle.
  EXPECT_TRUE(intersects(Circle({3, 0.5}, 2), Box2{{0, 0}, {1, 1}}));
  EXPECT_FALSE(intersects(Circle({3, 0.5}, std::nextafter(2.0, 0.0)), Box2{{0, 0}, {1, 1}}));
  EXPECT_TRUE(intersects(Circle({4, 5}, 5), Box2{{0, 0}, {1, 1}}));  // 3-4-5 to the corner
  EXPECT_TRUE(intersects(Circle({0.5, -1}, 1), sq));
  EXPECT_TRUE(intersects(Circle({0, 0}, 1), Circle({2, 0}, 1)));
  EXPECT_FALSE(intersects(Circle({0, 0}, 1), Circle({std::nextafter(2.0, 3.0), 0}, 1)));
  EXPECT_TRUE(intersects(Sphere3({0, 0, 0}, 1), Box3{{1, -5, -5}, {2, 5, 5}}));
}

TEST(NarrowPhaseOverlap, DegenerateShapes) {
  const ConvexPolygon sq{{0, 0}, {2, 0}, {2, 2}, {0, 2}};
  const ConvexPolygon point{{1, 1}}, corner{{2, 2}}, outside{{3, 1}};
  EXPECT_TRUE(intersects(sq, point));
  EXPECT_TRUE(intersects(corner, sq));
  EXPECT_FALSE(intersects(sq, outside));
  EXPECT_TRUE(intersects(point, point));
  EXPECT_FALSE(intersects(point, corner));
  // Segments: crossing, touching at an end, collinear overlapping, collinear apart, parallel.
  const ConvexPolygon s1{{0, 0}, {4, 4}};
  EXPECT_TRUE(intersects(s1, ConvexPolygon{{0, 4}, {4, 0}}));
  EXPECT_TRUE(intersects(s1, ConvexPolygon{{4, 4}, {6, 0}}));
  EXPECT_TRUE(intersects(s1, ConvexPolygon{{3, 3}, {8, 8}}));
  EXPECT_FALSE(intersects(s1, ConvexPolygon{{5, 5}, {8, 8}}));
  EXPECT_FALSE(intersects(ConvexPolygon{{5, 5}, {8, 8}}, s1));
  EXPECT_FALSE(intersects(ConvexPolygon{{-2, -2}, {-1, -1}}, s1));
  EXPECT_FALSE(intersects(s1, ConvexPolygon{{-1, -1}}));
  EXPECT_FALSE(intersects(ConvexPolygon{{-1, -1}}, s1));
  EXPECT_TRUE(intersects(s1, ConvexPolygon{{4, 4}, {8, 8}}));
  EXPECT_FALSE(intersects(s1, ConvexPolygon{{0, 1}, {4, 5}}));
  EXPECT_TRUE(intersects(s1, ConvexPolygon{{2, 2}}));
  EXPECT_FALSE(intersects(s1, ConvexPolygon{{5, 5}}));
  EXPECT_FALSE(intersects(s1, ConvexPolygon{{2, 2.5}}));
  // A segment through a square without a vertex inside it.
  EXPECT_TRUE(intersects(sq, ConvexPolygon{{-1, 1}, {3, 1}}));
  EXPECT_FALSE(intersects(sq, ConvexPolygon{{-1, 4}, {4, 2.5}}));
  // Zero-size boxes are points and segments.
  EXPECT_TRUE(intersects(Box2{{2, 1}, {2, 1}}, sq));
  EXPECT_FALSE(intersects(Box2{{3, 1}, {3, 1}}, sq));
  EXPECT_TRUE(intersects(Box2{{1, -3}, {1, 5}}, sq));
  EXPECT_TRUE(intersects(Box2{{2, 2}, {3, 2}}, s1));
  EXPECT_TRUE(intersects(Circle({5, 5}, 0), Box2{{5, 5}, {5, 5}}));
  EXPECT_TRUE(intersects(Circle({1, 1}, 0), sq));
  EXPECT_TRUE(intersects(Circle({3, 0}, 1), sq));
  EXPECT_FALSE(intersects(Circle({3, 3}, 1), sq));  // beyond the rounded corner
  EXPECT_TRUE(intersects(Circle({3, 3}, 1.5), sq));
}

// Every ordered pair of kinds against the references: the exact one for polygons, GMP for
// circles, allowing circles to differ within 1e-12 of tangency.
TEST(NarrowPhaseOverlap, RandomAgainstReferences) {
  Gen g(20240611);
  int agree = 0, met = 0, missed = 0, near_tangent = 0;
  for (int trial = 0; trial < 6000; ++trial) {
    const int ka = trial % 3, kb = (trial / 3) % 3;
    const double spread = 2.5;
    auto [a, ra] = g.shape(ka, {g.u(-spread, spread), g.u(-spread, spread)});
    auto [b, rb] = g.shape(kb, {g.u(-spread, spread), g.u(-spread, spread)});
    const bool got = intersects(a, b);
    EXPECT_EQ(got, intersects(b, a)) << trial;
    bool want;
    if (ra.circle || rb.circle) {
      const mpq_class m =
          ra.circle ? ref_circle_margin<mpq_class>(ra, rb) : ref_circle_margin<mpq_class>(rb, ra);
      want = m <= 0;
      if (got != want && std::fabs(m.get_d()) < 1e-12) {
        ++near_tangent;
        continue;
      }
    } else {
      want = ref_polygons_meet(ra.v, rb.v);
    }
    EXPECT_EQ(got, want) << trial << " " << kind_name(ka) << " vs " << kind_name(kb);
    agree += got == want;
    (want ? met : missed)++;
  }
  EXPECT_GT(met, 1200);
  EXPECT_GT(missed, 1200);
  EXPECT_EQ(agree + near_tangent, 6000);  // every other answer agreed
  EXPECT_LT(near_tangent, 5);
}

// Integer polygons on a small grid: exact touches, shared and collinear edges, points and
// segments. Polygons and boxes must agree with the reference exactly.
TEST(NarrowPhaseOverlap, ExactTouchesOnAGrid) {
  Gen g(77);
  int met = 0, missed = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const Poly p = g.grid_polygon(0, 0);
    const Poly q = g.grid_polygon(g.i(-4, 4), g.i(-4, 4));
    const bool want = ref_polygons_meet(p, q);
    EXPECT_EQ(intersects(ConvexPolygon(p), ConvexPolygon(q)), want) << trial;
    EXPECT_EQ(intersects(ConvexPolygon(q), ConvexPolygon(p)), want) << trial;
    (want ? met : missed)++;
    // A box with integer corners against the polygon.
    const double x0 = g.i(-2, 5), y0 = g.i(-2, 5);
    const Box2 box{{x0, y0}, {x0 + g.i(0, 2), y0 + g.i(0, 2)}};
    const Poly corners = box_corners(box);
    EXPECT_EQ(intersects(box, ConvexPolygon(p)), ref_polygons_meet(corners, p))
        << trial << " " << to_string(box) << " vs " << describe(p);
    // A circle centred on the grid with an integer radius: squared distances are exact.
    const Circle c({double(g.i(-2, 6)), double(g.i(-2, 6))}, double(g.i(0, 2)));
    Ref2 rc;
    rc.circle = true, rc.c = c.center(), rc.r = c.radius();
    Ref2 rp;
    rp.v = p;
    EXPECT_EQ(intersects(c, ConvexPolygon(p)), ref_circle_margin<mpq_class>(rc, rp) <= 0) << trial;
  }
  EXPECT_GT(met, 800);
  EXPECT_GT(missed, 800);
}

TEST(NarrowPhaseOverlap, Random3D) {
  Gen g(31);
  int met = 0, missed = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    Point3 ca, cb;
    for (int k = 0; k < 3; ++k)
      ca[k] = g.u(-2, 2), cb[k] = g.u(-2, 2);
    const Sphere3 s(ca, g.u(0, 2));
    Box3 b;
    for (int k = 0; k < 3; ++k) {
      const double h = g.i(0, 5) == 0 ? 0.0 : g.u(0.1, 1.5);
      b.min[k] = cb[k] - h, b.max[k] = cb[k] + h;
    }
    // Exact squared distance from the centre to the box.
    mpq_class d2 = 0;
    for (int k = 0; k < 3; ++k) {
      mpq_class d = 0;
      if (ca[k] < b.min[k]) d = mpq_class(b.min[k]) - ca[k];
      if (ca[k] > b.max[k]) d = mpq_class(ca[k]) - b.max[k];
      d2 += d * d;
    }
    const mpq_class r = s.radius();
    const bool want = d2 <= r * r;
    EXPECT_EQ(intersects(s, b), want) << trial;
    EXPECT_EQ(intersects(Shape3(b), Shape3(s)), want) << trial;
    (want ? met : missed)++;
    const Sphere3 t(cb, g.u(0, 2));
    mpq_class dd = 0;
    for (int k = 0; k < 3; ++k) {
      const mpq_class d = mpq_class(ca[k]) - cb[k];
      dd += d * d;
    }
    const mpq_class reach = mpq_class(s.radius()) + t.radius();
    EXPECT_EQ(intersects(Shape3(s), Shape3(t)), dd <= reach * reach) << trial;
  }
  EXPECT_GT(met, 800);
  EXPECT_GT(missed, 800);
}

// ---- Contact intervals -------------------------------------------------------------------

// Where a bisected simulation places the first and last contact in [t0, t1].
struct Simulated {
  bool hit = false;
  double enter_lo = 0, enter_hi = 0, exit_lo = 0, exit_hi = 0;
};

template <class Meet>
Simulated simulate(Meet&& meet, double t0, double t1, double dt) {
  const int steps = int(std::ceil((t1 - t0) / dt));
  auto at = [&](int i) { return i >= steps ? t1 : t0 + i * dt; };
  int first = -1, last = -1;
  for (int i = 0; i <= steps; ++i)
    if (meet(at(i))) {
      if (first < 0) first = i;
      last = i;
    }
  Simulated s;
  if (first < 0) return s;
  s.hit = true;
  auto bisect = [&](double off, double on, double& lo, double& hi) {
    for (int k = 0; k < 200 && std::fabs(on - off) > 1e-13; ++k) {
      const double mid = 0.5 * (off + on);
      (meet(mid) ? on : off) = mid;
    }
    lo = std::min(off, on), hi = std::max(off, on);
  };
  if (first == 0)
    s.enter_lo = s.enter_hi = t0;
  else
    bisect(at(first - 1), at(first), s.enter_lo, s.enter_hi);
  if (last == steps)
    s.exit_lo = s.exit_hi = t1;
  else
    bisect(at(last + 1), at(last), s.exit_lo, s.exit_hi);
  return s;
}

// Checks a computed interval against the simulation; returns whether they met.
bool check_against(const ContactInterval& got, const Simulated& sim, double dt, double tol,
                   const std::string& what) {
  if (sim.hit) {
    EXPECT_FALSE(got.empty()) << what;
    if (got.empty()) return true;
    EXPECT_LE(got.enter, sim.enter_hi + tol) << what << " entry later than the first contact";
    EXPECT_GE(got.enter, sim.enter_lo - tol) << what;
    EXPECT_LE(got.exit, sim.exit_hi + tol) << what;
    EXPECT_GE(got.exit, sim.exit_lo - tol) << what;
    return true;
  }
  if (!got.empty()) EXPECT_LE(got.exit - got.enter, dt) << what << " contact missed by sampling";
  return false;
}

// Every ordered pair of kinds, moving, against the simulation (positions sampled in double,
// decided by the references: exact for polygons, long double for circles).
void random_contacts(std::uint64_t seed, double offset, double tol) {
  Gen g(seed);
  const double t0 = 0, t1 = 10, dt = 0.02;
  int hits = 0, misses = 0, at_start = 0;
  for (int trial = 0; trial < 540; ++trial) {
    const int ka = trial % 3, kb = (trial / 3) % 3;
    const Point2 ca{g.u(-8, 8), g.u(-8, 8)}, cb{g.u(-8, 8), g.u(-8, 8)};
    auto [a, ra] = g.shape(ka, {offset + ca[0], offset + ca[1]});
    auto [b, rb] = g.shape(kb, {offset + cb[0], offset + cb[1]});
    // Headed roughly for each other, so that about half the pairs meet.
    Point2 va{g.u(-1, 1), g.u(-1, 1)}, vb{g.u(-1, 1), g.u(-1, 1)};
    for (int k = 0; k < 2; ++k)
      va[k] += (cb[k] - ca[k]) / 8;
    if (trial % 17 == 0) vb = va;                 // parallel motion
    if (trial % 19 == 0) va = vb = Point2{0, 0};  // no motion
    if (trial % 23 == 0) va[1] = vb[1] = 0;       // along one axis
    const ContactInterval got = contact_interval(a, va, b, vb, t0, t1);
    const Simulated sim = simulate(
        [&, &ref_a = ra, &ref_b = rb](double t) {
          return ref_meet<long double>(moved(ref_a, va, t), moved(ref_b, vb, t));
        },
        t0, t1, dt);
    const std::string what = "trial " + std::to_string(trial) + " " + kind_name(ka) + " vs " +
                             kind_name(kb) + " offset " + std::to_string(offset);
    (check_against(got, sim, dt, tol, what) ? hits : misses)++;
    at_start += sim.hit && sim.enter_hi == t0;
    // The same pair the other way round.
    const ContactInterval rev = contact_interval(b, vb, a, va, t0, t1);
    EXPECT_EQ(rev.empty(), got.empty()) << what;
    if (!rev.empty() && !got.empty()) {
      EXPECT_NEAR(rev.enter, got.enter, tol) << what;
      EXPECT_NEAR(rev.exit, got.exit, tol) << what;
    }
    const auto toi = time_of_impact(a, va, b, vb, t0, t1);
    EXPECT_EQ(toi.has_value(), !got.empty()) << what;
    if (toi) EXPECT_EQ(*toi, got.enter) << what;
  }
  EXPECT_GT(hits, 100);
  EXPECT_GT(misses, 100);
  EXPECT_GT(at_start, 5);
}

TEST(NarrowPhaseContact, RandomAgainstSimulation) {
  random_contacts(5, 0, kTol);
}

TEST(NarrowPhaseContact, LargeCoordinates) {
  random_contacts(6, 1e6, 1e-7);
}

TEST(NarrowPhaseContact, Random3DAgainstSimulation) {
  Gen g(8);
  const double t0 = 0, t1 = 10, dt = 0.02;
  int hits = 0, misses = 0;
  for (int trial = 0; trial < 400; ++trial) {
    Point3 ca, cb, va, vb, h;
    for (int k = 0; k < 3; ++k) {
      ca[k] = g.u(-8, 8), cb[k] = g.u(-8, 8), va[k] = g.u(-0.3, 0.3), vb[k] = g.u(-0.3, 0.3);
      h[k] = trial % 7 == 0 ? 0.0 : g.u(0.1, 1.5);
    }
    for (int k = 0; k < 3; ++k)
      va[k] += (cb[k] - ca[k]) / 8;
    if (trial % 13 == 0) va = vb;
    const Sphere3 s(ca, g.u(0, 2)), s2(cb, g.u(0, 2));
    const Box3 b{{cb[0] - h[0], cb[1] - h[1], cb[2] - h[2]},
                 {cb[0] + h[0], cb[1] + h[1], cb[2] + h[2]}};
    auto sphere_box_meet = [&](double t) {
      long double d2 = 0;
      for (int k = 0; k < 3; ++k) {
        const long double x = ca[k] + va[k] * t;
        const long double lo = b.min[k] + vb[k] * t, hi = b.max[k] + vb[k] * t;
        const long double d = x < lo ? lo - x : x > hi ? x - hi : 0;
        d2 += d * d;
      }
      return d2 <= (long double)s.radius() * s.radius();
    };
    const std::string what = "3D trial " + std::to_string(trial);
    const ContactInterval got = contact_interval(Shape3(s), va, Shape3(b), vb, t0, t1);
    (check_against(got, simulate(sphere_box_meet, t0, t1, dt), dt, kTol, what) ? hits : misses)++;
    const ContactInterval rev = contact_interval(b, vb, s, va, t0, t1);
    EXPECT_EQ(rev, got) << what;
    auto spheres_meet = [&](double t) {
      long double d2 = 0;
      for (int k = 0; k < 3; ++k) {
        const long double d = (ca[k] + va[k] * t) - (cb[k] + vb[k] * t);
        d2 += d * d;
      }
      const long double r = (long double)s.radius() + s2.radius();
      return d2 <= r * r;
    };
    check_against(contact_interval(Shape3(s), va, Shape3(s2), vb, t0, t1),
                  simulate(spheres_meet, t0, t1, dt), dt, kTol, what + " spheres");
  }
  EXPECT_GT(hits, 60);
  EXPECT_GT(misses, 60);
}

// The circle-box contact (piecewise quadratic) against the circle-polygon one (the grown
// polygon) on the box's corners, and boxes against their polygons: two methods each.
TEST(NarrowPhaseContact, MethodsAgree) {
  Gen g(12);
  int hits = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const Point2 c{g.u(-6, 6), g.u(-6, 6)}, bc{g.u(-6, 6), g.u(-6, 6)};
    const Circle circle(c, trial % 10 == 0 ? 0.0 : g.u(0.1, 2));
    const double hx = trial % 11 == 0 ? 0.0 : g.u(0.1, 2), hy = trial % 13 == 0 ? 0.0 : g.u(0.1, 2);
    const Box2 box{{bc[0] - hx, bc[1] - hy}, {bc[0] + hx, bc[1] + hy}};
    const ConvexPolygon as_polygon{
        box.min, {box.max[0], box.min[1]}, box.max, {box.min[0], box.max[1]}};
    const Point2 va{g.u(-2, 2), g.u(-2, 2)}, vb{g.u(-2, 2), g.u(-2, 2)};
    const ContactInterval piecewise = contact_interval(circle, va, box, vb, 0, 10);
    const ContactInterval grown = contact_interval(circle, va, as_polygon, vb, 0, 10);
    ASSERT_EQ(piecewise.empty(), grown.empty()) << trial;
    if (!grown.empty()) {
      ++hits;
      EXPECT_NEAR(piecewise.enter, grown.enter, kTol) << trial;
      EXPECT_NEAR(piecewise.exit, grown.exit, kTol) << trial;
    }
    const ConvexPolygon other(g.polygon_vertices({g.u(-6, 6), g.u(-6, 6)}));
    const ContactInterval via_box = contact_interval(box, vb, other, va, 0, 10);
    const ContactInterval via_polygon = contact_interval(as_polygon, vb, other, va, 0, 10);
    ASSERT_EQ(via_box.empty(), via_polygon.empty()) << trial;
    if (!via_box.empty()) {
      EXPECT_NEAR(via_box.enter, via_polygon.enter, kTol) << trial;
      EXPECT_NEAR(via_box.exit, via_polygon.exit, kTol) << trial;
    }
    const Box2 box2{{c[0] - 1, c[1] - 0.5}, {c[0] + 0.5, c[1] + 1}};
    const ContactInterval slab = contact_interval(Shape2(box2), va, Shape2(box), vb, 0, 10);
    const ContactInterval sat = contact_interval(
        ConvexPolygon{box2.min, {box2.max[0], box2.min[1]}, box2.max, {box2.min[0], box2.max[1]}},
        va, as_polygon, vb, 0, 10);
    ASSERT_EQ(slab.empty(), sat.empty()) << trial;
    if (!slab.empty()) {
      EXPECT_NEAR(slab.enter, sat.enter, kTol) << trial;
      EXPECT_NEAR(slab.exit, sat.exit, kTol) << trial;
    }
  }
  EXPECT_GT(hits, 300);
}

TEST(NarrowPhaseContact, HandCases) {
  const Point2 still{0, 0};
  const ConvexPolygon sq{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  const ConvexPolygon right{{3, 0}, {4, 0}, {4, 1}, {3, 1}};
  // Head-on: the gap of 2 closes at t = 2, the squares pass through each other by t = 4.
  EXPECT_EQ(contact_interval(sq, Point2{1, 0}, right, still, 0, 10), (ContactInterval{2, 4}));
  // Already touching at t0, identical shapes.
  EXPECT_EQ(time_of_impact(sq, Point2{-1, 0}, ConvexPolygon{{1, 0}, {2, 0}, {2, 1}, {1, 1}}, still,
                           0, 10),
            std::optional<double>(0.0));
  EXPECT_EQ(contact_interval(sq, Point2{3, 1}, sq, Point2{3, 1}, 2, 5), (ContactInterval{2, 5}));
  // Zero velocity: never, or the whole window.
  EXPECT_TRUE(contact_interval(sq, still, right, still, 0, 10).empty());
  EXPECT_EQ(contact_interval(Circle({0.5, 0.5}, 0.1), still, sq, still, 1, 3),
            (ContactInterval{1, 3}));
  // Parallel motion: sliding along a shared edge stays in contact; apart stays apart.
  EXPECT_EQ(contact_interval(sq, Point2{0, -1}, ConvexPolygon{{1, -5}, {2, -5}, {2, -4}, {1, -4}},
                             still, 0, 100),
            (ContactInterval{4, 6}));
  EXPECT_TRUE(contact_interval(sq, Point2{0, 1}, right, Point2{0, 1}, 0, 10).empty());
  // Grazing: a triangle's apex passes a square's corner, touching at t = 2 only.
  const ConvexPolygon tri{{-1, 3}, {0, 5}, {1, 4}};
  const ContactInterval graze = contact_interval(tri, Point2{1, -1}, sq, still, 0, 10);
  ASSERT_FALSE(graze.empty());
  EXPECT_DOUBLE_EQ(graze.enter, 2);
  EXPECT_DOUBLE_EQ(graze.exit, 2);
  // A circle grazing a polygon's vertex, and the edge of a square from above.
  const ContactInterval top = contact_interval(Circle({0.5, 5}, 1), Point2{0, -1}, sq, still, 0, 9);
  EXPECT_DOUBLE_EQ(top.enter, 3);
  EXPECT_DOUBLE_EQ(top.exit, 6);
  // Tangent to an edge all along it; then grazing a corner only (closest approach 5 at t = 2).
  EXPECT_EQ(contact_interval(Circle({-5, 2}, 1), Point2{1, 0}, sq, still, 0, 10),
            (ContactInterval{5, 6}));
  const ContactInterval vertex =
      contact_interval(Circle({-4, 11}, 5), Point2{4, -3}, sq, still, 0, 10);
  ASSERT_FALSE(vertex.empty());
  EXPECT_NEAR(vertex.enter, 2, 1e-7);
  EXPECT_NEAR(vertex.exit, 2, 1e-7);
  // Head for a corner: the first contact is on the corner's disc.
  const auto corner = time_of_impact(Circle({4, 4}, 1), Point2{-1, -1}, sq, still, 0, 10);
  ASSERT_TRUE(corner.has_value());
  EXPECT_NEAR(*corner, 3 - 1 / std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(
      *time_of_impact(Circle({4, 4}, 1), Point2{-1, -1}, Box2{{0, 0}, {1, 1}}, still, 0, 10),
      *corner, 1e-12);
  // Tunnelling: a small fast shape crosses a thin wall between two samples t = 0 and t = 1.
  const ConvexPolygon wall{{5, -10}, {5.01, -10}, {5.01, 10}, {5, 10}};
  const ContactInterval bullet =
      contact_interval(Circle({0, 0}, 0.05), Point2{10, 0}, wall, still, 0, 1);
  EXPECT_NEAR(bullet.enter, 0.495, 1e-12);
  EXPECT_NEAR(bullet.exit, 0.506, 1e-12);
  EXPECT_FALSE(intersects(Circle({0, 0}, 0.05), wall));
  EXPECT_FALSE(intersects(Circle({10, 0}, 0.05), wall));
}

TEST(NarrowPhaseContact, DegeneratePolygons) {
  const Point2 still{0, 0};
  const ConvexPolygon sq{{0, 0}, {2, 0}, {2, 2}, {0, 2}};
  // A point flying into a square, along an edge's line, past a corner.
  EXPECT_EQ(contact_interval(ConvexPolygon{{-3, 1}}, Point2{1, 0}, sq, still, 0, 10),
            (ContactInterval{3, 5}));
  EXPECT_EQ(contact_interval(ConvexPolygon{{-3, 2}}, Point2{1, 0}, sq, still, 0, 10),
            (ContactInterval{3, 5}));
  EXPECT_TRUE(contact_interval(ConvexPolygon{{-3, 3}}, Point2{1, 0}, sq, still, 0, 10).empty());
  // Two points: meet only when they coincide, and never when they pass side by side.
  EXPECT_EQ(
      contact_interval(ConvexPolygon{{0, 0}}, Point2{1, 1}, ConvexPolygon{{4, 4}}, still, 0, 10),
      (ContactInterval{4, 4}));
  EXPECT_TRUE(
      contact_interval(ConvexPolygon{{0, 0}}, Point2{1, 1}, ConvexPolygon{{4, 4.5}}, still, 0, 10)
          .empty());
  // A segment against a segment: crossing, collinear sliding, parallel.
  const ConvexPolygon vertical{{0, -1}, {0, 1}};
  EXPECT_EQ(contact_interval(ConvexPolygon{{-4, 0}, {-2, 0}}, Point2{1, 0}, vertical, still, 0, 10),
            (ContactInterval{2, 4}));
  EXPECT_EQ(contact_interval(ConvexPolygon{{0, -5}, {0, -3}}, Point2{0, 1}, vertical, still, 0, 10),
            (ContactInterval{2, 6}));
  EXPECT_TRUE(
      contact_interval(ConvexPolygon{{1, -5}, {1, -3}}, Point2{0, 1}, vertical, still, 0, 10)
          .empty());
  // A circle against a segment: the stadium around it.
  EXPECT_EQ(contact_interval(Circle({-5, 0}, 1), Point2{1, 0}, vertical, still, 0, 10),
            (ContactInterval{4, 6}));
  const ContactInterval cap =
      contact_interval(Circle({0, 5}, 1), Point2{0, -1}, vertical, still, 0, 10);
  EXPECT_DOUBLE_EQ(cap.enter, 3);
  EXPECT_DOUBLE_EQ(cap.exit, 7);
  // Zero-size boxes: a point box and a flat box.
  EXPECT_EQ(contact_interval(Box2{{-3, 1}, {-3, 1}}, Point2{1, 0}, sq, still, 0, 10),
            (ContactInterval{3, 5}));
  EXPECT_EQ(contact_interval(Box2{{-1, 5}, {1, 5}}, Point2{0, -1}, sq, still, 0, 10),
            (ContactInterval{3, 5}));
  EXPECT_EQ(contact_interval(Circle({0, 9}, 1), Point2{0, -1}, Box2{{0, 0}, {0, 0}}, still, 0, 10),
            (ContactInterval{8, 10}));
}

}  // namespace
}  // namespace loci
