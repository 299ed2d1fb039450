// Point-segment distances near rounding (geom/segment.hpp: accurate_squared_distance,
// compare_distance) against exact rational arithmetic: points exactly on segments (distance 0
// exactly, which floating point misses for slanted segments), points a few units in the last
// place off them, at magnitudes from 1e-6 to 1e9, and distances compared with D equal to the
// true distance rounded and one step either side.
#include <gmpxx.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "loci/geom/segment.hpp"

using namespace loci;

namespace {

mpq_class exact_d2(const Point2& p, const Segment2& s) {
  const mpq_class vx = mpq_class(s.b[0]) - s.a[0], vy = mpq_class(s.b[1]) - s.a[1];
  const mpq_class wx = mpq_class(p[0]) - s.a[0], wy = mpq_class(p[1]) - s.a[1];
  const mpq_class dot = wx * vx + wy * vy, vv = vx * vx + vy * vy;
  if (vv == 0 || dot <= 0) return wx * wx + wy * wy;
  if (dot >= vv) {
    const mpq_class ux = mpq_class(p[0]) - s.b[0], uy = mpq_class(p[1]) - s.b[1];
    return ux * ux + uy * uy;
  }
  const mpq_class cross = wx * vy - wy * vx;
  return cross * cross / vv;
}

// The textbook floating-point distance, through the projected point a + t (b - a): it misses
// most points lying exactly on a slanted segment, which is what the data below must contain.
double projected_d2(const Point2& p, const Segment2& s) {
  const double vx = s.b[0] - s.a[0], vy = s.b[1] - s.a[1];
  const double len2 = vx * vx + vy * vy;
  const double t =
      len2 > 0 ? std::clamp(((p[0] - s.a[0]) * vx + (p[1] - s.a[1]) * vy) / len2, 0.0, 1.0) : 0.0;
  const double dx = p[0] - (s.a[0] + t * vx), dy = p[1] - (s.a[1] + t * vy);
  return dx * dx + dy * dy;
}

int sign_of(const mpq_class& q) {
  return sgn(q);
}

TEST(ExactDistance, PointsOnAndBesideSegmentsAgreeWithRationals) {
  std::mt19937_64 rng(41);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::uniform_int_distribution<int> pick(0, 5), steps(-4, 4);
  int on = 0, missed_by_floating = 0, checked = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    // Magnitudes 1e-6 to 1e9, and every tenth trial near 1e-160, where squares underflow.
    const double scale = trial % 10 == 9 ? std::pow(10.0, -150.0 - double(trial % 30) / 3)
                                         : std::pow(10.0, double(trial % 16) - 6);
    const double ox = unit(rng) * scale * 10, oy = unit(rng) * scale * 10;
    Segment2 s{{ox + unit(rng) * scale, oy + unit(rng) * scale},
               {ox + unit(rng) * scale, oy + unit(rng) * scale}};
    if (trial % 7 == 0) s.b = s.a;         // a point
    if (trial % 11 == 0) s.b[1] = s.a[1];  // horizontal
    Point2 p;
    switch (pick(rng)) {
      case 0:
      case 1:  // on the segment's line, rounded: often exactly on it, often a hair off
        p = {s.a[0] + 0.37 * (s.b[0] - s.a[0]), s.a[1] + 0.37 * (s.b[1] - s.a[1])};
        break;
      case 2:  // a vertex, or a vertex moved by a few units in the last place
        p = s.a;
        for (int k = 0, n = steps(rng); k < std::abs(n); ++k)
          p[k % 2] = std::nextafter(p[k % 2], n > 0 ? INFINITY : -INFINITY);
        break;
      case 3: {  // on an axis-parallel or dyadic spot of the segment: exactly on it
        const double t = 0.25 * (1 + trial % 3);
        p = {s.a[0] + t * (s.b[0] - s.a[0]), s.a[1] + t * (s.b[1] - s.a[1])};
        break;
      }
      default:  // anywhere near
        p = {ox + unit(rng) * scale, oy + unit(rng) * scale};
    }
    const mpq_class d2 = exact_d2(p, s);
    const double got = accurate_squared_distance(p, s);
    if (d2 == 0) {
      ++on;
      missed_by_floating += projected_d2(p, s) != 0;
      EXPECT_EQ(got, 0.0) << trial;
    } else {
      EXPECT_GT(got, 0.0) << trial;
      // Within the rounding bound of the coordinates (segment.hpp's distance_rounding) of
      // the true distance.
      const double want = d2.get_d();
      const double bound = 1e-14 * (std::fabs(p[0]) + std::fabs(p[1]) + std::fabs(s.a[0]) +
                                    std::fabs(s.a[1]) + std::fabs(s.b[0]) + std::fabs(s.b[1]));
      const double tolerance = 2 * std::sqrt(want) * bound + bound * bound + 1e-300;
      EXPECT_NEAR(got, want, tolerance) << trial;
    }
    const double root = std::sqrt(d2.get_d());
    for (const double d : {std::nextafter(root, 0.0), root, std::nextafter(root, INFINITY), 0.0}) {
      const int want = sign_of(d2 - mpq_class(d) * mpq_class(d));
      EXPECT_EQ(compare_distance(p, s, d), want) << trial << " d " << d;
      ++checked;
    }
  }
  EXPECT_GT(on, 2500);
  EXPECT_GT(missed_by_floating, 5);  // the cases exactness is about
  EXPECT_EQ(checked, 80000);
}

}  // namespace
