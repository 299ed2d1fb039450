// SegmentWindowTree against brute force (the exact box/segment test of geom): random and
// crossing segments, polylines, and degenerate layers on an integer grid where segments are
// vertical, horizontal, duplicated, collinear, reduced to points, or pass exactly through the
// window's corners and along its edges.
#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "loci/index/segment_window_tree.hpp"
#include "support/brute_force.hpp"
#include "support/random_data.hpp"
#include "support/segment_data.hpp"

using namespace loci;
using namespace loci::test;

namespace {

enum class Layer { short_random, long_crossing, polyline, grid_degenerate, axis_parallel };

std::string name(Layer l) {
  switch (l) {
    case Layer::short_random:
      return "short_random";
    case Layer::long_crossing:
      return "long_crossing";
    case Layer::polyline:
      return "polyline";
    case Layer::grid_degenerate:
      return "grid_degenerate";
    default:
      return "axis_parallel";
  }
}

std::vector<Segment2> make_layer(Layer layer, std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1000), d(-15, 15), far(-300, 300);
  std::vector<Segment2> out;
  Point2 cur{500, 500};
  for (std::size_t i = 0; i < n; ++i) {
    switch (layer) {
      case Layer::short_random: {
        const Point2 a{u(rng), u(rng)};
        out.push_back({a, {a[0] + d(rng), a[1] + d(rng)}});
        break;
      }
      case Layer::long_crossing: {
        const Point2 a{u(rng), u(rng)};
        out.push_back({a, {a[0] + far(rng), a[1] + far(rng)}});
        break;
      }
      case Layer::polyline: {
        const Point2 next{std::clamp(cur[0] + d(rng), 0.0, 1000.0),
                          std::clamp(cur[1] + d(rng), 0.0, 1000.0)};
        out.push_back({cur, next});
        cur = next;
        break;
      }
      case Layer::grid_degenerate: {
        // small integer grid: exact touching, collinear overlaps, duplicates, points
        auto g = [&] { return double(rng() % 41); };
        const Point2 a{g(), g()};
        switch (rng() % 6) {
          case 0:
            out.push_back({a, {a[0], g()}});  // vertical
            break;
          case 1:
            out.push_back({a, {g(), a[1]}});  // horizontal
            break;
          case 2:
            out.push_back({a, a});  // a point
            break;
          case 3:
            if (!out.empty()) {
              out.push_back(out[rng() % out.size()]);  // duplicate
              break;
            }
            [[fallthrough]];
          case 4: {
            const double k = double(rng() % 10) + 1;  // diagonal through grid points
            out.push_back({a, {a[0] + k, a[1] + (rng() % 2 ? k : -k)}});
            break;
          }
          default:
            out.push_back({a, {g(), g()}});
        }
        break;
      }
      case Layer::axis_parallel: {
        const Point2 a{u(rng), u(rng)};
        if (rng() % 2)
          out.push_back({a, {a[0], a[1] + far(rng)}});
        else
          out.push_back({a, {a[0] + far(rng), a[1]}});
        break;
      }
    }
  }
  return out;
}

class Layers : public ::testing::TestWithParam<Layer> {};

TEST_P(Layers, MatchesBruteForce) {
  const bool grid = GetParam() == Layer::grid_degenerate;
  const auto segs = make_layer(GetParam(), grid ? 1500 : 3000, 17);
  const auto tree = SegmentWindowTree::build(segs);
  tree.validate();
  std::mt19937_64 rng(23);
  std::size_t hits = 0;
  for (int q = 0; q < 300; ++q) {
    const Box2 w = segment_window(rng, segs, grid);
    const auto expected = brute_segments(segs, w);
    const auto got = tree.query(w);
    ASSERT_EQ(got.size(), expected.size()) << to_string(w) << " (a duplicate or a miss)";
    ASSERT_EQ(sorted(got), expected) << to_string(w);
    hits += expected.size();
  }
  EXPECT_GT(hits, 300u);
}

INSTANTIATE_TEST_SUITE_P(Segments, Layers,
                         ::testing::Values(Layer::short_random, Layer::long_crossing,
                                           Layer::polyline, Layer::grid_degenerate,
                                           Layer::axis_parallel),
                         [](const auto& info) { return name(info.param); });

TEST(SegmentWindowTree, CrossingWithNoEndpointInside) {
  const std::vector<Segment2> segs = {
      {{-10, 5}, {20, 5}},   // straight through, horizontal
      {{5, -10}, {5, 20}},   // straight through, vertical
      {{-5, 0}, {0, -5}},    // touches the corner (0, 0) only... misses: passes (-2.5,-2.5)
      {{-5, 5}, {5, -5}},    // through the corner (0, 0)
      {{-5, 15}, {15, -5}},  // diagonal through the interior
      {{11, 0}, {20, 10}},   // outside to the right
      {{-5, 10}, {0, 10}},   // ends on the left edge at the top corner
  };
  const auto tree = SegmentWindowTree::build(segs);
  tree.validate();
  EXPECT_EQ(sorted(tree.query(Box2{{0, 0}, {10, 10}})), (std::vector<Id>{0, 1, 3, 4, 6}));
}

TEST(SegmentWindowTree, VisitorStopsEarlyAndBadInput) {
  const auto segs = make_layer(Layer::long_crossing, 500, 3);
  const auto tree = SegmentWindowTree::build(segs);
  int calls = 0;
  tree.query(Box2{{0, 0}, {1000, 1000}}, [&](Id, const Segment2&) { return ++calls < 9; });
  EXPECT_EQ(calls, 9);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(tree.query(Box2{{0, 0}, {nan, 1}}), InvalidGeometry);
  EXPECT_THROW(tree.query(Box2{{1, 0}, {0, 1}}), InvalidGeometry);
  const std::vector<Segment2> bad = {{{0, 0}, {1, std::numeric_limits<double>::infinity()}}};
  EXPECT_THROW(SegmentWindowTree::build(bad), InvalidGeometry);
  EXPECT_TRUE(SegmentWindowTree().query(Box2{{0, 0}, {1, 1}}).empty());
  EXPECT_TRUE(tree.segment(499) == segs[499]);
  EXPECT_THROW(tree.segment(500), InvalidArgument);  // an id not held: loci's error
  EXPECT_THROW(SegmentWindowTree().segment(0), InvalidArgument);
}

}  // namespace
