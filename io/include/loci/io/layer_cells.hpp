// The cells of a map layer: a RegionQuadtree over the layer's extent whose boundary cells are
// the finest cells its linework meets (the MX quadtree of the lines and rings), whose inside
// blocks lie in a polygon of the layer, and whose outside blocks meet no feature.
//
// A cell is classified from a per-segment index alone: it is boundary when some segment meets
// the closed cell (an index window query, then the exact box/segment test, stopping at the
// first hit); otherwise no linework crosses it, so the whole cell lies in one face of the
// layer and its centre decides, by crossing parity along a ray (containing_polygons). Points
// (kept as zero-length segments) mark the cells they lie in. The answer is exact: a cell
// touched at one corner by a segment is boundary.
#pragma once

#include "loci/index/region_quadtree.hpp"
#include "loci/io/layer_query.hpp"
#include "loci/io/progress.hpp"

namespace loci::io {

// The region is the index's bounds extended to a square, cut `levels` times (at most
// RegionQuadtree::kMaxLevels). Progress follows the area classified so far.
// Throws InvalidArgument for a per-feature index, an empty layer or bad levels.
RegionQuadtree layer_cells(const LayerIndex& index, int levels, const Progress& progress = {});

}  // namespace loci::io
