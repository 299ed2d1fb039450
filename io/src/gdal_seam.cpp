// The layer reads of gdal_seam.hpp, through GDAL.
#include "gdal_seam.hpp"

#include "gdal_layer.hpp"
#include "shapefile_polygons.hpp"

namespace loci::io::detail {

std::string layer_name_in(const std::string& path, const std::string& name) {
  return open_layer(path, name).layer->GetName();
}

namespace {

class GdalFeatureReader final : public FeatureReader {
 public:
  GdalFeatureReader(const std::string& path, const std::string& name)
      : path_(path), layer_(open_layer(path, name)), polygons_(path, *layer_.layer) {}

  FlatGeometry read(std::int64_t fid) override {
    OGRFeatureUniquePtr f(polygons_.fetch(fid));
    if (!f) throw Error(where(path_, fid) + " is not in the layer: the index does not match it");
    return flatten(f->GetGeometryRef(), where(path_, fid));
  }

 private:
  std::string path_;
  OpenLayer layer_;
  ShapefilePolygons polygons_;  // of layer_
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
