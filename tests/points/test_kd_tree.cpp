// KdTree against brute force: window, radius and nearest-n in 2D and 3D, median and
// sliding-midpoint builds, on uniform, clustered and degenerate points; insertion and erasure
// with partial rebuilds; early stop; bad input.
#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "loci/index/kd_tree.hpp"
#include "support/brute_force.hpp"
#include "support/churn.hpp"
#include "support/point_data.hpp"

using namespace loci;
using namespace loci::test;

namespace {

template <class Tree, int D>
void check_queries(const Tree& tree, const std::vector<Point<D>>& pts, std::uint64_t seed,
                   int queries = 60) {
  const auto boxes = point_boxes(pts);
  std::vector<Id> ids(pts.size());
  for (std::size_t i = 0; i < ids.size(); ++i)
    ids[i] = i;
  std::mt19937_64 rng(seed);
  std::size_t hits = 0;
  for (int q = 0; q < queries; ++q) {
    const Box<D> w = window_near(rng, pts);
    const auto expected = brute_window(boxes, ids, w, Relation::intersects);
    ASSERT_EQ(sorted(tree.query(w)), expected) << to_string(w);
    hits += expected.size();

    const Point<D> p = rng() % 2 ? pts[rng() % pts.size()] : random_point<D>(rng, -50, 1050);
    const double r = double(rng() % 40);
    std::vector<Id> got;
    for (const auto& nb : tree.radius(p, r)) {
      got.push_back(nb.id);
      ASSERT_DOUBLE_EQ(nb.distance, std::sqrt(squared_distance(p, pts[nb.id])));
    }
    ASSERT_EQ(sorted(got), brute_radius(pts, p, r));

    const std::size_t k = 1 + rng() % 20;
    expect_nearest(tree.nearest(p, k), boxes, p, k);
  }
  if (pts.size() > 100) EXPECT_GT(hits, 0u);
}

struct Case {
  PointShape shape;
  KdSplit split;
};

class KdStatic : public ::testing::TestWithParam<Case> {};

TEST_P(KdStatic, MatchesBruteForce2D) {
  const auto pts = make_points<2>(GetParam().shape, 4000, 3);
  const auto tree = KdTree2::build(pts, GetParam().split);
  tree.validate();
  ASSERT_EQ(tree.size(), pts.size());
  EXPECT_LE(tree.height(), 40);
  check_queries<KdTree2, 2>(tree, pts, 9);
}

TEST_P(KdStatic, MatchesBruteForce3D) {
  const auto pts = make_points<3>(GetParam().shape, 3000, 4);
  const auto tree = KdTree3::build(pts, GetParam().split);
  tree.validate();
  check_queries<KdTree3, 3>(tree, pts, 10);
}

std::vector<Case> all_cases() {
  std::vector<Case> out;
  for (auto s : kAllPointShapes)
    for (auto split : {KdSplit::median, KdSplit::sliding_midpoint})
      out.push_back({s, split});
  return out;
}

INSTANTIATE_TEST_SUITE_P(Points, KdStatic, ::testing::ValuesIn(all_cases()), [](const auto& info) {
  return name(info.param.shape) +
         (info.param.split == KdSplit::median ? "_median" : "_sliding_midpoint");
});

// Inserts and erases in random order, checking the tree against the live set as it goes.
template <int D>
void churn(PointShape shape, KdSplit split, std::uint64_t seed) {
  const auto pool = make_points<D>(shape, 3000, seed);
  std::mt19937_64 rng(seed + 1);
  KdTree<D, 8> tree(split);
  std::vector<bool> live(pool.size(), false);
  std::size_t count = 0;
  for (int step = 0; step < 6000; ++step) {
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
      // compare against the live points, ids kept as pool positions
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
  // a tree built by insertion stays shallow
  EXPECT_LE(tree.height(), 40);
  for (std::size_t j = 0; j < pool.size(); ++j)
    if (live[j]) ASSERT_TRUE(tree.erase(pool[j], j));
  EXPECT_TRUE(tree.empty());
  tree.validate();
}

TEST(KdDynamic, ChurnUniform2D) {
  churn<2>(PointShape::uniform, KdSplit::median, 1);
}
TEST(KdDynamic, ChurnClustered2D) {
  churn<2>(PointShape::clustered, KdSplit::sliding_midpoint, 2);
}
TEST(KdDynamic, ChurnDuplicates2D) {
  churn<2>(PointShape::duplicates, KdSplit::median, 3);
}
TEST(KdDynamic, ChurnIdentical2D) {
  churn<2>(PointShape::identical, KdSplit::median, 4);
}
TEST(KdDynamic, ChurnHorizontal3D) {
  churn<3>(PointShape::horizontal, KdSplit::sliding_midpoint, 5);
}
TEST(KdDynamic, ChurnUniform3D) {
  churn<3>(PointShape::uniform, KdSplit::median, 6);
}

TEST(KdDynamic, SortedInsertionStaysBalanced) {
  KdTree2 tree;
  for (int i = 0; i < 20000; ++i)
    tree.insert({double(i), 0.0}, Id(i));
  tree.validate();
  EXPECT_LE(tree.height(), 40);
  EXPECT_EQ(tree.query(Box2{{100, 0}, {199, 0}}).size(), 100u);
}

TEST(KdTree, VisitorStopsEarly) {
  const auto pts = make_points<2>(PointShape::uniform, 1000, 1);
  const auto tree = KdTree2::build(pts);
  int calls = 0;
  const auto s =
      tree.query(Box2{{0, 0}, {1000, 1000}}, [&](Id, const Box2&) { return ++calls < 7; });
  EXPECT_EQ(calls, 7);
  EXPECT_EQ(s.results, 7u);
  calls = 0;
  tree.nearest(Point2{500, 500}, 50, [&](Id, const Box2&, double) { return ++calls < 3; });
  EXPECT_EQ(calls, 3);
  calls = 0;
  tree.radius(Point2{500, 500}, 300, [&](Id, const Box2&, double) { return ++calls < 4; });
  EXPECT_EQ(calls, 4);
}

TEST(KdTree, RejectsBadInput) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<Point2> bad = {{0, 0}, {nan, 1}};
  EXPECT_THROW(KdTree2::build(bad), InvalidGeometry);
  KdTree2 tree = KdTree2::build(std::vector<Point2>{{0, 0}, {1, 1}});
  EXPECT_THROW(tree.insert({inf, 0}, 3), InvalidGeometry);
  EXPECT_THROW(tree.nearest({0, 0}, 0), InvalidArgument);
  EXPECT_THROW(tree.nearest({nan, 0}, 1), InvalidGeometry);
  EXPECT_THROW(tree.radius({0, 0}, -1), InvalidArgument);
  EXPECT_THROW(tree.radius({0, 0}, nan), InvalidArgument);
  EXPECT_THROW(tree.query(Box2{{1, 1}, {0, 0}}), InvalidGeometry);
  EXPECT_TRUE(KdTree2().query(Box2{{0, 0}, {1, 1}}).empty());
  EXPECT_TRUE(KdTree2().nearest({0, 0}, 3).empty());
  const std::vector<Id> ids = {7};
  EXPECT_THROW(KdTree2::build(bad, ids), InvalidArgument);
}

TEST(KdTree, CustomIds) {
  const std::vector<Point2> pts = {{0, 0}, {5, 5}, {9, 9}};
  const std::vector<Id> ids = {70, 50, 90};
  const auto tree = KdTree2::build(pts, ids);
  EXPECT_EQ(tree.nearest({6, 6}, 1).front().id, 50u);
  EXPECT_EQ(sorted(tree.query(Box2{{0, 0}, {5, 5}})), (std::vector<Id>{50, 70}));
}

// The shared churn harness (tests/support/churn.hpp) on points.

TEST(KdDynamic, SharedChurnHarness) {
  PointChurn<KdTree2> ops{KdTree2()};
  churn_against_brute_force(ops, 73, 4000);
}

}  // namespace
