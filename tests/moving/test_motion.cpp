// Linear motion: positions, moving windows and closest approach, by hand and against a fine
// simulation of the motion.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "loci/geom/motion.hpp"

namespace loci {
namespace {

TEST(Motion, PositionExtrapolatesBothWays) {
  const Motion2 m{10, {1, 2}, {0.5, -1}};
  EXPECT_EQ(position(m, 12), (Point2{2, 0}));
  EXPECT_EQ(position(m, 8), (Point2{0, 4}));
}

TEST(Motion, EpochTimesKeepSubSecondMotion) {
  // At 1.7e9 s a report 0.25 s old of an object doing 1 m/s is 0.25 m back.
  const Motion2 m{1.7e9 - 0.25, {100, 0}, {1, 0}};
  EXPECT_DOUBLE_EQ(position(m, 1.7e9)[0], 100.25);
}

TEST(Motion, BadReportsAreRefused) {
  const double nan = std::nan("");
  EXPECT_THROW(check_motion(Motion2{nan, {0, 0}, {0, 0}}), InvalidGeometry);
  EXPECT_THROW(check_motion(Motion2{0, {nan, 0}, {0, 0}}), InvalidGeometry);
  EXPECT_THROW(check_motion(Motion2{0, {0, 0}, {0, INFINITY}}), InvalidGeometry);
  EXPECT_THROW(check_motion(Motion2{0, {2e150, 0}, {0, 0}}), InvalidGeometry);
  EXPECT_NO_THROW(check_motion(Motion2{0, {1e149, 0}, {0, 0}}));
  EXPECT_THROW(check_window(MovingWindow<2>::during({{0, 0}, {1, 1}}, 2, 1)), InvalidGeometry);
  EXPECT_THROW(check_window(MovingWindow<2>::at({{1, 0}, {0, 1}}, 0)), InvalidGeometry);
  // Moving windows doubles cannot follow: the bounds' speed overflows (it was infinite, and
  // the window met everything beyond it), the interval overflows (the speed came out 0, a
  // window standing still), or two boxes at one time (the second was ignored).
  const Box2 a{{0, 0}, {1, 1}}, b{{1, 0}, {2, 1}}, far{{100, 0}, {101, 1}};
  EXPECT_THROW(check_window(MovingWindow<2>(a, b, 0, std::numeric_limits<double>::denorm_min())),
               InvalidGeometry);
  EXPECT_THROW(check_window(MovingWindow<2>(a, far, -1e308, 1e308)), InvalidGeometry);
  EXPECT_THROW(check_window(MovingWindow<2>(a, b, 5, 5)), InvalidGeometry);
  EXPECT_NO_THROW(check_window(MovingWindow<2>(a, b, 0, 1e-300)));
  EXPECT_NO_THROW(check_window(MovingWindow<2>::during(a, -1e308, 1e308)));
  EXPECT_NO_THROW(check_window(MovingWindow<2>(a, far, -1e307, 1e307)));
}

// The message of check_motion's refusal (empty when it accepts).
template <int D>
std::string refusal(const Motion<D>& m, const char* what = "report") {
  try {
    check_motion(m, what);
  } catch (const InvalidGeometry& e) {
    return e.what();
  }
  return "";
}

// Each bad value of a report, on every axis, gets its own message, in the order time, then
// NaN or infinite coordinates, then magnitudes; the limits themselves are accepted.
TEST(Motion, RefusalsNameWhatIsWrong) {
  const double nan = std::nan("");
  EXPECT_EQ(refusal(Motion2{nan, {0, 0}, {0, 0}}), "report has a NaN or infinite time");
  EXPECT_EQ(refusal(Motion2{-INFINITY, {nan, 0}, {0, 0}}), "report has a NaN or infinite time");
  EXPECT_EQ(refusal(Motion2{2e150, {nan, 0}, {0, 0}}), "report has a time beyond 1e150");
  EXPECT_EQ(refusal(Motion2{0, {0, 0}, {0, 0}}, "row 7"), "");
  EXPECT_EQ(refusal(Motion2{-1e150, {1e150, -1e150}, {-1e150, 1e150}}), "");
  for (int a = 0; a < 3; ++a) {
    SCOPED_TRACE(a);
    for (const bool velocity : {false, true}) {
      Motion<3> m{1.7e9, {1, 2, 3}, {0, 0, 0}};
      (velocity ? m.v : m.p)[a] = nan;
      EXPECT_EQ(refusal(m, "row 7").rfind("row 7 has a NaN or infinite coordinate: ", 0), 0u)
          << refusal(m, "row 7");
      (velocity ? m.v : m.p)[a] = -INFINITY;
      EXPECT_EQ(refusal(m).rfind("report has a NaN or infinite coordinate: ", 0), 0u);
      (velocity ? m.v : m.p)[a] = -2e150;
      EXPECT_EQ(refusal(m), "report has a position or velocity beyond 1e150");
      (velocity ? m.v : m.p)[a] = std::nextafter(1e150, 2e150);
      EXPECT_EQ(refusal(m, "row 7"), "row 7 has a position or velocity beyond 1e150");
    }
  }
}

TEST(Motion, WindowHandCases) {
  const Box2 w{{10, 10}, {20, 20}};
  // Passes through the window between t = 10 and t = 20 (touching counts).
  const Motion2 m{0, {0, 15}, {1, 0}};
  EXPECT_FALSE(inside(m, MovingWindow<2>::at(w, 9.9)));
  EXPECT_TRUE(inside(m, MovingWindow<2>::at(w, 10)));
  EXPECT_TRUE(inside(m, MovingWindow<2>::at(w, 20)));
  EXPECT_FALSE(inside(m, MovingWindow<2>::during(w, 0, 9.5)));
  EXPECT_TRUE(inside(m, MovingWindow<2>::during(w, 0, 10)));
  const LinearSpan span = meets(m, MovingWindow<2>::during(w, 0, 100));
  EXPECT_DOUBLE_EQ(span.lo, 10);
  EXPECT_DOUBLE_EQ(span.hi, 20);
  // A window moving along with the object keeps it inside; one moving away never meets it.
  const MovingWindow<2> along{{{-1, 14}, {1, 16}}, {{99, 14}, {101, 16}}, 0, 100};
  EXPECT_TRUE(inside(m, along));
  const MovingWindow<2> away{{{5, 14}, {6, 16}}, {{205, 14}, {206, 16}}, 0, 100};
  EXPECT_FALSE(inside(m, away));
  // Stationary object: inside for all times or none.
  EXPECT_TRUE(inside(Motion2{0, {15, 15}, {0, 0}}, MovingWindow<2>::at(w, 1e6)));
  EXPECT_FALSE(inside(Motion2{0, {25, 15}, {0, 0}}, MovingWindow<2>::during(w, -1e6, 1e6)));
}

// The moving window test against a fine simulation: the sampled answer implies the exact one,
// and an exact "meets" is confirmed at the middle of the reported span.
TEST(Motion, WindowAgreesWithSimulation) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0, 100), v(-5, 5), len(0, 30);
  for (int trial = 0; trial < 3000; ++trial) {
    const Motion2 m{u(rng) - 50, {u(rng), u(rng)}, {v(rng), v(rng)}};
    const double t1 = u(rng) - 50, t2 = t1 + u(rng) / 5;
    const double x = u(rng), y = u(rng), wx = len(rng), wy = len(rng);
    const MovingWindow<2> w{{{x, y}, {x + wx, y + wy}},
                            {{x + v(rng) * (t2 - t1), y}, {x + wx + v(rng) * (t2 - t1), y + wy}},
                            t1,
                            t2};
    bool sampled = false;
    for (int k = 0; k <= 400 && !sampled; ++k) {
      const double s = t1 + (t2 - t1) * k / 400;
      const double f = t2 > t1 ? (s - t1) / (t2 - t1) : 0;
      Box2 at;
      for (int a = 0; a < 2; ++a) {
        at.min[a] = w.from.min[a] + (w.to.min[a] - w.from.min[a]) * f;
        at.max[a] = w.from.max[a] + (w.to.max[a] - w.from.max[a]) * f;
      }
      sampled = intersects(at, position(m, s));
    }
    const LinearSpan span = meets(m, w);
    if (sampled) EXPECT_FALSE(span.empty()) << trial;
    if (!span.empty()) {
      const double s = 0.5 * (span.lo + span.hi);
      const Point2 q = position(m, s);
      const double f = t2 > t1 ? (s - t1) / (t2 - t1) : 0;
      for (int a = 0; a < 2; ++a) {
        const double lo = w.from.min[a] + (w.to.min[a] - w.from.min[a]) * f;
        const double hi = w.from.max[a] + (w.to.max[a] - w.from.max[a]) * f;
        EXPECT_GE(q[a], lo - 1e-9) << trial;
        EXPECT_LE(q[a], hi + 1e-9) << trial;
      }
    }
  }
}

TEST(ClosestApproach, HeadOn) {
  const Motion2 a{0, {0, 0}, {1, 0}}, b{0, {100, 3}, {-1, 0}};
  const auto ap = closest_approach(a, b, 0, 100, 5);
  ASSERT_TRUE(ap);
  EXPECT_DOUBLE_EQ(ap->tcpa, 50);
  EXPECT_DOUBLE_EQ(ap->dcpa, 3);
  EXPECT_DOUBLE_EQ(ap->t_enter, 48);  // 2 * 2 units apart in x: sqrt(25 - 9) = 4
  EXPECT_DOUBLE_EQ(ap->t_exit, 52);
  EXPECT_FALSE(closest_approach(a, b, 0, 100, 2.9));
  EXPECT_TRUE(closest_approach(a, b, 0, 100, 3));  // touching the D-circle counts
  // A horizon ending before the approach clamps tcpa to its end.
  const auto early = closest_approach(a, b, 0, 49, 5);
  ASSERT_TRUE(early);
  EXPECT_DOUBLE_EQ(early->tcpa, 49);
  EXPECT_DOUBLE_EQ(early->t_enter, 48);
  EXPECT_DOUBLE_EQ(early->t_exit, 49);
}

TEST(ClosestApproach, ParallelStationaryAndIdentical) {
  // Same velocity: the distance never changes; tcpa is now.
  const Motion2 a{0, {0, 0}, {2, 1}}, b{0, {3, 4}, {2, 1}};
  const auto ap = closest_approach(a, b, 10, 60, 5);
  ASSERT_TRUE(ap);
  EXPECT_DOUBLE_EQ(ap->tcpa, 10);
  EXPECT_DOUBLE_EQ(ap->dcpa, 5);
  EXPECT_DOUBLE_EQ(ap->t_enter, 10);
  EXPECT_DOUBLE_EQ(ap->t_exit, 70);
  EXPECT_FALSE(closest_approach(a, b, 10, 60, 4.99));
  // Identical positions and velocities: distance 0 throughout.
  const auto same = closest_approach(a, a, 0, 5, 0);
  ASSERT_TRUE(same);
  EXPECT_EQ(same->dcpa, 0);
  // Moving away: closest now.
  const Motion2 c{0, {10, 0}, {1, 0}}, d{0, {0, 0}, {0, 0}};
  const auto away = closest_approach(c, d, 0, 100, 10);
  ASSERT_TRUE(away);
  EXPECT_EQ(away->tcpa, 0);
  EXPECT_EQ(away->t_enter, 0);
  EXPECT_DOUBLE_EQ(away->t_exit, 0);
}

TEST(ClosestApproach, ReportsAtDifferentTimes) {
  // b reported 10 units later than a, at the place a reaches then: they meet at t = 10.
  const Motion2 a{0, {0, 0}, {1, 0}}, b{10, {10, 0}, {0, 1}};
  const auto ap = closest_approach(a, b, 10, 5, 0.5);
  ASSERT_TRUE(ap);
  EXPECT_DOUBLE_EQ(ap->tcpa, 10);
  EXPECT_DOUBLE_EQ(ap->dcpa, 0);
  EXPECT_DOUBLE_EQ(ap->t_enter, 10);
}

TEST(ClosestApproach, AgreesWithSimulation) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0, 200), v(-4, 4), h(0, 60);
  for (int trial = 0; trial < 3000; ++trial) {
    const double s0 = trial % 2 ? 1.7e9 : 0;
    const Motion2 a{s0 - h(rng) / 60, {u(rng), u(rng)}, {v(rng), v(rng)}};
    const Motion2 b{s0, {u(rng), u(rng)}, {v(rng), v(rng)}};
    const double horizon = h(rng), within = u(rng) / 4;
    double best = INFINITY, best_t = s0;
    for (int k = 0; k <= 2000; ++k) {
      const double s = s0 + horizon * k / 2000;
      const double dist = std::sqrt(squared_distance(position(a, s), position(b, s)));
      if (dist < best) best = dist, best_t = s;
    }
    const auto ap = closest_approach(a, b, s0, horizon, within);
    // The sampled minimum is never below the exact one, and is close to it.
    const double tol = 1e-6 * (1 + best);
    if (best <= within - tol) ASSERT_TRUE(ap) << trial;
    if (!ap) continue;
    EXPECT_LE(ap->dcpa, best + tol) << trial;
    EXPECT_LE(ap->dcpa, within);
    EXPECT_GE(ap->tcpa, s0);
    EXPECT_LE(ap->tcpa, s0 + horizon);
    EXPECT_LE(ap->t_enter, ap->tcpa);
    EXPECT_GE(ap->t_exit, ap->tcpa);
    // At the entry and exit times (unless clipped by the horizon) the distance is D.
    const double de =
        std::sqrt(squared_distance(position(a, ap->t_enter), position(b, ap->t_enter)));
    const double dx = std::sqrt(squared_distance(position(a, ap->t_exit), position(b, ap->t_exit)));
    EXPECT_LE(de, within + 1e-5) << trial;
    EXPECT_LE(dx, within + 1e-5) << trial;
    if (ap->t_enter > s0 + 1e-6) EXPECT_NEAR(de, within, 1e-5) << trial;
    (void)best_t;
  }
}

}  // namespace
}  // namespace loci
