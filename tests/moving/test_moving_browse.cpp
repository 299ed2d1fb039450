// Distance browsing on the moving trees: objects in increasing distance from a point at a
// time, one at a time until the visitor stops, against brute force over the objects'
// positions then, on every generated fleet, at times from before the clock to past it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <unordered_map>
#include <vector>

#include "loci/index/moving/star_tree.hpp"
#include "loci/index/moving/tpr_tree.hpp"
#include "support/fleet_data.hpp"

namespace loci {
namespace {

template <class T>
class MovingBrowseTest : public ::testing::Test {};
using Trees = ::testing::Types<TprTree<2>, StarTree<2>>;
TYPED_TEST_SUITE(MovingBrowseTest, Trees);

TYPED_TEST(MovingBrowseTest, MatchesBruteForceInOrderAndStops) {
  for (test::Fleet f : test::kAllFleets) {
    const auto fleet = test::make_fleet(f, 1200, 77);
    TypeParam index;
    std::unordered_map<Id, Motion2> objs;
    for (std::size_t i = 0; i < fleet.size(); ++i) {
      index.insert(Id(i * 5 + 2), fleet[i]);
      objs[Id(i * 5 + 2)] = fleet[i];
    }
    std::mt19937_64 rng(78);
    std::uniform_real_distribution<double> u(-100, 1100), dt(-30, 90);
    for (int q = 0; q < 40; ++q) {
      const Point2 p{u(rng), u(rng)};
      const double s = index.clock() + dt(rng);  // before the clock too
      std::vector<double> brute;
      for (const auto& [id, m] : objs)
        brute.push_back(std::sqrt(squared_distance(position(m, s), p)));
      std::sort(brute.begin(), brute.end());
      // The whole walk: every object once, in increasing distance, each at its own distance.
      std::vector<double> got;
      std::vector<Id> seen;
      index.browse(p, s, [&](Id id, const Motion2& m, double d) {
        EXPECT_EQ(d, std::sqrt(squared_distance(position(objs.at(id), s), p)));
        EXPECT_EQ(m.t, objs.at(id).t);
        got.push_back(d);
        seen.push_back(id);
        return true;
      });
      ASSERT_EQ(got, brute) << test::name(f) << " query " << q;
      std::sort(seen.begin(), seen.end());
      EXPECT_TRUE(std::adjacent_find(seen.begin(), seen.end()) == seen.end());
      // Stopped after k: the first k distances, and no more visits.
      const std::size_t k = 1 + std::size_t(rng() % 20);
      std::vector<double> first;
      index.browse(p, s, [&](Id, const Motion2&, double d) {
        first.push_back(d);
        return first.size() < k;
      });
      ASSERT_EQ(first.size(), k);
      EXPECT_TRUE(std::equal(first.begin(), first.end(), brute.begin()));
      // nearest() with the same k gives the same distances.
      const auto near = index.nearest(p, s, k);
      ASSERT_EQ(near.size(), k);
      for (std::size_t i = 0; i < k; ++i)
        EXPECT_EQ(near[i].distance, first[i]);
    }
  }
}

TYPED_TEST(MovingBrowseTest, EmptyTreeAndBadInput) {
  TypeParam index;
  int visits = 0;
  index.browse(Point2{0, 0}, 0.0, [&](Id, const Motion2&, double) { return ++visits, true; });
  EXPECT_EQ(visits, 0);
  index.insert(1, Motion2{0, {0, 0}, {1, 0}});
  index.browse(Point2{0, 0}, 5.0, [&](Id id, const Motion2&, double d) {
    EXPECT_EQ(id, 1u);
    EXPECT_EQ(d, 5.0);
    return ++visits, true;
  });
  EXPECT_EQ(visits, 1);
  const auto none = [](Id, const Motion2&, double) { return true; };
  EXPECT_THROW(index.browse(Point2{NAN, 0}, 0.0, none), InvalidGeometry);
  EXPECT_THROW(index.browse(Point2{0, 0}, 1e200, none), InvalidArgument);
}

}  // namespace
}  // namespace loci
