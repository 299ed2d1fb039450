// DynamicRTree<D, M, Policy>: the machinery every insertion-built R-tree shares.
//
// Guttman's R-tree ("R-trees: a dynamic index structure for spatial searching", SIGMOD 1984)
// and Beckmann et al.'s R*-tree (SIGMOD 1990) differ only in how an entry picks its subtree,
// how an overfull node is split, and whether an overfull node first gives entries back for
// reinsertion. Those three decisions come from `Policy`; the node pool, insertion, deletion
// with condensing, bulk loading, queries and validation live here once.
//
// Representation. Nodes sit in a NodePool addressed by 32-bit indices, released nodes on a free
// list threaded through their parent links, so a tree is copied, moved or saved as plain
// arrays. A node keeps its
// children's boxes structure-of-arrays (SoaBoxes), the child slots (a node index, or the
// entry's id in a leaf), its parent, its entry count and its level (0 = leaf). Each entry's
// box is exactly the union of its child's entries: insertion enlarges boxes on the way down,
// splits, reinsertion and deletion recompute them on the way up.
//
// Invariants (validate()): every non-root node holds between min_entries and M entries; the
// root is a leaf or has at least two entries; levels decrease by one from parent to child;
// parent links match; entry boxes are tight; the leaves hold size() entries; every node of the
// pool is reachable once or free once.
//
// Thread-safety: const member functions may run concurrently; insert, erase and update need
// exclusive access.
#pragma once

#include <algorithm>
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
#include "loci/index/detail/soa_boxes.hpp"
#include "loci/index/detail/str_partition.hpp"
#include "loci/index/query.hpp"

namespace loci {

namespace detail {

template <int D, int M, class Policy>
class DynamicRTree {
 public:
  static_assert(M >= 4 && M <= 64, "node capacity M must be in [4, 64]");
  static constexpr int dimension = D;
  static constexpr int max_entries = M;
  // 40% of M: the value Beckmann et al. found best for the R*-tree, used for both variants.
  static constexpr int min_entries = std::max(2, M * 2 / 5);

  struct Node {             // (16 D + 8) M + 8 bytes
    SoaBoxes<D, M> boxes;   // 16 D M: children's boxes, unused slots empty
    std::uint64_t slot[M];  // 8 M: the entry's id in a leaf, the child's index above
    std::uint32_t parent;   // 4: kNone at the root; next free node while on the free list
    std::uint16_t count;    // 2: slots in use
    std::uint16_t level;    // 2: 0 for a leaf
  };

  // An empty tree holds no node: the root leaf is made by the first insertion.
  DynamicRTree() = default;
  DynamicRTree(const DynamicRTree&) = default;
  DynamicRTree& operator=(const DynamicRTree&) = default;
  // Moving leaves `other` empty, as if default-constructed.
  DynamicRTree(DynamicRTree&& other) noexcept { swap(other); }
  DynamicRTree& operator=(DynamicRTree&& other) noexcept {
    DynamicRTree(std::move(other)).swap(*this);
    return *this;
  }

  // Builds a tree from (box, id) pairs by top-down STR tiling with near-equal node sizes, so
  // every node respects the minimum fill. Throws InvalidGeometry on a bad box.
  static DynamicRTree bulk_load(std::span<const std::pair<Box<D>, Id>> entries);

  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  int height() const { return root_ == kNone ? 1 : node(root_).level + 1; }
  Box<D> bounds() const {
    return root_ == kNone ? Box<D>::empty() : node(root_).boxes.bounds(node(root_).count);
  }
  std::size_t memory_bytes() const { return nodes_.memory_bytes(); }

  // Throws InvalidGeometry on a NaN, infinite or inverted box.
  void insert(const Box<D>& box, Id id) {
    check_box(box, "inserted box");
    reinserted_levels_ = 0;
    if (root_ == kNone) root_ = new_node(0);
    insert_at({box, id}, 0);
    ++size_;
  }
  // Removes one entry with exactly this box and id; false when there is none.
  bool erase(const Box<D>& box, Id id);
  // Moves entry `id` from old_box to new_box; false (and no change) when it is not there.
  bool update(const Box<D>& old_box, const Box<D>& new_box, Id id) {
    check_box(new_box, "updated box");
    if (!erase(old_box, id)) return false;
    insert(new_box, id);
    return true;
  }

  template <WindowVisitor<D> Visit>
  QueryStats query(const Box<D>& window, Visit&& visit, Relation rel = Relation::intersects) const;
  std::vector<Id> query(const Box<D>& window, Relation rel = Relation::intersects) const {
    return collect_ids([&](auto&& v) { return query(window, v, rel); });
  }

  template <NearestVisitor<D> Visit>
  QueryStats nearest(const Point<D>& p, std::size_t k, Visit&& visit) const;
  std::vector<Neighbor> nearest(const Point<D>& p, std::size_t k) const {
    return collect_neighbors([&](auto&& v) { return nearest(p, k, v); });
  }

  // Calls visit(id, box, distance) for the entries in increasing distance from p, one at a
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
  void swap(DynamicRTree& other) noexcept {
    nodes_.swap(other.nodes_);
    std::swap(root_, other.root_);
    std::swap(size_, other.size_);
    std::swap(reinserted_levels_, other.reinserted_levels_);
  }
  const Node& node(std::uint32_t n) const { return nodes_[n]; }
  Node& node(std::uint32_t n) { return nodes_[n]; }
  std::uint32_t new_node(int level);
  void free_node(std::uint32_t n) { nodes_.release(n); }
  int slot_of(std::uint32_t parent, std::uint32_t child) const;
  Entry<D> entry(std::uint32_t n, int i) const { return {node(n).boxes.box(i), node(n).slot[i]}; }
  void append(std::uint32_t n, const Entry<D>& e);
  void remove_slot(std::uint32_t n, int i);
  void refit_up(std::uint32_t n);

  void insert_at(const Entry<D>& e, int level);
  void place(std::uint32_t n, const Entry<D>& e);
  void reinsert(std::uint32_t n, const Entry<D>& extra);
  void split(std::uint32_t n, const Entry<D>& extra);
  void condense(std::uint32_t leaf);

  struct BulkItem {
    Point<D> c;
    Box<D> box;
    Id id;
  };
  std::uint32_t bulk_node(BulkItem* first, std::size_t count, int level, std::size_t cap);

  NodePool<Node, &Node::parent> nodes_;
  std::uint32_t root_ = kNone;
  std::size_t size_ = 0;
  std::uint64_t reinserted_levels_ = 0;  // R*: levels already treated by reinsertion
};

template <int D, int M, class P>
std::uint32_t DynamicRTree<D, M, P>::new_node(int level) {
  const std::uint32_t n = nodes_.allocate("R-tree");
  Node& nd = nodes_[n];
  nd.boxes.clear();
  nd.parent = kNone;
  nd.count = 0;
  nd.level = std::uint16_t(level);
  return n;
}

template <int D, int M, class P>
int DynamicRTree<D, M, P>::slot_of(std::uint32_t parent, std::uint32_t child) const {
  const Node& p = node(parent);
  for (int i = 0; i < p.count; ++i)
    if (p.slot[i] == child) return i;
  throw Error("R-tree corrupt: child not found in its parent");
}

template <int D, int M, class P>
void DynamicRTree<D, M, P>::append(std::uint32_t n, const Entry<D>& e) {
  Node& nd = node(n);
  nd.boxes.set(nd.count, e.box);
  nd.slot[nd.count] = e.slot;
  ++nd.count;
  if (nd.level > 0) node(std::uint32_t(e.slot)).parent = n;
}

template <int D, int M, class P>
void DynamicRTree<D, M, P>::remove_slot(std::uint32_t n, int i) {
  Node& nd = node(n);
  const int last = nd.count - 1;
  if (i != last) {
    nd.boxes.set(i, nd.boxes.box(last));
    nd.slot[i] = nd.slot[last];
  }
  nd.boxes.set(last, Box<D>::empty());
  --nd.count;
}

template <int D, int M, class P>
void DynamicRTree<D, M, P>::refit_up(std::uint32_t n) {
  while (n != root_) {
    const std::uint32_t p = node(n).parent;
    node(p).boxes.set(slot_of(p, n), node(n).boxes.bounds(node(n).count));
    n = p;
  }
}

template <int D, int M, class P>
void DynamicRTree<D, M, P>::insert_at(const Entry<D>& e, int level) {
  std::uint32_t n = root_;
  while (node(n).level > level) {
    const int i = P::choose_subtree(node(n).boxes, node(n).count, node(n).level, e.box);
    node(n).boxes.expand(i, e.box);
    n = std::uint32_t(node(n).slot[i]);
  }
  place(n, e);
}

template <int D, int M, class P>
void DynamicRTree<D, M, P>::place(std::uint32_t n, const Entry<D>& e) {
  if (node(n).count < M) {
    append(n, e);
    return;
  }
  const std::uint64_t bit = std::uint64_t(1) << node(n).level;
  if (P::forced_reinsert && n != root_ && !(reinserted_levels_ & bit)) {
    reinserted_levels_ |= bit;
    reinsert(n, e);
  } else {
    split(n, e);
  }
}

// R*-tree forced reinsertion: the entries whose centres lie farthest from the node's centre
// leave it and are inserted again from the root, nearest of them first ("close reinsert").
template <int D, int M, class P>
void DynamicRTree<D, M, P>::reinsert(std::uint32_t n, const Entry<D>& extra) {
  Entry<D> all[M + 1];
  for (int i = 0; i < M; ++i)
    all[i] = entry(n, i);
  all[M] = extra;
  Box<D> bounds = node(n).boxes.bounds(M);
  bounds.expand(extra.box);
  const Point<D> c = bounds.center();
  std::pair<double, int> order[M + 1];
  for (int i = 0; i <= M; ++i)
    order[i] = {squared_distance(all[i].box.center(), c), i};
  std::sort(order, order + M + 1);
  constexpr int kReinsert = std::max(1, M * 3 / 10);
  const int level = node(n).level;
  node(n).boxes.clear();
  node(n).count = 0;
  for (int i = 0; i <= M - kReinsert; ++i)
    append(n, all[order[i].second]);
  refit_up(n);
  for (int i = M - kReinsert + 1; i <= M; ++i)
    insert_at(all[order[i].second], level);
}

template <int D, int M, class P>
void DynamicRTree<D, M, P>::split(std::uint32_t n, const Entry<D>& extra) {
  Entry<D> all[M + 1];
  for (int i = 0; i < M; ++i)
    all[i] = entry(n, i);
  all[M] = extra;
  const int in_first = P::template split<D>(all, M + 1, min_entries);
  const int level = node(n).level;
  const std::uint32_t sibling = new_node(level);
  node(n).boxes.clear();
  node(n).count = 0;
  for (int i = 0; i < in_first; ++i)
    append(n, all[i]);
  for (int i = in_first; i <= M; ++i)
    append(sibling, all[i]);
  const Entry<D> sib{node(sibling).boxes.bounds(node(sibling).count), sibling};
  if (n == root_) {
    const std::uint32_t r = new_node(level + 1);
    append(r, {node(n).boxes.bounds(node(n).count), n});
    append(r, sib);
    root_ = r;
    return;
  }
  const std::uint32_t p = node(n).parent;
  node(p).boxes.set(slot_of(p, n), node(n).boxes.bounds(node(n).count));
  place(p, sib);
}

template <int D, int M, class P>
bool DynamicRTree<D, M, P>::erase(const Box<D>& box, Id id) {
  check_box(box, "erased box");
  if (root_ == kNone) return false;
  Scratch<std::uint32_t> scratch;
  auto& stack = *scratch;
  stack.push_back(root_);
  while (!stack.empty()) {
    const std::uint32_t n = stack.back();
    stack.pop_back();
    const Node& nd = node(n);
    if (nd.level == 0) {
      for (int i = 0; i < nd.count; ++i) {
        if (nd.slot[i] == id && nd.boxes.box(i) == box) {
          remove_slot(n, i);
          --size_;
          condense(n);
          return true;
        }
      }
      continue;
    }
    for (auto m = nd.boxes.containing(box); m;)
      stack.push_back(std::uint32_t(nd.slot[pop_lowest(m)]));
  }
  return false;
}

// Guttman's CondenseTree: underfull nodes on the path to the root are dissolved and their
// entries inserted again at their own level; the other boxes on the path are tightened.
template <int D, int M, class P>
void DynamicRTree<D, M, P>::condense(std::uint32_t n) {
  std::vector<std::pair<Entry<D>, int>> orphans;
  while (n != root_) {
    const std::uint32_t p = node(n).parent;
    const int i = slot_of(p, n);
    if (node(n).count < min_entries) {
      for (int j = 0; j < node(n).count; ++j)
        orphans.push_back({entry(n, j), node(n).level});
      remove_slot(p, i);
      free_node(n);
    } else {
      node(p).boxes.set(i, node(n).boxes.bounds(node(n).count));
    }
    n = p;
  }
  for (const auto& [e, level] : orphans) {
    reinserted_levels_ = 0;
    insert_at(e, level);
  }
  while (node(root_).level > 0 && node(root_).count == 1) {
    const std::uint32_t old = root_;
    root_ = std::uint32_t(node(old).slot[0]);
    node(root_).parent = kNone;
    free_node(old);
  }
}

template <int D, int M, class P>
DynamicRTree<D, M, P> DynamicRTree<D, M, P>::bulk_load(
    std::span<const std::pair<Box<D>, Id>> entries) {
  DynamicRTree t;
  if (entries.empty()) return t;
  std::vector<BulkItem> items(entries.size());
  for (std::size_t i = 0; i < entries.size(); ++i) {
    check_box(entries[i].first, ("box " + std::to_string(i)).c_str());
    items[i] = {entries[i].first.center(), entries[i].first, entries[i].second};
  }
  int level = 0;
  std::size_t cap = M;  // entries a subtree rooted at `level` can hold
  while (cap < items.size()) {
    ++level;
    cap *= M;
  }
  t.nodes_.clear();
  t.nodes_.reserve(items.size() / (M / 2) + 8);
  t.root_ = t.bulk_node(items.data(), items.size(), level, cap / M);
  t.size_ = items.size();
  return t;
}

// Builds the subtree of `count` items at `level`; `cap` is what one child subtree may hold.
template <int D, int M, class P>
std::uint32_t DynamicRTree<D, M, P>::bulk_node(BulkItem* first, std::size_t count, int level,
                                               std::size_t cap) {
  const std::uint32_t n = new_node(level);
  if (level == 0) {
    for (std::size_t i = 0; i < count; ++i)
      append(n, {first[i].box, first[i].id});
    return n;
  }
  const std::size_t k = (count + cap - 1) / cap;
  std::size_t cuts[M + 1];
  for (std::size_t g = 0; g <= k; ++g)
    cuts[g] = g * count / k;
  str_tile<D>(first, std::span<const std::size_t>(cuts, k + 1),
              [](const BulkItem& it, int axis) { return it.c[axis]; });
  for (std::size_t g = 0; g < k; ++g) {
    const std::uint32_t child =
        bulk_node(first + cuts[g], cuts[g + 1] - cuts[g], level - 1, cap / M);
    append(n, {node(child).boxes.bounds(node(child).count), child});
  }
  return n;
}

template <int D, int M, class P>
template <WindowVisitor<D> Visit>
QueryStats DynamicRTree<D, M, P>::query(const Box<D>& window, Visit&& visit, Relation rel) const {
  check_box(window, "query window");
  QueryStats s;
  if (root_ == kNone) return s;
  Scratch<std::uint32_t> scratch;
  auto& stack = *scratch;
  stack.push_back(root_);
  while (!stack.empty()) {
    const Node& nd = node(stack.back());
    stack.pop_back();
    ++s.nodes_visited;
    s.entries_tested += nd.count;
    auto hits =
        rel == Relation::contains ? nd.boxes.containing(window) : nd.boxes.intersecting(window);
    if (nd.level > 0) {
      while (hits)
        stack.push_back(std::uint32_t(nd.slot[pop_lowest(hits)]));
      continue;
    }
    if (rel == Relation::within) hits &= nd.boxes.inside(window);
    while (hits) {
      const int i = pop_lowest(hits);
      ++s.results;
      if (!visit(Id(nd.slot[i]), nd.boxes.box(i))) return s;
    }
  }
  return s;
}

template <int D, int M, class P>
template <NearestVisitor<D> Visit>
QueryStats DynamicRTree<D, M, P>::nearest(const Point<D>& p, std::size_t k, Visit&& visit) const {
  check_point(p, "query point");
  if (k == 0) throw InvalidArgument("nearest-n query needs k >= 1");
  if (empty()) return {};
  return walk_nearest(p, visit, [k](std::uint64_t root, auto& expand, auto& report) {
    return detail::best_first(root, k, expand, report);
  });
}

template <int D, int M, class P>
template <NearestVisitor<D> Visit>
QueryStats DynamicRTree<D, M, P>::browse(const Point<D>& p, Visit&& visit) const {
  check_point(p, "query point");
  if (empty()) return {};
  return walk_nearest(p, visit, [](std::uint64_t root, auto& expand, auto& report) {
    return detail::browse(root, expand, report);
  });
}

template <int D, int M, class P>
template <class Visit, class Walk>
QueryStats DynamicRTree<D, M, P>::walk_nearest(const Point<D>& p, Visit& visit, Walk&& walk) const {
  auto expand = [&](std::uint64_t ref, auto& sink) -> std::size_t {
    const Node& nd = node(std::uint32_t(ref));
    double d2[decltype(nd.boxes)::kSlots];
    nd.boxes.squared_distances(p, d2);
    if (nd.level == 0)
      sink.push_entries(
          d2, nd.count, [&](int i) { return ref * M + i; }, [&](int i) { return Id(nd.slot[i]); });
    else
      sink.push_subtrees(d2, nd.count, [&](int i) { return nd.slot[i]; });
    return std::size_t(nd.count);
  };
  auto report = [&](Id id, std::uint64_t ref, double d) {
    return visit(id, node(std::uint32_t(ref / M)).boxes.box(int(ref % M)), d);
  };
  return walk(root_, expand, report);
}

template <int D, int M, class P>
void DynamicRTree<D, M, P>::validate() const {
  auto fail = [](const std::string& what) { throw Error("R-tree invalid: " + what); };
  if (root_ == kNone) {
    if (size_ != 0 || nodes_.in_use() != 0) fail("entries or nodes without a root");
    return;
  }
  if (!nodes_.contains(root_) || node(root_).parent != kNone) fail("bad root");
  if (node(root_).level > 0 && node(root_).count < 2) fail("inner root with fewer than 2 entries");
  std::size_t items = 0;
  std::vector<bool> seen(nodes_.size(), false);
  if (!nodes_.validate_free(seen)) fail("free list corrupt");
  if (seen[root_]) fail("root is on the free list");
  seen[root_] = true;
  std::size_t reachable = 1;
  std::vector<std::uint32_t> stack{root_};
  while (!stack.empty()) {
    const std::uint32_t n = stack.back();
    stack.pop_back();
    const Node& nd = node(n);
    const std::string where =
        "node " + std::to_string(n) + " (level " + std::to_string(nd.level) + ")";
    if (nd.count > M) fail(where + " overfull");
    if (n != root_ && nd.count < min_entries) fail(where + " underfull");
    for (int i = nd.count; i < M; ++i)
      if (!(nd.boxes.box(i) == Box<D>::empty())) fail(where + " unused slot not empty");
    if (nd.level == 0) {
      items += nd.count;
      for (int i = 0; i < nd.count; ++i)
        if (nd.boxes.box(i).is_empty()) fail(where + " holds an empty box");
      continue;
    }
    for (int i = 0; i < nd.count; ++i) {
      const auto c = std::uint32_t(nd.slot[i]);
      if (!nodes_.contains(c) || seen[c]) fail(where + " points outside the pool or twice");
      seen[c] = true;
      const Node& ch = node(c);
      if (ch.parent != n) fail(where + " child's parent link is wrong");
      if (ch.level + 1 != nd.level) fail(where + " child level is not one below");
      if (!(ch.boxes.bounds(ch.count) == nd.boxes.box(i))) fail(where + " entry box is not tight");
      stack.push_back(c);
      ++reachable;
    }
  }
  if (reachable != nodes_.in_use()) fail("nodes leaked from the pool");
  if (items != size_)
    fail("leaves hold " + std::to_string(items) + " entries, size() is " + std::to_string(size_));
}

}  // namespace detail
}  // namespace loci
