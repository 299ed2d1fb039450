// Per-feature boxes and per-segment items of an ESRI shapefile, read straight from its .shx
// and .shp.
//
// An index per feature needs one box per feature, and one per segment the segments, yet
// reading the layer through GDAL builds every geometry whole (and, for polygons, sorts rings
// into polygons), which is most of the time `loci index` takes on a large shapefile. The shapefile
// format (ESRI Shapefile Technical Description, 1998) makes a direct read simple:
//
//   .shx  100-byte header (file length in 16-bit words, big-endian, at byte 24), then one
//         8-byte entry per record: offset and content length, in 16-bit words, big-endian.
//   .shp  the same header; each record an 8-byte big-endian header, then little-endian
//         content: shape type, and for multipoints, lines and polygons a stored box, the
//         counts of parts and points, the part starts and the x,y points (Z and M follow).
//   .dbf  the attribute table: one record per shape, a leading '*' marking it deleted.
//
// The stored box is not trusted: each feature's box is the minimum and maximum over its
// points, which is GDAL's envelope, and every point is checked for NaN, infinity and range
// as the GDAL path does, with the same message. FIDs are record numbers from 0, as GDAL's
// shapefile driver gives them; null shapes are skipped, as features without geometry are.
//
// Anything unusual hands the file back to GDAL (nullopt): a missing .shx or .dbf, deleted
// records, counts that disagree, a record out of bounds or inconsistent, mixed or
// multipatch shapes, empty shapes. So a file is either read here with GDAL's answer, or read
// by GDAL. The .shp is read sequentially in chunks, never held whole.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "loci/io/layer_reader.hpp"

namespace loci::io {

struct ShapefileBoxes {
  LayerItems items;            // per feature
  std::uint64_t segments = 0;  // what a per-segment read would give: to choose granularity
};

// Reads the per-feature boxes of the shapefile at `path` (a .shp) directly, or returns
// nullopt when `path` is not a shapefile this reader takes (GDAL then reads it). `layer`
// as for read_items. Throws InvalidGeometry for a bad coordinate, loci::Error when the file
// cannot be opened or read.
std::optional<ShapefileBoxes> read_shapefile_boxes(const std::string& path,
                                                   const std::string& layer = {},
                                                   const Progress& progress = {});

// The per-segment items of the same shapefiles, read directly under the same rules: every
// segment of every line and ring, with its flags, as read_items(path, layer, Per::segment)
// gives through GDAL, parts numbered in the file's order (GDAL may regroup a polygon's
// rings); each point of a point or multipoint shape as a zero-length segment. Every point is
// checked, as per feature: a bad coordinate in a part of one point, which has no segment and
// which the GDAL path does not look at, is refused too. nullopt when GDAL must read the file;
// throws as read_shapefile_boxes.
std::optional<LayerItems> read_shapefile_segments(const std::string& path,
                                                  const std::string& layer = {},
                                                  const Progress& progress = {});

// What `loci info` reports of a shapefile the direct reader takes, without building its
// geometries: the records, how many of each geometry type GDAL's shapefile driver makes of
// them, and the extent. Points are Point, multipoints Multi Point, lines of one part Line
// String and of more Multi Line String; a polygon record of one ring is a Polygon, and of more
// a Polygon when exactly one ring is an outer ring (clockwise, the format's rule: holes run
// counter-clockwise) and the others start inside it, a Multi Polygon when more rings are
// outer. GDAL sorts the rings of a record with several outer rings into polygons by testing
// which holds which, all against all, which takes minutes on a layer of countries with
// thousands of islands; the orientation of the rings gives the type in linear time. nullopt,
// for GDAL to answer, when the file is not one the direct reader takes, when
// OGR_ORGANIZE_POLYGONS is set, and when a record holds a ring orientation cannot place
// plainly (see polygon_type in the source); throws as read_shapefile_boxes.
struct ShapefileSummary {
  std::int64_t records = 0;                                          // null shapes included
  std::vector<std::pair<std::string, std::int64_t>> geometry_types;  // GDAL's names, "(none)"
  Box2 extent = Box2::empty();
};
std::optional<ShapefileSummary> read_shapefile_summary(const std::string& path,
                                                       const std::string& layer = {},
                                                       const Progress& progress = {});

}  // namespace loci::io
