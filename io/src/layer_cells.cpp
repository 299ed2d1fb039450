#include "loci/io/layer_cells.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "loci/geom/error.hpp"
#include "loci/geom/segment.hpp"

namespace loci::io {

RegionQuadtree layer_cells(const LayerIndex& index, int levels, const Progress& progress) {
  if (index.per() != Per::segment)
    throw InvalidArgument("the cells of a layer need a per-segment index (--per segment)");
  if (index.size() == 0) throw InvalidArgument("the layer has no geometry to cover");
  Box2 region = index.bounds();
  // a layer along one line, or a single point, still gets a square to cut
  double side =
      std::max({region.extent(0), region.extent(1),
                1e-9 * std::max(std::abs(region.min[0]), std::abs(region.min[1])), 1e-300});
  for (int a = 0; a < 2; ++a)  // min + (max - min) may round below max
    while (region.min[a] + side < region.max[a])
      side = std::nextafter(side, std::numeric_limits<double>::infinity());
  region.max = {region.min[0] + side, region.min[1] + side};
  // progress is the area of the leaves made so far; finest cells are leaves whatever they are
  const double finest = std::ldexp(side, -std::clamp(levels, 0, RegionQuadtree::kMaxLevels));
  ProgressTicker ticker(progress, side * side);
  double done = 0;
  RegionQuadtree cells = RegionQuadtree::build(region, levels, [&](const Box2& cell) {
    bool crossed = false;
    index.window(cell, [&](const ItemRecord& r, const Box2& b) {
      crossed = intersects(cell, segment_of(b, r.flags));
      return !crossed;
    });
    if (!crossed || cell.extent(0) <= 1.5 * finest) ticker.tick(done += cell.content());
    if (crossed) return Cover::boundary;
    return containing_polygons(index, cell.center()).empty() ? Cover::outside : Cover::inside;
  });
  if (progress) progress(1.0);
  return cells;
}

}  // namespace loci::io
