// The seam of gdal_seam.hpp without GDAL: every function that would read or write through
// GDAL throws NeedsGdal, except the reading of a shapefile's features, which the direct reader
// (shapefile_records.hpp) does as GDAL would, where it can. Linked only into the `loci` front, in
// place of the GDAL part of loci::io, so that a query its sidecar answers starts without loading
// GDAL.
#include "gdal_seam.hpp"
#include "loci/io/atomic_file.hpp"
#include "loci/io/layer_reader.hpp"
#include "shapefile_records.hpp"

namespace loci::io {

LayerItems read_items(const std::string&, const std::string&, Per, const Progress&, bool) {
  throw detail::NeedsGdal();
}

// Met only by a text output onto an SQLite database or a TIFF (AtomicFile), which appeared
// after the front chose to answer: refused as loci-full refuses any text output there.
void refuse_replacing_layers(const std::string& out) {
  refuse_replacing_binary_dataset(out);
  throw detail::NeedsGdal();
}

namespace detail {

std::string layer_name_in(const std::string&, const std::string&) {
  throw NeedsGdal();
}

namespace {

// A shapefile's features as GDAL's driver gives them, read without it; a record the direct
// reader leaves to GDAL needs GDAL.
class ShapefileFeatureReader final : public FeatureReader {
 public:
  explicit ShapefileFeatureReader(const std::string& path) : features_(path) {
    if (!features_.active()) throw NeedsGdal();
  }
  FlatGeometry read(std::int64_t fid) override {
    std::optional<FlatGeometry> g = features_.read(fid);
    if (!g) throw NeedsGdal();
    return std::move(*g);
  }

 private:
  shp::ShapefileFeatures features_;
};

}  // namespace

std::unique_ptr<FeatureReader> open_feature_reader(const std::string& path, const std::string&) {
  return std::make_unique<ShapefileFeatureReader>(path);
}

// Only a shapefile is read here, by FID in place.
bool read_whole_layer(const std::string& path, const std::string&,
                      std::unordered_map<std::int64_t, FlatGeometry>&) {
  if (!shp::ShapefileFeatures(path).active()) throw NeedsGdal();
  return false;
}

void write_feature_answers(const AnswerSource&, std::span<const Answer>, Format, bool, bool, bool,
                           const std::string&, std::FILE*) {
  throw NeedsGdal();
}

}  // namespace detail
}  // namespace loci::io
