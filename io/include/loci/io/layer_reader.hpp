// Reading vector layers through GDAL/OGR: any path GDAL opens (shapefile, GeoPackage,
// GeoJSON, TopoJSON, FlatGeobuf, ...), one layer chosen by name or the first one.
//
// A layer is read either as one envelope per feature or as the segments of its linework (every
// segment of every line string and of every polygon ring, with the feature's FID and the part
// number). Coordinates are the layer's own; only x and y are kept. read_items() is what an
// index is built from: one box and one ItemRecord per entry, in either granularity.
//
// GDAL's GeoJSON driver refuses single objects above 200 MB unless told otherwise; Natural
// Earth's 10 m countries exceed it, so the limit is lifted unless the user set it.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "loci/geom/box.hpp"
#include "loci/geom/segment.hpp"
#include "loci/io/exact.hpp"
#include "loci/io/progress.hpp"
#include "loci/io/sidecar.hpp"

namespace loci::io {

struct SegmentRecord {
  Segment<2> segment;
  std::int64_t fid;   // the feature id GDAL reports
  std::int32_t part;  // index of the line or ring within the feature, in reading order
};

struct FeatureRecord {
  Box<2> envelope;
  std::int64_t fid;
};

// Throws loci::Error when the path cannot be opened, the layer does not exist or has no
// geometry column, or a coordinate is NaN or infinite (naming the feature). `system`, when
// given, receives the layer's coordinate system as WKT (empty when it has none).
std::vector<SegmentRecord> read_segments(const std::string& path, const std::string& layer = {},
                                         const Progress& progress = {},
                                         std::string* system = nullptr);
std::vector<FeatureRecord> read_envelopes(const std::string& path, const std::string& layer = {});

struct LayerItems {
  Per per = Per::feature;
  std::string layer_name;  // the layer actually read
  bool has_polygons = false;
  std::vector<Box2> boxes;
  std::vector<ItemRecord> records;  // records[i] describes boxes[i]
  // With keep_geometries, per feature, for a text layer (one GDAL cannot read by FID in
  // place): every feature's flattened geometry, so that queries need not read it again.
  std::unordered_map<std::int64_t, FlatGeometry> geometries;
  std::uint64_t features = 0;          // features with a geometry
  std::uint64_t without_geometry = 0;  // features skipped: no geometry, or an empty one
  // The hash fingerprint_of() gives the layer's files, when the reader had it from the bytes
  // it read (a shapefile read directly); else nothing, and the caller hashes them itself.
  std::optional<std::uint64_t> content_hash;
};

// Throws like read_segments; features with an empty or missing geometry are skipped.
LayerItems read_items(const std::string& path, const std::string& layer, Per per,
                      const Progress& progress = {}, bool keep_geometries = false);

// A layer's features average at least this many segments: per segment serves it better (a
// query then never tests, nor fetches from GDAL, a huge geometry whole).
inline constexpr std::uint64_t kSegmentsPerFeatureForSegments = 64;

// read_items() choosing the granularity in the same pass: per segment when the features
// average at least kSegmentsPerFeatureForSegments segments, else per feature.
LayerItems read_items_choosing(const std::string& path, const std::string& layer,
                               const Progress& progress = {});

struct LayerSummary {
  std::string path;
  std::string driver;
  std::string layer_name;
  std::vector<std::string> layer_names;  // every layer of the dataset
  std::int64_t feature_count = 0;
  // GDAL's type names and counts, in name order: "(none)" counts features without a geometry,
  // "Point (empty)" and the like geometries without points; neither widens the extent.
  std::vector<std::pair<std::string, std::int64_t>> geometry_types;
  Box2 extent = Box2::empty();
  std::string crs;  // a short name of the layer's coordinate system, or empty
  std::vector<std::pair<std::string, std::string>> fields;  // name, type
};

// The name of the layer a command reads when no --layer is given: the dataset's first. For
// formats that hold one layer (shapefile, GeoJSON, FlatGeobuf) this is "" without opening the
// file: there is nothing to choose. Throws like read_segments.
std::string default_layer_name(const std::string& path);

// Reads every feature to count geometry types. Throws like read_segments.
LayerSummary summarize_layer(const std::string& path, const std::string& layer,
                             const Progress& progress = {});

}  // namespace loci::io
