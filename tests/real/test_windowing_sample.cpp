// The windowing structures on real linework: SegmentWindowTree on the bundled Natural Earth
// sample's segments, and AxisParallelWindowTree on a rectilinear layer derived from it, the
// outlines of the sample's region quadtree cells (shared edges, collinear runs and windows
// along the grid lines included). Both against the exact brute force of geom.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "loci/index/axis_parallel_window_tree.hpp"
#include "loci/index/segment_window_tree.hpp"
#include "loci/io/layer_cells.hpp"
#include "support/brute_force.hpp"
#include "support/segment_data.hpp"

using namespace loci;
using namespace loci::test;

namespace {

const std::string kSample = std::string(LOCI_DATASETS_DIR) + "/samples/coastline-denmark.geojson";

// Windows centred on the data, of sides from nothing to a fifth of the extent.
std::vector<Box2> windows(const std::vector<Segment2>& segs, const Box2& ext, std::size_t n) {
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> side(0, 0.2 * std::max(ext.extent(0), ext.extent(1)));
  std::vector<Box2> out;
  for (std::size_t q = 0; q < n; ++q) {
    const Point2 c = segs[rng() % segs.size()].a;
    const double w = side(rng), h = q % 5 == 0 ? 0.0 : side(rng);
    out.push_back({{c[0] - w / 2, c[1] - h / 2}, {c[0] + w / 2, c[1] + h / 2}});
  }
  return out;
}

}  // namespace

TEST(LayerWindowing, SegmentWindowTreeOnTheSample) {
  const auto items = io::read_items(kSample, "", io::Per::segment);
  std::vector<Segment2> segs;
  Box2 ext = Box2::empty();
  for (std::size_t i = 0; i < items.boxes.size(); ++i) {
    segs.push_back(io::segment_of(items.boxes[i], items.records[i].flags));
    ext.expand(items.boxes[i]);
  }
  ASSERT_GT(segs.size(), 1000u);
  const auto tree = SegmentWindowTree::build(segs);
  tree.validate();
  std::size_t hits = 0;
  for (const Box2& w : windows(segs, ext, 200)) {
    const auto want = brute_segments(segs, w);
    ASSERT_EQ(sorted(tree.query(w)), want) << to_string(w);
    hits += want.size();
  }
  EXPECT_GT(hits, 1000u);
}

TEST(LayerWindowing, AxisParallelWindowTreeOnTheSampleCellOutlines) {
  const auto index = io::LayerIndex::build(io::read_items(kSample, "", io::Per::segment),
                                           io::Structure::packed_hilbert);
  const RegionQuadtree cells = io::layer_cells(index, 7);
  std::vector<Segment2> segs;
  cells.visit_cells([&](const QuadCell& c) {
    if (c.cover == Cover::outside) return;
    const Box2& b = c.box;
    segs.push_back({b.min, {b.max[0], b.min[1]}});
    segs.push_back({{b.max[0], b.min[1]}, b.max});
    segs.push_back({{b.min[0], b.max[1]}, b.max});
    segs.push_back({b.min, {b.min[0], b.max[1]}});
  });
  ASSERT_GT(segs.size(), 1000u);
  const auto tree = AxisParallelWindowTree::build(segs);
  tree.validate();
  auto ws = windows(segs, cells.region(), 200);
  std::mt19937_64 rng(5);
  for (int k = 0; k < 50; ++k)  // exactly on cell edges and corners
    ws.push_back(cells.cell_box(rng() % 32, rng() % 32, 5));
  std::size_t hits = 0;
  for (const Box2& w : ws) {
    const auto want = brute_segments(segs, w);
    ASSERT_EQ(sorted(tree.query(w)), want) << to_string(w);
    hits += want.size();
  }
  EXPECT_GT(hits, 1000u);
}
