// Real layers (labelled "large;real"): the segment boxes of Natural Earth's coastlines,
// read through GDAL, in every tree, against brute force. Skipped with a message when
// datasets/fetch.sh has not filled the cache.
#include <gtest/gtest.h>

#include <filesystem>
#include <random>

#include "loci/index/packed_rtree.hpp"
#include "loci/index/rstar_tree.hpp"
#include "loci/index/rtree.hpp"
#include "loci/io/layer_reader.hpp"
#include "support/brute_force.hpp"

using namespace loci;
using namespace loci::test;

namespace {

const std::string kCoastline =
    std::string(LOCI_DATASETS_DIR) + "/cache/countries-coastline-1m/map.geo.json";

struct Coastline {
  std::vector<Box2> boxes;
  std::vector<Id> ids;
};

const Coastline& coastline() {
  static const Coastline c = [] {
    Coastline c;
    for (const auto& r : io::read_segments(kCoastline))
      c.boxes.push_back(r.segment.box());
    // a fixed sample keeps the brute-force side affordable
    std::mt19937_64 rng(2024);
    std::shuffle(c.boxes.begin(), c.boxes.end(), rng);
    c.boxes.resize(std::min<std::size_t>(c.boxes.size(), 200000));
    for (std::size_t i = 0; i < c.boxes.size(); ++i)
      c.ids.push_back(i);
    return c;
  }();
  return c;
}

class RealLayer : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!std::filesystem::exists(kCoastline))
      GTEST_SKIP() << "no " << kCoastline << ": run datasets/fetch.sh to fetch the real layers";
  }
};

template <class Tree>
void check(const Tree& tree) {
  const auto& c = coastline();
  tree.validate();
  std::mt19937_64 rng(77);
  std::size_t hits = 0;
  for (int q = 0; q < 200; ++q) {
    const Box2& around = c.boxes[rng() % c.boxes.size()];
    const double r = double(rng() % 200) / 100.0;  // up to 2 degrees
    const Box2 w{{around.min[0] - r, around.min[1] - r}, {around.max[0] + r, around.max[1] + r}};
    const auto expected = brute_window(c.boxes, c.ids, w, Relation::intersects);
    ASSERT_EQ(sorted(tree.query(w)), expected);
    hits += expected.size();
  }
  EXPECT_GT(hits, 200u);
  for (int q = 0; q < 30; ++q) {
    const Point2 p{double(rng() % 360) - 180, double(rng() % 180) - 90};
    expect_nearest(tree.nearest(p, 10), c.boxes, p, 10);
  }
}

}  // namespace

TEST_F(RealLayer, CoastlineSegmentsPackedHilbert) {
  check(PackedRTree2::build(coastline().boxes, Packing::hilbert));
}
TEST_F(RealLayer, CoastlineSegmentsPackedStr) {
  check(PackedRTree2::build(coastline().boxes, Packing::str));
}

TEST_F(RealLayer, CoastlineSegmentsInserted) {
  const auto& c = coastline();
  RStarTree2 rstar;
  RTree<2, QuadraticSplit> quadratic;
  RTree<2, LinearSplit> linear;
  for (std::size_t i = 0; i < 50000; ++i) {
    rstar.insert(c.boxes[i], i);
    quadratic.insert(c.boxes[i], i);
    linear.insert(c.boxes[i], i);
  }
  // only the first 50,000 were inserted; compare against those
  Coastline part{{c.boxes.begin(), c.boxes.begin() + 50000},
                 {c.ids.begin(), c.ids.begin() + 50000}};
  std::mt19937_64 rng(5);
  for (int q = 0; q < 100; ++q) {
    const Box2& around = part.boxes[rng() % part.boxes.size()];
    const Box2 w{{around.min[0] - 1, around.min[1] - 1}, {around.max[0] + 1, around.max[1] + 1}};
    const auto expected = brute_window(part.boxes, part.ids, w, Relation::intersects);
    ASSERT_EQ(sorted(rstar.query(w)), expected);
    ASSERT_EQ(sorted(quadratic.query(w)), expected);
    ASSERT_EQ(sorted(linear.query(w)), expected);
  }
  rstar.validate();
  quadratic.validate();
  linear.validate();
}
