// Point location in batch: which polygons of a layer contain (or touch) each of many points.
// loci's layer query (the code path of `loci query --point-file`, in process: a per-feature
// and a per-segment index, exact refinement) beside GEOS prepared polygons behind an STRtree
// of their envelopes (what PostGIS and shapely do), on the same points, answers compared.
//
// Points: half uniform over the layer's extent, half near the coasts (a ring vertex picked at
// random plus up to 0.05 units of noise), fixed seed. Layer: countries-land-10m when it has
// been fetched (datasets/fetch.sh), else the bundled sample.
//
// Usage: bench_point_location [--layer PATH] [--points N]
#include <geos_c.h>

#include <algorithm>
#include <chrono>
#include <cstdarg>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "loci/io/commands.hpp"
#include "loci/io/layer_query.hpp"
#include "support/geos_from_ogr.hpp"
#include "support/layer_polygons.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using loci::Point2;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

void geos_message(const char*, void*) {}

}  // namespace

int main(int argc, char** argv) {
  std::string layer = std::string(LOCI_DATASETS_DIR) + "/cache/countries-land-10m/map.geo.json";
  if (!std::filesystem::exists(layer))
    layer = std::string(LOCI_DATASETS_DIR) + "/samples/coastline-denmark.geojson";
  std::size_t n = 1000000;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--layer")
      layer = argv[i + 1];
    else if (a == "--points")
      n = std::stoul(argv[i + 1]);
  }
  GDALAllRegister();
  CPLSetConfigOption("OGR_GEOJSON_MAX_OBJ_SIZE", "0");

  // The features as GEOS polygons, with their FIDs.
  GEOSContextHandle_t geos = GEOS_init_r();
  GEOSContext_setNoticeMessageHandler_r(geos, geos_message, nullptr);
  GEOSContext_setErrorMessageHandler_r(geos, geos_message, nullptr);
  std::vector<GEOSGeometry*> geoms;
  std::vector<long long> fids;
  std::vector<Point2> vertices;
  {
    std::unique_ptr<GDALDataset> ds(
        GDALDataset::Open(layer.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY));
    if (!ds) {
      std::fprintf(stderr, "bench_point_location: cannot open %s\n", layer.c_str());
      return 1;
    }
    GEOSWKBReader* reader = GEOSWKBReader_create_r(geos);
    for (auto& f : *ds->GetLayer(0)) {
      const OGRGeometry* g = f->GetGeometryRef();
      if (!g || g->IsEmpty()) continue;
      geoms.push_back(loci::test::to_geos(geos, reader, *g));
      fids.push_back(f->GetFID());
      std::vector<loci::BspPolygon> polys;
      if (wkbFlatten(g->getGeometryType()) == wkbPolygon)
        loci::test::add_ogr_polygon(*g->toPolygon(), polys);
      else if (wkbFlatten(g->getGeometryType()) == wkbMultiPolygon)
        for (const OGRPolygon* p : *g->toMultiPolygon())
          loci::test::add_ogr_polygon(*p, polys);
      for (const auto& p : polys)
        vertices.insert(vertices.end(), p.outer.begin(), p.outer.end());
    }
    GEOSWKBReader_destroy_r(geos, reader);
  }
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  for (const Point2& v : vertices)
    x0 = std::min(x0, v[0]), y0 = std::min(y0, v[1]), x1 = std::max(x1, v[0]),
    y1 = std::max(y1, v[1]);
  std::printf("layer %s: %zu features, %zu ring vertices; %zu points\n", layer.c_str(),
              geoms.size(), vertices.size(), n);

  std::mt19937_64 rng(4242);
  std::uniform_real_distribution<double> ux(x0, x1), uy(y0, y1), noise(-0.05, 0.05);
  std::vector<Point2> points(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (i % 2 == 0) {
      points[i] = {ux(rng), uy(rng)};
    } else {
      const Point2& v = vertices[rng() % vertices.size()];
      points[i] = {v[0] + noise(rng), v[1] + noise(rng)};
    }
  }

  // GEOS: prepared polygons in an STRtree of their envelopes.
  auto t0 = Clock::now();
  GEOSSTRtree* tree = GEOSSTRtree_create_r(geos, 10);
  std::vector<const GEOSPreparedGeometry*> prepared;
  for (std::size_t i = 0; i < geoms.size(); ++i) {
    prepared.push_back(GEOSPrepare_r(geos, geoms[i]));
    GEOSSTRtree_insert_r(geos, tree, geoms[i], reinterpret_cast<void*>(i));
  }
  const double geos_build = seconds_since(t0);
  std::vector<std::vector<long long>> geos_answers(n);
  struct Ctx {
    GEOSContextHandle_t geos;
    const std::vector<const GEOSPreparedGeometry*>* prepared;
    const std::vector<long long>* fids;
    GEOSGeometry* point;
    std::vector<long long>* out;
  };
  t0 = Clock::now();
  for (std::size_t i = 0; i < n; ++i) {
    GEOSGeometry* pt = GEOSGeom_createPointFromXY_r(geos, points[i][0], points[i][1]);
    Ctx ctx{geos, &prepared, &fids, pt, &geos_answers[i]};
    GEOSSTRtree_query_r(
        geos, tree, pt,
        [](void* item, void* user) {
          auto* c = static_cast<Ctx*>(user);
          const auto k = reinterpret_cast<std::size_t>(item);
          if (GEOSPreparedIntersects_r(c->geos, (*c->prepared)[k], c->point) == 1)
            c->out->push_back((*c->fids)[k]);
        },
        &ctx);
    GEOSGeom_destroy_r(geos, pt);
    std::sort(geos_answers[i].begin(), geos_answers[i].end());
  }
  const double geos_query = seconds_since(t0);
  std::printf("%-38s %10s %10s %12s %10s\n", "method", "build s", "query s", "points/s", "x GEOS");
  std::printf("%-38s %10.3f %10.3f %12.0f %10.2f\n", "GEOS prepared polygons + STRtree", geos_build,
              geos_query, double(n) / geos_query, 1.0);

  int status = 0;
  for (const loci::io::Per per : {loci::io::Per::feature, loci::io::Per::segment}) {
    loci::io::LoadOptions load;
    load.layer_path = layer;
    load.index_path = "";
    load.per = per;
    t0 = Clock::now();
    const loci::io::LayerIndex index = loci::io::load_index(load);
    const double build = seconds_since(t0);
    loci::io::LayerQuery query(index, layer, index.layer_name());
    std::vector<loci::io::Answer> answers;
    {
      // The layer's geometries are read before the clock starts, as GEOS's are: a text layer
      // is read whole on the first lookup.
      loci::io::Query q;
      q.kind = loci::io::Query::Kind::point;
      q.point = points[0];
      query.run(q, 1, false, answers);
      answers.clear();
    }
    t0 = Clock::now();
    for (std::size_t i = 0; i < n; ++i) {
      loci::io::Query q;
      q.kind = loci::io::Query::Kind::point;
      q.point = points[i];
      query.run(q, i + 1, false, answers);
    }
    const double secs = seconds_since(t0);
    std::vector<std::vector<long long>> got(n);
    for (const auto& a : answers)
      got[a.query - 1].push_back(a.fid);
    std::size_t differ = 0;
    for (std::size_t i = 0; i < n; ++i) {
      std::sort(got[i].begin(), got[i].end());
      if (got[i] != geos_answers[i] && differ++ < 3) {
        std::printf("  differs at %.17g,%.17g: loci", points[i][0], points[i][1]);
        for (long long f : got[i])
          std::printf(" %lld", f);
        std::printf("; GEOS");
        for (long long f : geos_answers[i])
          std::printf(" %lld", f);
        std::printf("\n");
      }
    }
    const std::string name = std::string("loci per ") + loci::io::to_string(per);
    std::printf("%-38s %10.3f %10.3f %12.0f %10.2f   (%zu points answered differently)\n",
                name.c_str(), build, secs, double(n) / secs, geos_query / secs, differ);
    if (differ > n / 10000) status = 1;
  }
  for (auto* p : prepared)
    GEOSPreparedGeom_destroy_r(geos, p);
  GEOSSTRtree_destroy_r(geos, tree);
  for (auto* g : geoms)
    GEOSGeom_destroy_r(geos, g);
  GEOS_finish_r(geos);
  return status;
}
