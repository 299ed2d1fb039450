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
// one array with per-node offsets (compressed rows): detail::SlotTree, shared with SlabTree.
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
#include <utility>
#include <vector>

#include "loci/geom/error.hpp"
#include "loci/index/detail/slot_tree.hpp"
#include "loci/index/query.hpp"

namespace loci {

class SegmentTree {
 public:
  SegmentTree() = default;
  SegmentTree(const SegmentTree&) = default;
  SegmentTree& operator=(const SegmentTree&) = default;
  // Moving leaves `other` empty, as if default-constructed.
  SegmentTree(SegmentTree&& other) noexcept : SegmentTree() { swap(other); }
  SegmentTree& operator=(SegmentTree&& other) noexcept {
    SegmentTree(std::move(other)).swap(*this);
    return *this;
  }

  // Interval i gets id i. Throws InvalidGeometry on a NaN, infinite or inverted interval.
  static SegmentTree build(std::span<const Interval> intervals) {
    if (intervals.size() >= 0xffffffffu)
      throw InvalidArgument("SegmentTree holds at most 2^32 - 2 intervals");
    for (std::size_t i = 0; i < intervals.size(); ++i)
      check_interval(intervals[i], ("interval " + std::to_string(i)).c_str());
    SegmentTree t;
    t.intervals_.assign(intervals.begin(), intervals.end());
    t.slots_ = detail::SlotTree(intervals.size(), t.range());
    return t;
  }

  std::size_t size() const { return intervals_.size(); }
  bool empty() const { return intervals_.empty(); }
  // Throws InvalidArgument for an id the tree does not hold.
  const Interval& interval(Id id) const {
    if (id >= intervals_.size())
      throw InvalidArgument("SegmentTree: no interval with id " + std::to_string(id));
    return intervals_[std::size_t(id)];
  }
  std::size_t memory_bytes() const {
    return intervals_.size() * sizeof(Interval) + slots_.memory_bytes();
  }

  // Calls visit(id, interval) for every interval containing x; stops when it returns false.
  // Throws InvalidGeometry when x is NaN or infinite.
  template <IntervalVisitor Visit>
  QueryStats stab(double x, Visit&& visit) const {
    check_coordinate(x, "stabbing value");
    QueryStats s;
    std::size_t slot = 0;
    if (!slots_.slot_of(x, slot)) return s;
    for (std::size_t v = slots_.leaves() + slot; v >= 1; v >>= 1) {
      ++s.nodes_visited;
      for (const std::uint32_t k : slots_.list(v)) {
        ++s.entries_tested;
        ++s.results;
        if (!visit(Id(k), intervals_[k])) return s;
      }
    }
    return s;
  }
  std::vector<Id> stab(double x) const {
    return collect_ids([&](auto&& v) { return stab(x, v); });
  }

  // Throws loci::Error describing the first broken invariant.
  void validate() const { slots_.validate(intervals_.size(), range(), "SegmentTree"); }

 private:
  // The slot tree's view of the intervals: every one is held.
  struct Range {
    const std::vector<Interval>* intervals;
    bool operator()(std::size_t k, double& lo, double& hi) const {
      lo = (*intervals)[k].lo;
      hi = (*intervals)[k].hi;
      return true;
    }
  };
  Range range() const { return {&intervals_}; }

  void swap(SegmentTree& other) noexcept {
    intervals_.swap(other.intervals_);
    std::swap(slots_, other.slots_);
  }
  std::vector<Interval> intervals_;
  detail::SlotTree slots_;  // the intervals at their canonical nodes
};

static_assert(IntervalIndex<SegmentTree>);

}  // namespace loci
