// PrioritySearchTree against brute force: both open sides on the point shapes of
// support/point_data.hpp (uniform, clustered, duplicates, on a line, all equal, ulp gaps),
// integer grids where query bounds fall exactly on points, every small size (so that every
// heap shape is built), and the bad-input and early-stop contracts.
#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "loci/index/priority_search_tree.hpp"
#include "support/brute_force.hpp"
#include "support/point_data.hpp"

using namespace loci;
using namespace loci::test;

namespace {

std::vector<Id> brute_three_sided(const std::vector<Point2>& pts, bool left, double qx, double y1,
                                  double y2) {
  std::vector<Id> out;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const bool x_ok = left ? pts[i][0] <= qx : pts[i][0] >= qx;
    if (x_ok && y1 <= pts[i][1] && pts[i][1] <= y2) out.push_back(i);
  }
  return out;
}

// Query bounds taken from the data half of the time, so that closedness is exercised.
double bound(std::mt19937_64& rng, const std::vector<Point2>& pts, int axis) {
  if (!pts.empty() && rng() % 2) return pts[rng() % pts.size()][axis];
  return std::uniform_real_distribution<double>(-50, 1050)(rng);
}

void expect_matches(const PrioritySearchTree& t, const std::vector<Point2>& pts,
                    std::mt19937_64& rng, int queries) {
  for (int q = 0; q < queries; ++q) {
    const double qx = bound(rng, pts, 0);
    double y1 = bound(rng, pts, 1), y2 = bound(rng, pts, 1);
    if (y1 > y2) std::swap(y1, y2);
    if (rng() % 8 == 0) y2 = y1;  // a single y
    for (const bool left : {true, false}) {
      const auto expected = brute_three_sided(pts, left, qx, y1, y2);
      std::vector<Id> got;
      auto collect = [&](Id id, const Point2& p) {
        EXPECT_EQ(p, pts[id]);
        return got.push_back(id), true;
      };
      const QueryStats s =
          left ? t.query_left(qx, y1, y2, collect) : t.query_right(qx, y1, y2, collect);
      ASSERT_EQ(s.results, got.size());
      ASSERT_EQ(got.size(), expected.size())
          << (left ? "left" : "right") << " qx=" << qx << " y=[" << y1 << ", " << y2 << "]";
      ASSERT_EQ(sorted(got), expected);
    }
  }
}

class Shapes : public ::testing::TestWithParam<PointShape> {};

TEST_P(Shapes, MatchesBruteForce) {
  const auto pts = make_points<2>(GetParam(), 2000, 31);
  const auto t = PrioritySearchTree::build(pts);
  t.validate();
  ASSERT_EQ(t.size(), pts.size());
  std::mt19937_64 rng(5);
  expect_matches(t, pts, rng, 300);
}

INSTANTIATE_TEST_SUITE_P(PrioritySearchTree, Shapes, ::testing::ValuesIn(kAllPointShapes),
                         [](const auto& info) { return name(info.param); });

TEST(PrioritySearchTree, IntegerGridWithDuplicatesAndEqualY) {
  std::mt19937_64 rng(9);
  std::vector<Point2> pts;
  for (int i = 0; i < 1500; ++i) {
    const double x = double(rng() % 25), y = double(rng() % 8);  // few y values, many repeats
    pts.push_back({x, y});
  }
  const auto t = PrioritySearchTree::build(pts);
  t.validate();
  for (double qx = -1; qx <= 25; qx += 1)
    for (double y1 = -1; y1 <= 8; y1 += 1)
      for (double y2 = y1; y2 <= 8; y2 += 2) {
        ASSERT_EQ(sorted(t.query_left(qx, y1, y2)), brute_three_sided(pts, true, qx, y1, y2));
        ASSERT_EQ(sorted(t.query_right(qx, y1, y2)), brute_three_sided(pts, false, qx, y1, y2));
      }
}

TEST(PrioritySearchTree, EverySmallSize) {
  std::mt19937_64 rng(12);
  for (std::size_t n = 0; n <= 70; ++n) {
    std::vector<Point2> pts;
    for (std::size_t i = 0; i < n; ++i)
      pts.push_back({double(rng() % 10), double(rng() % 10)});
    const auto t = PrioritySearchTree::build(pts);
    t.validate();
    for (double qx = -1; qx <= 10; qx += 1)
      for (double y1 = -1; y1 <= 10; y1 += 3)
        for (double y2 = y1; y2 <= 10; y2 += 2) {
          ASSERT_EQ(sorted(t.query_left(qx, y1, y2)), brute_three_sided(pts, true, qx, y1, y2))
              << "n=" << n;
          ASSERT_EQ(sorted(t.query_right(qx, y1, y2)), brute_three_sided(pts, false, qx, y1, y2))
              << "n=" << n;
        }
  }
}

TEST(PrioritySearchTree, EmptyInput) {
  const auto t = PrioritySearchTree::build({});
  t.validate();
  EXPECT_TRUE(t.empty());
  EXPECT_TRUE(t.query_left(0, -1, 1).empty());
  EXPECT_TRUE(t.query_right(0, -1, 1).empty());
  EXPECT_TRUE(PrioritySearchTree().query_left(0, 0, 0).empty());
}

TEST(PrioritySearchTree, VisitorStopsAfterOneReport) {
  const auto pts = make_points<2>(PointShape::uniform, 500, 2);
  const auto t = PrioritySearchTree::build(pts);
  int calls = 0;
  const QueryStats s =
      t.query_left(1000, 0, 1000, [&](Id, const Point2&) { return ++calls, false; });
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(s.results, 1u);
  calls = 0;
  t.query_right(0, 0, 1000, [&](Id, const Point2&) { return ++calls < 7; });
  EXPECT_EQ(calls, 7);
}

TEST(PrioritySearchTree, BadInputThrows) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<Point2> bad = {{0, 0}, {1, 1}, {nan, 2}};
  try {
    PrioritySearchTree::build(bad);
    FAIL() << "NaN point accepted";
  } catch (const InvalidGeometry& e) {
    EXPECT_NE(std::string(e.what()).find("point 2"), std::string::npos) << e.what();
  }
  const std::vector<Point2> infinite = {{0, inf}};
  EXPECT_THROW(PrioritySearchTree::build(infinite), InvalidGeometry);
  const auto t = PrioritySearchTree::build(std::vector<Point2>{{0, 0}, {1, 1}});
  EXPECT_THROW(t.query_left(nan, 0, 1), InvalidGeometry);
  EXPECT_THROW(t.query_right(0, nan, 1), InvalidGeometry);
  EXPECT_THROW(t.query_right(0, 0, inf), InvalidGeometry);
  EXPECT_EQ(t.point(1)[0], 1);
  EXPECT_THROW(t.point(2), InvalidArgument);  // an id not held: loci's error, not the STL's
  EXPECT_THROW(t.query_left(0, 1, 0), InvalidGeometry);
}

}  // namespace
