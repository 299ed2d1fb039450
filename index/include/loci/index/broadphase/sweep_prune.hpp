// SweepPrune<D> and IncrementalSweepPrune<D>: sort-and-sweep on one axis ("box pruning").
//
// Every tick the proxies are ordered by the min coordinate of their boxes on one axis, the
// sweep axis. Walking that order, proxy i can only meet the proxies j after it whose min is
// at most i's max on the axis; those are compared on the other axes and the hits reported.
// Each pair is found once, from the proxy that comes first (Baraff's sweep and prune, 1992;
// Terdiman, "Box pruning revisited", 2017, for the single-axis, sort-every-frame form).
//
// Axis. The axis is the one along which the box centres vary most: the fewer boxes share a
// stretch of that axis, the shorter the runs. SweepPrune picks it afresh each tick.
//
// Sorting. SweepPrune sorts from scratch each tick with an LSD radix sort on the min
// coordinate mapped to a 64-bit key whose unsigned order is the order of the doubles
// (detail::ordered_key). IncrementalSweepPrune keeps the order from the last tick and
// repairs it with insertion sort, which costs O(n + swaps) when boxes move little between
// ticks (coherence); past a budget of swaps it gives up and radix sorts, so a scene that
// jumps costs no more than SweepPrune. It changes axis only when another axis's centre
// variance is well above the current one's (hysteresis: a change costs a full sort).
//
// Sweep. The sorted boxes are gathered into structure-of-arrays with a +inf sentinel after the
// last, so the run of proxy i ends on a comparison instead of a bounds check; the test on the
// other axes is branch-free and writes each candidate into a buffer whose cursor advances by
// the test's result (left-packed output), so the only unpredictable branch is the end of the
// run.
//
// Queries: query(box) scans the proxies (O(n)); a structure answering windows in O(log n)
// is DynamicAabbTree.
//
// Complexity per tick: O(n) for the sort (six radix passes; O(n + swaps) when incremental),
// O(n + runs + k) for the sweep where runs is the number of pairs overlapping on the sweep
// axis. Memory: O(n).
//
// Thread-safety as broad_phase.hpp says.
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>
#include <limits>
#include <vector>

#include "loci/geom/box.hpp"
#include "loci/index/broadphase/broad_phase.hpp"
#include "loci/index/broadphase/detail/pair_tracker.hpp"
#include "loci/index/broadphase/detail/proxy_table.hpp"
#include "loci/index/detail/radix_sort.hpp"

namespace loci {

namespace detail {

// Unsigned key with the order of the double x (negative numbers flipped whole, positive ones
// with the sign bit set): -0.0 sorts just before +0.0, which is harmless as they are equal.
inline std::uint64_t ordered_key(double x) {
  const auto bits = std::bit_cast<std::uint64_t>(x);
  return (bits >> 63) ? ~bits : bits | (std::uint64_t(1) << 63);
}

// Index of the axis along which the centres of the live boxes vary most.
template <int D>
int widest_axis(const ProxyTable<D>& proxies, double* variance = nullptr) {
  double sum[D] = {}, sq[D] = {};
  std::size_t n = 0;
  for (std::uint32_t s = 0; s < proxies.slots(); ++s) {
    if (!proxies.alive(s)) continue;
    const Box<D>& b = proxies.box(s);
    for (int a = 0; a < D; ++a) {
      const double c = 0.5 * (b.min[a] + b.max[a]);
      sum[a] += c;
      sq[a] += c * c;
    }
    ++n;
  }
  int best = 0;
  double best_var = -1;
  for (int a = 0; a < D; ++a) {
    const double mean = n ? sum[a] / double(n) : 0.0;
    const double var = n ? sq[a] / double(n) - mean * mean : 0.0;
    if (variance) variance[a] = var;
    if (var > best_var) best_var = var, best = a;
  }
  return best;
}

}  // namespace detail

template <int D, bool Incremental>
class BasicSweepPrune {
  static_assert(D == 2 || D == 3, "sweep and prune is written for 2 and 3 dimensions");

 public:
  static constexpr int dimension = D;

  void add(Id id, const Box<D>& b) {
    const std::uint32_t s = proxies_.add(id, b, kName);
    if constexpr (Incremental) {
      if (pos_.size() < proxies_.slots()) pos_.resize(proxies_.slots(), kNone);
      pos_[s] = std::uint32_t(order_.size());
      order_.push_back(s);
    }
  }
  void move(Id id, const Box<D>& b) {
    check_box(b, "proxy box");
    proxies_.set_box(proxies_.slot_of(id, kName), b);
  }
  bool remove(Id id) {
    const std::uint32_t s = proxies_.find(id);
    if (s == kNone) return false;
    if constexpr (Incremental) {
      order_[pos_[s]] = kNone;
      pos_[s] = kNone;
      ++holes_;
    }
    proxies_.remove(s);
    return true;
  }
  void clear() {
    proxies_.clear();
    order_.clear();
    pos_.clear();
    holes_ = 0;
    tracker_.reset();
  }

  bool contains(Id id) const { return proxies_.find(id) != kNone; }
  std::size_t size() const { return proxies_.size(); }
  bool empty() const { return size() == 0; }
  // The axis of the last sweep.
  int axis() const { return axis_; }

  template <PairVisitor F>
  QueryStats pairs(F&& visit) {
    sort();
    return sweep(visit);
  }
  std::vector<IdPair> pairs() {
    return collect_pairs([&](auto&& v) { return pairs(v); });
  }

  template <PairVisitor Begin, PairVisitor End>
  QueryStats update(Begin&& begin, End&& end) {
    return tracker_.update([&](auto&& v) { return pairs(v); }, begin, end);
  }

  template <WindowVisitor<D> F>
  QueryStats query(const Box<D>& w, F&& visit) const {
    return proxies_.scan(w, visit);
  }
  std::vector<Id> query(const Box<D>& w) const {
    return collect_ids([&](auto&& v) { return query(w, v); });
  }

  // Throws Error on the first broken invariant: the proxy table, and for the incremental
  // variant that the kept order holds every live slot once.
  void validate() const {
    proxies_.validate(kName);
    if constexpr (Incremental) {
      std::size_t live = 0;
      for (std::size_t p = 0; p < order_.size(); ++p) {
        const std::uint32_t s = order_[p];
        if (s == kNone) continue;
        ++live;
        if (s >= proxies_.slots() || !proxies_.alive(s) || pos_[s] != p)
          throw Error(std::string(kName) + ": sort order and positions disagree");
      }
      if (live != proxies_.size()) throw Error(std::string(kName) + ": sort order misses proxies");
    }
  }

 private:
  static constexpr const char* kName = Incremental ? "IncrementalSweepPrune" : "SweepPrune";

  // Leaves order_ holding the live slots by increasing min on axis_.
  void sort() {
    if constexpr (Incremental) {
      double var[D];
      const int best = detail::widest_axis(proxies_, var);
      const bool switch_axis = best != axis_ && var[best] > 2.0 * var[axis_];
      if (holes_) {
        std::erase(order_, kNone);
        holes_ = 0;
      }
      if (switch_axis || !sorted_once_) {
        axis_ = best;
        radix_order();
      } else if (!insertion_order()) {
        radix_order();
      }
      sorted_once_ = true;
      for (std::uint32_t p = 0; p < order_.size(); ++p)
        pos_[order_[p]] = p;
    } else {
      axis_ = detail::widest_axis(proxies_);
      order_.clear();
      for (std::uint32_t s = 0; s < proxies_.slots(); ++s)
        if (proxies_.alive(s)) order_.push_back(s);
      radix_order();
    }
  }

  // Radix sorts order_ by the min coordinate on axis_.
  void radix_order() {
    keyed_.resize(order_.size());
    for (std::size_t p = 0; p < order_.size(); ++p)
      keyed_[p] = {detail::ordered_key(proxies_.box(order_[p]).min[axis_]), order_[p]};
    detail::radix_sort(keyed_, 64);
    for (std::size_t p = 0; p < order_.size(); ++p)
      order_[p] = keyed_[p].index;
  }

  // Insertion sort of order_ by the current min on axis_; false (order_ still a permutation,
  // partly sorted) when it gives up after a budget of element moves.
  bool insertion_order() {
    const std::size_t n = order_.size();
    key_.resize(n);
    for (std::size_t p = 0; p < n; ++p)
      key_[p] = proxies_.box(order_[p]).min[axis_];
    std::size_t budget = 8 * n + 64;
    for (std::size_t i = 1; i < n; ++i) {
      const double k = key_[i];
      if (!(k < key_[i - 1])) continue;
      const std::uint32_t s = order_[i];
      std::size_t j = i;
      while (j > 0 && k < key_[j - 1]) {
        key_[j] = key_[j - 1];
        order_[j] = order_[j - 1];
        --j;
      }
      key_[j] = k;
      order_[j] = s;
      const std::size_t moved = i - j;
      if (moved > budget) return false;
      budget -= moved;
    }
    return true;
  }

  template <class F>
  QueryStats sweep(F& visit) {
    const std::size_t n = order_.size();
    constexpr int kOther = D - 1;
    lo_.resize(n + 1);
    hi_.resize(n + 1);
    for (int k = 0; k < kOther; ++k) {
      olo_[k].resize(n + 1);
      ohi_[k].resize(n + 1);
    }
    ids_.resize(n + 1);
    hits_.resize(n + 1);
    for (std::size_t p = 0; p < n; ++p) {
      const Box<D>& b = proxies_.box(order_[p]);
      lo_[p] = b.min[axis_];
      hi_[p] = b.max[axis_];
      for (int k = 0, a = 0; a < D; ++a) {
        if (a == axis_) continue;
        olo_[k][p] = b.min[a];
        ohi_[k][p] = b.max[a];
        ++k;
      }
      ids_[p] = proxies_.id(order_[p]);
    }
    lo_[n] = std::numeric_limits<double>::infinity();  // ends every run

    QueryStats st;
    st.nodes_visited = n;
    const double* lo = lo_.data();
    std::uint32_t* hits = hits_.data();
    for (std::size_t i = 0; i < n; ++i) {
      const double end = hi_[i];
      double ilo[kOther > 0 ? kOther : 1], ihi[kOther > 0 ? kOther : 1];
      const double* jlo[kOther > 0 ? kOther : 1];
      const double* jhi[kOther > 0 ? kOther : 1];
      for (int k = 0; k < kOther; ++k) {
        ilo[k] = olo_[k][i], ihi[k] = ohi_[k][i];
        jlo[k] = olo_[k].data(), jhi[k] = ohi_[k].data();
      }
      std::size_t found = 0;
      std::size_t j = i + 1;
      for (; lo[j] <= end; ++j) {
        bool meet = true;
        for (int k = 0; k < kOther; ++k)
          meet &= (jlo[k][j] <= ihi[k]) & (ilo[k] <= jhi[k][j]);
        hits[found] = std::uint32_t(j);
        found += meet;
      }
      st.entries_tested += j - i - 1;
      const Id a = ids_[i];
      for (std::size_t h = 0; h < found; ++h) {
        const Id b = ids_[hits[h]];
        ++st.results;
        if (!(a < b ? visit(a, b) : visit(b, a))) return st;
      }
    }
    return st;
  }

  detail::ProxyTable<D> proxies_;
  detail::PairTracker tracker_;
  int axis_ = 0;                      // sweep axis of the last tick
  bool sorted_once_ = false;          // incremental: order_ has been sorted at least once
  std::vector<std::uint32_t> order_;  // slots by increasing min on axis_ (kNone: a hole)
  std::vector<std::uint32_t> pos_;    // incremental: position of each slot in order_
  std::size_t holes_ = 0;             // incremental: kNone entries in order_
  std::vector<detail::KeyedIndex> keyed_;
  std::vector<double> key_;
  // The sweep's structure-of-arrays, in sorted order, one slot longer for the sentinel.
  std::vector<double> lo_, hi_;
  std::vector<double> olo_[D > 1 ? D - 1 : 1], ohi_[D > 1 ? D - 1 : 1];
  std::vector<Id> ids_;
  std::vector<std::uint32_t> hits_;  // left-packed candidates of one run
};

// Sorts from scratch every tick (radix sort): the choice when boxes move far between ticks.
template <int D>
using SweepPrune = BasicSweepPrune<D, false>;
// Keeps the order between ticks (insertion sort): the choice when boxes move little.
template <int D>
using IncrementalSweepPrune = BasicSweepPrune<D, true>;

static_assert(BroadPhase<SweepPrune<2>>);
static_assert(BroadPhase<SweepPrune<3>>);
static_assert(BroadPhase<IncrementalSweepPrune<2>>);
static_assert(BroadPhase<IncrementalSweepPrune<3>>);

}  // namespace loci
