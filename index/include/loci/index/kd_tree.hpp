// KdTree<D, Bucket>: a k-d tree of points (Bentley, "Multidimensional binary search trees
// used for associative searching", CACM 1975) with leaf buckets, a balanced static build and
// insertion/erasure kept balanced by partial rebuilds.
//
// Build. A node's points are split on the axis of their largest extent, either at the median
// (KdSplit::median, the default: depth ceil(log2(n / Bucket))) or at the middle of the
// extent, slid to the nearest point when one side would be empty (KdSplit::sliding_midpoint,
// Maneewongvatana and Mount, "It's okay to be skinny, if your friends are fat", 1999), falling
// back to the median when a side would get less than an eighth of the points so that the depth
// stays logarithmic. Splitting is by rank, never by value alone, so duplicates and points on
// a line cannot recurse forever. A node of at most Bucket points is a leaf.
//
// Layout. Nodes live in one pool indexed by 32-bit integers and carry the bounding box of
// their points, so queries prune with boxes (tighter than split planes) and report a node
// lying inside a window without testing its points. Each leaf owns one slot of Bucket entries
// in a point pool; free lists recycle nodes and slots. A static build allocates nodes and
// slots in depth-first order, so a subtree's points are contiguous in memory.
//
// Updates. insert() descends by the split planes, grows the boxes on the way and splits a
// full leaf into a two-leaf subtree. erase() finds the point through the boxes and removes it
// from its leaf; boxes are not shrunk (they stay conservative) until the next rebuild. After
// either, the highest node on the path whose larger child holds more than 3/4 of its points
// is rebuilt from scratch (the scapegoat rule of Galperin and Rivest, SODA 1993), and a node
// left with at most Bucket points is turned back into a leaf. Amortised O(log^2 n) per update.
//
// Queries: window (closed), radius (distance <= r), nearest-n best first through
// detail::best_first.
//
// Invariants (checked by validate()): each node's box contains its points and its children's
// boxes; sizes add up; left points <= split value <= right points on the node's axis; leaves
// hold at most Bucket points; every slot and node is either in use once or on a free list.
//
// Thread-safety: const member functions may run concurrently (queries use thread-local
// scratch); insert/erase need exclusive access.
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
#include "loci/index/detail/node_pool.hpp"
#include "loci/index/detail/scratch.hpp"
#include "loci/index/query.hpp"

namespace loci {

enum class KdSplit : std::uint8_t { median, sliding_midpoint };

template <int D, int Bucket = 12>
class KdTree {
  static_assert(Bucket >= 2 && Bucket <= 256, "bucket size must be in [2, 256]");

 public:
  static constexpr int dimension = D;
  static constexpr int bucket = Bucket;

  KdTree() = default;
  explicit KdTree(KdSplit split) : split_(split) {}
  KdTree(const KdTree&) = default;
  KdTree& operator=(const KdTree&) = default;
  // Moving leaves `other` empty, keeping its parameters.
  KdTree(KdTree&& other) noexcept : KdTree(other.split_) { swap(other); }
  KdTree& operator=(KdTree&& other) noexcept {
    KdTree(std::move(other)).swap(*this);
    return *this;
  }

  // Point i gets id i. Throws InvalidGeometry on a NaN or infinite coordinate.
  static KdTree build(std::span<const Point<D>> points, KdSplit split = KdSplit::median) {
    std::vector<Item> items(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
      check_point(points[i], ("point " + std::to_string(i)).c_str());
      items[i] = {points[i], Id(i)};
    }
    return KdTree(std::move(items), split);
  }
  static KdTree build(std::span<const Point<D>> points, std::span<const Id> ids,
                      KdSplit split = KdSplit::median) {
    if (points.size() != ids.size()) throw InvalidArgument("points and ids differ in length");
    std::vector<Item> items(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
      check_point(points[i], ("point " + std::to_string(i)).c_str());
      items[i] = {points[i], ids[i]};
    }
    return KdTree(std::move(items), split);
  }

  std::size_t size() const { return root_ == kNone ? 0 : nodes_[root_].size; }
  bool empty() const { return size() == 0; }
  KdSplit split() const { return split_; }
  // A box holding every point: their bounding box after a build, conservative after erases
  // (as the nodes' boxes are) until the next rebuild.
  Box<D> bounds() const { return empty() ? Box<D>::empty() : nodes_[root_].box; }
  int height() const { return root_ == kNone ? 0 : height_of(root_); }
  std::size_t memory_bytes() const { return nodes_.memory_bytes() + leaves_.memory_bytes(); }

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

  // Calls visit(id, box, distance) for each point at distance <= r from p, in no particular
  // order. Throws InvalidGeometry for a bad point, InvalidArgument for r < 0 or NaN.
  template <NearestVisitor<D> Visit>
  QueryStats radius(const Point<D>& p, double r, Visit&& visit) const;
  std::vector<Neighbor> radius(const Point<D>& p, double r) const {
    return collect_neighbors([&](auto&& v) { return radius(p, r, v); });
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

  // Throws loci::Error describing the first broken invariant.
  void validate() const;

 private:
  // Runs walk(root, expand, report), detail::best_first or detail::browse, with this
  // tree's expansion around p.
  template <class Visit, class Walk>
  QueryStats walk_nearest(const Point<D>& p, Visit& visit, Walk&& walk) const;
  struct Item {
    Point<D> p;
    Id id;
  };

  struct Node {           // 16 D + 24 bytes
    Box<D> box;           // 16 D: contains every point of the subtree
    double split;         // 8: internal: left <= split <= right on `axis`
    std::uint32_t left;   // 4: kNone for a leaf; next free node while on the pool's free list
    std::uint32_t right;  // 4: leaf: its bucket in leaves_
    std::uint32_t size;   // 4: points in the subtree
    std::uint32_t axis;   // 4: internal: the axis of the split
    bool leaf() const { return left == kNone; }
  };
  // The points of one leaf, kept apart from the nodes so that a leaf scan reads only them.
  struct Leaf {               // (8 D + 8) Bucket + 8 bytes
    Point<D> p[Bucket];       // the first `size` (of the owning node) are in use
    Id id[Bucket];            // p[i]'s id
    std::uint32_t next_free;  // next free bucket while on the pool's free list
  };

  void swap(KdTree& other) noexcept {
    nodes_.swap(other.nodes_);
    leaves_.swap(other.leaves_);
    std::swap(root_, other.root_);
    std::swap(split_, other.split_);
  }
  KdTree(std::vector<Item>&& items, KdSplit split) : split_(split) {
    if (items.size() >= kNone) throw InvalidArgument("KdTree holds at most 2^32 - 2 points");
    if (items.empty()) return;
    nodes_.reserve(2 * (items.size() / (Bucket / 2) + 1));
    leaves_.reserve(items.size() / (Bucket / 2) + 1);
    root_ = nodes_.allocate("KdTree");
    build_at(root_, items.data(), items.size());
  }

  // Builds the subtree of items[0, n) into node `at`; the node's old contents are ignored.
  void build_at(std::uint32_t at, Item* items, std::size_t n);
  std::size_t choose_cut(Item* items, std::size_t n, int axis, const Box<D>& box) const;
  // Frees the subtree's nodes except `n` itself and its slots, appending its items to out.
  void collect(std::uint32_t n, std::vector<Item>& out);
  void rebuild(std::uint32_t n) {
    std::vector<Item> items;
    items.reserve(nodes_[n].size);
    collect(n, items);
    build_at(n, items.data(), items.size());
  }
  bool erase_at(std::uint32_t n, const Point<D>& p, Id id);
  // Rebuilds the highest unbalanced node on the path from the root towards p.
  void rebalance(const Point<D>& p);
  bool unbalanced(const Node& x) const {
    if (x.leaf()) return false;
    const std::uint32_t big = std::max(nodes_[x.left].size, nodes_[x.right].size);
    return x.size <= Bucket || big == x.size ||
           4 * std::uint64_t(big) > 3 * std::uint64_t(x.size) + 4 * Bucket;
  }
  int height_of(std::uint32_t n) const {
    const Node& x = nodes_[n];
    return x.leaf() ? 1 : 1 + std::max(height_of(x.left), height_of(x.right));
  }

  template <class Visit>
  bool report_subtree(std::uint32_t n, Visit& visit, QueryStats& s) const;

  detail::NodePool<Node, &Node::left> nodes_;
  detail::NodePool<Leaf, &Leaf::next_free> leaves_;
  std::uint32_t root_ = kNone;
  KdSplit split_ = KdSplit::median;
};

template <int D, int Bucket>
std::size_t KdTree<D, Bucket>::choose_cut(Item* items, std::size_t n, int axis,
                                          const Box<D>& box) const {
  auto less = [axis](const Item& a, const Item& b) { return a.p[axis] < b.p[axis]; };
  const std::size_t mid = n / 2;
  if (split_ == KdSplit::sliding_midpoint) {
    const double m = box.center(axis);
    Item* cut = std::partition(items, items + n, [&](const Item& it) { return it.p[axis] < m; });
    std::size_t c = std::size_t(cut - items);
    if (c == 0) {  // slide up to the lowest point
      std::iter_swap(items, std::min_element(items, items + n, less));
      c = 1;
    } else if (c == n) {  // slide down to the highest point
      std::iter_swap(items + n - 1, std::max_element(items, items + n, less));
      c = n - 1;
    }
    if (8 * c >= n && 8 * (n - c) >= n) {
      // the right side must start at its lowest point so that left <= split <= right
      std::iter_swap(items + c, std::min_element(items + c, items + n, less));
      return c;
    }
  }
  std::nth_element(items, items + mid, items + n, less);
  return mid;
}

template <int D, int Bucket>
void KdTree<D, Bucket>::build_at(std::uint32_t at, Item* items, std::size_t n) {
  if (n <= std::size_t(Bucket)) {
    Box<D> box = Box<D>::empty();
    const std::uint32_t slot = leaves_.allocate("KdTree");
    Leaf& leaf = leaves_[slot];
    for (std::size_t i = 0; i < n; ++i) {
      box.expand(items[i].p);
      leaf.p[i] = items[i].p;
      leaf.id[i] = items[i].id;
    }
    nodes_[at] = Node{box, 0.0, kNone, slot, std::uint32_t(n), 0};
    return;
  }
  Box<D> box = Box<D>::empty();
  for (std::size_t i = 0; i < n; ++i)
    box.expand(items[i].p);
  int axis = 0;
  for (int a = 1; a < D; ++a)
    if (box.extent(a) > box.extent(axis)) axis = a;
  const std::size_t cut = choose_cut(items, n, axis, box);
  const double split = items[cut].p[axis];
  const std::uint32_t l = nodes_.allocate("KdTree");
  build_at(l, items, cut);
  const std::uint32_t r = nodes_.allocate("KdTree");
  build_at(r, items + cut, n - cut);
  // children first: allocating may have moved the pool
  nodes_[at] = Node{
      merged(nodes_[l].box, nodes_[r].box), split, l, r, std::uint32_t(n), std::uint32_t(axis)};
}

template <int D, int Bucket>
void KdTree<D, Bucket>::collect(std::uint32_t n, std::vector<Item>& out) {
  const Node x = nodes_[n];
  if (x.leaf()) {
    const Leaf& leaf = leaves_[x.right];
    for (std::size_t i = 0; i < x.size; ++i)
      out.push_back({leaf.p[i], leaf.id[i]});
    leaves_.release(x.right);
    return;
  }
  for (std::uint32_t c : {x.left, x.right}) {
    collect(c, out);
    nodes_.release(c);
  }
}

template <int D, int Bucket>
void KdTree<D, Bucket>::insert(const Point<D>& p, Id id) {
  check_point(p, "inserted point");
  if (root_ == kNone) {
    root_ = nodes_.allocate("KdTree");
    Item it{p, id};
    build_at(root_, &it, 1);
    return;
  }
  if (size() >= kNone - 1) throw InvalidArgument("KdTree holds at most 2^32 - 2 points");
  std::uint32_t n = root_;
  for (;;) {
    Node& x = nodes_[n];
    x.box.expand(p);
    ++x.size;
    if (x.leaf()) break;
    const double v = p[int(x.axis)];
    if (v < x.split)
      n = x.left;
    else if (v > x.split)
      n = x.right;
    else  // on the plane either side is valid; keep duplicates balanced
      n = nodes_[x.left].size <= nodes_[x.right].size ? x.left : x.right;
  }
  Node& leaf = nodes_[n];
  if (leaf.size <= Bucket) {
    leaves_[leaf.right].p[leaf.size - 1] = p;
    leaves_[leaf.right].id[leaf.size - 1] = id;
  } else {
    std::vector<Item> items;
    items.reserve(Bucket + 1);
    --leaf.size;
    collect(n, items);
    items.push_back({p, id});
    build_at(n, items.data(), items.size());
  }
  rebalance(p);
}

template <int D, int Bucket>
bool KdTree<D, Bucket>::erase_at(std::uint32_t n, const Point<D>& p, Id id) {
  Node& x = nodes_[n];
  if (!intersects(x.box, p)) return false;
  if (x.leaf()) {
    Leaf& leaf = leaves_[x.right];
    for (std::size_t i = 0; i < x.size; ++i) {
      if (leaf.id[i] == id && leaf.p[i] == p) {
        leaf.p[i] = leaf.p[x.size - 1];
        leaf.id[i] = leaf.id[x.size - 1];
        --x.size;
        return true;
      }
    }
    return false;
  }
  const std::uint32_t l = x.left, r = x.right;
  const double v = p[int(x.axis)];
  const bool found = (v <= x.split && erase_at(l, p, id)) || (v >= x.split && erase_at(r, p, id));
  if (found) --nodes_[n].size;
  return found;
}

template <int D, int Bucket>
bool KdTree<D, Bucket>::erase(const Point<D>& p, Id id) {
  check_point(p, "erased point");
  if (root_ == kNone || !erase_at(root_, p, id)) return false;
  if (nodes_[root_].size == 0) {
    nodes_.clear();
    leaves_.clear();
    root_ = kNone;
    return true;
  }
  rebalance(p);
  return true;
}

template <int D, int Bucket>
void KdTree<D, Bucket>::rebalance(const Point<D>& p) {
  std::uint32_t n = root_;
  while (!nodes_[n].leaf()) {
    const Node& x = nodes_[n];
    if (unbalanced(x)) {
      rebuild(n);
      return;
    }
    // follow the side that changed; when p lies on the plane, the larger side is the one at risk
    const double v = p[int(x.axis)];
    if (v < x.split)
      n = x.left;
    else if (v > x.split)
      n = x.right;
    else
      n = nodes_[x.left].size >= nodes_[x.right].size ? x.left : x.right;
  }
}

template <int D, int Bucket>
template <class Visit>
bool KdTree<D, Bucket>::report_subtree(std::uint32_t n, Visit& visit, QueryStats& s) const {
  const Node& x = nodes_[n];
  if (!x.leaf()) return report_subtree(x.left, visit, s) && report_subtree(x.right, visit, s);
  const Leaf& leaf = leaves_[x.right];
  for (std::size_t i = 0; i < x.size; ++i) {
    ++s.results;
    if (!visit(leaf.id[i], Box<D>::of_point(leaf.p[i]))) return false;
  }
  return true;
}

template <int D, int Bucket>
template <WindowVisitor<D> Visit>
QueryStats KdTree<D, Bucket>::query(const Box<D>& window, Visit&& visit) const {
  check_box(window, "query window");
  QueryStats s;
  if (root_ == kNone) return s;
  detail::Scratch<std::uint32_t> scratch;
  auto& stack = *scratch;
  stack.push_back(root_);
  while (!stack.empty()) {
    const std::uint32_t n = stack.back();
    stack.pop_back();
    const Node& x = nodes_[n];
    ++s.entries_tested;
    if (!intersects(x.box, window)) continue;
    if (contains(window, x.box)) {
      if (!report_subtree(n, visit, s)) return s;
      continue;
    }
    ++s.nodes_visited;
    if (!x.leaf()) {
      stack.push_back(x.right);
      stack.push_back(x.left);
      continue;
    }
    const Leaf& leaf = leaves_[x.right];
    for (std::size_t i = 0; i < x.size; ++i) {
      ++s.entries_tested;
      if (!intersects(window, leaf.p[i])) continue;
      ++s.results;
      if (!visit(leaf.id[i], Box<D>::of_point(leaf.p[i]))) return s;
    }
  }
  return s;
}

template <int D, int Bucket>
template <NearestVisitor<D> Visit>
QueryStats KdTree<D, Bucket>::radius(const Point<D>& p, double r, Visit&& visit) const {
  check_point(p, "query point");
  if (!(r >= 0) || !std::isfinite(r))
    throw InvalidArgument("radius must be finite and >= 0, got " + std::to_string(r));
  QueryStats s;
  if (root_ == kNone) return s;
  const double r2 = r * r;
  detail::Scratch<std::uint32_t> scratch;
  auto& stack = *scratch;
  stack.push_back(root_);
  while (!stack.empty()) {
    const Node& x = nodes_[stack.back()];
    stack.pop_back();
    ++s.entries_tested;
    if (squared_distance(p, x.box) > r2) continue;
    ++s.nodes_visited;
    if (!x.leaf()) {
      stack.push_back(x.right);
      stack.push_back(x.left);
      continue;
    }
    const Leaf& leaf = leaves_[x.right];
    for (std::size_t i = 0; i < x.size; ++i) {
      ++s.entries_tested;
      const double d2 = squared_distance(p, leaf.p[i]);
      if (d2 > r2) continue;
      ++s.results;
      if (!visit(leaf.id[i], Box<D>::of_point(leaf.p[i]), std::sqrt(d2))) return s;
    }
  }
  return s;
}

template <int D, int Bucket>
template <NearestVisitor<D> Visit>
QueryStats KdTree<D, Bucket>::nearest(const Point<D>& p, std::size_t k, Visit&& visit) const {
  check_point(p, "query point");
  if (k == 0) throw InvalidArgument("nearest-n query needs k >= 1");
  if (root_ == kNone) return {};
  return walk_nearest(p, visit, [k](std::uint64_t root, auto& expand, auto& report) {
    return detail::best_first(root, k, expand, report);
  });
}

template <int D, int Bucket>
template <NearestVisitor<D> Visit>
QueryStats KdTree<D, Bucket>::browse(const Point<D>& p, Visit&& visit) const {
  check_point(p, "query point");
  if (root_ == kNone) return {};
  return walk_nearest(p, visit, [](std::uint64_t root, auto& expand, auto& report) {
    return detail::browse(root, expand, report);
  });
}

template <int D, int Bucket>
template <class Visit, class Walk>
QueryStats KdTree<D, Bucket>::walk_nearest(const Point<D>& p, Visit& visit, Walk&& walk) const {
  // `q` is best_first's sink, which drops whatever lies beyond the k-th best entry so far.
  // An expansion walks down the nearer child to a leaf and queues only the farther siblings:
  // half the queue operations of queueing both, and the best candidates are found first.
  auto expand = [&](std::uint64_t ref, auto& q) -> std::size_t {
    std::uint32_t n = std::uint32_t(ref);
    std::size_t tested = 0;
    while (!nodes_[n].leaf()) {
      const Node& x = nodes_[n];
      const double dl = squared_distance(p, nodes_[x.left].box);
      const double dr = squared_distance(p, nodes_[x.right].box);
      tested += 2;
      const bool left_first = dl <= dr;
      q.push_subtree(left_first ? dr : dl, left_first ? x.right : x.left);
      n = left_first ? x.left : x.right;
      if constexpr (requires { q.bound(); })
        if ((left_first ? dl : dr) > q.bound()) return tested;
    }
    const Node& x = nodes_[n];
    const std::size_t base = std::size_t(x.right) * Bucket;
    const Leaf& leaf = leaves_[x.right];
    for (std::size_t i = 0; i < x.size; ++i)
      q.push_entry(squared_distance(p, leaf.p[i]), base + i, leaf.id[i]);
    return tested + x.size;
  };
  auto report = [&](Id id, std::uint64_t pos, double d) {
    return visit(id, Box<D>::of_point(leaves_[std::uint32_t(pos / Bucket)].p[pos % Bucket]), d);
  };
  return walk(root_, expand, report);
}

template <int D, int Bucket>
void KdTree<D, Bucket>::validate() const {
  auto fail = [](const std::string& what) { throw Error("KdTree invalid: " + what); };
  if (root_ == kNone) {
    if (nodes_.size() != 0) fail("empty tree with nodes");
    return;
  }
  std::vector<bool> node_seen(nodes_.size(), false);
  std::vector<bool> slot_seen(leaves_.size(), false);
  if (!nodes_.validate_free(node_seen)) fail("free node list corrupt");
  if (!leaves_.validate_free(slot_seen)) fail("free bucket list corrupt");
  std::vector<std::uint32_t> stack{root_};
  while (!stack.empty()) {
    const std::uint32_t n = stack.back();
    stack.pop_back();
    if (n >= nodes_.size() || node_seen[n]) fail("node " + std::to_string(n) + " reused");
    node_seen[n] = true;
    const Node& x = nodes_[n];
    if (x.leaf()) {
      if (x.right >= slot_seen.size() || slot_seen[x.right]) fail("leaf slot reused");
      slot_seen[x.right] = true;
      if (x.size > Bucket) fail("leaf " + std::to_string(n) + " over capacity");
      for (std::size_t i = 0; i < x.size; ++i)
        if (!intersects(x.box, leaves_[x.right].p[i]))
          fail("point outside its leaf's box at node " + std::to_string(n));
      continue;
    }
    const Node& l = nodes_[x.left];
    const Node& r = nodes_[x.right];
    if (l.size + r.size != x.size) fail("sizes do not add up at node " + std::to_string(n));
    if (!contains(x.box, l.box) || !contains(x.box, r.box))
      fail("child box escapes node " + std::to_string(n));
    const int a = int(x.axis);
    if (a >= D) fail("bad axis at node " + std::to_string(n));
    // points, not boxes: boxes of erased points may reach over the plane
    std::vector<std::uint32_t> sub{x.left};
    while (!sub.empty()) {
      const Node& y = nodes_[sub.back()];
      sub.pop_back();
      if (!y.leaf()) {
        sub.push_back(y.left);
        sub.push_back(y.right);
        continue;
      }
      for (std::size_t i = 0; i < y.size; ++i)
        if (leaves_[y.right].p[i][a] > x.split)
          fail("left point beyond the split at node " + std::to_string(n));
    }
    sub.push_back(x.right);
    while (!sub.empty()) {
      const Node& y = nodes_[sub.back()];
      sub.pop_back();
      if (!y.leaf()) {
        sub.push_back(y.left);
        sub.push_back(y.right);
        continue;
      }
      for (std::size_t i = 0; i < y.size; ++i)
        if (leaves_[y.right].p[i][a] < x.split)
          fail("right point before the split at node " + std::to_string(n));
    }
    stack.push_back(x.left);
    stack.push_back(x.right);
  }
  if (std::count(node_seen.begin(), node_seen.end(), false) != 0) fail("nodes leaked");
  if (std::count(slot_seen.begin(), slot_seen.end(), false) != 0) fail("slots leaked");
}

static_assert(DynamicPointIndex<KdTree<2>> && NearestIndex<KdTree<2>>);

using KdTree2 = KdTree<2>;
using KdTree3 = KdTree<3>;

}  // namespace loci
