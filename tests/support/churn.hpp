// The churn harness of the dynamic structures: a fixed-seed random interleaving of insertions
// (new items, duplicates of live ones), erasures (of live entries, and of absent ones, which
// must report false), updates (erase then insert elsewhere) and window queries, every answer
// compared with a brute-force model of the live entries, validate() and size() checked
// periodically and at the end, after everything was erased again.
//
// `ops` adapts one structure:
//   Item make_item(std::mt19937_64&)          Window make_window(std::mt19937_64&)
//   bool meets(const Item&, const Window&)    void insert(const Item&, Id)
//   bool erase(const Item&, Id)               std::vector<Id> query(const Window&)
//   void validate()                           std::size_t size()
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include "loci/index/query.hpp"
#include "support/random_data.hpp"

namespace loci::test {

template <class Ops>
void churn_against_brute_force(Ops& ops, std::uint64_t seed, std::size_t steps) {
  using Item = decltype(ops.make_item(std::declval<std::mt19937_64&>()));
  std::mt19937_64 rng(seed);
  std::vector<std::pair<Item, Id>> live;
  Id next_id = 0;
  auto check = [&](std::size_t step) {
    ops.validate();
    ASSERT_EQ(ops.size(), live.size()) << "step " << step;
  };
  for (std::size_t step = 0; step < steps; ++step) {
    const unsigned op = unsigned(rng() % 10);
    if (op < 5 || live.empty()) {  // insert, a duplicate of a live item one time in four
      const Item item =
          !live.empty() && rng() % 4 == 0 ? live[rng() % live.size()].first : ops.make_item(rng);
      ops.insert(item, next_id);
      live.push_back({item, next_id++});
    } else if (op < 7) {  // erase a live entry
      const std::size_t k = rng() % live.size();
      ASSERT_TRUE(ops.erase(live[k].first, live[k].second)) << "step " << step;
      live[k] = live.back();
      live.pop_back();
    } else if (op == 7) {  // erase an entry that is not there: right item, wrong id
      const std::size_t k = rng() % live.size();
      ASSERT_FALSE(ops.erase(live[k].first, next_id + 1)) << "step " << step;
    } else if (op == 8) {  // update: the same id moves
      const std::size_t k = rng() % live.size();
      ASSERT_TRUE(ops.erase(live[k].first, live[k].second)) << "step " << step;
      live[k].first = ops.make_item(rng);
      ops.insert(live[k].first, live[k].second);
    } else {  // a window query against the model
      const auto w = ops.make_window(rng);
      std::vector<Id> ref;
      for (const auto& [item, id] : live)
        if (ops.meets(item, w)) ref.push_back(id);
      std::vector<Id> got = ops.query(w);
      std::sort(ref.begin(), ref.end());
      std::sort(got.begin(), got.end());
      ASSERT_EQ(got, ref) << "step " << step;
    }
    if (step % 97 == 0) check(step);
  }
  check(steps);
  while (!live.empty()) {
    ASSERT_TRUE(ops.erase(live.back().first, live.back().second));
    live.pop_back();
  }
  check(steps + 1);
}

// The adapter of a dynamic point index (KdTree, PrQuadtree): random points and windows.
template <class Tree>
struct PointChurn {
  Tree tree;
  Point<2> make_item(std::mt19937_64& rng) { return random_point<2>(rng); }
  Box<2> make_window(std::mt19937_64& rng) { return random_window<2>(rng); }
  bool meets(const Point<2>& p, const Box<2>& w) { return intersects(w, p); }
  void insert(const Point<2>& p, Id id) { tree.insert(p, id); }
  bool erase(const Point<2>& p, Id id) { return tree.erase(p, id); }
  std::vector<Id> query(const Box<2>& w) { return tree.query(w); }
  void validate() { tree.validate(); }
  std::size_t size() { return tree.size(); }
};

}  // namespace loci::test
