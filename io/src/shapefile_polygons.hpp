// ShapefilePolygons: the geometries of a shapefile's polygon records of several rings, built
// from the .shp as GDAL's shapefile driver builds them, without its sorting of rings.
//
// GDAL sorts the rings of every multi-ring polygon record into polygons by testing each hole
// against every larger outer ring, whole rings at a time: on a layer of countries with
// thousands of islands and lakes, building one country takes minutes. Writing answers as
// GeoJSON, clipping, or testing candidates exactly needs those geometries; this builds the
// same ones (same polygons, rings and points, in the same order) in about linear time
// (build_polygons in shapefile_boxes.cpp), and hands every other record back to GDAL.
// Implemented in shapefile_boxes.cpp beside the direct reader whose rules it shares.
#pragma once

#include <ogrsf_frmts.h>

#include <cstdint>
#include <memory>
#include <string>

#include "shapefile_records.hpp"

namespace loci::io::detail {

class ShapefilePolygons {
 public:
  // Takes the file at `path` when it is a .shp of 2D polygons with its .shx and .dbf, holding
  // the count of records GDAL's `layer` gives, and OGR_ORGANIZE_POLYGONS is not set;
  // otherwise every read() answers nullptr. Reads the files' headers only.
  // `layer` is GDAL's layer of the file, used by fetch() (which sets its ignored fields).
  ShapefilePolygons(const std::string& path, OGRLayer& layer);
  ~ShapefilePolygons();
  ShapefilePolygons(const ShapefilePolygons&) = delete;
  ShapefilePolygons& operator=(const ShapefilePolygons&) = delete;

  // Whether the file was taken (else read() always answers nullptr).
  bool active() const { return bool(files_); }

  // The geometry of feature `fid` as GDAL would give it, with the layer's spatial reference,
  // when it is a polygon record of several rings placed plainly; nullptr when GDAL must build
  // it (any other record, an unusual or unreadable one, a deleted one).
  std::unique_ptr<OGRGeometry> read(std::int64_t fid);

  // Feature `fid` of the layer, as its GetFeature gives it (nullptr when there is none), its
  // geometry from read() when that builds it, GDAL then reading the attributes only.
  OGRFeatureUniquePtr fetch(std::int64_t fid);

 private:
  std::unique_ptr<shp::RecordFiles> files_;
  std::string path_;
  OGRLayer* layer_;
  OGRSpatialReference* srs_ = nullptr;
  bool geometry_ignored_ = false;
};

}  // namespace loci::io::detail
