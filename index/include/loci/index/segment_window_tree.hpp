// SegmentWindowTree: the windowing structure for map segments. Given the segments of a layer,
// it reports every segment that meets an axis-parallel query window, including segments that
// cross the window with no endpoint inside it, with exact predicates (no epsilon anywhere).
//
// Method (de Berg, Cheong, van Kreveld and Overmars, "Computational Geometry", 3rd ed.,
// chapter 10, "Windowing"). A segment meets the closed window W either with an endpoint in W,
// or by crossing W's boundary, and then it meets one of W's four edges. So:
//   1. the 2n endpoints sit in a KdTree and a window query on it reports the first kind;
//   2. an "x-slab tree" answers "which segments meet the vertical query segment {x} x [y1, y2]"
//      for the left and right edges, and the same structure built on swapped coordinates
//      answers it for the bottom and top edges.
// The slab tree is a segment tree on the segments' x-intervals (elementary slots as in
// SegmentTree): a segment stored at a node spans the node's whole x-slab. Within one slab,
// segments that do not cross there are totally ordered from bottom to top, so the ones met by
// the vertical query segment are a contiguous run found by binary search. The book assumes
// non-crossing segments; real layers may cross, so each node's list is split greedily into
// chains in which every segment is verified, exactly, to lie on or above the previous one
// throughout the slab (the two do not intersect, or they only share an endpoint and are not
// collinear). A planar layer gives one chain per node; crossing data gives a few more. The
// binary search and the reporting test use the exact orientation predicate of the query
// point against the segment, so a segment through a window corner or along an edge is found.
// A vertical segment is left out of the x-slab tree (it is found through a bottom or top edge
// or through an endpoint) and a horizontal one out of the swapped tree, symmetrically.
//
// Every segment is reported once: through an endpoint (the first endpoint inside W), else
// through the first edge, in the order left, right, bottom, top, whose slab tree holds it.
// Segment i of build() is reported with id i; visitors are called as
// `bool visit(Id id, const Segment<2>& s)` and return false to stop.
//
// Complexity: O(n log n) memory and build (O(n log^2 n) worst case); a query costs
// O(c log^2 n + k) for k hits and c chains per node (c = 1 for a planar layer).
// Thread-safety: immutable after build; any number of concurrent queries.
#pragma once

#include <algorithm>
#include <bit>
#include <concepts>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "loci/geom/box.hpp"
#include "loci/geom/error.hpp"
#include "loci/geom/segment.hpp"
#include "loci/index/detail/canonical_nodes.hpp"
#include "loci/index/detail/segment_endpoints.hpp"
#include "loci/index/kd_tree.hpp"
#include "loci/index/query.hpp"

namespace loci {

namespace detail {

// Segment tree of x-intervals whose nodes keep their segments in vertically ordered chains.
// Works on the segments as given when `swap` is false, on (y, x) when it is true.
class SlabTree {
 public:
  SlabTree() = default;
  SlabTree(std::span<const Segment<2>> segs, bool swap);

  // Calls f(index) for every stored segment meeting {x} x [y1, y2] (frame coordinates).
  template <class F>
  bool stab(double x, double y1, double y2, F&& f, QueryStats& s) const;

  bool holds(std::size_t i) const { return local_[i].a[0] != local_[i].b[0]; }
  std::size_t memory_bytes() const {
    return local_.size() * sizeof(Segment<2>) + xs_.size() * sizeof(double) +
           (node_chains_.size() + chains_.size() + list_.size()) * sizeof(std::uint32_t);
  }
  void validate() const;

 private:
  std::pair<std::size_t, std::size_t> slots(const Segment<2>& s) const {
    const auto lo = std::lower_bound(xs_.begin(), xs_.end(), s.a[0]) - xs_.begin();
    const auto hi = std::lower_bound(xs_.begin(), xs_.end(), s.b[0]) - xs_.begin();
    return {2 * std::size_t(lo), 2 * std::size_t(hi)};
  }
  std::pair<std::size_t, std::size_t> node_range(std::size_t v) const {
    const int shift = std::countr_zero(leaves_) - (std::bit_width(v) - 1);
    return {(v << shift) - leaves_, ((v + 1) << shift) - leaves_ - 1};
  }
  // Middle x of the slab of slots [first, last].
  double slab_middle(std::size_t first, std::size_t last) const {
    const double lo = xs_[first / 2];
    const double hi = xs_[std::min((last + 1) / 2, xs_.size() - 1)];
    return 0.5 * (lo + hi);
  }
  template <class F>
  void canonical(std::size_t first, std::size_t last, F&& f) const {
    detail::for_each_canonical_node(leaves_, first, last, f);
  }
  // t lies on or below s across every slab both span (exact).
  static bool ordered(const Segment<2>& t, const Segment<2>& s);

  std::vector<Segment<2>> local_;           // frame coordinates, a.x < b.x when held
  std::vector<double> xs_;                  // sorted distinct x of held segments' endpoints
  std::size_t leaves_ = 1;                  // power of two >= slot count
  std::vector<std::uint32_t> node_chains_;  // node v's chains: [node_chains_[v], [v+1])
  std::vector<std::uint32_t> chains_;       // chain c: list_[chains_[c], chains_[c+1])
  std::vector<std::uint32_t> list_;         // segment indices, bottom to top per chain
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
    if (holds(i)) {
      xs_.push_back(s.a[0]);
      xs_.push_back(s.b[0]);
    }
  }
  std::sort(xs_.begin(), xs_.end());
  xs_.erase(std::unique(xs_.begin(), xs_.end()), xs_.end());
  leaves_ = std::bit_ceil(xs_.empty() ? std::size_t(1) : 2 * xs_.size() - 1);
  const std::size_t nodes = 2 * leaves_;

  // canonical lists, compressed rows (count, then fill)
  std::vector<std::uint32_t> offsets(nodes + 1, 0);
  for (std::size_t i = 0; i < local_.size(); ++i) {
    if (!holds(i)) continue;
    const auto [f, l] = slots(local_[i]);
    canonical(f, l, [&](std::size_t v) { ++offsets[v + 1]; });
  }
  for (std::size_t v = 1; v <= nodes; ++v)
    offsets[v] += offsets[v - 1];
  std::vector<std::uint32_t> raw(offsets.back());
  {
    std::vector<std::uint32_t> fill(offsets.begin(), offsets.end() - 1);
    for (std::size_t i = 0; i < local_.size(); ++i) {
      if (!holds(i)) continue;
      const auto [f, l] = slots(local_[i]);
      canonical(f, l, [&](std::size_t v) { raw[fill[v]++] = std::uint32_t(i); });
    }
  }

  // per node: sort by height at the slab's middle, then deal into verified chains
  node_chains_.assign(nodes + 1, 0);
  list_.reserve(raw.size());
  chains_.clear();
  std::vector<std::pair<double, std::uint32_t>> keyed;
  std::vector<std::uint32_t> chain_of, tails, counts;
  constexpr std::size_t kTries = 8;  // chains tried before opening a new one
  for (std::size_t v = 1; v < nodes; ++v) {
    node_chains_[v] = std::uint32_t(chains_.size());
    const std::uint32_t b = offsets[v], e = offsets[v + 1];
    if (b == e) continue;
    const auto [first, last] = node_range(v);
    const double xm = slab_middle(first, last);
    keyed.clear();
    for (std::uint32_t j = b; j < e; ++j) {
      const Segment<2>& s = local_[raw[j]];
      const double t = (xm - s.a[0]) / (s.b[0] - s.a[0]);
      keyed.push_back({s.a[1] + t * (s.b[1] - s.a[1]), raw[j]});
    }
    std::sort(keyed.begin(), keyed.end());
    chain_of.clear();
    tails.clear();
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
    counts.assign(tails.size() + 1, 0);
    for (std::uint32_t c : chain_of)
      ++counts[c + 1];
    for (std::size_t c = 1; c < counts.size(); ++c)
      counts[c] += counts[c - 1];
    const std::size_t base = list_.size();
    for (std::size_t c = 0; c < tails.size(); ++c)
      chains_.push_back(std::uint32_t(base + counts[c]));
    list_.resize(base + keyed.size());
    for (std::size_t j = 0; j < keyed.size(); ++j)
      list_[base + counts[chain_of[j]]++] = keyed[j].second;
  }
  node_chains_[nodes] = std::uint32_t(chains_.size());
  chains_.push_back(std::uint32_t(list_.size()));
}

template <class F>
bool SlabTree::stab(double x, double y1, double y2, F&& f, QueryStats& s) const {
  if (xs_.empty() || x < xs_.front() || x > xs_.back()) return true;
  const auto it = std::lower_bound(xs_.begin(), xs_.end(), x);
  const std::size_t i = std::size_t(it - xs_.begin());
  const std::size_t slot = *it == x ? 2 * i : 2 * i - 1;
  const Point<2> low{x, y1}, high{x, y2};
  for (std::size_t v = leaves_ + slot; v >= 1; v >>= 1) {
    ++s.nodes_visited;
    for (std::uint32_t c = node_chains_[v]; c < node_chains_[v + 1]; ++c) {
      // first segment of the chain not strictly below `low`
      std::uint32_t lo = chains_[c], hi = chains_[c + 1];
      while (lo < hi) {
        const std::uint32_t mid = lo + (hi - lo) / 2;
        const Segment<2>& g = local_[list_[mid]];
        ++s.entries_tested;
        if (orientation(g.a, g.b, low) == Orientation::counterclockwise)
          lo = mid + 1;
        else
          hi = mid;
      }
      for (; lo < chains_[c + 1]; ++lo) {
        const Segment<2>& g = local_[list_[lo]];
        ++s.entries_tested;
        if (orientation(g.a, g.b, high) == Orientation::clockwise) break;  // strictly above
        if (!f(std::size_t(list_[lo]))) return false;
      }
    }
  }
  return true;
}

inline void SlabTree::validate() const {
  auto fail = [](const std::string& what) { throw Error("SegmentWindowTree invalid: " + what); };
  for (std::size_t i = 1; i < xs_.size(); ++i)
    if (!(xs_[i - 1] < xs_[i])) fail("slab coordinates not strictly increasing");
  std::vector<std::size_t> covered(local_.size(), 0);
  for (std::size_t v = 1; v < 2 * leaves_; ++v) {
    const auto [first, last] = node_range(v);
    for (std::uint32_t c = node_chains_[v]; c < node_chains_[v + 1]; ++c) {
      if (chains_[c] >= chains_[c + 1]) fail("empty chain at node " + std::to_string(v));
      for (std::uint32_t j = chains_[c]; j < chains_[c + 1]; ++j) {
        const std::uint32_t i = list_[j];
        if (i >= local_.size() || !holds(i)) fail("bad segment index in a chain");
        const auto [lo, hi] = slots(local_[i]);
        if (first < lo || last > hi) fail("segment stored above its x-range");
        if (v > 1) {
          const auto [pf, pl] = node_range(v / 2);
          if (pf >= lo && pl <= hi) fail("segment stored below a node it spans");
        }
        covered[i] += last - first + 1;
        if (j > chains_[c] && !ordered(local_[list_[j - 1]], local_[i]))
          fail("chain out of vertical order at node " + std::to_string(v));
      }
    }
  }
  for (std::size_t i = 0; i < local_.size(); ++i) {
    if (!holds(i)) continue;
    const auto [lo, hi] = slots(local_[i]);
    if (covered[i] != hi - lo + 1) fail("segment " + std::to_string(i) + " not tiled exactly");
  }
}

}  // namespace detail

class SegmentWindowTree {
 public:
  SegmentWindowTree() = default;

  // Segment i gets id i. Throws InvalidGeometry on a NaN or infinite coordinate.
  static SegmentWindowTree build(std::span<const Segment<2>> segments) {
    SegmentWindowTree t;
    t.ends_ = detail::SegmentEndpoints<KdTree<2>>(segments, "SegmentWindowTree",
                                                  [](std::size_t, auto&) {});
    t.by_x_ = detail::SlabTree(segments, false);
    t.by_y_ = detail::SlabTree(segments, true);
    return t;
  }

  std::size_t size() const { return ends_.segments().size(); }
  bool empty() const { return size() == 0; }
  const Segment<2>& segment(Id id) const { return ends_.segment(id); }
  std::size_t memory_bytes() const {
    return ends_.memory_bytes() + by_x_.memory_bytes() + by_y_.memory_bytes();
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
    ends_.validate("SegmentWindowTree");
    by_x_.validate();
    by_y_.validate();
  }

 private:
  detail::SegmentEndpoints<KdTree<2>> ends_;  // the segments, and their endpoints in a kd-tree
  detail::SlabTree by_x_;                     // for the left and right edges
  detail::SlabTree by_y_;                     // on (y, x): for the bottom and top edges
};

template <SegmentVisitor Visit>
QueryStats SegmentWindowTree::query(const Box<2>& w, Visit&& visit) const {
  check_box(w, "query window");
  QueryStats s;
  if (empty()) return s;
  // 1. segments with an endpoint inside: reported through the first such endpoint
  if (!ends_.report_inside(w, s, visit)) return s;
  const auto segs = ends_.segments();

  // 2. segments crossing the boundary with both endpoints outside, through the first edge
  const Segment<2> left{{w.min[0], w.min[1]}, {w.min[0], w.max[1]}};
  const Segment<2> right{{w.max[0], w.min[1]}, {w.max[0], w.max[1]}};
  const Segment<2> bottom{{w.min[0], w.min[1]}, {w.max[0], w.min[1]}};
  auto outside = [&](const Segment<2>& g) { return !intersects(w, g.a) && !intersects(w, g.b); };
  auto report = [&](std::size_t i) {
    ++s.results;
    return bool(visit(Id(i), segs[i]));
  };
  if (!by_x_.stab(
          w.min[0], w.min[1], w.max[1],
          [&](std::size_t i) { return !outside(segs[i]) || report(i); }, s))
    return s;
  if (!by_x_.stab(
          w.max[0], w.min[1], w.max[1],
          [&](std::size_t i) {
            const Segment<2>& g = segs[i];
            return !outside(g) || intersects(g, left) || report(i);
          },
          s))
    return s;
  // an edge's slab tree may not hold a segment that meets it (axis-parallel ones)
  auto earlier_x = [&](std::size_t i) {
    const Segment<2>& g = segs[i];
    return by_x_.holds(i) && (intersects(g, left) || intersects(g, right));
  };
  if (!by_y_.stab(
          w.min[1], w.min[0], w.max[0],
          [&](std::size_t i) { return !outside(segs[i]) || earlier_x(i) || report(i); }, s))
    return s;
  by_y_.stab(
      w.max[1], w.min[0], w.max[0],
      [&](std::size_t i) {
        return !outside(segs[i]) || earlier_x(i) || intersects(segs[i], bottom) || report(i);
      },
      s);
  return s;
}

}  // namespace loci
