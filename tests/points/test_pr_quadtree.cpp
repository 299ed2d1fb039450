// PrQuadtree (PR, bucket PR, octree) against brute force: window and nearest-n on uniform,
// clustered and degenerate points (duplicates, lines, points closer than the precision limit),
// insert/erase with merging, growth of the region, early stop, bad input.
#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <string>
#include <vector>

#include "loci/index/pr_quadtree.hpp"
#include "support/brute_force.hpp"
#include "support/churn.hpp"
#include "support/point_data.hpp"

using namespace loci;
using namespace loci::test;

namespace {

template <int D>
void check_queries(const PrQuadtree<D>& tree, const std::vector<Point<D>>& pts,
                   std::uint64_t seed) {
  const auto boxes = point_boxes(pts);
  std::vector<Id> ids(pts.size());
  for (std::size_t i = 0; i < ids.size(); ++i)
    ids[i] = i;
  std::mt19937_64 rng(seed);
  std::size_t hits = 0;
  for (int q = 0; q < 60; ++q) {
    const Box<D> w = window_near(rng, pts);
    const auto expected = brute_window(boxes, ids, w, Relation::intersects);
    ASSERT_EQ(sorted(tree.query(w)), expected) << to_string(w);
    hits += expected.size();
    const Point<D> p = rng() % 2 ? pts[rng() % pts.size()] : random_point<D>(rng, -50, 1050);
    const std::size_t k = 1 + rng() % 20;
    expect_nearest(tree.nearest(p, k), boxes, p, k);
  }
  EXPECT_GT(hits, 0u);
}

struct Case {
  PointShape shape;
  std::uint32_t bucket;
};

class QuadStatic : public ::testing::TestWithParam<Case> {};

TEST_P(QuadStatic, MatchesBruteForce2D) {
  const auto pts = make_points<2>(GetParam().shape, 3000, 13);
  const auto tree = PrQuadtree2::build(pts, GetParam().bucket);
  tree.validate();
  ASSERT_EQ(tree.size(), pts.size());
  EXPECT_LE(tree.height(), tree.max_depth() + 1);
  check_queries(tree, pts, 7);
}

TEST_P(QuadStatic, MatchesBruteForceOctree) {
  const auto pts = make_points<3>(GetParam().shape, 2000, 14);
  const auto tree = Octree::build(pts, GetParam().bucket);
  tree.validate();
  check_queries(tree, pts, 8);
}

std::vector<Case> all_cases() {
  std::vector<Case> out;
  for (auto s : kAllPointShapes)
    for (std::uint32_t b : {1u, 8u})
      out.push_back({s, b});
  return out;
}

INSTANTIATE_TEST_SUITE_P(Points, QuadStatic, ::testing::ValuesIn(all_cases()),
                         [](const auto& info) {
                           return name(info.param.shape) + "_bucket" +
                                  std::to_string(info.param.bucket);
                         });

template <int D>
void churn(PointShape shape, std::uint32_t bucket, std::uint64_t seed) {
  const auto pool = make_points<D>(shape, 2000, seed);
  std::mt19937_64 rng(seed + 1);
  PrQuadtree<D> tree(bucket);  // region found from the data and grown
  std::vector<bool> live(pool.size(), false);
  std::size_t count = 0;
  for (int step = 0; step < 5000; ++step) {
    const std::size_t i = rng() % pool.size();
    if (!live[i]) {
      tree.insert(pool[i], i);
      live[i] = true;
      ++count;
    } else if (rng() % 2) {
      ASSERT_TRUE(tree.erase(pool[i], i));
      ASSERT_FALSE(tree.erase(pool[i], i));
      live[i] = false;
      --count;
    }
    ASSERT_EQ(tree.size(), count);
    if (step % 500 == 499) {
      ASSERT_NO_THROW(tree.validate()) << "step " << step;
      std::vector<Box<D>> boxes;
      std::vector<Id> ids;
      for (std::size_t j = 0; j < pool.size(); ++j)
        if (live[j]) {
          boxes.push_back(Box<D>::of_point(pool[j]));
          ids.push_back(j);
        }
      for (int q = 0; q < 10; ++q) {
        const Box<D> w = window_near(rng, pool);
        ASSERT_EQ(sorted(tree.query(w)), brute_window(boxes, ids, w, Relation::intersects));
        const Point<D> p = random_point<D>(rng);
        const auto got = tree.nearest(p, 5);
        const auto ref = brute_distances(boxes, p);
        ASSERT_EQ(got.size(), std::min<std::size_t>(5, boxes.size()));
        for (std::size_t r = 0; r < got.size(); ++r) {
          EXPECT_DOUBLE_EQ(got[r].distance, ref[r]);
          EXPECT_TRUE(live[got[r].id]);
        }
      }
    }
  }
  for (std::size_t j = 0; j < pool.size(); ++j)
    if (live[j]) ASSERT_TRUE(tree.erase(pool[j], j));
  EXPECT_TRUE(tree.empty());
  tree.validate();
  // everything merged back into the root
  EXPECT_EQ(tree.height(), 1);
}

TEST(QuadDynamic, ChurnUniformPr) {
  churn<2>(PointShape::uniform, 1, 1);
}
TEST(QuadDynamic, ChurnClusteredBucket) {
  churn<2>(PointShape::clustered, 4, 2);
}
TEST(QuadDynamic, ChurnDuplicatesPr) {
  churn<2>(PointShape::duplicates, 1, 3);
}
TEST(QuadDynamic, ChurnTinyGapsPr) {
  churn<2>(PointShape::tiny_gaps, 1, 4);
}
TEST(QuadDynamic, ChurnHorizontalOctree) {
  churn<3>(PointShape::horizontal, 2, 5);
}
TEST(QuadDynamic, ChurnIdenticalOctree) {
  churn<3>(PointShape::identical, 1, 6);
}

// Points on the axis y = 0, or all at the origin: build() widens the region by one ulp of
// zero (4.9e-324), an extent whose Hilbert scale would overflow.
TEST(PrQuadtree, BuildOnAnAxisOrAtTheOrigin) {
  std::mt19937_64 rng(15);
  std::uniform_real_distribution<double> u(0, 1000);
  std::vector<Point2> axis, origin(50, Point2{0, 0});
  for (int i = 0; i < 500; ++i)
    axis.push_back({u(rng), 0});
  for (const auto& pts : {axis, origin})
    for (std::uint32_t bucket : {1u, 8u}) {
      const auto tree = PrQuadtree2::build(pts, bucket);
      tree.validate();
      ASSERT_EQ(tree.size(), pts.size());
      check_queries(tree, pts, 16);
    }
}

TEST(PrQuadtree, CoincidentPointsShareOneLeaf) {
  PrQuadtree2 tree(Box2{{0, 0}, {1, 1}});
  for (int i = 0; i < 1000; ++i)
    tree.insert({0.25, 0.25}, Id(i));
  tree.validate();
  EXPECT_EQ(tree.height(), 1);  // no split at all: the points cannot be separated
  tree.insert({0.75, 0.75}, 1000);
  tree.validate();
  EXPECT_EQ(tree.height(), 2);
  EXPECT_EQ(tree.query(Box2{{0, 0}, {0.5, 0.5}}).size(), 1000u);
}

TEST(PrQuadtree, DepthIsCapped) {
  PrQuadtree2 tree(Box2{{0, 0}, {1, 1}}, 1, 10);
  tree.insert({0.5, 0.5}, 0);
  tree.insert({std::nextafter(0.5, 1.0), 0.5}, 1);
  tree.validate();
  EXPECT_LE(tree.height(), 11);
  EXPECT_EQ(tree.nearest({0.5, 0.5}, 2).size(), 2u);
}

TEST(PrQuadtree, RegionGrowsInEveryDirection) {
  PrQuadtree2 tree(Box2{{0, 0}, {1, 1}}, 1);
  std::vector<Point2> pts;
  std::mt19937_64 rng(3);
  for (int i = 0; i < 300; ++i) {
    const Point2 p = random_point<2>(rng, -1e6, 1e6);
    pts.push_back(p);
    tree.insert(p, Id(i));
  }
  tree.validate();
  // the region grew from the first point until it held every later one
  Box2 extent = Box2::empty();
  for (const auto& p : pts)
    extent.expand(p);
  EXPECT_TRUE(contains(tree.region(), extent));
  EXPECT_EQ(tree.size(), pts.size());
  const auto all = tree.query(Box2{{-1e7, -1e7}, {1e7, 1e7}});
  EXPECT_EQ(all.size(), pts.size());
  expect_nearest(tree.nearest({0, 0}, 7), point_boxes(pts), Point2{0, 0}, 7);
}

TEST(PrQuadtree, CellsCoverTheRegion) {
  const auto pts = make_points<2>(PointShape::clustered, 500, 2);
  const auto tree = PrQuadtree2::build(pts, 4);
  double leaf_area = 0;
  std::size_t leaf_points = 0;
  tree.visit_cells([&](const Box2& r, int, std::size_t count, bool leaf) {
    if (!leaf) return;
    leaf_area += r.content();
    leaf_points += count;
  });
  EXPECT_NEAR(leaf_area, tree.region().content(), 1e-6 * tree.region().content());
  EXPECT_EQ(leaf_points, pts.size());
}

TEST(PrQuadtree, VisitorStopsEarly) {
  const auto pts = make_points<2>(PointShape::uniform, 1000, 1);
  const auto tree = PrQuadtree2::build(pts, 1);
  int calls = 0;
  tree.query(Box2{{0, 0}, {1000, 1000}}, [&](Id, const Box2&) { return ++calls < 5; });
  EXPECT_EQ(calls, 5);
  calls = 0;
  tree.nearest(Point2{1, 1}, 30, [&](Id, const Box2&, double) { return ++calls < 2; });
  EXPECT_EQ(calls, 2);
}

TEST(PrQuadtree, RejectsBadInput) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_THROW(PrQuadtree2(0), InvalidArgument);
  EXPECT_THROW(PrQuadtree2(Box2{{1, 1}, {0, 0}}), InvalidGeometry);
  PrQuadtree2 tree;
  EXPECT_THROW(tree.insert({nan, 0}, 0), InvalidGeometry);
  EXPECT_THROW(tree.insert({0, inf}, 0), InvalidGeometry);
  tree.insert({1, 1}, 0);
  EXPECT_THROW(tree.nearest({0, 0}, 0), InvalidArgument);
  EXPECT_THROW(tree.query(Box2{{0, nan}, {1, 1}}), InvalidGeometry);
  EXPECT_FALSE(tree.erase({5, 5}, 0));
  EXPECT_FALSE(tree.erase({1, 1}, 9));
  EXPECT_TRUE(tree.erase({1, 1}, 0));
  EXPECT_TRUE(tree.nearest({0, 0}, 3).empty());
}

// A point the region cannot grow to without overflowing is refused before anything changes:
// the tree keeps its height and region (it used to double about a thousand times first), and
// a refused first point leaves the tree empty (it used to stay rooted at that point, refusing
// everything after).
TEST(PrQuadtree, ARefusedFarPointChangesNothing) {
  const double big = std::numeric_limits<double>::max();
  const auto pts = make_points<2>(PointShape::uniform, 200, 4);
  PrQuadtree2 tree;
  for (std::size_t i = 0; i < pts.size(); ++i)
    tree.insert(pts[i], Id(i));
  const int height = tree.height();
  const Box2 region = tree.region();
  EXPECT_THROW(tree.insert({big, 0}, 999), InvalidGeometry);
  EXPECT_THROW(tree.insert({0, -big}, 999), InvalidGeometry);
  EXPECT_EQ(tree.height(), height);
  EXPECT_TRUE(tree.region() == region);
  EXPECT_EQ(tree.size(), pts.size());
  tree.validate();
  tree.insert({1e308, 0}, 999);  // far, but within reach: the region grows to it
  tree.validate();
  EXPECT_EQ(tree.query(Box2{{9e307, -1}, {1.1e308, 1}}), (std::vector<Id>{999}));

  PrQuadtree2 empty;
  EXPECT_THROW(empty.insert({big, 0}, 1), InvalidGeometry);
  EXPECT_TRUE(empty.empty());
  empty.validate();
  empty.insert({1, 1}, 1);
  empty.insert({2, 3}, 2);
  empty.validate();
  EXPECT_EQ(sorted(empty.query(Box2{{0, 0}, {5, 5}})), (std::vector<Id>{1, 2}));

  // build() names the point as insert() does (it spoke of an infinite region never given).
  const std::vector<Point2> with_big{{0, 0}, {1, 2}, {3, big}};
  try {
    PrQuadtree2::build(with_big);
    ADD_FAILURE() << "a point at the largest double was taken";
  } catch (const InvalidGeometry& e) {
    EXPECT_EQ(std::string(e.what()).rfind("point 2 too far from the quadtree's region: (3", 0), 0u)
        << e.what();
  }
  // Far apart, both within reach: taken, and answered.
  const std::vector<Point2> apart{{-1.7e308, 0}, {1.7e308, 0}, {0, 0}};
  const PrQuadtree2 wide = PrQuadtree2::build(apart);
  wide.validate();
  EXPECT_EQ(sorted(wide.query(Box2{{1e308, -1}, {big, 1}})), (std::vector<Id>{1}));
  EXPECT_EQ(sorted(wide.query(Box2{{-big, -1}, {big, 1}})), (std::vector<Id>{0, 1, 2}));
}

// The shared churn harness (tests/support/churn.hpp) on points.

TEST(PrQuadtreeDynamic, SharedChurnHarness) {
  PointChurn<PrQuadtree2> ops{PrQuadtree2(4)};
  churn_against_brute_force(ops, 79, 4000);
}

}  // namespace
