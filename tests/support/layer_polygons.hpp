// The polygons of a layer read through GDAL, as BspPolygon (outer ring and holes), for the
// suites and benchmarks that build a BspTree from a real map layer. Needs GDAL at link time.
#pragma once

#include <gdal.h>
#include <ogr_api.h>
#include <ogrsf_frmts.h>

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "loci/index/broadphase/bsp_tree.hpp"

namespace loci::test {

inline std::vector<Point2> ogr_ring(const OGRLinearRing& r) {
  std::vector<Point2> out;
  out.reserve(static_cast<std::size_t>(r.getNumPoints()));
  for (int i = 0; i < r.getNumPoints(); ++i)
    out.push_back({r.getX(i), r.getY(i)});
  return out;
}

inline void add_ogr_polygon(const OGRPolygon& p, std::vector<BspPolygon>& out) {
  if (p.IsEmpty()) return;
  BspPolygon poly;
  poly.outer = ogr_ring(*p.getExteriorRing());
  for (int i = 0; i < p.getNumInteriorRings(); ++i)
    poly.holes.push_back(ogr_ring(*p.getInteriorRing(i)));
  out.push_back(std::move(poly));
}

// Every polygon of every feature of the first layer of `path`.
inline std::vector<BspPolygon> read_polygons(const std::string& path) {
  GDALAllRegister();
  std::unique_ptr<GDALDataset> ds(
      GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY));
  if (!ds) throw std::runtime_error("cannot open " + path);
  OGRLayer* layer = ds->GetLayer(0);
  std::vector<BspPolygon> out;
  for (auto& f : *layer) {
    const OGRGeometry* g = f->GetGeometryRef();
    if (!g) continue;
    switch (wkbFlatten(g->getGeometryType())) {
      case wkbPolygon:
        add_ogr_polygon(*g->toPolygon(), out);
        break;
      case wkbMultiPolygon:
        for (const OGRPolygon* p : *g->toMultiPolygon())
          add_ogr_polygon(*p, out);
        break;
      default:
        break;
    }
  }
  return out;
}

}  // namespace loci::test
