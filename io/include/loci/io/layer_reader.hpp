// Reading vector layers through GDAL/OGR: any path GDAL opens (shapefile, GeoPackage,
// GeoJSON, TopoJSON, FlatGeobuf, ...), one layer chosen by name or the first one.
//
// A layer is read either as one envelope per feature or as the segments of its linework (every
// segment of every line string and of every polygon ring, with the feature's FID and the part
// number). Coordinates are the layer's own; only x and y are kept.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "loci/geom/box.hpp"
#include "loci/geom/segment.hpp"

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
// geometry column, or a coordinate is NaN or infinite (naming the feature).
std::vector<SegmentRecord> read_segments(const std::string& path, const std::string& layer = {});
std::vector<FeatureRecord> read_envelopes(const std::string& path, const std::string& layer = {});

}  // namespace loci::io
