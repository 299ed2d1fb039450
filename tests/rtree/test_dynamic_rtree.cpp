// RTree (linear, quadratic) and RStarTree against brute force, 2D and 3D, with interleaved
// inserts, erases and updates checked by validate() after every batch.
#include <gtest/gtest.h>

#include <limits>
#include <map>
#include <random>

#include "loci/index/rstar_tree.hpp"
#include "loci/index/rtree.hpp"
#include "support/brute_force.hpp"
#include "support/churn.hpp"
#include "support/random_data.hpp"

using namespace loci;
using namespace loci::test;

template <class T>
class DynamicRTreeTest : public ::testing::Test {};

using Trees = ::testing::Types<RTree<2, LinearSplit>, RTree<2, QuadraticSplit>, RStarTree<2>,
                               RTree<3, LinearSplit>, RTree<3, QuadraticSplit>, RStarTree<3>,
                               RTree<2, QuadraticSplit, 4>, RStarTree<2, 4>, RStarTree<2, 8>,
                               // odd capacities: the node's box arrays carry a padding slot
                               RTree<2, LinearSplit, 7>, RStarTree<2, 5>, RStarTree<3, 63>>;
TYPED_TEST_SUITE(DynamicRTreeTest, Trees);

namespace {

// The live content of a tree under test: id -> box.
template <int D>
struct Model {
  std::map<Id, Box<D>> live;
  std::vector<Box<D>> boxes() const {
    std::vector<Box<D>> v;
    for (const auto& [id, b] : live)
      v.push_back(b);
    return v;
  }
  std::vector<Id> ids() const {
    std::vector<Id> v;
    for (const auto& [id, b] : live)
      v.push_back(id);
    return v;
  }
};

template <class Tree, int D>
void check_queries(const Tree& tree, const Model<D>& model, std::mt19937_64& rng,
                   int windows = 40) {
  ASSERT_NO_THROW(tree.validate());
  ASSERT_EQ(tree.size(), model.live.size());
  const auto boxes = model.boxes();
  const auto ids = model.ids();
  for (int q = 0; q < windows; ++q) {
    Box<D> w = random_window<D>(rng, q % 8 == 0 ? 500 : 90);
    if (q % 5 == 0 && !boxes.empty()) w = boxes[rng() % boxes.size()];
    for (Relation rel : {Relation::intersects, Relation::within, Relation::contains})
      ASSERT_EQ(sorted(tree.query(w, rel)), brute_window(boxes, ids, w, rel)) << to_string(w);
  }
  for (int q = 0; q < 10; ++q) {
    const Point<D> p = random_point<D>(rng, -50, 1050);
    const std::size_t k = q % 2 ? 1 : 25;
    const auto got = tree.nearest(p, k);
    const auto ref = brute_distances(boxes, p);
    ASSERT_EQ(got.size(), std::min(k, boxes.size()));
    for (std::size_t i = 0; i < got.size(); ++i) {
      EXPECT_DOUBLE_EQ(got[i].distance, ref[i]);
      ASSERT_TRUE(model.live.count(got[i].id));
      EXPECT_DOUBLE_EQ(got[i].distance, std::sqrt(squared_distance(p, model.live.at(got[i].id))));
    }
  }
}

// The shared churn harness: insertions, duplicates, erasures (also of absent entries),
// updates and window queries against brute force, for every dynamic R-tree.
template <class Tree>
struct BoxChurn {
  static constexpr int D = Tree::dimension;
  Tree tree;
  double side;
  Box<D> make_item(std::mt19937_64& rng) {
    const Point<D> p = loci::test::random_point<D>(rng);
    std::uniform_real_distribution<double> s(0.0, side);
    Box<D> b{p, p};
    for (int a = 0; a < D; ++a)
      b.max[a] += s(rng);
    return b;
  }
  Box<D> make_window(std::mt19937_64& rng) { return loci::test::random_window<D>(rng); }
  bool meets(const Box<D>& b, const Box<D>& w) { return intersects(b, w); }
  void insert(const Box<D>& b, Id id) { tree.insert(b, id); }
  bool erase(const Box<D>& b, Id id) { return tree.erase(b, id); }
  std::vector<Id> query(const Box<D>& w) { return tree.query(w); }
  void validate() { tree.validate(); }
  std::size_t size() { return tree.size(); }
};

TYPED_TEST(DynamicRTreeTest, SharedChurnHarness) {
  for (double side : {0.0, 12.0}) {
    BoxChurn<TypeParam> ops{TypeParam(), side};
    loci::test::churn_against_brute_force(ops, 71, 3000);
  }
}

}  // namespace

TYPED_TEST(DynamicRTreeTest, InsertEraseUpdateAgainstBruteForce) {
  constexpr int D = TypeParam::dimension;
  for (Shape shape : kAllShapes) {
    SCOPED_TRACE(name(shape));
    const auto pool = make_boxes<D>(shape, 2400, 31);
    std::mt19937_64 rng(17);
    TypeParam tree;
    Model<D> model;
    Id next = 1000;  // ids unrelated to positions
    std::size_t used = 0;
    for (int round = 0; round < 6; ++round) {
      for (int i = 0; i < 300 && used < pool.size(); ++i, ++next) {
        tree.insert(pool[used], next);
        model.live[next] = pool[used++];
      }
      check_queries(tree, model, rng);
      // erase a third of what is there, some of it twice
      std::vector<Id> ids = model.ids();
      std::shuffle(ids.begin(), ids.end(), rng);
      for (std::size_t i = 0; i < ids.size() / 3; ++i) {
        ASSERT_TRUE(tree.erase(model.live[ids[i]], ids[i]));
        ASSERT_FALSE(tree.erase(model.live[ids[i]], ids[i]));
        model.live.erase(ids[i]);
      }
      check_queries(tree, model, rng);
      // move some entries
      ids = model.ids();
      for (std::size_t i = 0; i < ids.size(); i += 7) {
        Box<D> moved = model.live[ids[i]];
        for (int a = 0; a < D; ++a)
          moved.min[a] += 13, moved.max[a] += 13;
        ASSERT_TRUE(tree.update(model.live[ids[i]], moved, ids[i]));
        model.live[ids[i]] = moved;
      }
      check_queries(tree, model, rng);
    }
    // drain completely
    for (const auto& [id, b] : model.live)
      ASSERT_TRUE(tree.erase(b, id));
    model.live.clear();
    check_queries(tree, model, rng, 5);
    EXPECT_TRUE(tree.empty());
  }
}

TYPED_TEST(DynamicRTreeTest, BulkLoad) {
  constexpr int D = TypeParam::dimension;
  for (Shape shape : kAllShapes)
    for (std::size_t n : {0u, 1u, 5u, 16u, 17u, 257u, 3000u}) {
      SCOPED_TRACE(name(shape) + " n=" + std::to_string(n));
      const auto boxes = make_boxes<D>(shape, n, 41 + n);
      std::vector<std::pair<Box<D>, Id>> entries;
      Model<D> model;
      for (std::size_t i = 0; i < n; ++i) {
        entries.push_back({boxes[i], i * 3});
        model.live[i * 3] = boxes[i];
      }
      auto tree = TypeParam::bulk_load(entries);
      std::mt19937_64 rng(5);
      check_queries(tree, model, rng, 20);
      // the bulk-loaded tree stays a working dynamic tree
      for (std::size_t i = 0; i < n; i += 2) {
        ASSERT_TRUE(tree.erase(boxes[i], i * 3));
        model.live.erase(i * 3);
      }
      for (std::size_t i = 0; i < 50; ++i) {
        tree.insert(boxes.empty() ? Box<D>{} : boxes[i % n], 100000 + i);
        if (!boxes.empty()) model.live[100000 + i] = boxes[i % n];
      }
      if (boxes.empty()) continue;
      check_queries(tree, model, rng, 20);
    }
}

TYPED_TEST(DynamicRTreeTest, HeightGrowsLogarithmically) {
  constexpr int D = TypeParam::dimension;
  const auto boxes = make_boxes<D>(Shape::uniform, 5000, 3);
  TypeParam tree;
  for (std::size_t i = 0; i < boxes.size(); ++i)
    tree.insert(boxes[i], i);
  tree.validate();
  const double m = TypeParam::min_entries;
  const int bound = int(std::ceil(std::log(5000.0) / std::log(m))) + 1;
  EXPECT_LE(tree.height(), bound);
  EXPECT_GE(tree.height(), 2);
}

TYPED_TEST(DynamicRTreeTest, BadInputAndEmptyTree) {
  constexpr int D = TypeParam::dimension;
  TypeParam tree;
  EXPECT_TRUE(tree.query(Box<D>{}).empty());
  EXPECT_TRUE(tree.nearest(Point<D>{}, 4).empty());
  EXPECT_FALSE(tree.erase(Box<D>{}, 1));
  Box<D> bad{};
  bad.min[0] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(tree.insert(bad, 1), InvalidGeometry);
  bad.min[0] = 2;  // inverted
  EXPECT_THROW(tree.insert(bad, 1), InvalidGeometry);
  EXPECT_TRUE(tree.empty());
  tree.validate();
  tree.insert(Box<D>{}, 1);
  EXPECT_THROW(tree.nearest(Point<D>{}, 0), InvalidArgument);
  EXPECT_THROW(tree.update(Box<D>{}, bad, 1), InvalidGeometry);
  EXPECT_EQ(tree.size(), 1u);
  Box<D> absent{};
  absent.max[0] = 1;
  EXPECT_FALSE(tree.update(absent, Box<D>{}, 1));  // not there: nothing changes
  EXPECT_EQ(tree.size(), 1u);
  std::vector<std::pair<Box<D>, Id>> entries{{Box<D>{}, 1}, {bad, 2}};
  EXPECT_THROW(TypeParam::bulk_load(entries), InvalidGeometry);
}

TYPED_TEST(DynamicRTreeTest, VisitorStopsEarly) {
  constexpr int D = TypeParam::dimension;
  const auto boxes = make_boxes<D>(Shape::clustered, 1000, 8);
  TypeParam tree;
  for (std::size_t i = 0; i < boxes.size(); ++i)
    tree.insert(boxes[i], i);
  Box<D> all;
  for (int a = 0; a < D; ++a)
    all.min[a] = -1e9, all.max[a] = 1e9;
  int seen = 0;
  const auto stats = tree.query(all, [&](Id, const Box<D>&) { return ++seen < 4; });
  EXPECT_EQ(seen, 4);
  EXPECT_EQ(stats.results, 4u);
  seen = 0;
  tree.nearest(Point<D>{}, 100, [&](Id, const Box<D>&, double) { return ++seen < 6; });
  EXPECT_EQ(seen, 6);
}

// Boxes 2e110 wide have a volume of inf in 3D, so every waste and enlargement the quadratic
// split compares is inf or NaN; the split must still partition the node.
TEST(DynamicRTree, QuadraticSplitWithInfiniteVolumes) {
  RTree<3, QuadraticSplit> tree;
  std::vector<Box<3>> boxes;
  std::vector<Id> ids;
  for (int i = 0; i < 200; ++i) {
    const double c = (i % 7) * 1e109 - (i % 5) * 3e109;
    const Box<3> b{{c - 1e110, c - 1e110, c - (i % 3) * 1e110}, {c + 1e110, c + 1e110, c + 1e110}};
    tree.insert(b, Id(i));
    boxes.push_back(b);
    ids.push_back(Id(i));
  }
  ASSERT_NO_THROW(tree.validate());
  ASSERT_EQ(tree.size(), boxes.size());
  for (double x : {-2e110, 0.0, 1.5e110, 4e110}) {
    const Box<3> w{{x, x, x}, {x, x, x}};
    EXPECT_EQ(sorted(tree.query(w)), brute_window(boxes, ids, w, Relation::intersects));
  }
}
