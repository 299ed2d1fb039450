// Segment intersection (geom/segment_intersection.hpp) against exact rational arithmetic: the
// kind of answer on random and degenerate segments (shared endpoints, collinear overlaps,
// vertical, horizontal and zero-length segments, T-junctions), near-parallel segments with
// coordinates near 1e6 and 1e-6 where a floating epsilon decides wrongly, and the crossing point
// as the nearest double of the true one.
#include <gmpxx.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "loci/geom/segment_intersection.hpp"

using namespace loci;

namespace {

int exact_side(const Point2& a, const Point2& b, const Point2& c) {
  const mpq_class det = (mpq_class(b[0]) - a[0]) * (mpq_class(c[1]) - a[1]) -
                        (mpq_class(b[1]) - a[1]) * (mpq_class(c[0]) - a[0]);
  return sgn(det);
}

// Independent oracle: parametric form in rationals. Returns the kind and, for a single point,
// the exact point.
struct Exact {
  SegmentMeet kind;
  mpq_class x, y;
};

Exact exact_intersection(const Segment2& s, const Segment2& t) {
  const mpq_class ax = s.a[0], ay = s.a[1], dx = mpq_class(s.b[0]) - ax,
                  dy = mpq_class(s.b[1]) - ay;
  const mpq_class bx = t.a[0], by = t.a[1], ex = mpq_class(t.b[0]) - bx,
                  ey = mpq_class(t.b[1]) - by;
  const mpq_class denom = dx * ey - dy * ex;
  if (denom != 0) {
    const mpq_class u = ((bx - ax) * ey - (by - ay) * ex) / denom;
    const mpq_class v = ((bx - ax) * dy - (by - ay) * dx) / denom;
    if (u < 0 || u > 1 || v < 0 || v > 1) return {SegmentMeet::none, 0, 0};
    return {SegmentMeet::point, ax + u * dx, ay + u * dy};
  }
  // parallel (or degenerate): collect the parameters along the longer of the two of every
  // endpoint lying on the other segment
  auto on = [](const Segment2& g, const Point2& p) {
    if (exact_side(g.a, g.b, p) != 0) return false;
    return std::min(g.a[0], g.b[0]) <= p[0] && p[0] <= std::max(g.a[0], g.b[0]) &&
           std::min(g.a[1], g.b[1]) <= p[1] && p[1] <= std::max(g.a[1], g.b[1]);
  };
  std::vector<Point2> common;
  for (const Point2& p : {t.a, t.b})
    if (on(s, p)) common.push_back(p);
  for (const Point2& p : {s.a, s.b})
    if (on(t, p)) common.push_back(p);
  if (common.empty()) return {SegmentMeet::none, 0, 0};
  std::sort(common.begin(), common.end(), [](const Point2& p, const Point2& q) {
    return p[0] < q[0] || (p[0] == q[0] && p[1] < q[1]);
  });
  if (common.front() == common.back()) return {SegmentMeet::point, common[0][0], common[0][1]};
  return {SegmentMeet::overlap, 0, 0};
}

// q is the nearest double to x when no double lies strictly nearer.
bool nearest(double q, const mpq_class& x) {
  const mpq_class err = abs(mpq_class(q) - x);
  for (double n : {std::nextafter(q, -INFINITY), std::nextafter(q, INFINITY)})
    if (abs(mpq_class(n) - x) < err) return false;
  return true;
}

void expect_matches_exact(const Segment2& s, const Segment2& t) {
  const SegmentIntersection got = intersection(s, t);
  const Exact ref = exact_intersection(s, t);
  ASSERT_EQ(int(got.kind), int(ref.kind)) << "s " << to_string(s.a) << "-" << to_string(s.b)
                                          << " t " << to_string(t.a) << "-" << to_string(t.b);
  EXPECT_EQ(got.kind != SegmentMeet::none, intersects(s, t));
  if (got.kind == SegmentMeet::point) {
    EXPECT_TRUE(nearest(got.a[0], ref.x) && nearest(got.a[1], ref.y))
        << "point " << to_string(got.a) << " is not the nearest double of the true one";
    EXPECT_EQ(got.a, got.b);
  }
  if (got.kind == SegmentMeet::overlap) {
    EXPECT_NE(got.a, got.b);
    EXPECT_EQ(exact_side(s.a, s.b, got.a), 0);
    EXPECT_EQ(exact_side(s.a, s.b, got.b), 0);
  }
  // symmetric in its arguments
  const SegmentIntersection swapped = intersection(t, s);
  EXPECT_EQ(int(swapped.kind), int(got.kind));
  if (got.kind == SegmentMeet::overlap) {
    EXPECT_EQ(swapped.a, got.a);
    EXPECT_EQ(swapped.b, got.b);
  }
}

TEST(SegmentIntersection, SmallGridCoversEveryDegenerateCase) {
  // coordinates on a 4 x 4 grid: shared endpoints, collinear overlaps, T-junctions,
  // verticals, horizontals and zero-length segments all occur many times
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<int> c(0, 3);
  for (int i = 0; i < 20000; ++i) {
    const Segment2 s{{double(c(rng)), double(c(rng))}, {double(c(rng)), double(c(rng))}};
    const Segment2 t{{double(c(rng)), double(c(rng))}, {double(c(rng)), double(c(rng))}};
    expect_matches_exact(s, t);
  }
}

TEST(SegmentIntersection, RandomSegmentsCrossAtTheNearestDouble) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-100, 100);
  for (int i = 0; i < 20000; ++i) {
    const Segment2 s{{u(rng), u(rng)}, {u(rng), u(rng)}};
    const Segment2 t{{u(rng), u(rng)}, {u(rng), u(rng)}};
    expect_matches_exact(s, t);
  }
}

TEST(SegmentIntersection, NearParallelAtLargeAndSmallScales) {
  std::mt19937_64 rng(7);
  for (double scale : {1e6, 1e-6, 1.0, 1e155, 1e300}) {
    std::uniform_int_distribution<int> ulps(-4, 4);
    for (int i = 0; i < 5000; ++i) {
      // t is s moved by a few ulps at one or both ends: parallel, crossing, or touching
      const Segment2 s{{scale * 1.1, scale * 2.3}, {scale * 7.9, scale * 5.1}};
      Segment2 t = s;
      for (double* v : {&t.a[0], &t.a[1], &t.b[0], &t.b[1]})
        for (int k = ulps(rng); k != 0; k += k > 0 ? -1 : 1)
          *v = std::nextafter(*v, k > 0 ? INFINITY : -INFINITY);
      expect_matches_exact(s, t);
      // and a segment along s, shifted along it: collinear overlaps in floating coordinates
      const double f = std::uniform_real_distribution<double>(0.1, 0.9)(rng);
      const Segment2 along{{s.a[0] + f * (s.b[0] - s.a[0]), s.a[1] + f * (s.b[1] - s.a[1])},
                           {s.b[0] * 1.5, s.b[1] * 1.5}};
      expect_matches_exact(s, along);
    }
  }
}

TEST(SegmentIntersection, HandCases) {
  const Segment2 x{{0, 0}, {4, 0}};
  EXPECT_EQ(intersection(x, {{2, -1}, {2, 1}}),
            (SegmentIntersection{SegmentMeet::point, {2, 0}, {2, 0}}));
  EXPECT_EQ(intersection(x, {{2, 0}, {2, 3}}).a, (Point2{2, 0}));  // T-junction
  EXPECT_EQ(intersection(x, {{4, 0}, {5, 5}}).a, (Point2{4, 0}));  // shared endpoint
  EXPECT_EQ(intersection(x, {{3, 0}, {9, 0}}),
            (SegmentIntersection{SegmentMeet::overlap, {3, 0}, {4, 0}}));
  EXPECT_EQ(intersection(x, {{4, 0}, {9, 0}}),
            (SegmentIntersection{SegmentMeet::point, {4, 0}, {4, 0}}));
  EXPECT_EQ(intersection(x, {{5, 0}, {9, 0}}).kind, SegmentMeet::none);
  EXPECT_EQ(intersection(x, {{1, 0}, {1, 0}}).kind, SegmentMeet::point);  // zero length on it
  EXPECT_EQ(intersection(x, {{1, 1e-300}, {1, 1e-300}}).kind, SegmentMeet::none);
  EXPECT_EQ(intersection(x, {{0, 1}, {4, 1}}).kind, SegmentMeet::none);  // parallel
}

}  // namespace
