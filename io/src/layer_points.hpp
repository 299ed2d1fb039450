// How io/ names a feature in messages and checks a layer's coordinates, shared by its GDAL part
// and its GDAL-free core. Private to io/.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>

#include "loci/geom/error.hpp"
#include "loci/geom/point.hpp"

namespace loci::io::detail {

inline std::string where(const std::string& path, std::int64_t fid) {
  return path + ": feature " + std::to_string(fid);
}

// Throws InvalidGeometry naming `what` for a NaN or infinite coordinate, or one beyond
// +-kMaxCoordinate (1e150), which loci's distance arithmetic cannot carry.
inline void check_layer_point(const Point2& p, const std::string& what) {
  if (!is_finite(p)) throw InvalidGeometry(what + " has a NaN or infinite coordinate");
  if (!within_coordinate_range(p)) {
    char buf[96];
    std::snprintf(buf, sizeof buf, " has coordinate (%.6g, %.6g), beyond +-1e150", p[0], p[1]);
    throw InvalidGeometry(what + buf + ": too large for exact distances");
  }
}

}  // namespace loci::io::detail
