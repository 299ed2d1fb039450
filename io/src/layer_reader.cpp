// Layer reading through GDAL: see layer_reader.hpp. Also the GDAL plumbing the other io/
// sources share (gdal_layer.hpp).
#include "loci/io/layer_reader.hpp"

#include <cpl_conv.h>
#include <sys/stat.h>

#include <algorithm>
#include <map>
#include <memory>

#include "gdal_layer.hpp"
#include "loci/geom/error.hpp"

namespace loci::io {
namespace detail {

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

std::string where(const std::string& path, std::int64_t fid) {
  return path + ": feature " + std::to_string(fid);
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
    case wkbPolygon: {
      const std::uint32_t id = polygons++;
      for (const auto* ring : *g->toPolygon())
        f(*ring, true, id);
      break;
    }
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
  if (!g) return;
  const auto type = wkbFlatten(g->getGeometryType());
  if (type == wkbPoint) {
    const OGRPoint* p = g->toPoint();
    if (p->IsEmpty()) return;
    const Point2 q{p->getX(), p->getY()};
    if (!is_finite(q)) throw InvalidGeometry(what + " has a NaN or infinite coordinate");
    const auto at = std::uint32_t(out.points.size());
    out.points.push_back(q);
    out.parts.push_back({at, at + 1, PartKind::point, 0});
  } else if (type == wkbMultiPoint || type == wkbGeometryCollection) {
    for (const auto* part : *g->toGeometryCollection())
      add_points(part, out, what);
  }
}

}  // namespace

void for_each_curve(const OGRGeometry* g,
                    const std::function<void(const OGRSimpleCurve&, bool, std::uint32_t)>& f) {
  const auto linear = linear_copy(g);
  std::uint32_t polygons = 0;
  walk(linear ? linear.get() : g, polygons, f);
}

FlatGeometry flatten(const OGRGeometry* g, const std::string& what) {
  FlatGeometry out;
  if (!g || g->IsEmpty()) return out;
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
      if (!is_finite(q)) throw InvalidGeometry(what + " has a NaN or infinite coordinate");
      out.points.push_back(q);
    }
    out.parts.push_back(
        {at, std::uint32_t(out.points.size()), ring ? PartKind::ring : PartKind::line, polygon});
  });
  out.polygons = polygons;
  return out;
}

GDALDriver* driver_for(const std::string& path) {
  GDALAllRegister();
  std::string ext = CPLGetExtension(path.c_str());
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  const char* name = "GeoJSON";
  if (ext == "shp")
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
  GDALDriver* d = GetGDALDriverManager()->GetDriverByName(name);
  if (!d) throw Error(std::string("GDAL has no ") + name + " driver");
  return d;
}

}  // namespace detail

using detail::open_layer;
using detail::where;

std::vector<SegmentRecord> read_segments(const std::string& path, const std::string& layer) {
  auto ol = open_layer(path, layer);
  std::vector<SegmentRecord> out;
  for (auto& feature : *ol.layer) {
    const std::int64_t fid = feature->GetFID();
    std::int32_t part = 0;
    detail::for_each_curve(
        feature->GetGeometryRef(), [&](const OGRSimpleCurve& c, bool, std::uint32_t) {
          const int n = c.getNumPoints();
          for (int i = 0; i + 1 < n; ++i) {
            const Segment<2> s{{c.getX(i), c.getY(i)}, {c.getX(i + 1), c.getY(i + 1)}};
            if (!is_finite(s.a) || !is_finite(s.b))
              throw InvalidGeometry(where(path, fid) + " has a NaN or infinite coordinate");
            out.push_back({s, fid, part});
          }
          ++part;
        });
  }
  return out;
}

std::vector<FeatureRecord> read_envelopes(const std::string& path, const std::string& layer) {
  auto ol = open_layer(path, layer);
  std::vector<FeatureRecord> out;
  for (auto& feature : *ol.layer) {
    const OGRGeometry* g = feature->GetGeometryRef();
    if (!g || g->IsEmpty()) continue;
    OGREnvelope e;
    g->getEnvelope(&e);
    const Box<2> box{{e.MinX, e.MinY}, {e.MaxX, e.MaxY}};
    check_box(box, where(path, feature->GetFID()).c_str());
    out.push_back({box, feature->GetFID()});
  }
  return out;
}

namespace {

bool is_polygonal(const OGRGeometry* g) {
  const auto t = wkbFlatten(g->getGeometryType());
  return t == wkbPolygon || t == wkbMultiPolygon || t == wkbCurvePolygon || t == wkbMultiSurface ||
         t == wkbGeometryCollection;
}

void add_segments(const OGRGeometry* g, std::int64_t fid, const std::string& path,
                  LayerItems& out) {
  std::int32_t part = 0;
  detail::for_each_curve(g, [&](const OGRSimpleCurve& c, bool ring, std::uint32_t) {
    const int n = c.getNumPoints();
    for (int i = 0; i + 1 < n; ++i) {
      const Point2 a{c.getX(i), c.getY(i)}, b{c.getX(i + 1), c.getY(i + 1)};
      if (!is_finite(a) || !is_finite(b))
        throw InvalidGeometry(where(path, fid) + " has a NaN or infinite coordinate");
      const Segment2 s{a, b};
      // The box keeps the segment when we also know which diagonal of it the segment is.
      const bool anti = (a[0] < b[0]) != (a[1] < b[1]) && a[0] != b[0] && a[1] != b[1];
      out.boxes.push_back(s.box());
      out.records.push_back({fid, part, (ring ? item_ring : 0u) | (anti ? item_antidiagonal : 0u)});
    }
    ++part;
  });
  // Isolated points have no linework; they are kept as zero-length segments so that a
  // per-segment index still answers for them.
  const auto t = wkbFlatten(g->getGeometryType());
  if (t == wkbPoint || t == wkbMultiPoint || t == wkbGeometryCollection) {
    const FlatGeometry flat = detail::flatten(g, where(path, fid));
    for (const Part& p : flat.parts) {
      if (p.kind != PartKind::point) continue;
      out.boxes.push_back(Box2::of_point(flat.points[p.begin]));
      out.records.push_back({fid, part++, 0u});
    }
  }
}

}  // namespace

LayerItems read_items(const std::string& path, const std::string& layer, Per per,
                      const Progress& progress) {
  auto ol = open_layer(path, layer);
  LayerItems out;
  out.per = per;
  out.layer_name = ol.layer->GetName();
  ProgressTicker ticker(progress, double(ol.layer->GetFeatureCount(FALSE)));
  std::size_t seen = 0;
  for (auto& feature : *ol.layer) {
    ticker.tick(double(++seen));
    const OGRGeometry* g = feature->GetGeometryRef();
    if (!g || g->IsEmpty()) continue;
    const std::int64_t fid = feature->GetFID();
    if (is_polygonal(g)) out.has_polygons = true;
    if (per == Per::feature) {
      // The envelope skips NaN coordinates; the feature must be refused, not half indexed.
      detail::flatten(g, where(path, fid));
      OGREnvelope e;
      g->getEnvelope(&e);
      const Box2 box{{e.MinX, e.MinY}, {e.MaxX, e.MaxY}};
      check_box(box, where(path, fid).c_str());
      out.boxes.push_back(box);
      out.records.push_back({fid, 0, 0u});
    } else {
      add_segments(g, fid, path, out);
    }
  }
  return out;
}

LayerSummary summarize_layer(const std::string& path, const std::string& layer,
                             const Progress& progress) {
  auto ol = open_layer(path, layer);
  LayerSummary s;
  s.path = path;
  s.driver = ol.dataset->GetDriver() ? ol.dataset->GetDriver()->GetDescription() : "";
  s.layer_name = ol.layer->GetName();
  for (int i = 0; i < ol.dataset->GetLayerCount(); ++i)
    s.layer_names.push_back(ol.dataset->GetLayer(i)->GetName());
  if (const OGRSpatialReference* srs = ol.layer->GetSpatialRef()) {
    const char* name = srs->GetName();
    s.crs = name ? name : "";
    const char* auth = srs->GetAuthorityName(nullptr);
    const char* code = srs->GetAuthorityCode(nullptr);
    if (auth && code) s.crs += std::string(" (") + auth + ":" + code + ")";
  }
  const OGRFeatureDefn* defn = ol.layer->GetLayerDefn();
  for (int i = 0; i < defn->GetFieldCount(); ++i) {
    const OGRFieldDefn* f = defn->GetFieldDefn(i);
    s.fields.emplace_back(f->GetNameRef(), OGRFieldDefn::GetFieldTypeName(f->GetType()));
  }
  std::map<std::string, std::int64_t> types;
  ProgressTicker ticker(progress, double(ol.layer->GetFeatureCount(FALSE)));
  for (auto& feature : *ol.layer) {
    ++s.feature_count;
    ticker.tick(double(s.feature_count));
    const OGRGeometry* g = feature->GetGeometryRef();
    if (!g || g->IsEmpty()) {
      ++types["(none)"];
      continue;
    }
    ++types[OGRGeometryTypeToName(wkbFlatten(g->getGeometryType()))];
    OGREnvelope e;
    g->getEnvelope(&e);
    s.extent.expand(Box2{{e.MinX, e.MinY}, {e.MaxX, e.MaxY}});
  }
  s.geometry_types.assign(types.begin(), types.end());
  return s;
}

}  // namespace loci::io
