// `loci draw`: an SVG of a layer's linework under the nodes of its packed R-tree, one colour
// per level, so that a user sees how the packing grouped their data (long thin nodes, nodes
// straddling the antimeridian, overlap between siblings); or, with --cells, under the layer's
// region quadtree: inside blocks, the MX boundary cells its linework runs through, and the
// empty blocks outlined.
//
// The tree's levels come from its implicit layout (PackedRTree::level) and a node's rectangle
// is the union of its entries. Linework is projected to pixels with y up and
// rounded to a tenth of a pixel; consecutive points that round together are dropped, which
// keeps a drawing of a million-segment layer a few megabytes.
#include <cmath>
#include <cstdio>

#include <sys/stat.h>

#include "gdal_layer.hpp"
#include "loci/geom/error.hpp"
#include "loci/io/commands.hpp"
#include "loci/io/layer_cells.hpp"
#include "svg.hpp"

namespace loci::io {
namespace {

using detail::Frame;
using detail::write_rect;

// Nodes, from the leaves' parents up to the root, coarser levels drawn last and thicker.
std::size_t write_nodes(std::FILE* o, const Frame& f, const PackedRTree2& tree, int max_levels) {
  static const char* colours[] = {"#1b9e77", "#d95f02", "#7570b3", "#e7298a", "#66a61e", "#e6ab02"};
  const auto blocks = tree.blocks();
  const int levels = tree.levels();
  const int first = std::max(0, levels - max_levels);
  std::size_t drawn = 0;
  for (int l = first; l < levels; ++l) {
    std::fprintf(o, "<g fill=\"none\" stroke=\"%s\" stroke-width=\"%.1f\" opacity=\"0.8\">\n",
                 colours[(levels - 1 - l) % 6], 0.6 + 0.6 * (l - first));
    const auto& level = tree.level(l);
    for (std::size_t b = 0; b < level.blocks; ++b) {
      const int used = int(std::min<std::size_t>(PackedRTree2::node_size,
                                                 level.entries - b * PackedRTree2::node_size));
      write_rect(o, f, blocks[level.first_block + b].bounds(used));
      ++drawn;
    }
    std::fprintf(o, "</g>\n");
  }
  return drawn;
}

// One group per cover, each leaf once: outside blocks outlined, the others filled.
std::size_t write_cells(std::FILE* o, const Frame& f, const RegionQuadtree& cells) {
  static const char* styles[] = {
      "fill=\"none\" stroke=\"#bbb\" stroke-width=\"0.4\"",         // outside
      "fill=\"#cfe8c9\" stroke=\"#7fb174\" stroke-width=\"0.4\"",   // inside
      "fill=\"#f4a261\" stroke=\"#c4703a\" stroke-width=\"0.3\""};  // boundary
  std::size_t drawn = 0;
  for (const Cover c : {Cover::outside, Cover::inside, Cover::boundary}) {
    std::fprintf(o, "<g %s>\n", styles[int(c)]);
    cells.visit_cells([&](const QuadCell& cell) {
      if (cell.cover != c) return;
      write_rect(o, f, cell.box);
      ++drawn;
    });
    std::fprintf(o, "</g>\n");
  }
  return drawn;
}

}  // namespace

std::size_t draw_index(const DrawOptions& options) {
  LoadOptions load;
  if (!options.index_path.empty()) {
    load.layer_path = options.path;
    load.index_path = options.index_path;
  } else if (detail::ends_with(options.path, ".loci")) {
    load.layer_path = options.path.substr(0, options.path.size() - 5);
    load.index_path = options.path;
    struct stat st {};
    if (::stat(options.path.c_str(), &st) == 0 && ::stat(load.layer_path.c_str(), &st) != 0 &&
        load.layer_path.rfind("/vsi", 0) != 0)
      throw Error(options.path + ": its layer " + load.layer_path +
                  " is missing (an index is drawn over the layer it was built from: loci draw "
                  "LAYER --index " +
                  options.path + ")");
  } else {
    load.layer_path = options.path;
  }
  load.layer_name = options.layer_name;
  load.progress = options.progress;
  refuse_overwriting(options.out_path, load.layer_path);  // the layer a sidecar names too
  refuse_overwriting(options.out_path, sidecar_path_of(load), "index");  // LAYER.loci by default
  const bool cells = options.cell_levels >= 0;
  if (cells) load.per = Per::segment;
  const LayerIndex index = load_index(load);
  const PackedRTree2* tree = index.packed();
  if (!tree || tree->empty()) throw Error(options.path + ": nothing to draw");
  RegionQuadtree quadtree;
  if (cells) quadtree = layer_cells(index, options.cell_levels, options.progress);

  const Frame f = detail::frame_of(detail::drawn_world(cells ? quadtree.region() : tree->bounds()),
                                   options.width);
  OutputFile out(options.out_path, stdout);
  std::FILE* o = out.stream();
  detail::write_svg_head(o, f);
  std::size_t drawn = 0;
  if (cells) drawn = write_cells(o, f, quadtree);
  detail::write_linework(o, f, load.layer_path, index.layer_name());
  if (!cells) drawn = write_nodes(o, f, *tree, options.max_levels);
  std::fprintf(o, "</svg>\n");
  out.commit();
  return drawn;
}

}  // namespace loci::io
