// Fleets with history: queries about any time answer from the reports in force then, checked
// against brute force over the histories (exact for timeslices and nearest-n, against a fine
// simulation for windows over an interval), with reports arriving out of time order.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <vector>

#include "loci/index/moving/fleet.hpp"
#include "loci/index/moving/moving_grid.hpp"
#include "loci/index/moving/moving_scan.hpp"
#include "loci/index/moving/star_tree.hpp"
#include "loci/index/moving/tpr_tree.hpp"

namespace loci {
namespace {

using History = std::map<Id, std::map<double, Motion2>>;  // by id, by time

const Motion2* at(const std::map<double, Motion2>& h, double s) {
  auto it = h.upper_bound(s);
  return it == h.begin() ? nullptr : &std::prev(it)->second;
}

template <class T>
class FleetTest : public ::testing::Test {};
using Indexes = ::testing::Types<MovingScan<2>, TprTree<2>, StarTree<2>, MovingGrid<2>>;
TYPED_TEST_SUITE(FleetTest, Indexes);

TYPED_TEST(FleetTest, AnswersFromTheReportsInForce) {
  for (double epoch : {0.0, 1.7e9}) {
    Fleet<TypeParam> fleet;
    History truth;
    std::mt19937_64 rng(epoch > 0 ? 2 : 1);
    std::uniform_real_distribution<double> pos(0, 1000), vel(-3, 3), when(0, 100);
    // 600 objects, each with 1 to 4 reports at random times, given in random order.
    std::vector<std::pair<Id, Motion2>> reports;
    for (Id id = 0; id < 600; ++id)
      for (int k = 0, n = 1 + int(rng() % 4); k < n; ++k)
        reports.push_back(
            {id * 11, {epoch + when(rng), {pos(rng), pos(rng)}, {vel(rng), vel(rng)}}});
    std::shuffle(reports.begin(), reports.end(), rng);
    for (const auto& [id, m] : reports) {
      fleet.report(id, m);
      truth[id][m.t] = m;
    }
    fleet.validate();
    EXPECT_EQ(fleet.size(), truth.size());
    for (int q = 0; q < 150; ++q) {
      // Times before, among and after the reports.
      const double s = epoch + when(rng) * 1.4 - 20;
      const double x = pos(rng), y = pos(rng);
      const Box2 box{{x, y}, {x + 120, y + 120}};
      std::vector<Id> want;
      for (const auto& [id, h] : truth)
        if (const Motion2* m = at(h, s); m && intersects(box, position(*m, s))) want.push_back(id);
      auto got = fleet.query(MovingWindow<2>::at(box, s));
      std::sort(got.begin(), got.end());
      ASSERT_EQ(got, want) << "timeslice " << q;
      // Nearest-n at s.
      std::vector<double> d;
      for (const auto& [id, h] : truth)
        if (const Motion2* m = at(h, s))
          d.push_back(std::sqrt(squared_distance(position(*m, s), Point2{x, y})));
      std::sort(d.begin(), d.end());
      const auto near = fleet.nearest(Point2{x, y}, s, 5);
      ASSERT_EQ(near.size(), std::min<std::size_t>(5, d.size()));
      for (std::size_t i = 0; i < near.size(); ++i)
        ASSERT_DOUBLE_EQ(near[i].distance, d[i]) << "nearest " << q;
      // A window over [s, s + 8]: what a fine simulation sees is reported; what is reported is
      // seen by the simulation with the window grown by the distance moved between samples.
      const auto during = MovingWindow<2>::during(box, s, s + 8);
      auto hits = fleet.query(during);
      std::sort(hits.begin(), hits.end());
      for (const auto& [id, h] : truth) {
        bool seen = false, near_seen = false;
        for (int k = 0; k <= 800; ++k) {
          const double u = s + 8.0 * k / 800;
          const Motion2* m = at(h, u);
          if (!m) continue;
          const Point2 p = position(*m, u);
          seen |= intersects(box, p);
          near_seen |= intersects(Box2{{x - 0.05, y - 0.05}, {x + 120.05, y + 120.05}}, p);
        }
        const bool reported = std::binary_search(hits.begin(), hits.end(), id);
        if (seen) EXPECT_TRUE(reported) << "interval " << q << " id " << id;
        if (reported) EXPECT_TRUE(near_seen) << "interval " << q << " id " << id;
      }
    }
    // Conflicts at a time among the reports: from the reports in force then.
    const double now = epoch + 50;
    std::vector<Id> ids;
    std::vector<Motion2> motions;
    for (const auto& [id, h] : truth)
      if (const Motion2* m = at(h, now)) ids.push_back(id), motions.push_back(*m);
    const auto want = find_conflicts<2>(ids, motions, 15, now, 20);
    const auto got = fleet.conflicts(15, now, 20);
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t i = 0; i < got.size(); ++i)
      EXPECT_TRUE(got[i].a == want[i].a && got[i].b == want[i].b);
    EXPECT_GT(got.size(), 0u);
  }
}

TYPED_TEST(FleetTest, LaterReportReplacesAndStoppedObjectsKeepMoving) {
  Fleet<TypeParam> fleet;
  fleet.report(1, {10, {0, 0}, {1, 0}});
  fleet.report(1, {20, {100, 0}, {0, 1}});  // a jump: the later report is what holds from 20
  fleet.report(1, {15, {5, 5}, {0, 0}});    // late, but in force over [15, 20)
  fleet.report(2, {0, {50, 50}, {0, 0}});   // reports once, never again: it stays put
  EXPECT_EQ(fleet.reports(), 4u);
  EXPECT_EQ(fleet.size(), 2u);
  EXPECT_EQ(fleet.query(MovingWindow<2>::at({{99, 9}, {101, 11}}, 30)), std::vector<Id>{1});
  EXPECT_EQ(fleet.query(MovingWindow<2>::at({{4, 4}, {6, 6}}, 17)), std::vector<Id>{1});
  EXPECT_EQ(fleet.query(MovingWindow<2>::at({{1, -1}, {3, 1}}, 12)), std::vector<Id>{1});
  EXPECT_TRUE(fleet.query(MovingWindow<2>::at({{-1, -1}, {1, 1}}, 9)).empty());  // not yet
  EXPECT_EQ(fleet.query(MovingWindow<2>::at({{49, 49}, {51, 51}}, 1e6)), std::vector<Id>{2});
  ASSERT_NE(fleet.in_force(1, 16), nullptr);
  EXPECT_EQ(fleet.in_force(1, 16)->t, 15);
  EXPECT_EQ(fleet.in_force(1, 9.99), nullptr);
  // Same time again: replaced.
  fleet.report(2, {0, {60, 60}, {0, 0}});
  EXPECT_EQ(fleet.reports(), 5u);
  EXPECT_EQ(fleet.query(MovingWindow<2>::at({{59, 59}, {61, 61}}, 5)), std::vector<Id>{2});
  fleet.validate();
  EXPECT_THROW(fleet.report(3, {std::nan(""), {0, 0}, {0, 0}}), InvalidGeometry);
  // k = 0 is refused as the indexes refuse it, before the clock as after.
  EXPECT_THROW(fleet.nearest(Point2{0, 0}, 30, 0), InvalidArgument);
  EXPECT_THROW(fleet.nearest(Point2{0, 0}, 12, 0), InvalidArgument);
  EXPECT_THROW(Fleet<TypeParam>().nearest(Point2{0, 0}, 0, 0), InvalidArgument);
}

}  // namespace
}  // namespace loci
