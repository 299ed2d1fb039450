// The cells of a layer (io::layer_cells and `loci draw --cells`) against a brute force through
// OGR's own geometry (GEOS): a finest cell is boundary when some feature's linework (a
// polygon's rings, a line, a point) meets the closed cell, inside when its centre lies in a
// polygon, outside otherwise. On the bundled Natural Earth sample and on a layer built on an
// integer grid so that rings, lines and points run exactly along cell edges and corners.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "layers/cli_support.hpp"
#include "loci/io/layer_cells.hpp"

namespace fs = std::filesystem;
using namespace loci;
using namespace loci::test;

namespace {

struct Truth {
  OgrFeatureSet features;
  std::vector<std::unique_ptr<OGRGeometry>> linework;  // per feature
  std::vector<bool> polygonal;
};

Truth truth_of(const std::string& path) {
  Truth t{read_with_ogr(path), {}, {}};
  for (const auto& g : t.features.geoms) {
    const auto flat = wkbFlatten(g->getGeometryType());
    const bool poly = flat == wkbPolygon || flat == wkbMultiPolygon;
    t.polygonal.push_back(poly);
    t.linework.emplace_back(poly ? g->Boundary() : g->clone());
  }
  return t;
}

Cover brute_cover(const Truth& t, const Box2& cell) {
  const auto box = ogr_box(cell.min[0], cell.min[1], cell.max[0], cell.max[1]);
  for (const auto& l : t.linework)
    if (l->Intersects(box.get())) return Cover::boundary;
  const OGRPoint centre(cell.center(0), cell.center(1));
  for (std::size_t i = 0; i < t.linework.size(); ++i)
    if (t.polygonal[i] && t.features.geoms[i]->Contains(&centre)) return Cover::inside;
  return Cover::outside;
}

void expect_matches_ogr(const std::string& path, int levels) {
  const Truth truth = truth_of(path);
  ASSERT_FALSE(truth.features.fids.empty()) << path;
  const auto index = io::LayerIndex::build(io::read_items(path, "", io::Per::segment),
                                           io::Structure::packed_hilbert);
  double last = -1;
  const RegionQuadtree cells = io::layer_cells(index, levels, [&](double f) {
    EXPECT_GE(f, last);
    last = f;
  });
  EXPECT_EQ(last, 1.0);
  cells.validate();
  const std::uint32_t n = 1u << levels;
  std::size_t boundary = 0;
  for (std::uint32_t y = 0; y < n; ++y)
    for (std::uint32_t x = 0; x < n; ++x) {
      const Box2 cell = cells.cell_box(x, y, levels);
      const Cover want = brute_cover(truth, cell);
      ASSERT_EQ(cells.cover_at(cell.center()), want)
          << path << ": cell " << x << "," << y << " " << to_string(cell);
      boundary += want == Cover::boundary;
    }
  EXPECT_EQ(cells.count(Cover::boundary), boundary);
}

// Polygons with a hole and a shared edge, a line along a grid line, points inside a cell and
// on a cell corner, all on the 16 x 16 grid of the layer's extent [0, 16]^2 at 4 levels.
std::string grid_layer(const fs::path& dir) {
  const fs::path p = dir / "grid.geojson";
  std::ofstream(p) << R"({"type": "FeatureCollection", "features": [
{"type": "Feature", "properties": {}, "geometry": {"type": "Polygon", "coordinates": [
  [[2, 2], [10, 2], [10, 10], [2, 10], [2, 2]], [[4, 4], [4, 6], [6, 6], [6, 4], [4, 4]]]}},
{"type": "Feature", "properties": {}, "geometry": {"type": "Polygon", "coordinates": [
  [[10, 2], [14, 2], [14, 6], [10, 6], [10, 2]]]}},
{"type": "Feature", "properties": {}, "geometry": {"type": "LineString", "coordinates": [
  [1, 15], [15, 15]]}},
{"type": "Feature", "properties": {}, "geometry": {"type": "MultiPoint", "coordinates": [
  [12.5, 12.5], [13, 9], [0, 0], [16, 16]]}}
]})";
  return p.string();
}

class LayerCells : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("loci-cells-" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static inline fs::path dir_;
};

const std::string kSample = std::string(LOCI_DATASETS_DIR) + "/samples/coastline-denmark.geojson";

}  // namespace

TEST_F(LayerCells, GridLayerMatchesOgrOnEdgesAndCorners) {
  expect_matches_ogr(grid_layer(dir_), 4);
  expect_matches_ogr(grid_layer(dir_), 6);
}

TEST_F(LayerCells, NaturalEarthSampleMatchesOgr) {
  expect_matches_ogr(kSample, 5);
}

TEST_F(LayerCells, PerFeatureIndexAndBadLevelsAreRefused) {
  const std::string path = grid_layer(dir_);
  const auto per_feature = io::LayerIndex::build(io::read_items(path, "", io::Per::feature),
                                                 io::Structure::packed_hilbert);
  EXPECT_THROW(io::layer_cells(per_feature, 4), InvalidArgument);
  const auto per_segment = io::LayerIndex::build(io::read_items(path, "", io::Per::segment),
                                                 io::Structure::packed_hilbert);
  EXPECT_THROW(io::layer_cells(per_segment, 31), InvalidArgument);
}

TEST_F(LayerCells, DrawCellsWritesEveryLeafOnce) {
  const std::string path = grid_layer(dir_);
  const std::string out = (dir_ / "cells.svg").string();
  const CliRun r = run_loci("draw " + path + " --cells 4 -o " + out);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto index = io::LayerIndex::build(io::read_items(path, "", io::Per::segment),
                                           io::Structure::packed_hilbert);
  const RegionQuadtree cells = io::layer_cells(index, 4);
  const std::size_t leaves =
      cells.count(Cover::outside) + cells.count(Cover::inside) + cells.count(Cover::boundary);
  const std::string svg = read_text(out);
  std::size_t rects = 0;
  for (auto at = svg.find("<rect x="); at != std::string::npos; at = svg.find("<rect x=", at + 1))
    ++rects;
  EXPECT_EQ(rects, leaves);
  EXPECT_NE(r.err.find(std::to_string(leaves) + " cells drawn"), std::string::npos) << r.err;

  for (const char* bad : {"x", "-1", "31", ""}) {
    const std::string bad_out = (dir_ / "bad.svg").string();
    const CliRun e = run_loci("draw " + path + " --cells '" + bad + "' -o " + bad_out);
    EXPECT_EQ(e.status, 1) << bad;
    EXPECT_EQ(lines(e.err).size(), 1u) << e.err;
    EXPECT_NE(e.err.find("loci: error: --cells"), std::string::npos) << e.err;
    EXPECT_FALSE(fs::exists(bad_out));
  }
  // --levels is the index's: refused beside --cells (it was ignored).
  const std::string both_out = (dir_ / "both.svg").string();
  const CliRun both = run_loci("draw " + path + " --cells 2 --levels 3 -o " + both_out);
  EXPECT_EQ(both.status, 1);
  EXPECT_NE(both.err.find("--levels (index nodes) or --cells (quadtree cells), not both"),
            std::string::npos)
      << both.err;
  EXPECT_FALSE(fs::exists(both_out));
}
