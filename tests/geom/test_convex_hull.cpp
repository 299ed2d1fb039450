// Convex hulls (geom/convex_hull.hpp) against exact rational arithmetic: on random points, on
// points of a small grid (many collinear and repeated), on nearly collinear points a few units
// in the last place apart at 1e6, and on one or two distinct points. The hull's vertices are
// input points, every turn is strictly left, every input point lies in or on the hull, and the
// Akl-Toussaint filter changes nothing. A certified nearest vertex is the hull's nearest point
// to p, exactly, and certification happens for most far points; the nearest vertex's distance
// and hull_lower_bound() hold the exact distance to the points between them.
#include <gmpxx.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "loci/geom/convex_hull.hpp"

using namespace loci;

namespace {

int exact_orientation(const Point2& a, const Point2& b, const Point2& c) {
  const mpq_class d = (mpq_class(b[0]) - a[0]) * (mpq_class(c[1]) - a[1]) -
                      (mpq_class(b[1]) - a[1]) * (mpq_class(c[0]) - a[0]);
  return sgn(d);
}

mpq_class exact_d2(const Point2& p, const Point2& a, const Point2& b) {
  const mpq_class vx = mpq_class(b[0]) - a[0], vy = mpq_class(b[1]) - a[1];
  const mpq_class wx = mpq_class(p[0]) - a[0], wy = mpq_class(p[1]) - a[1];
  const mpq_class dot = wx * vx + wy * vy, vv = vx * vx + vy * vy;
  if (vv == 0 || dot <= 0) return wx * wx + wy * wy;
  if (dot >= vv) {
    const mpq_class ux = mpq_class(p[0]) - b[0], uy = mpq_class(p[1]) - b[1];
    return ux * ux + uy * uy;
  }
  const mpq_class cross = wx * vy - wy * vx;
  return cross * cross / vv;
}

void check_hull(std::vector<Point2> points, const char* what) {
  std::vector<Point2> all = points;
  const std::vector<Point2> hull = convex_hull(all);
  std::vector<Point2> filtered;
  hull_candidates(points, filtered);
  EXPECT_EQ(convex_hull(filtered), hull) << what << ": the filter changed the hull";
  for (const Point2& v : hull)
    EXPECT_NE(std::find(points.begin(), points.end(), v), points.end())
        << what << ": a vertex that is no input point";
  const std::size_t h = hull.size();
  if (h >= 3) {
    for (std::size_t i = 0; i < h; ++i)
      ASSERT_EQ(exact_orientation(hull[i], hull[(i + 1) % h], hull[(i + 2) % h]), 1)
          << what << ": not a strict left turn at " << i;
    for (const Point2& p : points)
      for (std::size_t i = 0; i < h; ++i)
        ASSERT_GE(exact_orientation(hull[i], hull[(i + 1) % h], p), 0)
            << what << ": an input point outside the hull";
  } else {
    // Collinear: every point on the line through the ends, between them.
    for (const Point2& p : points) {
      if (h == 1) {
        EXPECT_EQ(p, hull[0]) << what;
        continue;
      }
      EXPECT_EQ(exact_orientation(hull[0], hull[1], p), 0) << what;
      EXPECT_EQ(exact_d2(p, hull[0], hull[1]), 0) << what;
    }
  }
}

TEST(ConvexHull, RandomAndDegeneratePointSets) {
  std::mt19937_64 rng(41);
  for (int round = 0; round < 200; ++round) {
    std::uniform_int_distribution<int> size(1, 300);
    const int n = size(rng);
    std::vector<Point2> points;
    const int kind = round % 4;
    std::uniform_real_distribution<double> u(-100, 100);
    std::uniform_int_distribution<int> grid(0, 4), ulp(-3, 3);
    for (int i = 0; i < n; ++i) {
      if (kind == 0) {
        points.push_back({u(rng), u(rng)});
      } else if (kind == 1) {
        points.push_back({double(grid(rng)), double(grid(rng))});
      } else if (kind == 2) {
        // Along the line y = x / 3 at 1e6, each coordinate a few units in the last place off.
        const double x = 1e6 + std::floor(u(rng) * 1000);
        double y = x / 3;
        for (int k = ulp(rng); k != 0; k += k > 0 ? -1 : 1)
          y = std::nextafter(y, k > 0 ? INFINITY : -INFINITY);
        points.push_back({x, y});
      } else {
        points.push_back(i % 2 ? Point2{1, 2} : Point2{3, 4 + double(round % 8 == 3)});
      }
    }
    check_hull(points, kind == 0 ? "random" : kind == 1 ? "grid" : kind == 2 ? "near line" : "two");
  }
  check_hull({}, "none");
  EXPECT_TRUE(convex_hull(std::span<Point2>{}).empty());
}

TEST(ConvexHull, CertifiedNearestVertexIsTheHullsNearestPoint) {
  std::mt19937_64 rng(43);
  std::size_t certified = 0, far = 0, far_certified = 0;
  for (int round = 0; round < 100; ++round) {
    std::uniform_real_distribution<double> u(-10, 10);
    std::uniform_int_distribution<int> grid(-3, 3);
    std::vector<Point2> points;
    const int n = 1 + round % 40;
    for (int i = 0; i < n; ++i)
      points.push_back(round % 3 == 0 ? Point2{double(grid(rng)), double(grid(rng))}
                                      : Point2{u(rng), u(rng)});
    const std::vector<Point2> hull = convex_hull(points);
    const std::size_t h = hull.size();
    std::uniform_real_distribution<double> q(-40, 40);
    for (int t = 0; t < 200; ++t) {
      // Far points, points near the hull, and points on the normals through vertices.
      Point2 p{q(rng), q(rng)};
      if (t % 4 == 1) p = {q(rng) / 4, q(rng) / 4};
      if (t % 4 == 2 && h >= 2) {
        const Point2 &v = hull[t % h], &w = hull[(t + 1) % h];
        p = {v[0] - (w[1] - v[1]), v[1] + (w[0] - v[0])};  // v plus the edge turned right
      }
      // the nearest vertex and hull_lower_bound() bound the distance to the points (exact in
      // rationals); the lower one is the hull's own when p is outside it, 0 inside.
      mpq_class to_set = exact_d2(p, points[0], points[0]);
      for (const Point2& x : points)
        to_set = std::min(to_set, mpq_class(exact_d2(p, x, x)));
      const NearestVertex nv = nearest_vertex(hull, p);
      const double lower = hull_lower_bound(hull, p);
      EXPECT_LE(mpq_class(lower), to_set);
      EXPECT_GE(mpq_class(nv.d2), to_set * mpq_class(1 - 1e-15));
      if (h >= 3) {
        bool outside = false;
        mpq_class to_hull = to_set;
        for (std::size_t e = 0; e < h; ++e) {
          outside = outside || exact_orientation(hull[e], hull[(e + 1) % h], p) < 0;
          to_hull = std::min(to_hull, exact_d2(p, hull[e], hull[(e + 1) % h]));
        }
        EXPECT_EQ(strictly_outside(hull, p), outside);
        if (!outside) {
          EXPECT_EQ(lower, 0.0);
        } else {
          EXPECT_LE(mpq_class(lower), to_hull);
          // Tight but for the rounding allowance (about 1e-14 of the coordinates).
          if (to_hull > 1e-6) EXPECT_GE(mpq_class(lower), to_hull * mpq_class(1 - 1e-9));
        }
      }
      if (h <= 2) EXPECT_EQ(strictly_outside(hull, p), exact_d2(p, hull[0], hull[h - 1]) > 0);
      const bool is_far = std::hypot(p[0], p[1]) > 30;
      far += is_far;
      if (!nv.certified) continue;
      const int i = int(nv.index);
      EXPECT_LE(abs(mpq_class(nv.d2) - to_set), to_set * mpq_class(1e-15));
      ++certified;
      far_certified += is_far;
      const Point2& v = hull[std::size_t(i)];
      const mpq_class to_v = exact_d2(p, v, v);
      // Nearest among the hull's edges (and so among the points, which lie in it; p is
      // outside, or v itself).
      for (std::size_t e = 0; e < h; ++e)
        ASSERT_LE(to_v, exact_d2(p, hull[e], hull[(e + 1) % h])) << "round " << round;
      for (const Point2& x : points)
        ASSERT_LE(to_v, exact_d2(p, x, x));
      if (h >= 3 && to_v > 0) {
        bool outside = false;
        for (std::size_t e = 0; e < h; ++e)
          outside = outside || exact_orientation(hull[e], hull[(e + 1) % h], p) < 0;
        EXPECT_TRUE(outside) << "certified from inside the hull";
      }
    }
  }
  EXPECT_GT(certified, 5000u);
  EXPECT_GT(far_certified, far / 2) << "most far points see a vertex nearest";
  EXPECT_FALSE(nearest_vertex({}, {0, 0}).certified);
  EXPECT_EQ(nearest_vertex({}, {0, 0}).d2, INFINITY);
  EXPECT_EQ(hull_lower_bound({}, {0, 0}), INFINITY);
}

}  // namespace
