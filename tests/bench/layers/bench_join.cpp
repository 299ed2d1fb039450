// Spatial joins of two layers (`loci join LEFT RIGHT --predicate ...`): loci's join on the
// layers as read (envelope sweep, each feature prepared once, exact pair tests) beside GEOS as
// PostGIS and shapely use it: an STRtree of the right layer's geometries, each left geometry
// prepared and tested against the candidates of its envelope (grown by D for dwithin, with
// the pairs that do not meet measured by GEOS's indexed facet distance). Reading the layers through
// GDAL is left out on both sides; the pairs (and distances, to 1e-9) must be the same.
//
// Default layers: countries-land-10m against countries-coastline-1m when they have been
// fetched (datasets/fetch.sh), else the bundled sample against itself.
// Usage: bench_join [--left PATH] [--right PATH] [--distance D]
#include <gdal_priv.h>
#include <geos_c.h>
#include <ogrsf_frmts.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "loci/io/join.hpp"
#include "support/geos_from_ogr.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using loci::io::JoinPredicate;
using loci::io::JoinRow;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

void geos_message(const char*, void*) {}

struct GeosLayer {
  std::vector<GEOSGeometry*> geoms;
  std::vector<long long> fids;
};

GeosLayer read_geos(GEOSContextHandle_t geos, const std::string& path) {
  GeosLayer out;
  std::unique_ptr<GDALDataset> ds(
      GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY));
  if (!ds) {
    std::fprintf(stderr, "bench_join: cannot open %s\n", path.c_str());
    std::exit(1);
  }
  GEOSWKBReader* reader = GEOSWKBReader_create_r(geos);
  for (auto& f : *ds->GetLayer(0)) {
    const OGRGeometry* g = f->GetGeometryRef();
    if (!g || g->IsEmpty()) continue;
    out.geoms.push_back(loci::test::to_geos(geos, reader, *g));
    out.fids.push_back(f->GetFID());
  }
  GEOSWKBReader_destroy_r(geos, reader);
  return out;
}

// GEOS: STRtree of the right layer, each left geometry prepared.
std::vector<JoinRow> geos_join(GEOSContextHandle_t geos, const GeosLayer& left,
                               const GeosLayer& right, bool dwithin, double d) {
  GEOSSTRtree* tree = GEOSSTRtree_create_r(geos, 10);
  for (std::size_t j = 0; j < right.geoms.size(); ++j)
    GEOSSTRtree_insert_r(geos, tree, right.geoms[j], reinterpret_cast<void*>(j));
  std::vector<JoinRow> rows;
  struct Ctx {
    GEOSContextHandle_t geos;
    const GEOSPreparedGeometry* prepared;
    const GEOSGeometry* left;
    const GeosLayer* right;
    long long left_fid;
    bool dwithin;
    double d;
    std::vector<JoinRow>* rows;
  };
  for (std::size_t i = 0; i < left.geoms.size(); ++i) {
    const GEOSPreparedGeometry* prepared = GEOSPrepare_r(geos, left.geoms[i]);
    double x0, y0, x1, y1;
    GEOSGeom_getXMin_r(geos, left.geoms[i], &x0);
    GEOSGeom_getYMin_r(geos, left.geoms[i], &y0);
    GEOSGeom_getXMax_r(geos, left.geoms[i], &x1);
    GEOSGeom_getYMax_r(geos, left.geoms[i], &y1);
    const double g = dwithin ? d : 0;
    GEOSGeometry* env = GEOSGeom_createRectangle_r(geos, x0 - g, y0 - g, x1 + g, y1 + g);
    Ctx ctx{geos, prepared, left.geoms[i], &right, left.fids[i], dwithin, d, &rows};
    GEOSSTRtree_query_r(
        geos, tree, env,
        [](void* item, void* user) {
          auto* c = static_cast<Ctx*>(user);
          const auto j = reinterpret_cast<std::size_t>(item);
          const GEOSGeometry* other = c->right->geoms[j];
          if (c->dwithin) {
            // GEOS's fastest way to both the answer and the distance here: pairs that meet
            // are at 0, the others measured by the indexed facet distance (the prepared
            // distance calls fall back to all pairs of edges on these polygons).
            double dist = 0;
            if (GEOSPreparedIntersects_r(c->geos, c->prepared, other) != 1)
              GEOSDistanceIndexed_r(c->geos, c->left, other, &dist);
            if (dist <= c->d) c->rows->push_back({c->left_fid, c->right->fids[j], dist});
          } else if (GEOSPreparedIntersects_r(c->geos, c->prepared, other) == 1) {
            c->rows->push_back({c->left_fid, c->right->fids[j], 0});
          }
        },
        &ctx);
    GEOSGeom_destroy_r(geos, env);
    GEOSPreparedGeom_destroy_r(geos, prepared);
  }
  GEOSSTRtree_destroy_r(geos, tree);
  std::sort(rows.begin(), rows.end());
  return rows;
}

bool same_rows(const std::vector<JoinRow>& a, const std::vector<JoinRow>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t k = 0; k < a.size(); ++k) {
    if (a[k].left != b[k].left || a[k].right != b[k].right) return false;
    if (std::abs(a[k].distance - b[k].distance) > 1e-9 * std::max(1.0, a[k].distance)) return false;
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string cache = std::string(LOCI_DATASETS_DIR) + "/cache/";
  std::string left = cache + "countries-land-10m/map.geo.json";
  std::string right = cache + "countries-coastline-1m/map.geo.json";
  if (!std::filesystem::exists(left) || !std::filesystem::exists(right))
    left = right = std::string(LOCI_DATASETS_DIR) + "/samples/coastline-denmark.geojson";
  double d = 0.5;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--left")
      left = argv[i + 1];
    else if (a == "--right")
      right = argv[i + 1];
    else if (a == "--distance")
      d = std::stod(argv[i + 1]);
  }
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  GDALAllRegister();
  CPLSetConfigOption("OGR_GEOJSON_MAX_OBJ_SIZE", "0");
  GEOSContextHandle_t geos = GEOS_init_r();
  GEOSContext_setNoticeMessageHandler_r(geos, geos_message, nullptr);
  GEOSContext_setErrorMessageHandler_r(geos, geos_message, nullptr);

  auto t0 = Clock::now();
  const loci::io::JoinLayer mine_left = loci::io::read_join_layer(left);
  const loci::io::JoinLayer mine_right = loci::io::read_join_layer(right);
  const GeosLayer geos_left = read_geos(geos, left), geos_right = read_geos(geos, right);
  std::printf("left %s (%zu features), right %s (%zu features); read in %.1f s\n", left.c_str(),
              mine_left.fids.size(), right.c_str(), mine_right.fids.size(), seconds_since(t0));
  std::printf("%-22s %12s %12s %10s %8s\n", "predicate", "loci s", "GEOS s", "x GEOS", "pairs");

  int status = 0;
  for (const bool dwithin : {false, true}) {
    // Fresh layers for each predicate, so that loci's preparation is timed every time.
    const loci::io::JoinLayer l = loci::io::read_join_layer(left);
    const loci::io::JoinLayer r = loci::io::read_join_layer(right);
    t0 = Clock::now();
    const std::vector<JoinRow> mine = loci::io::join_layers(
        l, &r, dwithin ? JoinPredicate::dwithin : JoinPredicate::intersects, d);
    const double loci_s = seconds_since(t0);
    t0 = Clock::now();
    const std::vector<JoinRow> theirs = geos_join(geos, geos_left, geos_right, dwithin, d);
    const double geos_s = seconds_since(t0);
    const bool same = same_rows(mine, theirs);
    char name[64];
    std::snprintf(name, sizeof name, dwithin ? "dwithin:%g" : "intersects", d);
    std::printf("%-22s %12.3f %12.3f %10.2f %8zu %s\n", name, loci_s, geos_s, geos_s / loci_s,
                mine.size(), same ? "identical" : "DIFFERENT");
    if (!same) {
      std::printf("  GEOS has %zu pairs\n", theirs.size());
      status = 1;
    }
  }
  for (auto* g : geos_left.geoms)
    GEOSGeom_destroy_r(geos, g);
  for (auto* g : geos_right.geoms)
    GEOSGeom_destroy_r(geos, g);
  GEOS_finish_r(geos);
  return status;
}
