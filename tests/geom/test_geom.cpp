// Geometry layer: closed-box semantics, exact orientation and box-segment tests against exact
// rational arithmetic, distances against Boost.Geometry, and the Boost registration itself.
#include <gmpxx.h>
#include <gtest/gtest.h>

#include <boost/geometry.hpp>
#include <cmath>
#include <limits>
#include <random>

#include "loci/geom/boost_adapt.hpp"
#include "loci/geom/geom.hpp"

namespace bg = boost::geometry;
using namespace loci;

namespace {

int exact_orientation(const Point2& a, const Point2& b, const Point2& c) {
  const mpq_class det = (mpq_class(b[0]) - a[0]) * (mpq_class(c[1]) - a[1]) -
                        (mpq_class(b[1]) - a[1]) * (mpq_class(c[0]) - a[0]);
  return sgn(det);
}

// Exact segment/box test by clipping the parameter interval with rationals.
template <int D>
bool exact_box_segment(const Box<D>& box, const Segment<D>& s) {
  mpq_class t0 = 0, t1 = 1;
  for (int a = 0; a < D; ++a) {
    const mpq_class p = s.a[a], d = mpq_class(s.b[a]) - s.a[a];
    const mpq_class lo = box.min[a], hi = box.max[a];
    if (d == 0) {
      if (p < lo || p > hi) return false;
      continue;
    }
    mpq_class ta = (lo - p) / d, tb = (hi - p) / d;
    if (ta > tb) std::swap(ta, tb);
    if (ta > t0) t0 = ta;
    if (tb < t1) t1 = tb;
    if (t0 > t1) return false;
  }
  return true;
}

}  // namespace

TEST(Box, ClosedSemantics) {
  const Box2 a{{0, 0}, {1, 1}};
  EXPECT_TRUE(intersects(a, Box2{{1, 1}, {2, 2}}));      // corner touch
  EXPECT_TRUE(intersects(a, Box2{{1, 0.5}, {2, 0.7}}));  // edge touch
  EXPECT_FALSE(intersects(a, Box2{{1.0000001, 0}, {2, 1}}));
  EXPECT_TRUE(intersects(a, Point2{1, 1}));
  EXPECT_TRUE(contains(a, a));
  EXPECT_TRUE(within(Box2{{0, 0}, {1, 0}}, a));
  EXPECT_FALSE(contains(a, Box2{{0, 0}, {1.5, 1}}));
  EXPECT_FALSE(intersects(Box2::empty(), a));
  EXPECT_TRUE(Box2::empty().is_empty());
  Box2 e = Box2::empty();
  e.expand(a);
  EXPECT_EQ(e, a);
  EXPECT_DOUBLE_EQ(overlap(a, Box2{{0.5, 0.5}, {2, 2}}), 0.25);
  EXPECT_DOUBLE_EQ(overlap(a, Box2{{1, 1}, {2, 2}}), 0.0);
}

TEST(Box, MagnitudeIsTheLargestCoordinateInAbsoluteValue) {
  EXPECT_EQ(magnitude(Box2{{-7, 2}, {3, 5}}), 7.0);
  EXPECT_EQ(magnitude(Box2{{1, -2}, {3, 9}}), 9.0);
  EXPECT_EQ(magnitude(Box3{{0, 0, -1e300}, {0, 0, 0}}), 1e300);
  EXPECT_EQ(magnitude(Box2{{0, 0}, {0, 0}}), 0.0);
  EXPECT_EQ(magnitude(Box2::empty()), std::numeric_limits<double>::infinity());
}

TEST(Box, RejectsBadCoordinates) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_THROW(check_box(Box2{{nan, 0}, {1, 1}}), InvalidGeometry);
  EXPECT_THROW(check_box(Box2{{0, 0}, {inf, 1}}), InvalidGeometry);
  EXPECT_THROW(check_box(Box2{{2, 0}, {1, 1}}), InvalidGeometry);
  EXPECT_NO_THROW(check_box(Box2{{1, 1}, {1, 1}}));
  try {
    check_box(Box3{{0, 5, 0}, {1, 1, 1}}, "box 17");
    FAIL();
  } catch (const InvalidGeometry& e) {
    EXPECT_NE(std::string(e.what()).find("box 17"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("axis 1"), std::string::npos);
  }
  // The message shows the coordinates as they are (six decimals showed 2e-9 > 1e-9 as
  // 0.000000 against 0.000000, and 1e100 in a hundred digits).
  try {
    check_box(Box2{{2e-9, 0}, {1e-9, 1e100}});
    FAIL();
  } catch (const InvalidGeometry& e) {
    EXPECT_NE(std::string(e.what()).find("(2e-09, 0) .. (1e-09, 1e+100)"), std::string::npos)
        << e.what();
  }
}

TEST(Orientation, ExactOnNearlyCollinearPoints) {
  // Points near the line y = x, perturbed by a few ulps: the naive determinant gets many of
  // these wrong; the filtered predicate must agree with exact arithmetic on all of them.
  const Point2 a{0.5, 0.5}, b{12, 12};
  int checked = 0;
  for (int i = 0; i < 64; ++i)
    for (int j = 0; j < 64; ++j) {
      const Point2 c{std::nextafter(24.0, 0.0) + i * std::ldexp(1.0, -48),
                     24.0 + j * std::ldexp(1.0, -48)};
      EXPECT_EQ(sign(orientation(a, b, c)), exact_orientation(a, b, c)) << i << "," << j;
      ++checked;
    }
  EXPECT_EQ(checked, 4096);
  EXPECT_EQ(orientation(Point2{0, 0}, Point2{1, 1}, Point2{2, 2}), Orientation::collinear);
  EXPECT_EQ(orientation(Point2{0, 0}, Point2{1, 0}, Point2{0, 1}), Orientation::counterclockwise);
  EXPECT_EQ(orientation(Point2{0, 0}, Point2{0, 1}, Point2{1, 0}), Orientation::clockwise);
}

TEST(Orientation, MatchesExactOnRandomInput) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1e3, 1e3);
  for (int i = 0; i < 20000; ++i) {
    const Point2 a{u(rng), u(rng)}, b{u(rng), u(rng)};
    // c on the line through a and b, rounded: the hard case.
    const double t = u(rng) / 100;
    const Point2 c{a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])};
    ASSERT_EQ(sign(orientation(a, b, c)), exact_orientation(a, b, c));
  }
}

TEST(Orientation, ExactAtEveryScale) {
  // Points on (or a few ulps off) a line at scales from 1e-300 to 1e300, where the floating
  // filter gives up and the exact path decides (by expansions, or the exact kernel for inputs
  // so small that products underflow or so large that they overflow).
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_int_distribution<int> ulps(-3, 3);
  int collinear = 0;
  for (const double scale : {1e-300, 1e-150, 1e-6, 1.0, 1e6, 1e140, 1e155, 1e300}) {
    for (int i = 0; i < 4000; ++i) {
      const double ox = u(rng) * 1e3 * scale, oy = u(rng) * 1e3 * scale;
      const Point2 a{ox + u(rng) * scale, oy + u(rng) * scale};
      const Point2 b{ox + u(rng) * scale, oy + u(rng) * scale};
      const double t = u(rng) * 4;
      Point2 c{a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])};
      for (int k = ulps(rng); k != 0; k += k > 0 ? -1 : 1)
        c[k & 1] = std::nextafter(c[k & 1], k > 0 ? 1e300 : -1e300);
      if (i % 7 == 0) c = i % 2 ? a : b;  // a repeated point
      const int want = exact_orientation(a, b, c);
      collinear += want == 0;
      ASSERT_EQ(sign(orientation(a, b, c)), want) << scale << " " << i;
      ASSERT_EQ(sign(orientation(c, a, b)), want) << scale << " " << i;
    }
  }
  EXPECT_GT(collinear, 1000);
  // Differences of coordinates that overflow a double.
  constexpr double kMax = std::numeric_limits<double>::max();
  const Point2 w{-kMax, 0}, e{kMax, 0}, n{0, kMax}, s{0, -kMax};
  EXPECT_EQ(orientation(w, e, n), Orientation::counterclockwise);
  EXPECT_EQ(orientation(w, e, s), Orientation::clockwise);
  EXPECT_EQ(orientation(w, e, Point2{kMax / 3, 0}), Orientation::collinear);
  EXPECT_EQ(orientation(s, n, e), Orientation::clockwise);
  EXPECT_EQ(orientation(e, w, Point2{0, 0x1p-1074}), Orientation::clockwise);
}

// The side of a line on which the crossing of a segment with another line lies, the crossing
// never computed: against rationals, with the line through the crossing rounded (the hard
// case), at every scale, and exactly on it where three lines of an integer grid meet.
TEST(Orientation, CrossingMatchesExact) {
  const auto exact = [](const Point2& a, const Point2& b, const Point2& c, const Point2& d,
                        const Point2& p, const Point2& q) {
    const auto det = [](const Point2& u, const Point2& w, const Point2& x) -> mpq_class {
      return (mpq_class(w[0]) - u[0]) * (mpq_class(x[1]) - u[1]) -
             (mpq_class(w[1]) - u[1]) * (mpq_class(x[0]) - u[0]);
    };
    const mpq_class oa = det(c, d, a), ob = det(c, d, b), pa = det(p, q, a), pb = det(p, q, b);
    const mpq_class num = oa * pb - ob * pa, den = oa - ob;
    return sgn(num) * sgn(den);
  };
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_int_distribution<int> ulps(-2, 2);
  int on = 0;
  // Made at unit scale and scaled by powers of two (exactly), down to where products
  // underflow.
  for (const int e : {-990, -20, 0, 20, 460}) {
    for (int i = 0; i < 3000; ++i) {
      Point2 a{u(rng), u(rng)}, b{u(rng), u(rng)}, c{u(rng), u(rng)}, d{u(rng), u(rng)};
      const int sa = sign(orientation(c, d, a)), sb = sign(orientation(c, d, b));
      if (sa * sb >= 0) continue;
      // p-q through the rounded crossing (or a few ulps off it).
      const double oa = (d[0] - c[0]) * (a[1] - c[1]) - (d[1] - c[1]) * (a[0] - c[0]);
      const double ob = (d[0] - c[0]) * (b[1] - c[1]) - (d[1] - c[1]) * (b[0] - c[0]);
      const double t = oa / (oa - ob);
      Point2 p{a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])}, q{u(rng), u(rng)};
      for (int k = ulps(rng); k != 0; k += k > 0 ? -1 : 1)
        p[k & 1] = std::nextafter(p[k & 1], k > 0 ? 1e300 : -1e300);
      for (Point2* v : {&a, &b, &c, &d, &p, &q})
        *v = Point2{std::ldexp((*v)[0], e), std::ldexp((*v)[1], e)};
      ASSERT_EQ(sign(crossing_orientation(a, b, c, d, p, q)), exact(a, b, c, d, p, q))
          << e << " " << i;
      ASSERT_EQ(sign(crossing_orientation(a, b, c, d, q, p)), exact(a, b, c, d, q, p))
          << e << " " << i;
    }
  }
  // Integer grid: a-b, c-d and p-q often meet at one point.
  std::uniform_int_distribution<int> g(0, 6);
  for (int i = 0; i < 20000; ++i) {
    const auto pt = [&] { return Point2{double(g(rng)), double(g(rng))}; };
    const Point2 a = pt(), b = pt(), c = pt(), d = pt(), p = pt(), q = pt();
    if (sign(orientation(c, d, a)) * sign(orientation(c, d, b)) >= 0) continue;
    const int want = exact(a, b, c, d, p, q);
    on += want == 0;
    ASSERT_EQ(sign(crossing_orientation(a, b, c, d, p, q)), want) << i;
  }
  EXPECT_GT(on, 100);
}

TEST(Segment, TestsOnPointAtMatchExact) {
  // compare_coordinate_at and orientation_at on s.a + t (s.b - s.a) against rationals; on a
  // small grid, where the segment often runs along the line a-b or has an end on it, or has
  // both ends at v (each decided without rationals), and on random doubles with a-b through
  // the rounded point.
  const auto at = [](const Segment2& s, double t, int axis) -> mpq_class {
    return mpq_class(s.a[axis]) + mpq_class(t) * (mpq_class(s.b[axis]) - s.a[axis]);
  };
  std::mt19937_64 rng(23);
  std::uniform_int_distribution<int> g(0, 4);
  std::uniform_real_distribution<double> u(-1, 1), ut(0, 1);
  const auto grid = [&] { return Point2{double(g(rng)), double(g(rng))}; };
  int along = 0, end_on = 0, flat = 0;
  for (int i = 0; i < 40000; ++i) {
    const bool on_grid = i % 2 == 0;
    const Segment2 s =
        on_grid ? Segment2{grid(), grid()} : Segment2{{u(rng), u(rng)}, {u(rng), u(rng)}};
    const double t = i % 7 == 0 ? double(i % 3) / 2 : ut(rng);
    const Point2 m = point_at(s, t);
    const Point2 a = on_grid ? grid() : Point2{u(rng), u(rng)};
    const Point2 b = on_grid ? grid() : m;
    const mpq_class px = at(s, t, 0), py = at(s, t, 1);
    const mpq_class det =
        (mpq_class(b[0]) - a[0]) * (py - a[1]) - (mpq_class(b[1]) - a[1]) * (px - a[0]);
    const int want = sgn(det);
    const Orientation oa = orientation(a, b, s.a), ob = orientation(a, b, s.b);
    along += oa == Orientation::collinear && ob == Orientation::collinear;
    end_on += (oa == Orientation::collinear) != (ob == Orientation::collinear);
    ASSERT_EQ(sign(orientation_at(a, b, s, t)), want) << i;
    for (int axis = 0; axis < 2; ++axis) {
      const double v = on_grid ? double(g(rng)) : m[axis];
      flat += s.a[axis] == v && s.b[axis] == v;
      ASSERT_EQ(compare_coordinate_at(s, t, axis, v), cmp(at(s, t, axis), v) > 0   ? 1
                                                      : cmp(at(s, t, axis), v) < 0 ? -1
                                                                                   : 0)
          << i;
    }
  }
  EXPECT_GT(along, 500);
  EXPECT_GT(end_on, 2000);
  EXPECT_GT(flat, 500);
}

TEST(Segment, BoxIntersectionIsExact2D) {
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> u(0, 10);
  std::uniform_int_distribution<int> grid(0, 10);
  int hits = 0, total = 0;
  for (int i = 0; i < 20000; ++i) {
    // Half on a coarse grid, where touching corners and collinear edges are common; a
    // quarter scaled by 2^600 (the same answers: every product of differences overflows).
    const double scale = i % 4 < 2 ? 1 : 0x1p600;
    auto coord = [&] { return scale * (i % 2 ? double(grid(rng)) : u(rng)); };
    Box2 box{{coord(), coord()}, {0, 0}};
    box.max = {box.min[0] + scale * std::floor(u(rng) / 2),
               box.min[1] + scale * std::floor(u(rng) / 2)};
    const Segment2 s{{coord(), coord()}, {coord(), coord()}};
    const bool expected = exact_box_segment(box, s);
    ASSERT_EQ(intersects(box, s), expected)
        << to_string(box) << " " << to_string(s.a) << to_string(s.b);
    hits += expected;
    ++total;
  }
  EXPECT_GT(hits, total / 10);
  EXPECT_LT(hits, total * 9 / 10);
}

TEST(Segment, BoxIntersectionIsExact3D) {
  std::mt19937_64 rng(13);
  std::uniform_int_distribution<int> grid(0, 8);
  int hits = 0;
  for (int i = 0; i < 20000; ++i) {
    auto g = [&] { return double(grid(rng)); };
    Box3 box{{g(), g(), g()}, {0, 0, 0}};
    for (int a = 0; a < 3; ++a)
      box.max[a] = box.min[a] + double(grid(rng) / 3);
    const Segment3 s{{g(), g(), g()}, {g(), g(), g()}};
    const bool expected = exact_box_segment(box, s);
    ASSERT_EQ(intersects(box, s), expected);
    hits += expected;
  }
  EXPECT_GT(hits, 300);
}

TEST(Segment, SegmentIntersectionExact) {
  const Segment2 s{{0, 0}, {2, 2}};
  EXPECT_TRUE(intersects(s, Segment2{{0, 2}, {2, 0}}));
  EXPECT_TRUE(intersects(s, Segment2{{2, 2}, {3, 0}}));   // shared endpoint
  EXPECT_TRUE(intersects(s, Segment2{{1, 1}, {5, 0}}));   // endpoint on interior
  EXPECT_TRUE(intersects(s, Segment2{{1, 1}, {3, 3}}));   // collinear overlap
  EXPECT_FALSE(intersects(s, Segment2{{3, 3}, {4, 4}}));  // collinear, apart
  EXPECT_FALSE(intersects(s, Segment2{{0, 1}, {1, 2}}));  // parallel
  EXPECT_FALSE(intersects(s, Segment2{{3, 0}, {1.6, 1.5}}));
  std::mt19937_64 rng(14);
  std::uniform_int_distribution<int> grid(0, 6);
  for (int i = 0; i < 20000; ++i) {
    auto g = [&] { return Point2{double(grid(rng)), double(grid(rng))}; };
    const Segment2 a{g(), g()}, b{g(), g()};
    // Small integers: Boost's answer is exact here.
    ASSERT_EQ(intersects(a, b), bg::intersects(a, b));
  }
}

TEST(Distance, MatchesBoost) {
  std::mt19937_64 rng(15);
  std::uniform_real_distribution<double> u(-100, 100);
  for (int i = 0; i < 5000; ++i) {
    const Point2 p{u(rng), u(rng)};
    const Segment2 s{{u(rng), u(rng)}, {u(rng), u(rng)}};
    Box2 b{{u(rng), u(rng)}, {0, 0}};
    b.max = {b.min[0] + std::fabs(u(rng)), b.min[1] + std::fabs(u(rng))};
    EXPECT_NEAR(std::sqrt(squared_distance(p, s)), bg::distance(p, s), 1e-9);
    EXPECT_NEAR(std::sqrt(squared_distance(p, b)), bg::distance(p, b), 1e-9);
  }
  const Segment3 s3{{0, 0, 0}, {0, 0, 0}};
  EXPECT_DOUBLE_EQ(squared_distance(Point3{1, 2, 2}, s3), 9.0);
}

// MINMAXDIST bounds from above the distance to every point set whose bounding box is b, and
// is reached: for the set of the far corners on each side (one per side), its nearest point is
// exactly that far.
TEST(Distance, MinMaxBoundsEverySetWithThatBox) {
  std::mt19937_64 rng(16);
  std::uniform_real_distribution<double> u(-50, 50), t(0, 1);
  for (int i = 0; i < 5000; ++i) {
    std::vector<Point2> set(1 + i % 6);
    for (Point2& q : set)
      q = {u(rng), u(rng)};
    // Points on every side of the box: move one point onto each side now and then.
    Box2 b = Box2::empty();
    for (const Point2& q : set)
      b.expand(q);
    if (i % 2) b.expand(Point2{u(rng), u(rng)});  // widen, then put a point on each side
    if (i % 2) {
      set.push_back({b.min[0], b.min[1] + t(rng) * (b.max[1] - b.min[1])});
      set.push_back({b.max[0], b.min[1] + t(rng) * (b.max[1] - b.min[1])});
      set.push_back({b.min[0] + t(rng) * (b.max[0] - b.min[0]), b.min[1]});
      set.push_back({b.min[0] + t(rng) * (b.max[0] - b.min[0]), b.max[1]});
    }
    const Point2 p = i % 3 ? Point2{u(rng), u(rng)} : Point2{u(rng) / 10, u(rng) / 10};
    double nearest = std::numeric_limits<double>::infinity();
    for (const Point2& q : set)
      nearest = std::min(nearest, squared_distance(p, q));
    const double bound = squared_minmax_distance(p, b);
    ASSERT_LE(nearest, bound * (1 + 1e-12)) << i;
    ASSERT_GE(bound, squared_distance(p, b));
  }
  // p = (1, 1) in [0, 4] x [0, 10]: nearer side in x is x = 0, its far corner (0, 10):
  // 1 + 81 = 82; nearer side in y is y = 0, its far corner (4, 0): 9 + 1 = 10.
  const Box2 b{{0, 0}, {4, 10}};
  EXPECT_DOUBLE_EQ(squared_minmax_distance(Point2{1, 1}, b), 10.0);
  const std::vector<Point2> corners{{4, 0}, {0, 10}, {4, 10}};  // one on every side
  double nearest = std::numeric_limits<double>::infinity();
  for (const Point2& q : corners)
    nearest = std::min(nearest, squared_distance(Point2{1, 1}, q));
  EXPECT_DOUBLE_EQ(nearest, 10.0);
  EXPECT_DOUBLE_EQ(squared_minmax_distance(Point3{0, 0, 0}, Box3{{1, 1, 1}, {2, 2, 2}}), 9.0);
}

TEST(BoostAdapt, AlgorithmsAcceptLociTypes) {
  const Box2 a{{0, 0}, {2, 3}};
  EXPECT_DOUBLE_EQ(bg::area(a), 6.0);
  EXPECT_TRUE(bg::intersects(a, Box2{{2, 3}, {4, 4}}));
  EXPECT_TRUE(bg::within(Point2{1, 1}, a));
  Box2 env;
  bg::envelope(Segment2{{3, 1}, {-1, 5}}, env);
  EXPECT_EQ(env, (Box2{{-1, 1}, {3, 5}}));
  EXPECT_DOUBLE_EQ(bg::distance(Point3{0, 0, 0}, Point3{1, 2, 2}), 3.0);
  bg::model::box<bg::model::point<double, 2, bg::cs::cartesian>> boost_box;
  bg::convert(a, boost_box);
  EXPECT_DOUBLE_EQ(boost_box.max_corner().get<1>(), 3.0);
}
