// IntervalTree and SegmentTree against brute force: stabbing and overlap on uniform,
// clustered, nested, duplicate and zero-length intervals, dynamic insert/erase, early stop,
// bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "loci/index/interval_tree.hpp"
#include "loci/index/segment_tree.hpp"
#include "support/brute_force.hpp"
#include "support/churn.hpp"
#include "support/interval_data.hpp"

using namespace loci;
using namespace loci::test;

namespace {

std::vector<Id> iota_ids(std::size_t n) {
  std::vector<Id> ids(n);
  for (std::size_t i = 0; i < n; ++i)
    ids[i] = i;
  return ids;
}

class Shapes : public ::testing::TestWithParam<IntervalShape> {};

TEST_P(Shapes, IntervalTreeMatchesBruteForce) {
  const auto ivs = make_intervals(GetParam(), 3000, 11);
  const auto ids = iota_ids(ivs.size());
  const auto tree = IntervalTree::build(ivs);
  tree.validate();
  ASSERT_EQ(tree.size(), ivs.size());
  std::mt19937_64 rng(5);
  std::size_t hits = 0;
  for (int q = 0; q < 300; ++q) {
    const double x = query_value(rng, ivs);
    const auto expected = brute_stab(ivs, ids, x);
    ASSERT_EQ(sorted(tree.stab(x)), expected) << "x = " << x;
    hits += expected.size();
    const double y = query_value(rng, ivs);
    const Interval r{std::min(x, y), std::min(x, y) + std::fabs(x - y) * 0.1};
    ASSERT_EQ(sorted(tree.overlap(r)), brute_overlap(ivs, ids, r)) << to_string(r);
  }
  EXPECT_GT(hits, 100u);
}

TEST_P(Shapes, SegmentTreeMatchesBruteForce) {
  const auto ivs = make_intervals(GetParam(), 3000, 12);
  const auto ids = iota_ids(ivs.size());
  const auto tree = SegmentTree::build(ivs);
  tree.validate();
  std::mt19937_64 rng(6);
  std::size_t hits = 0;
  for (int q = 0; q < 400; ++q) {
    const double x = query_value(rng, ivs);
    const auto expected = brute_stab(ivs, ids, x);
    ASSERT_EQ(sorted(tree.stab(x)), expected) << "x = " << x;
    hits += expected.size();
  }
  EXPECT_GT(hits, 100u);
}

INSTANTIATE_TEST_SUITE_P(IntervalData, Shapes, ::testing::ValuesIn(kAllIntervalShapes),
                         [](const auto& info) { return name(info.param); });

TEST(IntervalTree, InsertEraseAgainstBruteForce) {
  std::mt19937_64 rng(21);
  IntervalTree tree;
  std::vector<Interval> live;
  std::vector<Id> ids;
  const auto pool = make_intervals(IntervalShape::duplicates, 600, 3);
  Id next = 0;
  for (int step = 0; step < 4000; ++step) {
    if (live.empty() || rng() % 3 != 0) {
      const Interval iv = pool[rng() % pool.size()];
      tree.insert(iv, next);
      live.push_back(iv);
      ids.push_back(next++);
    } else {
      const std::size_t i = rng() % live.size();
      ASSERT_TRUE(tree.erase(live[i], ids[i]));
      EXPECT_FALSE(tree.erase(live[i], ids[i] + 1000000));  // wrong id
      live.erase(live.begin() + long(i));
      ids.erase(ids.begin() + long(i));
    }
    if (step % 97 == 0) {
      tree.validate();
      const double x = query_value(rng, live);
      ASSERT_EQ(sorted(tree.stab(x)), brute_stab(live, ids, x));
      const Interval r{x - 3, x + 3};
      ASSERT_EQ(sorted(tree.overlap(r)), brute_overlap(live, ids, r));
    }
  }
  ASSERT_EQ(tree.size(), live.size());
  while (!live.empty()) {
    ASSERT_TRUE(tree.erase(live.back(), ids.back()));
    live.pop_back();
    ids.pop_back();
  }
  tree.validate();
  EXPECT_TRUE(tree.empty());
  EXPECT_TRUE(tree.stab(500).empty());
}

TEST(IntervalTree, BulkBuiltTreeTakesUpdates) {
  // build() lays the tree out itself; inserts and erases must keep it a valid treap
  std::mt19937_64 rng(22);
  std::vector<Interval> live = make_intervals(IntervalShape::uniform, 2000, 4);
  std::vector<Id> ids = iota_ids(live.size());
  IntervalTree tree = IntervalTree::build(live);
  tree.validate();
  const auto pool = make_intervals(IntervalShape::nested, 500, 5);
  Id next = live.size();
  for (int step = 0; step < 3000; ++step) {
    if (rng() % 2) {
      const Interval iv = pool[rng() % pool.size()];
      tree.insert(iv, next);
      live.push_back(iv);
      ids.push_back(next++);
    } else if (!live.empty()) {
      const std::size_t i = rng() % live.size();
      ASSERT_TRUE(tree.erase(live[i], ids[i]));
      live.erase(live.begin() + long(i));
      ids.erase(ids.begin() + long(i));
    }
    if (step % 151 == 0) {
      tree.validate();
      const double x = query_value(rng, live);
      ASSERT_EQ(sorted(tree.stab(x)), brute_stab(live, ids, x));
      const Interval r{x - 5, x + 20};
      ASSERT_EQ(sorted(tree.overlap(r)), brute_overlap(live, ids, r));
    }
  }
  tree.validate();
  EXPECT_EQ(tree.size(), live.size());
  const std::vector<Interval> bad = {{0, 1}, {2, 3}, {5, 4}};
  try {
    IntervalTree::build(bad);
    ADD_FAILURE() << "inverted interval accepted";
  } catch (const InvalidGeometry& e) {
    EXPECT_NE(std::string(e.what()).find("interval 2"), std::string::npos) << e.what();
  }
}

TEST(IntervalTree, VisitorStopsEarly) {
  const std::vector<Interval> ivs(50, Interval{0, 10});
  const auto tree = IntervalTree::build(ivs);
  int calls = 0;
  const auto s = tree.stab(5, [&](Id, const Interval&) { return ++calls < 3; });
  EXPECT_EQ(calls, 3);
  EXPECT_EQ(s.results, 3u);
  const auto st = SegmentTree::build(ivs);
  calls = 0;
  st.stab(5, [&](Id, const Interval&) { return ++calls < 4; });
  EXPECT_EQ(calls, 4);
}

TEST(IntervalTree, ClosedEndpoints) {
  const std::vector<Interval> ivs = {{0, 1}, {1, 2}, {2, 2}, {3, 4}};
  const auto it = IntervalTree::build(ivs);
  const auto st = SegmentTree::build(ivs);
  EXPECT_EQ(sorted(it.stab(1)), (std::vector<Id>{0, 1}));
  EXPECT_EQ(sorted(st.stab(1)), (std::vector<Id>{0, 1}));
  EXPECT_EQ(sorted(it.stab(2)), (std::vector<Id>{1, 2}));
  EXPECT_EQ(sorted(st.stab(2)), (std::vector<Id>{1, 2}));
  EXPECT_TRUE(st.stab(2.5).empty());
  EXPECT_TRUE(it.stab(4.0001).empty());
  EXPECT_EQ(sorted(it.overlap({2, 3})), (std::vector<Id>{1, 2, 3}));
}

TEST(IntervalTree, RejectsBadInput) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  IntervalTree tree;
  EXPECT_THROW(tree.insert({2, 1}, 0), InvalidGeometry);
  EXPECT_THROW(tree.insert({nan, 1}, 0), InvalidGeometry);
  EXPECT_THROW(tree.insert({0, inf}, 0), InvalidGeometry);
  EXPECT_THROW(tree.stab(nan), InvalidGeometry);
  EXPECT_THROW(tree.overlap({3, 1}), InvalidGeometry);
  const std::vector<Interval> bad = {{0, 1}, {5, 4}};
  EXPECT_THROW(SegmentTree::build(bad), InvalidGeometry);
  const auto st = SegmentTree::build(std::vector<Interval>{{0, 1}});
  EXPECT_THROW(st.stab(inf), InvalidGeometry);
  EXPECT_TRUE(SegmentTree().stab(1).empty());
  EXPECT_EQ(st.interval(0).hi, 1);
  EXPECT_THROW(st.interval(1), InvalidArgument);  // an id not held: loci's error, not the STL's
}

// The shared churn harness (tests/support/churn.hpp) on intervals.
struct IntervalChurn {
  IntervalTree tree;
  Interval make_item(std::mt19937_64& rng) {
    std::uniform_real_distribution<double> u(0, 1000), len(0, 30);
    const double lo = u(rng);
    return {lo, rng() % 5 == 0 ? lo : lo + len(rng)};
  }
  Interval make_window(std::mt19937_64& rng) { return make_item(rng); }
  bool meets(const Interval& iv, const Interval& w) { return iv.overlaps(w); }
  void insert(const Interval& iv, Id id) { tree.insert(iv, id); }
  bool erase(const Interval& iv, Id id) { return tree.erase(iv, id); }
  std::vector<Id> query(const Interval& w) { return tree.overlap(w); }
  void validate() { tree.validate(); }
  std::size_t size() { return tree.size(); }
};

TEST(IntervalTreeDynamic, SharedChurnHarness) {
  IntervalChurn ops;
  churn_against_brute_force(ops, 83, 4000);
}

}  // namespace
