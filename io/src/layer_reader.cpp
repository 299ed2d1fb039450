// Layer reading through GDAL: see layer_reader.hpp.
#include "loci/io/layer_reader.hpp"

#include <algorithm>
#include <cctype>
#include <map>
#include <memory>
#include <vector>

#include "gdal_layer.hpp"
#include "loci/geom/error.hpp"
#include "loci/io/shapefile_boxes.hpp"

namespace loci::io {

using detail::open_layer;
using detail::where;

std::vector<SegmentRecord> read_segments(const std::string& path, const std::string& layer,
                                         const Progress& progress, std::string* system) {
  auto ol = open_layer(path, layer);
  if (system) *system = detail::system_of(*ol.layer);
  std::vector<SegmentRecord> out;
  ProgressTicker ticker(progress, double(ol.layer->GetFeatureCount(FALSE)));
  std::size_t seen = 0;
  const detail::ReadCheck read_check(path);
  for (auto& feature : *ol.layer) {
    ticker.tick(double(++seen));
    const std::int64_t fid = feature->GetFID();
    read_check.feature(fid);
    // Points have no linework, but a bad one (a NaN point GDAL reads as empty, or one in a
    // multipoint) is bad input here as in every other command.
    const OGRGeometry* g = feature->GetGeometryRef();
    if (!g) continue;
    const auto type = wkbFlatten(g->getGeometryType());
    if (type == wkbPoint || type == wkbMultiPoint || type == wkbGeometryCollection) {
      const std::string what = where(path, fid);
      if (detail::without_points(g, what)) continue;
      detail::check_points(g, what);
    }
    std::int32_t part = 0;
    detail::for_each_curve(g, [&](const OGRSimpleCurve& c, bool, std::uint32_t) {
      const int n = c.getNumPoints();
      // A curve of one point is that point: a segment of length zero.
      for (int i = 0; i + 1 < n || (i == 0 && n == 1); ++i) {
        const int j = std::min(i + 1, n - 1);
        const Segment<2> s{{c.getX(i), c.getY(i)}, {c.getX(j), c.getY(j)}};
        if (!within_coordinate_range(s.a) || !within_coordinate_range(s.b)) {
          detail::check_layer_point(s.a, where(path, fid));
          detail::check_layer_point(s.b, where(path, fid));
        }
        out.push_back({s, fid, part});
      }
      ++part;
    });
  }
  read_check.finish();
  return out;
}

std::vector<FeatureRecord> read_envelopes(const std::string& path, const std::string& layer) {
  auto ol = open_layer(path, layer);
  std::vector<FeatureRecord> out;
  const detail::ReadCheck read_check(path);
  for (auto& feature : *ol.layer) {
    read_check.feature(feature->GetFID());
    const OGRGeometry* g = feature->GetGeometryRef();
    if (detail::without_points(g, where(path, feature->GetFID()))) continue;
    OGREnvelope e;
    g->getEnvelope(&e);
    const Box<2> box{{e.MinX, e.MinY}, {e.MaxX, e.MaxY}};
    check_box(box, where(path, feature->GetFID()).c_str());
    out.push_back({box, feature->GetFID()});
  }
  read_check.finish();
  return out;
}

namespace {

bool is_polygonal(const OGRGeometry* g) {
  const auto t = wkbFlatten(g->getGeometryType());
  return t == wkbPolygon || t == wkbMultiPolygon || t == wkbCurvePolygon || t == wkbMultiSurface ||
         t == wkbGeometryCollection || detail::of_faces(t);
}

// Refuses a line or polygon feature with a coordinate out of range (NaN, infinite), without
// copying its points.
void check_curves(const OGRGeometry* g, const std::string& path, std::int64_t fid) {
  detail::for_each_curve(g, [&](const OGRSimpleCurve& c, bool, std::uint32_t) {
    for (int i = 0, n = c.getNumPoints(); i < n; ++i) {
      const Point2 a{c.getX(i), c.getY(i)};
      if (!within_coordinate_range(a)) detail::check_layer_point(a, where(path, fid));
    }
  });
}

}  // namespace

namespace {

// One pass over the layer filling `by_feature` and/or `by_segment`.
void read_layer_items(const std::string& path, const std::string& layer, const Progress& progress,
                      bool keep_geometries, LayerItems* by_feature, LayerItems* by_segment) {
  auto ol = open_layer(path, layer);
  const bool keep = keep_geometries && by_feature && !detail::fast_random_read(*ol.dataset);
  for (LayerItems* out : {by_feature, by_segment})
    if (out) out->layer_name = ol.layer->GetName();
  ProgressTicker ticker(progress, double(ol.layer->GetFeatureCount(FALSE)));
  std::size_t seen = 0;
  const detail::ReadCheck read_check(path);
  for (auto& feature : *ol.layer) {
    ticker.tick(double(++seen));
    const OGRGeometry* g = feature->GetGeometryRef();
    const std::int64_t fid = feature->GetFID();
    read_check.feature(fid);
    if (detail::without_points(g, where(path, fid))) {
      for (LayerItems* out : {by_feature, by_segment})
        if (out) ++out->without_geometry;
      if (keep) by_feature->geometries.emplace(fid, FlatGeometry{});
      continue;
    }
    for (LayerItems* out : {by_feature, by_segment})
      if (out) {
        if (is_polygonal(g)) out->has_polygons = true;
        ++out->features;
      }
    if (by_feature) {
      // The envelope skips NaN coordinates; the feature must be refused, not half indexed.
      const auto type = wkbFlatten(g->getGeometryType());
      if (keep || type == wkbPoint || type == wkbMultiPoint || type == wkbGeometryCollection) {
        FlatGeometry flat = detail::flatten(g, where(path, fid));
        if (keep) by_feature->geometries.emplace(fid, std::move(flat));
      } else {
        check_curves(g, path, fid);
      }
      OGREnvelope e;
      g->getEnvelope(&e);
      const Box2 box{{e.MinX, e.MinY}, {e.MaxX, e.MaxY}};
      check_box(box, where(path, fid).c_str());
      by_feature->boxes.push_back(box);
      by_feature->records.push_back({fid, 0, 0u});
    }
    if (by_segment) detail::add_segments(g, fid, path, *by_segment);
  }
  read_check.finish();
}

}  // namespace

LayerItems read_items(const std::string& path, const std::string& layer, Per per,
                      const Progress& progress, bool keep_geometries) {
  // A shapefile's boxes and segments come faster from its records than from GDAL's
  // geometries (and GDAL reads a shapefile's features by FID in place: there are no
  // geometries to keep).
  if (per == Per::feature)
    if (auto direct = read_shapefile_boxes(path, layer, progress)) return std::move(direct->items);
  if (per == Per::segment)
    if (auto direct = read_shapefile_segments(path, layer, progress)) return std::move(*direct);
  LayerItems out;
  out.per = per;
  read_layer_items(path, layer, progress, keep_geometries, per == Per::feature ? &out : nullptr,
                   per == Per::segment ? &out : nullptr);
  return out;
}

LayerItems read_items_choosing(const std::string& path, const std::string& layer,
                               const Progress& progress) {
  const auto segments_serve = [](std::uint64_t segments, std::uint64_t features) {
    return features > 0 && segments >= kSegmentsPerFeatureForSegments * features;
  };
  // A shapefile is read directly, boxes first; when segments serve, a second direct pass
  // (about twice the work: it writes every segment) reads them.
  Progress first, rest;
  if (progress) {
    first = [&](double f) { progress(0.3 * f); };
    rest = [&](double f) { progress(0.3 + 0.7 * f); };
  }
  if (auto direct = read_shapefile_boxes(path, layer, first)) {
    if (!segments_serve(direct->segments, direct->items.features)) {
      if (progress) progress(1.0);
      return std::move(direct->items);
    }
    // The content hash stays that of the first pass: the caller's before-and-after check of
    // sizes, times and inodes covers both passes.
    LayerItems by_segment = read_items(path, layer, Per::segment, rest);
    by_segment.content_hash = direct->items.content_hash;
    return by_segment;
  }
  LayerItems by_feature, by_segment;
  by_feature.per = Per::feature;
  by_segment.per = Per::segment;
  read_layer_items(path, layer, progress, false, &by_feature, &by_segment);
  if (segments_serve(by_segment.records.size(), by_feature.features)) return by_segment;
  return by_feature;
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
    if (const std::string code = detail::authority_code(*srs); !code.empty())
      s.crs += " (" + code + ")";
  }
  const OGRFeatureDefn* defn = ol.layer->GetLayerDefn();
  for (int i = 0; i < defn->GetFieldCount(); ++i) {
    const OGRFieldDefn* f = defn->GetFieldDefn(i);
    s.fields.emplace_back(f->GetNameRef(), OGRFieldDefn::GetFieldTypeName(f->GetType()));
  }
  // A shapefile's types and extent come from its records, without GDAL's geometries (see
  // read_shapefile_summary); a bad coordinate there is GDAL's to report, as for other formats.
  try {
    if (auto direct = read_shapefile_summary(path, layer, progress)) {
      s.feature_count = direct->records;
      s.geometry_types = std::move(direct->geometry_types);
      s.extent = direct->extent;
      return s;
    }
  } catch (const InvalidGeometry&) {
  }
  std::map<std::string, std::int64_t> types;
  ProgressTicker ticker(progress, double(ol.layer->GetFeatureCount(FALSE)));
  const detail::ReadCheck read_check(path);
  for (auto& feature : *ol.layer) {
    ++s.feature_count;
    ticker.tick(double(s.feature_count));
    read_check.feature(feature->GetFID());
    const OGRGeometry* g = feature->GetGeometryRef();
    if (!g) {
      ++types["(none)"];
      continue;
    }
    // A NaN or infinite coordinate is refused, as by every command that reads the layer (the
    // extent said inf, or left the NaN out; a point with one NaN is read as an empty point).
    detail::flatten(g, detail::where(path, feature->GetFID()));
    const std::string type = OGRGeometryTypeToName(g->getGeometryType());
    if (g->IsEmpty()) {  // a geometry without points (POINT EMPTY): counted apart, no extent
      ++types[type + " (empty)"];
      continue;
    }
    ++types[type];
    OGREnvelope e;
    g->getEnvelope(&e);
    s.extent.expand(Box2{{e.MinX, e.MinY}, {e.MaxX, e.MaxY}});
  }
  read_check.finish();
  s.geometry_types.assign(types.begin(), types.end());
  return s;
}

}  // namespace loci::io
