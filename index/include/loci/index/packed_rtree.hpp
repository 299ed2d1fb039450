// PackedRTree<D, NodeSize>: a static R-tree bulk-loaded from a known set of boxes.
//
// Packing. The boxes are ordered once, either along a Hilbert curve through their centres
// (Kamel and Faloutsos, "On Packing R-trees", CIKM 1993; the order flatbush uses) or by
// Sort-Tile-Recursive tiling applied from the root down (Leutenegger et al., ICDE 1997), and
// then cut into nodes of exactly NodeSize entries. Every node is full except the last one of
// each level.
//
// Layout. The tree is implicit, as in flatbush: level 0 holds the entries in packed order,
// level l+1 holds one box per node of level l, and entry e of level l is the bounding box of
// node e of level l-1. No child links are stored; entry e of level l covers the contiguous
// run of items [e * NodeSize^l, (e+1) * NodeSize^l), which is what lets a window query report
// a node that lies entirely inside the window without testing its entries. Nodes are stored
// as SoaBoxes blocks (structure of arrays, unused slots empty) so a node's test is a few
// vector instructions. Item i of the builder is reported with id i. Memory: one block of
// 2 * D * NodeSize doubles per node plus a 32-bit item index per slot of level 0, about
// 36 * (1 + 1/(NodeSize-1)) bytes per 2D box.
//
// Invariants (checked by validate()): every entry of level l+1 is exactly the union of its
// node's entries; unused slots are empty; level 0 holds a permutation of 0..size()-1.
//
// Complexity: build O(n log n); window query O(log n + hits) on well-spread data; nearest-n
// best first. Thread-safety: a finished tree is immutable and may be queried from any number
// of threads at once.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "loci/geom/box.hpp"
#include "loci/geom/error.hpp"
#include "loci/index/detail/best_first.hpp"
#include "loci/index/detail/hilbert.hpp"
#include "loci/index/detail/lazy_check.hpp"
#include "loci/index/detail/radix_sort.hpp"
#include "loci/index/detail/scratch.hpp"
#include "loci/index/detail/soa_boxes.hpp"
#include "loci/index/detail/str_partition.hpp"
#include "loci/index/query.hpp"

namespace loci {

enum class Packing : std::uint8_t { hilbert = 0, str = 1 };

template <int D, int NodeSize = 16>
class PackedRTree {
 public:
  using Block = detail::SoaBoxes<D, NodeSize>;
  static constexpr int dimension = D;
  static constexpr int node_size = NodeSize;

  // Collects boxes, then finish() packs them. Throws InvalidGeometry on a NaN, infinite or
  // inverted box, naming its index.
  class Builder {
   public:
    explicit Builder(std::size_t expected = 0) { boxes_.reserve(expected); }
    std::uint32_t add(const Box<D>& b) {
      if (!is_valid(b)) check_box(b, ("box " + std::to_string(boxes_.size())).c_str());
      if (boxes_.size() >= std::numeric_limits<std::uint32_t>::max())
        throw InvalidArgument("PackedRTree holds at most 2^32 - 2 boxes");
      boxes_.push_back(b);
      return static_cast<std::uint32_t>(boxes_.size() - 1);
    }
    std::size_t size() const { return boxes_.size(); }
    PackedRTree finish(Packing packing = Packing::hilbert) && {
      PackedRTree t(boxes_, packing);
      boxes_ = {};
      return t;
    }

   private:
    std::vector<Box<D>> boxes_;
  };

  PackedRTree() = default;
  PackedRTree(const PackedRTree&) = delete;
  PackedRTree& operator=(const PackedRTree&) = delete;
  // Moving leaves `other` empty, as if default-constructed.
  PackedRTree(PackedRTree&& other) noexcept : PackedRTree() { swap(other); }
  PackedRTree& operator=(PackedRTree&& other) noexcept {
    PackedRTree(std::move(other)).swap(*this);
    return *this;
  }

  // Builds from boxes; box i gets id i. Throws InvalidGeometry on a bad box.
  static PackedRTree build(std::span<const Box<D>> boxes, Packing packing = Packing::hilbert) {
    // Checked in place and packed from the caller's array: no copy of the boxes is made.
    if (boxes.size() > std::numeric_limits<std::uint32_t>::max())
      throw InvalidArgument("PackedRTree holds at most 2^32 - 2 boxes");
    for (std::size_t i = 0; i < boxes.size(); ++i)
      if (!is_valid(boxes[i])) check_box(boxes[i], ("box " + std::to_string(i)).c_str());
    return PackedRTree(boxes, packing);
  }

  // Wraps arrays laid out as blocks() and item_indices() return them (for instance from a
  // memory-mapped file). `keep_alive` owns the memory (and `check`, when given). The arrays
  // are trusted to be a valid tree of `size` items; call validate() when they come from an
  // untrusted source. With `check`, every read of the arrays is first handed to
  // check->touch(), which verifies the bytes the first time they are read.
  static PackedRTree adopt(std::size_t size, Packing packing, std::span<const Block> blocks,
                           std::span<const std::uint32_t> item_indices,
                           std::shared_ptr<const void> keep_alive,
                           const detail::LazyCheck* check = nullptr) {
    if (size > std::numeric_limits<std::uint32_t>::max() - 1)
      throw Error("packed R-tree arrays hold more than 2^32 - 2 items");
    PackedRTree t;
    t.size_ = size;
    t.packing_ = packing;
    t.compute_levels();
    const std::size_t slots = size == 0 ? 0 : t.level_blocks(0) * NodeSize;
    if (blocks.size() != t.total_blocks() || item_indices.size() != slots)
      throw Error("packed R-tree arrays do not match its item count");
    t.blocks_ = blocks.data();
    t.items_ = item_indices.data();
    t.keep_alive_ = std::move(keep_alive);
    t.check_ = check;
    return t;
  }

  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  Packing packing() const { return packing_; }
  int levels() const { return static_cast<int>(levels_.size()); }
  // The most levels a tree of at most 2^32 items has.
  static constexpr int kMaxLevels = [] {
    int l = 1;
    for (std::uint64_t covered = NodeSize; covered < (std::uint64_t(1) << 32); covered *= NodeSize)
      ++l;
    return l;
  }();
  Box<D> bounds() const {
    return empty() ? Box<D>::empty() : root_block().bounds(int(levels_.back().entries));
  }
  // Box of item id (its builder index).
  Box<D> item_box(Id id) const;

  // The implicit layout. Level l (0 = the items, levels() - 1 = the root) holds `entries`
  // boxes in `blocks` blocks, the first at blocks()[first_block]; entry e of level l covers
  // the items [e * span, (e + 1) * span) in packed order.
  struct Level {
    std::size_t entries;
    std::size_t first_block;
    std::size_t blocks;
    std::size_t span;
  };
  // The levels of a tree of `items` items (none when it is empty): what a file holding one
  // must contain.
  static std::vector<Level> layout(std::size_t items) {
    std::vector<Level> out;
    for (std::size_t count = items, first = 0, span = 1; count > 0; span *= NodeSize) {
      const std::size_t nblocks = (count + NodeSize - 1) / NodeSize;
      out.push_back({count, first, nblocks, span});
      if (nblocks == 1) break;
      first += nblocks;
      count = nblocks;
    }
    return out;
  }
  static std::size_t block_count(std::size_t items) {
    const auto l = layout(items);
    return l.empty() ? 0 : l.back().first_block + l.back().blocks;
  }
  const Level& level(int l) const { return levels_[std::size_t(l)]; }

  // The whole arrays (for an adopted tree with a check, verified first).
  std::span<const Block> blocks() const {
    const std::span<const Block> all{blocks_, total_blocks()};
    if (check_) check_->touch(all.data(), all.size_bytes());
    return all;
  }
  std::span<const std::uint32_t> item_indices() const {
    const std::span<const std::uint32_t> all{items_, empty() ? 0 : level_blocks(0) * NodeSize};
    if (check_) check_->touch(all.data(), all.size_bytes());
    return all;
  }
  std::size_t memory_bytes() const {
    return total_blocks() * sizeof(Block) + item_indices().size() * sizeof(std::uint32_t);
  }

  // Calls visit(id, box) for each item in relation `rel` with `window`; stops when it returns
  // false. Throws InvalidGeometry on a bad window.
  template <WindowVisitor<D> Visit>
  QueryStats query(const Box<D>& window, Visit&& visit, Relation rel = Relation::intersects) const;
  std::vector<Id> query(const Box<D>& window, Relation rel = Relation::intersects) const {
    return collect_ids([&](auto&& v) { return query(window, v, rel); });
  }
  // query() for a caller that keeps its own arrays in packed order: visit(pos, box) gets the
  // packed position (item_at(pos) is the id). ahead(pos) announces the leaf holding positions
  // [pos, pos + node_size) before any of them is visited, as early as the walk knows it will
  // read that leaf, so the caller can prefetch what it will read for them.
  template <class Visit, class Ahead>
  QueryStats query_packed(const Box<D>& window, Visit&& visit, Ahead&& ahead,
                          Relation rel = Relation::intersects) const {
    return walk_window<true>(window, visit, ahead, rel);
  }

  // Calls visit(id, box, distance) for the k items nearest to p, nearest first; stops when it
  // returns false. Throws InvalidArgument for k = 0, InvalidGeometry for a bad point.
  template <NearestVisitor<D> Visit>
  QueryStats nearest(const Point<D>& p, std::size_t k, Visit&& visit) const;
  std::vector<Neighbor> nearest(const Point<D>& p, std::size_t k) const {
    return collect_neighbors([&](auto&& v) { return nearest(p, k, v); });
  }

  // Calls visit(id, box, distance) for the items in increasing distance from p, one at a
  // time, until it returns false (distance browsing: nothing is fixed in advance, each answer
  // costs what it takes to find it). Throws InvalidGeometry for a bad point.
  template <NearestVisitor<D> Visit>
  QueryStats browse(const Point<D>& p, Visit&& visit) const;
  // browse() that asks keep(first, last, distance) before an entry or subtree waits in the
  // queue, [first, last) being the packed positions of the items it covers (item_at) and
  // distance its box's from p; false drops it with all it covers. Callers that group items
  // (the segments of one feature) use it to skip whole runs of a group already answered.
  template <NearestVisitor<D> Visit, class Keep>
  QueryStats browse(const Point<D>& p, Visit&& visit, Keep&& keep) const;
  // Calls visit(id, box, key) for the items in increasing key(box) (a double >= 0, or
  // infinity to leave the box and all under it out), one at a time, until it returns false.
  // key must not decrease from a node's box to the boxes inside it: the order along a ray,
  // for example (the first hit of a line of sight, without enumerating all it crosses).
  template <class Key, class Visit>
  QueryStats ordered(Key&& key, Visit&& visit) const;
  // The id and the box of the item at packed position pos < size().
  Id item_at(std::size_t pos) const { return Id(item_index(pos)); }
  Box<D> box_at(std::size_t pos) const { return leaf_box(pos); }
  // The boxes of the items at packed positions [b * NodeSize, (b + 1) * NodeSize), leaf b
  // (slots past size() hold the empty box), read at once.
  const Block& leaf(std::size_t b) const { return block(0, b); }
  // Announces that leaf b < level(0).blocks and its item indices will be read soon (nothing
  // is read or verified now).
  void prefetch_leaf(std::size_t b) const {
    blocks_[level(0).first_block + b].prefetch();
    __builtin_prefetch(items_ + b * NodeSize);
  }
  // The box of entry e < level(l).entries of level l (level 0: box_at(e)).
  Box<D> entry_box(int l, std::size_t e) const {
    return block(l, e / NodeSize).box(int(e % NodeSize));
  }

  // Throws loci::Error describing the first broken invariant.
  void validate() const;

 private:
  // Runs walk(root, expand, report), detail::best_first or detail::browse, with this
  // tree's expansion around p.
  template <class Visit, class Walk, class Keep>
  QueryStats walk_nearest(const Point<D>& p, Visit& visit, Walk&& walk, Keep&& keep) const;
  struct KeepAll {
    bool operator()(std::size_t, std::size_t, double) const { return true; }
  };
  PackedRTree(std::span<const Box<D>> boxes, Packing packing);

  struct Item {
    Point<D> c;
    std::uint32_t index;
  };

  void swap(PackedRTree& other) noexcept {
    std::swap(size_, other.size_);
    std::swap(packing_, other.packing_);
    levels_.swap(other.levels_);
    std::swap(blocks_, other.blocks_);
    std::swap(items_, other.items_);
    own_blocks_.swap(other.own_blocks_);
    own_items_.swap(other.own_items_);
    keep_alive_.swap(other.keep_alive_);
    std::swap(check_, other.check_);
  }
  void compute_levels() { levels_ = layout(size_); }
  std::size_t level_blocks(int l) const { return level(l).blocks; }
  std::size_t total_blocks() const {
    return levels_.empty() ? 0 : levels_.back().first_block + levels_.back().blocks;
  }
  const Block& block(int l, std::size_t b) const {
    const Block& node = blocks_[level(l).first_block + b];
    if (check_) [[unlikely]]
      check_->touch(&node, sizeof(Block));
    return node;
  }
  const Block& root_block() const { return block(levels() - 1, 0); }
  std::uint32_t item_index(std::size_t pos) const {
    if (check_) [[unlikely]]
      check_->touch(items_ + pos, sizeof(std::uint32_t));
    return items_[pos];
  }
  Box<D> leaf_box(std::size_t pos) const {
    return block(0, pos / NodeSize).box(int(pos % NodeSize));
  }

  // order[pos] = the builder index of the item packed at position pos.
  void order_hilbert(std::span<const Box<D>> boxes, std::uint32_t* order) const;
  void order_str(std::span<const Box<D>> boxes, std::uint32_t* order) const;
  void tile(Item* base, std::size_t first, std::size_t count, std::size_t cap) const;

  // Counts and reports the item at packed position pos (by position or by id).
  template <bool ByPosition, class Visit>
  bool report(std::size_t pos, const Box<D>& box, Visit& visit, QueryStats& s) const {
    ++s.results;
    if constexpr (ByPosition)
      return visit(pos, box);
    else
      return visit(Id(item_index(pos)), box);
  }
  template <bool ByPosition, class Visit, class Ahead>
  bool report_run(std::size_t first, std::size_t last, Visit& visit, Ahead& ahead,
                  QueryStats& s) const;
  template <bool ByPosition, class Visit, class Ahead>
  QueryStats walk_window(const Box<D>& window, Visit& visit, Ahead& ahead, Relation rel) const;

  std::size_t size_ = 0;
  Packing packing_ = Packing::hilbert;
  std::vector<Level> levels_;  // layout(size_)
  const Block* blocks_ = nullptr;
  const std::uint32_t* items_ = nullptr;
  // Owned storage, left uninitialised on allocation: the build writes every slot.
  std::unique_ptr<Block[]> own_blocks_;
  std::unique_ptr<std::uint32_t[]> own_items_;
  std::shared_ptr<const void> keep_alive_;
  const detail::LazyCheck* check_ = nullptr;  // owned by keep_alive_
};

template <int D, int NodeSize>
PackedRTree<D, NodeSize>::PackedRTree(std::span<const Box<D>> boxes, Packing packing)
    : size_(boxes.size()), packing_(packing) {
  compute_levels();
  if (size_ == 0) return;

  const std::size_t slots = level_blocks(0) * NodeSize;
  own_blocks_.reset(new Block[total_blocks()]);
  if constexpr (Block::kSlots != NodeSize)  // an odd size: the padding slot stays empty
    for (std::size_t b = 0; b < total_blocks(); ++b)
      own_blocks_[b].clear();
  own_items_.reset(new std::uint32_t[slots]);
  std::uint32_t* order = own_items_.get();
  if (packing == Packing::hilbert)
    order_hilbert(boxes, order);
  else
    order_str(boxes, order);

  // A gather in packed order: prefetching a few items ahead hides most of its cache misses.
  constexpr std::size_t kAhead = 8;
  for (std::size_t pos = 0; pos < slots; ++pos) {
    if (pos + kAhead < size_) __builtin_prefetch(&boxes[order[pos + kAhead]]);
    Block& block = own_blocks_[pos / NodeSize];
    if (pos < size_) {
      block.set(int(pos % NodeSize), boxes[order[pos]]);
    } else {
      block.set(int(pos % NodeSize), Box<D>::empty());
      order[pos] = std::numeric_limits<std::uint32_t>::max();
    }
  }
  for (int l = 1; l < levels(); ++l) {
    const std::size_t below = level(l - 1).first_block;
    for (std::size_t e = 0; e < level_blocks(l) * NodeSize; ++e) {
      Block& block = own_blocks_[level(l).first_block + e / NodeSize];
      if (e < level(l).entries) {
        const int used = int(std::min<std::size_t>(NodeSize, level(l - 1).entries - e * NodeSize));
        block.set(int(e % NodeSize), own_blocks_[below + e].bounds(used));
      } else {
        block.set(int(e % NodeSize), Box<D>::empty());
      }
    }
  }
  blocks_ = own_blocks_.get();
  items_ = own_items_.get();
}

template <int D, int NodeSize>
void PackedRTree<D, NodeSize>::order_hilbert(std::span<const Box<D>> boxes,
                                             std::uint32_t* order) const {
  // Centres as the sum of halves: min + max of boxes beyond 9e307 overflows, and the same
  // centre otherwise.
  const auto centre = [](const Box<D>& b) {
    Point<D> c;
    for (int a = 0; a < D; ++a)
      c[a] = b.min[a] / 2 + b.max[a] / 2;
    return c;
  };
  Box<D> extent = Box<D>::empty();
  for (const auto& b : boxes)
    extent.expand(centre(b));
  const detail::HilbertGrid<D> grid(extent);
  if constexpr (D == 2) {
    // 32-bit keys: key and index share one 64-bit word, halving the sort's memory traffic.
    std::vector<std::uint64_t> keyed(boxes.size());
    for (std::size_t i = 0; i < boxes.size(); ++i)
      keyed[i] = (grid.key(centre(boxes[i])) << 32) | i;
    detail::radix_sort(keyed, 32, 32, [](std::uint64_t v) { return v; });
    for (std::size_t i = 0; i < boxes.size(); ++i)
      order[i] = std::uint32_t(keyed[i]);
  } else {
    std::vector<detail::KeyedIndex> keyed(boxes.size());
    for (std::size_t i = 0; i < boxes.size(); ++i)
      keyed[i] = {grid.key(centre(boxes[i])), std::uint32_t(i)};
    detail::radix_sort(keyed, 0, D * detail::hilbert_bits<D>(),
                       [](const detail::KeyedIndex& k) { return k.key; });
    for (std::size_t i = 0; i < boxes.size(); ++i)
      order[i] = keyed[i].index;
  }
}

template <int D, int NodeSize>
void PackedRTree<D, NodeSize>::order_str(std::span<const Box<D>> boxes,
                                         std::uint32_t* order) const {
  std::vector<Item> items(boxes.size());
  for (std::size_t i = 0; i < boxes.size(); ++i)
    items[i] = {boxes[i].center(), std::uint32_t(i)};
  tile(items.data(), 0, items.size(), levels_.back().span);
  for (std::size_t i = 0; i < items.size(); ++i)
    order[i] = items[i].index;
}

// Orders items[first, first + count) into groups of `cap` items (the last may be short), then
// each group into groups of cap / NodeSize, down to leaf nodes.
template <int D, int NodeSize>
void PackedRTree<D, NodeSize>::tile(Item* base, std::size_t first, std::size_t count,
                                    std::size_t cap) const {
  if (cap <= 1 || count <= 1) return;
  std::size_t cuts[NodeSize + 1];
  const std::size_t groups = (count + cap - 1) / cap;
  for (std::size_t g = 0; g < groups; ++g)
    cuts[g] = first + g * cap;
  cuts[groups] = first + count;
  detail::str_tile<D>(base, std::span<const std::size_t>(cuts, groups + 1),
                      [](const Item& it, int axis) { return it.c[axis]; });
  for (std::size_t g = 0; g < groups; ++g)
    tile(base, cuts[g], cuts[g + 1] - cuts[g], cap / NodeSize);
}

template <int D, int NodeSize>
Box<D> PackedRTree<D, NodeSize>::item_box(Id id) const {
  for (std::size_t pos = 0; pos < size_; ++pos)
    if (item_index(pos) == id) return leaf_box(pos);
  throw InvalidArgument("no item with id " + std::to_string(id));
}

template <int D, int NodeSize>
template <bool ByPosition, class Visit, class Ahead>
bool PackedRTree<D, NodeSize>::report_run(std::size_t first, std::size_t last, Visit& visit,
                                          Ahead& ahead, QueryStats& s) const {
  // first is the start of a leaf; each leaf is announced while the one before it is read.
  last = std::min(last, size_);
  if (first < last) ahead(first);
  for (std::size_t pos = first; pos < last; ++pos) {
    if (pos % NodeSize == 0 && pos + NodeSize < last) ahead(pos + NodeSize);
    if (!report<ByPosition>(pos, leaf_box(pos), visit, s)) return false;
  }
  return true;
}

template <int D, int NodeSize>
template <WindowVisitor<D> Visit>
QueryStats PackedRTree<D, NodeSize>::query(const Box<D>& window, Visit&& visit,
                                           Relation rel) const {
  const auto no_ahead = [](std::size_t) {};
  return walk_window<false>(window, visit, no_ahead, rel);
}

template <int D, int NodeSize>
template <bool ByPosition, class Visit, class Ahead>
QueryStats PackedRTree<D, NodeSize>::walk_window(const Box<D>& window, Visit& visit, Ahead& ahead,
                                                 Relation rel) const {
  check_box(window, "query window");
  QueryStats s;
  if (empty()) return s;
  // The internal levels are walked depth first. The leaves they lead to are not read at once:
  // each is fetched as soon as it is found and read a little later, a batch at a time, so the
  // cache misses of a batch overlap instead of following one another.
  // Both buffers are bounded, so they live on the call's stack: the depth-first stack holds
  // fewer than NodeSize entries a level, and the leaves at most a batch and one node's.
  constexpr std::size_t kBatch = 32;
  detail::FixedStack<std::uint64_t, std::size_t(kMaxLevels) * NodeSize> stack;
  detail::FixedStack<std::uint64_t, kBatch + NodeSize> leaves;  // block << 1 | 1: all inside
  const auto read_leaves = [&]() -> bool {
    for (const std::uint64_t x : leaves) {
      const std::size_t b = std::size_t(x >> 1);
      if (x & 1) {
        if (!report_run<ByPosition>(b * NodeSize, (b + 1) * NodeSize, visit, ahead, s))
          return false;
        continue;
      }
      const Block& node = block(0, b);
      ++s.nodes_visited;
      s.entries_tested += std::min<std::size_t>(NodeSize, level(0).entries - b * NodeSize);
      auto hits = rel == Relation::contains ? node.containing(window) : node.intersecting(window);
      if (rel == Relation::within) hits &= node.inside(window);
      const std::size_t base = b * NodeSize;
      while (hits) {
        const int i = detail::pop_lowest(hits);
        if (!report<ByPosition>(base + std::size_t(i), node.box(i), visit, s)) return false;
      }
    }
    leaves.clear();
    return true;
  };
  if (levels() == 1) {
    ahead(std::size_t(0));
    leaves.push_back(0);
  } else {
    stack.push_back(std::uint64_t(levels() - 1) << 32);
  }
  while (!stack.empty()) {
    const std::uint64_t top = stack.back();
    stack.pop_back();
    const int level = int(top >> 32);
    const std::size_t b = std::size_t(top & 0xffffffffu);
    const Block& node = block(level, b);
    ++s.nodes_visited;
    s.entries_tested += std::min<std::size_t>(NodeSize, this->level(level).entries - b * NodeSize);
    auto hits = rel == Relation::contains ? node.containing(window) : node.intersecting(window);
    if (!hits) continue;
    const std::size_t base = b * NodeSize;
    auto inside = rel == Relation::contains ? decltype(hits)(0) : node.inside(window) & hits;
    hits &= ~inside;
    if (level == 1) {
      for (auto all = hits | inside; all;) {
        const int i = detail::pop_lowest(all);
        const std::size_t e = base + std::size_t(i);
        block(0, e).prefetch();
        ahead(e * NodeSize);
        leaves.push_back(std::uint64_t(e) << 1 | ((inside >> i) & 1u));
      }
      if (leaves.size() >= kBatch && !read_leaves()) return s;
      continue;
    }
    // Fetch every child at once; the stack is filled from the last, so the first is tested
    // first.
    for (auto all = hits | inside; all;)
      block(level - 1, base + std::size_t(detail::pop_lowest(all))).prefetch();
    while (inside) {
      const std::size_t e = base + std::size_t(detail::pop_lowest(inside));
      const std::size_t span = this->level(level).span;
      if (!report_run<ByPosition>(e * span, (e + 1) * span, visit, ahead, s)) return s;
    }
    while (hits) {
      const int i = detail::pop_highest(hits);
      stack.push_back((std::uint64_t(level - 1) << 32) | (base + std::size_t(i)));
    }
  }
  read_leaves();
  return s;
}

template <int D, int NodeSize>
template <NearestVisitor<D> Visit>
QueryStats PackedRTree<D, NodeSize>::nearest(const Point<D>& p, std::size_t k,
                                             Visit&& visit) const {
  check_point(p, "query point");
  if (k == 0) throw InvalidArgument("nearest-n query needs k >= 1");
  if (empty()) return {};
  return walk_nearest(
      p, visit,
      [k](std::uint64_t root, auto& expand, auto& report) {
        return detail::best_first(root, k, expand, report);
      },
      KeepAll{});
}

template <int D, int NodeSize>
template <NearestVisitor<D> Visit>
QueryStats PackedRTree<D, NodeSize>::browse(const Point<D>& p, Visit&& visit) const {
  check_point(p, "query point");
  if (empty()) return {};
  return browse(p, visit, KeepAll{});
}

template <int D, int NodeSize>
template <NearestVisitor<D> Visit, class Keep>
QueryStats PackedRTree<D, NodeSize>::browse(const Point<D>& p, Visit&& visit, Keep&& keep) const {
  check_point(p, "query point");
  if (empty()) return {};
  return walk_nearest(
      p, visit,
      [](std::uint64_t root, auto& expand, auto& report) {
        return detail::browse(root, expand, report);
      },
      keep);
}

template <int D, int NodeSize>
template <class Key, class Visit>
QueryStats PackedRTree<D, NodeSize>::ordered(Key&& key, Visit&& visit) const {
  if (empty()) return {};
  constexpr double kInf = std::numeric_limits<double>::infinity();
  auto expand = [&](std::uint64_t ref, auto& sink) -> std::size_t {
    const int level = int(ref >> 32);
    const std::size_t b = std::size_t(ref & 0xffffffffu);
    const std::size_t base = b * NodeSize;
    const int used = int(std::min<std::size_t>(NodeSize, this->level(level).entries - base));
    const Block& node = block(level, b);
    for (int i = 0; i < used; ++i) {
      const double k = key(node.box(i));
      if (!(k < kInf)) continue;
      // The walk orders by its first field (the key itself: no square to overflow); the
      // report below asks key() again rather than take the walk's square root of it.
      if (level == 0)
        sink.push_entry(k, base + i, Id(item_index(base + i)));
      else
        sink.push_subtree(k, (std::uint64_t(level - 1) << 32) | (base + i));
    }
    return std::size_t(used);
  };
  auto report = [&](Id id, std::uint64_t pos, double) {
    const Box<D> box = leaf_box(pos);
    return visit(id, box, key(box));
  };
  return detail::browse(std::uint64_t(levels() - 1) << 32, expand, report);
}

template <int D, int NodeSize>
template <class Visit, class Walk, class Keep>
QueryStats PackedRTree<D, NodeSize>::walk_nearest(const Point<D>& p, Visit& visit, Walk&& walk,
                                                  Keep&& keep) const {
  constexpr bool kAll = std::is_same_v<std::remove_cvref_t<Keep>, KeepAll>;
  auto expand = [&](std::uint64_t ref, auto& sink) -> std::size_t {
    const int level = int(ref >> 32);
    const std::size_t b = std::size_t(ref & 0xffffffffu);
    const std::size_t base = b * NodeSize;
    const int used = int(std::min<std::size_t>(NodeSize, this->level(level).entries - base));
    double d2[Block::kSlots];
    block(level, b).squared_distances(p, d2);
    if constexpr (!kAll) {
      // Entries the caller does not keep are pushed as nothing: each kept one separately.
      // The node itself is asked again first: what the caller learnt since it was queued can
      // rule it out now, and nothing under it is nearer than its nearest entry.
      const std::size_t span = this->level(level).span;
      double nearest = d2[0];
      for (int i = 1; i < used; ++i)
        nearest = std::min(nearest, d2[i]);
      if (!keep(base * span, std::min((base + NodeSize) * span, size_), std::sqrt(nearest)))
        return std::size_t(used);
      for (int i = 0; i < used; ++i) {
        const std::size_t first = (base + i) * span;
        if (!keep(first, std::min(first + span, size_), std::sqrt(d2[i]))) continue;
        if (level == 0)
          sink.push_entry(d2[i], base + i, Id(item_index(base + i)));
        else
          sink.push_subtree(d2[i], (std::uint64_t(level - 1) << 32) | (base + i));
      }
      return std::size_t(used);
    }
    if (level == 0)
      sink.push_entries(
          d2, used, [&](int i) { return base + i; },
          [&](int i) { return Id(item_index(base + i)); });
    else
      sink.push_subtrees(d2, used,
                         [&](int i) { return (std::uint64_t(level - 1) << 32) | (base + i); });
    return std::size_t(used);
  };
  auto report = [&](Id id, std::uint64_t pos, double d) { return visit(id, leaf_box(pos), d); };
  return walk(std::uint64_t(levels() - 1) << 32, expand, report);
}

template <int D, int NodeSize>
void PackedRTree<D, NodeSize>::validate() const {
  auto fail = [](const std::string& what) { throw Error("PackedRTree invalid: " + what); };
  if (empty()) {
    if (total_blocks() != 0) fail("empty tree with nodes");
    return;
  }
  if (levels_.back().entries > std::size_t(NodeSize)) fail("root level has more than one node");
  for (int l = 0; l < levels(); ++l) {
    for (std::size_t b = 0; b < level_blocks(l); ++b) {
      const Block& node = block(l, b);
      for (int i = NodeSize; i < Block::kSlots; ++i)
        if (!(node.box(i) == Box<D>::empty()))
          fail("padding slot is not empty at level " + std::to_string(l));
      for (int i = 0; i < NodeSize; ++i) {
        const std::size_t e = b * NodeSize + i;
        const Box<D> box = node.box(i);
        if (e >= level(l).entries) {
          if (!(box == Box<D>::empty()))
            fail("unused slot is not empty at level " + std::to_string(l));
          continue;
        }
        if (box.is_empty())
          fail("empty entry " + std::to_string(e) + " at level " + std::to_string(l));
        if (l > 0) {
          const int used =
              int(std::min<std::size_t>(NodeSize, level(l - 1).entries - e * NodeSize));
          if (!(block(l - 1, e).bounds(used) == box))
            fail("entry " + std::to_string(e) + " at level " + std::to_string(l) +
                 " is not the union of its node");
        }
      }
    }
  }
  std::vector<bool> seen(size_, false);
  for (std::size_t pos = 0; pos < size_; ++pos) {
    const std::uint32_t id = item_index(pos);
    if (id >= size_ || seen[id]) fail("item indices are not a permutation");
    seen[id] = true;
  }
}

static_assert(BoxIndex<PackedRTree<2>> && NearestIndex<PackedRTree<2>>);

using PackedRTree2 = PackedRTree<2>;
using PackedRTree3 = PackedRTree<3>;

}  // namespace loci
