// PrQuadtree<D>: the point-region quadtree (D = 2) and octree (D = 3), with one point per leaf
// (bucket = 1, the PR quadtree of Orenstein, 1982) or up to `bucket` points per leaf (the
// bucket PR quadtree; Samet, "Foundations of Multidimensional and Metric Data Structures",
// 2006, section 1.4.2).
//
// Structure. Every node owns a region of space, a box; an internal node cuts it at its centre
// into 2^D equal children (child c takes the upper half on axis a when bit a of c is set, and
// a point on a cut belongs to the upper side). A leaf keeps a list of its points. A leaf is
// split when it holds more than `bucket` points, unless (a) its points all coincide, (b) it
// sits at max_depth, or (c) its region can no longer be halved in double precision; those
// three cases let duplicates and points closer than the precision limit share one leaf
// instead of recursing forever. Within a given region the tree is shaped by the space, not by
// the insertion order: the same set of points always gives the same tree.
//
// Region. A cube (a given box is extended to one), half-open at its upper faces, given at
// construction or taken from the first points, and grown on demand: a point outside the root makes
// the root's region double towards it (the old root becomes one child of the new one), so the tree
// accepts any finite input. A point the region cannot grow to without overflowing is refused
// before anything changes. Without a region given, the root's region comes from the first point
// and the doublings since, so the tree then depends on which points came first.
//
// Layout. Nodes live in one pool indexed by 32-bit integers; the 2^D children of a node are
// consecutive, allocated and freed as a group through a free list. Each node stores its region
// (children's regions are computed once, from their parent's centre, so every node agrees
// with its parent exactly), its subtree's point count and depth. Points live in a second pool
// as singly linked lists, one per leaf. erase() merges a subtree back into a leaf as soon as
// it holds at most `bucket` points.
//
// Queries: window (closed; a node whose region lies inside the window reports its points
// without tests), nearest-n best first through detail::best_first, and visit_cells() for
// drawing the subdivision.
//
// Invariants (checked by validate()): children tile their parent's region exactly; counts add
// up; leaf points lie in the leaf's region; a leaf holds at most `bucket` points unless one of
// (a)-(c) holds; an internal node holds more than `bucket` points; pools have no leaks.
//
// Complexity: insert/erase O(depth); depth is O(log(extent / closest pair)), bounded by
// max_depth. Window and nearest-n as for any region tree. Memory about (32 + 8 * 2 * D) bytes
// per node plus 32 (2D) or 40 (3D) bytes per point.
//
// Thread-safety: const member functions may run concurrently; insert/erase need exclusive
// access.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "loci/geom/box.hpp"
#include "loci/geom/error.hpp"
#include "loci/index/detail/best_first.hpp"
#include "loci/index/detail/hilbert.hpp"
#include "loci/index/detail/node_pool.hpp"
#include "loci/index/detail/scratch.hpp"
#include "loci/index/query.hpp"

namespace loci {

template <int D>
class PrQuadtree {
 public:
  static constexpr int dimension = D;
  static constexpr int fan_out = 1 << D;

  // Points closer than the region's extent / 2^max_depth share a leaf.
  explicit PrQuadtree(std::uint32_t bucket = 1, int max_depth = 48)
      : bucket_(bucket), max_depth_(max_depth) {
    check_parameters();
  }
  // Starts with `region`; it still grows if a point falls outside.
  PrQuadtree(const Box<D>& region, std::uint32_t bucket = 1, int max_depth = 48)
      : bucket_(bucket), max_depth_(max_depth) {
    check_parameters();
    check_box(region, "quadtree region");
    make_root(cube(region));
  }
  PrQuadtree(const PrQuadtree&) = default;
  PrQuadtree& operator=(const PrQuadtree&) = default;
  // Moving leaves `other` empty, keeping its parameters.
  PrQuadtree(PrQuadtree&& other) noexcept : PrQuadtree(other.bucket_, other.max_depth_) {
    swap(other);
  }
  PrQuadtree& operator=(PrQuadtree&& other) noexcept {
    PrQuadtree(std::move(other)).swap(*this);
    return *this;
  }

  // Point i gets id i; the region is the points' bounding box. Throws InvalidGeometry on a NaN
  // or infinite coordinate.
  static PrQuadtree build(std::span<const Point<D>> points, std::uint32_t bucket = 1,
                          int max_depth = 48) {
    Box<D> region = Box<D>::empty();
    for (std::size_t i = 0; i < points.size(); ++i) {
      check_point(points[i], ("point " + std::to_string(i)).c_str());
      region.expand(points[i]);
    }
    for (int a = 0; a < D && !points.empty(); ++a) {  // the root is open at the top
      region.max[a] = std::nextafter(region.max[a], std::numeric_limits<double>::infinity());
      if (std::isinf(region.max[a]))  // a point at the largest double, named as insert does
        for (std::size_t i = 0; i < points.size(); ++i)
          if (points[i][a] == std::numeric_limits<double>::max())
            throw InvalidGeometry("point " + std::to_string(i) +
                                  " too far from the quadtree's region: " + to_string(points[i]));
    }
    PrQuadtree t =
        points.empty() ? PrQuadtree(bucket, max_depth) : PrQuadtree(region, bucket, max_depth);
    t.entries_.reserve(points.size());
    // inserting along a Hilbert curve puts each leaf's entries, and each subtree's nodes,
    // next to each other in the pools: window queries then read memory in order
    std::vector<std::pair<std::uint64_t, std::uint32_t>> order(points.size());
    const detail::HilbertGrid<D> grid(region);
    for (std::size_t i = 0; i < points.size(); ++i)
      order[i] = {grid.key(points[i]), std::uint32_t(i)};
    std::sort(order.begin(), order.end());
    for (const auto& [key, i] : order)
      t.insert(points[i], Id(i));
    return t;
  }

  std::size_t size() const { return nodes_.size() == 0 ? 0 : nodes_[0].count; }
  bool empty() const { return size() == 0; }
  std::uint32_t bucket() const { return bucket_; }
  int max_depth() const { return max_depth_; }
  Box<D> region() const { return nodes_.size() == 0 ? Box<D>::empty() : nodes_[0].region; }
  int height() const;
  std::size_t memory_bytes() const { return nodes_.memory_bytes() + entries_.memory_bytes(); }

  // Throws InvalidGeometry on a NaN or infinite coordinate.
  void insert(const Point<D>& p, Id id);
  // Removes one entry equal to (p, id); returns false when there is none.
  bool erase(const Point<D>& p, Id id);

  // Calls visit(id, box) for each point inside the closed window; stops when it returns false.
  // Throws InvalidGeometry on a bad window.
  template <WindowVisitor<D> Visit>
  QueryStats query(const Box<D>& window, Visit&& visit) const;
  std::vector<Id> query(const Box<D>& window) const {
    return collect_ids([&](auto&& v) { return query(window, v); });
  }

  // Calls visit(id, box, distance) for the k points nearest to p, nearest first.
  // Throws InvalidArgument for k = 0, InvalidGeometry for a bad point.
  template <NearestVisitor<D> Visit>
  QueryStats nearest(const Point<D>& p, std::size_t k, Visit&& visit) const;
  std::vector<Neighbor> nearest(const Point<D>& p, std::size_t k) const {
    return collect_neighbors([&](auto&& v) { return nearest(p, k, v); });
  }

  // Calls visit(id, box, distance) for the points in increasing distance from p, one at a
  // time, until it returns false (distance browsing: nothing is fixed in advance, each answer
  // costs what it takes to find it). Throws InvalidGeometry for a bad point.
  template <NearestVisitor<D> Visit>
  QueryStats browse(const Point<D>& p, Visit&& visit) const;

  // Calls f(region, depth, count, is_leaf) for every node, parents before children: the cells
  // a map draws.
  template <class F>
  void visit_cells(F&& f) const {
    if (nodes_.size() == 0) return;
    std::vector<std::uint32_t> stack{0};
    while (!stack.empty()) {
      const Node& x = nodes_[stack.back()];
      stack.pop_back();
      f(x.region, int(x.depth), std::size_t(x.count), x.leaf());
      if (!x.leaf())
        for (int c = fan_out - 1; c >= 0; --c)
          stack.push_back(x.child + std::uint32_t(c));
    }
  }

  // Throws loci::Error describing the first broken invariant.
  void validate() const;

 private:
  // Runs walk(root, expand, report), detail::best_first or detail::browse, with this
  // tree's expansion around p.
  template <class Visit, class Walk>
  QueryStats walk_nearest(const Point<D>& p, Visit& visit, Walk&& walk) const;
  struct Node {           // 16 D + 16 bytes
    Box<D> region;        // 16 D: the cell; children's are cut from it at its centre
    std::uint32_t child;  // 4: first of fan_out children, kNone for a leaf; pool free link
    std::uint32_t first;  // 4: leaf: head of its entry list
    std::uint32_t count;  // 4: points in the subtree
    std::uint32_t depth;  // 4: 0 at the root
    bool leaf() const { return child == kNone; }
  };
  struct Entry {         // 8 D + 16 bytes
    Point<D> p;          // 8 D: the point
    Id id;               // 8: its id
    std::uint32_t next;  // 4: next entry of the same leaf, or of the pool's free list
  };

  // The root is node 0, the first of a run of fan_out whose other nodes stay unused, so that
  // every later run holds exactly one node's children.
  void make_root(const Box<D>& region) {
    nodes_.allocate("PrQuadtree");
    for (int c = 1; c < fan_out; ++c)
      nodes_[std::uint32_t(c)] = leaf_node(Box<D>::empty(), 0);
    nodes_[0] = leaf_node(region, 0);
  }

  static Node leaf_node(const Box<D>& region, std::uint32_t depth) {
    return Node{region, kNone, kNone, 0, depth};
  }

  void check_parameters() const {
    if (bucket_ < 1) throw InvalidArgument("quadtree bucket size must be >= 1");
    if (max_depth_ < 1 || max_depth_ > 1100)
      throw InvalidArgument("quadtree max_depth must be in [1, 1100]");
  }

  // Which child of internal node x takes p.
  int child_of(const Node& x, const Point<D>& p) const {
    const Node& last = nodes_[x.child + fan_out - 1];  // upper half on every axis
    int c = 0;
    for (int a = 0; a < D; ++a)
      c |= int(p[a] >= last.region.min[a]) << a;
    return c;
  }
  static Box<D> child_region(const Box<D>& r, int c) {
    Box<D> b = r;
    for (int a = 0; a < D; ++a)
      (c >> a & 1 ? b.min[a] : b.max[a]) = r.center(a);
    return b;
  }
  // The root is half-open, [min, max): a point on its upper boundary would be routed away
  // from the old root by the cut that growing upwards puts there.
  bool in_root(const Point<D>& p) const { return in_region(nodes_[0].region, p); }
  static bool in_region(const Box<D>& r, const Point<D>& p) {
    for (int a = 0; a < D; ++a)
      if (!(r.min[a] <= p[a] && p[a] < r.max[a])) return false;
    return true;
  }
  // Cells are cubes, so that no axis of a line of points is left unsplittable.
  static Box<D> cube(Box<D> r) {
    double side = 0;
    for (int a = 0; a < D; ++a)
      side = std::max(side, r.extent(a));
    for (int a = 0; a < D; ++a)  // rounding must not cut off the old maximum
      r.max[a] = std::max(r.max[a], r.min[a] + side);
    return r;
  }
  static bool splittable(const Box<D>& r) {
    for (int a = 0; a < D; ++a) {
      const double m = r.center(a);
      if (!(r.min[a] < m && m < r.max[a])) return false;
    }
    return true;
  }
  bool must_stay_leaf(const Node& x) const;

  void swap(PrQuadtree& other) noexcept {
    std::swap(bucket_, other.bucket_);
    std::swap(max_depth_, other.max_depth_);
    nodes_.swap(other.nodes_);
    entries_.swap(other.entries_);
  }
  std::uint32_t allocate_group() { return nodes_.allocate("PrQuadtree"); }
  std::uint32_t allocate_entry(const Point<D>& p, Id id) {
    const std::uint32_t e = entries_.allocate("PrQuadtree entry");
    entries_[e] = {p, id, kNone};
    return e;
  }
  void grow_towards(const Point<D>& p);
  // One doubling of the root's region towards p (a leaf root is widened to fit p instead);
  // slot gets where the old root goes among the new root's children. False on overflow.
  static bool grow_step(Box<D>& region, bool leaf, const Point<D>& p, int& slot);
  void split(std::uint32_t n);
  // Moves every entry of n's subtree into n's list and frees its descendants.
  void collapse(std::uint32_t n);
  void gather(std::uint32_t n, std::uint32_t& head);

  std::uint32_t bucket_ = 1;
  int max_depth_ = 48;
  detail::NodePool<Node, &Node::child, fan_out> nodes_;  // runs of fan_out siblings
  detail::NodePool<Entry, &Entry::next> entries_;
};

template <int D>
bool PrQuadtree<D>::must_stay_leaf(const Node& x) const {
  if (x.count <= bucket_ || int(x.depth) >= max_depth_ || !splittable(x.region)) return true;
  const Point<D>& p0 = entries_[x.first].p;
  for (std::uint32_t e = entries_[x.first].next; e != kNone; e = entries_[e].next)
    if (!(entries_[e].p == p0)) return false;
  return true;  // all coincide: no split can separate them
}

template <int D>
bool PrQuadtree<D>::grow_step(Box<D>& region, bool leaf, const Point<D>& p, int& slot) {
  const Box<D> old = region;
  if (leaf) {  // nothing to re-route: widen the leaf to fit p
    region = cube(merged(old, Box<D>{p, p}));
    for (int a = 0; a < D; ++a)
      region.max[a] = std::nextafter(region.max[a], std::numeric_limits<double>::infinity());
    return is_finite(region.max);
  }
  slot = 0;
  for (int a = 0; a < D; ++a) {
    const double side = std::max(old.extent(a), 1e-300);
    if (p[a] < old.min[a]) {
      region.min[a] = old.min[a] - side;
      slot |= 1 << a;
    } else {
      region.max[a] = old.max[a] + side;
    }
  }
  return is_finite(region.min) && is_finite(region.max);
}

template <int D>
void PrQuadtree<D>::grow_towards(const Point<D>& p) {
  // the whole growth is tried on the region alone first, so that a refused point leaves the
  // tree as it was (not doubled a thousand times on its way to overflowing)
  Box<D> trial = nodes_[0].region;
  for (int slot = 0; !in_region(trial, p);)
    if (!grow_step(trial, nodes_[0].leaf(), p, slot))
      throw InvalidGeometry("point too far from the quadtree's region: " + to_string(p));
  while (!in_root(p)) {
    const Box<D> old = nodes_[0].region;
    Box<D> grown = old;
    int slot = 0;  // where the old root goes among the new root's children
    grow_step(grown, nodes_[0].leaf(), p, slot);
    if (nodes_[0].leaf()) {
      nodes_[0].region = grown;
      continue;
    }
    const std::uint32_t g = allocate_group();
    for (std::uint32_t n = 0; n < nodes_.size(); ++n)
      ++nodes_[n].depth;  // rare (once per doubling), so a pass over the pool is fine
    // cut the grown region at the old root's corner so that the old root is a child exactly
    Point<D> cut;
    for (int a = 0; a < D; ++a)
      cut[a] = (slot >> a & 1) ? old.min[a] : old.max[a];
    for (int c = 0; c < fan_out; ++c) {
      Box<D> r = grown;
      for (int a = 0; a < D; ++a)
        (c >> a & 1 ? r.min[a] : r.max[a]) = cut[a];
      nodes_[g + c] = leaf_node(r, 1);
    }
    nodes_[g + slot] = nodes_[0];
    nodes_[g + slot].depth = 1;
    nodes_[0] = Node{grown, g, kNone, nodes_[g + slot].count, 0};
  }
}

template <int D>
void PrQuadtree<D>::split(std::uint32_t n) {
  while (!must_stay_leaf(nodes_[n])) {
    const std::uint32_t g = allocate_group();
    Node& x = nodes_[n];
    for (int c = 0; c < fan_out; ++c)
      nodes_[g + c] = leaf_node(child_region(x.region, c), x.depth + 1);
    x.child = g;
    std::uint32_t e = x.first;
    x.first = kNone;
    while (e != kNone) {
      const std::uint32_t next = entries_[e].next;
      Node& y = nodes_[g + child_of(x, entries_[e].p)];
      entries_[e].next = y.first;
      y.first = e;
      ++y.count;
      e = next;
    }
    // at most one child can still be over capacity: the one that took every point
    std::uint32_t over = kNone;
    for (int c = 0; c < fan_out; ++c)
      if (nodes_[g + c].count > bucket_) over = g + c;
    if (over == kNone) return;
    n = over;
  }
}

template <int D>
void PrQuadtree<D>::insert(const Point<D>& p, Id id) {
  check_point(p, "inserted point");
  if (nodes_.size() == 0) {
    make_root(Box<D>{p, p});
    try {
      grow_towards(p);
    } catch (...) {  // a refused first point leaves the tree empty, not rooted at it
      nodes_.clear();
      throw;
    }
  } else {
    grow_towards(p);
  }
  const std::uint32_t e = allocate_entry(p, id);
  std::uint32_t n = 0;
  for (;;) {
    Node& x = nodes_[n];
    ++x.count;
    if (x.leaf()) break;
    n = x.child + std::uint32_t(child_of(x, p));
  }
  entries_[e].next = nodes_[n].first;
  nodes_[n].first = e;
  split(n);
}

template <int D>
void PrQuadtree<D>::gather(std::uint32_t n, std::uint32_t& head) {
  const Node x = nodes_[n];
  if (x.leaf()) {
    for (std::uint32_t e = x.first; e != kNone;) {
      const std::uint32_t next = entries_[e].next;
      entries_[e].next = head;
      head = e;
      e = next;
    }
    return;
  }
  for (int c = 0; c < fan_out; ++c)
    gather(x.child + std::uint32_t(c), head);
  nodes_.release(x.child);
}

template <int D>
void PrQuadtree<D>::collapse(std::uint32_t n) {
  std::uint32_t head = kNone;
  gather(n, head);
  nodes_[n].child = kNone;
  nodes_[n].first = head;
}

template <int D>
bool PrQuadtree<D>::erase(const Point<D>& p, Id id) {
  check_point(p, "erased point");
  if (nodes_.size() == 0 || !intersects(nodes_[0].region, p)) return false;
  detail::Scratch<std::uint32_t> scratch;
  auto& path = *scratch;
  std::uint32_t n = 0;
  while (!nodes_[n].leaf()) {
    path.push_back(n);
    n = nodes_[n].child + std::uint32_t(child_of(nodes_[n], p));
  }
  path.push_back(n);
  std::uint32_t* link = &nodes_[n].first;
  while (*link != kNone && !(entries_[*link].id == id && entries_[*link].p == p))
    link = &entries_[*link].next;
  if (*link == kNone) return false;
  const std::uint32_t e = *link;
  *link = entries_[e].next;
  entries_.release(e);
  for (std::uint32_t m : path)
    --nodes_[m].count;
  for (std::uint32_t m : path)  // the highest internal node that no longer needs children
    if (!nodes_[m].leaf() && nodes_[m].count <= bucket_) {
      collapse(m);
      break;
    }
  return true;
}

template <int D>
int PrQuadtree<D>::height() const {
  int h = 0;
  visit_cells([&](const Box<D>&, int depth, std::size_t, bool) { h = std::max(h, depth + 1); });
  return h;
}

template <int D>
template <WindowVisitor<D> Visit>
QueryStats PrQuadtree<D>::query(const Box<D>& window, Visit&& visit) const {
  check_box(window, "query window");
  QueryStats s;
  if (empty()) return s;
  detail::Scratch<std::uint64_t> scratch;
  auto& stack = *scratch;
  // low 32 bits: node; bit 32: the node is inside the window, report without tests
  constexpr std::uint64_t kInside = std::uint64_t(1) << 32;
  stack.push_back(0);
  while (!stack.empty()) {
    const std::uint64_t top = stack.back();
    stack.pop_back();
    const Node& x = nodes_[std::uint32_t(top)];
    bool inside = top & kInside;
    if (!inside) {
      ++s.entries_tested;
      if (!intersects(x.region, window)) continue;
      inside = contains(window, x.region);
      if (!inside) ++s.nodes_visited;
    }
    if (!x.leaf()) {
      for (int c = fan_out - 1; c >= 0; --c)
        if (nodes_[x.child + c].count)
          stack.push_back((inside ? kInside : 0) | (x.child + std::uint32_t(c)));
      continue;
    }
    for (std::uint32_t e = x.first; e != kNone; e = entries_[e].next) {
      const Entry& en = entries_[e];
      if (!inside) {
        ++s.entries_tested;
        if (!intersects(window, en.p)) continue;
      }
      ++s.results;
      if (!visit(en.id, Box<D>::of_point(en.p))) return s;
    }
  }
  return s;
}

template <int D>
template <NearestVisitor<D> Visit>
QueryStats PrQuadtree<D>::nearest(const Point<D>& p, std::size_t k, Visit&& visit) const {
  check_point(p, "query point");
  if (k == 0) throw InvalidArgument("nearest-n query needs k >= 1");
  if (empty()) return {};
  return walk_nearest(p, visit, [k](std::uint64_t root, auto& expand, auto& report) {
    return detail::best_first(root, k, expand, report);
  });
}

template <int D>
template <NearestVisitor<D> Visit>
QueryStats PrQuadtree<D>::browse(const Point<D>& p, Visit&& visit) const {
  check_point(p, "query point");
  if (empty()) return {};
  return walk_nearest(p, visit, [](std::uint64_t root, auto& expand, auto& report) {
    return detail::browse(root, expand, report);
  });
}

template <int D>
template <class Visit, class Walk>
QueryStats PrQuadtree<D>::walk_nearest(const Point<D>& p, Visit& visit, Walk&& walk) const {
  auto expand = [&](std::uint64_t ref, auto& q) -> std::size_t {
    const Node& x = nodes_[std::uint32_t(ref)];
    std::size_t tested = 0;
    if (!x.leaf()) {
      for (int c = 0; c < fan_out; ++c) {
        const Node& y = nodes_[x.child + c];
        if (!y.count) continue;
        ++tested;
        q.push_subtree(squared_distance(p, y.region), x.child + std::uint32_t(c));
      }
      return tested;
    }
    for (std::uint32_t e = x.first; e != kNone; e = entries_[e].next, ++tested)
      q.push_entry(squared_distance(p, entries_[e].p), e, entries_[e].id);
    return tested;
  };
  auto report = [&](Id id, std::uint64_t e, double d) {
    return visit(id, Box<D>::of_point(entries_[e].p), d);
  };
  return walk(0, expand, report);
}

template <int D>
void PrQuadtree<D>::validate() const {
  auto fail = [](const std::string& what) { throw Error("PrQuadtree invalid: " + what); };
  if (nodes_.size() == 0) {
    if (entries_.size() != 0) fail("entries without nodes");
    return;
  }
  std::vector<bool> node_seen(nodes_.size(), false), entry_seen(entries_.size(), false);
  if (!nodes_.validate_free(node_seen)) fail("free group list corrupt");
  if (!entries_.validate_free(entry_seen)) fail("free entry list corrupt");
  std::vector<std::uint32_t> stack{0};
  for (int c = 0; c < fan_out; ++c)  // the root and the unused rest of its run
    node_seen[std::uint32_t(c)] = true;
  while (!stack.empty()) {
    const std::uint32_t n = stack.back();
    stack.pop_back();
    const Node& x = nodes_[n];
    const std::string at = " at node " + std::to_string(n);
    if (x.leaf()) {
      std::uint32_t count = 0;
      for (std::uint32_t e = x.first; e != kNone; e = entries_[e].next) {
        if (e >= entries_.size() || entry_seen[e]) fail("entry list corrupt" + at);
        entry_seen[e] = true;
        ++count;
        if (!intersects(x.region, entries_[e].p)) fail("point outside its leaf" + at);
      }
      if (count != x.count) fail("leaf count wrong" + at);
      if (count > bucket_ && !must_stay_leaf(x)) fail("leaf over capacity" + at);
      continue;
    }
    if (x.count <= bucket_) fail("internal node with too few points" + at);
    if (x.child >= nodes_.size() || nodes_.size() - x.child < std::size_t(fan_out))
      fail("child group out of range" + at);
    std::uint32_t sum = 0;
    // the upper-on-every-axis child fixes the cut; all children must tile the region with it
    const Box<D>& last = nodes_[x.child + fan_out - 1].region;
    for (int c = 0; c < fan_out; ++c) {
      const std::uint32_t y = x.child + std::uint32_t(c);
      if (y >= nodes_.size() || node_seen[y]) fail("child reused" + at);
      node_seen[y] = true;
      const Node& ch = nodes_[y];
      if (ch.depth != x.depth + 1) fail("child depth wrong" + at);
      for (int a = 0; a < D; ++a) {
        const double cut = last.min[a];
        const bool upper = c >> a & 1;
        const double lo = upper ? cut : x.region.min[a], hi = upper ? x.region.max[a] : cut;
        if (ch.region.min[a] != lo || ch.region.max[a] != hi)
          fail("children do not tile the region" + at);
        if (!(x.region.min[a] <= cut && cut <= x.region.max[a])) fail("cut outside region" + at);
      }
      sum += ch.count;
      stack.push_back(y);
    }
    if (sum != x.count) fail("counts do not add up" + at);
  }
  if (std::count(node_seen.begin(), node_seen.end(), false)) fail("nodes leaked");
  if (std::count(entry_seen.begin(), entry_seen.end(), false)) fail("entries leaked");
}

static_assert(DynamicPointIndex<PrQuadtree<2>> && NearestIndex<PrQuadtree<2>>);

using PrQuadtree2 = PrQuadtree<2>;
using Octree = PrQuadtree<3>;

}  // namespace loci
