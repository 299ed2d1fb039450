// BspTree on the bundled Natural Earth sample (land polygons around Denmark, countries
// sharing borders): points classified as GDAL/GEOS classify them, and vessel-sized circles
// moving over the sea hit the coast within the bevel error of the exact answer.
#include <cpl_error.h>
#include <gtest/gtest.h>
#include <ogr_geometry.h>

#include <cmath>
#include <iomanip>
#include <iostream>
#include <random>

#include "loci/index/broadphase/bsp_tree.hpp"
#include "support/layer_polygons.hpp"
#include "support/solid_reference.hpp"

namespace loci {
namespace {

const std::string kSample = std::string(LOCI_DATASETS_DIR) + "/samples/coastline-denmark.geojson";

// The rings of p, closed, added to the OGR polygon g (for GEOS's answers).
void add_ogr_rings(const BspPolygon& p, OGRPolygon& g) {
  auto ring = [](const std::vector<Point2>& r) {
    auto* lr = new OGRLinearRing;
    for (const Point2& v : r)
      lr->addPoint(v[0], v[1]);
    lr->closeRings();
    return lr;
  };
  g.addRingDirectly(ring(p.outer));
  for (const auto& h : p.holes)
    g.addRingDirectly(ring(h));
}

TEST(BspLayer, PointsAsGeosSays) {
  const auto polys = test::read_polygons(kSample);
  ASSERT_GT(polys.size(), 100u);
  const BspTree tree = BspTree::build(polys);
  tree.validate();
  // GEOS through OGR: some polygon contains the point (boundary included).
  std::vector<OGRPolygon> all;
  for (const BspPolygon& p : polys) {
    add_ogr_rings(p, all.emplace_back());
  }
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> lon(7, 16), lat(53.5, 58.5);
  int land = 0, checked = 0;
  for (int q = 0; q < 3000; ++q) {
    const Point2 p{lon(rng), lat(rng)};
    OGRPoint pt(p[0], p[1]);
    bool want = false;
    for (const OGRPolygon& g : all)
      want = want || g.Intersects(&pt);
    ASSERT_EQ(tree.solid(p), want) << p[0] << "," << p[1];
    ASSERT_EQ(test::in_solid(polys, p), want);
    land += want;
    ++checked;
  }
  EXPECT_GT(land, 300);
  EXPECT_LT(land, checked - 300);
}

TEST(BspLayer, VesselsHitTheCoastWithinTheBevelError) {
  const auto polys = test::read_polygons(kSample);
  const BspTree tree = BspTree::build(polys);
  const double grow = 1 / std::cos(BspParams{}.bevel_angle / 2);
  std::mt19937_64 rng(43);
  std::uniform_real_distribution<double> lon(7, 16), lat(53.5, 58.5), len(0, 0.3),
      ang(0, 2 * std::numbers::pi), rad(0.001, 0.03);
  int hits = 0;
  for (int q = 0; q < 400; ++q) {
    const Point2 from{lon(rng), lat(rng)};
    const double r = rad(rng), a = ang(rng), l = len(rng);
    if (tree.overlaps(from, BspCircle{r})) continue;
    const Point2 to{from[0] + l * std::cos(a), from[1] + l * std::sin(a)};
    const BspHit h = tree.trace(from, to, BspCircle{r});
    const double late = test::first_contact_circle(polys, from, to, r);
    const double early = test::first_contact_circle(polys, from, to, r * grow);
    if (late <= 1) {
      ASSERT_TRUE(h.hit) << q << " from " << std::setprecision(17) << from[0] << "," << from[1]
                         << " to " << to[0] << "," << to[1] << " r " << r << " late " << late;
      ASSERT_LE(h.t, late + 1e-9) << q;
    }
    if (h.hit) {
      ++hits;
      ASSERT_LE(early, h.t + 1e-9) << q;
    }
  }
  EXPECT_GT(hits, 20);
}

// Random polygons on a small grid (rings touching, crossing, sharing edges, holes anywhere):
// every polygon GEOS calls valid is built, and every polygon built answers, at every point of
// a half-step grid through its vertices and edges, as crossing parity over its rings does
// (the points on an edge the polygon has twice excepted: the tree leaves such an edge out).
TEST(BspLayer, RandomPolygonsBuiltWhenValidAndAnsweredExactly) {
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<int> coord(0, 6), count(3, 6), holes(0, 2);
  auto ring = [&](int n) {
    std::vector<Point2> r;
    for (int i = 0; i < n; ++i)
      r.push_back({static_cast<double>(coord(rng)), static_cast<double>(coord(rng))});
    return r;
  };
  int valid = 0, built = 0, built_invalid = 0;
  CPLPushErrorHandler(CPLQuietErrorHandler);  // GEOS's complaints about rings of two points
  for (int q = 0; q < 4000; ++q) {
    BspPolygon poly{ring(count(rng)), {}};
    for (int h = holes(rng); h > 0; --h)
      poly.holes.push_back(ring(count(rng) - 1));
    const std::vector<BspPolygon> layer{poly};
    OGRPolygon g;
    add_ogr_rings(poly, g);
    const bool geos_valid = g.IsValid();
    BspTree tree;
    bool ok = true;
    try {
      tree = BspTree::build(layer);
    } catch (const InvalidGeometry&) {
      ok = false;
    }
    valid += geos_valid;
    ASSERT_TRUE(ok || !geos_valid) << "refused a valid polygon, case " << q;
    if (!ok) continue;
    ++built;
    built_invalid += !geos_valid;
    tree.validate();
    // Edges that cancel against their reverse.
    std::vector<std::pair<Point2, Point2>> edges, cancelled;
    test::for_each_edge(std::span<const BspPolygon>(layer), [&](const Point2& a, const Point2& b) {
      edges.push_back({a, b});
    });
    for (const auto& [a, b] : edges)
      for (const auto& [c, d] : edges)
        if ((a == d && b == c) || (&a != &c && a == c && b == d)) cancelled.push_back({a, b});
    for (int i = -2; i <= 14; ++i)
      for (int j = -2; j <= 14; ++j) {
        const Point2 p{i * 0.5, j * 0.5};
        bool skip = false;
        for (const auto& [a, b] : cancelled)
          skip = skip || test::on_segment(p, a, b);
        if (skip) continue;
        ASSERT_EQ(tree.solid(p), test::in_solid(layer, p))
            << "case " << q << ": " << p[0] << "," << p[1];
      }
  }
  CPLPopErrorHandler();
  // The cases cover each outcome.
  EXPECT_GT(valid, 300);
  EXPECT_GT(built_invalid, 50);
  EXPECT_GT(4000 - built, 1000);
  std::cout << valid << " valid by GEOS, " << built << " built (" << built_invalid
            << " of them invalid by GEOS)\n";
}

}  // namespace
}  // namespace loci
