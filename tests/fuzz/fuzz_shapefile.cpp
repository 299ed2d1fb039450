// Fuzz target: a shapefile (.shp, .shx and .dbf from the input's bytes) read by the direct
// reader that `loci index`, `loci info` and the answers' geometries use, against GDAL's own
// reading of the same files (the summary of `loci info` too, type names included). Input: one flag
// byte, the .shx's and the .dbf's lengths (two bytes each, little-endian; cut to what is there),
// those files' bytes, then the .shp's.
//
// What the direct reader takes it must read as GDAL does (the boxes of the features GDAL
// gives, the polygons GDAL builds, byte for byte, the features the front reads flattened as
// GDAL's are); what it cannot read as GDAL does it must
// hand back (nullopt) or refuse with a loci::Error. A difference aborts: a finding.
#include <cpl_error.h>
#include <gdal_priv.h>
#include <ogrsf_frmts.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "fuzz_support.hpp"
#include "gdal_layer.hpp"
#include "loci/geom/box.hpp"
#include "loci/geom/error.hpp"
#include "loci/io/shapefile_boxes.hpp"
#include "shapefile_polygons.hpp"
#include "shapefile_records.hpp"

namespace {

std::vector<unsigned char> wkb_of(const OGRGeometry& g) {
  std::vector<unsigned char> b(g.WkbSize());
  g.exportToWkb(wkbNDR, b.data(), wkbVariantIso);
  return b;
}

// GDAL's features, in order: each feature's id and the box of its geometry, when it has a
// non-empty one. False when GDAL cannot read the layer through.
struct GdalFeature {
  GIntBig fid;
  loci::Box2 box;
  const char* type;  // GDAL's name of the geometry's type
};
bool gdal_features(OGRLayer& layer, std::vector<GdalFeature>& out) {
  layer.ResetReading();
  CPLErrorReset();
  for (auto& f : layer) {
    if (CPLGetLastErrorType() >= CE_Failure) return false;
    const OGRGeometry* g = f->GetGeometryRef();
    if (!g || g->IsEmpty()) continue;
    OGREnvelope e;
    g->getEnvelope(&e);
    out.push_back({f->GetFID(),
                   {{e.MinX, e.MinY}, {e.MaxX, e.MaxY}},
                   OGRGeometryTypeToName(g->getGeometryType())});
  }
  return CPLGetLastErrorType() < CE_Failure;
}

void check(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "direct shapefile reader differs from GDAL: %s\n", what);
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 5) return 0;
  CPLSetErrorHandler(CPLQuietErrorHandler);
  static const bool registered = (GDALAllRegister(), true);
  (void)registered;
  static const std::string stem = loci::fuzz::scratch_path("-shapefile");
  const std::string shp = stem + ".shp", shx = stem + ".shx", dbf = stem + ".dbf";
  const unsigned flags = data[0];
  std::size_t at = 5;
  const std::size_t shx_size = std::min<std::size_t>(data[1] | data[2] << 8, size - at);
  loci::fuzz::write_file(shx, data + at, shx_size);
  at += shx_size;
  const std::size_t dbf_size = std::min<std::size_t>(data[3] | data[4] << 8, size - at);
  loci::fuzz::write_file(dbf, data + at, dbf_size);
  at += dbf_size;
  // A .shp must start with the format's code: other bytes would be taken by other drivers
  // (GDAL's JML driver leaks on some), which is not what this target tests.
  if (size - at < 4 || data[at] != 0 || data[at + 1] != 0 || data[at + 2] != 0x27 ||
      data[at + 3] != 0x0a)
    return 0;
  loci::fuzz::write_file(shp, data + at, size - at);

  try {
    const char* const shapefile_only[] = {"ESRI Shapefile", nullptr};
    GDALDatasetUniquePtr ds(
        GDALDataset::Open(shp.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY, shapefile_only));
    OGRLayer* layer = ds && ds->GetLayerCount() == 1 ? ds->GetLayer(0) : nullptr;
    std::vector<GdalFeature> ref;
    const bool gdal_read = layer && gdal_features(*layer, ref);

    if (flags & 1) {
      if (const auto boxes = loci::io::read_shapefile_boxes(shp)) {
        check(gdal_read, "read a layer GDAL cannot");
        const auto& items = boxes->items;
        check(items.boxes.size() == ref.size(), "feature count");
        for (std::size_t i = 0; i < ref.size(); ++i) {
          check(items.records[i].fid == ref[i].fid, "feature id");
          check(items.boxes[i] == ref[i].box, "feature box");
        }
      }
    } else {
      if (const auto segments = loci::io::read_shapefile_segments(shp)) {
        check(gdal_read, "read a layer GDAL cannot");
        // Each feature's segments lie within its box, and every feature has some.
        std::size_t k = 0;
        for (const auto& f : ref) {
          check(k < segments->records.size() && segments->records[k].fid == f.fid,
                "segments of a feature");
          for (; k < segments->records.size() && segments->records[k].fid == f.fid; ++k)
            check(loci::contains(f.box, segments->boxes[k]), "segment outside its feature");
        }
        check(k == segments->records.size(), "segments of no feature");
      }
    }
    if (flags & 2) {
      if (const auto summary = loci::io::read_shapefile_summary(shp)) {
        check(gdal_read, "summarised a layer GDAL cannot read");
        check(summary->records == layer->GetFeatureCount(), "record count");
        loci::Box2 extent = loci::Box2::empty();
        for (const auto& f : ref)
          extent.expand(f.box);
        check(ref.empty() || summary->extent == extent, "extent");
        std::map<std::string, std::int64_t> types,
            named(summary->geometry_types.begin(), summary->geometry_types.end());
        for (const auto& f : ref)
          ++types[f.type];
        named.erase("(none)");
        check(named == types, "geometry type names");
      }
    }
    if (gdal_read && (flags & 4)) {
      loci::io::detail::ShapefilePolygons polygons(shp, *layer);
      GDALDatasetUniquePtr again(GDALDataset::Open(shp.c_str(), GDAL_OF_VECTOR, shapefile_only));
      OGRLayer* reference = again ? again->GetLayer(0) : nullptr;
      for (GIntBig fid = 0; reference && fid < std::min<GIntBig>(reference->GetFeatureCount(), 64);
           ++fid) {
        const auto ours = polygons.read(fid);
        if (!ours) continue;
        OGRFeatureUniquePtr f(reference->GetFeature(fid));
        const OGRGeometry* g = f ? f->GetGeometryRef() : nullptr;
        check(g != nullptr, "built a polygon GDAL does not give");
        check(wkb_of(*ours) == wkb_of(*g), "polygon differs from GDAL's");
      }
    }
    // The features the `loci` front reads without GDAL: each one it takes, flattened as GDAL's
    // geometry of it is flattened.
    if (layer && (flags & 8)) {
      loci::io::detail::shp::ShapefileFeatures direct(shp);
      GDALDatasetUniquePtr again(GDALDataset::Open(shp.c_str(), GDAL_OF_VECTOR, shapefile_only));
      OGRLayer* reference = again ? again->GetLayer(0) : nullptr;
      const GIntBig count = reference ? std::min<GIntBig>(reference->GetFeatureCount(), 64) : 0;
      for (GIntBig fid = -1; direct.active() && fid <= count; ++fid) {
        const auto ours = direct.read(fid);
        if (!ours) continue;
        CPLErrorReset();
        OGRFeatureUniquePtr f(reference ? reference->GetFeature(fid) : nullptr);
        check(f != nullptr && CPLGetLastErrorType() < CE_Failure,
              "read a feature GDAL does not give");
        loci::io::FlatGeometry g;
        try {
          g = loci::io::detail::flatten(f->GetGeometryRef(), "feature");
        } catch (const loci::Error&) {
          check(false, "read a feature GDAL refuses");
        }
        check(ours->points == g.points && ours->polygons == g.polygons &&
                  ours->parts.size() == g.parts.size(),
              "feature's points differ from GDAL's");
        for (std::size_t i = 0; i < g.parts.size(); ++i)
          check(ours->parts[i].begin == g.parts[i].begin && ours->parts[i].end == g.parts[i].end &&
                    ours->parts[i].kind == g.parts[i].kind &&
                    ours->parts[i].polygon == g.parts[i].polygon,
                "feature's parts differ from GDAL's");
      }
    }
  } catch (const loci::Error&) {
  }
  return 0;
}
