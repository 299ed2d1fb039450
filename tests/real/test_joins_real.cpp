// Joins and point location on Natural Earth's countries-land-10m (labelled large;real): the
// land polygons joined with themselves must give neighbouring countries as touching pairs, and
// the pairs of smaller features must agree with OGR's Intersects; point location in batch must
// agree with a brute force over the features' rings read through OGR, and with OGR's
// Intersects on the smaller features where GEOS accepts them. Skipped with a
// message when datasets/fetch.sh has not filled the cache.
#include <gdal_priv.h>
#include <gtest/gtest.h>
#include <ogrsf_frmts.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "loci/geom/predicates.hpp"
#include "loci/io/commands.hpp"
#include "loci/io/exact.hpp"
#include "loci/io/join.hpp"
#include "loci/io/layer_query.hpp"

namespace fs = std::filesystem;

namespace {

const std::string kLand = std::string(LOCI_DATASETS_DIR) + "/cache/countries-land-10m/map.geo.json";

struct OgrLayer {
  std::vector<std::unique_ptr<OGRGeometry>> geoms;
  std::vector<long long> fids;
  std::vector<std::string> codes;  // A3
  std::vector<OGREnvelope> envelopes;
  std::vector<int> vertices;
};

OgrLayer read_ogr(const std::string& path) {
  GDALAllRegister();
  CPLSetConfigOption("OGR_GEOJSON_MAX_OBJ_SIZE", "0");
  std::unique_ptr<GDALDataset> ds(
      GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY));
  OgrLayer out;
  if (!ds) return out;
  for (auto& f : *ds->GetLayer(0)) {
    const OGRGeometry* g = f->GetGeometryRef();
    if (!g || g->IsEmpty()) continue;
    out.geoms.emplace_back(g->clone());
    out.fids.push_back(f->GetFID());
    out.codes.push_back(f->GetFieldAsString("A3"));
    OGREnvelope e;
    g->getEnvelope(&e);
    out.envelopes.push_back(e);
    int n = 0;
    if (wkbFlatten(g->getGeometryType()) == wkbMultiPolygon)
      for (const OGRPolygon* p : *g->toMultiPolygon())
        for (const OGRLinearRing* r : *p)
          n += r->getNumPoints();
    else if (wkbFlatten(g->getGeometryType()) == wkbPolygon)
      for (const OGRLinearRing* r : *g->toPolygon())
        n += r->getNumPoints();
    out.vertices.push_back(n);
  }
  return out;
}

// Every ring of a feature read through OGR, as point lists.
std::vector<std::vector<loci::Point2>> rings_of(const OGRGeometry& g) {
  std::vector<const OGRPolygon*> polygons;
  if (wkbFlatten(g.getGeometryType()) == wkbMultiPolygon)
    for (const OGRPolygon* poly : *g.toMultiPolygon())
      polygons.push_back(poly);
  else if (wkbFlatten(g.getGeometryType()) == wkbPolygon)
    polygons.push_back(g.toPolygon());
  std::vector<std::vector<loci::Point2>> out;
  for (const OGRPolygon* poly : polygons)
    for (const OGRLinearRing* ring : *poly) {
      out.emplace_back();
      for (int k = 0; k < ring->getNumPoints(); ++k)
        out.back().push_back({ring->getX(k), ring->getY(k)});
    }
  return out;
}

// Brute force over those rings: on an edge, or an odd number of crossings of the ray towards
// +x (the even-odd rule of GEOS; on the valid polygons of these layers, loci's winding rule
// answers the same).
bool brute_meets(const std::vector<std::vector<loci::Point2>>& rings, const loci::Point2& p) {
  bool odd = false;
  for (const auto& ring : rings)
    for (std::size_t k = 0; k + 1 < ring.size(); ++k) {
      const loci::Point2& a = ring[k];
      const loci::Point2& b = ring[k + 1];
      if (std::min(a[1], b[1]) <= p[1] && p[1] <= std::max(a[1], b[1]) &&
          std::min(a[0], b[0]) <= p[0] && p[0] <= std::max(a[0], b[0]) &&
          loci::orientation(a, b, p) == loci::Orientation::collinear)
        return true;
      odd ^= loci::io::ray_crosses(a, b, p);
    }
  return odd;
}

bool envelopes_meet(const OGREnvelope& a, const OGREnvelope& b) {
  return a.MinX <= b.MaxX && b.MinX <= a.MaxX && a.MinY <= b.MaxY && b.MinY <= a.MaxY;
}

class LandReal : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(kLand))
      GTEST_SKIP() << "no " << kLand << ": run datasets/fetch.sh to fetch the real layers";
  }
};

TEST_F(LandReal, NeighboursTouchAndSmallPairsMatchOgr) {
  const OgrLayer ogr = read_ogr(kLand);
  ASSERT_GT(ogr.fids.size(), 200u);
  const loci::io::JoinLayer land = loci::io::read_join_layer(kLand);
  const std::vector<loci::io::JoinRow> rows =
      loci::io::join_layers(land, nullptr, loci::io::JoinPredicate::intersects);
  std::set<std::pair<long long, long long>> got;
  for (const auto& r : rows)
    got.insert({r.left, r.right});
  std::map<std::string, long long> fid_of;
  for (std::size_t i = 0; i < ogr.fids.size(); ++i)
    fid_of[ogr.codes[i]] = ogr.fids[i];
  for (const auto& [a, b] : std::vector<std::pair<std::string, std::string>>{
           {"FRA", "ESP"}, {"USA", "CAN"}, {"DEU", "POL"}, {"CHN", "IND"}, {"BRA", "ARG"}}) {
    ASSERT_TRUE(fid_of.count(a) && fid_of.count(b)) << a << " " << b;
    EXPECT_TRUE(got.count({fid_of[a], fid_of[b]})) << a << " and " << b << " should touch";
    EXPECT_TRUE(got.count({fid_of[b], fid_of[a]})) << b << " and " << a << " should touch";
  }
  EXPECT_FALSE(got.count({fid_of["FRA"], fid_of["USA"]}));
  // Every pair of features with at most 4,000 vertices each, through OGR (GEOS).
  std::size_t checked = 0;
  for (std::size_t i = 0; i < ogr.fids.size(); ++i)
    for (std::size_t j = 0; j < ogr.fids.size(); ++j) {
      if (ogr.vertices[i] > 4000 || ogr.vertices[j] > 4000) continue;
      if (!envelopes_meet(ogr.envelopes[i], ogr.envelopes[j])) continue;
      const bool want = ogr.geoms[i]->Intersects(ogr.geoms[j].get());
      EXPECT_EQ(got.count({ogr.fids[i], ogr.fids[j]}) == 1, want)
          << ogr.codes[i] << " " << ogr.codes[j];
      ++checked;
    }
  EXPECT_GT(checked, 300u);
}

TEST_F(LandReal, PointLocationMatchesOgr) {
  const OgrLayer ogr = read_ogr(kLand);
  loci::io::LoadOptions load;
  load.layer_path = kLand;
  load.index_path = "";
  const loci::io::LayerIndex index = loci::io::load_index(load);
  loci::io::LayerQuery query(index, kLand, index.layer_name());
  // Half uniform over the extent, half within 0.05 degrees of a vertex of a small feature.
  std::mt19937_64 rng(77);
  std::uniform_real_distribution<double> ux(-180, 180), uy(-90, 84), noise(-0.05, 0.05);
  std::vector<loci::Point2> points;
  for (int k = 0; k < 1500; ++k)
    points.push_back({ux(rng), uy(rng)});
  for (std::size_t i = 0; i < ogr.fids.size() && points.size() < 3000; ++i) {
    if (ogr.vertices[i] > 20000) continue;
    OGRPoint p;
    ogr.geoms[i]->Centroid(&p);
    for (int k = 0; k < 8; ++k)
      points.push_back({p.getX() + noise(rng) * 40, p.getY() + noise(rng) * 40});
  }
  std::vector<loci::io::Answer> answers;
  for (std::size_t k = 0; k < points.size(); ++k) {
    loci::io::Query q;
    q.kind = loci::io::Query::Kind::point;
    q.point = points[k];
    query.run(q, k + 1, false, answers);
  }
  std::vector<std::vector<long long>> got(points.size());
  for (const auto& a : answers)
    got[a.query - 1].push_back(a.fid);
  std::vector<std::vector<std::vector<loci::Point2>>> rings;
  for (const auto& g : ogr.geoms)
    rings.push_back(rings_of(*g));
  std::size_t inside = 0, by_geos = 0;
  for (std::size_t k = 0; k < points.size(); ++k) {
    std::vector<long long> want;
    const OGRPoint p(points[k][0], points[k][1]);
    for (std::size_t i = 0; i < ogr.fids.size(); ++i) {
      const OGREnvelope& e = ogr.envelopes[i];
      if (p.getX() < e.MinX || p.getX() > e.MaxX || p.getY() < e.MinY || p.getY() > e.MaxY)
        continue;
      const bool yes = brute_meets(rings[i], points[k]);
      if (yes) want.push_back(ogr.fids[i]);
      // OGR's own Intersects (GEOS) on the smaller features, where GEOS accepts the feature
      // (it reports a topology error on some invalid features of the layer, then answers
      // true).
      if (ogr.vertices[i] > 20000) continue;
      CPLErrorReset();
      CPLPushErrorHandler(CPLQuietErrorHandler);
      const bool geos = ogr.geoms[i]->Intersects(&p);
      CPLPopErrorHandler();
      if (CPLGetLastErrorType() == CE_None) {
        EXPECT_EQ(geos, yes) << ogr.codes[i] << " at " << p.getX() << "," << p.getY();
        ++by_geos;
      }
    }
    std::sort(got[k].begin(), got[k].end());
    std::sort(want.begin(), want.end());
    EXPECT_EQ(got[k], want) << points[k][0] << "," << points[k][1];
    inside += !want.empty();
  }
  EXPECT_GT(inside, 600u);
  EXPECT_GT(by_geos, 500u);
}

}  // namespace
