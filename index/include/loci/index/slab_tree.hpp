// SlabTree: the segments of a layer in a segment tree on their x-intervals, each node keeping
// its segments in vertically ordered chains, answering "which segments meet the vertical query
// segment {x} x [y1, y2]" exactly. SegmentWindowTree keeps two (one on (x, y) for the left and
// right window edges, one on (y, x) for the bottom and top edges).
//
// Method (de Berg, Cheong, van Kreveld and Overmars, "Computational Geometry", 3rd ed., 10.3).
// The segment tree is detail::SlotTree (the machinery of SegmentTree): a segment stored at a
// node spans the node's whole x-slab. Within one slab, segments that do not cross there are
// totally ordered from bottom to top, so the ones met by the query are a contiguous run found
// by binary search. The book assumes non-crossing segments; real layers may cross, so each
// node's list is split greedily into chains in which every segment is verified, exactly, to
// lie on or above the previous one throughout the slab (the two do not intersect, or they
// only share an endpoint and are not collinear). A planar layer gives one chain per node;
// crossing data gives a few more. The binary search and the reporting test use the exact
// orientation predicate of the query point against the segment, so a segment through a query
// end or along the query is found. A segment that is vertical in the frame (a.x == b.x) is not
// held: its owner finds it another way.
//
// Layout: the SlotTree's per-node lists, reordered in place into chain order; chains_ holds
// the end of each chain within its node's list, node_chains_ the first chain of each node.
//
// Invariants (validate()): the lists are the canonical decomposition of every held segment's
// x-interval; chains are non-empty, tile their node's list and are in vertical order.
//
// Complexity: O(n log n) memory and build (O(n log^2 n) worst case); a stab costs
// O(c log^2 n + k) for k hits and c chains per node. Thread-safety: immutable after
// construction; any number of concurrent stabs.
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "loci/geom/error.hpp"
#include "loci/geom/predicates.hpp"
#include "loci/geom/segment.hpp"
#include "loci/index/detail/slot_tree.hpp"
#include "loci/index/query.hpp"

namespace loci {

class SlabTree {
 public:
  SlabTree() = default;
  SlabTree(const SlabTree&) = default;
  SlabTree& operator=(const SlabTree&) = default;
  // Moving leaves `other` empty, as if default-constructed.
  SlabTree(SlabTree&& other) noexcept : SlabTree() { swap(other); }
  SlabTree& operator=(SlabTree&& other) noexcept {
    SlabTree(std::move(other)).swap(*this);
    return *this;
  }
  // The segments as given when `swap` is false, on (y, x) when it is true; segment i of the
  // span is item i.
  SlabTree(std::span<const Segment<2>> segs, bool swap);

  // Calls f(i) for every held segment meeting {x} x [y1, y2] (frame coordinates), once each;
  // returns false as soon as f does.
  template <class F>
  bool stab(double x, double y1, double y2, F&& f, QueryStats& s) const;

  bool holds(std::size_t i) const { return local_[i].a[0] != local_[i].b[0]; }
  std::size_t memory_bytes() const {
    return local_.size() * sizeof(Segment<2>) + slots_.memory_bytes() +
           (node_chains_.size() + chains_.size()) * sizeof(std::uint32_t);
  }
  // Throws loci::Error, its message starting with `owner`, for the first broken invariant.
  void validate(const std::string& owner) const;

 private:
  // The slot tree's view of the segments: held ones by their x-interval.
  struct Range {
    const SlabTree* t;
    bool operator()(std::size_t i, double& lo, double& hi) const {
      if (!t->holds(i)) return false;
      lo = t->local_[i].a[0];
      hi = t->local_[i].b[0];
      return true;
    }
  };
  // t lies on or below s across every slab both span (exact).
  static bool ordered(const Segment<2>& t, const Segment<2>& s);
  // Reorders node v's list into chains, appending their ends to chains_.
  void make_chains(std::size_t v);

  void swap(SlabTree& other) noexcept {
    local_.swap(other.local_);
    std::swap(slots_, other.slots_);
    node_chains_.swap(other.node_chains_);
    chains_.swap(other.chains_);
  }
  std::vector<Segment<2>> local_;           // frame coordinates, a.x <= b.x
  detail::SlotTree slots_;                  // held segments at their canonical nodes
  std::vector<std::uint32_t> node_chains_;  // node v's chains: [node_chains_[v], [v + 1])
  std::vector<std::uint32_t> chains_;       // end of each chain within its node's list
};

inline bool SlabTree::ordered(const Segment<2>& t, const Segment<2>& s) {
  if (intersects(t, s)) {
    const bool shared = t.a == s.a || t.a == s.b || t.b == s.a || t.b == s.b;
    if (!shared) return false;
    // distinct lines through a shared endpoint meet only there, at the end of every slab
    // both span
    if (orientation(t.a, t.b, s.a) == Orientation::collinear &&
        orientation(t.a, t.b, s.b) == Orientation::collinear)
      return false;
  }
  // Decide above/below at an endpoint inside the other's x-range; one of the two sides is
  // off the other's line, else the segments would be collinear or intersect elsewhere.
  const Orientation left = s.a[0] >= t.a[0] ? orientation(t.a, t.b, s.a)
                                            : Orientation(-sign(orientation(s.a, s.b, t.a)));
  if (left != Orientation::collinear) return left == Orientation::counterclockwise;
  const Orientation right = s.b[0] <= t.b[0] ? orientation(t.a, t.b, s.b)
                                             : Orientation(-sign(orientation(s.a, s.b, t.b)));
  return right == Orientation::counterclockwise;
}

inline SlabTree::SlabTree(std::span<const Segment<2>> segs, bool swap) {
  local_.resize(segs.size());
  for (std::size_t i = 0; i < segs.size(); ++i) {
    Segment<2> s = segs[i];
    if (swap) s = {{s.a[1], s.a[0]}, {s.b[1], s.b[0]}};
    if (s.b[0] < s.a[0]) std::swap(s.a, s.b);
    local_[i] = s;
  }
  slots_ = detail::SlotTree(local_.size(), Range{this});
  node_chains_.assign(slots_.nodes() + 1, 0);
  for (std::size_t v = 1; v < slots_.nodes(); ++v) {
    node_chains_[v] = std::uint32_t(chains_.size());
    make_chains(v);
  }
  node_chains_[slots_.nodes()] = std::uint32_t(chains_.size());
}

// Sorts the list by height at the slab's middle, then deals it into verified chains: each
// segment joins the most recent of a few chains whose top lies on or below it.
inline void SlabTree::make_chains(std::size_t v) {
  const std::span<std::uint32_t> list = slots_.list(v);
  if (list.empty()) return;
  const double xm = slots_.slab_middle(v);
  std::vector<std::pair<double, std::uint32_t>> keyed;
  keyed.reserve(list.size());
  for (const std::uint32_t i : list) {
    const Segment<2>& s = local_[i];
    const double t = (xm - s.a[0]) / (s.b[0] - s.a[0]);
    keyed.push_back({s.a[1] + t * (s.b[1] - s.a[1]), i});
  }
  std::sort(keyed.begin(), keyed.end());
  constexpr std::size_t kTries = 8;  // chains tried before opening a new one
  std::vector<std::uint32_t> chain_of, tails;
  for (const auto& [key, i] : keyed) {
    std::size_t c = tails.size();
    for (std::size_t k = 0; k < std::min(kTries, tails.size()); ++k) {
      const std::size_t cand = tails.size() - 1 - k;
      if (ordered(local_[tails[cand]], local_[i])) {
        c = cand;
        break;
      }
    }
    if (c == tails.size()) tails.push_back(i);
    tails[c] = i;
    chain_of.push_back(std::uint32_t(c));
  }
  std::vector<std::uint32_t> starts(tails.size() + 1, 0);
  for (std::uint32_t c : chain_of)
    ++starts[c + 1];
  for (std::size_t c = 1; c < starts.size(); ++c)
    starts[c] += starts[c - 1];
  for (std::size_t c = 1; c < starts.size(); ++c)
    chains_.push_back(starts[c]);
  for (std::size_t j = 0; j < keyed.size(); ++j)
    list[starts[chain_of[j]]++] = keyed[j].second;
}

template <class F>
bool SlabTree::stab(double x, double y1, double y2, F&& f, QueryStats& s) const {
  std::size_t slot = 0;
  if (!slots_.slot_of(x, slot)) return true;
  const Point<2> low{x, y1}, high{x, y2};
  for (std::size_t v = slots_.leaves() + slot; v >= 1; v >>= 1) {
    ++s.nodes_visited;
    const std::span<const std::uint32_t> list = slots_.list(v);
    std::uint32_t begin = 0;
    for (std::uint32_t c = node_chains_[v]; c < node_chains_[v + 1]; ++c) {
      const std::uint32_t end = chains_[c];
      // first segment of the chain not strictly below `low`
      std::uint32_t lo = begin, hi = end;
      while (lo < hi) {
        const std::uint32_t mid = lo + (hi - lo) / 2;
        const Segment<2>& g = local_[list[mid]];
        ++s.entries_tested;
        if (orientation(g.a, g.b, low) == Orientation::counterclockwise)
          lo = mid + 1;
        else
          hi = mid;
      }
      for (; lo < end; ++lo) {
        const Segment<2>& g = local_[list[lo]];
        ++s.entries_tested;
        if (orientation(g.a, g.b, high) == Orientation::clockwise) break;  // strictly above
        if (!f(std::size_t(list[lo]))) return false;
      }
      begin = end;
    }
  }
  return true;
}

inline void SlabTree::validate(const std::string& owner) const {
  auto fail = [&](const std::string& what) { throw Error(owner + " invalid: " + what); };
  slots_.validate(local_.size(), Range{this}, owner);
  if (!slots_.built()) {
    if (!node_chains_.empty() || !chains_.empty()) fail("chains without a tree");
    return;
  }
  if (node_chains_.size() != slots_.nodes() + 1) fail("chain index does not match the tree");
  for (std::size_t v = 1; v < slots_.nodes(); ++v) {
    const std::span<const std::uint32_t> list = slots_.list(v);
    std::uint32_t begin = 0;
    for (std::uint32_t c = node_chains_[v]; c < node_chains_[v + 1]; ++c) {
      if (c >= chains_.size() || chains_[c] <= begin || chains_[c] > list.size())
        fail("empty or overlong chain at node " + std::to_string(v));
      for (std::uint32_t j = begin + 1; j < chains_[c]; ++j)
        if (!ordered(local_[list[j - 1]], local_[list[j]]))
          fail("chain out of vertical order at node " + std::to_string(v));
      begin = chains_[c];
    }
    if (begin != list.size()) fail("chains do not cover the list of node " + std::to_string(v));
  }
}

}  // namespace loci
