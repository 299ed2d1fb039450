// Sort-and-sweep joins against brute force on every shape of random data (uniform, clustered,
// duplicates, zero-area boxes, all on a line), for one set and for two, with early stops,
// empty inputs and bad boxes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "loci/index/sweep_join.hpp"
#include "support/brute_force.hpp"
#include "support/random_data.hpp"

namespace loci::test {
namespace {

using Pairs = BoxPairs;

Pairs sorted(Pairs p) {
  std::sort(p.begin(), p.end());
  return p;
}

class SweepJoin : public ::testing::TestWithParam<Shape> {};

TEST_P(SweepJoin, SelfJoinMatchesBruteForce) {
  for (std::size_t n : {0, 1, 2, 17, 1500}) {
    const auto boxes = make_boxes<2>(GetParam(), n, 100 + n);
    Pairs got;
    const QueryStats s = self_join(boxes, [&](Id i, Id j) {
      EXPECT_LT(i, j);
      return got.push_back({i, j}), true;
    });
    EXPECT_EQ(sorted(got), brute_self_pairs(boxes)) << n << " boxes";
    EXPECT_EQ(s.results, got.size());
  }
}

TEST_P(SweepJoin, TwoSetJoinMatchesBruteForce) {
  for (auto [na, nb] : {std::pair<std::size_t, std::size_t>{0, 5}, {5, 0}, {1, 1}, {900, 1300}}) {
    const auto a = make_boxes<2>(GetParam(), na, 200 + na);
    // the second set shares some boxes with the first, so equal minimum x and touching occur
    auto b = make_boxes<2>(GetParam(), nb, 300 + nb);
    for (std::size_t i = 0; i < std::min(a.size(), b.size()); i += 7)
      b[i] = a[i];
    Pairs got;
    join(a, b, [&](Id i, Id j) { return got.push_back({i, j}), true; });
    EXPECT_EQ(sorted(got), brute_join_pairs(a, b)) << na << " x " << nb;
  }
}

INSTANTIATE_TEST_SUITE_P(Shapes, SweepJoin, ::testing::ValuesIn(kAllShapes),
                         [](const auto& info) { return name(info.param); });

TEST(SweepJoinEdges, StopsEarlyAndRefusesBadBoxes) {
  const auto boxes = make_boxes<2>(Shape::clustered, 500, 9);
  std::size_t calls = 0;
  const QueryStats s = self_join(boxes, [&](Id, Id) { return ++calls < 5; });
  EXPECT_EQ(calls, 5u);
  EXPECT_EQ(s.results, 5u);
  calls = 0;
  join(boxes, boxes, [&](Id, Id) { return ++calls < 3; });
  EXPECT_EQ(calls, 3u);
  std::vector<Box<2>> bad = {Box<2>{{0, 0}, {1, 1}}, Box<2>{{std::nan(""), 0}, {1, 1}}};
  EXPECT_THROW(self_join(bad, [](Id, Id) { return true; }), InvalidGeometry);
  EXPECT_THROW(join(bad, boxes, [](Id, Id) { return true; }), InvalidGeometry);
  bad[1] = Box<2>{{2, 0}, {1, 1}};  // inverted
  EXPECT_THROW(self_join(bad, [](Id, Id) { return true; }), InvalidGeometry);
}

TEST(SweepJoinEdges, TouchingCountsAndNegativeCoordinatesSort) {
  const std::vector<Box<2>> boxes = {{{-5, -5}, {-1, -1}},
                                     {{-1, -1}, {3, 3}},
                                     {{3, 3}, {4, 4}},
                                     {{-0.0, 10}, {0.0, 11}},
                                     {{0.0, 11}, {0.0, 12}}};
  Pairs got;
  self_join(boxes, [&](Id i, Id j) { return got.push_back({i, j}), true; });
  EXPECT_EQ(sorted(got), (Pairs{{0, 1}, {1, 2}, {3, 4}}));
}

// Linework along one axis: the segments of a north-south line all share one x, so a sweep
// along x compares every pair; the sweep runs along the axis where the boxes overlap less.
// Wide flat boxes and tall thin ones, against brute force, with the pairs scanned counted.
TEST(SweepJoinEdges, SweepsAlongTheAxisOfLessOverlap) {
  std::mt19937_64 rng(41);
  std::uniform_real_distribution<double> u(0, 100);
  for (const int axis : {0, 1}) {
    const auto box = [&](double along, double across, double length, double width) {
      Box<2> b{{along, across}, {along + length, across + width}};
      if (axis == 1) {
        std::swap(b.min[0], b.min[1]);
        std::swap(b.max[0], b.max[1]);
      }
      return b;
    };
    // A line of 4,000 segments at one coordinate across, and a second one crossing it.
    std::vector<Box<2>> line, other;
    for (int k = 0; k < 4000; ++k)
      line.push_back(box(k * 0.025, 50, 0.025, 0));
    for (int k = 0; k < 3000; ++k)
      other.push_back(box(u(rng), u(rng), 0.5, 0.01));
    Pairs got;
    const QueryStats s = self_join(line, [&](Id i, Id j) { return got.push_back({i, j}), true; });
    EXPECT_EQ(sorted(got), brute_self_pairs(line)) << axis;
    EXPECT_LT(s.entries_tested, 3 * line.size()) << axis;
    got.clear();
    const QueryStats t = join(line, other, [&](Id i, Id j) { return got.push_back({i, j}), true; });
    EXPECT_EQ(sorted(got), brute_join_pairs(line, other)) << axis;
    EXPECT_LT(t.entries_tested, 60 * (line.size() + other.size())) << axis;
    got.clear();
    join(other, other, [&](Id i, Id j) { return got.push_back({i, j}), true; });
    EXPECT_EQ(sorted(got), brute_join_pairs(other, other)) << axis;
  }
}

}  // namespace
}  // namespace loci::test
