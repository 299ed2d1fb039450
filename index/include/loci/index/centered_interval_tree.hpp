// CenteredIntervalTree: the segments of a layer that are horizontal in a frame (the segments
// as given, or swapped to (y, x) for the vertical ones), answering "which of them meet the
// vertical query segment {x} x [y1, y2]" on one root-to-leaf path.
//
// Method: Edelsbrunner's centered interval tree (1980; de Berg et al., "Computational
// Geometry", 3rd ed., 10.1) on the segments' x-intervals. A node takes the median x of its
// segments' endpoints (`mid`), keeps the segments whose interval contains it and passes those
// wholly left or right of it to its two subtrees. Instead of the book's two sorted lists, a
// node keeps its segments in two priority search trees (detail/pst.hpp, section 10.2), one on
// (left end x, y) and one on (right end x, y): x < mid asks the left-end tree for ends
// <= x with y in [y1, y2] and goes left, x > mid asks the right-end tree for ends >= x and
// goes right, x == mid takes every stored segment with y in range and stops. Zero-length
// segments are not held. Every decision compares coordinates: exact, no epsilon.
//
// Layout: nodes in one array in preorder, addressed by 32-bit indices; the priority search
// trees of all nodes share two flat arrays, each node owning a contiguous run [begin, end).
// Depth O(log n): the median of the 2m ends sends at most m/2 segments to either side.
//
// Invariants (validate()): every node's segments contain its mid and lie strictly inside the
// x-range its ancestors leave it; each held segment is stored once, in both trees of one node,
// with its own coordinates; the runs tile the arrays in preorder; the priority search trees
// are in heap and split order.
//
// Complexity: build O(n log n), memory O(n) (40 bytes a node, 2 x 32 bytes a segment); a stab
// O(log^2 n + k). Used by AxisParallelWindowTree for both of its edges. Thread-safety:
// immutable after construction; any number of concurrent stabs (the caller owns the stack).
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "loci/geom/error.hpp"
#include "loci/geom/segment.hpp"
#include "loci/index/detail/pst.hpp"
#include "loci/index/query.hpp"

namespace loci {

class CenteredIntervalTree {
 public:
  CenteredIntervalTree() = default;
  CenteredIntervalTree(std::span<const Segment<2>> segs, bool swap);
  CenteredIntervalTree(const CenteredIntervalTree&) = default;
  CenteredIntervalTree& operator=(const CenteredIntervalTree&) = default;
  // Moving leaves `other` empty, as if default-constructed.
  CenteredIntervalTree(CenteredIntervalTree&& other) noexcept : CenteredIntervalTree() {
    swap(other);
  }
  CenteredIntervalTree& operator=(CenteredIntervalTree&& other) noexcept {
    CenteredIntervalTree(std::move(other)).swap(*this);
    return *this;
  }

  // s in frame coordinates, its ends ordered by x.
  static Segment<2> frame(const Segment<2>& s, bool swap) {
    Segment<2> f = swap ? Segment<2>{{s.a[1], s.a[0]}, {s.b[1], s.b[0]}} : s;
    if (f.b[0] < f.a[0]) std::swap(f.a, f.b);
    return f;
  }
  static bool holds(const Segment<2>& s, bool swap) {
    const Segment<2> f = frame(s, swap);
    return f.a[1] == f.b[1] && f.a[0] != f.b[0];
  }

  // Calls f(index) for every held segment meeting {x} x [y1, y2] (frame coordinates), once
  // each; returns false as soon as f does.
  template <class F>
  bool stab(double x, double y1, double y2, std::vector<std::uint32_t>& stack, QueryStats& s,
            F&& f) const;

  std::size_t memory_bytes() const {
    return nodes_.size() * sizeof(Node) + (by_lo_.size() + by_hi_.size()) * sizeof(detail::PstNode);
  }
  // Throws loci::Error, its message starting with `what`, for the first broken invariant.
  void validate(std::span<const Segment<2>> segs, const std::string& what) const;

 private:
  // 40 bytes. lo_min and hi_max repeat the roots of the node's two trees so that a walk
  // passes a node whose trees cannot answer without touching them.
  struct Node {
    double mid;           // median x of the endpoints of the segments the node was built from
    double lo_min;        // smallest left end x of the stored segments
    double hi_max;        // largest right end x
    std::uint32_t left;   // segments ending before mid; kNone when there are none
    std::uint32_t right;  // segments starting after mid
    std::uint32_t begin;  // the node's trees: [begin, end) of by_lo_ and of by_hi_
    std::uint32_t end;
  };

  std::span<const detail::PstNode> lo_tree(const Node& n) const {
    return std::span<const detail::PstNode>(by_lo_).subspan(n.begin, n.end - n.begin);
  }
  std::span<const detail::PstNode> hi_tree(const Node& n) const {
    return std::span<const detail::PstNode>(by_hi_).subspan(n.begin, n.end - n.begin);
  }
  struct Held {
    double lo, hi, y;  // frame coordinates
    std::uint32_t id;
  };
  // Builds the subtree of `held` (reordered) and returns its root. Recursion depth is the
  // tree height.
  std::uint32_t build_at(std::span<Held> held, std::vector<double>& ends,
                         std::vector<detail::PstNode>& items);

  void swap(CenteredIntervalTree& other) noexcept {
    std::swap(swap_, other.swap_);
    nodes_.swap(other.nodes_);
    by_lo_.swap(other.by_lo_);
    by_hi_.swap(other.by_hi_);
  }
  bool swap_ = false;
  std::vector<Node> nodes_;             // preorder; node 0 is the root when there is one
  std::vector<detail::PstNode> by_lo_;  // per node: (left end x, y), a detail::PstSide::left tree
  std::vector<detail::PstNode> by_hi_;  // per node: (right end x, y), a detail::PstSide::right tree
};

inline CenteredIntervalTree::CenteredIntervalTree(std::span<const Segment<2>> segs, bool swap)
    : swap_(swap) {
  std::vector<Held> held;
  for (std::size_t i = 0; i < segs.size(); ++i) {
    if (!holds(segs[i], swap)) continue;
    const Segment<2> f = frame(segs[i], swap);
    held.push_back({f.a[0], f.b[0], f.a[1], std::uint32_t(i)});
  }
  // every node stores at least one segment, so there are at most as many nodes as segments
  nodes_.reserve(held.size());
  by_lo_.reserve(held.size());
  by_hi_.reserve(held.size());
  std::vector<double> ends;
  std::vector<detail::PstNode> items;
  build_at(held, ends, items);
}

inline std::uint32_t CenteredIntervalTree::build_at(std::span<Held> held, std::vector<double>& ends,
                                                    std::vector<detail::PstNode>& items) {
  if (held.empty()) return kNone;
  const std::size_t m = held.size();
  ends.clear();
  for (const Held& h : held) {
    ends.push_back(h.lo);
    ends.push_back(h.hi);
  }
  // Rank m of the 2m ends: at most m ends lie below it, so at most m/2 segments go left,
  // fewer go right, and the segment owning it stays here. Depth is O(log n).
  std::nth_element(ends.begin(), ends.begin() + std::ptrdiff_t(m), ends.end());
  const double mid = ends[m];
  const auto here_begin =
      std::partition(held.begin(), held.end(), [&](const Held& h) { return h.hi < mid; });
  const auto here_end =
      std::partition(here_begin, held.end(), [&](const Held& h) { return h.lo <= mid; });
  const std::size_t n_left = std::size_t(here_begin - held.begin());
  const std::size_t n_here = std::size_t(here_end - here_begin);

  const std::uint32_t v = std::uint32_t(nodes_.size());
  const std::uint32_t begin = std::uint32_t(by_lo_.size());
  nodes_.push_back({mid, 0.0, 0.0, kNone, kNone, begin, std::uint32_t(begin + n_here)});
  by_lo_.resize(begin + n_here);
  by_hi_.resize(begin + n_here);
  items.clear();
  for (auto it = here_begin; it != here_end; ++it)
    items.push_back({{it->lo, it->y}, 0.0, it->id});
  detail::build_pst<detail::PstSide::left>(
      items, std::span<detail::PstNode>(by_lo_).subspan(begin, n_here));
  items.clear();
  for (auto it = here_begin; it != here_end; ++it)
    items.push_back({{it->hi, it->y}, 0.0, it->id});
  detail::build_pst<detail::PstSide::right>(
      items, std::span<detail::PstNode>(by_hi_).subspan(begin, n_here));
  nodes_[v].lo_min = by_lo_[begin].p[0];
  nodes_[v].hi_max = by_hi_[begin].p[0];

  const std::uint32_t l = build_at(held.first(n_left), ends, items);
  const std::uint32_t r = build_at(held.subspan(n_left + n_here), ends, items);
  nodes_[v].left = l;
  nodes_[v].right = r;
  return v;
}

template <class F>
bool CenteredIntervalTree::stab(double x, double y1, double y2, std::vector<std::uint32_t>& stack,
                                QueryStats& s, F&& f) const {
  auto report = [&](const detail::PstNode& e) { return bool(f(std::size_t(e.id))); };
  std::uint32_t v = nodes_.empty() ? kNone : 0;
  while (v != kNone) {
    const Node& n = nodes_[v];
    ++s.nodes_visited;
    if (x < n.mid) {
      if (n.lo_min <= x &&
          !detail::query_pst<detail::PstSide::left>(lo_tree(n), x, y1, y2, stack, s, report))
        return false;
      v = n.left;
    } else if (x > n.mid) {
      if (n.hi_max >= x &&
          !detail::query_pst<detail::PstSide::right>(hi_tree(n), x, y1, y2, stack, s, report))
        return false;
      v = n.right;
    } else {
      // every segment here contains x, and every segment below misses it
      return detail::query_pst<detail::PstSide::left>(lo_tree(n), x, y1, y2, stack, s, report);
    }
  }
  return true;
}

inline void CenteredIntervalTree::validate(std::span<const Segment<2>> segs,
                                           const std::string& what) const {
  const std::string owner = what + ": ";
  auto fail = [&](const std::string& msg) { throw Error(owner + msg); };
  if (by_lo_.size() != by_hi_.size()) fail("its two endpoint arrays differ in length");
  std::vector<std::uint8_t> seen_lo(segs.size(), 0), seen_hi(segs.size(), 0);
  std::vector<bool> reached(nodes_.size(), false);
  struct Pending {
    std::uint32_t v;
    double above;  // stored segments must start strictly after this
    double below;  // and end strictly before this
  };
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<Pending> stack;
  if (!nodes_.empty()) stack.push_back({0, -kInf, kInf});
  std::uint32_t expected_begin = 0;
  while (!stack.empty()) {
    const Pending p = stack.back();
    stack.pop_back();
    if (p.v >= nodes_.size() || reached[p.v]) fail("node reached twice or out of range");
    reached[p.v] = true;
    const Node& n = nodes_[p.v];
    const std::string at = " at node " + std::to_string(p.v);
    if (!(p.above < n.mid && n.mid < p.below)) fail("mid outside the range its parent leaves" + at);
    if (n.begin != expected_begin || !(n.begin < n.end) || n.end > by_lo_.size())
      fail("stored runs do not tile the arrays in preorder" + at);
    expected_begin = n.end;
    if (n.lo_min != by_lo_[n.begin].p[0] || n.hi_max != by_hi_[n.begin].p[0])
      fail("lo_min or hi_max differs from the root of its tree" + at);
    for (std::uint32_t j = n.begin; j < n.end; ++j) {
      for (const detail::PstNode* e : {&by_lo_[j], &by_hi_[j]}) {
        if (e->id >= segs.size() || !holds(segs[e->id], swap_))
          fail("stores a foreign segment" + at);
        const Segment<2> s = frame(segs[e->id], swap_);
        if (!(s.a[0] <= n.mid && n.mid <= s.b[0])) fail("segment does not contain mid" + at);
        if (!(p.above < s.a[0] && s.b[0] < p.below))
          fail("segment " + std::to_string(e->id) + " belongs to an ancestor" + at);
        const bool lo_side = e == &by_lo_[j];
        if (!(e->p == (lo_side ? s.a : s.b)))
          fail("segment " + std::to_string(e->id) + " stored with wrong coordinates" + at);
        ++(lo_side ? seen_lo : seen_hi)[e->id];
      }
    }
    detail::validate_pst<detail::PstSide::left>(lo_tree(n), owner + "left-end tree" + at + ": ");
    detail::validate_pst<detail::PstSide::right>(hi_tree(n), owner + "right-end tree" + at + ": ");
    // right pushed first so that the left subtree, next in preorder, is checked next
    if (n.right != kNone) stack.push_back({n.right, n.mid, p.below});
    if (n.left != kNone) stack.push_back({n.left, p.above, n.mid});
  }
  if (expected_begin != by_lo_.size()) fail("stored runs leave entries unowned");
  if (std::count(reached.begin(), reached.end(), false) != 0) fail("unreachable nodes");
  for (std::size_t i = 0; i < segs.size(); ++i) {
    const int want = holds(segs[i], swap_) ? 1 : 0;
    if (seen_lo[i] != want || seen_hi[i] != want)
      fail("segment " + std::to_string(i) + " stored " + std::to_string(seen_lo[i]) + " times");
  }
}

}  // namespace loci
