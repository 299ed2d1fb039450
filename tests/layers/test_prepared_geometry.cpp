// PreparedGeometry::locate (the grid of cells with per-cell parity values) against brute force
// (every edge through the exact predicates, each polygon by its own crossing parity) on random
// polygons with holes (their rings running either way), multi-polygons,
// overlapping polygons, lines and isolated points, with integer coordinates so that points fall
// on vertices, on edges and on the grid's cell borders; long diagonal edges that force a
// coarser grid; flat envelopes. Also the pair tests on prepared geometries against their
// definitions through brute-force point tests on lattice points.
#include <gmpxx.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <utility>
#include <vector>

#include "loci/geom/predicates.hpp"
#include "loci/geom/segment.hpp"
#include "loci/io/exact.hpp"

namespace loci::io {
namespace {

// Brute force: on an edge or isolated point, else inside when the crossing parity of some
// polygon's own rings is odd (each polygon by itself: where polygons overlap, inside).
Location brute(const FlatGeometry& g, const Point2& p) {
  std::vector<bool> odd(g.polygons);
  for (const Part& part : g.parts) {
    if (part.kind == PartKind::point || part.end - part.begin == 1) {
      for (std::uint32_t i = part.begin; i < part.end; ++i)
        if (g.points[i] == p) return Location::boundary;
      continue;
    }
    for (std::uint32_t i = part.begin; i + 1 < part.end; ++i) {
      const Point2& a = g.points[i];
      const Point2& b = g.points[i + 1];
      if (orientation(a, b, p) == Orientation::collinear && std::min(a[0], b[0]) <= p[0] &&
          p[0] <= std::max(a[0], b[0]) && std::min(a[1], b[1]) <= p[1] &&
          p[1] <= std::max(a[1], b[1]))
        return Location::boundary;
      if (part.kind == PartKind::ring && ray_crosses(a, b, p))
        odd[part.polygon] = !odd[part.polygon];
    }
  }
  for (const bool o : odd)
    if (o) return Location::inside;
  return Location::outside;
}

// Adds a ring to polygon `polygon`, its points in the order given or reversed.
void add_ring(FlatGeometry& g, std::vector<Point2> ring, std::uint32_t polygon,
              bool reversed = false) {
  if (reversed) std::reverse(ring.begin(), ring.end());
  const auto begin = std::uint32_t(g.points.size());
  g.points.insert(g.points.end(), ring.begin(), ring.end());
  g.points.push_back(ring.front());
  g.parts.push_back({begin, std::uint32_t(g.points.size()), PartKind::ring, polygon});
}

// A star-shaped ring around c with `n` integer vertices within radius r.
std::vector<Point2> star(std::mt19937_64& rng, Point2 c, double r, int n) {
  std::uniform_real_distribution<double> radius(r / 4, r);
  std::vector<Point2> ring;
  for (int k = 0; k < n; ++k) {
    const double t = 2 * M_PI * k / n, q = radius(rng);
    ring.push_back({std::round(c[0] + q * std::cos(t)), std::round(c[1] + q * std::sin(t))});
  }
  return ring;
}

void expect_same(const FlatGeometry& g, std::mt19937_64& rng, double lo, double hi,
                 const char* what) {
  const PreparedGeometry prepared(g);
  std::size_t counts[3] = {0, 0, 0};
  auto check = [&](const Point2& p) {
    const Location want = brute(g, p);
    ++counts[int(want)];
    ASSERT_EQ(prepared.locate(p), want) << what << " at " << p[0] << "," << p[1];
  };
  for (double x = lo; x <= hi; x += 1)
    for (double y = lo; y <= hi; y += 1)
      check({x, y});
  std::uniform_real_distribution<double> u(lo, hi);
  for (int k = 0; k < 3000; ++k)
    check({u(rng), u(rng)});
  for (const Point2& v : g.points) {
    check(v);
    check({v[0] + 0.5, v[1]});
  }
  // locate_at on segments between lattice points at sixteenths, where point_at is exact and
  // often falls on edges and vertices (its exact path) or on the cells' borders.
  std::uniform_int_distribution<int> grid_at{int(lo), int(hi)}, sixteenth(1, 15);
  for (int k = 0; k < 3000; ++k) {
    const Segment2 s{{double(grid_at(rng)), double(grid_at(rng))},
                     {double(grid_at(rng)), double(grid_at(rng))}};
    const double t = sixteenth(rng) / 16.0;
    const Location want = brute(g, point_at(s, t));
    ++counts[int(want)];
    ASSERT_EQ(prepared.locate_at(s, t), want) << what << " at " << t << " of " << s.a[0] << ","
                                              << s.a[1] << " " << s.b[0] << "," << s.b[1];
  }
  if (g.polygons > 0) {
    EXPECT_GT(counts[int(Location::inside)], 0u) << what;
    EXPECT_GT(counts[int(Location::boundary)], 0u) << what;
  }
  EXPECT_GT(counts[int(Location::outside)], 0u) << what;
}

TEST(PreparedGeometry, PolygonsWithHolesAndMultiPolygons) {
  std::mt19937_64 rng(31);
  for (int trial = 0; trial < 12; ++trial) {
    FlatGeometry g;
    const int polygons = 1 + trial % 4;
    for (int k = 0; k < polygons; ++k) {
      const Point2 c{double(20 + 25 * k), double(20 + 10 * (k % 2))};
      // Rings in either order: a hole running the same way as its outer ring is still one.
      add_ring(g, star(rng, c, 18, 12 + 40 * (trial % 3)), std::uint32_t(k), (trial + k) % 3 == 0);
      if (trial % 2) add_ring(g, star(rng, c, 5, 7), std::uint32_t(k), k % 2);  // a hole
    }
    g.polygons = std::uint32_t(polygons);
    expect_same(g, rng, -2, 110, "stars");
  }
}

TEST(PreparedGeometry, OverlappingPolygonsLinesAndPoints) {
  std::mt19937_64 rng(32);
  FlatGeometry g;
  add_ring(g, {{0, 0}, {40, 0}, {40, 40}, {0, 40}}, 0);
  add_ring(g, {{20, 20}, {60, 20}, {60, 60}, {20, 60}}, 1, true);  // overlaps the first
  // A third square over both, with a hole over their overlap (inside: the two squares there),
  // and a fourth over the third's hole where the first two do not reach.
  add_ring(g, {{30, 30}, {50, 30}, {50, 50}, {30, 50}}, 2);
  add_ring(g, {{32, 32}, {38, 32}, {38, 38}, {32, 38}}, 2);
  add_ring(g, {{0, 62}, {10, 62}, {10, 68}, {0, 68}}, 3, true);
  add_ring(g, {{4, 61}, {6, 61}, {6, 69}, {4, 69}}, 4);
  add_ring(g, {{4.5, 64}, {5.5, 64}, {5.5, 66}, {4.5, 66}}, 4, true);
  g.polygons = 5;
  const auto begin = std::uint32_t(g.points.size());
  for (int k = 0; k <= 30; ++k)
    g.points.push_back({double(70 + (k % 2) * 5), double(k * 2)});
  g.parts.push_back({begin, std::uint32_t(g.points.size()), PartKind::line, 0});
  g.points.push_back({90, 90});
  g.parts.push_back(
      {std::uint32_t(g.points.size() - 1), std::uint32_t(g.points.size()), PartKind::point, 0});
  expect_same(g, rng, -1, 95, "overlap, line, point");
  const PreparedGeometry prepared(g);
  EXPECT_EQ(prepared.locate({25, 25}), Location::inside);  // in both squares
  EXPECT_EQ(prepared.locate({35, 35}), Location::inside);  // in both, in the third's hole
  EXPECT_EQ(prepared.locate({45, 45}), Location::inside);  // in all three
  EXPECT_EQ(prepared.locate({10, 10}), Location::inside);
  EXPECT_EQ(prepared.locate({5, 65}), Location::inside);    // in 3, in 4's hole
  EXPECT_EQ(prepared.locate({5, 61.5}), Location::inside);  // in 4 only
  EXPECT_EQ(prepared.locate({5, 68.5}), Location::inside);  // in 4 only
  EXPECT_EQ(prepared.locate({5, 69.5}), Location::outside);
  EXPECT_EQ(prepared.locate({41, 41}), Location::inside);  // in 2 and 3
  for (const Point2& p : {Point2{25, 25}, Point2{35, 35}, Point2{5, 65}})
    EXPECT_EQ(prepared.locate_at({{p[0] - 0.5, p[1]}, {p[0] + 0.5, p[1]}}, 0.5), Location::inside);
}

// Polygons of one feature whose holes lie outside their own outer ring or overlap each other
// (invalid): each polygon by its own parity, a point is inside when any polygon holds it.
TEST(PreparedGeometry, InvalidPolygonsCountPolygonByPolygon) {
  std::mt19937_64 rng(39);
  FlatGeometry g;
  add_ring(g, {{0, 0}, {10, 0}, {10, 10}, {0, 10}}, 0);
  add_ring(g, {{20, 0}, {30, 0}, {30, 10}, {20, 10}}, 1);
  add_ring(g, {{2, 2}, {2, 4}, {4, 4}, {4, 2}}, 1);  // polygon 1's hole, inside polygon 0
  add_ring(g, {{5, 12}, {30, 12}, {30, 22}, {5, 22}}, 2);
  add_ring(g, {{6, 14}, {9, 14}, {9, 20}, {6, 20}}, 2);  // two holes that overlap
  add_ring(g, {{7, 15}, {9.5, 15}, {9.5, 19}, {7, 19}}, 2, true);
  add_ring(g, {{0, 12}, {10, 12}, {10, 22}, {0, 22}}, 3);  // over polygon 2's holes
  g.polygons = 4;
  expect_same(g, rng, -1, 31, "invalid polygons");
  const PreparedGeometry prepared(g);
  EXPECT_EQ(prepared.locate({3, 3}), Location::inside);    // polygon 0 (and 1's hole)
  EXPECT_EQ(prepared.locate({8, 17}), Location::inside);   // polygon 3 (2's two holes)
  EXPECT_EQ(prepared.locate({25, 5}), Location::inside);   // polygon 1
  EXPECT_EQ(prepared.locate({12, 5}), Location::outside);  // between them
  for (const Point2& p : {Point2{3, 3}, Point2{8, 17}})
    EXPECT_EQ(prepared.locate_at({{p[0] - 0.5, p[1]}, {p[0] + 0.5, p[1]}}, 0.5), Location::inside);
}

// Many polygons stacked on one another (floor slabs of a polyhedral surface): inside all of
// them is inside, as in one.
TEST(PreparedGeometry, ManyStackedPolygons) {
  std::mt19937_64 rng(40);
  FlatGeometry g;
  for (std::uint32_t k = 0; k < 60; ++k)
    add_ring(g, {{0, 0}, {10, 0}, {10, 10}, {0, 10}}, k, k % 2);
  g.polygons = 60;
  expect_same(g, rng, -1, 11, "stacked");
  const PreparedGeometry prepared(g);
  EXPECT_EQ(prepared.locate({5, 5}), Location::inside);
  EXPECT_EQ(prepared.locate({10.5, 5}), Location::outside);
}

TEST(PreparedGeometry, LongDiagonalEdgesAndManySmallRings) {
  // A huge thin triangle across many small squares: listing its edges in every cell of their
  // boxes would be quadratic, so the grid is made coarser; answers must not change.
  std::mt19937_64 rng(33);
  FlatGeometry g;
  add_ring(g, {{0, 0}, {200, 190}, {199, 200}}, 0);
  std::uint32_t polygon = 1;
  for (int x = 0; x < 200; x += 7)
    for (int y = 0; y < 200; y += 9)
      add_ring(g, {{double(x), double(y)}, {x + 3.0, double(y)}, {x + 3.0, y + 4.0}}, polygon++);
  g.polygons = polygon;
  expect_same(g, rng, -1, 201, "diagonal");
}

TEST(PreparedGeometry, FlatEnvelopes) {
  std::mt19937_64 rng(34);
  FlatGeometry line;
  for (int k = 0; k <= 20; ++k)
    line.points.push_back({double(k * 3), 7});
  line.parts.push_back({0, std::uint32_t(line.points.size()), PartKind::line, 0});
  expect_same(line, rng, 0, 70, "horizontal line");
  FlatGeometry column;
  for (int k = 0; k <= 20; ++k)
    column.points.push_back({5, double(k * 3)});
  column.parts.push_back({0, std::uint32_t(column.points.size()), PartKind::line, 0});
  expect_same(column, rng, 0, 70, "vertical line");
  FlatGeometry point;
  point.points.push_back({4, 4});
  point.parts.push_back({0, 1, PartKind::point, 0});
  expect_same(point, rng, 0, 8, "point");
}

TEST(PreparedGeometry, FlatEnvelopesWithFewEdges) {
  // Two or three long edges across a flat envelope: the grid asked for one cell once got a
  // column per unit of the aspect ratio, each edge listed in most of them, and the coarsening
  // that follows stopped at one cell asked with the counts half made: a write past the lists.
  FlatGeometry sliver, vee;
  add_ring(sliver, {{0, 0}, {1000, 1}, {0, 1}}, 0);
  sliver.polygons = 1;
  vee.points = {{0, 0}, {1000, 1}, {0, 0.5}};
  vee.parts.push_back({0, 3, PartKind::line, 0});
  for (const FlatGeometry* g : {&sliver, &vee}) {
    const PreparedGeometry prepared(*g);
    std::size_t counts[3] = {0, 0, 0};
    for (double x = -1; x <= 1001; x += 0.5)
      for (const double y : {-0.5, 0.0, 0.0005, 0.25, 0.5, 0.75, 1.0, 1.5}) {
        const Location want = brute(*g, {x, y});
        ++counts[int(want)];
        ASSERT_EQ(prepared.locate({x, y}), want) << x << "," << y;
      }
    EXPECT_GT(counts[int(Location::boundary)], 0u);
    EXPECT_GT(counts[int(Location::outside)], 0u);
    if (g->polygons > 0) EXPECT_GT(counts[int(Location::inside)], 0u);
  }
}

TEST(PreparedGeometry, LocateAtAHairFromEdges) {
  // Rings with integer vertices moved by up to two units in the last place, and exact points
  // (sixteenths along segments between lattice points) on the lattice's lines: such a point
  // lies within rounding of the moved edges but rarely on them, so that locate_at decides it by
  // its exact tests (in its cell or along its rows), not by a boundary.
  std::mt19937_64 rng(39);
  std::uniform_int_distribution<int> ulps(-2, 2), sixteenth(1, 15);
  const auto nudge = [&](double v) {
    for (int k = ulps(rng); k != 0; k += k > 0 ? -1 : 1)
      v = std::nextafter(v, k > 0 ? 1e300 : -1e300);
    return v;
  };
  std::size_t counts[3] = {0, 0, 0};
  for (int trial = 0; trial < 8; ++trial) {
    FlatGeometry g;
    for (int k = 0; k < 1 + trial % 3; ++k) {
      const Point2 c{double(20 + 25 * k), double(20 + 10 * (k % 2))};
      for (const double r : {18.0, 5.0}) {
        std::vector<Point2> ring = star(rng, c, r, 8 + 8 * (trial % 4));
        for (Point2& v : ring)
          v = {nudge(v[0]), nudge(v[1])};
        add_ring(g, ring, std::uint32_t(k));
      }
    }
    g.polygons = std::uint32_t(1 + trial % 3);
    const PreparedGeometry prepared(g);
    std::uniform_int_distribution<int> grid_at{0, 80};
    for (int k = 0; k < 20000; ++k) {
      // Along a row or a column of the lattice, or slanted.
      const Point2 a{double(grid_at(rng)), double(grid_at(rng))};
      const Point2 b = k % 3 == 0   ? Point2{double(grid_at(rng)), a[1]}
                       : k % 3 == 1 ? Point2{a[0], double(grid_at(rng))}
                                    : Point2{double(grid_at(rng)), double(grid_at(rng))};
      const Segment2 s{a, b};
      const double t = sixteenth(rng) / 16.0;
      const Point2 p = point_at(s, t);
      if (!prepared.near_boundary(p, point_at_rounding(s))) continue;
      const Location want = brute(g, p);
      ++counts[int(want)];
      ASSERT_EQ(prepared.locate_at(s, t), want)
          << trial << " at " << t << " of " << a[0] << "," << a[1] << " " << b[0] << "," << b[1];
    }
  }
  EXPECT_GT(counts[int(Location::inside)], 200u);
  EXPECT_GT(counts[int(Location::outside)], 200u);
}

TEST(PreparedGeometry, CoversAlongLongCollinearLines) {
  // A line of 100,000 collinear edges (horizontal, then vertical) and a polygon whose side is
  // made of them: b lying along that linework is cut into pieces at a's vertices, each located
  // at its middle within rounding of the edges, which the grid answers from the middle's cell
  // (scanning the whole row to its right for each made this quadratic: minutes).
  constexpr int n = 100000;
  for (const int axis : {0, 1}) {
    const auto at = [&](double along, double across) {
      return axis == 0 ? Point2{along, across} : Point2{across, along};
    };
    FlatGeometry line;
    for (int k = 0; k <= n; ++k)
      line.points.push_back(at(k, 0.7));
    line.parts.push_back({0, std::uint32_t(line.points.size()), PartKind::line, 0});
    // b: a line with a vertex between each two of a's, then one leaving the line by an ulp.
    FlatGeometry on, off;
    for (int k = 0; k < n; ++k)
      on.points.push_back(at(k + 0.5, 0.7));
    off.points = {at(0.5, 0.7), at(n - 0.5, std::nextafter(0.7, 1.0))};
    on.parts.push_back({0, std::uint32_t(on.points.size()), PartKind::line, 0});
    off.parts.push_back({0, 2, PartKind::line, 0});
    const PreparedGeometry pl(line), pon(on), poff(off);
    EXPECT_TRUE(covers(pl, pon)) << axis;
    EXPECT_FALSE(covers(pl, poff)) << axis;
    // A polygon with that linework as a side, and a triangle on it.
    FlatGeometry square = line, triangle;
    square.parts.clear();
    square.points.push_back(at(n, n));
    square.points.push_back(at(0, n));
    square.points.push_back(at(0, 0.7));
    square.parts.push_back({0, std::uint32_t(square.points.size()), PartKind::ring, 0});
    square.polygons = 1;
    add_ring(triangle, {at(0.5, 0.7), at(n - 0.5, 0.7), at(n / 2.0, 9)}, 0);
    triangle.polygons = 1;
    EXPECT_TRUE(covers(PreparedGeometry(square), PreparedGeometry(triangle))) << axis;
    // A polygon whose side zigzags between that side and an ulp inside: the middle of each of
    // its edges lies a hair inside a, within rounding of a's side.
    FlatGeometry zigzag;
    std::vector<Point2> ring;
    for (int k = 0; k < n; ++k)
      ring.push_back(at(k + 0.5, k % 2 ? std::nextafter(0.7, 1.0) : 0.7));
    ring.push_back(at(n / 2.0, 9));
    add_ring(zigzag, ring, 0);
    zigzag.polygons = 1;
    EXPECT_TRUE(covers(PreparedGeometry(square), PreparedGeometry(zigzag))) << axis;
    ring[1] = at(1.5, std::nextafter(0.7, 0.0));
    FlatGeometry out;
    add_ring(out, ring, 0);
    out.polygons = 1;
    EXPECT_FALSE(covers(PreparedGeometry(square), PreparedGeometry(out))) << axis;
    FlatGeometry below;
    add_ring(below, {at(0.5, 0.7), at(n / 2.0, -9), at(n - 0.5, 0.7)}, 0);
    below.polygons = 1;
    EXPECT_FALSE(covers(PreparedGeometry(square), PreparedGeometry(below))) << axis;
  }
}

// covers() at any scale: the parameters of the points where edges meet came from squared
// lengths, which underflow below about 1e-154 (a line across a square's hole was covered at
// 1e-170 and below) and overflow above 1e154. The same shapes, scaled, answer the same.
TEST(PreparedGeometry, CoversAtTinyAndHugeScales) {
  for (const double s :
       {1.0, 1e-150, 1e-170, 1e-200, 1e-250, 1e-300, 1e-310, 1e100, 1e150, 1e200, 1e290}) {
    const auto at = [s](double x, double y) { return Point2{x * s, y * s}; };
    FlatGeometry a;  // a square with a hole
    add_ring(a, {at(0, 0), at(10, 0), at(10, 10), at(0, 10)}, 0);
    add_ring(a, {at(4, 4), at(6, 4), at(6, 6), at(4, 6)}, 0, true);
    a.polygons = 1;
    auto line = [](Point2 p, Point2 q) {
      FlatGeometry g;
      g.points = {p, q};
      g.parts.push_back({0, 2, PartKind::line, 0});
      return g;
    };
    auto polygon = [](std::vector<Point2> ring) {
      FlatGeometry g;
      add_ring(g, std::move(ring), 0);
      g.polygons = 1;
      return g;
    };
    const PreparedGeometry pa(a);
    char at_scale[32];
    std::snprintf(at_scale, sizeof at_scale, "scale %g", s);
    // Across the hole (at 9/16 of the way, (5.5, 4.375)), and below it.
    EXPECT_FALSE(covers(pa, PreparedGeometry(line(at(1, 1), at(9, 7))))) << at_scale;
    EXPECT_TRUE(covers(pa, PreparedGeometry(line(at(1, 1), at(9, 2))))) << at_scale;
    // Along the hole's side, and from a corner of the square to one of the hole.
    EXPECT_TRUE(covers(pa, PreparedGeometry(line(at(3, 4), at(7, 4))))) << at_scale;
    EXPECT_TRUE(covers(pa, PreparedGeometry(line(at(0, 0), at(4, 4))))) << at_scale;
    // A triangle around the hole, and one beside it touching its side.
    EXPECT_FALSE(covers(pa, PreparedGeometry(polygon({at(1, 1), at(9, 1), at(5, 9)})))) << at_scale;
    EXPECT_TRUE(covers(pa, PreparedGeometry(polygon({at(1, 1), at(9, 1), at(5, 4)})))) << at_scale;
    EXPECT_FALSE(covers(pa, PreparedGeometry(polygon({at(1, 1), at(9, 1), at(5, 4.5)}))))
        << at_scale;
  }
}

TEST(PreparedGeometry, PairTestsAgreeWithPointTests) {
  // meets and covers on prepared geometries against lattice-point evidence on squares whose
  // corners are integers (for such shapes lattice and half-lattice points decide the answers).
  std::mt19937_64 rng(35);
  std::uniform_int_distribution<int> c(0, 20), s(1, 8);
  for (int trial = 0; trial < 200; ++trial) {
    FlatGeometry a, b;
    const double ax = c(rng), ay = c(rng), as = s(rng), bx = c(rng), by = c(rng), bs = s(rng);
    add_ring(a, {{ax, ay}, {ax + as, ay}, {ax + as, ay + as}, {ax, ay + as}}, 0);
    add_ring(b, {{bx, by}, {bx + bs, by}, {bx + bs, by + bs}, {bx, by + bs}}, 0);
    a.polygons = b.polygons = 1;
    const PreparedGeometry pa(a), pb(b);
    bool any_common = false, b_in_a = true;
    for (double x = 0; x <= 30; x += 0.5)
      for (double y = 0; y <= 30; y += 0.5) {
        const bool in_a = brute(a, {x, y}) != Location::outside;
        const bool in_b = brute(b, {x, y}) != Location::outside;
        any_common = any_common || (in_a && in_b);
        b_in_a = b_in_a && (!in_b || in_a);
      }
    EXPECT_EQ(meets(pa, pb), any_common) << trial;
    EXPECT_EQ(covers(pa, pb), b_in_a) << trial;
    const double gap = std::hypot(std::max({0.0, ax - (bx + bs), bx - (ax + as)}),
                                  std::max({0.0, ay - (by + bs), by - (ay + as)}));
    const auto d = distance_within(pa, pb, 100);
    ASSERT_TRUE(d.has_value());
    EXPECT_NEAR(*d, gap, 1e-12) << trial;
    EXPECT_NEAR(distance(pa, pb, gap + 50), gap, 1e-12) << trial;
  }
}

// A point or the end of a line at D, give or take a hair, beside a long slanted segment, near
// the origin and at coordinates of 1e7 and 1e12: whether it lies within D is decided exactly,
// and the distance is good to 1e-12 (it was the projected point's, whose rounding at 1e7 is a
// millionth of a distance of 1e-3: pairs beyond D were joined and pairs within D missed).
TEST(PreparedGeometry, DistanceWithinIsExactNearD) {
  std::mt19937_64 rng(53);
  std::uniform_real_distribution<double> u(0, 1);
  const double D = 1e-3;
  int in = 0, out = 0;
  for (const double offset : {0.0, 1e7, 1e12}) {
    for (int i = 0; i < 300; ++i) {
      const Point2 a{offset + i * 1000.0 + u(rng), offset + u(rng) * 1000};
      const double angle = u(rng) * 2 * M_PI, length = 10 + 490 * u(rng);
      const Point2 b{a[0] + length * std::cos(angle), a[1] + length * std::sin(angle)};
      const double t = 0.1 + 0.8 * u(rng);
      const double gap = D + (u(rng) - 0.5) * 2e-9;
      const Point2 n{-std::sin(angle), std::cos(angle)};
      const Point2 p{a[0] + t * (b[0] - a[0]) + gap * n[0], a[1] + t * (b[1] - a[1]) + gap * n[1]};
      FlatGeometry line, other;
      line.points = {a, b};
      line.parts.push_back({0, 2, PartKind::line, 0});
      other.points = {p};
      if (i % 3 == 0) {  // a line leaving the segment from p
        other.points.push_back({p[0] + 50 * n[0], p[1] + 50 * n[1]});
        other.parts.push_back({0, 2, PartKind::line, 0});
      } else {
        other.parts.push_back({0, 1, PartKind::point, 0});
      }
      // Exact: p is beside the segment, so its distance is that to the line.
      const mpq_class vx = mpq_class(b[0]) - a[0], vy = mpq_class(b[1]) - a[1];
      const mpq_class wx = mpq_class(p[0]) - a[0], wy = mpq_class(p[1]) - a[1];
      const mpq_class dot = wx * vx + wy * vy, vv = vx * vx + vy * vy;
      ASSERT_TRUE(dot > 0 && dot < vv) << i;
      const mpq_class cross = wx * vy - wy * vx;
      const mpq_class d2 = cross * cross / vv;
      const bool want = d2 <= mpq_class(D) * mpq_class(D);
      (want ? in : out)++;
      const double exact = std::sqrt(d2.get_d());
      const PreparedGeometry pl(line), po(other);
      for (const auto& got : {distance_within(pl, po, D), distance_within(po, pl, D)}) {
        ASSERT_EQ(got.has_value(), want) << offset << " " << i << " exact " << exact;
        if (got) {
          EXPECT_NEAR(*got, exact, 1e-12) << offset << " " << i;
          EXPECT_LE(*got, D);
        }
      }
      EXPECT_NEAR(distance(pl, po, 1), exact, 1e-12) << offset << " " << i;
    }
  }
  EXPECT_GT(in, 200);
  EXPECT_GT(out, 200);
}

TEST(PreparedGeometry, CoversOfOverlappingPolygonsAgainstLatticeEvidence) {
  // a: two or three rectangles as polygons of one feature, overlapping or apart (corners at
  // integers, then at quarters and halves, so that no two share an edge), rings either way, the
  // second sometimes with a hole; b: an integer rectangle. Eighth-lattice points decide. An
  // edge of one polygon inside another was taken for a's boundary inside b: not covered.
  std::mt19937_64 rng(38);
  std::uniform_int_distribution<int> c(0, 12), s(1, 9), coin(0, 1);
  int covered = 0, across = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    FlatGeometry a, b;
    const int n = 2 + trial % 2;
    for (int k = 0; k < n; ++k) {
      const double off = k * 0.25, x = c(rng) + off, y = c(rng) + off;
      const double w = s(rng), h = s(rng);
      add_ring(a, {{x, y}, {x + w, y}, {x + w, y + h}, {x, y + h}}, std::uint32_t(k), coin(rng));
      if (k == 1 && w >= 3 && h >= 3 && coin(rng))
        add_ring(a,
                 {{x + 1.25, y + 1.25},
                  {x + w - 1.25, y + 1.25},
                  {x + w - 1.25, y + h - 1.25},
                  {x + 1.25, y + h - 1.25}},
                 1, coin(rng));
    }
    a.polygons = std::uint32_t(n);
    std::uniform_int_distribution<int> small(1, 5);
    const double x = c(rng), y = c(rng), w = small(rng), h = small(rng);
    add_ring(b, {{x, y}, {x + w, y}, {x + w, y + h}, {x, y + h}}, 0);
    b.polygons = 1;
    bool b_in_a = true, in_two = false;
    for (double px = x; px <= x + w && b_in_a; px += 0.125)
      for (double py = y; py <= y + h; py += 0.125) {
        if (brute(a, {px, py}) == Location::outside) {
          b_in_a = false;
          break;
        }
        int holding = 0;
        for (std::uint32_t k = 0; k < a.polygons; ++k) {
          FlatGeometry one;
          for (const Part& part : a.parts)
            if (part.polygon == k)
              add_ring(one, {a.points.begin() + part.begin, a.points.begin() + part.end - 1}, 0);
          one.polygons = 1;
          holding += brute(one, {px, py}) != Location::outside;
        }
        in_two |= holding > 1;
      }
    covered += b_in_a;
    across += b_in_a && in_two;
    EXPECT_EQ(covers(PreparedGeometry(a), PreparedGeometry(b)), b_in_a) << trial;
  }
  EXPECT_GT(covered, 150);
  EXPECT_GT(across, 50);  // covered only by two polygons together, or by their overlap
}

// Polygons of one feature that share edges: grid cells cut along a diagonal into two
// triangles, each its own polygon (as the faces of a TIN), and integer rectangles that may share
// an edge with them or each other, on the same side or across, rings either way; b an integer
// rectangle or right triangle. One point inside each of the four triangles that a unit cell's
// two diagonals cut it into decides (each lies wholly inside or outside every polygon): b is
// covered when each one inside b is in a. At integers and at 1e6 in steps of 2^-30. An edge
// two polygons share was taken for the feature's boundary: b across it was not covered.
TEST(PreparedGeometry, CoversAcrossEdgesPolygonsShare) {
  std::mt19937_64 rng(71);
  int covered = 0, across = 0, trials = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const bool far = trial % 2;
    const auto at = [far](double x, double y) {
      return far ? Point2{1e6 + std::ldexp(x, -30), 1e6 + std::ldexp(y, -30)} : Point2{x, y};
    };
    const auto rng_int = [&rng](int lo, int hi) { return lo + int(rng() % unsigned(hi - lo + 1)); };
    FlatGeometry a, b;
    std::uint32_t polygons = 0;
    const int x0 = rng_int(0, 3), y0 = rng_int(0, 3), nx = rng_int(1, 5), ny = rng_int(1, 5);
    for (int i = x0; i < x0 + nx; ++i)
      for (int j = y0; j < y0 + ny; ++j) {
        const Point2 c00 = at(i, j), c10 = at(i + 1, j), c11 = at(i + 1, j + 1), c01 = at(i, j + 1);
        const bool rising = rng() % 2;
        const std::vector<std::vector<Point2>> halves =
            rising ? std::vector<std::vector<Point2>>{{c00, c10, c11}, {c00, c11, c01}}
                   : std::vector<std::vector<Point2>>{{c00, c10, c01}, {c10, c11, c01}};
        for (const auto& t : halves)
          if (rng() % 8) add_ring(a, t, polygons++, rng() % 2);
      }
    for (int k = rng_int(0, 2); k > 0; --k) {
      const int x = rng_int(0, 7), y = rng_int(0, 7), w = rng_int(1, 8 - x), h = rng_int(1, 8 - y);
      add_ring(a, {at(x, y), at(x + w, y), at(x + w, y + h), at(x, y + h)}, polygons++, rng() % 2);
    }
    if (polygons == 0) continue;
    a.polygons = polygons;
    // b within the grid's extent half of the time.
    const bool inner = rng() % 2;
    const int bx0 = inner ? x0 : 0, bx1 = inner ? x0 + nx : 8;
    const int by0 = inner ? y0 : 0, by1 = inner ? y0 + ny : 8;
    const int x = rng_int(bx0, bx1 - 1), y = rng_int(by0, by1 - 1);
    const int w = rng_int(1, bx1 - x), h = rng_int(1, by1 - y);
    if (rng() % 2) {
      add_ring(b, {at(x, y), at(x + w, y), at(x + w, y + h), at(x, y + h)}, 0, rng() % 2);
    } else {
      const int d = std::min(w, h);
      add_ring(b, {at(x, y), at(x + d, y), at(x, y + d)}, 0, rng() % 2);
    }
    b.polygons = 1;
    bool b_in_a = true;
    std::vector<bool> by_one(polygons, true);  // whether polygon k alone holds b
    for (int i = x; i < x + w; ++i)
      for (int j = y; j < y + h; ++j)
        for (const auto& [u, v] : {std::pair{0.5, 0.2}, {0.8, 0.5}, {0.5, 0.8}, {0.2, 0.5}}) {
          const Point2 p = at(i + u, j + v);
          if (brute(b, p) != Location::inside) continue;
          b_in_a &= brute(a, p) == Location::inside;
          for (std::uint32_t k = 0; k < polygons; ++k) {
            FlatGeometry one;
            for (const Part& part : a.parts)
              if (part.polygon == k)
                add_ring(one, {a.points.begin() + part.begin, a.points.begin() + part.end - 1}, 0);
            one.polygons = 1;
            by_one[k] = by_one[k] && brute(one, p) == Location::inside;
          }
        }
    ++trials;
    covered += b_in_a;
    across += b_in_a && std::find(by_one.begin(), by_one.end(), true) == by_one.end();
    EXPECT_EQ(covers(PreparedGeometry(a), PreparedGeometry(b)), b_in_a) << trial;
  }
  EXPECT_GT(trials, 2900);
  EXPECT_GT(covered, 300);
  EXPECT_GT(across, 200);  // covered only by polygons together, across the edges they share
}

// A long strip of a TIN's faces: the grid over it has its rows' border at half height, where
// the shared vertical edges have their middles, and its columns' borders at the vertices.
// Those points are decided from the cells about them (it scanned the rest of the row for each,
// 20 s for 10,000 faces), and as before: covered, not covered where one face is missing, and
// points on and beside those edges located as by brute force.
TEST(PreparedGeometry, CoversAcrossTheGridsBordersAlongAStrip) {
  for (const int missing : {-1, 1234}) {
    FlatGeometry a;
    std::uint32_t polygons = 0;
    for (int i = 0; i < 1500; ++i) {
      const double x = i;
      if (2 * i != missing) add_ring(a, {{x, 0}, {x + 1, 0}, {x + 1, 1}}, polygons++, i % 2);
      if (2 * i + 1 != missing) add_ring(a, {{x, 0}, {x + 1, 1}, {x, 1}}, polygons++);
    }
    a.polygons = polygons;
    FlatGeometry b;
    add_ring(b, {{0.5, 0.25}, {1499.5, 0.25}, {1499.5, 0.75}, {0.5, 0.75}}, 0);
    b.polygons = 1;
    const PreparedGeometry pa(a);
    EXPECT_EQ(covers(pa, PreparedGeometry(b)), missing < 0);
    for (int i = 1; i < 1500; i += 7)
      for (const double y : {0.5, 0.25, 0.75}) {
        const Segment2 s{{double(i), 0}, {double(i), 1}};
        EXPECT_EQ(pa.locate_at(s, y), brute(a, {double(i), y})) << i << " " << y;
        const Segment2 across{{i - 0.5, y}, {i + 0.5, y}};
        EXPECT_EQ(pa.locate_at(across, 0.25), brute(a, point_at(across, 0.25))) << i << " " << y;
      }
  }
}

// A polygon's own rings meeting inside another polygon's area (a hole touching its outer ring
// at the middle of an edge, a ring crossing itself): the edge is cut there too, so that no
// piece's middle lies on the ring that touches it, where its sides were undecided and the
// piece taken for boundary. b is the other polygon, or a window of it.
TEST(PreparedGeometry, CoversWhereAPolygonsRingsTouchInsideAnother) {
  FlatGeometry a, bowtie;
  add_ring(a, {{0, 0}, {4, 0}, {4, 4}, {0, 4}}, 0);
  add_ring(a, {{2, 0}, {3, 1}, {1, 1}}, 0);  // a hole touching the outer ring at (2, 0)
  add_ring(a, {{-1, -1}, {5, -1}, {5, 5}, {-1, 5}}, 1);
  a.polygons = 2;
  add_ring(bowtie, {{0, 0}, {4, 4}, {4, 0}, {0, 4}}, 0);  // crossing itself at (2, 2)
  add_ring(bowtie, {{1, 1}, {3, 1}, {3, 3}, {1, 3}}, 1);
  bowtie.polygons = 2;
  FlatGeometry whole, window, square;
  add_ring(whole, {{-1, -1}, {5, -1}, {5, 5}, {-1, 5}}, 0);
  add_ring(window, {{1, -0.5}, {3, -0.5}, {3, 0.5}, {1, 0.5}}, 0);
  add_ring(square, {{1, 1}, {3, 1}, {3, 3}, {1, 3}}, 0);
  whole.polygons = window.polygons = square.polygons = 1;
  EXPECT_TRUE(covers(PreparedGeometry(a), PreparedGeometry(whole)));
  EXPECT_TRUE(covers(PreparedGeometry(a), PreparedGeometry(window)));
  EXPECT_TRUE(covers(PreparedGeometry(bowtie), PreparedGeometry(square)));
  // Without the polygon around them, the hole and the bow-tie's notches are outside.
  FlatGeometry alone;
  add_ring(alone, {{0, 0}, {4, 0}, {4, 4}, {0, 4}}, 0);
  add_ring(alone, {{2, 0}, {3, 1}, {1, 1}}, 0);
  add_ring(alone, {{10, 10}, {11, 10}, {11, 11}}, 1);
  alone.polygons = 2;
  EXPECT_FALSE(covers(PreparedGeometry(alone), PreparedGeometry(window)));
}

// Four rectangles in a pinwheel over a hole of a fifth leave a hole of their own: every edge
// of theirs inside b is partly inside another of them and partly the feature's boundary (each
// edge is cut where the others cross it, so that the boundary part is tested).
TEST(PreparedGeometry, CoversSeesAHoleLeftByAPinwheelOfPolygons) {
  FlatGeometry a, b;
  const auto rect = [](FlatGeometry& g, double x0, double x1, double y0, double y1,
                       std::uint32_t polygon) {
    add_ring(
        g, {{x0 + 0.5, y0 + 0.5}, {x1 + 0.5, y0 + 0.5}, {x1 + 0.5, y1 + 0.5}, {x0 + 0.5, y1 + 0.5}},
        polygon);
  };
  rect(a, -10, 10, -10, 10, 0);
  rect(a, -0.9, 1.9, -0.9, 1.9, 0);  // its hole
  rect(a, -1, 4, -1, 0, 1);
  rect(a, 1, 2, -1, 4, 2);
  rect(a, -3, 2, 1, 2, 3);
  rect(a, -1, 0, -3, 2, 4);
  a.polygons = 5;
  add_ring(b, {{-5, -5}, {5, -5}, {5, 5}, {-5, 5}}, 0);
  b.polygons = 1;
  const PreparedGeometry pa(a), pb(b);
  EXPECT_EQ(pa.locate({1, 1}), Location::outside);
  EXPECT_FALSE(covers(pa, pb));
  // Filled by a sixth (its edges apart from theirs): covered.
  rect(a, -0.3, 1.3, -0.3, 1.3, 5);
  a.polygons = 6;
  EXPECT_TRUE(covers(PreparedGeometry(a), pb));
}

TEST(PreparedGeometry, CoversWithHolesAgainstLatticeEvidence) {
  // Rectangles with integer corners, each with a rectangular hole or none (a hole filled
  // exactly by the other, a hole sharing edges with it, a hole inside it): half-lattice
  // points decide covers. A polygon whose hole is filled exactly by b was once said to cover b.
  std::mt19937_64 rng(36);
  std::uniform_int_distribution<int> c(0, 12), s(1, 8), coin(0, 2);
  auto rect = [](FlatGeometry& g, double x0, double y0, double x1, double y1) {
    add_ring(g, {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, 0);
  };
  auto shape = [&](FlatGeometry& g, double x, double y, double w, double h) {
    rect(g, x, y, x + w, y + h);
    g.polygons = 1;
    if (w >= 2 && h >= 2 && coin(rng)) {
      std::uniform_int_distribution<int> hx(int(x), int(x + w) - 1), hy(int(y), int(y + h) - 1);
      double x0 = hx(rng), y0 = hy(rng);
      std::uniform_int_distribution<int> ex(1, int(x + w - x0)), ey(1, int(y + h - y0));
      double x1 = x0 + ex(rng), y1 = y0 + ey(rng);
      // Keep the hole off the shell's boundary where it would touch along an edge (invalid).
      x0 = std::max(x0, x + 1), y0 = std::max(y0, y + 1);
      x1 = std::min(x1, x + w - 1), y1 = std::min(y1, y + h - 1);
      if (x1 > x0 && y1 > y0) rect(g, x0, y0, x1, y1);
    }
  };
  int filled = 0, covered = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    FlatGeometry a, b;
    // Drawn one by one: the order in which a call's arguments are evaluated is the compiler's.
    const double ax = c(rng), ay = c(rng), aw = s(rng) + 2, ah = s(rng) + 2;
    shape(a, ax, ay, aw, ah);
    if (trial % 3 == 0 && a.parts.size() == 2) {
      // b is a's hole exactly, or the hole grown or shrunk on one side.
      const Part& hole = a.parts[1];
      Point2 lo = a.points[hole.begin], hi = a.points[hole.begin + 2];
      const int side = coin(rng);
      if (side == 1) lo[0] -= 1;
      if (side == 2) hi[1] += 0.5;
      rect(b, lo[0], lo[1], hi[0], hi[1]);
      b.polygons = 1;
      ++filled;
    } else {
      const double bx = c(rng), by = c(rng), bw = s(rng), bh = s(rng);
      shape(b, bx, by, bw, bh);
    }
    const PreparedGeometry pa(a), pb(b);
    bool b_in_a = true;
    for (double x = 0; x <= 32 && b_in_a; x += 0.5)
      for (double y = 0; y <= 32; y += 0.5)
        if (brute(b, {x, y}) != Location::outside && brute(a, {x, y}) == Location::outside) {
          b_in_a = false;
          break;
        }
    covered += b_in_a;
    EXPECT_EQ(covers(pa, pb), b_in_a) << trial;
    EXPECT_EQ(covers(a, b), b_in_a) << trial;
  }
  EXPECT_GT(filled, 300);
  EXPECT_GT(covered, 75);  // 89 with this seed
}

TEST(PreparedGeometry, CoversNearRoundingAndThinHoles) {
  // b is a's triangle with one vertex moved a unit in the last place inwards: a covers it,
  // though b's edges run within a hair of a's (a rounded middle of a's edge may fall inside b).
  FlatGeometry a, b;
  add_ring(a,
           {{135401.49193606543, 141486.6504535633},
            {135458.63329208002, 141498.15754682568},
            {135425.6988831334, 141555.2314589824}},
           0);
  add_ring(b,
           {{135401.49193606546, 141486.65045356334},
            {135458.63329208002, 141498.15754682568},
            {135425.6988831334, 141555.2314589824}},
           0);
  a.polygons = b.polygons = 1;
  EXPECT_TRUE(covers(a, b));
  // b fills a's hole exactly; the hole is a square with a spike thinner than a unit in the
  // last place, its vertices placed so that the widest bands between vertex heights all fall
  // in the spike: the square below still gives a point inside.
  FlatGeometry h, plug;
  add_ring(h, {{0, 0}, {1e7, 0}, {1e7, 1e7}, {0, 1e7}}, 0);
  const std::vector<Point2> hole = {
      {2, 2},       {2, 4},       {3, 4},       {3, 2250000},
      {3, 4500000}, {3, 6750000}, {3, 9000000}, {std::nextafter(3.0, 4.0), 4},
      {4, 4},       {4, 2}};
  add_ring(h, hole, 0);
  add_ring(plug, hole, 0);
  h.polygons = plug.polygons = 1;
  EXPECT_FALSE(covers(h, plug));
  EXPECT_TRUE(covers(plug, plug));
}

TEST(PreparedGeometry, CoversAlongSlantedEdges) {
  // a is a triangle; b has two vertices placed on a's slanted edge A-B by point_at, so each
  // lies a hair inside a, a hair outside or exactly on the edge, and its edge between them runs
  // within rounding of A-B. Since a is convex, a covers b exactly when neither of those two
  // vertices lies outside. The rounded middle of b's edge once decided, and fell outside a for
  // about a fifth of the triangles that a covers.
  std::mt19937_64 rng(37);
  std::uniform_real_distribution<double> u(-100, 100), at(0.05, 0.95);
  int inside = 0, outside = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const Point2 p{u(rng), u(rng)}, q{u(rng), u(rng)};
    const Point2 r{(p[0] + q[0]) / 2 - (q[1] - p[1]), (p[1] + q[1]) / 2 + (q[0] - p[0])};
    Point2 v = point_at(Segment2{p, q}, at(rng)), w = point_at(Segment2{p, q}, at(rng));
    const Point2 c{(p[0] + q[0] + r[0]) / 3, (p[1] + q[1] + r[1]) / 3};
    if (orientation(p, q, r) != Orientation::counterclockwise) continue;
    if (orientation(v, w, c) != Orientation::counterclockwise) std::swap(v, w);
    if (orientation(v, w, c) != Orientation::counterclockwise) continue;
    FlatGeometry a, b;
    add_ring(a, {p, q, r}, 0);
    add_ring(b, {v, w, c}, 0);
    a.polygons = b.polygons = 1;
    const bool want = orientation(p, q, v) != Orientation::clockwise &&
                      orientation(p, q, w) != Orientation::clockwise;
    (want ? inside : outside) += 1;
    ASSERT_EQ(covers(a, b), want) << trial;
  }
  EXPECT_GT(inside, 300);
  EXPECT_GT(outside, 300);
}

}  // namespace
}  // namespace loci::io
