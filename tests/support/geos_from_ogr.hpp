// An OGR geometry handed to GEOS's C API (through WKB), for the benchmarks that run GEOS beside
// loci on layers read with GDAL.
#pragma once

#include <geos_c.h>
#include <ogr_geometry.h>

#include <vector>

namespace loci::test {

inline GEOSGeometry* to_geos(GEOSContextHandle_t geos, GEOSWKBReader* reader,
                             const OGRGeometry& g) {
  std::vector<unsigned char> wkb(static_cast<std::size_t>(g.WkbSize()));
  g.exportToWkb(wkbNDR, wkb.data());
  return GEOSWKBReader_read_r(geos, reader, wkb.data(), wkb.size());
}

}  // namespace loci::test
