// BspTree against brute force: point classification, and first impacts of moving points,
// circles and boxes within the documented bevel error of the exact Minkowski answers.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "loci/index/broadphase/bsp_tree.hpp"
#include "support/solid_reference.hpp"

namespace loci {
namespace {

using test::first_contact_box;
using test::first_contact_circle;
using test::in_solid;
using test::kNever;

std::vector<Point2> star(double cx, double cy, int n, double rmin, double rmax,
                         std::mt19937_64& rng) {
  std::uniform_real_distribution<double> rad(rmin, rmax);
  std::vector<Point2> r;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * std::numbers::pi * i / n;
    const double q = rad(rng);
    r.push_back({cx + q * std::cos(a), cy + q * std::sin(a)});
  }
  return r;
}

// Rectangle with a vertex in the middle of every side (collinear neighbours).
std::vector<Point2> rect(double x0, double y0, double x1, double y1) {
  const double xm = (x0 + x1) / 2, ym = (y0 + y1) / 2;
  return {{x0, y0}, {xm, y0}, {x1, y0}, {x1, ym}, {x1, y1}, {xm, y1}, {x0, y1}, {x0, ym}};
}

// An 8 x 8 grid of 10-unit cells holding stars (some with holes, some clockwise), full
// blocks sharing their borders with neighbouring blocks, and half blocks meeting a
// neighbour along part of a side.
std::vector<BspPolygon> random_layer(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> kind(0, 5);
  std::vector<BspPolygon> out;
  for (int i = 0; i < 8; ++i) {
    for (int j = 0; j < 8; ++j) {
      const double x = 10.0 * i, y = 10.0 * j;
      const int k = kind(rng);
      BspPolygon p;
      if (k <= 1) {
        p.outer = star(x + 5, y + 5, 3 + static_cast<int>(rng() % 18), 1.5, 4.8, rng);
        if (k == 1) {
          p.holes.push_back(star(x + 5, y + 5, 3 + static_cast<int>(rng() % 8), 0.3, 1.2, rng));
        }
        if (rng() % 2) std::reverse(p.outer.begin(), p.outer.end());
      } else if (k == 2) {
        p.outer = rect(x, y, x + 10, y + 10);
      } else if (k == 3) {
        p.outer = rect(x, y + 2, x + 10, y + 7);
      } else {
        continue;
      }
      out.push_back(std::move(p));
    }
  }
  return out;
}

double dist_to_edges(const std::vector<BspPolygon>& polys, const Point2& p) {
  double near = kNever;
  test::for_each_edge(std::span<const BspPolygon>(polys), [&](const Point2& a, const Point2& b) {
    near = std::min(near, test::segment_distance(p, a, b));
  });
  return near;
}

TEST(BspTree, ClassifiesPointsLikeCrossingParity) {
  for (std::uint64_t seed : {1, 2, 3}) {
    const auto polys = random_layer(seed);
    const BspTree tree = BspTree::build(polys);
    tree.validate();
    EXPECT_GT(tree.solid_leaves(), 0u);
    std::mt19937_64 rng(seed * 7);
    std::uniform_real_distribution<double> u(-5, 85);
    int solid = 0;
    for (int q = 0; q < 20000; ++q) {
      const Point2 p{u(rng), u(rng)};
      if (dist_to_edges(polys, p) < 1e-9) continue;
      const bool want = in_solid(polys, p);
      ASSERT_EQ(tree.solid(p), want) << "seed " << seed << " at " << p[0] << "," << p[1];
      solid += want;
    }
    EXPECT_GT(solid, 1000);
  }
}

// Real layers overlap a little where neighbours meet; here stars are laid across the corners
// of the cells, over the blocks and stars of the layer.
std::vector<BspPolygon> overlapping_layer(std::uint64_t seed) {
  std::vector<BspPolygon> polys = random_layer(seed);
  std::mt19937_64 rng(seed + 100);
  for (int i = 1; i < 8; i += 2)
    for (int j = 1; j < 8; j += 2)
      polys.push_back({star(10.0 * i, 10.0 * j, 5 + static_cast<int>(rng() % 10), 2, 7, rng), {}});
  return polys;
}

TEST(BspTree, OverlappingPolygons) {
  for (std::uint64_t seed : {21, 22}) {
    const auto polys = overlapping_layer(seed);
    const BspTree tree = BspTree::build(polys);
    tree.validate();
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-5, 85);
    for (int q = 0; q < 20000; ++q) {
      const Point2 p{u(rng), u(rng)};
      if (dist_to_edges(polys, p) < 1e-9) continue;
      ASSERT_EQ(tree.solid(p), in_solid(polys, p)) << p[0] << "," << p[1];
    }
    for (int q = 0; q < 1000; ++q) {
      const Point2 from{u(rng), u(rng)}, to{u(rng), u(rng)};
      const double want = first_contact_circle(polys, from, to, 0);
      const BspHit h = tree.trace(from, to, BspPoint{});
      ASSERT_EQ(h.hit, want <= 1) << q;
      if (h.hit) ASSERT_NEAR(h.t, want, 1e-9) << q;
    }
  }
}

// Borders met by three edges or more, of duplicated polygons, of islands filling holes, of
// rectangles touching them: where the edges that cancel pair off, the one left covers a
// polygon on its other side too. Whole solid regions were lost (a rectangle beside a
// duplicated one read as empty; an island touched by a square; the inside of a hole filled
// by two polygons at once).
TEST(BspTree, BordersOfDuplicatedAndNestedPolygons) {
  const auto square = [](double x0, double y0, double x1, double y1) {
    return std::vector<Point2>{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
  };
  {
    const std::vector<BspPolygon> polys{
        {square(0, 1, 1, 3), {}}, {square(1, 1, 3, 3), {}}, {square(1, 1, 3, 3), {}}};
    const BspTree tree = BspTree::build(polys);
    EXPECT_TRUE(tree.solid({0.25, 1.25}));
    EXPECT_TRUE(tree.solid({0.5, 2}));
    EXPECT_FALSE(tree.solid({4, 2}));
    const BspHit h = tree.trace({-1, 2}, {4, 2}, BspPoint{});
    ASSERT_TRUE(h.hit);
    EXPECT_NEAR(h.t, 0.2, 1e-12);
  }
  {
    const std::vector<BspPolygon> polys{{square(4, 0, 5, 3), {}},
                                        {square(4, 3, 5, 4), {}},
                                        {square(3, 2, 7, 6), {square(4, 3, 5, 4)}}};
    EXPECT_TRUE(BspTree::build(polys).solid({4.5, 3.5}));
  }
  {
    const std::vector<BspPolygon> polys{{square(1, 0, 5, 4), {square(2, 1, 3, 3)}},
                                        {square(2, 2, 4, 4), {}},
                                        {square(1, 1, 5, 5), {square(2, 2, 4, 4)}}};
    const BspTree tree = BspTree::build(polys);
    EXPECT_TRUE(tree.solid({2.5, 1.5}));
    EXPECT_TRUE(tree.solid({2.5, 2.5}));
  }
  {
    // Two polygons meeting along part of a side: the line beyond them stays empty.
    const std::vector<BspPolygon> polys{{square(0, 4, 4, 8), {square(1, 5, 2, 6)}},
                                        {square(1, 3, 2, 4), {}}};
    const BspTree tree = BspTree::build(polys);
    EXPECT_FALSE(tree.solid({-1, 4}));
    EXPECT_FALSE(tree.solid({-0.5, 4}));
    EXPECT_FALSE(tree.solid({0.5, 3.5}));
    EXPECT_TRUE(tree.solid({1.5, 3.5}));
  }
}

// Points of the boundary count as solid, though planes carry rounding: the vertices of a
// thin triangle (bevel planes pass through computed corners), a point of a slanted edge (a
// unit normal rounded), a point of an edge where a hole's line meets it; and a move ending
// there touches. Each was outside.
TEST(BspTree, BoundaryPointsThroughRoundedPlanes) {
  {
    const std::vector<BspPolygon> polys{{{{0, 2}, {6, 0}, {0, 1}}, {}}};
    for (const double angle : {BspParams{}.bevel_angle, std::numbers::pi}) {
      BspParams params;
      params.bevel_angle = angle;
      const BspTree tree = BspTree::build(polys, params);
      for (const Point2& v : polys[0].outer)
        EXPECT_TRUE(tree.solid(v)) << v[0] << "," << v[1] << " bevels " << angle;
    }
  }
  EXPECT_TRUE(
      BspTree::build(std::vector<BspPolygon>{{{{1, 7}, {0, 2}, {4, 3}}, {}}}).solid({0.5, 4.5}));
  const std::vector<BspPolygon> polys{
      {{{3, 4}, {7, 4}, {7, 8}, {3, 8}}, {{{4, 5}, {6, 5}, {6, 7}, {4, 7}}}},
      {{{4, 0}, {8, 0}, {8, 4}, {4, 4}}, {{{5, 1}, {6, 1}, {6, 2}, {5, 2}}}}};
  const BspTree tree = BspTree::build(polys);
  EXPECT_TRUE(tree.solid({7, 7}));
  EXPECT_TRUE(tree.solid({7, 8}));
  const BspHit h = tree.trace({9, 7}, {7, 7}, BspPoint{});
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.t, 1, 1e-12);
}

// Random rectangles on a small integer grid, duplicated, holed, their holes filled by islands,
// touching and overlapping in every way: every point off the borders as brute force says.
TEST(BspTree, GridRectanglesSharingEdgesEveryWay) {
  for (std::uint64_t seed = 0; seed < 300; ++seed) {
    std::mt19937_64 rng(seed);
    const auto pick = [&](int lo, int hi) {
      return std::uniform_int_distribution<int>(lo, hi)(rng);
    };
    const auto square = [](double x0, double y0, double x1, double y1, bool cw) {
      std::vector<Point2> r{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
      if (cw) std::reverse(r.begin(), r.end());
      return r;
    };
    std::vector<BspPolygon> polys;
    const int n = pick(1, 6);
    for (int i = 0; i < n; ++i) {
      BspPolygon p;
      if (pick(0, 1)) {
        const double x = pick(0, 5), y = pick(0, 5);
        p.outer = square(x, y, x + pick(1, 3), y + pick(1, 3), pick(0, 1));
        if (pick(0, 3) == 0 && !polys.empty())
          p = polys[std::size_t(pick(0, int(polys.size()) - 1))];
      } else {
        const double x = pick(0, 4), y = pick(0, 4);
        p.outer = square(x, y, x + 4, y + 4, pick(0, 1));
        p.holes.push_back(square(x + 1, y + 1, x + 1 + pick(1, 2), y + 1 + pick(1, 2), pick(0, 1)));
        if (pick(0, 1)) polys.push_back({p.holes[0], {}});
      }
      polys.push_back(std::move(p));
    }
    BspParams params;
    params.candidates = std::uint32_t(pick(1, 8));
    const BspTree tree = BspTree::build(polys, params);
    tree.validate();
    for (int xi = -2; xi <= 24; ++xi)
      for (int yi = -2; yi <= 24; ++yi) {
        const Point2 p{xi * 0.5, yi * 0.5};
        if (dist_to_edges(polys, p) < 1e-9) continue;
        ASSERT_EQ(tree.solid(p), in_solid(polys, p))
            << "seed " << seed << " at " << p[0] << "," << p[1];
      }
  }
}

// Slanted triangles with small integer vertices, overlapping, sharing edges and vertices.
// Where three lines meet, rounded fractions left a sliver of a piece across the third line,
// which then split a cell it does not reach and decided its front at the meeting point, on
// other polygons' borders (a triangle's inside read as empty); and an edge of another polygon
// on the splitter's line, facing the same way, was missed by the piece's middle rounded off
// the line (a whole empty region read as solid).
TEST(BspTree, SlantedTrianglesMeetingOnAGrid) {
  const auto tri = [](Point2 a, Point2 b, Point2 c) { return BspPolygon{{a, b, c}, {}}; };
  {
    // x + 2y = 2, y = x / 2 and x = 1 meet at (1, 0.5), beside the inside of the second.
    const std::vector<BspPolygon> polys{tri({0, 0}, {2, 0}, {0, 1}), tri({0, 0}, {1, 0}, {2, 1}),
                                        tri({0, 0}, {1, 0}, {1, 1})};
    const BspTree tree = BspTree::build(polys);
    EXPECT_TRUE(tree.solid({1.25, 0.5}));
    EXPECT_TRUE(tree.solid({1.5, 0.6}));
  }
  {
    // The first two lie along part of x + y = 2, on the same side.
    const std::vector<BspPolygon> polys{tri({2, 0}, {2, 1}, {0, 2}), tri({1, 1}, {0, 2}, {1, 2}),
                                        tri({0, 0}, {1, 0}, {2, 1})};
    const BspTree tree = BspTree::build(polys);
    EXPECT_FALSE(tree.solid({-0.5, -0.25}));
    EXPECT_FALSE(tree.solid({0.5, 1}));
    EXPECT_FALSE(tree.solid({-1, 1}));
    EXPECT_TRUE(tree.solid({1.5, 1}));
  }
  // Layers of one to eight triangles on a 4 x 4 grid, every point of a quarter grid off the
  // borders as brute force says.
  for (std::uint64_t seed = 0; seed < 300; ++seed) {
    std::mt19937_64 rng(seed);
    const auto pick = [&](int lo, int hi) {
      return std::uniform_int_distribution<int>(lo, hi)(rng);
    };
    std::vector<BspPolygon> polys;
    std::vector<Point2> used;
    const int n = pick(1, 8);
    while (static_cast<int>(polys.size()) < n) {
      std::vector<Point2> r;
      for (int i = 0; i < 3; ++i)
        r.push_back(!used.empty() && pick(0, 2) == 0
                        ? used[std::size_t(pick(0, int(used.size()) - 1))]
                        : Point2{double(pick(0, 3)), double(pick(0, 3))});
      if (orientation(r[0], r[1], r[2]) == Orientation::collinear) continue;
      used.insert(used.end(), r.begin(), r.end());
      polys.push_back({std::move(r), {}});
    }
    const BspTree tree = BspTree::build(polys);
    tree.validate();
    for (int xi = -2; xi <= 14; ++xi)
      for (int yi = -2; yi <= 14; ++yi) {
        const Point2 p{xi * 0.25, yi * 0.25};
        bool border = false;
        test::for_each_edge(std::span<const BspPolygon>(polys),
                            [&](const Point2& a, const Point2& b) {
                              border = border || test::on_segment(p, a, b);
                            });
        if (border) continue;
        ASSERT_EQ(tree.solid(p), in_solid(polys, p))
            << "seed " << seed << " at " << p[0] << "," << p[1];
      }
  }
}

// Triangles with integer vertices scaled by 0.1 (rounded): edges of different triangles along
// one line, through a shared vertex and facing opposite ways, part by an ulp. The solid cell
// between them, a spike of that width, was rounded away by the clipping and got no bevels, so
// that its shifted copy reached along the whole line.
TEST(BspTree, SpikeBetweenNearlyOppositeEdges) {
  const int raw[6][6] = {{4, 6, 5, 4, 10, 4}, {5, 10, 6, 3, 9, 3},   {4, 6, 1, 9, 2, 10},
                         {2, 10, 5, 4, 0, 4}, {10, 10, 8, 6, 2, 10}, {5, 9, 2, 10, 5, 4}};
  std::vector<BspPolygon> polys;
  for (const auto& r : raw)
    polys.push_back(
        {{{r[0] * 0.1, r[1] * 0.1}, {r[2] * 0.1, r[3] * 0.1}, {r[4] * 0.1, r[5] * 0.1}}, {}});
  const BspTree tree = BspTree::build(polys);
  tree.validate();
  const double grow = 1 / std::cos(BspParams{}.bevel_angle / 2);
  // The line through (0.2, 1) and (0.4, 0.6), beyond the triangles.
  for (const double x : {0.15, 0.1, 0.0, -0.5, -1.0}) {
    const Point2 p{x, 1 + (0.2 - x) * 2};
    ASSERT_FALSE(in_solid(polys, p));
    EXPECT_FALSE(tree.solid(p)) << x;
    EXPECT_EQ(tree.overlaps(p, BspCircle{0.01}), dist_to_edges(polys, p) <= 0.01 * grow) << x;
  }
  EXPECT_FALSE(tree.overlaps({-1, 3.4}, BspCircle{0.01}));
  EXPECT_TRUE(tree.solid({0.6, 0.45}));
  EXPECT_TRUE(tree.solid({0.3, 0.9}));
  // Moving along the line towards the triangles: the first impact within the bevel error.
  for (const double r : {0.01, 0.05}) {
    const Point2 from{-1, 3.4}, to{0.35, 0.7};
    const BspHit h = tree.trace(from, to, BspCircle{r});
    const double late = first_contact_circle(polys, from, to, r);
    const double early = first_contact_circle(polys, from, to, r * grow);
    ASSERT_LE(late, 1);
    ASSERT_TRUE(h.hit) << r;
    EXPECT_LE(h.t, late + 1e-9) << r;
    EXPECT_GE(h.t, early - 1e-9) << r;
    EXPECT_GT(h.t, 0.8) << r;
  }
}

// Layers of one to six triangles with vertices on a 10 x 10 grid, some shared, scaled by 0.1
// (every coordinate rounded): points of a quarter grid off the borders read as brute force
// says, circles of radius 0.01 at each overlap within the bevel error, and moves along the
// lines through vertices meet the solid within it. Seven of these layers went wrong: spikes
// that lost their cells, and thin cells between nearly collinear edges decided at their
// piece's middle rounded off them (a sliver along a line read solid).
TEST(BspTree, ScaledGridLayersLikeBruteForce) {
  const double grow = 1 / std::cos(BspParams{}.bevel_angle / 2);
  const double r = 0.01;
  for (std::uint64_t seed = 430; seed < 680; ++seed) {
    std::mt19937_64 rng(seed);
    const auto pick = [&](int lo, int hi) {
      return std::uniform_int_distribution<int>(lo, hi)(rng);
    };
    std::vector<BspPolygon> polys;
    std::vector<Point2> grid, used;
    const int n = pick(1, 6);
    while (static_cast<int>(polys.size()) < n) {
      std::vector<Point2> t;
      for (int i = 0; i < 3; ++i)
        t.push_back(!grid.empty() && pick(0, 2) == 0
                        ? grid[std::size_t(pick(0, int(grid.size()) - 1))]
                        : Point2{double(pick(0, 10)), double(pick(0, 10))});
      if (orientation(t[0], t[1], t[2]) == Orientation::collinear) continue;
      grid.insert(grid.end(), t.begin(), t.end());
      for (Point2& v : t)
        v = Point2{v[0] * 0.1, v[1] * 0.1};
      used.insert(used.end(), t.begin(), t.end());
      polys.push_back({std::move(t), {}});
    }
    const BspTree tree = BspTree::build(polys);
    tree.validate();
    for (int xi = -2; xi <= 42; ++xi)
      for (int yi = -2; yi <= 42; ++yi) {
        const Point2 p{xi * 0.025, yi * 0.025};
        const auto at = [&] { return testing::Message() << seed << " at " << p[0] << "," << p[1]; };
        const bool in = in_solid(polys, p);
        const double edge = dist_to_edges(polys, p), d = in ? 0 : edge;
        if (edge > 1e-9) {
          ASSERT_EQ(tree.solid(p), in) << at();
        }
        const bool got = tree.overlaps(p, BspCircle{r});
        if (d < r * (1 - 1e-9)) {
          ASSERT_TRUE(got) << at();
        }
        if (d > r * grow * (1 + 1e-9)) {
          ASSERT_FALSE(got) << at();
        }
      }
    for (int q = 0; q < 10; ++q) {
      const Point2 a = used[rng() % used.size()], b = used[rng() % used.size()];
      if (a == b) continue;
      const Point2 from{a[0] + 3 * (a[0] - b[0]), a[1] + 3 * (a[1] - b[1])};
      const Point2 to{b[0] + 0.5 * (b[0] - a[0]), b[1] + 0.5 * (b[1] - a[1])};
      const double rr = q % 2 ? r : r / 5;
      const BspHit h = tree.trace(from, to, BspCircle{rr});
      const double late = first_contact_circle(polys, from, to, rr);
      const double early = first_contact_circle(polys, from, to, rr * grow + 1e-12);
      const auto at = [&] { return testing::Message() << seed << " move " << q; };
      if (late <= 1) {
        ASSERT_TRUE(h.hit) << at();
        ASSERT_LE(h.t, late + 1e-9) << at();
      }
      if (h.hit) {
        ASSERT_GE(h.t, early - 1e-9) << at();
      }
    }
  }
}

// Three collinear grid points scaled by 0.1 make a triangle of an ulp's width, which the
// thin cells along it lost (a circle of radius 0.01 on it met nothing; a front cell thinner
// than 1e-12 was taken for one of no area), and which the sign of its rounded area turned
// inside out for one in ten (everything around it solid) or, where that area rounds to 0,
// refused.
TEST(BspTree, SliverTrianglesOfScaledCollinearPoints) {
  int slivers = 0, zero_area = 0;
  for (int ax = 0; ax <= 10; ++ax)
    for (int ay = 0; ay <= 10; ++ay)
      for (int dx = 1; dx <= 3; ++dx)
        for (int dy = -3; dy <= 3; ++dy) {
          const int cx = ax + 3 * dx, cy = ay + 3 * dy;
          if (cx > 10 || cy < 0 || cy > 10) continue;
          const std::vector<Point2> t{
              {ax * 0.1, ay * 0.1}, {(ax + dx) * 0.1, (ay + dy) * 0.1}, {cx * 0.1, cy * 0.1}};
          if (orientation(t[0], t[1], t[2]) == Orientation::collinear) continue;
          ++slivers;
          zero_area += detail::bsp_signed_area(t) == 0;
          // Alone, and crossed by another triangle.
          for (const bool crossed : {false, true}) {
            std::vector<BspPolygon> polys{{t, {}}};
            if (crossed) polys.push_back({{{0, 1}, {0.3, 0.4}, {0.2, 0.1}}, {}});
            const BspTree tree = BspTree::build(polys);
            tree.validate();
            const Point2 mid{(t[0][0] + t[2][0]) / 2, (t[0][1] + t[2][1]) / 2};
            for (const Point2& p : {t[0], t[1], t[2], mid})
              ASSERT_TRUE(tree.overlaps(p, BspCircle{0.01}))
                  << ax << "," << ay << " " << dx << "," << dy << " at " << p[0] << "," << p[1];
            EXPECT_TRUE(tree.solid(t[1])) << ax << "," << ay << " " << dx << "," << dy;
            for (const Point2& far : {Point2{-0.5, -0.5}, Point2{1.5, 1.5}, Point2{-0.5, 1.5}})
              EXPECT_FALSE(tree.overlaps(far, BspCircle{0.01}))
                  << ax << "," << ay << " " << dx << "," << dy;
          }
        }
  EXPECT_GT(slivers, 50);
  EXPECT_GT(zero_area, 5);  // their area rounds to 0; they were refused
  // Along another triangle's edge, facing the same way.
  const auto at = [](int x, int y) { return Point2{x * 0.37, y * 0.37}; };
  const std::vector<BspPolygon> polys{{{at(10, 2), at(2, 10), at(9, 3)}, {}},
                                      {{at(8, 4), at(1, 8), at(10, 2)}, {}}};
  const BspTree tree = BspTree::build(polys);
  for (int i = 4; i <= 18; ++i)
    EXPECT_TRUE(tree.overlaps({i * 0.5 * 0.37, (12 - i * 0.5) * 0.37}, BspCircle{0.0037})) << i;
}

// A layer scaled by a power of two is the same layer: its tree answers alike at the scaled
// points, down to coordinates near 1e-301, where areas underflow to 0 (such layers were
// refused as having no area) and products of differences lose digits.
TEST(BspTree, LayersScaledTowardsUnderflowAnswerAlike) {
  int compared = 0;
  for (std::uint64_t seed = 1; seed < 60; ++seed) {
    std::mt19937_64 rng(seed);
    const auto pick = [&](int lo, int hi) {
      return std::uniform_int_distribution<int>(lo, hi)(rng);
    };
    std::vector<BspPolygon> polys;
    const int n = pick(1, 6);
    while (static_cast<int>(polys.size()) < n) {
      std::vector<Point2> t;
      for (int i = 0; i < 3; ++i)
        t.push_back({pick(0, 10) * 0.1, pick(0, 10) * 0.1});
      if (orientation(t[0], t[1], t[2]) == Orientation::collinear) continue;
      polys.push_back({std::move(t), {}});
    }
    const BspTree base = BspTree::build(polys);
    for (const int e : {-660, -1000}) {
      const auto scaled = [e](const Point2& p) {
        return Point2{std::ldexp(p[0], e), std::ldexp(p[1], e)};
      };
      std::vector<BspPolygon> small = polys;
      for (BspPolygon& p : small)
        for (Point2& v : p.outer)
          v = scaled(v);
      const BspTree tree = BspTree::build(small);
      tree.validate();
      for (int xi = -1; xi <= 21; ++xi)
        for (int yi = -1; yi <= 21; ++yi) {
          const Point2 p{xi * 0.05, yi * 0.05};
          ++compared;
          ASSERT_EQ(tree.solid(scaled(p)), base.solid(p)) << seed << " 2^" << e;
          ASSERT_EQ(tree.overlaps(scaled(p), BspCircle{std::ldexp(0.01, e)}),
                    base.overlaps(p, BspCircle{0.01}))
              << seed << " 2^" << e;
        }
    }
  }
  EXPECT_GT(compared, 50000);
}

// The origin as a vertex of a triangle or a point of its edge: the rounding of the planes
// there is that of the layer's coordinates, while the query and the planes' offsets are near
// 0; one triangle in six read its vertex at the origin as not solid.
TEST(BspTree, BoundaryPointsAtTheOrigin) {
  std::mt19937_64 rng(43);
  std::uniform_real_distribution<double> u(-100, 100);
  std::uniform_int_distribution<int> g(1, 50);
  int built = 0;
  for (int k = 0; k < 3000; ++k) {
    std::vector<Point2> t;
    if (k % 2) {
      t = {{0, 0}, {u(rng), u(rng)}, {u(rng), u(rng)}};
    } else {  // the origin inside the edge from -m p to q p
      const double px = g(rng), py = g(rng) - 25, m = g(rng), q = g(rng);
      t = {{-px * m, -py * m}, {px * q, py * q}, {u(rng), u(rng)}};
    }
    std::rotate(t.begin(), t.begin() + k % 3, t.end());
    if (orientation(t[0], t[1], t[2]) == Orientation::collinear) continue;
    const std::vector<BspPolygon> polys{{t, {}}};
    const BspTree tree = BspTree::build(polys);
    ++built;
    ASSERT_TRUE(tree.solid({0, 0})) << k;
    // Just outside, by 1e-9 along the edges' outward normal at the origin's side.
    const Point2 c{(t[0][0] + t[1][0] + t[2][0]) / 3, (t[0][1] + t[1][1] + t[2][1]) / 3};
    const double len = std::hypot(c[0], c[1]);
    const Point2 out{-c[0] / len * 1e-9, -c[1] / len * 1e-9};
    if (!in_solid(polys, out) && dist_to_edges(polys, out) > 1e-10) {
      ASSERT_FALSE(tree.solid(out)) << k;
    }
  }
  EXPECT_GT(built, 2900);
}

TEST(BspTree, VerticesAndBordersCountAsSolid) {
  const auto polys = random_layer(4);
  const BspTree tree = BspTree::build(polys);
  for (const BspPolygon& p : polys) {
    for (const Point2& v : p.outer)
      EXPECT_TRUE(tree.overlaps(v, BspCircle{1e-9}));
    for (const auto& h : p.holes)
      for (const Point2& v : h)
        EXPECT_TRUE(tree.overlaps(v, BspCircle{1e-9}));
  }
}

TEST(BspTree, SharedBordersLeaveOnlyTheOutline) {
  std::vector<BspPolygon> polys;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j)
      polys.push_back(
          {{{1.0 * i, 1.0 * j}, {i + 1.0, 1.0 * j}, {i + 1.0, j + 1.0}, {1.0 * i, j + 1.0}}, {}});
  const BspTree tree = BspTree::build(polys);
  tree.validate();
  EXPECT_EQ(tree.edges(), 40u);
  EXPECT_TRUE(tree.solid({5, 5}));
  EXPECT_TRUE(tree.solid({3, 4}));  // on an inner border
  EXPECT_FALSE(tree.solid({-0.5, 5}));
  EXPECT_FALSE(tree.solid({10.5, 5}));
  // A circle moving right along y = 5 from x = -5 meets the block at x = -r.
  const BspHit h = tree.trace({-5, 5}, {5, 5}, BspCircle{1});
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.point[0], -1, 1e-12);
  EXPECT_NEAR(h.normal[0], -1, 1e-12);
  EXPECT_NEAR(h.normal[1], 0, 1e-12);
}

// The guarantee of the header: never later than the exact first contact of the shape, never
// earlier than that of a disc of radius R / cos(alpha / 2).
void expect_within_bevel_error(const std::vector<BspPolygon>& polys, const BspTree& tree,
                               double alpha, std::uint64_t seed, int moves) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-5, 85), len(0, 30), ang(0, 2 * std::numbers::pi),
      rad(0, 3);
  const double grow = 1 / std::cos(alpha / 2);
  const double tol = 1e-9;
  int hits = 0, inside = 0;
  for (int q = 0; q < moves; ++q) {
    const Point2 from{u(rng), u(rng)};
    const double a = ang(rng), l = len(rng);
    const Point2 to{from[0] + l * std::cos(a), from[1] + l * std::sin(a)};
    const int shape = q % 3;
    BspHit h;
    double late = 0, early = 0;
    if (shape == 0) {  // circle
      const double r = rad(rng);
      h = tree.trace(from, to, BspCircle{r});
      late = first_contact_circle(polys, from, to, r);
      early = first_contact_circle(polys, from, to, r * grow);
    } else if (shape == 1) {  // box
      const Point2 half{rad(rng), rad(rng)};
      h = tree.trace(from, to, BspBox{half});
      late = first_contact_box(polys, from, to, half);
      early = first_contact_circle(polys, from, to, std::hypot(half[0], half[1]) * grow);
    } else {  // a box whose reference point is its lower left corner
      const Point2 half{rad(rng), rad(rng)};
      const BspConvex k{{{0, 0}, {2 * half[0], 0}, {2 * half[0], 2 * half[1]}, {0, 2 * half[1]}}};
      h = tree.trace(from, to, k);
      const Point2 f2{from[0] + half[0], from[1] + half[1]}, t2{to[0] + half[0], to[1] + half[1]};
      late = first_contact_box(polys, f2, t2, half);
      early = first_contact_circle(polys, f2, t2, std::hypot(half[0], half[1]) * grow);
    }
    SCOPED_TRACE(testing::Message() << "move " << q << " shape " << shape << " from " << from[0]
                                    << "," << from[1] << " to " << to[0] << "," << to[1]);
    if (late <= 1) {
      ASSERT_TRUE(h.hit);
      ASSERT_LE(h.t, late + tol);
    }
    if (h.hit) {
      ++hits;
      ASSERT_LE(early, h.t + tol);
      EXPECT_NEAR(h.point[0], from[0] + h.t * (to[0] - from[0]), 1e-9);
      if (h.started_inside) {
        ++inside;
        EXPECT_EQ(h.t, 0);
      } else {
        EXPECT_NEAR(std::hypot(h.normal[0], h.normal[1]), 1, 1e-12);
        // The plane of impact faces the motion.
        EXPECT_LE(h.normal[0] * (to[0] - from[0]) + h.normal[1] * (to[1] - from[1]), 1e-9);
      }
    } else {
      EXPECT_EQ(h.t, 1);
    }
  }
  EXPECT_GT(hits, moves / 5);
  EXPECT_GT(inside, 0);
  EXPECT_LT(inside, hits);
}

TEST(BspTree, FirstImpactWithinBevelErrorDefault) {
  for (std::uint64_t seed : {11, 12}) {
    const auto polys = random_layer(seed);
    const BspTree tree = BspTree::build(polys);
    tree.validate();
    EXPECT_GT(tree.bevel_count(), 0u);
    expect_within_bevel_error(polys, tree, BspParams{}.bevel_angle, seed, 1500);
  }
}

TEST(BspTree, FirstImpactWithinBevelErrorOverlapping) {
  const auto polys = overlapping_layer(23);
  const BspTree tree = BspTree::build(polys);
  expect_within_bevel_error(polys, tree, BspParams{}.bevel_angle, 23, 1000);
}

TEST(BspTree, FirstImpactWithinBevelErrorCoarseBevels) {
  const auto polys = random_layer(13);
  BspParams params;
  params.bevel_angle = std::numbers::pi / 2;
  const BspTree tree = BspTree::build(polys, params);
  tree.validate();
  expect_within_bevel_error(polys, tree, params.bevel_angle, 13, 1500);
  // Finer bevels cost nodes.
  EXPECT_LT(tree.node_count(), BspTree::build(polys).node_count());
}

TEST(BspTree, WithoutBevelsNothingIsMissed) {
  const auto polys = random_layer(14);
  BspParams params;
  params.bevel_angle = std::numbers::pi;
  const BspTree tree = BspTree::build(polys, params);
  EXPECT_EQ(tree.bevel_count(), 0u);
  std::mt19937_64 rng(14);
  std::uniform_real_distribution<double> u(-5, 85), rad(0, 3);
  for (int q = 0; q < 800; ++q) {
    const Point2 from{u(rng), u(rng)}, to{u(rng), u(rng)};
    const double r = rad(rng);
    const double late = first_contact_circle(polys, from, to, r);
    const BspHit h = tree.trace(from, to, BspCircle{r});
    if (late <= 1) {
      ASSERT_TRUE(h.hit);
      ASSERT_LE(h.t, late + 1e-9);
    }
  }
}

TEST(BspTree, PointTracesAreExact) {
  const auto polys = random_layer(15);
  const BspTree tree = BspTree::build(polys);
  std::mt19937_64 rng(15);
  std::uniform_real_distribution<double> u(-5, 85);
  for (int q = 0; q < 2000; ++q) {
    const Point2 from{u(rng), u(rng)}, to{u(rng), u(rng)};
    const double want = first_contact_circle(polys, from, to, 0);
    const BspHit h = tree.trace(from, to, BspPoint{});
    if (want <= 1) {
      ASSERT_TRUE(h.hit) << q;
      ASSERT_NEAR(h.t, want, 1e-9) << q;
    } else {
      ASSERT_FALSE(h.hit) << q;
    }
  }
}

TEST(BspTree, StationaryOverlapWithinBevelError) {
  const auto polys = random_layer(16);
  const BspTree tree = BspTree::build(polys);
  const double grow = 1 / std::cos(BspParams{}.bevel_angle / 2);
  std::mt19937_64 rng(16);
  std::uniform_real_distribution<double> u(-5, 85), rad(0, 3);
  int yes = 0, no = 0;
  for (int q = 0; q < 5000; ++q) {
    const Point2 p{u(rng), u(rng)};
    const double r = rad(rng);
    const double dist = in_solid(polys, p) ? 0 : dist_to_edges(polys, p);
    const bool got = tree.overlaps(p, BspCircle{r});
    if (dist <= r * (1 - 1e-12)) ASSERT_TRUE(got) << q;
    if (dist > r * grow * (1 + 1e-12)) ASSERT_FALSE(got) << q;
    (got ? yes : no)++;
  }
  EXPECT_GT(yes, 500);
  EXPECT_GT(no, 500);
}

TEST(BspTree, SlideAlongAWall) {
  // Solid below y = 0; a circle of radius 1 moving down and right hits at (4, 1) halfway and
  // slides along the wall for the rest of its move.
  const std::vector<BspPolygon> polys{{{{-50, -10}, {50, -10}, {50, 0}, {-50, 0}}, {}}};
  const BspTree tree = BspTree::build(polys);
  const BspHit h = tree.trace({2, 5}, {6, -3}, BspCircle{1});
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.t, 0.5, 1e-12);
  EXPECT_NEAR(h.point[0], 4, 1e-12);
  EXPECT_NEAR(h.point[1], 1, 1e-12);
  EXPECT_NEAR(h.normal[1], 1, 1e-12);
  const BspSlide s = tree.slide({2, 5}, {6, -3}, BspCircle{1});
  EXPECT_EQ(s.contacts, 1);
  EXPECT_FALSE(s.stuck);
  EXPECT_NEAR(s.position[0], 6, 1e-6);
  EXPECT_NEAR(s.position[1], 1, 1e-6);
  EXPECT_GE(s.position[1], 1);
}

TEST(BspTree, SlidesNeverEndInsideTheSolid) {
  const auto polys = random_layer(17);
  const BspTree tree = BspTree::build(polys);
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(-5, 85), rad(0.1, 2);
  int contacts = 0;
  for (int q = 0; q < 600; ++q) {
    const Point2 from{u(rng), u(rng)}, to{u(rng), u(rng)};
    const double r = rad(rng);
    if (tree.overlaps(from, BspCircle{r})) continue;
    const BspSlide s = tree.slide(from, to, BspCircle{r});
    contacts += s.contacts;
    ASSERT_FALSE(tree.overlaps(s.position, BspCircle{r})) << q;
    ASSERT_EQ(first_contact_circle(polys, s.position, s.position, r), kNever) << q;
  }
  EXPECT_GT(contacts, 100);
}

TEST(BspTree, DeepChainOfAConvexPolygon) {
  // A regular 2,000-gon: every edge's line leaves all the others behind it.
  std::vector<Point2> ring;
  for (int i = 0; i < 2000; ++i) {
    const double a = 2 * std::numbers::pi * i / 2000;
    ring.push_back({100 * std::cos(a), 100 * std::sin(a)});
  }
  const std::vector<BspPolygon> polys{{ring, {}}};
  const BspTree tree = BspTree::build(polys);
  tree.validate();
  EXPECT_TRUE(tree.solid({0, 0}));
  EXPECT_FALSE(tree.solid({99.99, 99.99}));
  const BspHit h = tree.trace({-300, 0}, {300, 0}, BspCircle{5});
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.point[0], -105, 1e-3);
}

TEST(BspTree, EmptyLayerAndDegenerateMoves) {
  const BspTree none = BspTree::build(std::vector<BspPolygon>{});
  none.validate();
  EXPECT_TRUE(none.empty());
  EXPECT_FALSE(none.trace({0, 0}, {1, 1}, BspCircle{5}).hit);
  EXPECT_FALSE(none.solid({0, 0}));

  const std::vector<BspPolygon> polys{{{{0, 0}, {10, 0}, {10, 10}, {0, 10}}, {}}};
  const BspTree tree = BspTree::build(polys);
  // Starting inside.
  const BspHit in = tree.trace({5, 5}, {50, 50}, BspPoint{});
  EXPECT_TRUE(in.hit && in.started_inside);
  EXPECT_EQ(in.t, 0);
  EXPECT_EQ(in.normal[0], 0);
  // A move of length zero outside, and one touching a corner exactly.
  EXPECT_FALSE(tree.trace({20, 20}, {20, 20}, BspCircle{1}).hit);
  const BspHit corner = tree.trace({-1, 11}, {1, 9}, BspPoint{});
  ASSERT_TRUE(corner.hit);
  EXPECT_NEAR(corner.t, 0.5, 1e-12);
  // Moving along the wall at exactly the radius touches it all the way.
  EXPECT_TRUE(tree.trace({-5, 11}, {15, 11}, BspCircle{1}).hit);
  EXPECT_FALSE(tree.trace({-5, 11.001}, {15, 11.001}, BspCircle{1}).hit);
}

TEST(BspTree, RejectsBadInput) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  using V = std::vector<BspPolygon>;
  EXPECT_THROW(BspTree::build(V{{{{0, 0}, {1, 0}, {nan, 1}}, {}}}), InvalidGeometry);
  EXPECT_THROW(BspTree::build(V{{{{0, 0}, {1, 0}, {0, 0}}, {}}}), InvalidGeometry);
  EXPECT_THROW(BspTree::build(V{{{{0, 0}, {1, 1}, {2, 2}}, {}}}), InvalidGeometry);
  EXPECT_THROW(BspTree::build(V{{{{0, 0}, {1, 0}, {1, 1}}, {{{0, 0}}}}}), InvalidGeometry);
  BspParams bad;
  bad.bevel_angle = 0;
  EXPECT_THROW(BspTree::build(V{}, bad), InvalidArgument);
  bad.bevel_angle = 4;
  EXPECT_THROW(BspTree::build(V{}, bad), InvalidArgument);
  // Beyond 1e150: the root cell's margin overflowed (6e307 killed the process in GMP with an
  // infinity) and areas past 1.3e154 read as NaN ("no area").
  for (const double big : {6e307, 1e200, 2e150}) {
    EXPECT_THROW(BspTree::build(V{{{{-big, -big}, {big, -big}, {big, big}, {-big, big}}, {}}}),
                 InvalidGeometry)
        << big;
  }
  EXPECT_NO_THROW(BspTree::build(V{{{{-1e150, -1e150}, {1e150, -1e150}, {0, 1e150}}, {}}}));
  const BspTree tree = BspTree::build(V{{{{0, 0}, {1, 0}, {1, 1}}, {}}});
  EXPECT_THROW(tree.trace({nan, 0}, {1, 1}, BspPoint{}), InvalidGeometry);
  // (a move from 1.7e308 to -1.7e308 has no finite length: the contact came out NaN)
  EXPECT_THROW(tree.trace({1.7e308, 0.5}, {-1.7e308, 0.5}, BspPoint{}), InvalidGeometry);
  EXPECT_THROW(tree.trace({0.5, 0.5}, {2e150, 0.5}, BspCircle{1}), InvalidGeometry);
  EXPECT_THROW(tree.overlaps({5, 5}, BspCircle{1e151}), InvalidGeometry);
  // Shapes: a NaN, infinite or negative size, or a polygon without vertices, is refused.
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_THROW(tree.trace({5, 5}, {6, 6}, BspCircle{nan}), InvalidGeometry);
  EXPECT_THROW(tree.overlaps({5, 5}, BspCircle{inf}), InvalidGeometry);
  EXPECT_THROW(tree.overlaps({5, 5}, BspCircle{-1}), InvalidGeometry);
  EXPECT_THROW(tree.overlaps({5, 5}, BspBox{{1, nan}}), InvalidGeometry);
  EXPECT_THROW(tree.overlaps({5, 5}, BspBox{{-1, 1}}), InvalidGeometry);
  EXPECT_THROW(tree.overlaps({5, 5}, BspConvex{}), InvalidGeometry);
  EXPECT_THROW(tree.slide({5, 5}, {6, 6}, BspConvex{{{0, 0}, {nan, 1}}}), InvalidGeometry);
  // Sizes of zero are points, and a polygon away from its reference point is a shape too.
  EXPECT_FALSE(tree.overlaps({5, 5}, BspCircle{0}));
  EXPECT_TRUE(tree.overlaps({0.9, 0.1}, BspBox{{0, 0}}));
  EXPECT_TRUE(tree.overlaps({5, 5}, BspConvex{{{-4.5, -4.9}, {-4.4, -4.9}, {-4.4, -4.8}}}));
}

// Polygons whose edges cross, or run along each other over a stretch, are refused, with the
// polygon and rings named: the inside changes sides along such an edge at a point no double
// holds. Before, the edges were taken to have the inside on their left and regions far from
// every polygon were called solid (a hole along part of its outer ring's side made
// solid(-100, 3) true).
TEST(BspTree, RefusesEdgesThatCrossOrRunAlongEachOther) {
  using V = std::vector<BspPolygon>;
  using R = std::vector<Point2>;
  const R square{{0, 0}, {10, 0}, {10, 10}, {0, 10}};
  auto refused = [](const V& layer, const char* says) {
    try {
      BspTree::build(layer);
    } catch (const InvalidGeometry& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
      return true;
    }
    return false;
  };
  // A hole along part of the outer ring's side (a notch), a ring doubling back along itself.
  EXPECT_TRUE(refused(V{{square, {R{{0, 2}, {3, 4}, {0, 6}}}}},
                      "the outer ring and hole 0 of polygon 0 run along each other"));
  EXPECT_TRUE(refused(V{{R{{0, 0}, {10, 0}, {5, 0}, {5, 5}}, {}}}, "runs along itself"));
  // A bow-tie outer ring, a hole crossing its outer ring, two holes crossing.
  EXPECT_TRUE(refused(V{{R{{0, 0}, {4, 4}, {4, 0}, {0, 6}}, {}}}, "crosses itself"));
  EXPECT_TRUE(refused(V{{square, {R{{8, 4}, {12, 4}, {12, 6}, {8, 6}}}}}, "cross"));
  EXPECT_TRUE(refused(V{{square, {R{{2, 2}, {5, 2}, {5, 5}}, R{{4, 1}, {6, 1}, {6, 4}, {4, 4}}}}},
                      "hole 0 and hole 1 of polygon 0 cross"));
  // The polygon is named by its index; polygons may cross one another.
  EXPECT_TRUE(refused(V{{square, {}}, {square, {R{{8, 4}, {12, 4}, {12, 6}, {8, 6}}}}},
                      "of polygon 1 cross"));
  EXPECT_NO_THROW(BspTree::build(V{{square, {}}, {R{{8, 4}, {12, 4}, {12, 6}, {8, 6}}, {}}}));
}

// Rings that touch at points, holes outside their outer ring or inside other holes, rings
// winding twice, edges given twice: each polygon is what the even-odd rule over its rings
// encloses, as the layer queries read it (a hole outside its outer ring is an island, a ring
// winding twice round a region leaves a lake, an edge given twice cancels). Points of a
// quarter-step grid through every vertex are classified as crossing parity classifies them.
TEST(BspTree, PolygonsAreWhatTheEvenOddRuleEncloses) {
  using V = std::vector<BspPolygon>;
  using R = std::vector<Point2>;
  const R square{{0, 0}, {10, 0}, {10, 10}, {0, 10}};
  const std::vector<V> layers{
      // A hole touching its outer ring's side; an outer ring touching itself round a hole.
      V{{square, {R{{0, 5}, {4, 3}, {4, 7}}}}},
      V{{R{{0, 0}, {10, 0}, {10, 10}, {5, 10}, {7, 5}, {3, 5}, {5, 10}, {0, 10}}, {}}},
      // Holes touching each other.
      V{{square, {R{{2, 2}, {4, 2}, {4, 4}, {2, 4}}, R{{4, 4}, {6, 4}, {6, 6}, {4, 6}}}}},
      V{{square, {R{{2, 2}, {4, 2}, {4, 4}}, R{{4, 4}, {8, 8}, {4, 8}}}}},
      // Holes outside the outer ring, apart and touching it: islands.
      V{{square, {R{{12, 0}, {14, 0}, {14, 2}}}}}, V{{square, {R{{10, 5}, {12, 4}, {12, 6}}}}},
      // A hole inside another hole: an island in the lake.
      V{{square, {R{{1, 1}, {9, 1}, {9, 9}, {1, 9}}, R{{3, 3}, {7, 3}, {7, 7}}}}},
      // An outer ring winding twice round a region through a shared vertex: a lake.
      V{{R{{0, 0}, {10, 0}, {10, 10}, {0, 10}, {0, 0}, {2, 1}, {8, 1}, {8, 8}, {1, 8}}, {}}},
      // Overlapping polygons, one with a hole.
      V{{square, {}}, {R{{5, 5}, {15, 5}, {15, 15}, {5, 15}}, {R{{6, 6}, {9, 6}, {9, 9}}}}}};
  for (std::size_t k = 0; k < layers.size(); ++k) {
    BspTree tree;
    ASSERT_NO_THROW(tree = BspTree::build(layers[k])) << k;
    tree.validate();
    for (int i = -4; i <= 64; ++i)
      for (int j = -4; j <= 64; ++j) {
        const Point2 p{i * 0.25, j * 0.25};
        ASSERT_EQ(tree.solid(p), test::in_solid(layers[k], p)) << k << ": " << p[0] << "," << p[1];
      }
  }
  EXPECT_TRUE(BspTree::build(layers[4]).solid({13.5, 0.5}));
  EXPECT_FALSE(BspTree::build(layers[7]).solid({5, 5}));
  // A hole sharing a side with the outer ring, an edge given twice: they cancel, and the solid
  // is the rest.
  const BspTree notch = BspTree::build(V{{square, {R{{0, 0}, {0, 10}, {5, 5}}}}});
  EXPECT_FALSE(notch.solid({1, 5}));
  EXPECT_FALSE(notch.solid({-100, 3}));
  EXPECT_TRUE(notch.solid({1, 0.5}));
  EXPECT_TRUE(notch.solid({6, 5}));
  const BspTree twice =
      BspTree::build(V{{R{{0, 0}, {10, 0}, {10, 10}, {0, 0}, {10, 0}, {5, -5}}, {}}});
  EXPECT_TRUE(twice.solid({5, 0}));
  EXPECT_TRUE(twice.solid({9, 1}));
  EXPECT_TRUE(twice.solid({5, -1}));
  EXPECT_FALSE(twice.solid({20, 0}));
}

}  // namespace
}  // namespace loci
