// What the io/ sources share about GDAL (implemented in gdal_layer.cpp): opening a layer with
// a useful error, walking the linework of an OGR geometry, flattening it for the exact tests,
// and choosing an output driver. Private to io/: no public header includes GDAL.
#pragma once

#include <gdal_priv.h>
#include <ogrsf_frmts.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "layer_points.hpp"
#include "loci/io/exact.hpp"
#include "loci/io/layer_reader.hpp"

namespace loci::io::detail {

struct OpenLayer {
  GDALDatasetUniquePtr dataset;
  OGRLayer* layer = nullptr;
};

// Throws loci::Error for a path GDAL cannot open, a missing layer or a layer without geometry.
OpenLayer open_layer(const std::string& path, const std::string& name);

// Whether (path_a, name_a) and (path_b, name_b) select the same layer: the same file however
// spelled (same_file), and names that pick the same layer of it (an empty name is the first
// layer; GDAL matches a name without regard to case when no layer has it exactly).
bool same_layer(const std::string& path_a, const std::string& name_a, const std::string& path_b,
                const std::string& name_b);

// Whether the dataset's driver reads a feature by FID in place (shapefile, GeoPackage,
// FlatGeobuf...); the others (GeoJSON, CSV, GML, KML...) parse from the start of the file for
// each lookup.
bool fast_random_read(GDALDataset& ds);

// A coordinate system's authority and code ("EPSG:4326"), empty when it has none.
std::string authority_code(const OGRSpatialReference& srs);

// A layer's coordinate system as WKT, empty when it has none.
std::string system_of(const OGRLayer& layer);

// A layer as messages name it: the file, and the layer when one was named (two layers of one
// GeoPackage read apart).
inline std::string layer_label(const std::string& path, const std::string& layer) {
  return layer.empty() ? path : path + " (layer '" + layer + "')";
}

// Throws loci::Error when two layers (files a and b, systems as system_of gives them) are in
// different coordinate systems: their coordinates cannot be compared. A layer without a system
// is taken to be in the other's.
void check_same_system(const std::string& a, const std::string& a_system, const std::string& b,
                       const std::string& b_system);

// Throws loci::Error when the layer at `path` (its system as system_of gives it) is in a
// projected system: AIS positions are longitudes and latitudes. Any geographic system (WGS 84,
// ETRS89, NAD83: within metres of each other) or none is taken as theirs.
void check_lonlat_system(const std::string& path, const std::string& system);

// The "crs" member (with its trailing comma) a GeoJSON text written by hand gives coordinates
// in `system` (system_of's WKT), as GDAL's GeoJSON writer names it: empty for WGS 84
// longitudes and latitudes (GeoJSON's own), for no system, or one without an authority code.
std::string geojson_crs_member(const std::string& system);

// Whether a feature's geometry has no points to index (none, or an empty one), to be skipped.
// GDAL reads a point with a NaN coordinate (GeoJSON's NaN, `[NaN, 3]`) as an empty point that
// keeps its NaN: that one is bad input, and throws InvalidGeometry naming `what` like any other
// NaN coordinate, also inside an empty collection. A point with both coordinates NaN is
// POINT EMPTY as WKB and GeoPackage write it, and is empty.
bool without_points(const OGRGeometry* g, const std::string& what);

// Checks the isolated points of g (a point, or the points of a collection) as flatten() does:
// throws InvalidGeometry naming `what` for a NaN, infinite or too large coordinate. For readers
// of linework only, which skip points but must refuse bad ones like every other reader.
void check_points(const OGRGeometry* g, const std::string& what);

// Calls f(p) for every isolated point of g (a point, or the points of a multipoint or
// collection, in reading order), each checked as check_points() checks it; empty points are
// skipped.
void for_each_point(const OGRGeometry* g, const std::string& what,
                    const std::function<void(const Point2&)>& f);

// Calls f(curve, is_ring, polygon) for every line string and ring of g, in reading order;
// `polygon` counts the polygons met so far (rings of one polygon share it). A ring whose last
// point is not its first (GDAL reads one, with a warning) is handed over closed: the
// closing edge is implied, by every command alike.
void for_each_curve(const OGRGeometry* g,
                    const std::function<void(const OGRSimpleCurve&, bool, std::uint32_t)>& f);

// Whether the ring does not end at the point it starts from, in plan (ends differing only in
// z are closed).
bool unclosed(const OGRLinearRing& ring);

// Whether a ring of g (of its polygons, at any depth of collections) is unclosed().
bool has_unclosed_ring(const OGRGeometry& g);

// Throws InvalidGeometry (naming `what`) on a NaN or infinite coordinate.
FlatGeometry flatten(const OGRGeometry* g, const std::string& what);

// The segments of g for a per-segment index, appended to `out` (what read_items gives per
// segment): each line or ring's consecutive points, parts numbered in order, a ring's
// segments with the number of the polygon it bounds; a curve of one point and each isolated
// point as a segment of length zero. Refuses a coordinate out of range.
void add_segments(const OGRGeometry* g, std::int64_t fid, const std::string& path, LayerItems& out);

// A triangle, TIN or polyhedral surface: a surface made of polygon faces, read as those faces.
inline bool of_faces(OGRwkbGeometryType type) {
  type = wkbFlatten(type);
  return type == wkbTriangle || type == wkbTIN || type == wkbPolyhedralSurface;
}

// GDAL reports a file it can read only in part (a truncated or garbled shapefile) through its
// error state, feature after feature, and still hands out what it could read. A ReadCheck made
// before reading resets that state; finish() after reading throws loci::Error naming the file
// and carrying GDAL's message if anything failed, so a layer is read whole or refused.
// finish() also refuses a layer whose features share a FID (GDAL gives GeoJSON features their
// "id", repeated or not): loci reads features back by FID, which would fetch the wrong one.
class ReadCheck {
 public:
  explicit ReadCheck(std::string path);
  // Called right after feature `fid` is read: throws as finish() does, naming the feature,
  // when reading it failed (GDAL reports a geometry it cannot parse, a CSV's unreadable WKT
  // say, while reading its feature, and hands the feature out without it).
  void feature(std::int64_t fid) const;
  void finish() const;

 private:
  // Throws the failure GDAL's error state holds, `where` (say "feature 2: ") before its text.
  [[noreturn]] void fail(const std::string& where) const;
  std::string path_;
  // The FIDs read, and whether they came in increasing order (then none repeats).
  mutable std::vector<std::int64_t> fids_;
  mutable bool increasing_ = true;
};

// Feature `fid` of `layer` (nullptr when it has none, a deleted record too), read by FID;
// throws loci::Error naming the file at `path` and the feature when GDAL could read it only in
// part (the file truncated or
// rewritten since it was opened: GDAL says so through its error state and hands the feature out
// without its geometry, which would drop it from an answer unsaid).
OGRFeatureUniquePtr read_feature(OGRLayer& layer, std::int64_t fid, const std::string& path);

// A GDAL vector driver chosen from the output file name's extension (.geojson or .json, .shp,
// .gpkg, .fgb, .csv, .kml, .gml); any other extension is an InvalidArgument.
GDALDriver* driver_for(const std::string& path);

}  // namespace loci::io::detail
