#include "loci/io/layer_reader.hpp"

#include <gdal_priv.h>
#include <ogrsf_frmts.h>

#include <functional>

#include "loci/geom/error.hpp"

namespace loci::io {
namespace {

struct OpenLayer {
  GDALDatasetUniquePtr dataset;
  OGRLayer* layer = nullptr;
};

OpenLayer open_layer(const std::string& path, const std::string& name) {
  GDALAllRegister();
  CPLPushErrorHandler(CPLQuietErrorHandler);
  OpenLayer ol;
  ol.dataset.reset(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY));
  CPLPopErrorHandler();
  if (!ol.dataset) throw Error(path + ": cannot open as a vector layer");
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

// Calls f(curve) for every line string and ring of g, in reading order.
void for_each_curve(const OGRGeometry* g, const std::function<void(const OGRSimpleCurve&)>& f) {
  if (!g) return;
  switch (wkbFlatten(g->getGeometryType())) {
    case wkbLineString:
    case wkbLinearRing:
      f(*g->toSimpleCurve());
      break;
    case wkbPolygon:
      for (const auto* ring : *g->toPolygon())
        f(*ring);
      break;
    case wkbMultiLineString:
    case wkbMultiPolygon:
    case wkbGeometryCollection:
      for (const auto* part : *g->toGeometryCollection())
        for_each_curve(part, f);
      break;
    default:
      break;
  }
}

}  // namespace

std::vector<SegmentRecord> read_segments(const std::string& path, const std::string& layer) {
  OpenLayer ol = open_layer(path, layer);
  std::vector<SegmentRecord> out;
  for (auto& feature : *ol.layer) {
    const std::int64_t fid = feature->GetFID();
    std::int32_t part = 0;
    for_each_curve(feature->GetGeometryRef(), [&](const OGRSimpleCurve& c) {
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
  OpenLayer ol = open_layer(path, layer);
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

}  // namespace loci::io
