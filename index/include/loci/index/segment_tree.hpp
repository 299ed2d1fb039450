// SegmentTree: a static set of closed 1D intervals answering stabbing queries (every interval
// containing x), after Bentley's segment tree (1977; de Berg et al., "Computational Geometry",
// chapter 10.3).
//
// Structure. The sorted distinct endpoints p_0 < ... < p_{m-1} cut the line into 2m - 1
// elementary slots: the points themselves (slot 2i) and the open gaps between them (slot
// 2i + 1); closed intervals are exact unions of slots. The slots are the leaves of a complete
// binary tree stored implicitly (node 1 is the root, node v has children 2v and 2v + 1, leaf
// slot s is node L + s), and every interval is stored in the O(log n) canonical nodes whose
// slot ranges tile its own, found by the usual bottom-up sweep. The lists of all nodes live in
// one array with per-node offsets (compressed rows), so the whole tree is three flat vectors.
// A stabbing query finds x's slot by binary search and reports the list of every node on the
// leaf-to-root path, each interval exactly once. Interval i of build() is reported with id i.
//
// Compared with IntervalTree: faster stabbing (no pruning tests, every node visited is
// output) at the price of O(n log n) memory and no updates.
//
// Invariants (checked by validate()): endpoints strictly increasing; each stored interval
// covers its node's slot range and not its parent's; the nodes holding an interval tile its
// slot range exactly.
//
// Complexity: build O(n log n); stabbing O(log n + hits). Thread-safety: immutable after
// build, any number of concurrent queries.
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "loci/geom/error.hpp"
#include "loci/index/detail/canonical_nodes.hpp"
#include "loci/index/query.hpp"

namespace loci {

class SegmentTree {
 public:
  SegmentTree() = default;

  // Interval i gets id i. Throws InvalidGeometry on a NaN, infinite or inverted interval.
  static SegmentTree build(std::span<const Interval> intervals);

  std::size_t size() const { return intervals_.size(); }
  bool empty() const { return intervals_.empty(); }
  const Interval& interval(Id id) const { return intervals_.at(std::size_t(id)); }
  std::size_t memory_bytes() const {
    return intervals_.size() * sizeof(Interval) + points_.size() * sizeof(double) +
           offsets_.size() * sizeof(std::uint32_t) + lists_.size() * sizeof(std::uint32_t);
  }

  // Calls visit(id, interval) for every interval containing x; stops when it returns false.
  // Throws InvalidGeometry when x is NaN or infinite.
  template <IntervalVisitor Visit>
  QueryStats stab(double x, Visit&& visit) const {
    check_coordinate(x, "stabbing value");
    QueryStats s;
    if (points_.empty() || x < points_.front() || x > points_.back()) return s;
    const auto it = std::lower_bound(points_.begin(), points_.end(), x);
    const std::size_t i = std::size_t(it - points_.begin());
    const std::size_t slot = *it == x ? 2 * i : 2 * i - 1;
    for (std::size_t v = leaves_ + slot; v >= 1; v >>= 1) {
      ++s.nodes_visited;
      for (std::uint32_t e = offsets_[v]; e < offsets_[v + 1]; ++e) {
        const std::uint32_t k = lists_[e];
        ++s.entries_tested;
        ++s.results;
        if (!visit(Id(k), intervals_[k])) return s;
      }
    }
    return s;
  }
  std::vector<Id> stab(double x) const {
    std::vector<Id> out;
    stab(x, [&](Id id, const Interval&) { return out.push_back(id), true; });
    return out;
  }

  // Throws loci::Error describing the first broken invariant.
  void validate() const;

 private:
  // Slot range [first, last] of interval k.
  std::pair<std::size_t, std::size_t> slots(const Interval& iv) const {
    const auto lo = std::lower_bound(points_.begin(), points_.end(), iv.lo) - points_.begin();
    const auto hi = std::lower_bound(points_.begin(), points_.end(), iv.hi) - points_.begin();
    return {2 * std::size_t(lo), 2 * std::size_t(hi)};
  }
  // Calls f(node) for the canonical nodes of slots [first, last].
  template <class F>
  void canonical(std::size_t first, std::size_t last, F&& f) const {
    detail::for_each_canonical_node(leaves_, first, last, f);
  }
  // Slot range [first, last] covered by node v.
  std::pair<std::size_t, std::size_t> node_range(std::size_t v) const {
    const int shift = std::countr_zero(leaves_) - (std::bit_width(v) - 1);
    return {(v << shift) - leaves_, ((v + 1) << shift) - leaves_ - 1};
  }

  std::vector<Interval> intervals_;
  std::vector<double> points_;          // sorted distinct endpoints
  std::size_t leaves_ = 1;              // power of two >= number of slots
  std::vector<std::uint32_t> offsets_;  // node v's list is lists_[offsets_[v], offsets_[v+1])
  std::vector<std::uint32_t> lists_;    // interval indices
};

inline SegmentTree SegmentTree::build(std::span<const Interval> intervals) {
  if (intervals.size() >= 0xffffffffu)
    throw InvalidArgument("SegmentTree holds at most 2^32 - 2 intervals");
  SegmentTree t;
  t.intervals_.assign(intervals.begin(), intervals.end());
  for (std::size_t i = 0; i < intervals.size(); ++i)
    check_interval(intervals[i], ("interval " + std::to_string(i)).c_str());
  t.points_.reserve(2 * intervals.size());
  for (const auto& iv : intervals) {
    t.points_.push_back(iv.lo);
    t.points_.push_back(iv.hi);
  }
  std::sort(t.points_.begin(), t.points_.end());
  t.points_.erase(std::unique(t.points_.begin(), t.points_.end()), t.points_.end());
  const std::size_t nslots = t.points_.empty() ? 1 : 2 * t.points_.size() - 1;
  t.leaves_ = std::bit_ceil(nslots);
  t.offsets_.assign(2 * t.leaves_ + 1, 0);
  // two passes over the canonical decompositions: count, then fill
  std::vector<std::pair<std::size_t, std::size_t>> ranges(intervals.size());
  for (std::size_t k = 0; k < intervals.size(); ++k) {
    ranges[k] = t.slots(intervals[k]);
    t.canonical(ranges[k].first, ranges[k].second, [&](std::size_t v) { ++t.offsets_[v + 1]; });
  }
  for (std::size_t v = 1; v < t.offsets_.size(); ++v)
    t.offsets_[v] += t.offsets_[v - 1];
  t.lists_.resize(t.offsets_.back());
  std::vector<std::uint32_t> fill(t.offsets_.begin(), t.offsets_.end() - 1);
  for (std::size_t k = 0; k < intervals.size(); ++k)
    t.canonical(ranges[k].first, ranges[k].second,
                [&](std::size_t v) { t.lists_[fill[v]++] = std::uint32_t(k); });
  return t;
}

inline void SegmentTree::validate() const {
  auto fail = [](const std::string& what) { throw Error("SegmentTree invalid: " + what); };
  for (std::size_t i = 1; i < points_.size(); ++i)
    if (!(points_[i - 1] < points_[i])) fail("endpoints not strictly increasing");
  if (!std::has_single_bit(leaves_)) fail("leaf count not a power of two");
  if (offsets_.size() != 2 * leaves_ + 1 || offsets_.back() != lists_.size())
    fail("offsets do not match the lists");
  std::vector<std::size_t> covered(intervals_.size(), 0);
  for (std::size_t v = 1; v < 2 * leaves_; ++v) {
    if (offsets_[v] > offsets_[v + 1]) fail("offsets decrease at node " + std::to_string(v));
    const auto [first, last] = node_range(v);
    for (std::uint32_t e = offsets_[v]; e < offsets_[v + 1]; ++e) {
      const std::uint32_t k = lists_[e];
      if (k >= intervals_.size()) fail("interval index out of range");
      const auto [lo, hi] = slots(intervals_[k]);
      if (first < lo || last > hi)
        fail("interval " + std::to_string(k) + " stored above its range at node " +
             std::to_string(v));
      if (v > 1) {
        const auto [pf, pl] = node_range(v / 2);
        if (pf >= lo && pl <= hi)
          fail("interval " + std::to_string(k) + " stored below a node it covers");
      }
      covered[k] += last - first + 1;
    }
  }
  for (std::size_t k = 0; k < intervals_.size(); ++k) {
    const auto [lo, hi] = slots(intervals_[k]);
    if (covered[k] != hi - lo + 1) fail("interval " + std::to_string(k) + " not tiled exactly");
  }
}

}  // namespace loci
