// The drawing primitives of loci's SVG output (`loci draw`, `loci fleet draw`): a frame from
// world coordinates to pixels (y up, the world's width fitted to the drawing's), rectangles,
// and a layer's linework (its isolated points as dots), projected and rounded to a tenth of a
// pixel with consecutive points that round together dropped.
#pragma once

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "gdal_layer.hpp"
#include "loci/geom/box.hpp"

namespace loci::io::detail {

struct Frame {
  Box2 world;
  double scale;
  int width, height;
  double x(double wx) const { return (wx - world.min[0]) * scale; }
  double y(double wy) const { return (world.max[1] - wy) * scale; }
};

inline bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// The world's width fitted to `width` pixels, at any extent (a layer 1e-15 wide fills the
// drawing as one 1e15 wide does; a floor of 1e-12 once drew small layers in the corner). A side
// of no extent takes the other's; a scale beyond a double's range is held at its largest.
inline Frame frame_of(const Box2& world, int width) {
  Frame f;
  f.world = world;
  const double w0 = world.extent(0), h0 = world.extent(1);
  const double w = w0 > 0 ? w0 : (h0 > 0 ? h0 : 1), h = h0 > 0 ? h0 : w;
  f.width = std::max(width, 16);
  f.scale = std::min(f.width / w, std::numeric_limits<double>::max());
  f.height = int(std::clamp(std::ceil(h * f.scale), 1.0, 1e7));
  return f;
}

// The world a drawing shows around `world`: a margin of 5% of its larger side, so that what
// lies on its edges is drawn whole, and a side of no extent (a layer of one horizontal line,
// of one point) given a tenth of the other, or 1 unit when both have none, so that the drawing
// is not one pixel high. A world too large to pad is kept as it is.
inline Box2 drawn_world(Box2 world) {
  const double larger = std::max(world.extent(0), world.extent(1));
  if (!std::isfinite(larger)) return world;
  const double least = larger > 0 ? larger / 10 : 1;
  const double margin = 0.05 * std::max(larger, least);
  for (int a = 0; a < 2; ++a) {
    const double grow = std::max(0.0, least - world.extent(a)) / 2 + margin;
    world.min[a] -= grow;
    world.max[a] += grow;
  }
  return world;
}

inline void write_rect(std::FILE* o, const Frame& f, const Box2& r) {
  std::fprintf(o, "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\"/>\n", f.x(r.min[0]),
               f.y(r.max[1]), r.extent(0) * f.scale, r.extent(1) * f.scale);
}

// With `lonlat`, a layer in a projected system is refused (check_lonlat_system), and so is
// one without a system whose points are no longitudes and latitudes.
inline void write_linework(std::FILE* o, const Frame& f, const std::string& layer_path,
                           const std::string& layer_name, bool lonlat = false) {
  auto src = open_layer(layer_path, layer_name);
  if (lonlat) check_lonlat_system(layer_path, system_of(*src.layer));
  std::fprintf(o, "<g fill=\"none\" stroke=\"#555\" stroke-width=\"0.5\">\n");
  // Tenths of a pixel, clamped far outside any canvas (a vertex beyond the frame's range
  // would overflow a long: a layer much larger than a fleet drawn at one point).
  const auto tenths = [](double v) { return std::lround(std::clamp(v * 10, -1e15, 1e15)); };
  // With `lonlat`, a layer without a system is refused where a point is no lon/lat.
  const auto check_point = [&](const Point2& p, std::int64_t fid) {
    if (!within_coordinate_range(p)) check_layer_point(p, where(layer_path, fid));
    if (lonlat && !(std::abs(p[0]) <= 180 && std::abs(p[1]) <= 90)) {
      char buf[160];
      std::snprintf(buf, sizeof buf,
                    " has coordinate (%.6g, %.6g), no longitude and latitude, and AIS positions "
                    "are; reproject the layer first (ogr2ogr -t_srs EPSG:4326)",
                    p[0], p[1]);
      throw Error(where(layer_path, fid) + buf);
    }
  };
  for (auto& feature : *src.layer) {
    const std::int64_t fid = feature->GetFID();
    detail::for_each_curve(
        feature->GetGeometryRef(), [&](const OGRSimpleCurve& c, bool, std::uint32_t) {
          const int n = c.getNumPoints();
          for (int i = 0; i < n; ++i)
            check_point({c.getX(i), c.getY(i)}, fid);
          if (n < 2) return;
          std::fprintf(o, "<path d=\"");
          long lx = LONG_MIN, ly = LONG_MIN;
          for (int i = 0; i < n; ++i) {
            const long px = tenths(f.x(c.getX(i))), py = tenths(f.y(c.getY(i)));
            if (px == lx && py == ly && i + 1 < n) continue;
            std::fprintf(o, "%c%.1f %.1f", i == 0 ? 'M' : 'L', px / 10.0, py / 10.0);
            lx = px;
            ly = py;
          }
          std::fprintf(o, "\"/>\n");
        });
    // Isolated points (a point layer, the points of a collection) as dots.
    detail::for_each_point(feature->GetGeometryRef(), where(layer_path, fid), [&](const Point2& p) {
      check_point(p, fid);
      std::fprintf(o, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"1.5\" fill=\"#555\"/>\n",
                   tenths(f.x(p[0])) / 10.0, tenths(f.y(p[1])) / 10.0);
    });
  }
  std::fprintf(o, "</g>\n");
}

// The SVG's opening: size, view box and a white background.
inline void write_svg_head(std::FILE* o, const Frame& f) {
  std::fprintf(o,
               "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" "
               "viewBox=\"0 0 %d %d\">\n<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n",
               f.width, f.height, f.width, f.height);
}

}  // namespace loci::io::detail
