// Contact intervals of moving boxes and spheres: exact hand cases, and random cases against a
// fine-step simulation.
#include <gmpxx.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <utility>

#include "loci/geom/swept.hpp"

namespace loci {
namespace {

Box2 box(double x0, double y0, double x1, double y1) {
  return {{x0, y0}, {x1, y1}};
}

TEST(BoxContact, HeadOn) {
  // a reaches b at t = 2 (a.max = 3) and leaves it at t = 4 (a.min = 4): touching counts.
  const auto c =
      box_contact(box(0, 0, 1, 1), Point2{1, 0}, box(3, 0, 4, 1), Point2{0, 0}, 0.0, 10.0);
  EXPECT_EQ(c, (ContactInterval{2, 4}));
  // Both moving: relative speed 2.
  EXPECT_EQ(box_contact(box(0, 0, 1, 1), Point2{1, 0}, box(3, 0, 4, 1), Point2{-1, 0}, 0.0, 10.0),
            (ContactInterval{1, 2}));
}

TEST(BoxContact, TouchingOnlyCounts) {
  // The y extents only touch (a.max y = b.min y) for the whole run.
  const auto c =
      box_contact(box(0, 0, 1, 1), Point2{1, 0}, box(2, 1, 3, 2), Point2{0, 0}, 0.0, 10.0);
  EXPECT_EQ(c, (ContactInterval{1, 3}));
  // Corner to corner at one instant.
  const auto d =
      box_contact(box(0, 0, 1, 1), Point2{1, 1}, box(2, 2, 3, 3), Point2{0, 0}, 0.0, 10.0);
  EXPECT_EQ(d, (ContactInterval{1, 3}));
  const auto e =
      box_contact(box(0, 0, 1, 1), Point2{1, 0}, box(3, 0, 4, 1), Point2{0, 0}, 0.0, 2.0);
  EXPECT_EQ(e, (ContactInterval{2, 2}));
}

TEST(BoxContact, ParallelMotion) {
  // Same velocity: apart forever, or together forever.
  EXPECT_TRUE(
      box_contact(box(0, 0, 1, 1), Point2{1, 1}, box(0, 3, 1, 4), Point2{1, 1}, 0.0, 10.0).empty());
  EXPECT_EQ(
      box_contact(box(0, 0, 1, 1), Point2{1, 1}, box(0.5, 0.5, 2, 2), Point2{1, 1}, 0.0, 10.0),
      (ContactInterval{0, 10}));
  // Moving along x, apart on y: never.
  EXPECT_TRUE(box_contact(box(0, 0, 1, 1), Point2{1, 0}, box(3, 1.5, 4, 2), Point2{0, 0}, 0.0, 10.0)
                  .empty());
}

TEST(BoxContact, AlreadyOverlappingAndWindow) {
  EXPECT_EQ(box_contact(box(0, 0, 2, 2), Point2{1, 0}, box(1, 0, 3, 2), Point2{0, 0}, 0.0, 10.0),
            (ContactInterval{0, 3}));
  // Contact [2, 4] clipped to [3, 10], and missed by [5, 10] and [0, 1].
  const Box2 a = box(0, 0, 1, 1), b = box(3, 0, 4, 1);
  EXPECT_EQ(box_contact(a, Point2{1, 0}, b, Point2{0, 0}, 3.0, 10.0), (ContactInterval{3, 4}));
  EXPECT_TRUE(box_contact(a, Point2{1, 0}, b, Point2{0, 0}, 5.0, 10.0).empty());
  EXPECT_TRUE(box_contact(a, Point2{1, 0}, b, Point2{0, 0}, 0.0, 1.0).empty());
}

TEST(SphereContact, HandCases) {
  // |(-5 + t, 0)| <= 2 for t in [3, 7].
  const auto c =
      sphere_contact(Point2{0, 0}, 1.0, Point2{1, 0}, Point2{5, 0}, 1.0, Point2{0, 0}, 0.0, 10.0);
  EXPECT_DOUBLE_EQ(c.enter, 3);
  EXPECT_DOUBLE_EQ(c.exit, 7);
  // Grazing: the distance is 2 at t = 5 only.
  const auto g =
      sphere_contact(Point2{0, 0}, 1.0, Point2{1, 0}, Point2{5, 2}, 1.0, Point2{0, 0}, 0.0, 10.0);
  ASSERT_FALSE(g.empty());
  EXPECT_DOUBLE_EQ(g.enter, 5);
  EXPECT_DOUBLE_EQ(g.exit, 5);
  // Misses by a little; parallel; already overlapping; 3D.
  EXPECT_TRUE(
      sphere_contact(Point2{0, 0}, 1.0, Point2{1, 0}, Point2{5, 2.01}, 1.0, Point2{0, 0}, 0.0, 10.0)
          .empty());
  EXPECT_TRUE(
      sphere_contact(Point2{0, 0}, 1.0, Point2{1, 0}, Point2{0, 3}, 1.0, Point2{1, 0}, 0.0, 10.0)
          .empty());
  EXPECT_EQ(
      sphere_contact(Point2{0, 0}, 1.0, Point2{1, 0}, Point2{0, 1}, 1.0, Point2{1, 0}, 0.0, 10.0),
      (ContactInterval{0, 10}));
  const auto o =
      sphere_contact(Point2{0, 0}, 1.0, Point2{1, 0}, Point2{1, 0}, 1.0, Point2{0, 0}, 0.0, 10.0);
  EXPECT_EQ(o.enter, 0);
  EXPECT_DOUBLE_EQ(o.exit, 3);
  const auto s = sphere_contact(Point3{0, 0, 0}, 0.5, Point3{0, 0, 2}, Point3{0, 0, 10}, 0.5,
                                Point3{0, 0, 0}, 0.0, 10.0);
  EXPECT_DOUBLE_EQ(s.enter, 4.5);
  EXPECT_DOUBLE_EQ(s.exit, 5.5);
  // Fast and thin: a tick-by-tick overlap test at t = 0, 1, 2 would miss this (tunnelling).
  const auto t =
      sphere_contact(Point2{0, 0}, 0.1, Point2{10, 0}, Point2{5, 0}, 0.1, Point2{0, 0}, 0.0, 2.0);
  EXPECT_NEAR(t.enter, 0.48, 1e-12);
  EXPECT_NEAR(t.exit, 0.52, 1e-12);
}

// Lengths scaled by 2^a and speeds by 2^b scale the contact times by 2^(a - b), bit for bit:
// together from 2^-400 to 2^480 (where the contact equation's terms would overflow or
// underflow unscaled), and apart by up to 900 (speeds of 1e150 against lengths of 1e-100);
// by 1e140 and 1e-140 together, to rounding.
TEST(SphereContact, ScaleInvariant) {
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> u(-10, 10), pos(0.5, 3);
  int met = 0;
  for (int i = 0; i < 300; ++i) {
    const Point2 ca{u(rng), u(rng)}, va{u(rng), u(rng)}, cb{u(rng), u(rng)}, vb{u(rng), u(rng)};
    const double ra = pos(rng), rb = pos(rng);
    const auto want = sphere_contact(ca, ra, va, cb, rb, vb, 0.0, 5.0);
    met += !want.empty();
    // Lengths times fl, speeds times fv, so times times fl / fv.
    auto scaled = [&](double fl, double fv) {
      auto l = [fl](Point2 p) { return Point2{p[0] * fl, p[1] * fl}; };
      auto v = [fv](Point2 p) { return Point2{p[0] * fv, p[1] * fv}; };
      return sphere_contact(l(ca), ra * fl, v(va), l(cb), rb * fl, v(vb), 0.0, 5.0 * fl / fv);
    };
    for (auto [a, b] : {std::pair{-400, -400},
                        {-250, -250},
                        {250, 250},
                        {480, 480},
                        {0, 480},
                        {-400, 300},
                        {300, -400},
                        {-450, 450},
                        {200, 0}}) {
      const double ft = std::ldexp(1.0, a - b);
      const auto got = scaled(std::ldexp(1.0, a), std::ldexp(1.0, b));
      ASSERT_EQ(got.empty(), want.empty()) << i << " 2^" << a << " 2^" << b;
      if (want.empty()) continue;
      EXPECT_EQ(got.enter, want.enter * ft) << i << " 2^" << a << " 2^" << b;
      EXPECT_EQ(got.exit, want.exit * ft) << i << " 2^" << a << " 2^" << b;
    }
    for (double f : {1e140, 1e-140}) {
      const auto got = scaled(f, f);
      if (want.empty() || got.empty()) continue;  // a grazing pair may round either way
      EXPECT_NEAR(got.enter, want.enter, 1e-9) << i << " " << f;
      EXPECT_NEAR(got.exit, want.exit, 1e-9) << i << " " << f;
    }
  }
  EXPECT_GT(met, 30);
  // Lengths of 1e-100 closing at 1e150: in contact from (2 - sqrt(3/4)) 1e-250 to
  // (2 + sqrt(3/4)) 1e-250, not from 0.
  const auto c = sphere_contact(Point2{0, 0}, 0.5e-100, Point2{0, 0}, Point2{2e-100, 0.5e-100},
                                0.5e-100, Point2{-1e150, 0}, 0.0, 4e-250);
  ASSERT_FALSE(c.empty());
  EXPECT_NEAR(c.enter / 1e-250, 2 - std::sqrt(0.75), 1e-12);
  EXPECT_NEAR(c.exit / 1e-250, 2 + std::sqrt(0.75), 1e-12);
}

TEST(SweptBox, ContainsTheMotion) {
  const Box2 b = box(0, 0, 1, 2);
  const Point2 v{2, -1};
  const Box2 s = swept_box(b, v, 1.0, 3.0);
  EXPECT_EQ(s, box(2, -3, 7, 1));
  for (double t = 1; t <= 3; t += 0.125)
    EXPECT_TRUE(contains(s, moved_box(b, v, t)));
}

// The swept box holds the exact motion where x + v t is not a double: rounded to nearest, a
// box touching another exactly at t1 had a swept box an ulp short of it (0.09 + 0.35 x 0.75
// is 0.35249999999999998 and a fraction, rounded to 0.35249999999999992). Checked against
// exact rationals on random motions, with bounds no further out than the rounding needs.
TEST(SweptBox, BoundsAreRoundedOutward) {
  const Box2 a = box(0.09 - 1, 0, 0.09, 1), b = box(0.35249999999999998, 0, 1.35249999999999998, 1);
  const Point2 v{0.35, 0}, still{0, 0};
  EXPECT_TRUE(intersects(swept_box(a, v, 0.0, 0.75), swept_box(b, still, 0.0, 0.75)));
  EXPECT_FALSE(box_contact(a, v, b, still, 0.0, 0.75).empty());
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(-10, 10);
  int widened = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const double x = u(rng), w = std::ldexp(u(rng), int(rng() % 40) - 20), t = u(rng) + 10;
    const Box2 one{{x, 0}, {x, 0}};
    const Box2 s = swept_box(one, Point2{w, 0}, 0.0, t);
    ASSERT_EQ(s.min[1], 0.0);
    ASSERT_EQ(s.max[1], 0.0);
    const mpq_class exact = mpq_class(x) + mpq_class(w) * mpq_class(t);
    const mpq_class lo = exact < mpq_class(x) ? exact : mpq_class(x);
    const mpq_class hi = exact < mpq_class(x) ? mpq_class(x) : exact;
    ASSERT_LE(mpq_class(s.min[0]), lo) << trial;
    ASSERT_GE(mpq_class(s.max[0]), hi) << trial;
    // No further out than the rounding needs: a few ulps of the terms.
    const double moved = exact < mpq_class(x) ? s.min[0] : s.max[0];
    EXPECT_LE(std::abs(mpq_class(moved - exact).get_d()),
              0x1p-50 * (std::abs(w * t) + std::abs(x)) + 0x1p-1070)
        << trial;
    widened += s.max[0] != std::max(x, x + w * t) || s.min[0] != std::min(x, x + w * t);
  }
  EXPECT_GT(widened, 1000);
}

// Against a fine-step simulation: every sampled time in contact lies in the interval, every
// sampled time well inside the interval is in contact.
TEST(Contact, FineStepSimulation) {
  std::mt19937_64 rng(99);
  auto u = [&](double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng);
  };
  const double t0 = 0, t1 = 10, dt = 1e-3, eps = 1e-9;
  int boxes_hit = 0, spheres_hit = 0;
  for (int trial = 0; trial < 200; ++trial) {
    Box2 a, b;
    Point2 va, vb, ca, cb;
    for (int k = 0; k < 2; ++k) {
      const double c1 = u(-10, 10), c2 = u(-10, 10), h1 = u(0.1, 2), h2 = u(0.1, 2);
      a.min[k] = c1 - h1, a.max[k] = c1 + h1;
      b.min[k] = c2 - h2, b.max[k] = c2 + h2;
      va[k] = u(-2, 2), vb[k] = u(-2, 2);
      ca[k] = c1, cb[k] = c2;
    }
    const double ra = u(0.1, 2), rb = u(0.1, 2);
    const auto bc = box_contact(a, va, b, vb, t0, t1);
    const auto sc = sphere_contact(ca, ra, va, cb, rb, vb, t0, t1);
    double first_box = -1, first_sphere = -1;
    for (double t = t0; t <= t1; t += dt) {
      const bool box_meet = intersects(moved_box(a, va, t), moved_box(b, vb, t));
      if (box_meet && first_box < 0) first_box = t;
      if (box_meet)
        EXPECT_TRUE(!bc.empty() && bc.enter - eps <= t && t <= bc.exit + eps)
            << trial << " t " << t;
      if (!bc.empty() && bc.enter + eps < t && t < bc.exit - eps) EXPECT_TRUE(box_meet) << trial;
      double d2 = 0;
      for (int k = 0; k < 2; ++k) {
        const double d = (ca[k] + va[k] * t) - (cb[k] + vb[k] * t);
        d2 += d * d;
      }
      const bool sphere_meet = std::sqrt(d2) <= ra + rb;
      if (sphere_meet && first_sphere < 0) first_sphere = t;
      if (sphere_meet)
        EXPECT_TRUE(!sc.empty() && sc.enter - eps <= t && t <= sc.exit + eps) << trial;
      if (!sc.empty() && sc.enter + 1e-7 < t && t < sc.exit - 1e-7)
        EXPECT_TRUE(sphere_meet) << trial;
    }
    if (first_box >= 0) {
      ++boxes_hit;
      EXPECT_NEAR(bc.enter, first_box, dt) << trial;
    }
    if (first_sphere >= 0) {
      ++spheres_hit;
      EXPECT_NEAR(sc.enter, first_sphere, dt) << trial;
    }
  }
  // The random cases do exercise contact.
  EXPECT_GT(boxes_hit, 20);
  EXPECT_GT(spheres_hit, 20);
}

}  // namespace
}  // namespace loci
