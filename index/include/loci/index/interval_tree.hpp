// IntervalTree: a dynamic set of closed 1D intervals answering stabbing queries (every interval
// that contains x) and overlap queries (every interval that meets [a, b]).
//
// Structure. An augmented search tree in the manner of Cormen et al. ("Introduction to
// Algorithms", section 14.3): nodes are ordered by (lo, hi, id) and each node keeps the largest
// hi of its subtree, so a query skips every subtree whose max_hi lies left of the query and,
// thanks to the order on lo, every right subtree once a node starts right of it. Balance comes
// from treap priorities (Seidel and Aragon, "Randomized Search Trees", Algorithmica 1996)
// drawn from a fixed-seed hash of an insertion counter, so the same operations always build
// the same tree. Nodes live in one pool indexed by 32-bit integers with a free list. build()
// makes the balanced tree of a whole set at once, in pre-order in the pool, so that the many
// subtrees a query enters are read in memory order rather than scattered by insertion order.
//
// Typical uses: route mileposts (which features cover kilometre 12.3?), time ranges of
// reports (which reports were valid between t1 and t2?).
//
// Invariants (checked by validate()): in-order sequence sorted by (lo, hi, id); every node's
// priority at least its children's; max_hi is the true subtree maximum; the node count equals
// size() and no node is reachable twice.
//
// Complexity: insert and erase O(log n) expected; stabbing and overlap O(log n + hits)
// expected for the pruning on lo, O(min(n, k log n)) in the worst case of the classic
// augmented tree. Memory: 48 bytes per interval.
//
// Thread-safety: const member functions may run concurrently; insert/erase need exclusive
// access.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <limits>
#include <span>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "loci/geom/error.hpp"
#include "loci/index/detail/node_pool.hpp"
#include "loci/index/detail/scratch.hpp"
#include "loci/index/query.hpp"

namespace loci {

class IntervalTree {
 public:
  IntervalTree() = default;
  IntervalTree(const IntervalTree&) = default;
  IntervalTree& operator=(const IntervalTree&) = default;
  // Moving leaves `other` empty, as if default-constructed.
  IntervalTree(IntervalTree&& other) noexcept : IntervalTree() { swap(other); }
  IntervalTree& operator=(IntervalTree&& other) noexcept {
    IntervalTree(std::move(other)).swap(*this);
    return *this;
  }

  // Builds from intervals; interval i gets id i. Throws InvalidGeometry on a bad interval.
  // The tree comes out perfectly balanced and laid out in pre-order (a node, then its left
  // subtree, then its right), so that a query reads memory mostly forwards; treap priorities
  // are drawn as for insertions and handed out shallowest node first, so later insertions
  // and erasures keep it a treap.
  static IntervalTree build(std::span<const Interval> intervals);

  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }

  // Throws InvalidGeometry on a NaN, infinite or inverted interval.
  void insert(const Interval& iv, Id id) {
    check_interval(iv);
    const std::uint32_t n = allocate(iv, id);
    root_ = insert_at(root_, n);
    ++size_;
  }

  // Removes one entry equal to (iv, id); returns false when there is none.
  bool erase(const Interval& iv, Id id) {
    check_interval(iv);
    bool found = false;
    root_ = erase_at(root_, iv, id, found);
    if (found) --size_;
    return found;
  }

  void clear() {
    nodes_.clear();
    root_ = kNone;
    size_ = 0;
  }

  // Calls visit(id, interval) for every interval containing x; stops when it returns false.
  // Throws InvalidGeometry when x is NaN or infinite.
  template <IntervalVisitor Visit>
  QueryStats stab(double x, Visit&& visit) const {
    check_coordinate(x, "stabbing value");
    return walk(x, x, visit);
  }
  std::vector<Id> stab(double x) const {
    return collect_ids([&](auto&& v) { return stab(x, v); });
  }

  // Calls visit(id, interval) for every interval meeting the closed range q.
  // Throws InvalidGeometry on a bad range.
  template <IntervalVisitor Visit>
  QueryStats overlap(const Interval& q, Visit&& visit) const {
    check_interval(q, "query range");
    return walk(q.lo, q.hi, visit);
  }
  std::vector<Id> overlap(const Interval& q) const {
    return collect_ids([&](auto&& v) { return overlap(q, v); });
  }

  // Throws loci::Error describing the first broken invariant.
  void validate() const;

 private:
  struct Node {           // 48 bytes
    Interval iv;          // 16: the entry
    double max_hi;        // 8: largest hi in the subtree, what lets a query skip it
    Id id;                // 8: the entry's id
    std::uint32_t left;   // 4: lower keys; next free node while on the pool's free list
    std::uint32_t right;  // 4: higher keys
    std::uint32_t prio;   // 4: treap priority, at least the children's
  };

  static bool key_less(const Interval& a, Id ia, const Interval& b, Id ib) {
    return std::tie(a.lo, a.hi, ia) < std::tie(b.lo, b.hi, ib);
  }

  // splitmix64 of a counter: reproducible priorities without a generator object
  std::uint32_t next_priority() {
    std::uint64_t z = (++inserted_) * 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return std::uint32_t(z >> 32);
  }

  std::uint32_t allocate(const Interval& iv, Id id) {
    const std::uint32_t n = nodes_.allocate("IntervalTree");
    nodes_[n] = Node{iv, iv.hi, id, kNone, kNone, next_priority()};
    return n;
  }

  void pull(std::uint32_t n) {
    Node& x = nodes_[n];
    x.max_hi = x.iv.hi;
    if (x.left != kNone) x.max_hi = std::max(x.max_hi, nodes_[x.left].max_hi);
    if (x.right != kNone) x.max_hi = std::max(x.max_hi, nodes_[x.right].max_hi);
  }

  std::uint32_t rotate_right(std::uint32_t n) {
    const std::uint32_t l = nodes_[n].left;
    nodes_[n].left = nodes_[l].right;
    nodes_[l].right = n;
    pull(n);
    pull(l);
    return l;
  }
  std::uint32_t rotate_left(std::uint32_t n) {
    const std::uint32_t r = nodes_[n].right;
    nodes_[n].right = nodes_[r].left;
    nodes_[r].left = n;
    pull(n);
    pull(r);
    return r;
  }

  // Recursion depth is the tree height, O(log n) expected.
  std::uint32_t insert_at(std::uint32_t t, std::uint32_t n) {
    if (t == kNone) return n;
    const Node& x = nodes_[n];
    if (key_less(x.iv, x.id, nodes_[t].iv, nodes_[t].id)) {
      const std::uint32_t l = insert_at(nodes_[t].left, n);
      nodes_[t].left = l;
      pull(t);
      if (nodes_[l].prio > nodes_[t].prio) t = rotate_right(t);
    } else {
      const std::uint32_t r = insert_at(nodes_[t].right, n);
      nodes_[t].right = r;
      pull(t);
      if (nodes_[r].prio > nodes_[t].prio) t = rotate_left(t);
    }
    return t;
  }

  std::uint32_t erase_at(std::uint32_t t, const Interval& iv, Id id, bool& found) {
    if (t == kNone) return kNone;
    Node& x = nodes_[t];
    if (x.iv == iv && x.id == id) {
      found = true;
      const std::uint32_t merged = merge(x.left, x.right);
      nodes_.release(t);
      return merged;
    }
    if (key_less(iv, id, x.iv, x.id))
      nodes_[t].left = erase_at(nodes_[t].left, iv, id, found);
    else
      nodes_[t].right = erase_at(nodes_[t].right, iv, id, found);
    if (found) pull(t);
    return t;
  }

  // Joins two treaps whose keys are ordered a < b.
  std::uint32_t merge(std::uint32_t a, std::uint32_t b) {
    if (a == kNone) return b;
    if (b == kNone) return a;
    if (nodes_[a].prio > nodes_[b].prio) {
      nodes_[a].right = merge(nodes_[a].right, b);
      pull(a);
      return a;
    }
    nodes_[b].left = merge(a, nodes_[b].left);
    pull(b);
    return b;
  }

  // Reports every interval meeting [a, b] (a == b for stabbing).
  template <class Visit>
  QueryStats walk(double a, double b, Visit& visit) const {
    QueryStats s;
    if (root_ == kNone) return s;
    detail::Scratch<std::uint32_t> scratch;
    auto& stack = *scratch;
    stack.push_back(root_);
    while (!stack.empty()) {
      const Node& x = nodes_[stack.back()];
      stack.pop_back();
      ++s.nodes_visited;
      ++s.entries_tested;
      if (x.max_hi < a) continue;  // nothing below reaches the query
      if (x.iv.lo <= b && a <= x.iv.hi) {
        ++s.results;
        if (!visit(x.id, x.iv)) return s;
      }
      // the right subtree starts at or after x.iv.lo; the left one is taken first, as laid
      // out by build()
      if (x.right != kNone && x.iv.lo <= b) stack.push_back(x.right);
      if (x.left != kNone) stack.push_back(x.left);
    }
    return s;
  }

  void swap(IntervalTree& other) noexcept {
    nodes_.swap(other.nodes_);
    std::swap(root_, other.root_);
    std::swap(size_, other.size_);
    std::swap(inserted_, other.inserted_);
  }
  detail::NodePool<Node, &Node::left> nodes_;
  std::uint32_t root_ = kNone;
  std::size_t size_ = 0;
  std::uint64_t inserted_ = 0;
};

inline IntervalTree IntervalTree::build(std::span<const Interval> intervals) {
  if (intervals.size() >= kNone - 1)
    throw InvalidArgument("IntervalTree holds at most 2^32 - 2 intervals");
  for (std::size_t i = 0; i < intervals.size(); ++i)
    check_interval(intervals[i], ("interval " + std::to_string(i)).c_str());
  const std::size_t n = intervals.size();
  std::vector<std::uint32_t> order(n);
  for (std::size_t i = 0; i < n; ++i)
    order[i] = std::uint32_t(i);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return key_less(intervals[a], a, intervals[b], b);
  });
  IntervalTree t;
  t.nodes_.reserve(n);
  std::vector<std::uint8_t> depth(n);
  // sorted range [lo, hi) becomes the subtree at the next free slot; recursion depth log2(n)
  auto place = [&](auto& self, std::size_t lo, std::size_t hi, std::uint8_t d) -> std::uint32_t {
    if (lo == hi) return kNone;
    const std::size_t mid = lo + (hi - lo) / 2;
    const std::uint32_t slot = t.nodes_.allocate("IntervalTree"), k = order[mid];
    depth[slot] = d;
    const std::uint32_t left = self(self, lo, mid, std::uint8_t(d + 1));
    const std::uint32_t right = self(self, mid + 1, hi, std::uint8_t(d + 1));
    t.nodes_[slot] = Node{intervals[k], intervals[k].hi, Id(k), left, right, 0};
    t.pull(slot);
    return slot;
  };
  t.root_ = place(place, 0, n, 0);
  t.size_ = n;
  // the largest priorities to the shallowest nodes: a heap, whatever the draws
  std::vector<std::uint32_t> prio(n);
  for (auto& p : prio)
    p = t.next_priority();
  std::sort(prio.begin(), prio.end(), std::greater<>());
  std::vector<std::uint32_t> by_depth(n);
  std::vector<std::size_t> start(65, 0);
  for (std::uint8_t d : depth)
    ++start[d + 1];
  for (std::size_t d = 1; d < start.size(); ++d)
    start[d] += start[d - 1];
  for (std::uint32_t v = 0; v < n; ++v)
    by_depth[start[depth[v]]++] = v;
  for (std::size_t r = 0; r < n; ++r)
    t.nodes_[by_depth[r]].prio = prio[r];
  return t;
}

inline void IntervalTree::validate() const {
  auto fail = [](const std::string& what) { throw Error("IntervalTree invalid: " + what); };
  std::vector<bool> seen(nodes_.size(), false);
  if (!nodes_.validate_free(seen)) fail("free list corrupt");
  std::size_t count = 0;
  const Node* prev = nullptr;
  // in-order traversal with an explicit stack
  std::vector<std::uint32_t> stack;
  std::uint32_t cur = root_;
  while (cur != kNone || !stack.empty()) {
    while (cur != kNone) {
      if (!nodes_.contains(cur)) fail("child index out of range");
      if (seen[cur]) fail("node " + std::to_string(cur) + " reachable twice");
      seen[cur] = true;
      stack.push_back(cur);
      cur = nodes_[cur].left;
    }
    const std::uint32_t n = stack.back();
    stack.pop_back();
    const Node& x = nodes_[n];
    ++count;
    if (!(x.iv.lo <= x.iv.hi)) fail("inverted interval at node " + std::to_string(n));
    if (prev && key_less(x.iv, x.id, prev->iv, prev->id)) fail("in-order sequence not sorted");
    double m = x.iv.hi;
    for (std::uint32_t c : {x.left, x.right}) {
      if (c == kNone) continue;
      if (nodes_[c].prio > x.prio) fail("heap order broken at node " + std::to_string(n));
      m = std::max(m, nodes_[c].max_hi);
    }
    if (m != x.max_hi) fail("max_hi wrong at node " + std::to_string(n));
    prev = &x;
    cur = x.right;
  }
  if (count != size_)
    fail("node count " + std::to_string(count) + " != size " + std::to_string(size_));
  if (count != nodes_.in_use()) fail("nodes leaked from the pool");
}

static_assert(IntervalIndex<IntervalTree>);

}  // namespace loci
