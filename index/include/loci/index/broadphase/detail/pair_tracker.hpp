// PairTracker: the incremental half of the broad-phase contract, written once.
//
// update() collects the current pairs (any order), sorts them and walks the sorted list beside
// the previous tick's: a pair only in the new list began, a pair only in the old one ended.
// Sorting k pairs costs O(k log k) and the walk O(k), with no hash set and no allocation once
// the two lists have grown to their working size.
#pragma once

#include <algorithm>
#include <vector>

#include "loci/index/broadphase/broad_phase.hpp"

namespace loci::detail {

class PairTracker {
 public:
  // pairs(visitor) is the structure's pair report; begin/end get (a, b) with a < b.
  template <class Pairs, class Begin, class End>
  QueryStats update(Pairs&& pairs, Begin&& begin, End&& end) {
    cur_.clear();
    QueryStats st = pairs([&](Id a, Id b) { return cur_.push_back({a, b}), true; });
    std::sort(cur_.begin(), cur_.end());
    st.results = 0;
    bool go = true;
    auto report = [&](auto& visit, const IdPair& p) {
      if (!go) return;
      ++st.results;
      go = visit(p.a, p.b);
    };
    std::size_t i = 0, j = 0;
    while (i < cur_.size() || j < prev_.size()) {
      if (j == prev_.size() || (i < cur_.size() && cur_[i] < prev_[j])) {
        report(begin, cur_[i++]);
      } else if (i == cur_.size() || prev_[j] < cur_[i]) {
        report(end, prev_[j++]);
      } else {
        ++i, ++j;
      }
    }
    prev_.swap(cur_);
    return st;
  }

 private:
  std::vector<IdPair> prev_;  // the pairs at the last update(), sorted
  std::vector<IdPair> cur_;   // scratch for the current pairs
};

}  // namespace loci::detail
