// PackedRTree against brute force: both packings, 2D and 3D, several node sizes, uniform,
// clustered and degenerate data, every window relation and nearest-n.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>
#include <thread>

#include "loci/index/packed_rtree.hpp"
#include "support/brute_force.hpp"
#include "support/random_data.hpp"

using namespace loci;
using namespace loci::test;

namespace {

template <int D, int N>
void check_tree(const std::vector<Box<D>>& boxes, Packing packing, std::uint64_t seed) {
  SCOPED_TRACE("n=" + std::to_string(boxes.size()) + " packing=" + std::to_string(int(packing)));
  const auto tree = PackedRTree<D, N>::build(boxes, packing);
  ASSERT_NO_THROW(tree.validate());
  ASSERT_EQ(tree.size(), boxes.size());
  std::vector<Id> ids(boxes.size());
  for (std::size_t i = 0; i < ids.size(); ++i)
    ids[i] = i;

  std::mt19937_64 rng(seed);
  std::size_t total_hits = 0;
  for (int q = 0; q < 150; ++q) {
    Box<D> w = random_window<D>(rng, q % 10 == 0 ? 600 : 80);
    if (q % 7 == 0 && !boxes.empty()) w = boxes[rng() % boxes.size()];  // windows equal to data
    for (Relation rel : {Relation::intersects, Relation::within, Relation::contains}) {
      const auto expected = brute_window(boxes, ids, w, rel);
      ASSERT_EQ(sorted(tree.query(w, rel)), expected)
          << "window " << to_string(w) << " rel " << int(rel);
      // By packed position: the same items, each leaf announced before it is read.
      std::vector<Id> by_position;
      std::vector<bool> announced((boxes.size() + N - 1) / N + 1, false);
      tree.query_packed(
          w,
          [&](std::size_t pos, const Box<D>& b) {
            EXPECT_TRUE(announced[pos / N]) << pos;
            EXPECT_TRUE(b == tree.box_at(pos));
            by_position.push_back(tree.item_at(pos));
            return true;
          },
          [&](std::size_t pos) {
            EXPECT_EQ(pos % N, 0u);
            announced[pos / N] = true;
          },
          rel);
      ASSERT_EQ(sorted(by_position), expected) << "window " << to_string(w) << " rel " << int(rel);
      total_hits += expected.size();
    }
  }
  if (boxes.size() > 100) {
    EXPECT_GT(total_hits, 0u);
  }
  for (int q = 0; q < 40; ++q) {
    const Point<D> p = random_point<D>(rng, -50, 1050);
    for (std::size_t k : {std::size_t(1), std::size_t(10), std::size_t(100)})
      expect_nearest(tree.nearest(p, k), boxes, p, k);
  }
}

template <int D, int N>
void check_all_shapes() {
  for (Shape shape : kAllShapes)
    for (std::size_t n : {0u, 1u, 2u, unsigned(N) - 1, unsigned(N), unsigned(N) + 1, 1000u, 3000u})
      for (Packing p : {Packing::hilbert, Packing::str}) {
        SCOPED_TRACE(name(shape));
        check_tree<D, N>(make_boxes<D>(shape, n, 100 + n), p, 7 + n);
      }
}

}  // namespace

TEST(PackedRTree, BruteForce2D) {
  check_all_shapes<2, 16>();
}
TEST(PackedRTree, BruteForce3D) {
  check_all_shapes<3, 16>();
}
TEST(PackedRTree, BruteForceSmallNodes) {
  check_all_shapes<2, 4>();
}
TEST(PackedRTree, BruteForceWideNodes) {
  check_all_shapes<2, 32>();
}
// An odd node size: each block carries a padding slot that must stay empty.
TEST(PackedRTree, BruteForceOddNodes) {
  check_all_shapes<2, 5>();
  check_all_shapes<3, 13>();
}

TEST(PackedRTree, ManyLevels) {
  const auto boxes = make_boxes<2>(Shape::uniform, 20000, 5);
  for (Packing p : {Packing::hilbert, Packing::str}) {
    const auto tree = PackedRTree<2, 4>::build(boxes, p);
    EXPECT_EQ(tree.levels(), 8);  // 20000 -> 5000 -> 1250 -> 313 -> 79 -> 20 -> 5 -> 2
    tree.validate();
    std::mt19937_64 rng(3);
    std::vector<Id> ids(boxes.size());
    for (std::size_t i = 0; i < ids.size(); ++i)
      ids[i] = i;
    for (int q = 0; q < 50; ++q) {
      const auto w = random_window<2>(rng, 300);
      ASSERT_EQ(sorted(tree.query(w)), brute_window(boxes, ids, w, Relation::intersects));
    }
  }
}

TEST(PackedRTree, ContainedNodesAreReportedWithoutTests) {
  const auto boxes = make_boxes<2>(Shape::uniform, 5000, 9);
  const auto tree = PackedRTree<2>::build(boxes);
  std::size_t n = 0;
  const auto all =
      tree.query(Box2{{-1e9, -1e9}, {1e9, 1e9}}, [&](Id, const Box2&) { return ++n, true; });
  EXPECT_EQ(n, boxes.size());
  EXPECT_EQ(all.results, boxes.size());
  EXPECT_EQ(all.nodes_visited, 1u);  // the root: every child lies inside the window
}

// Hilbert packing of a shuffled row of points whose centres overflow (min + max beyond
// DBL_MAX) or spread over less than 65535 / DBL_MAX: the packing still follows the row, so a
// window around one point reads one path, and answers are exact.
TEST(PackedRTree, HilbertPackingOfExtremeCentres) {
  for (const auto& [x0, step] : {std::pair{1e308, 1.6e304}, std::pair{1e-300, 5e-308}}) {
    std::vector<Box2> boxes;
    for (int i = 0; i < 4096; ++i)
      boxes.push_back(Box2::of_point({x0 + i * step, 1}));
    std::shuffle(boxes.begin(), boxes.end(), std::mt19937_64(12));
    std::vector<Id> ids(boxes.size());
    for (std::size_t i = 0; i < ids.size(); ++i)
      ids[i] = i;
    const auto tree = PackedRTree<2>::build(boxes);
    tree.validate();
    for (int i : {0, 1000, 4095}) {
      const double x = x0 + i * step;
      const Box2 w{{x - step / 4, 0}, {x + step / 4, 2}};
      std::size_t n = 0;
      const auto st = tree.query(w, [&](Id, const Box2&) { return ++n, true; });
      EXPECT_EQ(n, 1u);
      EXPECT_LE(st.nodes_visited, 6u) << x0;
      EXPECT_EQ(sorted(tree.query(w)), brute_window(boxes, ids, w, Relation::intersects));
    }
  }
}

TEST(PackedRTree, VisitorStopsEarly) {
  const auto boxes = make_boxes<2>(Shape::clustered, 3000, 10);
  const auto tree = PackedRTree<2>::build(boxes);
  std::size_t seen = 0;
  tree.query(Box2{{-1e9, -1e9}, {1e9, 1e9}}, [&](Id, const Box2&) { return ++seen < 5; });
  EXPECT_EQ(seen, 5u);
  seen = 0;
  tree.query(Box2{{100, 100}, {900, 900}}, [&](Id, const Box2&) { return ++seen < 3; });
  EXPECT_EQ(seen, 3u);
  seen = 0;
  tree.nearest(Point2{500, 500}, 50, [&](Id, const Box2&, double) { return ++seen < 7; });
  EXPECT_EQ(seen, 7u);
  const auto no_ahead = [](std::size_t) {};
  seen = 0;  // whole subtrees reported in runs
  tree.query_packed(
      Box2{{-1e9, -1e9}, {1e9, 1e9}}, [&](std::size_t, const Box2&) { return ++seen < 40; },
      no_ahead);
  EXPECT_EQ(seen, 40u);
  // Every leaf tested: boxes around the origin, the ones containing it asked for.
  std::vector<Box2> around(3000);
  for (std::size_t i = 0; i < around.size(); ++i)
    around[i] = {{-1.0 - double(i), -2.0}, {1.0, 2.0 + double(i)}};
  const auto nested = PackedRTree<2>::build(around);
  seen = 0;
  nested.query_packed(
      Box2{{0, 0}, {0, 0}}, [&](std::size_t, const Box2&) { return ++seen < 40; }, no_ahead,
      Relation::contains);
  EXPECT_EQ(seen, 40u);
}

TEST(PackedRTree, NearestReportsBoxesAndOrder) {
  const auto boxes = make_boxes<2>(Shape::uniform, 2000, 11);
  const auto tree = PackedRTree<2>::build(boxes, Packing::str);
  double last = -1;
  tree.nearest(Point2{300, 700}, 2000, [&](Id id, const Box2& b, double d) {
    EXPECT_EQ(b, boxes[id]);
    EXPECT_GE(d, last);
    last = d;
    return true;
  });
  EXPECT_EQ(tree.nearest(Point2{300, 700}, 5000).size(), 2000u);
}

TEST(PackedRTree, BadInput) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<Box2> boxes = make_boxes<2>(Shape::uniform, 100, 1);
  boxes[42].min[1] = nan;
  EXPECT_THROW(PackedRTree<2>::build(boxes), InvalidGeometry);
  boxes[42] = Box2{{5, 5}, {4, 6}};
  try {
    PackedRTree<2>::build(boxes);
    FAIL() << "inverted box accepted";
  } catch (const InvalidGeometry& e) {
    EXPECT_NE(std::string(e.what()).find("box 42"), std::string::npos) << e.what();
  }
  boxes[42] = Box2{{5, 5}, {inf, 6}};
  EXPECT_THROW(PackedRTree<2>::build(boxes), InvalidGeometry);
  boxes[42] = Box2{{5, 5}, {6, 6}};
  const auto tree = PackedRTree<2>::build(boxes);
  EXPECT_THROW(tree.nearest(Point2{1, 1}, 0), InvalidArgument);
  EXPECT_THROW(tree.nearest(Point2{nan, 1}, 3), InvalidGeometry);
  EXPECT_THROW(tree.query(Box2{{nan, 0}, {1, 1}}), InvalidGeometry);
  EXPECT_THROW(tree.query(Box2{{2, 0}, {1, 1}}), InvalidGeometry);
}

TEST(PackedRTree, EmptyTree) {
  const auto tree = PackedRTree<2>::build({});
  tree.validate();
  EXPECT_TRUE(tree.empty());
  EXPECT_TRUE(tree.query(Box2{{0, 0}, {1, 1}}).empty());
  EXPECT_TRUE(tree.nearest(Point2{0, 0}, 3).empty());
  EXPECT_TRUE(tree.bounds().is_empty());
}

TEST(PackedRTree, AdoptsExternalArrays) {
  const auto boxes = make_boxes<2>(Shape::clustered, 1234, 12);
  const auto tree = PackedRTree<2>::build(boxes);
  auto blocks = std::make_shared<std::vector<PackedRTree<2>::Block>>(tree.blocks().begin(),
                                                                     tree.blocks().end());
  auto items = std::make_shared<std::vector<std::uint32_t>>(tree.item_indices().begin(),
                                                            tree.item_indices().end());
  const auto view = PackedRTree<2>::adopt(tree.size(), tree.packing(), *blocks, *items, blocks);
  view.validate();
  const Box2 w{{200, 200}, {400, 400}};
  EXPECT_EQ(sorted(view.query(w)), sorted(tree.query(w)));
  EXPECT_THROW(PackedRTree<2>::adopt(tree.size() + 100, tree.packing(), *blocks, *items, nullptr),
               Error);
  // A corrupted copy is caught by validate().
  (*items)[3] = (*items)[4];
  const auto bad = PackedRTree<2>::adopt(tree.size(), tree.packing(), *blocks, *items, nullptr);
  EXPECT_THROW(bad.validate(), Error);
}

TEST(PackedRTree, ConcurrentQueriesAgree) {
  const auto boxes = make_boxes<2>(Shape::uniform, 5000, 13);
  const auto tree = PackedRTree<2>::build(boxes);
  std::vector<std::vector<Id>> results(4);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (int i = 0; i < 50; ++i)
        results[t] = sorted(tree.query(Box2{{100, 100}, {300, 250}}));
    });
  for (auto& th : threads)
    th.join();
  for (int t = 1; t < 4; ++t)
    EXPECT_EQ(results[t], results[0]);
}
