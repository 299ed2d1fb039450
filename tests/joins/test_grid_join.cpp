// Tiled sort-and-sweep joins against brute force: every shape of random data, long boxes that
// cross many tiles (where the tiling matters), boxes meeting exactly on tile borders, extents
// of zero width or height, the fall-back to the plain sweep when boxes span most tiles, early
// stops, empty inputs and bad boxes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "loci/index/grid_join.hpp"
#include "support/brute_force.hpp"
#include "support/random_data.hpp"

namespace loci::test {
namespace {

using Pairs = BoxPairs;

Pairs self_pairs(const std::vector<Box<2>>& boxes) {
  Pairs got;
  const QueryStats s = grid_self_join(boxes, [&](Id i, Id j) {
    EXPECT_LT(i, j);
    return got.push_back({i, j}), true;
  });
  EXPECT_EQ(s.results, got.size());
  std::sort(got.begin(), got.end());
  return got;
}

Pairs join_pairs(const std::vector<Box<2>>& a, const std::vector<Box<2>>& b) {
  Pairs got;
  grid_join(a, b, [&](Id i, Id j) { return got.push_back({i, j}), true; });
  std::sort(got.begin(), got.end());
  return got;
}

// Short boxes with a share of long ones, horizontal, vertical and diagonal, over [0, 1000]^2.
std::vector<Box<2>> with_long_boxes(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1000), small(0, 4), big(50, 600);
  std::vector<Box<2>> out;
  for (std::size_t i = 0; i < n; ++i) {
    const double x = u(rng), y = u(rng);
    double w = small(rng), h = small(rng);
    switch (rng() % 10) {
      case 0:
        w = big(rng);
        break;
      case 1:
        h = big(rng);
        break;
      case 2:
        w = big(rng), h = big(rng);
        break;
      default:
        break;
    }
    out.push_back({{x, y}, {x + w, y + h}});
  }
  return out;
}

class GridJoin : public ::testing::TestWithParam<Shape> {};

TEST_P(GridJoin, SelfJoinMatchesBruteForce) {
  for (std::size_t n : {0, 1, 2, 17, 3000}) {
    const auto boxes = make_boxes<2>(GetParam(), n, 100 + n);
    EXPECT_EQ(self_pairs(boxes), brute_self_pairs(boxes)) << n << " boxes";
  }
}

TEST_P(GridJoin, TwoSetJoinMatchesBruteForce) {
  for (auto [na, nb] : {std::pair<std::size_t, std::size_t>{0, 5}, {5, 0}, {1, 1}, {1900, 2300}}) {
    const auto a = make_boxes<2>(GetParam(), na, 200 + na);
    auto b = make_boxes<2>(GetParam(), nb, 300 + nb);
    for (std::size_t i = 0; i < std::min(a.size(), b.size()); i += 7)
      b[i] = a[i];
    EXPECT_EQ(join_pairs(a, b), brute_join_pairs(a, b)) << na << " x " << nb;
  }
}

INSTANTIATE_TEST_SUITE_P(Shapes, GridJoin, ::testing::ValuesIn(kAllShapes),
                         [](const auto& info) { return name(info.param); });

TEST(GridJoinEdges, LongBoxesAcrossTiles) {
  for (std::uint64_t seed : {1, 2, 3}) {
    const auto a = with_long_boxes(4000, seed), b = with_long_boxes(2500, seed + 10);
    EXPECT_EQ(self_pairs(a), brute_self_pairs(a)) << seed;
    EXPECT_EQ(join_pairs(a, b), brute_join_pairs(a, b)) << seed;
    // Fewer box pairs compared than the plain sweep, which is the point of the tiles.
    std::size_t plain = self_join(a, [](Id, Id) { return true; }).entries_tested;
    std::size_t tiled = grid_self_join(a, [](Id, Id) { return true; }).entries_tested;
    EXPECT_LT(tiled, plain / 2) << seed;
  }
}

TEST(GridJoinEdges, BoxesMeetingOnTileBorders) {
  // Unit boxes on an integer lattice over [0, 64]^2: with 4096 boxes the tiles' borders fall on
  // lattice lines, where boxes touch edge to edge and corner to corner.
  std::vector<Box<2>> boxes;
  for (int x = 0; x < 64; ++x)
    for (int y = 0; y < 64; ++y)
      boxes.push_back({{double(x), double(y)}, {x + 1.0, y + 1.0}});
  EXPECT_EQ(self_pairs(boxes), brute_self_pairs(boxes));
  std::vector<Box<2>> points;
  for (int x = 0; x <= 64; x += 2)
    for (int y = 0; y <= 64; y += 2)
      points.push_back(Box<2>::of_point({double(x), double(y)}));
  EXPECT_EQ(join_pairs(points, boxes), brute_join_pairs(points, boxes));
  EXPECT_EQ(join_pairs(boxes, points), brute_join_pairs(boxes, points));
}

TEST(GridJoinEdges, FlatExtentsAndBoxesSpanningEverything) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-100, 100);
  std::vector<Box<2>> row, column, wide;
  for (int i = 0; i < 2000; ++i) {
    const double x = u(rng);
    row.push_back({{x, 3}, {x + 0.5, 3}});
    column.push_back({{-0.0, x}, {0.0, x + 0.5}});
    wide.push_back({{-100 + u(rng) / 100, -100}, {100, 100 + u(rng) / 100}});
  }
  EXPECT_EQ(self_pairs(row), brute_self_pairs(row));
  EXPECT_EQ(self_pairs(column), brute_self_pairs(column));
  EXPECT_EQ(join_pairs(row, column), brute_join_pairs(row, column));
  // Every box covers the extent: listing them per tile would multiply them, so the plain
  // sweep answers (still correctly).
  EXPECT_EQ(self_pairs(wide), brute_self_pairs(wide));
}

// Finite boxes further apart than a double reaches: max - min of the extent overflows on
// both axes, yet the grid must still be a grid.
TEST(GridJoinEdges, ExtentBeyondTheRangeOfDoubles) {
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Box<2>> boxes;
  for (int i = 0; i < 3000; ++i) {
    const double cx = (int(rng() % 3) - 1) * 1e308 * u(rng), cy = (int(rng() % 3) - 1) * 1e308;
    const double wx = i % 50 == 0 ? 5e307 : 1e306 * u(rng), wy = 1e306 * u(rng);
    boxes.push_back({{cx - wx, cy - wy}, {cx + wx, cy + wy}});
  }
  boxes.push_back({{-1.7e308, -1.7e308}, {-1.7e308, -1.7e308}});
  boxes.push_back({{1.7e308, 1.7e308}, {1.7e308, 1.7e308}});
  const std::vector<Box<2>> some(boxes.begin(), boxes.begin() + 500);
  EXPECT_EQ(self_pairs(boxes), brute_self_pairs(boxes));
  EXPECT_EQ(join_pairs(some, boxes), brute_join_pairs(some, boxes));
}

TEST(GridJoinEdges, StopsEarlyAndRefusesBadBoxes) {
  const auto boxes = make_boxes<2>(Shape::clustered, 3000, 9);
  std::size_t calls = 0;
  grid_self_join(boxes, [&](Id, Id) { return ++calls < 5; });
  EXPECT_EQ(calls, 5u);
  calls = 0;
  grid_join(boxes, boxes, [&](Id, Id) { return ++calls < 3; });
  EXPECT_EQ(calls, 3u);
  std::vector<Box<2>> bad = {Box<2>{{0, 0}, {1, 1}}, Box<2>{{std::nan(""), 0}, {1, 1}}};
  EXPECT_THROW(grid_self_join(bad, [](Id, Id) { return true; }), InvalidGeometry);
  EXPECT_THROW(grid_join(bad, boxes, [](Id, Id) { return true; }), InvalidGeometry);
  bad[1] = Box<2>{{2, 0}, {1, 1}};
  EXPECT_THROW(grid_self_join(bad, [](Id, Id) { return true; }), InvalidGeometry);
}

}  // namespace
}  // namespace loci::test
