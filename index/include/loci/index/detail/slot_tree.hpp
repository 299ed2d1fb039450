// SlotTree: the machinery of every segment tree in loci (SegmentTree, SlabTree): elementary
// slots over a set of closed intervals, the implicit complete binary tree over the slots, and
// each item stored at the canonical nodes of its slot range, in per-node lists.
//
// Slots. The sorted distinct endpoints x_0 < ... < x_{m-1} cut the line into 2m - 1
// elementary slots: the points themselves (slot 2i) and the open gaps between them (slot
// 2i + 1); a closed interval with endpoints among the x_i is an exact union of slots.
//
// Tree. The slots are the leaves of a complete binary tree stored implicitly: node 1 is the
// root, node v has children 2v and 2v + 1, slot s is node leaves() + s. The slots [first,
// last] are covered by at most 2 log2(leaves()) disjoint canonical nodes, found by walking both
// ends of the range up one level at a time; an item is stored at exactly those nodes, so the
// nodes on the path from a slot's leaf to the root hold every item covering that slot, each
// once.
//
// Lists. The lists of all nodes live in one array with per-node offsets (compressed rows):
// list(v) is items_[offsets_[v], offsets_[v + 1]). An owner may reorder a node's list in place
// (SlabTree sorts it into vertical chains); validate() does not depend on the order.
//
// Memory: 8 bytes per distinct endpoint, 4 bytes per node offset and 4 per stored item
// (O(n log n) items).
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "loci/geom/error.hpp"

namespace loci::detail {

// Calls f(v) for the canonical nodes of slots [first, last] in a tree of `leaves` leaves.
template <class F>
void for_each_canonical_node(std::size_t leaves, std::size_t first, std::size_t last, F&& f) {
  std::size_t l = first + leaves, r = last + leaves + 1;
  while (l < r) {
    if (l & 1) f(l++);
    if (r & 1) f(--r);
    l >>= 1;
    r >>= 1;
  }
}

class SlotTree {
 public:
  SlotTree() = default;
  SlotTree(const SlotTree&) = default;
  SlotTree& operator=(const SlotTree&) = default;
  // Moving leaves `other` empty, as if default-constructed.
  SlotTree(SlotTree&& other) noexcept : SlotTree() { swap(other); }
  SlotTree& operator=(SlotTree&& other) noexcept {
    SlotTree(std::move(other)).swap(*this);
    return *this;
  }

  // Items 0..n-1; range(k, lo, hi) sets item k's closed interval and returns true, or returns
  // false for an item the tree does not hold. Intervals must be finite with lo <= hi.
  template <class Range>
  SlotTree(std::size_t n, Range&& range) {
    double lo = 0, hi = 0;
    for (std::size_t k = 0; k < n; ++k) {
      if (!range(k, lo, hi)) continue;
      xs_.push_back(lo);
      xs_.push_back(hi);
    }
    std::sort(xs_.begin(), xs_.end());
    xs_.erase(std::unique(xs_.begin(), xs_.end()), xs_.end());
    leaves_ = std::bit_ceil(xs_.empty() ? std::size_t(1) : 2 * xs_.size() - 1);
    offsets_.assign(2 * leaves_ + 1, 0);
    // two passes over the canonical decompositions: count, then fill
    std::vector<std::pair<std::size_t, std::size_t>> ranges(n, {1, 0});
    for (std::size_t k = 0; k < n; ++k) {
      if (!range(k, lo, hi)) continue;
      ranges[k] = slots(lo, hi);
      for_each_canonical_node(leaves_, ranges[k].first, ranges[k].second,
                              [&](std::size_t v) { ++offsets_[v + 1]; });
    }
    for (std::size_t v = 1; v < offsets_.size(); ++v)
      offsets_[v] += offsets_[v - 1];
    items_.resize(offsets_.back());
    std::vector<std::uint32_t> fill(offsets_.begin(), offsets_.end() - 1);
    for (std::size_t k = 0; k < n; ++k)
      if (ranges[k].first <= ranges[k].second)
        for_each_canonical_node(leaves_, ranges[k].first, ranges[k].second,
                                [&](std::size_t v) { items_[fill[v]++] = std::uint32_t(k); });
  }

  std::span<const double> coordinates() const { return xs_; }
  // False for a default-constructed (or moved-from) tree, which holds no list.
  bool built() const { return !offsets_.empty(); }
  std::size_t leaves() const { return leaves_; }
  std::size_t nodes() const { return 2 * leaves_; }  // node indices run from 1 to nodes() - 1
  std::size_t memory_bytes() const {
    return xs_.size() * sizeof(double) + (offsets_.size() + items_.size()) * sizeof(std::uint32_t);
  }

  // The slot range [first, last] of the interval [lo, hi], whose ends are endpoints.
  std::pair<std::size_t, std::size_t> slots(double lo, double hi) const {
    const auto a = std::lower_bound(xs_.begin(), xs_.end(), lo) - xs_.begin();
    const auto b = std::lower_bound(xs_.begin(), xs_.end(), hi) - xs_.begin();
    return {2 * std::size_t(a), 2 * std::size_t(b)};
  }
  // The slot of x; false when x lies outside every stored interval's endpoints.
  bool slot_of(double x, std::size_t& slot) const {
    if (xs_.empty() || x < xs_.front() || x > xs_.back()) return false;
    const auto it = std::lower_bound(xs_.begin(), xs_.end(), x);
    const std::size_t i = std::size_t(it - xs_.begin());
    slot = *it == x ? 2 * i : 2 * i - 1;
    return true;
  }
  // The slot range [first, last] that node v covers.
  std::pair<std::size_t, std::size_t> node_range(std::size_t v) const {
    const int shift = std::countr_zero(leaves_) - (std::bit_width(v) - 1);
    return {(v << shift) - leaves_, ((v + 1) << shift) - leaves_ - 1};
  }
  // The x-interval of node v's slab, for an owner that orders what it stores there.
  double slab_middle(std::size_t v) const {
    const auto [first, last] = node_range(v);
    const double lo = xs_[first / 2];
    const double hi = xs_[std::min((last + 1) / 2, xs_.size() - 1)];
    return 0.5 * (lo + hi);
  }

  // The items stored at node v.
  std::span<const std::uint32_t> list(std::size_t v) const {
    return {items_.data() + offsets_[v], offsets_[v + 1] - offsets_[v]};
  }
  std::span<std::uint32_t> list(std::size_t v) {
    return {items_.data() + offsets_[v], offsets_[v + 1] - offsets_[v]};
  }

  // Throws loci::Error (message prefixed by `owner`) unless the lists hold every item of
  // range(k, lo, hi) at exactly the canonical nodes of its slots, and nothing else.
  template <class Range>
  void validate(std::size_t n, Range&& range, const std::string& owner) const {
    auto fail = [&](const std::string& what) { throw Error(owner + " invalid: " + what); };
    for (std::size_t i = 1; i < xs_.size(); ++i)
      if (!(xs_[i - 1] < xs_[i])) fail("endpoints not strictly increasing");
    if (offsets_.empty()) {  // never built: holds nothing
      double lo = 0, hi = 0;
      if (!xs_.empty() || !items_.empty() || leaves_ != 1) fail("lists missing");
      for (std::size_t k = 0; k < n; ++k)
        if (range(k, lo, hi)) fail("item " + std::to_string(k) + " not stored");
      return;
    }
    if (!std::has_single_bit(leaves_)) fail("leaf count not a power of two");
    if (offsets_.size() != 2 * leaves_ + 1 || offsets_.back() != items_.size())
      fail("offsets do not match the lists");
    std::vector<std::size_t> covered(n, 0);
    double lo = 0, hi = 0;
    for (std::size_t v = 1; v < 2 * leaves_; ++v) {
      if (offsets_[v] > offsets_[v + 1]) fail("offsets decrease at node " + std::to_string(v));
      const auto [first, last] = node_range(v);
      for (const std::uint32_t k : list(v)) {
        if (k >= n || !range(k, lo, hi)) fail("item index out of range or not held");
        const auto [a, b] = slots(lo, hi);
        if (first < a || last > b)
          fail("item " + std::to_string(k) + " stored above its range at node " +
               std::to_string(v));
        if (v > 1) {
          const auto [pf, pl] = node_range(v / 2);
          if (pf >= a && pl <= b)
            fail("item " + std::to_string(k) + " stored below a node it covers");
        }
        covered[k] += last - first + 1;
      }
    }
    for (std::size_t k = 0; k < n; ++k) {
      if (!range(k, lo, hi)) continue;
      const auto [a, b] = slots(lo, hi);
      if (covered[k] != b - a + 1) fail("item " + std::to_string(k) + " not tiled exactly");
    }
  }

 private:
  void swap(SlotTree& other) noexcept {
    xs_.swap(other.xs_);
    std::swap(leaves_, other.leaves_);
    offsets_.swap(other.offsets_);
    items_.swap(other.items_);
  }

  std::vector<double> xs_;              // sorted distinct endpoints
  std::size_t leaves_ = 1;              // power of two >= number of slots
  std::vector<std::uint32_t> offsets_;  // node v's list: items_[offsets_[v], offsets_[v + 1])
  std::vector<std::uint32_t> items_;    // item indices
};

}  // namespace loci::detail
