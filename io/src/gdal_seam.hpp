// The seam between io/'s GDAL-free core and its GDAL part.
//
// A query on a sidecar per segment (or for candidates only) reads nothing but the sidecar: it
// runs without GDAL, whose 115 libraries take about 30 ms to load. The core (the sidecar, the
// queries, the ids output, atomic files) calls GDAL only through the functions declared here
// and those of the public headers listed below. The full library (loci::io) defines them with
// GDAL; the `loci` front (cli/front.cpp), which does not link GDAL, is linked with
// without_gdal.cpp instead, where each throws NeedsGdal, except that a shapefile's features
// are read there directly (shapefile_records.hpp) where they can be; the front hands any
// command that meets NeedsGdal to `loci-full` before it has read its input or written
// anything, or, per feature of a shapefile, before it has written anything, its queries
// coming from the command line, a regular file, or a copy in memory of a pipe's, which
// loci-full reads again. What
// changes while it reads its queries (the layer, an output file appearing) is met as
// loci-full meets it where that needs no GDAL, or refused (query_layer,
// refuse_replacing_layers in without_gdal.cpp).
//
// Also on the seam, declared where their callers find them: read_items (layer_reader.hpp) and
// refuse_replacing_layers (atomic_file.hpp). A core file that calls any other GDAL function
// fails to link into the front.
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <span>
#include <string>
#include <unordered_map>

#include "loci/geom/error.hpp"
#include "loci/io/commands.hpp"
#include "loci/io/exact.hpp"
#include "loci/io/output.hpp"

namespace loci::io::detail {

// The work asked for needs GDAL, which this process has not loaded (commands.hpp).
using loci::io::NeedsGdal;

// The name GDAL gives the layer `name` of `path` (the first layer when empty): a name matched
// without regard to case comes back as the layer spells it. Throws loci::Error as open_layer.
std::string layer_name_in(const std::string& path, const std::string& name);

// A layer's features by FID, each flattened for the exact tests; a shapefile's records are read
// directly where the direct reader takes them, and its polygons of many rings built without
// GDAL's sorting of rings.
class FeatureReader {
 public:
  virtual ~FeatureReader() = default;
  // Throws loci::Error for a FID not in the layer, InvalidGeometry for a bad coordinate.
  virtual FlatGeometry read(std::int64_t fid) = 0;
};
std::unique_ptr<FeatureReader> open_feature_reader(const std::string& path,
                                                   const std::string& name);

// For a layer whose driver finds a feature by FID by parsing the file from its start (GeoJSON,
// CSV, GML...): every geometry, flattened, into `all`, and true. False, with `all` untouched,
// for a layer read by FID in place.
bool read_whole_layer(const std::string& path, const std::string& name,
                      std::unordered_map<std::int64_t, FlatGeometry>& all);

// write_answers' csv and GeoJSON formats, which read the features' attributes and geometries.
void write_feature_answers(const AnswerSource& source, std::span<const Answer> answers,
                           Format format, bool numbered, bool with_distance, bool with_point,
                           const std::string& out_path, std::FILE* fallback);

}  // namespace loci::io::detail
