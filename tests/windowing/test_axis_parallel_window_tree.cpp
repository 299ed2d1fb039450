// AxisParallelWindowTree against brute force (the exact box/segment test of geom) and against
// SegmentWindowTree on the same data: uniform, clustered and long segments, a street grid, and
// degenerate layers on an integer grid (duplicates, zero-length segments, nested and
// overlapping collinear segments, everything on one line or at one y) queried with windows
// whose edges and corners fall exactly on segments.
#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "loci/index/axis_parallel_window_tree.hpp"
#include "loci/index/segment_window_tree.hpp"
#include "support/brute_force.hpp"
#include "support/random_data.hpp"
#include "support/segment_data.hpp"

using namespace loci;
using namespace loci::test;

namespace {

enum class Layer {
  uniform,
  clustered,
  long_segments,
  street_grid,
  grid_degenerate,
  one_line,
  equal_y
};

std::string name(Layer l) {
  switch (l) {
    case Layer::uniform:
      return "uniform";
    case Layer::clustered:
      return "clustered";
    case Layer::long_segments:
      return "long_segments";
    case Layer::street_grid:
      return "street_grid";
    case Layer::grid_degenerate:
      return "grid_degenerate";
    case Layer::one_line:
      return "one_line";
    default:
      return "equal_y";
  }
}

bool on_integer_grid(Layer l) {
  return l == Layer::street_grid || l == Layer::grid_degenerate || l == Layer::one_line ||
         l == Layer::equal_y;
}

Segment2 axis_segment(const Point2& a, double length, bool horizontal) {
  return horizontal ? Segment2{a, {a[0] + length, a[1]}} : Segment2{a, {a[0], a[1] + length}};
}

std::vector<Segment2> make_layer(Layer layer, std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1000), len(-30, 30), far(-300, 300);
  std::normal_distribution<double> spread(0, 20);
  auto g = [&](int cells) { return double(rng() % std::uint64_t(cells)); };
  std::vector<Point2> centres;
  for (int c = 0; c < 6; ++c)
    centres.push_back({u(rng), u(rng)});
  std::vector<Segment2> out;
  for (std::size_t i = 0; i < n; ++i) {
    const bool horizontal = rng() % 2;
    switch (layer) {
      case Layer::uniform:
        out.push_back(axis_segment({u(rng), u(rng)}, len(rng), horizontal));
        break;
      case Layer::clustered: {
        const Point2& c = centres[rng() % centres.size()];
        out.push_back(axis_segment({c[0] + spread(rng), c[1] + spread(rng)}, len(rng), horizontal));
        break;
      }
      case Layer::long_segments:
        out.push_back(axis_segment({u(rng), u(rng)}, far(rng), horizontal));
        break;
      case Layer::street_grid: {
        // blocks between grid lines every 4 units, many sharing their ends
        const Point2 a{4 * g(20), 4 * g(20)};
        out.push_back(axis_segment(a, 4 * double(rng() % 3 + 1), horizontal));
        break;
      }
      case Layer::grid_degenerate: {
        const Point2 a{g(41), g(41)};
        switch (rng() % 5) {
          case 0:
            out.push_back({a, a});  // zero length
            break;
          case 1:
            if (!out.empty()) {
              out.push_back(out[rng() % out.size()]);  // duplicate
              break;
            }
            [[fallthrough]];
          case 2: {
            // nested and overlapping along a few lines
            const double line = 10 * g(5), lo = g(41), hi = g(41);
            out.push_back(horizontal ? Segment2{{lo, line}, {hi, line}}
                                     : Segment2{{line, lo}, {line, hi}});
            break;
          }
          default:
            out.push_back(axis_segment(a, g(41) - 20, horizontal));
        }
        break;
      }
      case Layer::one_line: {
        // overlapping pieces of y = 20, a few of them points
        const double a = g(41), b = g(41);
        out.push_back({{a, 20}, {rng() % 10 ? b : a, 20}});
        break;
      }
      case Layer::equal_y: {
        // horizontal segments at three heights, vertical ones between them
        const double y = 10 * double(rng() % 3 + 1);
        const double x = g(41);
        if (rng() % 4)
          out.push_back({{x, y}, {g(41), y}});
        else
          out.push_back({{x, y}, {x, y + 10}});
        break;
      }
    }
  }
  return out;
}

class Layers : public ::testing::TestWithParam<Layer> {};

TEST_P(Layers, MatchesBruteForceAndSegmentWindowTree) {
  const bool grid = on_integer_grid(GetParam());
  const auto segs = make_layer(GetParam(), grid ? 1500 : 3000, 17);
  const auto tree = AxisParallelWindowTree::build(segs);
  tree.validate();
  ASSERT_EQ(tree.size(), segs.size());
  const auto general = SegmentWindowTree::build(segs);
  std::mt19937_64 rng(23);
  std::size_t hits = 0;
  for (int q = 0; q < 300; ++q) {
    const Box2 w = segment_window(rng, segs, grid);
    const auto expected = brute_segments(segs, w);
    std::vector<Id> got;
    const QueryStats s = tree.query(w, [&](Id id, const Segment2& g) {
      EXPECT_EQ(g, segs[id]);
      return got.push_back(id), true;
    });
    ASSERT_EQ(s.results, got.size());
    ASSERT_EQ(got.size(), expected.size()) << to_string(w) << " (a duplicate or a miss)";
    ASSERT_EQ(sorted(got), expected) << to_string(w);
    ASSERT_EQ(sorted(general.query(w)), expected) << to_string(w);
    hits += expected.size();
  }
  EXPECT_GT(hits, 300u);
}

INSTANTIATE_TEST_SUITE_P(AxisParallel, Layers,
                         ::testing::Values(Layer::uniform, Layer::clustered, Layer::long_segments,
                                           Layer::street_grid, Layer::grid_degenerate,
                                           Layer::one_line, Layer::equal_y),
                         [](const auto& info) { return name(info.param); });

TEST(AxisParallelWindowTree, EdgesCornersAndCrossings) {
  const Box2 w{{0, 0}, {10, 10}};
  const std::vector<Segment2> segs = {
      {{-5, 5}, {15, 5}},     // 0: crosses left to right, no endpoint inside
      {{5, -5}, {5, 15}},     // 1: crosses bottom to top, no endpoint inside
      {{-5, 0}, {15, 0}},     // 2: along the bottom edge, beyond both corners
      {{10, -5}, {10, 15}},   // 3: along the right edge, beyond both corners
      {{-5, 10}, {0, 10}},    // 4: ends on the top-left corner
      {{10, 10}, {10, 20}},   // 5: starts on the top-right corner
      {{-5, -1}, {15, -1}},   // 6: passes just below
      {{11, -5}, {11, 15}},   // 7: passes just right
      {{-3, 3}, {0, 3}},      // 8: ends on the left edge
      {{3, 3}, {7, 3}},       // 9: inside
      {{3, 3}, {7, 3}},       // 10: its duplicate
      {{0, 0}, {0, 0}},       // 11: a point on a corner
      {{-1, -1}, {-1, -1}},   // 12: a point outside
      {{-20, 10}, {20, 10}},  // 13: along the top edge, both ends far out
      {{0, -20}, {0, 20}},    // 14: along the left edge, both ends far out
      {{-20, 11}, {20, 11}},  // 15: just above
  };
  const auto tree = AxisParallelWindowTree::build(segs);
  tree.validate();
  EXPECT_EQ(sorted(tree.query(w)), (std::vector<Id>{0, 1, 2, 3, 4, 5, 8, 9, 10, 11, 13, 14}));
  EXPECT_EQ(sorted(tree.query(w)), brute_segments(segs, w));
  // a window that is a single point on a crossing
  EXPECT_EQ(sorted(tree.query(Box2{{5, 5}, {5, 5}})), (std::vector<Id>{0, 1}));
  // a window that is a line segment along an edge
  EXPECT_EQ(sorted(tree.query(Box2{{0, 10}, {10, 10}})),
            brute_segments(segs, Box2{{0, 10}, {10, 10}}));
}

TEST(AxisParallelWindowTree, EmptyInput) {
  const auto tree = AxisParallelWindowTree::build({});
  tree.validate();
  EXPECT_TRUE(tree.empty());
  EXPECT_TRUE(tree.query(Box2{{0, 0}, {1, 1}}).empty());
  EXPECT_TRUE(AxisParallelWindowTree().query(Box2{{0, 0}, {1, 1}}).empty());
}

TEST(AxisParallelWindowTree, VisitorStopsAfterOneReport) {
  const auto segs = make_layer(Layer::long_segments, 500, 3);
  const auto tree = AxisParallelWindowTree::build(segs);
  int calls = 0;
  const QueryStats s =
      tree.query(Box2{{0, 0}, {1000, 1000}}, [&](Id, const Segment2&) { return ++calls, false; });
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(s.results, 1u);
  // no endpoint inside: the stop has to come from the crossing walks, both of them
  const std::vector<Segment2> crossing = {
      {{-5, 1}, {15, 1}}, {{-5, 2}, {15, 2}}, {{1, -5}, {1, 15}}, {{2, -5}, {2, 15}}};
  const auto cross_tree = AxisParallelWindowTree::build(crossing);
  for (int stop_after = 1; stop_after <= 4; ++stop_after) {
    calls = 0;
    cross_tree.query(Box2{{0, 0}, {10, 10}},
                     [&](Id, const Segment2&) { return ++calls < stop_after; });
    EXPECT_EQ(calls, stop_after);
  }
}

TEST(AxisParallelWindowTree, BadInputThrows) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  auto message = [](const std::vector<Segment2>& segs) -> std::string {
    try {
      AxisParallelWindowTree::build(segs);
    } catch (const InvalidGeometry& e) {
      return e.what();
    }
    return "accepted";
  };
  const std::vector<Segment2> diagonal = {{{0, 0}, {1, 0}}, {{0, 0}, {0, 1}}, {{0, 0}, {1, 1}}};
  EXPECT_NE(message(diagonal).find("segment 2 is not axis-parallel"), std::string::npos)
      << message(diagonal);
  const std::vector<Segment2> not_a_number = {{{0, 0}, {1, 0}}, {{nan, 0}, {nan, 1}}};
  EXPECT_NE(message(not_a_number).find("segment 1"), std::string::npos) << message(not_a_number);
  const std::vector<Segment2> infinite = {{{0, 0}, {inf, 0}}};
  EXPECT_NE(message(infinite).find("segment 0"), std::string::npos) << message(infinite);

  const auto tree = AxisParallelWindowTree::build(make_layer(Layer::uniform, 100, 4));
  EXPECT_THROW(tree.query(Box2{{0, 0}, {nan, 1}}), InvalidGeometry);
  EXPECT_THROW(tree.query(Box2{{nan, 0}, {1, 1}}), InvalidGeometry);
  EXPECT_THROW(tree.query(Box2{{1, 0}, {0, 1}}), InvalidGeometry);
  EXPECT_THROW(tree.query(Box2{{0, 0}, {1, inf}}), InvalidGeometry);
  EXPECT_THROW(tree.segment(100), InvalidArgument);  // an id not held: loci's error
}

}  // namespace
