// RTreeIndex: what one loci_rtree virtual table holds in memory, and its on-disk form.
//
// The rows of a table are `base` (a PackedRTree bulk-loaded at the last repack, stored in the
// %_node shadow table) minus `dead` (ids of base entries deleted or changed since, %_dead)
// plus `delta` (rows written since, %_delta, also kept in a small R*-tree for queries). Writes
// touch only the delta and dead sets, in memory; the table flushes them to the shadow tables at
// savepoints and commits, and repacks everything into a new base when the delta and dead sets
// grow past an eighth of the base (so a bulk INSERT ... SELECT in one transaction becomes one
// packed build at commit). Coordinates are doubles end to end: no rounding, no false hits.
//
// This header knows nothing of SQLite: rtree_table.cpp moves the bytes in and out.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "loci/index/detail/large_alloc.hpp"
#include "loci/index/packed_rtree.hpp"
#include "loci/index/rstar_tree.hpp"

namespace loci::sqlite {

using Box2 = Box<2>;
using RowId = std::int64_t;

// Coordinate columns in the table's declared order: id, minx, maxx, miny, maxy.
enum Column : int { col_id = 0, col_minx = 1, col_maxx = 2, col_miny = 3, col_maxy = 4 };

inline double column_of(const Box2& b, int column) {
  switch (column) {
    case col_minx:
      return b.min[0];
    case col_maxx:
      return b.max[0];
    case col_miny:
      return b.min[1];
    default:
      return b.max[1];
  }
}

enum class Op : std::uint8_t { eq, lt, le, gt, ge };

// The coordinate constraints of a WHERE clause, answered exactly. Each of the four columns
// gets a lower and an upper bound (strict or not); `prune` is a box every matching row's box
// meets (what the trees are searched with), matches() the exact test.
class Window {
 public:
  // Adds "column op value". The value is exact: the caller has already turned SQL integers and
  // text into the double bound that compares the same way with every double.
  void add(int column, Op op, double value) {
    const int c = column - col_minx;
    if (op == Op::eq || op == Op::ge || op == Op::gt) tighten_lo(c, value, op == Op::gt);
    if (op == Op::eq || op == Op::le || op == Op::lt) tighten_hi(c, value, op == Op::lt);
    bounded_ = true;
  }
  // A constraint no row can meet (a NULL operand, or a number compared above every text).
  void make_empty() { never_ = true; }

  // True when no box can match: a column bounded from both sides with nothing in between, or
  // a box's min held above its max (min >= lo and max <= hi with lo > hi).
  bool empty() const {
    if (never_) return true;
    for (int c = 0; c < 4; ++c)
      if (lo_[c] > hi_[c] || (lo_[c] == hi_[c] && (lo_strict_[c] || hi_strict_[c]))) return true;
    return lo_[0] > hi_[1] || lo_[2] > hi_[3];
  }
  bool unbounded() const { return !bounded_; }

  // A row's minx and maxx lie inside its box's x extent, so a lower bound on either needs
  // box.max >= it and an upper bound on either needs box.min <= it: the box meets [lo, hi] on
  // that axis. When lo > hi ("minx <= 3 AND maxx >= 5": boxes holding [3, 5]) the condition
  // box.min <= hi and box.max >= lo is still what the box must meet, but it is no window: the
  // box returned is then [hi, lo], which every such box meets too, and matches() decides.
  Box2 prune() const {
    Box2 b;
    for (int a = 0; a < 2; ++a) {
      const auto [lo, hi] = meets(a);  // the trees take finite windows only
      b.min[a] = std::clamp(std::min(lo, hi), -kMaxDouble, kMaxDouble);
      b.max[a] = std::clamp(std::max(lo, hi), -kMaxDouble, kMaxDouble);
    }
    return b;
  }
  // True when every box meeting prune() (closed) matches: only "min <= v" and "max >= v"
  // constraints, none strict, making a proper window (the form of SQLite's rtree
  // documentation).
  bool prune_is_exact() const {
    for (int c = 0; c < 4; ++c)
      if (lo_strict_[c] || hi_strict_[c]) return false;
    if (lo_[0] != -kInf || hi_[1] != kInf || lo_[2] != -kInf || hi_[3] != kInf) return false;
    for (int a = 0; a < 2; ++a)
      if (const auto [lo, hi] = meets(a); lo > hi) return false;
    return true;
  }
  bool matches(const Box2& b) const {
    const double v[4] = {b.min[0], b.max[0], b.min[1], b.max[1]};
    bool ok = true;
    for (int c = 0; c < 4; ++c) {
      ok &= lo_strict_[c] ? v[c] > lo_[c] : v[c] >= lo_[c];
      ok &= hi_strict_[c] ? v[c] < hi_[c] : v[c] <= hi_[c];
    }
    return ok;
  }

 private:
  static constexpr double kMaxDouble = std::numeric_limits<double>::max();
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  // What a matching box's extent on axis a must meet: box.max >= lo and box.min <= hi (lo may
  // be +inf and hi -inf, which no finite box meets).
  std::pair<double, double> meets(int a) const {
    return {std::max({lo_[2 * a], lo_[2 * a + 1], -kMaxDouble}),
            std::min({hi_[2 * a], hi_[2 * a + 1], kMaxDouble})};
  }
  void tighten_lo(int c, double v, bool strict) {
    if (v > lo_[c] || (v == lo_[c] && strict)) lo_[c] = v, lo_strict_[c] = strict;
  }
  void tighten_hi(int c, double v, bool strict) {
    if (v < hi_[c] || (v == hi_[c] && strict)) hi_[c] = v, hi_strict_[c] = strict;
  }
  double lo_[4] = {-kInf, -kInf, -kInf, -kInf};
  double hi_[4] = {kInf, kInf, kInf, kInf};
  bool lo_strict_[4] = {};
  bool hi_strict_[4] = {};
  bool bounded_ = false;
  bool never_ = false;
};

struct Hit {
  RowId id;
  Box2 box;
};

struct Near {
  double distance;
  RowId id;
  friend bool operator<(const Near& a, const Near& b) {
    return a.distance < b.distance || (a.distance == b.distance && a.id < b.id);
  }
};

class RTreeIndex {
 public:
  using Packed = PackedRTree<2, 16>;
  using Block = Packed::Block;

  // The stored form of the base: a fixed header, then a payload cut into chunks.
  struct Header {
    char magic[8];
    std::uint32_t format;
    std::uint32_t node_size;
    std::uint64_t size;
    std::uint64_t payload_bytes;
    std::uint8_t packing;
    std::uint8_t pad[7];
  };
  static constexpr char kMagic[8] = {'l', 'o', 'c', 'i', 'r', 't', 'r', '\1'};
  static constexpr std::uint32_t kFormat = 1;

  RTreeIndex() = default;
  RTreeIndex(RTreeIndex&&) = default;
  RTreeIndex& operator=(RTreeIndex&&) = default;

  std::size_t size() const { return base_.size() - dead_.size() + delta_.size(); }
  std::size_t base_size() const { return base_.size(); }
  std::size_t delta_size() const { return delta_.size(); }
  std::size_t dead_size() const { return dead_.size(); }
  bool any_row() const { return size() != 0; }

  // The largest live id, or nothing when the table is empty: SQLite gives a NULL id one more,
  // as in a rowid table (an erased top id is not remembered).
  std::optional<RowId> max_id() {
    if (!any_row()) return std::nullopt;
    if (!max_known_) {
      std::optional<RowId> top;
      for (std::size_t j = by_id_.size(); j-- > 0;)
        if (const RowId id = id_at(j); !dead_.count(id)) {
          top = id;
          break;
        }
      for (const auto& [id, b] : delta_)
        if (!top || id > *top) top = id;
      max_id_ = *top;
      max_known_ = true;
    }
    return max_id_;
  }

  // The row's box, if the row exists.
  std::optional<Box2> find(RowId id) const {
    if (auto it = delta_.find(id); it != delta_.end()) return it->second;
    const std::size_t pos = base_position(id);
    if (pos == kAbsent || dead_.count(id)) return std::nullopt;
    return leaf_box(pos);
  }

  // Inserts the row or replaces its box. The box is valid (finite, min <= max).
  void put(RowId id, const Box2& b) {
    if (max_known_) max_id_ = any_row() ? std::max(max_id_, id) : id;
    if (auto it = delta_.find(id); it != delta_.end()) {
      if (tree_current()) delta_tree_.update(it->second, b, Id(id));
      it->second = b;
    } else {
      if (base_position(id) != kAbsent) dead_.insert(id);
      delta_.emplace(id, b);
      if (tree_current()) delta_tree_.insert(b, Id(id));
    }
    touched_.push_back(id);
  }

  // Removes the row; false when there is none.
  bool erase(RowId id) {
    if (id == max_id_) max_known_ = false;
    if (auto it = delta_.find(id); it != delta_.end()) {
      if (tree_current()) delta_tree_.erase(it->second, Id(id));
      delta_.erase(it);
      touched_.push_back(id);
      return true;
    }
    if (base_position(id) == kAbsent || !dead_.insert(id).second) return false;
    touched_.push_back(id);
    return true;
  }

  // Appends the rows meeting the window.
  void window(const Window& w, std::vector<Hit>& out) {
    if (w.empty()) return;
    const Box2 prune = w.prune();
    // The base's items are numbered in packed order (repack, load), so ids_ is read by packed
    // position, its lines fetched as soon as a leaf is queued.
    const RowId* ids = ids_.data();
    const std::size_t last = ids_.empty() ? 0 : ids_.size() - 1;
    const auto ahead = [ids, last](std::size_t pos) {
      __builtin_prefetch(ids + std::min(pos, last));
      __builtin_prefetch(ids + std::min(pos + 8, last));
    };
    if (w.prune_is_exact() && dead_.empty()) {
      base_.query_packed(
          prune,
          [&](std::size_t pos, const Box2& b) {
            out.push_back({ids[pos], b});
            return true;
          },
          ahead);
    } else {
      base_.query_packed(
          prune,
          [&](std::size_t pos, const Box2& b) {
            const RowId id = ids[pos];
            if (w.matches(b) && (dead_.empty() || !dead_.count(id))) out.push_back({id, b});
            return true;
          },
          ahead);
    }
    if (delta_.empty()) return;
    if (delta_.size() < 64) {
      for (const auto& [id, b] : delta_)
        if (w.matches(b)) out.push_back({id, b});
      return;
    }
    current_delta_tree().query(prune, [&](Id id, const Box2& b) {
      if (w.matches(b)) out.push_back({RowId(id), b});
      return true;
    });
  }

  // Appends every row (base rows in packed order, then the delta).
  void scan(std::vector<Hit>& out) const {
    out.reserve(out.size() + size());
    for (std::size_t pos = 0; pos < base_.size(); ++pos) {
      const RowId id = ids_[items()[pos]];
      if (dead_.empty() || !dead_.count(id)) out.push_back({id, leaf_box(pos)});
    }
    for (const auto& [id, b] : delta_)
      out.push_back({id, b});
  }

  // Appends every row in ascending id order, as a rowid table is scanned: a statement that
  // renumbers rows (UPDATE t SET id = id - 1) then meets the same conflicts as on any table.
  void scan_by_id(std::vector<Hit>& out) const {
    const std::size_t from = out.size();
    scan(out);  // in packed order, read one after the other, then sorted: cheaper than
                // reading the rows through by_id_ all over the arrays
    std::sort(out.begin() + std::ptrdiff_t(from), out.end(),
              [](const Hit& a, const Hit& b) { return a.id < b.id; });
  }

  // The k rows nearest p (distance to the box, 0 inside), nearest first.
  void nearest(const Point2& p, std::size_t k, std::vector<Near>& out) {
    out.clear();
    if (k == 0) return;
    base_.browse(p, [&](Id item, const Box2&, double d) {
      const RowId id = ids_[item];
      if (dead_.empty() || !dead_.count(id)) out.push_back({d, id});
      return out.size() < k;
    });
    if (delta_.empty()) return;
    const std::size_t from_base = out.size();
    if (delta_.size() < 64) {
      for (const auto& [id, b] : delta_)
        out.push_back({distance(p, b), id});
    } else {
      current_delta_tree().nearest(p, k, [&](Id id, const Box2&, double d) {
        out.push_back({d, RowId(id)});
        return true;
      });
    }
    std::sort(out.begin() + std::ptrdiff_t(from_base), out.end());
    std::inplace_merge(out.begin(), out.begin() + std::ptrdiff_t(from_base), out.end());
    if (out.size() > k) out.resize(k);
  }

  // ---- Writing back -----------------------------------------------------------------------

  // Ids written since the last take_touched(), each once.
  std::vector<RowId> take_touched() {
    std::sort(touched_.begin(), touched_.end());
    touched_.erase(std::unique(touched_.begin(), touched_.end()), touched_.end());
    return std::exchange(touched_, {});
  }
  bool has_touched() const { return !touched_.empty(); }
  bool in_delta(RowId id) const { return delta_.count(id) != 0; }
  bool is_dead(RowId id) const { return dead_.count(id) != 0; }
  std::optional<Box2> delta_box(RowId id) const {
    auto it = delta_.find(id);
    return it == delta_.end() ? std::nullopt : std::optional<Box2>(it->second);
  }

  // True when the delta and dead sets are worth folding into a new base.
  bool wants_repack() const {
    const std::size_t changes = delta_.size() + dead_.size();
    return changes >= std::max<std::size_t>(4096, base_.size() / 8);
  }

  // Packs every row into a new base; the delta and dead sets become empty.
  void repack() {
    std::vector<Hit> rows;
    scan(rows);
    std::vector<Box2> boxes(rows.size());
    for (std::size_t i = 0; i < rows.size(); ++i)
      boxes[i] = rows[i].box;
    const Packed built = Packed::build(boxes, Packing::hilbert);
    // Renumber the items in packed order, so a query reads the ids of its hits one after the
    // other instead of all over a large array.
    const std::size_t n = rows.size();
    auto arrays = std::make_shared<Arrays>();
    const auto blocks = built.blocks();
    arrays->blocks.assign(blocks.begin(), blocks.end());
    const auto items = built.item_indices();
    arrays->items.resize(items.size());
    ids_.assign(n, 0);
    for (std::size_t pos = 0; pos < items.size(); ++pos) {
      arrays->items[pos] = pos < n ? std::uint32_t(pos) : items[pos];  // unused slots as built
      if (pos < n) ids_[pos] = rows[items[pos]].id;
    }
    base_ = Packed::adopt(n, Packing::hilbert, std::span<const Block>(arrays->blocks),
                          arrays->items, arrays);
    base_arrays_ = arrays;
    index_by_id();
    dead_.clear();
    delta_.clear();
    delta_tree_ = {};
    tree_stale_ = false;
    unqueried_ = 0;
    touched_.clear();
  }

  Header header() const {
    Header h{};
    std::memcpy(h.magic, kMagic, sizeof kMagic);
    h.format = kFormat;
    h.node_size = Packed::node_size;
    h.size = base_.size();
    h.payload_bytes = payload_bytes(base_.size());
    h.packing = std::uint8_t(base_.packing());
    return h;
  }

  // The payload, as the pieces to concatenate: blocks, item indices, ids, id order.
  std::vector<std::span<const std::byte>> payload() const {
    const auto bytes = [](auto span) { return std::as_bytes(span); };
    return {bytes(base_.blocks()), bytes(base_.item_indices()), bytes(std::span<const RowId>(ids_)),
            bytes(std::span<const std::uint32_t>(by_id_))};
  }

  // Rebuilds an index from its stored parts. `read(dst)` fills dst with the next payload
  // bytes and returns false when the stored payload runs out. Throws loci::Error saying what
  // is inconsistent.
  static RTreeIndex load(const Header& h, const std::function<bool(std::span<std::byte>)>& read,
                         std::vector<Hit> delta, std::vector<RowId> dead) {
    if (std::memcmp(h.magic, kMagic, sizeof kMagic) != 0 || h.format != kFormat ||
        h.node_size != std::uint32_t(Packed::node_size) || h.packing > 1)
      throw Error("the %_node header is not a loci_rtree index of this version");
    if (h.size >= std::numeric_limits<std::uint32_t>::max() ||
        h.payload_bytes != payload_bytes(h.size))
      throw Error("the %_node header's sizes disagree");
    RTreeIndex x;
    const std::size_t n = h.size;
    auto arrays = std::make_shared<Arrays>();
    const std::size_t blocks = Packed::block_count(n);
    const std::size_t slots = n == 0 ? 0 : Packed::layout(n)[0].blocks * Packed::node_size;
    arrays->blocks.resize(blocks);
    arrays->items.resize(slots);
    x.ids_.resize(n);
    x.by_id_.resize(n);
    const auto fill = [&](auto& span) {
      if (!read(std::as_writable_bytes(span))) throw Error("the %_node payload is truncated");
    };
    std::span<Block> bs(arrays->blocks);
    std::span<std::uint32_t> is(arrays->items);
    std::span<RowId> ids(x.ids_);
    std::span<std::uint32_t> order(x.by_id_);
    fill(bs), fill(is), fill(ids), fill(order);
    std::byte extra;
    if (read(std::span<std::byte>(&extra, 1))) throw Error("the %_node payload is too long");
    x.base_ = Packed::adopt(n, Packing(h.packing), bs, is, arrays);
    x.base_arrays_ = arrays;
    x.base_.validate();
    // Number the items in packed order, as repack() does, if an older writer did not.
    bool packed_order = true;
    for (std::size_t pos = 0; pos < n && packed_order; ++pos)
      packed_order = is[pos] == pos;
    if (!packed_order) {
      detail::LargeVector<RowId> by_position(n);
      for (std::size_t pos = 0; pos < n; ++pos)
        by_position[pos] = x.ids_[is[pos]];
      x.ids_.swap(by_position);
      for (std::size_t pos = 0; pos < n; ++pos)
        is[pos] = std::uint32_t(pos);
    }
    for (std::size_t j = 0; j < n; ++j) {
      if (x.by_id_[j] >= n) throw Error("the %_node id order points outside the tree");
      if (j > 0 && !(x.id_at(j - 1) < x.id_at(j)))
        throw Error("the %_node ids are not unique and sorted");
    }
    x.max_known_ = false;
    for (RowId id : dead) {
      if (x.base_position(id) == kAbsent)
        throw Error("%_dead names id " + std::to_string(id) + ", which the %_node tree lacks");
      x.dead_.insert(id);
    }
    x.delta_.reserve(delta.size());
    for (const Hit& r : delta) {
      if (!is_valid(r.box))
        throw Error("%_delta holds an invalid box for id " + std::to_string(r.id));
      if (x.base_position(r.id) != kAbsent && !x.dead_.count(r.id))
        throw Error("id " + std::to_string(r.id) + " is both in %_delta and live in %_node");
      x.delta_.emplace(r.id, r.box);
    }
    x.tree_stale_ = !x.delta_.empty();
    return x;
  }

  // Same rows, same boxes?
  bool same_rows(const RTreeIndex& o) const {
    if (size() != o.size()) return false;
    std::vector<Hit> rows;
    scan(rows);
    for (const Hit& r : rows) {
      const auto b = o.find(r.id);
      if (!b || !(*b == r.box)) return false;
    }
    return true;
  }

  // Throws loci::Error on a broken invariant of the in-memory structures.
  void validate() {
    base_.validate();
    current_delta_tree().validate();
    if (delta_tree_.size() != delta_.size()) throw Error("the delta tree and the delta disagree");
  }

 private:
  static constexpr std::size_t kAbsent = std::size_t(-1);
  // Large arrays ask for huge pages: fewer page walks on a query's cache misses (about 3% of a
  // window's time inside a transaction on 1M rows).
  struct Arrays {
    detail::LargeVector<Block> blocks;
    detail::LargeVector<std::uint32_t> items;
  };

  static std::uint64_t payload_bytes(std::uint64_t n) {
    const std::uint64_t slots = n == 0 ? 0 : Packed::layout(n)[0].blocks * Packed::node_size;
    return Packed::block_count(n) * sizeof(Block) + slots * 4 + n * 8 + n * 4;
  }
  const std::uint32_t* items() const { return base_.item_indices().data(); }
  RowId id_at(std::size_t j) const { return ids_[items()[by_id_[j]]]; }
  Box2 leaf_box(std::size_t pos) const {
    const Block& b = base_.blocks()[base_.level(0).first_block + pos / Packed::node_size];
    const std::size_t s = pos % Packed::node_size;
    return Box2{{{b.lo[0][s], b.lo[1][s]}}, {{b.hi[0][s], b.hi[1][s]}}};
  }
  // Position in packed order of the base entry with this id, or kAbsent.
  std::size_t base_position(RowId id) const {
    std::size_t lo = 0, hi = by_id_.size();
    while (lo < hi) {
      const std::size_t mid = (lo + hi) / 2;
      if (id_at(mid) < id)
        lo = mid + 1;
      else
        hi = mid;
    }
    return lo < by_id_.size() && id_at(lo) == id ? by_id_[lo] : kAbsent;
  }
  void index_by_id() {
    const std::size_t n = base_.size();
    by_id_.resize(n);
    for (std::size_t pos = 0; pos < n; ++pos)
      by_id_[pos] = std::uint32_t(pos);
    std::sort(by_id_.begin(), by_id_.end(), [&](std::uint32_t a, std::uint32_t b) {
      return ids_[items()[a]] < ids_[items()[b]];
    });
    max_known_ = false;
  }
  static double distance(const Point2& p, const Box2& b) {
    const double dx = std::max({b.min[0] - p[0], 0.0, p[0] - b.max[0]});
    const double dy = std::max({b.min[1] - p[1], 0.0, p[1] - b.max[1]});
    return std::sqrt(dx * dx + dy * dy);
  }
  // Keeps the delta tree in step while queries come; a long run of writes without a query
  // (a bulk load) only marks it stale, and the next query bulk-loads it.
  bool tree_current() {
    if (tree_stale_) return false;
    if (++unqueried_ > 256) {
      tree_stale_ = true;
      delta_tree_ = {};
      return false;
    }
    return true;
  }
  RStarTree<2>& current_delta_tree() {
    unqueried_ = 0;
    if (tree_stale_) {
      std::vector<std::pair<Box2, Id>> entries;
      entries.reserve(delta_.size());
      for (const auto& [id, b] : delta_)
        entries.emplace_back(b, Id(id));
      delta_tree_ = RStarTree<2>::bulk_load(entries);
      tree_stale_ = false;
    }
    return delta_tree_;
  }

  Packed base_;
  std::shared_ptr<Arrays> base_arrays_;  // the base's memory when it was loaded
  detail::LargeVector<RowId> ids_;       // builder index (= packed position) -> id
  std::vector<std::uint32_t> by_id_;     // packed positions sorted by id
  std::unordered_set<RowId> dead_;
  std::unordered_map<RowId, Box2> delta_;
  RStarTree<2> delta_tree_;
  bool tree_stale_ = false;
  std::size_t unqueried_ = 0;
  RowId max_id_ = 0;  // the largest live id when max_known_
  bool max_known_ = true;
  std::vector<RowId> touched_;
};

}  // namespace loci::sqlite
