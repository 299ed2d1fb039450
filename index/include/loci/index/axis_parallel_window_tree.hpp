// AxisParallelWindowTree: windowing for layers made only of horizontal and vertical segments
// (street grids, cadastral lines, rasters turned into outlines, VLSI wiring). It reports every
// segment that meets a closed axis-parallel window; segments along an edge, ending on one, or
// through a corner count.
//
// Method (de Berg, Cheong, van Kreveld and Overmars, "Computational Geometry", 3rd ed.,
// chapters 10.1 and 10.2). A segment meets the window W either with an endpoint in W, or with
// both endpoints outside; in the second case a horizontal segment spans W's whole width, so
// it crosses W's left edge, and a vertical one crosses W's bottom edge. So:
//   1. the 2n endpoints sit in a KdTree and a window query on it reports the first kind,
//      each segment through its first endpoint inside W (as SegmentWindowTree does);
//   2. the horizontal segments sit in a centered interval tree on their x-intervals
//      (Edelsbrunner, 1980): a node takes the median x of its segments' endpoints, keeps the
//      segments whose x-interval contains it and passes those wholly left or right of it to
//      its two subtrees. Instead of the book's two sorted lists, a node keeps its segments in
//      two priority search trees, one on (left end x, y) and one on (right end x, y), so
//      that the vertical query segment {qx} x [y1, y2] is answered on one root-to-leaf path:
//      qx < mid asks the left-end tree for x <= qx and goes left, qx > mid asks the right-end
//      tree for x >= qx and goes right, qx == mid takes every stored segment with y in range
//      and stops. The walk for W's left edge reports the horizontal segments of the second
//      kind, after a filter that drops those with an endpoint in W (already reported);
//   3. the vertical segments sit in the same structure built on (y, x), walked for W's
//      bottom edge.
// A zero-length segment is in neither tree; its endpoint reports it. Everything is decided by
// comparing coordinates, so the answer is exact with no epsilon. The priority search trees of
// all nodes share two flat arrays (each node owns a contiguous run), and the interval tree's
// nodes live in one array addressed by 32-bit indices.
//
// Input must be axis-parallel: any other segment is refused at build() with an
// InvalidGeometry naming it (SegmentWindowTree takes arbitrary segments). Segment i of
// build() is reported with id i; visitors are called as `bool visit(Id id, const
// Segment<2>& s)` and return false to stop.
//
// Invariants (checked by validate()): every node's stored segments contain its mid and lie
// strictly inside the x-range its ancestors leave it; each horizontal (vertical) segment is
// stored once, in both trees of one node of the horizontal (vertical) tree, with its own
// coordinates; the priority search trees are in heap and split order; the endpoint tree holds
// 2n points.
//
// Complexity: build O(n log n); memory O(n), about 230 bytes per segment of which the endpoint
// tree takes half. The crossing part of a query costs O(log^2 n + k); the endpoint part is a
// k-d tree window query, O(sqrt(n) + k) in the worst case (the book's range tree would give
// O(log^2 n + k) at the price of O(n log n) memory).
// Thread-safety: immutable after build; any number of concurrent queries.
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "loci/geom/box.hpp"
#include "loci/geom/error.hpp"
#include "loci/geom/segment.hpp"
#include "loci/index/detail/scratch.hpp"
#include "loci/index/detail/segment_endpoints.hpp"
#include "loci/index/priority_search_tree.hpp"
#include "loci/index/query.hpp"

namespace loci {

namespace detail {

// Centered interval tree over the segments that are horizontal, and not points, in a frame:
// the segments as given when `swap` is false, on (y, x) when it is true.
class CenteredIntervalTree {
 public:
  CenteredIntervalTree() = default;
  CenteredIntervalTree(std::span<const Segment<2>> segs, bool swap);

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
    return nodes_.size() * sizeof(Node) + (by_lo_.size() + by_hi_.size()) * sizeof(PstNode);
  }
  // Throws loci::Error, naming the tree `what`, for the first broken invariant.
  void validate(std::span<const Segment<2>> segs, const std::string& what) const;

 private:
  static constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

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

  std::span<const PstNode> lo_tree(const Node& n) const {
    return std::span<const PstNode>(by_lo_).subspan(n.begin, n.end - n.begin);
  }
  std::span<const PstNode> hi_tree(const Node& n) const {
    return std::span<const PstNode>(by_hi_).subspan(n.begin, n.end - n.begin);
  }
  struct Held {
    double lo, hi, y;  // frame coordinates
    std::uint32_t id;
  };
  // Builds the subtree of `held` (reordered) and returns its root. Recursion depth is the
  // tree height.
  std::uint32_t build_at(std::span<Held> held, std::vector<double>& ends,
                         std::vector<PstNode>& items);

  bool swap_ = false;
  std::vector<Node> nodes_;     // preorder; node 0 is the root when there is one
  std::vector<PstNode> by_lo_;  // per node: (left end x, y), a PstSide::left tree
  std::vector<PstNode> by_hi_;  // per node: (right end x, y), a PstSide::right tree
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
  std::vector<PstNode> items;
  build_at(held, ends, items);
}

inline std::uint32_t CenteredIntervalTree::build_at(std::span<Held> held, std::vector<double>& ends,
                                                    std::vector<PstNode>& items) {
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
  build_pst<PstSide::left>(items, std::span<PstNode>(by_lo_).subspan(begin, n_here));
  items.clear();
  for (auto it = here_begin; it != here_end; ++it)
    items.push_back({{it->hi, it->y}, 0.0, it->id});
  build_pst<PstSide::right>(items, std::span<PstNode>(by_hi_).subspan(begin, n_here));
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
  auto report = [&](const PstNode& e) { return bool(f(std::size_t(e.id))); };
  std::uint32_t v = nodes_.empty() ? kNone : 0;
  while (v != kNone) {
    const Node& n = nodes_[v];
    ++s.nodes_visited;
    if (x < n.mid) {
      if (n.lo_min <= x && !query_pst<PstSide::left>(lo_tree(n), x, y1, y2, stack, s, report))
        return false;
      v = n.left;
    } else if (x > n.mid) {
      if (n.hi_max >= x && !query_pst<PstSide::right>(hi_tree(n), x, y1, y2, stack, s, report))
        return false;
      v = n.right;
    } else {
      // every segment here contains x, and every segment below misses it
      return query_pst<PstSide::left>(lo_tree(n), x, y1, y2, stack, s, report);
    }
  }
  return true;
}

inline void CenteredIntervalTree::validate(std::span<const Segment<2>> segs,
                                           const std::string& what) const {
  const std::string owner = "AxisParallelWindowTree invalid: " + what + ": ";
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
      for (const PstNode* e : {&by_lo_[j], &by_hi_[j]}) {
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
    validate_pst<PstSide::left>(lo_tree(n), owner + "left-end tree" + at + ": ");
    validate_pst<PstSide::right>(hi_tree(n), owner + "right-end tree" + at + ": ");
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

}  // namespace detail

class AxisParallelWindowTree {
 public:
  AxisParallelWindowTree() = default;

  // Segment i gets id i. Throws InvalidGeometry on a NaN or infinite coordinate or a segment
  // that is neither horizontal nor vertical, InvalidArgument for 2^31 - 1 segments or more.
  static AxisParallelWindowTree build(std::span<const Segment<2>> segments) {
    AxisParallelWindowTree t;
    t.ends_ = detail::SegmentEndpoints(
        segments, "AxisParallelWindowTree", [](std::size_t i, const Segment<2>& s) {
          if (s.a[0] != s.b[0] && s.a[1] != s.b[1])
            throw InvalidGeometry("segment " + std::to_string(i) + " is not axis-parallel: " +
                                  to_string(s.a) + " - " + to_string(s.b));
        });
    t.horizontal_ = detail::CenteredIntervalTree(segments, false);
    t.vertical_ = detail::CenteredIntervalTree(segments, true);
    return t;
  }

  std::size_t size() const { return ends_.segments().size(); }
  bool empty() const { return size() == 0; }
  const Segment<2>& segment(Id id) const { return ends_.segment(id); }
  std::size_t memory_bytes() const {
    return ends_.memory_bytes() + horizontal_.memory_bytes() + vertical_.memory_bytes();
  }

  // Calls visit(id, segment) once for every segment meeting the closed window; stops when it
  // returns false. Throws InvalidGeometry on a bad window.
  template <SegmentVisitor Visit>
  QueryStats query(const Box<2>& w, Visit&& visit) const;
  std::vector<Id> query(const Box<2>& w) const {
    std::vector<Id> out;
    query(w, [&](Id id, const Segment<2>&) { return out.push_back(id), true; });
    return out;
  }

  // Throws loci::Error describing the first broken invariant.
  void validate() const {
    ends_.validate("AxisParallelWindowTree");
    horizontal_.validate(ends_.segments(), "horizontal tree");
    vertical_.validate(ends_.segments(), "vertical tree");
  }

 private:
  detail::SegmentEndpoints ends_;            // the segments, and their endpoints in a kd-tree
  detail::CenteredIntervalTree horizontal_;  // walked along the window's left edge
  detail::CenteredIntervalTree vertical_;    // on (y, x): walked along the bottom edge
};

template <SegmentVisitor Visit>
QueryStats AxisParallelWindowTree::query(const Box<2>& w, Visit&& visit) const {
  check_box(w, "query window");
  QueryStats s;
  if (empty()) return s;
  if (!ends_.report_inside(w, s, visit)) return s;

  // The walks also meet segments with an endpoint in W; those were reported above.
  auto crossing = [&](std::size_t i) {
    const Segment<2>& g = ends_.segments()[i];
    if (intersects(w, g.a) || intersects(w, g.b)) return true;
    ++s.results;
    return bool(visit(Id(i), g));
  };
  detail::Scratch<std::uint32_t> scratch;
  if (!horizontal_.stab(w.min[0], w.min[1], w.max[1], *scratch, s, crossing)) return s;
  vertical_.stab(w.min[1], w.min[0], w.max[0], *scratch, s, crossing);
  return s;
}

}  // namespace loci
