// The GDAL plumbing io/ shares (gdal_layer.hpp): opening a layer, walking and flattening
// geometries, choosing an output driver.
#include "gdal_layer.hpp"

#include <cstdio>

#include <cpl_conv.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "loci/geom/error.hpp"
#include "loci/io/atomic_file.hpp"
#include "loci/io/commands.hpp"
#include "loci/io/sidecar.hpp"

namespace loci::io {

namespace detail {

ReadCheck::ReadCheck(std::string path) : path_(std::move(path)) {
  CPLErrorReset();
}

namespace {

bool read_failed() {
  const CPLErr e = CPLGetLastErrorType();
  return e == CE_Failure || e == CE_Fatal;
}

}  // namespace

void ReadCheck::fail(const std::string& where) const {
  throw Error(path_ + ": cannot read the layer whole (" + where + CPLGetLastErrorMsg() + ")");
}

void ReadCheck::feature(std::int64_t fid) const {
  if (read_failed()) fail("feature " + std::to_string(fid) + ": ");
  if (!fids_.empty() && fid <= fids_.back()) increasing_ = false;
  fids_.push_back(fid);
}

OGRFeatureUniquePtr read_feature(OGRLayer& layer, std::int64_t fid, const std::string& path) {
  CPLErrorReset();
  OGRFeatureUniquePtr f(layer.GetFeature(fid));
  // No feature at all (a deleted record, say, which GDAL also reports as a failure): the
  // caller says that the layer has none, and the failure is not left for the next read.
  if (!f) {
    CPLErrorReset();
    return f;
  }
  if (read_failed())
    throw Error(path + ": cannot read feature " + std::to_string(fid) + " (" +
                CPLGetLastErrorMsg() + "): the file is damaged, or changed while loci read it");
  return f;
}

void ReadCheck::finish() const {
  if (read_failed()) fail("");
  if (increasing_) return;
  std::sort(fids_.begin(), fids_.end());
  const auto twice = std::adjacent_find(fids_.begin(), fids_.end());
  if (twice != fids_.end())
    throw Error(path_ + ": two features have FID " + std::to_string(*twice) +
                " (in GeoJSON, their \"id\"); loci reads features back by FID, so each needs "
                "its own");
}

}  // namespace detail

void silence_gdal_messages() {
  CPLSetErrorHandler(CPLQuietErrorHandler);
}
namespace detail {

bool fast_random_read(GDALDataset& ds) {
  const std::string driver = ds.GetDriver() ? ds.GetDriver()->GetDescription() : "";
  for (const char* fast : {"ESRI Shapefile", "GPKG", "SQLite", "FlatGeobuf", "OpenFileGDB",
                           "MapInfo File", "PostgreSQL", "Memory"})
    if (driver == fast) return true;
  return false;
}

OpenLayer open_layer(const std::string& path, const std::string& name) {
  GDALAllRegister();
  if (!CPLGetConfigOption("OGR_GEOJSON_MAX_OBJ_SIZE", nullptr))
    CPLSetConfigOption("OGR_GEOJSON_MAX_OBJ_SIZE", "0");
  // A FIFO or device would block GDAL or feed it endless bytes: only files and directories (a
  // directory of shapefiles) are layers on disk; other names (/vsi..., PG:...) go to GDAL.
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode))
    throw Error(path + ": not a regular file");
  CPLPushErrorHandler(CPLQuietErrorHandler);
  OpenLayer ol;
  ol.dataset.reset(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY));
  const std::string gdal_message = CPLGetLastErrorMsg();
  CPLPopErrorHandler();
  if (!ol.dataset) {
    VSIStatBufL st;
    if (VSIStatL(path.c_str(), &st) != 0) throw Error(path + ": no such file");
    if (starts_as_sidecar(path))
      throw Error(path + ": a loci index, not a layer (give the layer it indexes)");
    // A file this process may not read says why (GDAL, which finds no driver, does not).
    if (S_ISREG(st.st_mode) && ::access(path.c_str(), R_OK) != 0)
      throw Error(path + ": cannot read the file (" + std::strerror(errno) + ")");
    throw Error(path + ": cannot open as a vector layer" +
                (gdal_message.empty() ? std::string() : " (" + gdal_message + ")"));
  }
  if (ol.dataset->GetLayerCount() == 0) throw Error(path + ": contains no layer");
  ol.layer = name.empty() ? ol.dataset->GetLayer(0) : ol.dataset->GetLayerByName(name.c_str());
  if (!ol.layer) throw Error(path + ": no layer named '" + name + "'");
  if (ol.layer->GetLayerDefn()->GetGeomFieldCount() == 0)
    throw Error(path + ": layer '" + ol.layer->GetName() + "' has no geometry");
  ol.layer->ResetReading();
  return ol;
}

bool same_layer(const std::string& path_a, const std::string& name_a, const std::string& path_b,
                const std::string& name_b) {
  if (!same_file(path_a, path_b)) return false;
  if (name_a == name_b) return true;
  const OpenLayer ol = open_layer(path_a, name_a);
  OGRLayer* b =
      name_b.empty() ? ol.dataset->GetLayer(0) : ol.dataset->GetLayerByName(name_b.c_str());
  return b == ol.layer;
}

namespace {

void walk(const OGRGeometry* g, std::uint32_t& polygons,
          const std::function<void(const OGRSimpleCurve&, bool, std::uint32_t)>& f) {
  if (!g) return;
  switch (wkbFlatten(g->getGeometryType())) {
    case wkbLineString:
    case wkbLinearRing:
      f(*g->toSimpleCurve(), false, 0);
      break;
    case wkbPolygon:
    case wkbTriangle: {
      const std::uint32_t id = polygons++;
      for (const auto* ring : *g->toPolygon()) {
        if (unclosed(*ring)) {  // read closed (for_each_curve)
          OGRLinearRing closed(*ring);
          closed.closeRings();
          f(closed, true, id);
          continue;
        }
        f(*ring, true, id);
      }
      break;
    }
    case wkbPolyhedralSurface:
    case wkbTIN:  // faces (triangles of a TIN, a MultiPatch shapefile's 3D surfaces) as polygons
      for (const auto* face : *g->toPolyhedralSurface())
        walk(face, polygons, f);
      break;
    case wkbMultiLineString:
    case wkbMultiPolygon:
    case wkbGeometryCollection:
      for (const auto* part : *g->toGeometryCollection())
        walk(part, polygons, f);
      break;
    default:
      break;
  }
}

// Curved geometries (arcs) are approximated by GDAL's default linearisation.
std::unique_ptr<OGRGeometry> linear_copy(const OGRGeometry* g) {
  if (!g || !g->hasCurveGeometry()) return nullptr;
  return std::unique_ptr<OGRGeometry>(g->getLinearGeometry());
}

void add_points(const OGRGeometry* g, FlatGeometry& out, const std::string& what) {
  for_each_point(g, what, [&](const Point2& q) {
    const auto at = std::uint32_t(out.points.size());
    out.points.push_back(q);
    out.parts.push_back({at, at + 1, PartKind::point, 0});
  });
}

}  // namespace

void for_each_point(const OGRGeometry* g, const std::string& what,
                    const std::function<void(const Point2&)>& f) {
  if (!g) return;
  const auto type = wkbFlatten(g->getGeometryType());
  if (type == wkbPoint) {
    const OGRPoint* p = g->toPoint();
    if (without_points(p, what)) return;
    const Point2 q{p->getX(), p->getY()};
    check_layer_point(q, what);
    f(q);
  } else if (type == wkbMultiPoint || type == wkbGeometryCollection) {
    for (const auto* part : *g->toGeometryCollection())
      for_each_point(part, what, f);
  }
}

void check_points(const OGRGeometry* g, const std::string& what) {
  for_each_point(g, what, [](const Point2&) {});
}

bool unclosed(const OGRLinearRing& ring) {
  const int n = ring.getNumPoints();
  return n > 1 && (ring.getX(0) != ring.getX(n - 1) || ring.getY(0) != ring.getY(n - 1));
}

bool has_unclosed_ring(const OGRGeometry& g) {
  switch (wkbFlatten(g.getGeometryType())) {
    case wkbPolygon:
    case wkbTriangle:
      for (const auto* ring : *g.toPolygon())
        if (unclosed(*ring)) return true;
      return false;
    case wkbPolyhedralSurface:
    case wkbTIN:
      for (const auto* face : *g.toPolyhedralSurface())
        if (has_unclosed_ring(*face)) return true;
      return false;
    case wkbMultiPolygon:
    case wkbGeometryCollection:
      for (const auto* part : *g.toGeometryCollection())
        if (has_unclosed_ring(*part)) return true;
      return false;
    default:
      return false;
  }
}

void for_each_curve(const OGRGeometry* g,
                    const std::function<void(const OGRSimpleCurve&, bool, std::uint32_t)>& f) {
  const auto linear = linear_copy(g);
  std::uint32_t polygons = 0;
  walk(linear ? linear.get() : g, polygons, f);
}

std::string system_of(const OGRLayer& layer) {
  const OGRSpatialReference* srs = const_cast<OGRLayer&>(layer).GetSpatialRef();
  if (!srs) return "";
  // A GeoPackage written from a layer without a system says "Undefined geographic SRS" (or
  // Cartesian): no system.
  const char* name = srs->GetName();
  if (!srs->GetAuthorityCode(nullptr) && name && std::strncmp(name, "Undefined ", 10) == 0)
    return "";
  char* wkt = nullptr;
  const char* options[] = {"FORMAT=WKT2_2019", nullptr};
  if (srs->exportToWkt(&wkt, options) != OGRERR_NONE) {
    CPLFree(wkt);
    return "";
  }
  std::string out = wkt ? wkt : "";
  CPLFree(wkt);
  return out;
}

namespace {

std::unique_ptr<OGRSpatialReference> system_from(const std::string& wkt) {
  if (wkt.empty()) return nullptr;
  auto srs = std::make_unique<OGRSpatialReference>();
  if (srs->importFromWkt(wkt.c_str()) != OGRERR_NONE) return nullptr;
  return srs;
}

// The system as PROJ's +proj text without datum shifts or axis order, tokens sorted ("" when
// it has none).
std::string projection_text(const OGRSpatialReference& srs) {
  char* text = nullptr;
  if (srs.exportToProj4(&text) != OGRERR_NONE || !text) {
    CPLFree(text);
    return "";
  }
  std::istringstream in(text);
  CPLFree(text);
  std::vector<std::string> tokens;
  for (std::string t; in >> t;)
    if (t.rfind("+towgs84=", 0) != 0 && t.rfind("+axis=", 0) != 0 && t != "+no_defs" &&
        t != "+type=crs")
      tokens.push_back(t);
  std::sort(tokens.begin(), tokens.end());
  std::string out;
  for (const auto& t : tokens)
    out += t + ' ';
  return out;
}

std::string system_name(const OGRSpatialReference& srs) {
  if (std::string code = authority_code(srs); !code.empty()) return code;
  const char* name = srs.GetName();
  return name ? name : "unnamed";
}

}  // namespace

std::string authority_code(const OGRSpatialReference& srs) {
  const char* auth = srs.GetAuthorityName(nullptr);
  const char* code = srs.GetAuthorityCode(nullptr);
  return auth && code ? std::string(auth) + ":" + code : std::string();
}

void check_same_system(const std::string& a, const std::string& a_system, const std::string& b,
                       const std::string& b_system) {
  const auto sa = system_from(a_system), sb = system_from(b_system);
  if (!sa || !sb) return;
  // Equal as systems: the same system described in two ways (a .prj's ESRI text, GeoJSON's
  // EPSG code) and latitude-first or longitude-first axes count as the same.
  const char* criteria[] = {"CRITERION=EQUIVALENT_EXCEPT_AXIS_ORDER_GEOGCRS", nullptr};
  if (sa->IsSame(sb.get(), criteria)) return;
  // A projected system whose definition lists northing first (EPSG:31468) against a .prj of
  // the same listing easting first: the same projection, datum shifts and axes aside.
  const std::string projection = projection_text(*sa);
  if (!projection.empty() && projection == projection_text(*sb)) return;
  throw Error(a + " and " + b + " are in different coordinate systems (" + system_name(*sa) + ", " +
              system_name(*sb) + "); reproject one into the other's first (ogr2ogr -t_srs)");
}

void check_lonlat_system(const std::string& path, const std::string& system) {
  const auto srs = system_from(system);
  if (!srs || srs->IsGeographic()) return;
  throw Error(path + " is in a projected coordinate system (" + system_name(*srs) +
              "), and AIS positions are longitudes and latitudes; reproject it first (ogr2ogr "
              "-t_srs EPSG:4326)");
}

std::string geojson_crs_member(const std::string& system) {
  const auto srs = system_from(system);
  if (!srs) return "";
  const char* auth = srs->GetAuthorityName(nullptr);
  const char* code = srs->GetAuthorityCode(nullptr);
  if (!auth || !code) return "";
  if ((EQUAL(auth, "EPSG") && EQUAL(code, "4326")) || (EQUAL(auth, "OGC") && EQUAL(code, "CRS84")))
    return "";
  return std::string("\"crs\":{\"type\":\"name\",\"properties\":{\"name\":\"urn:ogc:def:crs:") +
         auth + "::" + code + "\"}},";
}

bool without_points(const OGRGeometry* g, const std::string& what) {
  if (!g) return true;
  if (!g->IsEmpty()) return false;
  const auto type = wkbFlatten(g->getGeometryType());
  if (type == wkbPoint) {
    const OGRPoint* p = g->toPoint();
    // Both NaN is how WKB and GeoPackage write POINT EMPTY; one NaN is a bad coordinate.
    if (std::isnan(p->getX()) != std::isnan(p->getY()))
      throw InvalidGeometry(what + " has a NaN or infinite coordinate");
  } else if (OGR_GT_IsSubClassOf(type, wkbGeometryCollection)) {
    for (const auto* part : *g->toGeometryCollection())
      without_points(part, what);
  }
  return true;
}

FlatGeometry flatten(const OGRGeometry* g, const std::string& what) {
  FlatGeometry out;
  if (without_points(g, what)) return out;
  const auto linear = linear_copy(g);
  if (linear) g = linear.get();
  add_points(g, out, what);
  std::uint32_t polygons = 0;
  walk(g, polygons, [&](const OGRSimpleCurve& c, bool ring, std::uint32_t polygon) {
    const int n = c.getNumPoints();
    if (n == 0) return;
    const auto at = std::uint32_t(out.points.size());
    for (int i = 0; i < n; ++i) {
      const Point2 q{c.getX(i), c.getY(i)};
      check_layer_point(q, what);
      out.points.push_back(q);
    }
    out.parts.push_back(
        {at, std::uint32_t(out.points.size()), ring ? PartKind::ring : PartKind::line, polygon});
  });
  out.polygons = polygons;
  return out;
}

void add_segments(const OGRGeometry* g, std::int64_t fid, const std::string& path,
                  LayerItems& out) {
  std::int32_t part = 0;
  for_each_curve(g, [&](const OGRSimpleCurve& c, bool ring, std::uint32_t polygon) {
    const int n = c.getNumPoints();
    // A curve of one point is that point: a segment of length zero, so that a per-segment
    // index answers for it as the feature's own geometry does.
    for (int i = 0; i + 1 < n || (i == 0 && n == 1); ++i) {
      const int j = std::min(i + 1, n - 1);
      const Point2 a{c.getX(i), c.getY(i)}, b{c.getX(j), c.getY(j)};
      if (!within_coordinate_range(a) || !within_coordinate_range(b)) {
        check_layer_point(a, where(path, fid));
        check_layer_point(b, where(path, fid));
      }
      // The box keeps the segment when we also know which diagonal of it the segment is; a
      // ring's segment, which polygon of the feature it bounds.
      out.boxes.push_back(Segment2{a, b}.box());
      out.records.push_back({fid, part, segment_flags(a, b, ring, polygon)});
    }
    ++part;
  });
  // Isolated points have no linework; they are kept as zero-length segments so that a
  // per-segment index still answers for them.
  const auto t = wkbFlatten(g->getGeometryType());
  if (t == wkbPoint || t == wkbMultiPoint || t == wkbGeometryCollection) {
    const FlatGeometry flat = flatten(g, where(path, fid));
    for (const Part& p : flat.parts) {
      if (p.kind != PartKind::point) continue;
      out.boxes.push_back(Box2::of_point(flat.points[p.begin]));
      out.records.push_back({fid, part++, 0u});
    }
  }
}

GDALDriver* driver_for(const std::string& path) {
  GDALAllRegister();
  std::string ext = CPLGetExtension(path.c_str());
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  const char* name = nullptr;
  if (ext == "geojson" || ext == "json")
    name = "GeoJSON";
  else if (ext == "shp")
    name = "ESRI Shapefile";
  else if (ext == "gpkg")
    name = "GPKG";
  else if (ext == "fgb")
    name = "FlatGeobuf";
  else if (ext == "csv")
    name = "CSV";
  else if (ext == "kml")
    name = "KML";
  else if (ext == "gml")
    name = "GML";
  if (!name)
    throw InvalidArgument("cannot tell the output format of " + path +
                          " from its extension: use .geojson, .shp, .gpkg, .fgb, .csv, .kml or "
                          ".gml");
  GDALDriver* d = GetGDALDriverManager()->GetDriverByName(name);
  if (!d) throw Error(std::string("GDAL has no ") + name + " driver");
  return d;
}

}  // namespace detail

}  // namespace loci::io
