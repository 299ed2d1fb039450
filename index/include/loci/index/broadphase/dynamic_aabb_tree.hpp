// DynamicAabbTree<D>: a bounding-volume hierarchy of fat boxes with a persistent pair list.
//
// The tree is binary; leaves hold one proxy each under a "fat" box, the proxy's box grown by
// a margin and stretched along its last displacement (the prediction), so that a proxy moving
// steadily stays inside its fat box for several ticks and the tree is not touched (Presson's
// btDbvt; Catto, Box2D's b2DynamicTree, and "Dynamic Bounding Volume Hierarchies", GDC 2019).
// A move that leaves the fat box removes the leaf and inserts it again with a new fat box.
//
// Insertion descends greedily by the surface-area heuristic (in 2D the perimeter; we use the
// sum of extents, proportional to both): at each node it compares the cost of making a new
// parent here with the cheapest lower bound of going into either child, the growth of every
// ancestor being paid on the way. On the way back up, each ancestor tries the four rotations
// that swap one child with a grandchild on the other side (Kensler, "Tree rotations for
// improving bounding volume hierarchies", 2008) and keeps the one that most reduces the cost
// of the child it changes.
//
// Pairs. The tree keeps the sorted list of slot pairs whose fat boxes meet. Moves that stay
// inside their fat box leave it as it is; proxies re-inserted, added or removed since the last
// tick are in the move buffer. A tick drops the listed pairs of buffered proxies, queries the
// tree with each buffered proxy's fat box for its new ones (a pair of two buffered proxies
// from the lower slot only), merges the two sorted lists, then reports the listed pairs whose
// tight boxes meet. So a tick costs O(buffered * log n + pairs), and in a coherent scene
// almost nothing is buffered.
//
// Layout. Nodes live in detail::NodePool (free list through `parent`). A proxy's tight box is
// in the ProxyTable; its fat box is its leaf's box.
//
// Invariants (validate()): parent and child links agree; an internal node's box contains its
// children's and its height is one more than theirs; each live proxy has one leaf whose fat box
// contains its box; every node is reachable once or free once; the pair list is sorted, unique,
// names live slots and, with an empty move buffer, only pairs whose fat boxes meet.
//
// Queries: query(box) descends the fat boxes and tests the tight ones, O(log n + k) in
// practice.
//
// Thread-safety as broad_phase.hpp says (query uses thread-local scratch).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "loci/geom/box.hpp"
#include "loci/index/broadphase/broad_phase.hpp"
#include "loci/index/broadphase/detail/pair_tracker.hpp"
#include "loci/index/broadphase/detail/proxy_table.hpp"
#include "loci/index/detail/node_pool.hpp"
#include "loci/index/detail/scratch.hpp"

namespace loci {

struct AabbTreeOptions {
  double margin = 0;             // added to every side of a fat box, in coordinate units
  double margin_fraction = 0.1;  // plus this fraction of the box's largest extent
  double prediction = 2.0;       // the fat box is stretched by this many last displacements
};

template <int D>
class DynamicAabbTree {
 public:
  static constexpr int dimension = D;

  explicit DynamicAabbTree(AabbTreeOptions options = {}) : opt_(options) {
    if (!(opt_.margin >= 0 && opt_.margin_fraction >= 0 && opt_.prediction >= 0) ||
        !std::isfinite(opt_.margin + opt_.margin_fraction + opt_.prediction))
      throw InvalidArgument("DynamicAabbTree: margins and prediction must be finite and >= 0");
  }
  DynamicAabbTree(const DynamicAabbTree&) = default;
  DynamicAabbTree& operator=(const DynamicAabbTree&) = default;
  // Moving leaves `other` empty, keeping its parameters.
  DynamicAabbTree(DynamicAabbTree&& other) noexcept : DynamicAabbTree(other.opt_) { swap(other); }
  DynamicAabbTree& operator=(DynamicAabbTree&& other) noexcept {
    DynamicAabbTree(std::move(other)).swap(*this);
    return *this;
  }

  void add(Id id, const Box<D>& b) {
    const std::uint32_t s = proxies_.add(id, b, kName);
    if (leaf_.size() < proxies_.slots()) {
      leaf_.resize(proxies_.slots(), kNone);
      buffered_.resize(proxies_.slots(), 0);
    }
    const std::uint32_t n = pool_.allocate(kName);
    pool_[n] = Node{fatten(b, b), kNone, kNone, s, 0};
    leaf_[s] = n;
    insert_leaf(n);
    buffer(s);
  }

  void move(Id id, const Box<D>& b) {
    check_box(b, "proxy box");
    const std::uint32_t s = proxies_.slot_of(id, kName);
    const Box<D> old = proxies_.box(s);
    proxies_.set_box(s, b);
    const std::uint32_t n = leaf_[s];
    const Box<D>& fat = pool_[n].box;
    if (loci::contains(fat, b) && !oversized(fat, b)) return;
    remove_leaf(n);
    pool_[n].box = fatten(b, old);
    insert_leaf(n);
    buffer(s);
  }

  bool remove(Id id) {
    const std::uint32_t s = proxies_.find(id);
    if (s == kNone) return false;
    remove_leaf(leaf_[s]);
    pool_.release(leaf_[s]);
    leaf_[s] = kNone;
    proxies_.remove(s);
    buffer(s);
    return true;
  }

  // Removes every proxy, as remove() would: the next update() reports their pairs as ended.
  void clear() {
    proxies_.clear();
    pool_.clear();
    root_ = kNone;
    leaf_.clear();
    buffered_.clear();
    moved_.clear();
    pairs_.clear();
  }

  bool contains(Id id) const { return proxies_.find(id) != kNone; }
  std::size_t size() const { return proxies_.size(); }
  bool empty() const { return size() == 0; }
  // Height of the tree (0 for one leaf, -1 when empty).
  int height() const { return root_ == kNone ? -1 : pool_[root_].height; }
  // Pairs whose fat boxes meet, as of the last tick.
  std::size_t candidate_pairs() const { return pairs_.size(); }

  template <PairVisitor F>
  QueryStats pairs(F&& visit) {
    QueryStats st;
    refresh_pairs(st);
    for (const std::uint64_t p : pairs_) {
      const std::uint32_t s = std::uint32_t(p >> 32), t = std::uint32_t(p);
      ++st.entries_tested;
      if (!intersects(proxies_.box(s), proxies_.box(t))) continue;
      ++st.results;
      const Id a = proxies_.id(s), b = proxies_.id(t);
      if (!(a < b ? visit(a, b) : visit(b, a))) break;
    }
    return st;
  }
  std::vector<IdPair> pairs() {
    return collect_pairs([&](auto&& v) { return pairs(v); });
  }

  template <PairVisitor Begin, PairVisitor End>
  QueryStats update(Begin&& begin, End&& end) {
    return tracker_.update([&](auto&& v) { return pairs(v); }, begin, end);
  }

  template <WindowVisitor<D> F>
  QueryStats query(const Box<D>& w, F&& visit) const {
    check_box(w, "query window");
    QueryStats st;
    detail::Scratch<std::uint32_t> stack;
    traverse(w, *stack, st, [&](std::uint32_t s) {
      const Box<D>& b = proxies_.box(s);
      if (!intersects(b, w)) return true;
      ++st.results;
      return bool(visit(proxies_.id(s), b));
    });
    return st;
  }
  std::vector<Id> query(const Box<D>& w) const {
    return collect_ids([&](auto&& v) { return query(w, v); });
  }

  void validate() const;

 private:
  static constexpr const char* kName = "DynamicAabbTree";

  struct Node {
    Box<D> box;            // fat box of a leaf, union of the children's otherwise (16 D bytes)
    std::uint32_t parent;  // parent node, kNone at the root; next free node while free (4)
    std::uint32_t child1;  // first child, kNone for a leaf (4)
    std::uint32_t child2;  // second child; for a leaf, the proxy's slot (4)
    std::int32_t height;   // 0 for a leaf, 1 + the taller child's otherwise (4)
    bool leaf() const { return child1 == kNone; }
  };

  // The cost measure of the surface-area heuristic: the sum of extents (half the perimeter in
  // 2D; proportional to the surface area's usual stand-in in 3D).
  static double cost(const Box<D>& b) { return b.margin(); }

  double margin_of(const Box<D>& b) const {
    double e = 0;
    for (int a = 0; a < D; ++a)
      e = std::max(e, b.extent(a));
    // A fraction of 0 adds nothing, also to an extent that overflows (0 * inf is NaN).
    return opt_.margin_fraction == 0 ? opt_.margin : opt_.margin + opt_.margin_fraction * e;
  }

  // b grown by the margin and stretched along the displacement from `before` (a jump of more
  // than a few box sizes is a teleport and predicts nothing; so does a displacement that
  // overflows, which a prediction of 0 would turn into NaN).
  Box<D> fatten(const Box<D>& b, const Box<D>& before) const {
    const double m = margin_of(b);
    Box<D> f = b;
    double reach = 4 * m;
    for (int a = 0; a < D; ++a)
      reach += 4 * b.extent(a);
    for (int a = 0; a < D; ++a) {
      const double d = opt_.prediction * (b.min[a] - before.min[a]);
      f.min[a] -= m;
      f.max[a] += m;
      if (!(std::abs(d) <= reach)) continue;
      if (d < 0)
        f.min[a] += d;
      else
        f.max[a] += d;
    }
    return f;
  }

  // A fat box much larger than a fresh one would be (a fast proxy that slowed down).
  bool oversized(const Box<D>& fat, const Box<D>& b) const {
    double slack = 0, allowed = 0;
    const double m = margin_of(b);
    for (int a = 0; a < D; ++a) {
      slack += fat.extent(a) - b.extent(a);
      allowed += 2 * m + 8 * m + 2 * b.extent(a);
    }
    return slack > allowed;
  }

  void buffer(std::uint32_t s) {
    if (!buffered_[s]) {
      buffered_[s] = 1;
      moved_.push_back(s);
    }
  }

  void refit(std::uint32_t n) {
    Node& x = pool_[n];
    x.box = merged(pool_[x.child1].box, pool_[x.child2].box);
    x.height = 1 + std::max(pool_[x.child1].height, pool_[x.child2].height);
  }

  void replace_child(std::uint32_t parent, std::uint32_t old_child, std::uint32_t new_child) {
    if (parent == kNone) {
      root_ = new_child;
    } else if (pool_[parent].child1 == old_child) {
      pool_[parent].child1 = new_child;
    } else {
      pool_[parent].child2 = new_child;
    }
    pool_[new_child].parent = parent;
  }

  std::uint32_t best_sibling(const Box<D>& b) const {
    std::uint32_t n = root_;
    while (!pool_[n].leaf()) {
      const Node& x = pool_[n];
      const double here = cost(x.box);
      const double combined = cost(merged(x.box, b));
      const double new_parent = 2 * combined;  // a new parent of x and the leaf
      const double inherited = 2 * (combined - here);
      auto descend = [&](std::uint32_t c) {
        const Box<D> u = merged(pool_[c].box, b);
        return inherited + (pool_[c].leaf() ? cost(u) : cost(u) - cost(pool_[c].box));
      };
      const double c1 = descend(x.child1), c2 = descend(x.child2);
      if (new_parent <= std::min(c1, c2)) break;
      n = c1 <= c2 ? x.child1 : x.child2;
    }
    return n;
  }

  void insert_leaf(std::uint32_t leaf) {
    if (root_ == kNone) {
      root_ = leaf;
      pool_[leaf].parent = kNone;
      return;
    }
    const Box<D> b = pool_[leaf].box;
    const std::uint32_t sibling = best_sibling(b);
    const std::uint32_t old_parent = pool_[sibling].parent;
    const std::uint32_t p = pool_.allocate(kName);
    pool_[p] = Node{merged(pool_[sibling].box, b), old_parent, sibling, leaf, 0};
    replace_child(old_parent, sibling, p);
    pool_[sibling].parent = p;
    pool_[leaf].parent = p;
    for (std::uint32_t n = p; n != kNone; n = pool_[n].parent) {
      refit(n);
      rotate(n);
    }
  }

  void remove_leaf(std::uint32_t leaf) {
    if (leaf == root_) {
      root_ = kNone;
      return;
    }
    const std::uint32_t p = pool_[leaf].parent;
    const std::uint32_t grand = pool_[p].parent;
    const std::uint32_t sibling = pool_[p].child1 == leaf ? pool_[p].child2 : pool_[p].child1;
    replace_child(grand, p, sibling);
    pool_.release(p);
    for (std::uint32_t n = grand; n != kNone; n = pool_[n].parent)
      refit(n);
  }

  // Swaps a child of n with a grandchild on the other side when that lowers the cost of the
  // child that changes; n's own box does not change.
  void rotate(std::uint32_t n) {
    const std::uint32_t b = pool_[n].child1, c = pool_[n].child2;
    double best = 0;
    std::uint32_t from = kNone, to = kNone,
                  under = kNone;  // swap `from` with `to`, child of `under`
    auto consider = [&](std::uint32_t inner, std::uint32_t moved) {
      // `inner` (a child of n) gives up one child to n and receives `moved` (n's other child).
      if (pool_[inner].leaf()) return;
      const std::uint32_t k1 = pool_[inner].child1, k2 = pool_[inner].child2;
      for (const std::uint32_t out : {k1, k2}) {
        const std::uint32_t stays = out == k1 ? k2 : k1;
        const double gain =
            cost(pool_[inner].box) - cost(merged(pool_[stays].box, pool_[moved].box));
        if (gain > best) best = gain, from = moved, to = out, under = inner;
      }
    };
    consider(c, b);
    consider(b, c);
    if (from == kNone) return;
    // `to` (child of `under`) moves up to n, `from` (child of n) moves down into `under`.
    if (pool_[n].child1 == from)
      pool_[n].child1 = to;
    else
      pool_[n].child2 = to;
    pool_[to].parent = n;
    if (pool_[under].child1 == to)
      pool_[under].child1 = from;
    else
      pool_[under].child2 = from;
    pool_[from].parent = under;
    refit(under);
    pool_[n].height = 1 + std::max(pool_[pool_[n].child1].height, pool_[pool_[n].child2].height);
  }

  // Calls on_leaf(slot) for every leaf whose fat box meets w, until it returns false.
  template <class F>
  void traverse(const Box<D>& w, std::vector<std::uint32_t>& stack, QueryStats& st,
                F&& on_leaf) const {
    if (root_ == kNone) return;
    stack.clear();
    stack.push_back(root_);
    while (!stack.empty()) {
      const std::uint32_t n = stack.back();
      stack.pop_back();
      const Node& x = pool_[n];
      ++st.entries_tested;
      if (!intersects(x.box, w)) continue;
      if (x.leaf()) {
        if (!on_leaf(x.child2)) return;
        continue;
      }
      ++st.nodes_visited;
      stack.push_back(x.child1);
      stack.push_back(x.child2);
    }
  }

  // Brings pairs_ up to date with the move buffer.
  void refresh_pairs(QueryStats& st) {
    if (moved_.empty()) return;
    std::erase_if(pairs_, [&](std::uint64_t p) {
      return buffered_[std::uint32_t(p >> 32)] || buffered_[std::uint32_t(p)];
    });
    fresh_.clear();
    for (const std::uint32_t s : moved_) {
      if (!proxies_.alive(s)) continue;
      traverse(pool_[leaf_[s]].box, stack_, st, [&](std::uint32_t t) {
        if (t != s && !(buffered_[t] && t < s))
          fresh_.push_back(s < t ? (std::uint64_t(s) << 32 | t) : (std::uint64_t(t) << 32 | s));
        return true;
      });
    }
    std::sort(fresh_.begin(), fresh_.end());
    merged_.resize(pairs_.size() + fresh_.size());
    std::merge(pairs_.begin(), pairs_.end(), fresh_.begin(), fresh_.end(), merged_.begin());
    pairs_.swap(merged_);
    for (const std::uint32_t s : moved_)
      buffered_[s] = 0;
    moved_.clear();
  }

  void swap(DynamicAabbTree& other) noexcept {
    std::swap(opt_, other.opt_);
    std::swap(proxies_, other.proxies_);
    pool_.swap(other.pool_);
    std::swap(tracker_, other.tracker_);
    std::swap(root_, other.root_);
    leaf_.swap(other.leaf_);
    buffered_.swap(other.buffered_);
    moved_.swap(other.moved_);
    pairs_.swap(other.pairs_);
    fresh_.swap(other.fresh_);
    merged_.swap(other.merged_);
    stack_.swap(other.stack_);
  }
  AabbTreeOptions opt_;
  detail::ProxyTable<D> proxies_;
  detail::NodePool<Node, &Node::parent> pool_;
  detail::PairTracker tracker_;
  std::uint32_t root_ = kNone;
  std::vector<std::uint32_t> leaf_;     // leaf node of each slot (4 bytes a slot)
  std::vector<std::uint8_t> buffered_;  // 1 while a slot is in the move buffer
  std::vector<std::uint32_t> moved_;    // the move buffer: slots added, re-inserted, removed
  std::vector<std::uint64_t> pairs_;    // (lower slot << 32 | higher slot), fat boxes meet
  std::vector<std::uint64_t> fresh_;    // scratch: new pairs of one tick
  std::vector<std::uint64_t> merged_;   // scratch: the merge of the two
  std::vector<std::uint32_t> stack_;    // traversal stack of the tick
};

template <int D>
void DynamicAabbTree<D>::validate() const {
  const std::string who = kName;
  proxies_.validate(kName);
  std::vector<bool> seen(pool_.size(), false);
  if (!pool_.validate_free(seen)) throw Error(who + ": free list is broken");
  std::size_t leaves = 0;
  if (root_ != kNone) {
    if (pool_[root_].parent != kNone) throw Error(who + ": root has a parent");
    std::vector<std::uint32_t> stack{root_};
    while (!stack.empty()) {
      const std::uint32_t n = stack.back();
      stack.pop_back();
      if (!pool_.contains(n) || seen[n])
        throw Error(who + ": node " + std::to_string(n) + " reached twice or free");
      seen[n] = true;
      const Node& x = pool_[n];
      for (int a = 0; a < D; ++a)
        if (!(x.box.min[a] <= x.box.max[a]))
          throw Error(who + ": node " + std::to_string(n) + " has a NaN or inverted box");
      if (x.leaf()) {
        ++leaves;
        const std::uint32_t s = x.child2;
        if (s >= proxies_.slots() || !proxies_.alive(s) || leaf_[s] != n)
          throw Error(who + ": leaf " + std::to_string(n) + " names a slot that is not its own");
        if (!loci::contains(x.box, proxies_.box(s)))
          throw Error(who + ": fat box of proxy " + std::to_string(proxies_.id(s)) +
                      " misses its box");
        if (x.height != 0) throw Error(who + ": leaf with a height");
        continue;
      }
      for (const std::uint32_t c : {x.child1, x.child2}) {
        if (!pool_.contains(c) || pool_[c].parent != n)
          throw Error(who + ": child link broken at node " + std::to_string(n));
        if (!loci::contains(x.box, pool_[c].box))
          throw Error(who + ": node " + std::to_string(n) + " does not contain its child");
        stack.push_back(c);
      }
      if (x.height != 1 + std::max(pool_[x.child1].height, pool_[x.child2].height))
        throw Error(who + ": wrong height at node " + std::to_string(n));
    }
  }
  if (leaves != proxies_.size()) throw Error(who + ": leaves and proxies differ in number");
  for (std::size_t n = 0; n < seen.size(); ++n)
    if (!seen[n])
      throw Error(who + ": node " + std::to_string(n) + " is neither reachable nor free");
  for (std::size_t i = 0; i < pairs_.size(); ++i) {
    const std::uint32_t s = std::uint32_t(pairs_[i] >> 32), t = std::uint32_t(pairs_[i]);
    if (i > 0 && pairs_[i - 1] >= pairs_[i]) throw Error(who + ": pair list not sorted and unique");
    if (s >= t || t >= proxies_.slots()) throw Error(who + ": malformed pair");
    if (moved_.empty()) {
      if (!proxies_.alive(s) || !proxies_.alive(t))
        throw Error(who + ": pair names a removed proxy");
      if (!intersects(pool_[leaf_[s]].box, pool_[leaf_[t]].box))
        throw Error(who + ": listed pair whose fat boxes are apart");
    }
  }
}

static_assert(BroadPhase<DynamicAabbTree<2>>);
static_assert(BroadPhase<DynamicAabbTree<3>>);

}  // namespace loci
