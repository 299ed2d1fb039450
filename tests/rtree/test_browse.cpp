// Distance browsing (browse) on every tree that answers nearest-n, against brute force: entries
// come in increasing distance, every entry exactly once when the walk runs to the end, ties in
// any order, an early stop stops, an empty tree reports nothing; on uniform, clustered,
// duplicated, zero-area and collinear data.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "loci/index/kd_tree.hpp"
#include "loci/index/packed_rtree.hpp"
#include "loci/index/pr_quadtree.hpp"
#include "loci/index/rstar_tree.hpp"
#include "loci/index/rtree.hpp"
#include "support/random_data.hpp"

namespace loci::test {
namespace {

// Browses all of `tree` from p and checks order, distances and completeness against `boxes`
// (entry i has id i); then stops after `stop` answers and checks that exactly those came.
template <class Tree>
void expect_browse_exact(const Tree& tree, const std::vector<Box<2>>& boxes, const Point<2>& p,
                         std::size_t stop) {
  std::vector<Id> seen;
  double last = 0;
  bool ordered = true, distances = true;
  tree.browse(p, [&](Id id, const Box<2>& box, double d) {
    ordered &= d >= last;
    last = d;
    distances &=
        id < boxes.size() && box == boxes[id] && d == std::sqrt(squared_distance(p, boxes[id]));
    seen.push_back(id);
    return true;
  });
  EXPECT_TRUE(ordered) << "not in increasing distance";
  EXPECT_TRUE(distances) << "a reported distance or box is not the entry's";
  std::vector<Id> all(boxes.size());
  for (std::size_t i = 0; i < all.size(); ++i)
    all[i] = Id(i);
  std::vector<Id> sorted_seen = seen;
  std::sort(sorted_seen.begin(), sorted_seen.end());
  EXPECT_EQ(sorted_seen, all) << "not every entry exactly once";

  std::size_t calls = 0;
  const QueryStats s = tree.browse(p, [&](Id, const Box<2>&, double) { return ++calls < stop; });
  EXPECT_EQ(calls, std::min(stop, boxes.size()));
  EXPECT_EQ(s.results, calls);
  // the first answers of a stopped walk are the nearest ones
  std::vector<double> ref;
  for (const auto& b : boxes)
    ref.push_back(std::sqrt(squared_distance(p, b)));
  std::sort(ref.begin(), ref.end());
  std::vector<double> got;
  tree.browse(p, [&](Id, const Box<2>&, double d) { return got.push_back(d), got.size() < stop; });
  for (std::size_t i = 0; i < got.size(); ++i)
    EXPECT_EQ(got[i], ref[i]) << "rank " << i;
}

std::vector<Box<2>> points_of(const std::vector<Box<2>>& boxes) {
  std::vector<Box<2>> out;
  for (const auto& b : boxes)
    out.push_back(Box<2>::of_point(b.min));
  return out;
}

std::vector<Point<2>> corners(const std::vector<Box<2>>& boxes) {
  std::vector<Point<2>> out;
  for (const auto& b : boxes)
    out.push_back(b.min);
  return out;
}

class Browse : public ::testing::TestWithParam<Shape> {};

TEST_P(Browse, BoxTreesAgainstBruteForce) {
  const auto boxes = make_boxes<2>(GetParam(), 3000, 41);
  std::vector<std::pair<Box<2>, Id>> entries;
  for (std::size_t i = 0; i < boxes.size(); ++i)
    entries.push_back({boxes[i], Id(i)});
  const auto hilbert = PackedRTree2::build(boxes);
  const auto str = PackedRTree2::build(boxes, Packing::str);
  RStarTree2 rstar;
  RTree<2, LinearSplit> linear;
  for (const auto& [b, id] : entries) {
    rstar.insert(b, id);
    linear.insert(b, id);
  }
  const auto bulk = RStarTree2::bulk_load(entries);
  std::mt19937_64 rng(5);
  for (int q = 0; q < 12; ++q) {
    const Point<2> p = random_point<2>(rng, -50, 1050);
    const std::size_t stop = 1 + rng() % 40;
    expect_browse_exact(hilbert, boxes, p, stop);
    expect_browse_exact(str, boxes, p, stop);
    expect_browse_exact(rstar, boxes, p, stop);
    expect_browse_exact(linear, boxes, p, stop);
    expect_browse_exact(bulk, boxes, p, stop);
  }
}

// browse() with keep(): items are grouped (consecutive ids, like the segments of a feature)
// and a third of the groups are banned; keep drops every run of banned items. The walk must
// then give exactly the other items, nearest first, and keep must be shown lower bounds.
TEST_P(Browse, PackedKeepDropsRuns) {
  const auto boxes = make_boxes<2>(GetParam(), 4000, 43);
  const auto tree = PackedRTree2::build(boxes);
  auto banned = [](Id id) { return (id / 7) % 3 == 0; };
  std::mt19937_64 rng(6);
  for (int q = 0; q < 12; ++q) {
    const Point<2> p = random_point<2>(rng, -50, 1050);
    std::size_t asked = 0, dropped = 0;
    bool bounds_ok = true;
    std::vector<Id> seen;
    double last = 0;
    bool ordered = true;
    tree.browse(
        p,
        [&](Id id, const Box<2>&, double d) {
          ordered &= d >= last;
          last = d;
          seen.push_back(id);
          return true;
        },
        [&](std::size_t first, std::size_t last_pos, double d) {
          ++asked;
          bool all_banned = true;
          for (std::size_t pos = first; pos < last_pos; ++pos) {
            const Id id = tree.item_at(pos);
            all_banned &= banned(id);
            bounds_ok &= d <= std::sqrt(squared_distance(p, boxes[id]));
          }
          dropped += all_banned;
          return !all_banned;
        });
    EXPECT_TRUE(ordered);
    EXPECT_TRUE(bounds_ok) << "keep was given more than the distance of an item it covers";
    EXPECT_GT(dropped, 0u);
    std::vector<Id> want;
    for (Id id = 0; id < boxes.size(); ++id)
      if (!banned(id)) want.push_back(id);
    std::sort(seen.begin(), seen.end());
    EXPECT_EQ(seen, want);
    EXPECT_LT(asked, 2 * boxes.size());
  }
}

TEST_P(Browse, PointTreesAgainstBruteForce) {
  const auto boxes = points_of(make_boxes<2>(GetParam(), 3000, 43));
  const auto pts = corners(boxes);
  const auto kd = KdTree2::build(pts);
  const auto mid = KdTree2::build(pts, KdSplit::sliding_midpoint);
  const auto quad = PrQuadtree2::build(pts, 4);
  std::mt19937_64 rng(7);
  for (int q = 0; q < 12; ++q) {
    const Point<2> p = q == 0 ? pts[0] : random_point<2>(rng, -50, 1050);  // q 0: on a point
    const std::size_t stop = 1 + rng() % 40;
    expect_browse_exact(kd, boxes, p, stop);
    expect_browse_exact(mid, boxes, p, stop);
    expect_browse_exact(quad, boxes, p, stop);
  }
}

INSTANTIATE_TEST_SUITE_P(Shapes, Browse, ::testing::ValuesIn(kAllShapes),
                         [](const auto& info) { return name(info.param); });

TEST(BrowseEdges, EmptyTreesReportNothingAndBadPointsThrow) {
  const PackedRTree2 packed;
  const RStarTree2 rstar;
  const KdTree2 kd;
  const PrQuadtree2 quad;
  std::size_t calls = 0;
  auto count = [&](Id, const Box<2>&, double) { return ++calls, true; };
  packed.browse({0, 0}, count);
  rstar.browse({0, 0}, count);
  kd.browse({0, 0}, count);
  quad.browse({0, 0}, count);
  EXPECT_EQ(calls, 0u);
  const Point<2> nan{std::nan(""), 0};
  EXPECT_THROW(packed.browse(nan, count), InvalidGeometry);
  EXPECT_THROW(rstar.browse(nan, count), InvalidGeometry);
  EXPECT_THROW(kd.browse(nan, count), InvalidGeometry);
  EXPECT_THROW(quad.browse(nan, count), InvalidGeometry);
}

// Beyond 1e150 squared distances overflow: a nearest-n answer whose distance would be infinite
// is refused (it used to come back at distance inf, in no order: the farther of two points far
// away could be named the nearest), while answers whose distances fit are unaffected.
template <class Tree>
void expect_overflow_refused(const Tree& tree) {
  EXPECT_THROW(tree.nearest({0, 0}, 4), InvalidArgument);
  const auto near = tree.nearest({0, 0}, 2);
  ASSERT_EQ(near.size(), 2u);
  EXPECT_EQ(near[0].id, 0u);
  EXPECT_EQ(near[1].id, 1u);
  // Browsing hands the overflowed ones on last, at infinity, for the visitor to judge.
  std::vector<double> seen;
  tree.browse({0, 0}, [&](Id, const Box<2>&, double d) { return seen.push_back(d), true; });
  ASSERT_EQ(seen.size(), 4u);
  EXPECT_EQ(seen[0], std::sqrt(2.0));
  EXPECT_EQ(seen[1], 3.0);
  EXPECT_TRUE(std::isinf(seen[2]) && std::isinf(seen[3]));
}

TEST(BrowseEdges, DistancesThatOverflowAreRefused) {
  const std::vector<Point<2>> pts = {{1, 1}, {3, 0}, {2e200, 0}, {1e200, 0}};
  std::vector<Box<2>> boxes;
  for (const auto& p : pts)
    boxes.push_back({p, p});
  RStarTree2 rstar;
  RTree2 rtree;
  KdTree2 kd;
  PrQuadtree2 quad;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    rstar.insert(boxes[i], Id(i));
    rtree.insert(boxes[i], Id(i));
    kd.insert(pts[i], Id(i));
    quad.insert(pts[i], Id(i));
  }
  expect_overflow_refused(rstar);
  expect_overflow_refused(rtree);
  expect_overflow_refused(kd);
  expect_overflow_refused(quad);
  expect_overflow_refused(PackedRTree2::build(boxes));
}

// After erasures and re-insertions the browse still sees exactly the live entries.
TEST(BrowseEdges, DynamicTreesAfterChurn) {
  auto boxes = make_boxes<2>(Shape::clustered, 2000, 47);
  RStarTree2 rstar;
  KdTree2 kd;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    rstar.insert(boxes[i], Id(i));
    kd.insert(boxes[i].min, Id(i));
  }
  std::mt19937_64 rng(9);
  for (std::size_t i = 0; i < boxes.size(); i += 3) {  // move a third of them
    ASSERT_TRUE(rstar.erase(boxes[i], Id(i)));
    ASSERT_TRUE(kd.erase(boxes[i].min, Id(i)));
    const Point<2> to = random_point<2>(rng);
    boxes[i] = {to, {to[0] + 2, to[1] + 1}};
    rstar.insert(boxes[i], Id(i));
    kd.insert(boxes[i].min, Id(i));
  }
  const auto pts = points_of(boxes);
  for (int q = 0; q < 6; ++q) {
    const Point<2> p = random_point<2>(rng);
    expect_browse_exact(rstar, boxes, p, 25);
    expect_browse_exact(kd, pts, p, 25);
  }
}

}  // namespace
}  // namespace loci::test
