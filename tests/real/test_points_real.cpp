// Real layers (labelled "large;real"): Natural Earth coastlines through GDAL. The windowing
// structure on the coastline segments, and the point structures on their vertices, against
// brute force. Skipped with a message when datasets/fetch.sh has not filled the cache.
#include <gtest/gtest.h>

#include <filesystem>
#include <random>

#include "loci/index/kd_tree.hpp"
#include "loci/index/pr_quadtree.hpp"
#include "loci/index/segment_window_tree.hpp"
#include "loci/io/layer_reader.hpp"
#include "support/brute_force.hpp"
#include "support/point_data.hpp"

using namespace loci;
using namespace loci::test;

namespace {

const std::string kCoastline =
    std::string(LOCI_DATASETS_DIR) + "/cache/countries-coastline-1m/map.geo.json";

// The first segments in reading order: whole coastlines, so shared vertices and touching
// segments are kept as the layer has them.
const std::vector<Segment2>& coastline() {
  static const std::vector<Segment2> segs = [] {
    std::vector<Segment2> out;
    for (const auto& r : io::read_segments(kCoastline)) {
      out.push_back(r.segment);
      if (out.size() == 150000) break;
    }
    return out;
  }();
  return segs;
}

class RealPoints : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!std::filesystem::exists(kCoastline))
      GTEST_SKIP() << "no " << kCoastline << ": run datasets/fetch.sh to fetch the real layers";
  }
};

TEST_F(RealPoints, CoastlineWindowing) {
  const auto& segs = coastline();
  const auto tree = SegmentWindowTree::build(segs);
  tree.validate();
  std::mt19937_64 rng(41);
  std::size_t hits = 0, crossing_only = 0;
  for (int q = 0; q < 150; ++q) {
    const Segment2& around = segs[rng() % segs.size()];
    // large windows around a vertex, and tiny ones around a segment's middle, which the
    // segment crosses with both endpoints outside
    const bool tiny = q % 2;
    const double r = tiny ? double(rng() % 100 + 1) * 1e-5 : double(rng() % 100) / 50.0;
    const Point2 c =
        tiny ? Point2{0.5 * (around.a[0] + around.b[0]), 0.5 * (around.a[1] + around.b[1])}
             : around.a;
    const Box2 w{{c[0] - r, c[1] - r}, {c[0] + r, c[1] + r}};
    std::vector<Id> expected;
    for (std::size_t i = 0; i < segs.size(); ++i)
      if (intersects(w, segs[i])) {
        expected.push_back(i);
        crossing_only += !intersects(w, segs[i].a) && !intersects(w, segs[i].b);
      }
    const auto got = tree.query(w);
    ASSERT_EQ(got.size(), expected.size()) << to_string(w);
    ASSERT_EQ(sorted(got), expected) << to_string(w);
    hits += expected.size();
  }
  EXPECT_GT(hits, 1000u);
  EXPECT_GT(crossing_only, 10u);  // the case an endpoint index alone would miss
}

TEST_F(RealPoints, CoastlineVertices) {
  std::vector<Point2> pts;
  for (const auto& s : coastline())
    pts.push_back(s.a);
  const auto boxes = point_boxes(pts);
  std::vector<Id> ids(pts.size());
  for (std::size_t i = 0; i < ids.size(); ++i)
    ids[i] = i;
  const auto kd = KdTree2::build(pts);
  const auto qt = PrQuadtree2::build(pts, 8);
  kd.validate();
  qt.validate();
  std::mt19937_64 rng(42);
  for (int q = 0; q < 60; ++q) {
    const Point2& c = pts[rng() % pts.size()];
    const double r = double(rng() % 100) / 50.0;
    const Box2 w{{c[0] - r, c[1] - r}, {c[0] + r, c[1] + r}};
    const auto expected = brute_window(boxes, ids, w, Relation::intersects);
    ASSERT_EQ(sorted(kd.query(w)), expected);
    ASSERT_EQ(sorted(qt.query(w)), expected);
    const Point2 p{double(rng() % 360) - 180, double(rng() % 180) - 90};
    expect_nearest(kd.nearest(p, 10), boxes, p, 10);
    expect_nearest(qt.nearest(p, 10), boxes, p, 10);
  }
}

}  // namespace
