// SweepPrune<D> and IncrementalSweepPrune<D>: sort-and-sweep on one axis ("box pruning").
//
// Every tick the proxies are ordered by the min coordinate of their boxes on one axis, the
// sweep axis. Walking that order, proxy i can only meet the proxies j after it whose min is
// at most i's max on the axis; those are compared on the other axes and the hits reported.
// Each pair is found once, from the proxy that comes first (Baraff's sweep and prune, 1992;
// Terdiman, "Box pruning revisited", 2017, for the single-axis, sort-every-frame form).
//
// Axis. The sweep axis is the one along which the box centres vary most: the fewer boxes
// share a stretch of that axis, the shorter the runs.
//
// Stripes (SweepPrune, from 4096 proxies on). A single sweep over a square world of n boxes
// makes runs of length ~sqrt(n): every box in the whole height of the world whose min falls
// in a box's extent. So SweepPrune also cuts the second axis (the one of next largest centre
// variance) into stripes about four mean box extents high, enters each box in every stripe it
// touches, and sweeps the stripes one after the other (the bucketed variant of Terdiman's
// "multi box pruning"). A pair sharing several stripes is reported only from the stripe that
// holds the larger of the two boxes' mins on the stripe axis: the one where either box starts.
//
// Sorting. SweepPrune radix sorts (detail::radix_sort, LSD) 64-bit keys each tick: the stripe
// above, below it the box's min on the sweep axis rounded down to a float and mapped to an
// unsigned integer with the same order; four passes for up to 4096 stripes. The rounded key
// only orders the runs (it is <= the true min, so a run never stops early); the tests that
// report a pair are exact, on the doubles. IncrementalSweepPrune keeps one plain sweep's order
// (exact 64-bit keys of the doubles, detail::ordered_key) from the last tick and repairs it
// with insertion sort, which costs O(n + swaps) when boxes move little between ticks
// (coherence); past a budget of swaps it gives up and radix sorts, so a scene that jumps
// costs no more than a fresh sort. It changes axis only when another axis's centre variance
// is well above the current one's (hysteresis: a change costs a full sort). It keeps no
// stripes, so its runs grow as sqrt(n) in a square world.
//
// Sweep. The sorted boxes are gathered into structure-of-arrays, each stripe followed by a
// +inf sentinel, so a run ends on a comparison instead of a bounds check; the test on the
// other axes is branch-free and writes each candidate into a buffer whose cursor advances by
// the test's result (left-packed output), so the only unpredictable branch is the end of the
// run. With SSE2 (every x86-64) a run tests four entries a step.
//
// Callers with data of their own per proxy (find_conflicts keeps each object's motion) use
// entry_pairs: it gives them the sweep's order once, then each entry with its run's hits by
// position in that order, so that their own test of a pair reads neighbouring memory.
//
// Queries: query(box) scans the proxies (O(n)); a structure answering windows in O(log n)
// is DynamicAabbTree.
//
// Complexity per tick: O(n) for the sort (four radix passes; O(n + swaps) when incremental),
// O(n + runs + k) for the sweep where runs is the number of pairs of a stripe overlapping on
// the sweep axis. Memory: O(n) (plus one entry per extra stripe a box touches).
//
// Thread-safety as broad_phase.hpp says.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "loci/geom/box.hpp"
#include "loci/index/broadphase/broad_phase.hpp"
#include "loci/index/broadphase/detail/pair_tracker.hpp"
#include "loci/index/broadphase/detail/proxy_table.hpp"
#include "loci/index/detail/large_alloc.hpp"
#include "loci/index/detail/radix_sort.hpp"

namespace loci {

namespace detail {

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
  // The id of the entries that separate stripes in entry_pairs' order.
  static constexpr Id kSeparator = std::numeric_limits<Id>::max();

  // SweepPrune cuts space into stripes once it holds `striped_from` proxies (see above).
  explicit BasicSweepPrune(std::size_t striped_from = kStripedFrom) : striped_from_(striped_from) {}
  BasicSweepPrune(const BasicSweepPrune&) = default;
  BasicSweepPrune& operator=(const BasicSweepPrune&) = default;
  // Moving leaves `other` empty, keeping its parameters.
  BasicSweepPrune(BasicSweepPrune&& other) noexcept : BasicSweepPrune(other.striped_from_) {
    swap(other);
  }
  BasicSweepPrune& operator=(BasicSweepPrune&& other) noexcept {
    BasicSweepPrune(std::move(other)).swap(*this);
    return *this;
  }

  // Room for n proxies, so that adding them one by one does not move the tables.
  void reserve(std::size_t n) { proxies_.reserve(n); }

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
  // Removes every proxy, as remove() would: the next update() reports their pairs as ended.
  void clear() {
    proxies_.clear();
    order_.clear();
    pos_.clear();
    holes_ = 0;
  }

  bool contains(Id id) const { return proxies_.find(id) != kNone; }
  std::size_t size() const { return proxies_.size(); }
  bool empty() const { return size() == 0; }
  // The axis of the last sweep.
  int axis() const { return axis_; }

  template <PairVisitor F>
  QueryStats pairs(F&& visit) {
    sort_and_gather();
    const Id* ids = ids_.data();
    std::size_t visited = 0;
    auto by_id = [&](std::size_t e, std::span<const std::uint32_t> partners) {
      const Id a = ids[e];
      for (const std::uint32_t f : partners) {
        const Id b = ids[f];
        ++visited;
        if (!(a < b ? visit(a, b) : visit(b, a))) return false;
      }
      return true;
    };
    QueryStats st = sweep(by_id);
    st.results = visited;
    return st;
  }

  // pairs() for a caller that keeps data of its own per proxy in the sweep's order, so that
  // its test of a pair reads neighbouring memory: after sorting, order(ids) is called once
  // with the proxy id of every entry of the sweep in that order (a proxy has an entry in each
  // stripe it spans; the entries that separate stripes hold kSeparator, the largest Id, and
  // are never visited: a proxy with that id looks like one there), then visit(e, partners)
  // for each entry e whose box meets others': partners holds the positions f > e in `ids` of
  // those entries, each pair once over the whole sweep; a visit returning false stops. The
  // stats count as results every partner handed over.
  template <class Order, class F>
  QueryStats entry_pairs(Order&& order, F&& visit) {
    sort_and_gather();
    order(std::span<const Id>(ids_.data(), count_));
    std::size_t handed = 0;
    auto counted = [&](std::size_t e, std::span<const std::uint32_t> partners) {
      handed += partners.size();
      return visit(e, partners);
    };
    QueryStats st = sweep(counted);
    st.results = handed;
    return st;
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
  // Below this many proxies one stripe is best; above, at most this many stripes.
  static constexpr std::size_t kStripedFrom = 4096;
  static constexpr double kMaxStripes = 4096;

  // Sorts the proxies and gathers the sweep's arrays.
  void sort_and_gather() {
    if constexpr (Incremental) {
      sort_incremental();
      begin_gather(order_.size() + 1);  // the entries and one sentinel
      for (const std::uint32_t s : order_)
        gather(s, proxies_.box(s).min[axis_], true);
      gather_sentinel();
    } else {
      sort_striped();
    }
  }

  // Leaves order_ holding the live slots by increasing min on axis_ (incremental).
  void sort_incremental() {
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
  }

  // Radix sorts order_ by the min coordinate on axis_.
  void radix_order() {
    keyed_.resize(order_.size());
    for (std::size_t p = 0; p < order_.size(); ++p)
      keyed_[p] = {detail::ordered_key(proxies_.box(order_[p]).min[axis_]), order_[p]};
    detail::radix_sort(
        keyed_, 0, 64, [](const detail::KeyedIndex& e) { return e.key; }, spare_);
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

  // The stripes of the bucketed sweep: stripe_of(y) for y on stripe_axis_.
  std::uint32_t stripe_of(double y) const {
    // Truncation is the floor of the non-negative values that reach it (no libm call).
    const double k = (y - stripe_origin_) * stripe_inv_;
    if (!(k > 0)) return 0;
    return k < double(stripes_ - 1) ? std::uint32_t(k) : stripes_ - 1;
  }

  // Chooses the sweep axis and the stripes: about four mean box extents high, so that a box
  // is in one or two stripes and a run only meets the boxes of its own stripe.
  void choose_stripes() {
    double var[D];
    axis_ = detail::widest_axis(proxies_, var);
    stripe_axis_ = axis_ == 0 ? 1 : 0;
    for (int a = 0; a < D; ++a)
      if (a != axis_ && var[a] > var[stripe_axis_]) stripe_axis_ = a;
    stripes_ = 1;
    stripe_origin_ = 0;
    stripe_inv_ = 0;
    if (proxies_.size() < striped_from_) return;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo, extent = 0;
    for (std::uint32_t s = 0; s < proxies_.slots(); ++s) {
      if (!proxies_.alive(s)) continue;
      const Box<D>& b = proxies_.box(s);
      lo = std::min(lo, b.min[stripe_axis_]);
      hi = std::max(hi, b.min[stripe_axis_]);
      extent += b.extent(stripe_axis_);
    }
    const double span = hi - lo;
    const double height = std::max(4 * extent / double(proxies_.size()), span / kMaxStripes);
    if (!(height > 0) || !std::isfinite(span / height)) return;
    stripes_ = std::uint32_t(std::clamp(std::ceil(span / height), 1.0, double(kMaxStripes)));
    stripe_origin_ = lo;
    stripe_inv_ = 1.0 / height;
  }

  // Key of x rounded down to a float, in the float order (32 bits): a conservative start
  // for the run, refined by the exact test.
  static std::uint32_t float_key(double x) {
    const auto f = static_cast<float>(x);
    auto bits = std::bit_cast<std::uint32_t>(f);
    // Rounded up: the next float down, one step of the bits away from zero when negative
    // (-0 to the least negative float) and towards it when positive (+inf to the largest).
    // Without a branch: half the values round up, and a branch would mispredict on them.
    const std::uint32_t step = bits >> 31 ? 1 : std::uint32_t(-1);
    bits += step & -std::uint32_t(double(f) > x);
    return (bits >> 31) ? ~bits : bits | 0x80000000u;
  }
  static double from_float_key(std::uint32_t k) {
    const std::uint32_t bits = (k >> 31) ? k & 0x7fffffffu : ~k;
    return double(std::bit_cast<float>(bits));
  }

  // Sorts the (stripe, slot) entries by stripe, then by the min on axis_ (one radix sort on
  // 64-bit keys: stripe above, the float key below) and gathers them.
  void sort_striped() {
    choose_stripes();
    keyed_.clear();
    for (std::uint32_t s = 0; s < proxies_.slots(); ++s) {
      if (!proxies_.alive(s)) continue;
      const Box<D>& b = proxies_.box(s);
      const std::uint64_t k = float_key(b.min[axis_]);
      const std::uint32_t last = stripe_of(b.max[stripe_axis_]);
      for (std::uint32_t t = stripe_of(b.min[stripe_axis_]); t <= last; ++t)
        keyed_.push_back({std::uint64_t(t) << 32 | k, s});
    }
    detail::radix_sort(
        keyed_, 0, 32 + std::bit_width(stripes_ - 1),
        [](const detail::KeyedIndex& e) { return e.key; }, spare_);
    begin_gather(keyed_.size() + stripes_);
    std::uint32_t stripe = 0;
    for (const detail::KeyedIndex& e : keyed_) {
      const std::uint32_t t = std::uint32_t(e.key >> 32);
      if (t != stripe) {
        gather_sentinel();
        stripe = t;
      }
      const Box<D>& b = proxies_.box(e.index);
      gather(e.index, from_float_key(std::uint32_t(e.key)), stripe_of(b.min[stripe_axis_]) == t);
    }
    gather_sentinel();
  }

  // Room for `capacity` entries and sentinels (callers count both), plus three slots past the
  // last sentinel: the sweep reads four entries a step and masks out those past the end (and
  // writes a step's hits four at a time).
  void begin_gather(std::size_t capacity) {
    count_ = 0;
    const std::size_t room = capacity + 3;
    start_.resize(room);
    lo_.resize(room);
    hi_.resize(room);
    for (int k = 0; k < D - 1; ++k) {
      olo_[k].resize(room);
      ohi_[k].resize(room);
    }
    home_.resize(room);
    ids_.resize(room);
    hits_.resize(room);
  }
  // Appends slot s; `start` <= its min on axis_ orders the run, `home` marks the stripe
  // holding the box's min on the stripe axis.
  void gather(std::uint32_t s, double start, bool home) {
    const Box<D>& b = proxies_.box(s);
    start_[count_] = start;
    lo_[count_] = b.min[axis_];
    hi_[count_] = b.max[axis_];
    for (int k = 0, a = 0; a < D; ++a) {
      if (a == axis_) continue;
      olo_[k][count_] = b.min[a];
      ohi_[k][count_] = b.max[a];
      ++k;
    }
    home_[count_] = home ? ~std::uint64_t(0) : 0;
    ids_[count_] = proxies_.id(s);
    ++count_;
  }
  // Ends a stripe: a start of +inf stops every run before it.
  void gather_sentinel() {
    start_[count_] = std::numeric_limits<double>::infinity();
    hi_[count_] = -std::numeric_limits<double>::infinity();
    ids_[count_] = kSeparator;
    ++count_;
  }

  // The runs over the gathered entries, visit(e, partners) by entry positions. A pair met in
  // several stripes is reported from the stripe holding the larger of the two mins on the stripe
  // axis, the one where either box is at home.
  template <class F>
  QueryStats sweep(F& visit) {
    QueryStats st;
    const double* start = start_.data();
    std::uint32_t* hits = hits_.data();
    for (std::size_t i = 0; i < count_; ++i) {
      if (start[i] == std::numeric_limits<double>::infinity()) continue;  // a sentinel
      ++st.nodes_visited;
      std::size_t tested = 0;
      const std::size_t found = run(i, hits, tested);
      st.entries_tested += tested;
      if (found && !visit(i, std::span<const std::uint32_t>(hits, found))) return st;
    }
    return st;
  }

#if defined(__SSE2__)
  // For a mask of four lanes: its prefix of set lanes, its count of set lanes, and the
  // offsets of its set lanes left-packed.
  struct LaneTables {
    std::uint8_t prefix[16], count[16];
    alignas(16) std::int32_t packed[16][4];
  };
  static constexpr LaneTables lane_tables() {
    LaneTables t{};
    for (int m = 0; m < 16; ++m) {
      int p = 0;
      while (p < 4 && (m >> p & 1))
        ++p;
      t.prefix[m] = std::uint8_t((1 << p) - 1);
      int c = 0;
      for (int l = 0; l < 4; ++l)
        if (m >> l & 1) t.packed[m][c++] = l;
      t.count[m] = std::uint8_t(c);
    }
    return t;
  }
  static constexpr LaneTables kLanes = lane_tables();
#endif

  // The run of entry i: writes the positions of the entries after i whose boxes meet its box
  // into hits (left-packed), returns their count, and sets `tested` to the run's length. The
  // run ends at the first entry whose start is beyond i's max on the sweep axis (a sentinel's
  // +inf ends it at the latest); the test of an entry has no branch.
  std::size_t run(std::size_t i, std::uint32_t* hits, std::size_t& tested) const {
    constexpr int kOther = D - 1;
    const double* start = start_.data();
    const double* lo = lo_.data();
    const double* hi = hi_.data();
    const std::uint64_t* home = home_.data();
    std::size_t found = 0;
    std::size_t j = i + 1;
#if defined(__SSE2__)
    // Four entries a step, as two pairs of lanes. Starts never decrease within a stripe, so the
    // entries of a step in the run are a prefix of its lanes; the lanes from a sentinel on
    // (the next stripe, or the slots past the last sentinel) are masked out. The step's hits
    // are written at once, left-packed by a table indexed by their lane mask.
    const __m128d end = _mm_set1_pd(hi[i]), begin = _mm_set1_pd(lo[i]);
    const __m128d at_home = _mm_castsi128_pd(_mm_set1_epi64x(std::int64_t(home[i])));
    __m128d ilo[kOther], ihi[kOther];
    for (int k = 0; k < kOther; ++k)
      ilo[k] = _mm_set1_pd(olo_[k][i]), ihi[k] = _mm_set1_pd(ohi_[k][i]);
    auto meets = [&](std::size_t at) {
      const __m128d jhome =
          _mm_castsi128_pd(_mm_loadu_si128(reinterpret_cast<const __m128i*>(home + at)));
      __m128d meet = _mm_and_pd(_mm_cmple_pd(_mm_loadu_pd(lo + at), end),
                                _mm_cmple_pd(begin, _mm_loadu_pd(hi + at)));
      meet = _mm_and_pd(meet, _mm_or_pd(at_home, jhome));
      for (int k = 0; k < kOther; ++k)
        meet =
            _mm_and_pd(meet, _mm_and_pd(_mm_cmple_pd(_mm_loadu_pd(olo_[k].data() + at), ihi[k]),
                                        _mm_cmple_pd(ilo[k], _mm_loadu_pd(ohi_[k].data() + at))));
      return _mm_movemask_pd(meet);
    };
    for (;; j += 4) {
      const int in = _mm_movemask_pd(_mm_cmple_pd(_mm_loadu_pd(start + j), end)) |
                     _mm_movemask_pd(_mm_cmple_pd(_mm_loadu_pd(start + j + 2), end)) << 2;
      const int lanes = kLanes.prefix[in];
      const int m = (meets(j) | meets(j + 2) << 2) & lanes;
      _mm_storeu_si128(
          reinterpret_cast<__m128i*>(hits + found),
          _mm_add_epi32(_mm_set1_epi32(int(j)),
                        _mm_load_si128(reinterpret_cast<const __m128i*>(kLanes.packed[m]))));
      found += kLanes.count[m];
      if (lanes != 15) {
        j += kLanes.count[lanes];  // the lanes of this step that were in the run
        break;
      }
    }
#else
    const double end = hi[i], begin = lo[i];
    const std::uint64_t at_home = home[i];
    double ilo[kOther], ihi[kOther];
    for (int k = 0; k < kOther; ++k)
      ilo[k] = olo_[k][i], ihi[k] = ohi_[k][i];
    for (; start[j] <= end; ++j) {
      bool meet = (lo[j] <= end) & (begin <= hi[j]) & ((at_home | home[j]) != 0);
      for (int k = 0; k < kOther; ++k)
        meet &= (olo_[k][j] <= ihi[k]) & (ilo[k] <= ohi_[k][j]);
      hits[found] = std::uint32_t(j);
      found += meet;
    }
#endif
    tested = j - i - 1;
    return found;
  }

  void swap(BasicSweepPrune& other) noexcept {
    std::swap(striped_from_, other.striped_from_);
    std::swap(proxies_, other.proxies_);
    std::swap(tracker_, other.tracker_);
    std::swap(axis_, other.axis_);
    std::swap(sorted_once_, other.sorted_once_);
    order_.swap(other.order_);
    pos_.swap(other.pos_);
    std::swap(holes_, other.holes_);
    keyed_.swap(other.keyed_);
    spare_.swap(other.spare_);
    key_.swap(other.key_);
    std::swap(stripe_axis_, other.stripe_axis_);
    std::swap(stripes_, other.stripes_);
    std::swap(stripe_origin_, other.stripe_origin_);
    std::swap(stripe_inv_, other.stripe_inv_);
    std::swap(count_, other.count_);
    start_.swap(other.start_);
    lo_.swap(other.lo_);
    hi_.swap(other.hi_);
    std::swap(olo_, other.olo_);
    std::swap(ohi_, other.ohi_);
    home_.swap(other.home_);
    ids_.swap(other.ids_);
    hits_.swap(other.hits_);
  }
  std::size_t striped_from_ = kStripedFrom;
  detail::ProxyTable<D> proxies_;
  detail::PairTracker tracker_;
  int axis_ = 0;                              // sweep axis of the last tick
  bool sorted_once_ = false;                  // incremental: order_ has been sorted at least once
  detail::LargeVector<std::uint32_t> order_;  // slots by increasing min on axis_ (kNone: a hole)
  std::vector<std::uint32_t> pos_;            // incremental: position of each slot in order_
  std::size_t holes_ = 0;                     // incremental: kNone entries in order_
  detail::LargeVector<detail::KeyedIndex> keyed_;  // sort records (key, slot)
  detail::LargeVector<detail::KeyedIndex> spare_;  // the radix sort's second buffer
  std::vector<double> key_;                        // incremental: min on axis_ in order_
  int stripe_axis_ = 1;                            // the axis cut into stripes
  std::uint32_t stripes_ = 1;                      // stripe count (1: a plain sweep)
  double stripe_origin_ = 0, stripe_inv_ = 0;
  // The sweep's structure-of-arrays in sorted order, stripe after stripe, each stripe
  // followed by a sentinel.
  std::size_t count_ = 0;                // entries and sentinels gathered
  detail::LargeVector<double> start_;    // run order key: <= min on axis_, +inf at a sentinel
  detail::LargeVector<double> lo_, hi_;  // box on axis_
  detail::LargeVector<double> olo_[D - 1], ohi_[D - 1];  // box on the other axes
  detail::LargeVector<std::uint64_t>
      home_;  // all ones in the stripe of the box's min on stripe_axis_
  detail::LargeVector<Id> ids_;
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
