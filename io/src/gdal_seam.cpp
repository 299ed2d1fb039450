// The layer reads of gdal_seam.hpp, through GDAL.
#include "gdal_seam.hpp"

#include <cpl_conv.h>

#include <cstdlib>
#include <optional>

#include "gdal_layer.hpp"
#include "shapefile_polygons.hpp"
#include "shapefile_records.hpp"

namespace loci::io::detail {

std::string layer_name_in(const std::string& path, const std::string& name) {
  return open_layer(path, name).layer->GetName();
}

namespace {

// A shapefile's records are read directly where the direct reader takes them (as the `loci`
// front reads them, without building GDAL's geometry), when the GDAL loaded is the one whose
// rules it follows and no option of this process changes how GDAL sorts rings; any other
// feature through GDAL.
class GdalFeatureReader final : public FeatureReader {
 public:
  GdalFeatureReader(const std::string& path, const std::string& name)
      : path_(path), layer_(open_layer(path, name)), polygons_(path, *layer_.layer) {
    const bool rules = std::atoi(GDALVersionInfo("VERSION_NUM")) / 10000 == 306 &&
                       !CPLGetConfigOption("OGR_ORGANIZE_POLYGONS", nullptr) &&
                       !CPLGetConfigOption("OGR_DEBUG_ORGANIZE_POLYGONS", nullptr);
    if (rules) direct_ = std::make_unique<shp::ShapefileFeatures>(path);
  }

  FlatGeometry read(std::int64_t fid) override {
    if (direct_)
      if (std::optional<FlatGeometry> g = direct_->read(fid)) return std::move(*g);
    OGRFeatureUniquePtr f(polygons_.fetch(fid));
    if (!f) throw Error(where(path_, fid) + " is not in the layer: the index does not match it");
    return flatten(f->GetGeometryRef(), where(path_, fid));
  }

 private:
  std::string path_;
  OpenLayer layer_;
  ShapefilePolygons polygons_;  // of layer_
  std::unique_ptr<shp::ShapefileFeatures> direct_;
};

}  // namespace

std::unique_ptr<FeatureReader> open_feature_reader(const std::string& path,
                                                   const std::string& name) {
  return std::make_unique<GdalFeatureReader>(path, name);
}

bool read_whole_layer(const std::string& path, const std::string& name,
                      std::unordered_map<std::int64_t, FlatGeometry>& all) {
  const OpenLayer ol = open_layer(path, name);
  if (fast_random_read(*ol.dataset)) return false;
  ol.layer->ResetReading();
  for (auto& f : *ol.layer)
    all.emplace(f->GetFID(), flatten(f->GetGeometryRef(), where(path, f->GetFID())));
  return true;
}

}  // namespace loci::io::detail
