// BspTree on the bundled Natural Earth sample (land polygons around Denmark, countries
// sharing borders): points classified as GDAL/GEOS classify them, and vessel-sized circles
// moving over the sea hit the coast within the bevel error of the exact answer.
#include <gtest/gtest.h>
#include <ogr_geometry.h>

#include <cmath>
#include <iomanip>
#include <random>

#include "loci/index/broadphase/bsp_tree.hpp"
#include "support/layer_polygons.hpp"
#include "support/solid_reference.hpp"

namespace loci {
namespace {

const std::string kSample = std::string(LOCI_DATASETS_DIR) + "/samples/coastline-denmark.geojson";

TEST(BspLayer, PointsAsGeosSays) {
  const auto polys = test::read_polygons(kSample);
  ASSERT_GT(polys.size(), 100u);
  const BspTree tree = BspTree::build(polys);
  tree.validate();
  // GEOS through OGR: some polygon contains the point (boundary included).
  std::vector<OGRPolygon> all;
  for (const BspPolygon& p : polys) {
    OGRPolygon& g = all.emplace_back();
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

}  // namespace
}  // namespace loci
