// IntervalTree: a dynamic set of closed 1D intervals answering stabbing queries (every interval
// that contains x) and overlap queries (every interval that meets [a, b]).
//
// Structure. An augmented search tree in the manner of Cormen et al. ("Introduction to
// Algorithms", section 14.3): nodes are ordered by (lo, hi, id) and each node keeps the largest
// hi of its subtree, so a query skips every subtree whose max_hi lies left of the query and,
// thanks to the order on lo, every right subtree once a node starts right of it. Balance comes
// from treap priorities (Seidel and Aragon, "Randomized Search Trees", Algorithmica 1996)
// drawn from a fixed-seed hash of an insertion counter, so the same operations always build
// the same tree. Nodes live in one pool indexed by 32-bit integers with a free list.
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

#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <tuple>
#include <vector>

#include "loci/geom/error.hpp"
#include "loci/index/detail/interval.hpp"
#include "loci/index/detail/scratch.hpp"
#include "loci/index/query.hpp"

namespace loci {

class IntervalTree {
 public:
  IntervalTree() = default;

  // Builds from intervals; interval i gets id i. Throws InvalidGeometry on a bad interval.
  static IntervalTree build(std::span<const Interval> intervals) {
    IntervalTree t;
    t.nodes_.reserve(intervals.size());
    for (std::size_t i = 0; i < intervals.size(); ++i)
      t.insert(intervals[i], Id(i));
    return t;
  }

  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }

  // Throws InvalidGeometry on a NaN, infinite or inverted interval.
  void insert(const Interval& iv, Id id) {
    check_interval(iv);
    if (nodes_.size() >= kNil - 1 && free_ == kNil)
      throw InvalidArgument("IntervalTree holds at most 2^32 - 2 intervals");
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
    root_ = free_ = kNil;
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
    std::vector<Id> out;
    stab(x, [&](Id id, const Interval&) { return out.push_back(id), true; });
    return out;
  }

  // Calls visit(id, interval) for every interval meeting the closed range q.
  // Throws InvalidGeometry on a bad range.
  template <IntervalVisitor Visit>
  QueryStats overlap(const Interval& q, Visit&& visit) const {
    check_interval(q, "query range");
    return walk(q.lo, q.hi, visit);
  }
  std::vector<Id> overlap(const Interval& q) const {
    std::vector<Id> out;
    overlap(q, [&](Id id, const Interval&) { return out.push_back(id), true; });
    return out;
  }

  // Throws loci::Error describing the first broken invariant.
  void validate() const;

 private:
  static constexpr std::uint32_t kNil = std::numeric_limits<std::uint32_t>::max();

  struct Node {
    Interval iv;
    double max_hi;
    Id id;
    std::uint32_t left;  // also the next free node while on the free list
    std::uint32_t right;
    std::uint32_t prio;
  };

  static bool key_less(const Interval& a, Id ia, const Interval& b, Id ib) {
    return std::tie(a.lo, a.hi, ia) < std::tie(b.lo, b.hi, ib);
  }

  std::uint32_t allocate(const Interval& iv, Id id) {
    // splitmix64 of a counter: reproducible priorities without a generator object
    std::uint64_t z = (++inserted_) * 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    const Node node{iv, iv.hi, id, kNil, kNil, std::uint32_t(z >> 32)};
    if (free_ != kNil) {
      const std::uint32_t n = free_;
      free_ = nodes_[n].left;
      nodes_[n] = node;
      return n;
    }
    nodes_.push_back(node);
    return std::uint32_t(nodes_.size() - 1);
  }

  void pull(std::uint32_t n) {
    Node& x = nodes_[n];
    x.max_hi = x.iv.hi;
    if (x.left != kNil) x.max_hi = std::max(x.max_hi, nodes_[x.left].max_hi);
    if (x.right != kNil) x.max_hi = std::max(x.max_hi, nodes_[x.right].max_hi);
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
    if (t == kNil) return n;
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
    if (t == kNil) return kNil;
    Node& x = nodes_[t];
    if (x.iv == iv && x.id == id) {
      found = true;
      const std::uint32_t merged = merge(x.left, x.right);
      x.left = free_;
      free_ = t;
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
    if (a == kNil) return b;
    if (b == kNil) return a;
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
    if (root_ == kNil) return s;
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
      if (x.left != kNil) stack.push_back(x.left);
      // the right subtree starts at or after x.iv.lo
      if (x.right != kNil && x.iv.lo <= b) stack.push_back(x.right);
    }
    return s;
  }

  std::vector<Node> nodes_;
  std::uint32_t root_ = kNil;
  std::uint32_t free_ = kNil;
  std::size_t size_ = 0;
  std::uint64_t inserted_ = 0;
};

inline void IntervalTree::validate() const {
  auto fail = [](const std::string& what) { throw Error("IntervalTree invalid: " + what); };
  std::vector<bool> seen(nodes_.size(), false);
  std::size_t count = 0;
  const Node* prev = nullptr;
  // in-order traversal with an explicit stack
  std::vector<std::uint32_t> stack;
  std::uint32_t cur = root_;
  while (cur != kNil || !stack.empty()) {
    while (cur != kNil) {
      if (cur >= nodes_.size()) fail("child index out of range");
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
      if (c == kNil) continue;
      if (nodes_[c].prio > x.prio) fail("heap order broken at node " + std::to_string(n));
      m = std::max(m, nodes_[c].max_hi);
    }
    if (m != x.max_hi) fail("max_hi wrong at node " + std::to_string(n));
    prev = &x;
    cur = x.right;
  }
  if (count != size_)
    fail("node count " + std::to_string(count) + " != size " + std::to_string(size_));
  std::size_t free_count = 0;
  for (std::uint32_t f = free_; f != kNil; f = nodes_[f].left) {
    if (f >= nodes_.size() || seen[f]) fail("free list corrupt");
    seen[f] = true;
    ++free_count;
  }
  if (count + free_count != nodes_.size()) fail("nodes leaked from the pool");
}

}  // namespace loci
