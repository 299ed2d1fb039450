// MovingRTree<D, M, Policy>: the machinery the TPR*-tree (tpr_tree.hpp) and the STAR-tree
// (star_tree.hpp) share, an R-tree over moving points with time-parameterized bounds.
//
// Layout. Nodes live in detail::NodePool with up to M entries stored inline as
// structure-of-arrays (each entry's bounds relative to the tree's epoch, its child, and in
// leaves the object's report and id, so that queries read no other memory); parent links serve
// condensing. Objects are in flat arrays by slot (id, report, leaf) and ids map to slots through
// detail::IdMap, so an update finds its leaf at once.
//
// What the structures share: Choose_Path (branch and bound for the path of least total cost
// rise, with each node's entry costs kept at the clock), Pick_Worst reinsertion and splits over the
// 4 D sort orders, deletion with condensing and tightening, in-place updates, packing (build), and
// exact queries (vectorized timeslice tests; windows over an interval and moving windows by linear
// constraints; nearest-n best-first). What they do not share comes from the Policy: the name, the
// parameters, the cost of a box (Policy::horizon and Policy::extent feed detail::swept_cost: the
// TPR* swept area, or with both zero the area at the clock) and, for the STAR-tree, local
// regrouping.
//
// Time. Bounds are kept relative to the tree's epoch (the time of its first report), so that
// epoch-second timestamps lose no precision. A node's bounds are tightened at the tree's
// clock, the latest report time it has been given, and hold from then on; queries at or after
// the clock prune with them. A query reaching back before the clock is answered exactly by
// looking at every object (the bounds do not hold backwards).
//
// Thread-safety: const members may run concurrently with each other.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <queue>
#include <span>
#include <string>
#include <utility>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "loci/index/broadphase/detail/proxy_table.hpp"
#include "loci/index/detail/best_first.hpp"
#include "loci/index/detail/large_alloc.hpp"
#include "loci/index/detail/node_pool.hpp"
#include "loci/index/detail/scratch.hpp"
#include "loci/index/detail/str_partition.hpp"
#include "loci/index/moving/detail/tpbr.hpp"
#include "loci/index/moving/moving_index.hpp"

namespace loci {

namespace detail {

// Reaches the internals of MovingRTree (defined by its tests only).
struct MovingRTreeAccess;

template <int D, int M, class Policy>
class MovingRTree {
  static_assert(M >= 4 && M <= 63, "node entries are tracked in 64-bit masks");

 public:
  static constexpr int dimension = D;
  static constexpr const char* kName = Policy::kName;
  using Params = typename Policy::Params;
  static constexpr int kMinFill = std::max(2, M * 2 / 5);

  explicit MovingRTree(const Params& params = {}) : params_(params) { Policy::check(params); }
  MovingRTree(const MovingRTree&) = default;
  MovingRTree& operator=(const MovingRTree&) = default;
  // Moving leaves `other` empty, keeping its parameters.
  MovingRTree(MovingRTree&& other) noexcept : MovingRTree(other.params_) { swap(other); }
  MovingRTree& operator=(MovingRTree&& other) noexcept {
    MovingRTree(std::move(other)).swap(*this);
    return *this;
  }

  const Params& params() const { return params_; }

  void insert(Id id, const Motion<D>& m) {
    check_motion(m);
    if (map_.find(id) != kNone)
      throw InvalidArgument(std::string(kName) + ": id " + std::to_string(id) + " is already held");
    add(id, m);
  }

  void update(Id id, const Motion<D>& m) {
    check_motion(m);
    const std::uint32_t s = map_.find(id);
    if (s != kNone && params_.in_place_updates && update_in_place(s, m)) return;
    if (s != kNone) remove_slot(s);
    add(id, m);
  }

  bool erase(Id id) {
    const std::uint32_t s = map_.find(id);
    if (s == kNone) return false;
    remove_slot(s);
    return true;
  }

  void clear() { *this = MovingRTree(params_); }

  // Replaces the contents with objects[i] named ids[i], packed bottom-up instead of inserted
  // one by one (the rebuild-per-tick strategy of main-memory moving-object indexing): the
  // objects are tiled into leaves of 3/4 capacity by position and velocity (below), and each
  // level is packed from consecutive nodes of the one below, in tiling order. The
  // tree's epoch and clock become the latest report time. Throws InvalidArgument for
  // duplicate ids or lengths that differ, InvalidGeometry for a bad report.
  //
  // Rebuilt every tick, the tree reuses its memory (nodes and scratch arrays touch no new
  // pages) and, when the ids are those its slots hold, in the same order, its id map and table.
  void build(std::span<const Id> ids, std::span<const Motion<D>> objects) {
    if (ids.size() != objects.size())
      throw InvalidArgument(std::string(kName) + ": ids and reports differ in length");
    if (objects.size() + 1 >= kNone)
      throw InvalidArgument(std::string(kName) + ": too many objects");
    // Everything is checked before anything changes: bad input leaves the tree as it was.
    double latest = -std::numeric_limits<double>::infinity();
    for (const Motion<D>& m : objects) {
      check_motion(m);
      latest = std::max(latest, m.t);
    }
    const std::size_t n = objects.size();
    // Object i takes slot i. The map from ids to slots stands when every slot holds the id
    // given for it (then the ids are distinct too); otherwise a new one is made.
    const bool same_ids =
        count_ == n && obj_id_.size() == n && std::equal(ids.begin(), ids.end(), obj_id_.begin());
    detail::IdMap map;
    if (!same_ids)
      for (std::uint32_t i = 0; i < n; ++i) {
        if (map.find(ids[i]) != kNone)
          throw InvalidArgument(std::string(kName) + ": id " + std::to_string(ids[i]) +
                                " is given twice");
        map.insert(ids[i], i, i + 1);
      }
    // Leaves are tiles of the 2 D-dimensional space of positions at mid-horizon and
    // velocities, cut by Sort-Tile-Recursive on quantized keys (detail::str_tile_cells).
    const double mid = latest + 0.5 * Policy::lookahead(params_);
    const auto key = [&](const Motion<D>& m, int axis) {
      return axis < D ? m.p[axis] + m.v[axis] * (mid - m.t) : m.v[axis - D];
    };
    constexpr int kCellBits = detail::cell_bits<2 * D>();
    constexpr double kCellMax = double((1u << kCellBits) - 1);
    double kmin[2 * D], kmax[2 * D], kscale[2 * D];
    std::fill_n(kmin, 2 * D, std::numeric_limits<double>::infinity());
    std::fill_n(kmax, 2 * D, -std::numeric_limits<double>::infinity());
    for (const Motion<D>& m : objects)  // one pass over the reports for all axes
      for (int a = 0; a < 2 * D; ++a) {
        const double k = key(m, a);
        kmin[a] = std::min(kmin[a], k), kmax[a] = std::max(kmax[a], k);
      }
    for (int a = 0; a < 2 * D; ++a) {
      const double scale = kCellMax / (kmax[a] - kmin[a]);
      kscale[a] = std::isfinite(scale) ? scale : 0.0;  // one value, or beyond doubles
    }
    cells_.resize(n);
    for (std::uint32_t i = 0; i < n; ++i) {
      std::uint64_t c = 0;
      for (int a = 0; a < 2 * D; ++a) {
        const double q = (key(objects[i], a) - kmin[a]) * kscale[a];
        c |= std::uint64_t(q >= 0 ? std::min(q, kCellMax) : 0.0) << (kCellBits * a);
      }
      cells_[i] = {c, i};
    }
    constexpr std::size_t kFill = std::max<std::size_t>(kMinFill, M * 3 / 4);
    // Nodes of `count` entries about kFill each, never below the minimum fill (two nodes of
    // kFill + 1 halved are, for some M of 25 or more), nor above M (kMinFill <= 2 M / 5).
    const auto nodes_for = [](std::size_t count) {
      return std::max<std::size_t>(
          1, std::min((count + kFill - 1) / kFill, count / std::size_t(kMinFill)));
    };
    const std::size_t leaves = n == 0 ? 0 : nodes_for(n);
    if (n > 0) {
      std::vector<std::size_t> groups(leaves + 1);
      for (std::size_t g = 0; g <= leaves; ++g)
        groups[g] = n * g / leaves;
      detail::str_tile_cells<2 * D>(cells_.data(), std::span<const std::size_t>(groups),
                                    cells_tmp_);
    }
    // The old contents go; their memory is reused.
    nodes_.clear();
    nodes_.reserve(leaves + leaves / (kFill - 1) + 8);
    root_ = kNone;
    free_slots_.clear();
    if (!same_ids) obj_id_.assign(ids.begin(), ids.end());
    obj_motion_.assign(objects.begin(), objects.end());
    obj_leaf_.resize(n);
    if (!same_ids) map_ = std::move(map);
    count_ = n;
    epoch_ = clock_ = n > 0 ? latest : 0;
    mag_ = vmag_ = 0;
    if (n == 0) {
      clock_ = -std::numeric_limits<double>::infinity();
      return;
    }
    std::vector<Item>& level = level_;
    level.resize(leaves);
    // Leaves. Locals carry the entry index and the magnitudes, which stores through the
    // nodes' arrays would otherwise force back to memory at every entry.
    constexpr std::size_t kAhead = 32;
    const double epoch = epoch_;
    const Motion<D>* const motion = obj_motion_.data();
    double mag = 0, vmag = 0;
    for (std::size_t g = 0; g < leaves; ++g) {
      const std::uint32_t node = nodes_.allocate(kName);
      Node& nd = nodes_[node];
      nd.parent = kNone;
      nd.level = 0;
      nd.grouped = 0;
      const std::size_t first = n * g / leaves, last = n * (g + 1) / leaves;
      for (std::size_t k = first; k < last; ++k) {
        // Reports (the table's copy) are read in tiling order, scattered: ask for them ahead.
        if (k + kAhead < n) {
          const std::uint32_t ahead = cells_[k + kAhead].index;
          __builtin_prefetch(&motion[ahead]);
          __builtin_prefetch(reinterpret_cast<const char*>(motion + ahead + 1) - 1);
          __builtin_prefetch(&obj_id_[ahead]);
          __builtin_prefetch(&obj_leaf_[ahead], 1);
        }
        const std::uint32_t i = cells_[k].index;
        const Box_ b = Box_::of(motion[i], epoch);
        for (int a = 0; a < D; ++a) {
          mag = std::max({mag, std::abs(b.lo[a]), std::abs(motion[i].p[a])});
          vmag = std::max(vmag, std::abs(b.vlo[a]));
        }
        put(nd, int(k - first), {b, i, motion[i], obj_id_[i]});
        obj_leaf_[i] = node;
      }
      nd.count = std::uint8_t(last - first);
      level[g] = {bound(nd), node, {}, 0};
    }
    mag_ = mag, vmag_ = vmag;
    // Pack each level above into nodes of nearly equal counts, about 3/4 full.
    for (int height = 1; level.size() > 1; ++height) {
      const std::size_t groups = nodes_for(level.size());
      std::vector<Item>& up = up_;
      up.resize(groups);
      for (std::size_t g = 0; g < groups; ++g) {
        const std::uint32_t node = nodes_.allocate(kName);
        Node& nd = nodes_[node];
        nd.parent = kNone;
        nd.level = std::uint8_t(height);
        nd.count = 0;
        nd.grouped = 0;
        for (std::size_t e = level.size() * g / groups; e < level.size() * (g + 1) / groups; ++e) {
          put(nd, nd.count, level[e]);
          adopt(node, nd.count++);
        }
        up[g] = {bound(nd), node, {}, 0};
      }
      level.swap(up);
    }
    root_ = level[0].child;
  }

  bool contains(Id id) const { return map_.find(id) != kNone; }
  std::size_t size() const { return count_; }
  bool empty() const { return count_ == 0; }
  double clock() const { return clock_; }
  int height() const { return root_ == kNone ? 0 : nodes_[root_].level + 1; }
  std::size_t memory_bytes() const {
    return nodes_.memory_bytes() + obj_motion_.capacity() * (sizeof(Motion<D>) + 12);
  }
  // Local regroupings done so far (regrouping policies only).
  std::size_t regroups() const { return regroups_; }
  // Nodes examined by the most expensive Choose_Path so far (the price of TPR* insertions).
  std::size_t max_choose_path_nodes() const { return max_choose_nodes_; }

  Motion<D> at(Id id) const {
    const std::uint32_t s = map_.find(id);
    if (s == kNone) throw InvalidArgument(std::string(kName) + ": no object " + std::to_string(id));
    return obj_motion_[s];
  }

  template <MotionVisitor<D> F>
  QueryStats query(const MovingWindow<D>& w, F&& visit) const {
    check_window(w);
    QueryStats st;
    if (root_ == kNone) return st;
    if (w.t1 < clock_) return scan(w, visit);
    // Leased, not a thread_local: a query from inside a visitor gets a stack of its own.
    detail::Scratch<std::uint32_t> stack_lease;
    std::vector<std::uint32_t>& stack = *stack_lease;
    stack.push_back(root_);
    // A timeslice compares each entry's box at the query time with the window: no divisions.
    const bool slice = w.t1 == w.t2 && w.from == w.to;
    const double r = w.t1 - epoch_;
    Box<D> grown = w.from;
    const double tol = tolerance(r);
    for (int i = 0; i < D; ++i)
      grown.min[i] -= tol, grown.max[i] += tol;
    while (!stack.empty()) {
      const Node& n = nodes_[stack.back()];
      stack.pop_back();
      ++st.nodes_visited;
      st.entries_tested += n.count;
      bool in[kSlots];
      if (n.level == 0) {
        if (slice)
          positions_inside(n, w.from, w.t1, in);
        else
          for (int e = 0; e < n.count; ++e)
            in[e] = inside(n.motion[e], w);
        for (int e = 0; e < n.count; ++e) {
          if (!in[e]) continue;
          ++st.results;
          if (!visit(n.id[e], n.motion[e])) return st;
        }
      } else {
        if (slice)
          boxes_meet(n, grown, r, in);
        else
          for (int e = 0; e < n.count; ++e)
            in[e] = detail::tpbr_meets(n.box[e], epoch_, w, report_slack());
        for (int e = 0; e < n.count; ++e)
          if (in[e]) stack.push_back(n.child[e]);
      }
    }
    return st;
  }
  std::vector<Id> query(const MovingWindow<D>& w) const {
    return collect_ids([&](auto&& v) { return query(w, v); });
  }

  template <MotionNearestVisitor<D> F>
  QueryStats nearest(const Point<D>& q, double s, std::size_t k, F&& visit) const {
    detail::check_nearest_count(k);
    return walk_nearest(q, s, visit, [k](std::uint64_t root, auto& expand, auto& report) {
      return detail::best_first(root, k, expand, report);
    });
  }
  std::vector<Neighbor> nearest(const Point<D>& q, double s, std::size_t k) const {
    return collect_neighbors([&](auto&& v) { return nearest(q, s, k, v); });
  }

  // Calls visit(id, motion, distance) for the objects in increasing distance from q at time s,
  // one at a time, until it returns false (distance browsing: no k fixed in advance). Times
  // before the clock are answered too, without pruning by the bounds (kept for now and later).
  template <MotionNearestVisitor<D> F>
  QueryStats browse(const Point<D>& q, double s, F&& visit) const {
    return walk_nearest(q, s, visit, [](std::uint64_t root, auto& expand, auto& report) {
      return detail::browse(root, expand, report);
    });
  }

  template <MotionVisitor<D> F>
  void for_each(F&& visit) const {
    for (std::uint32_t s = 0; s < obj_id_.size(); ++s)
      if (obj_leaf_[s] != kNone && !visit(obj_id_[s], obj_motion_[s])) return;
  }

  void validate() const {
    const std::string who(kName);
    std::size_t objects = 0;
    if (root_ != kNone) {
      if (nodes_[root_].parent != kNone) throw Error(who + ": the root has a parent");
      std::vector<bool> seen(nodes_.size(), false);
      validate_node(root_, seen, objects);
      if (!nodes_.validate_free(seen)) throw Error(who + ": a node is both in use and free");
      for (std::uint32_t n = 0; n < nodes_.size(); ++n)
        if (!seen[n]) throw Error(who + ": node " + std::to_string(n) + " is lost");
    }
    if (objects != count_) throw Error(who + ": the leaves hold a different number of objects");
    std::size_t live = 0;
    for (std::uint32_t s = 0; s < obj_id_.size(); ++s) {
      if (obj_leaf_[s] == kNone) continue;
      ++live;
      if (map_.find(obj_id_[s]) != s)
        throw Error(who + ": id " + std::to_string(obj_id_[s]) + " does not map to its slot");
    }
    if (live != count_) throw Error(who + ": object table and count disagree");
  }

 private:
  // Runs walk(root, expand, report), detail::best_first or detail::browse, with this tree's
  // expansion around q at time s (the bounds prune only from the clock on).
  template <class F, class Walk>
  QueryStats walk_nearest(const Point<D>& q, double s, F& visit, Walk&& walk) const {
    check_point(q, "nearest point");
    detail::check_nearest_time(s);
    if (root_ == kNone) return {};
    const double r = s - epoch_;
    const bool prune = s >= clock_;
    auto expand = [&](std::uint64_t ref, auto& sink) -> std::size_t {
      const Node& n = nodes_[std::uint32_t(ref)];
      double d2[M + 1];
      if (n.level == 0) {
        for (int e = 0; e < n.count; ++e)
          d2[e] = squared_distance(position(n.motion[e], s), q);
        sink.push_entries(
            d2, n.count, [&](int e) { return std::uint64_t(n.child[e]); },
            [&](int e) { return n.id[e]; });
      } else {
        for (int e = 0; e < n.count; ++e)
          d2[e] = prune ? detail::tpbr_distance2(n.box[e], r, q, report_slack()) : 0.0;
        sink.push_subtrees(d2, n.count, [&](int e) { return std::uint64_t(n.child[e]); });
      }
      return n.count;
    };
    auto report = [&](Id id, std::uint64_t ref, double d) {
      detail::check_nearest_distance(d);
      return visit(id, obj_motion_[std::uint32_t(ref)], d);
    };
    return walk(root_, expand, report);
  }

  friend struct MovingRTreeAccess;
  using Box_ = detail::Tpbr<D>;
  static constexpr int kSlots = M + 1;  // one spare entry while overflowing

  // A node's entry boxes as structure-of-arrays, so that the tests of all entries of a node
  // run as one vectorized loop; box[e] reads (and, on a mutable node, writes) one entry.
  struct BoxArray {
    double lo[D][kSlots], hi[D][kSlots], vlo[D][kSlots], vhi[D][kSlots];
    // The cost (Policy's) at relative time costed_at of each entry below the node's count,
    // kept by enlargements() for Choose_Path, except for the entries set() has written since
    // (bits of `stale`).
    double cost[kSlots];
    double costed_at = std::numeric_limits<double>::quiet_NaN();
    std::uint64_t stale = ~std::uint64_t(0);

    Box_ get(int e) const {
      Box_ b;
      for (int i = 0; i < D; ++i)
        b.lo[i] = lo[i][e], b.hi[i] = hi[i][e], b.vlo[i] = vlo[i][e], b.vhi[i] = vhi[i][e];
      return b;
    }
    void set(int e, const Box_& b) {
      for (int i = 0; i < D; ++i)
        lo[i][e] = b.lo[i], hi[i][e] = b.hi[i], vlo[i][e] = b.vlo[i], vhi[i][e] = b.vhi[i];
      stale |= std::uint64_t(1) << e;
    }
    struct Ref {
      BoxArray& a;
      int e;
      operator Box_() const { return a.get(e); }
      Ref& operator=(const Box_& b) {
        a.set(e, b);
        return *this;
      }
      void enclose(const Box_& b, double c) {
        Box_ x = a.get(e);
        x.enclose(b, c);
        a.set(e, x);
      }
    };
    Box_ operator[](int e) const { return get(e); }
    Ref operator[](int e) { return {*this, e}; }
  };
  // The reports of a leaf's objects, likewise.
  struct MotionArray {
    double t[kSlots], p[D][kSlots], v[D][kSlots];

    Motion<D> operator[](int e) const {
      Motion<D> m;
      m.t = t[e];
      for (int i = 0; i < D; ++i)
        m.p[i] = p[i][e], m.v[i] = v[i][e];
      return m;
    }
    void set(int e, const Motion<D>& m) {
      t[e] = m.t;
      for (int i = 0; i < D; ++i)
        p[i][e] = m.p[i], v[i][e] = m.v[i];
    }
  };

  struct Node {
    // User-provided, so that the pool's new nodes are not zero-filled first (a node is a few
    // kilobytes; its users set what they read).
    Node() {}
    std::uint32_t parent = kNone;  // also the free-list link
    std::uint8_t level = 0;        // 0: leaf (children are object slots)
    std::uint8_t count = 0;
    double grouped = 0;  // area of the node's box when it was last grouped (regrouping policies)
    BoxArray box;
    std::uint32_t child[kSlots];
    // Leaves also keep each object's report and id, so that queries read no other memory.
    MotionArray motion;
    Id id[kSlots];
  };
  // An entry on its way from one node to another.
  struct Item {
    detail::Tpbr<D> box;
    std::uint32_t child;
    Motion<D> motion;
    Id id;
  };
  static Item take(const Node& n, int e) { return {n.box[e], n.child[e], n.motion[e], n.id[e]}; }
  static void put(Node& n, int e, const Item& it) {
    n.box.set(e, it.box);
    n.child[e] = it.child;
    n.motion.set(e, it.motion);
    n.id[e] = it.id;
  }
  using Pool = detail::NodePool<Node, &Node::parent>;

  double rel_clock() const { return clock_ - epoch_; }
  // The rounding allowance of box tests at relative time r: a bound rounded a few times at
  // magnitudes up to mag_ + vmag_ (|r| + |clock|) is off by far less (tpbr.hpp).
  double tolerance(double r) const {
    return 1e-12 * (4 * mag_ + 4 * vmag_ * (std::abs(r) + std::abs(rel_clock()))) + 1e-300;
  }
  // What the bounds' own slack (tpbr.hpp) leaves out: the rounding of an entry's bounds at the
  // size of its report, whose position and travel to the epoch can cancel.
  double report_slack() const { return 4e-12 * mag_; }

  // Vectorized timeslice tests of all entries of a node. in[e]: the entry's box at relative
  // time r meets `grown` (the window grown by the tolerance).
  static void boxes_meet(const Node& n, const Box<D>& grown, double r, bool* in) {
    const BoxArray& b = n.box;
    for (int e = 0; e < n.count; ++e) {
      unsigned ok = 1;
      for (int i = 0; i < D; ++i)
        ok &= unsigned(b.lo[i][e] + b.vlo[i][e] * r <= grown.max[i]) &
              unsigned(b.hi[i][e] + b.vhi[i][e] * r >= grown.min[i]);
      in[e] = ok;
    }
  }
  // in[e]: the object's position at time s lies in the window; the arithmetic of inside().
  static void positions_inside(const Node& n, const Box<D>& w, double s, bool* in) {
    const MotionArray& m = n.motion;
    for (int e = 0; e < n.count; ++e) {
      const double dt = s - m.t[e];
      unsigned ok = 1;
      for (int i = 0; i < D; ++i) {
        const double x = m.p[i][e] + m.v[i][e] * dt;
        ok &= unsigned(x >= w.min[i]) & unsigned(x <= w.max[i]);
      }
      in[e] = ok;
    }
  }

  // A box as grown_costs() takes it: per axis its bounds at the clock and their velocities.
  // nothing() grows no entry.
  struct Taken {
    double l[D], u[D], vl[D], vh[D];

    static Taken of(const Box_& b, double c) {
      Taken t;
      for (int i = 0; i < D; ++i) {
        t.l[i] = b.lo_at(i, c), t.u[i] = b.hi_at(i, c);
        t.vl[i] = b.vlo[i], t.vh[i] = b.vhi[i];
      }
      return t;
    }
    static Taken nothing() {
      Taken t;
      constexpr double inf = std::numeric_limits<double>::infinity();
      for (int i = 0; i < D; ++i)
        t.l[i] = t.vl[i] = inf, t.u[i] = t.vh[i] = -inf;
      return t;
    }
  };

  // out[e - from] for the entries e in [from, to) of a: the cost (detail::swept_cost's
  // arithmetic, in its order) at relative time c of the entry's box grown to take t. Entries'
  // own costs (t = nothing()) and their costs after taking a box come from this one code, so
  // that an entry holding the box rises by exactly 0 whatever a compiler fuses. With SSE2 two
  // entries a step (a last odd entry in both lanes); s_i is max(vh, 0) - min(vl, 0), the
  // value of swept_cost's cases.
  void grown_costs(const BoxArray& a, int from, int to, const Taken& t, double c,
                   double* out) const {
    const double h = Policy::horizon(params_);
    const Point<D> extent = Policy::extent(params_);
#if defined(__SSE2__)
    const __m128d cc = _mm_set1_pd(c), hh = _mm_set1_pd(h), half = _mm_set1_pd(0.5),
                  zero = _mm_setzero_pd(), one = _mm_set1_pd(1.0);
    __m128d tl[D], tu[D], tvl[D], tvh[D], ext[D];
    for (int i = 0; i < D; ++i) {
      tl[i] = _mm_set1_pd(t.l[i]), tu[i] = _mm_set1_pd(t.u[i]);
      tvl[i] = _mm_set1_pd(t.vl[i]), tvh[i] = _mm_set1_pd(t.vh[i]);
      ext[i] = _mm_set1_pd(extent[i]);
    }
    // Entries e and e + 1, or e twice when `pair` is false.
    auto step = [&](int e, bool pair) {
      __m128d g1[D], g2[D], gs[D];
      for (int i = 0; i < D; ++i) {
        const auto load = [&](const double* p) {
          return pair ? _mm_loadu_pd(p + e) : _mm_set1_pd(p[e]);
        };
        const __m128d vl = load(a.vlo[i]), vh = load(a.vhi[i]);
        const __m128d l = _mm_add_pd(load(a.lo[i]), _mm_mul_pd(vl, cc));
        const __m128d u = _mm_add_pd(load(a.hi[i]), _mm_mul_pd(vh, cc));
        const __m128d gl = _mm_min_pd(l, tl[i]), gu = _mm_max_pd(u, tu[i]);
        const __m128d gvl = _mm_min_pd(vl, tvl[i]), gvh = _mm_max_pd(vh, tvh[i]);
        g1[i] = _mm_add_pd(_mm_sub_pd(gu, gl), ext[i]);
        g2[i] = _mm_add_pd(g1[i], _mm_mul_pd(_mm_sub_pd(gvh, gvl), hh));
        gs[i] = _mm_sub_pd(_mm_max_pd(gvh, zero), _mm_min_pd(gvl, zero));
      }
      __m128d area = one;
      for (int i = 0; i < D; ++i)
        area = _mm_mul_pd(area, g1[i]);
      for (int i = 0; i < D; ++i) {
        __m128d up = one, down = one;
        for (int j = 0; j < D; ++j)
          if (j != i) up = _mm_mul_pd(up, g1[j]), down = _mm_mul_pd(down, g2[j]);
        area = _mm_add_pd(
            area, _mm_mul_pd(_mm_mul_pd(_mm_mul_pd(half, _mm_add_pd(up, down)), gs[i]), hh));
      }
      if (pair)
        _mm_storeu_pd(out + (e - from), area);
      else
        _mm_store_sd(out + (e - from), area);
    };
    int e = from;
    for (; e + 2 <= to; e += 2)
      step(e, true);
    if (e < to) step(e, false);
#else
    for (int e = from; e < to; ++e) {
      double g1[D], g2[D], gs[D];
      for (int i = 0; i < D; ++i) {
        const double vl = a.vlo[i][e], vh = a.vhi[i][e];
        const double l = a.lo[i][e] + vl * c, u = a.hi[i][e] + vh * c;
        const double gl = std::min(l, t.l[i]), gu = std::max(u, t.u[i]);
        const double gvl = std::min(vl, t.vl[i]), gvh = std::max(vh, t.vh[i]);
        g1[i] = gu - gl + extent[i];
        g2[i] = g1[i] + (gvh - gvl) * h;
        gs[i] = std::max(gvh, 0.0) - std::min(gvl, 0.0);
      }
      double area = 1;
      for (int i = 0; i < D; ++i)
        area *= g1[i];
      for (int i = 0; i < D; ++i) {
        double up = 1, down = 1;
        for (int j = 0; j < D; ++j)
          if (j != i) up *= g1[j], down *= g2[j];
        area += 0.5 * (up + down) * gs[i] * h;
      }
      out[e - from] = area;
    }
#endif
  }

  // pen[e]: the rise of the cost of entry e's box when it takes b (0 when it holds b), for all
  // entries of a node. The entries' own costs at the clock come from the node's cache
  // (BoxArray::cost), filled here: all of them when the clock has moved since, otherwise
  // those of the entries written since.
  void enlargements(Node& n, const Box_& b, double* pen) {
    const double c = rel_clock();
    BoxArray& a = n.box;
    if (a.costed_at != c) {
      a.costed_at = c;
      grown_costs(a, 0, n.count, Taken::nothing(), c, a.cost);
    } else {
      const std::uint64_t held =
          n.count < 64 ? (std::uint64_t(1) << n.count) - 1 : ~std::uint64_t(0);
      for (std::uint64_t m = a.stale & held; m != 0; m &= m - 1) {
        const int e = std::countr_zero(m);
        grown_costs(a, e, e + 1, Taken::nothing(), c, a.cost + e);
      }
    }
    a.stale = 0;
    double after[kSlots];
    grown_costs(a, 0, n.count, Taken::of(b, c), c, after);
    for (int e = 0; e < n.count; ++e)
      pen[e] = std::max(0.0, after[e] - a.cost[e]);  // 0 for NaN, from inf - inf
  }
  double cost(const Box_& b) const {
    return detail::swept_cost(b, rel_clock(), Policy::horizon(params_), Policy::extent(params_));
  }
  // The bounds on one axis of a set of entries from the clock on, entry by entry: the least
  // lower bound at the clock and the least lower velocity (the greatest for the upper side),
  // Tpbr::enclose's rule.
  struct AxisBounds {
    double l, h, vl, vh;

    static AxisBounds of(const BoxArray& a, int i, int e, double c) {
      return {a.lo[i][e] + a.vlo[i][e] * c, a.hi[i][e] + a.vhi[i][e] * c, a.vlo[i][e], a.vhi[i][e]};
    }
    void add(const BoxArray& a, int i, int e, double c) {
      l = std::min(l, a.lo[i][e] + a.vlo[i][e] * c);
      h = std::max(h, a.hi[i][e] + a.vhi[i][e] * c);
      vl = std::min(vl, a.vlo[i][e]);
      vh = std::max(vh, a.vhi[i][e]);
    }
    void write(Box_& b, int i, double c) const {
      b.vlo[i] = vl, b.vhi[i] = vh;
      b.lo[i] = l - vl * c, b.hi[i] = h - vh * c;
    }
  };

  // The bounds of n's entries from the clock on, gathered in one pass over the node's arrays
  // (two entries a step with SSE2).
  Box_ bound(const Node& n) const {
    const double c = rel_clock();
    const BoxArray& a = n.box;
    Box_ b;
    for (int i = 0; i < D; ++i) {
      AxisBounds f = AxisBounds::of(a, i, 0, c);
      int e = 1;
#if defined(__SSE2__)
      if (n.count >= 3) {
        const __m128d cc = _mm_set1_pd(c);
        __m128d l2 = _mm_set1_pd(f.l), h2 = _mm_set1_pd(f.h), vl2 = _mm_set1_pd(f.vl),
                vh2 = _mm_set1_pd(f.vh);
        for (; e + 2 <= n.count; e += 2) {
          const __m128d lo = _mm_loadu_pd(&a.lo[i][e]), hi = _mm_loadu_pd(&a.hi[i][e]);
          const __m128d vlo = _mm_loadu_pd(&a.vlo[i][e]), vhi = _mm_loadu_pd(&a.vhi[i][e]);
          l2 = _mm_min_pd(l2, _mm_add_pd(lo, _mm_mul_pd(vlo, cc)));
          h2 = _mm_max_pd(h2, _mm_add_pd(hi, _mm_mul_pd(vhi, cc)));
          vl2 = _mm_min_pd(vl2, vlo);
          vh2 = _mm_max_pd(vh2, vhi);
        }
        f.l = std::min(_mm_cvtsd_f64(l2), _mm_cvtsd_f64(_mm_unpackhi_pd(l2, l2)));
        f.h = std::max(_mm_cvtsd_f64(h2), _mm_cvtsd_f64(_mm_unpackhi_pd(h2, h2)));
        f.vl = std::min(_mm_cvtsd_f64(vl2), _mm_cvtsd_f64(_mm_unpackhi_pd(vl2, vl2)));
        f.vh = std::max(_mm_cvtsd_f64(vh2), _mm_cvtsd_f64(_mm_unpackhi_pd(vh2, vh2)));
      }
#endif
      for (; e < n.count; ++e)
        f.add(a, i, e, c);
      f.write(b, i, c);
    }
    return b;
  }

  // Where entry e of node n records its place: an object's leaf, a child node's parent.
  void adopt(std::uint32_t n, int e) {
    Node& node = nodes_[n];
    if (node.level == 0)
      obj_leaf_[node.child[e]] = n;
    else
      nodes_[node.child[e]].parent = n;
  }
  int slot_in_parent(std::uint32_t n) const {
    const Node& p = nodes_[nodes_[n].parent];
    for (int e = 0; e < p.count; ++e)
      if (p.child[e] == n) return e;
    throw Error(std::string(kName) + ": a node is missing from its parent");
  }

  void add(Id id, const Motion<D>& m) {
    if (count_ == 0 && root_ == kNone) epoch_ = m.t;
    clock_ = std::max(clock_, m.t);
    std::uint32_t s;
    if (!free_slots_.empty()) {
      s = free_slots_.back();
      free_slots_.pop_back();
    } else {
      if (obj_id_.size() + 1 >= kNone)
        throw InvalidArgument(std::string(kName) + ": too many objects");
      s = std::uint32_t(obj_id_.size());
      obj_id_.push_back(0);
      obj_motion_.push_back({});
      obj_leaf_.push_back(kNone);
    }
    obj_id_[s] = id;
    obj_motion_[s] = m;
    map_.insert(id, s, count_ + 1);
    ++count_;
    if (root_ == kNone) {
      root_ = nodes_.allocate(kName);
      Node& r = nodes_[root_];
      r.parent = kNone;
      r.level = 0;
      r.count = 0;
      r.grouped = 0;
    }
    const Box_ b = Box_::of(m, epoch_);
    for (int i = 0; i < D; ++i) {
      mag_ = std::max({mag_, std::abs(b.lo[i]), std::abs(m.p[i])});
      vmag_ = std::max(vmag_, std::abs(b.vlo[i]));
    }
    std::uint32_t reinserted = 0;
    insert_entry({b, s, m, id}, 0, reinserted);
    if constexpr (Policy::kRegroups) maybe_regroup(obj_leaf_[s]);
  }

  // Choose_Path: the node of `level` whose taking `b` raises the summed cost of the path to
  // it least, by branch and bound. A greedy descent (the cheapest entry of each node on the
  // way) gives a first candidate and its cost, minpen; partial paths cheaper than minpen then
  // wait in a heap by their cost so far, the children of a node just above the target level
  // are candidates compared with minpen, and the search ends when no waiting path is cheaper.
  // Rises are never negative, so no path left out could have done better: the answer is a
  // path of the least summed rise in the whole tree, the cost a best-first search from the
  // root finds (among equals the greedy path is kept), but paths that cannot win never enter
  // the heap.
  //
  // Costs of boxes spread over more than about 1e102 in 3D overflow to inf (the rises are
  // never NaN: enlargements() clamps them with std::max); then the greedy candidate's minpen
  // is inf and any path of finite cost replaces it.
  std::uint32_t choose_path(const Box_& b, int level) {
    if (nodes_[root_].level == level) return root_;
    if (nodes_[root_].level < level)
      throw Error(std::string(kName) + ": no node of level " + std::to_string(level));
    struct Waiting {
      double key;
      std::uint32_t node;
      bool operator<(const Waiting& o) const { return key > o.key; }
    };
    // The greedy descent, each node's rises kept for the bound below.
    struct Step {
      std::uint32_t node;
      int taken;
      double key;
      double rise[kSlots];
    };
    thread_local std::vector<Step> path;
    thread_local std::vector<Waiting> heap;
    path.clear();
    heap.clear();
    std::size_t explored = 0;
    double minpen;
    std::uint32_t best;
    for (std::uint32_t x = root_, depth = 0;; ++depth) {
      if (path.size() <= depth) path.emplace_back();
      Step& st = path[depth];
      Node& n = nodes_[x];
      ++explored;
      enlargements(n, b, st.rise);
      int arg = 0;
      for (int e = 1; e < n.count; ++e)
        if (st.rise[e] < st.rise[arg]) arg = e;
      st.node = x;
      st.taken = arg;
      st.key = depth == 0 ? 0.0 : path[depth - 1].key + path[depth - 1].rise[path[depth - 1].taken];
      if (n.level == level + 1) {
        minpen = st.key + st.rise[arg];
        best = n.child[arg];
        path.resize(depth);  // the last node's other entries cost no less than the candidate
        break;
      }
      x = n.child[arg];
    }
    for (const Step& st : path) {
      const Node& n = nodes_[st.node];
      for (int e = 0; e < n.count; ++e) {
        const double pen = st.key + st.rise[e];
        if (e != st.taken && pen < minpen) heap.push_back({pen, n.child[e]});
      }
    }
    std::make_heap(heap.begin(), heap.end());
    while (!heap.empty()) {
      std::pop_heap(heap.begin(), heap.end());
      const Waiting top = heap.back();
      heap.pop_back();
      if (!(top.key < minpen)) break;
      Node& n = nodes_[top.node];
      ++explored;
      double rise[kSlots];
      enlargements(n, b, rise);
      if (n.level == level + 1) {
        // Candidates: the cheapest entry (the first of equals) against the best so far.
        int arg = 0;
        for (int e = 1; e < n.count; ++e)
          if (rise[e] < rise[arg]) arg = e;
        if (const double pen = top.key + rise[arg]; pen < minpen) {
          minpen = pen;
          best = n.child[arg];
        }
        continue;
      }
      for (int e = 0; e < n.count; ++e) {
        const double pen = top.key + rise[e];
        if (pen < minpen) {
          heap.push_back({pen, n.child[e]});
          std::push_heap(heap.begin(), heap.end());
        }
      }
    }
    max_choose_nodes_ = std::max(max_choose_nodes_, explored);
    return best;
  }

  // Inserts the entry (b, child) into a node of `level`, handling overflow.
  void insert_entry(const Item& it, int level, std::uint32_t& reinserted) {
    const Box_& b = it.box;
    const std::uint32_t n = choose_path(b, level);
    Node& node = nodes_[n];
    put(node, node.count, it);
    ++node.count;
    adopt(n, node.count - 1);
    // Grow the path's bounds.
    const double c = rel_clock();
    for (std::uint32_t x = n; nodes_[x].parent != kNone; x = nodes_[x].parent)
      nodes_[nodes_[x].parent].box[slot_in_parent(x)].enclose(b, c);
    if (node.count > M) overflow(n, reinserted);
  }

  void overflow(std::uint32_t n, std::uint32_t& reinserted) {
    const int level = nodes_[n].level;
    if (n != root_ && !(reinserted & (1u << level))) {
      reinserted |= 1u << level;
      pick_worst(n, reinserted);
    } else {
      split(n, reinserted);
    }
  }

  // Sort key k of entry e: k / D picks lo at the clock, hi at the clock, vlo, vhi; k % D the
  // axis.
  double key(const Node& node, int e, int k) const {
    const int axis = k % D, what = k / D;
    const BoxArray& a = node.box;
    switch (what) {
      case 0:
        return a.lo[axis][e] + a.vlo[axis][e] * rel_clock();
      case 1:
        return a.hi[axis][e] + a.vhi[axis][e] * rel_clock();
      case 2:
        return a.vlo[axis][e];
      default:
        return a.vhi[axis][e];
    }
  }

  // The node's entries in ascending order of sort key k.
  void order_by(const Node& node, int k, std::uint8_t* order) const {
    double keys[kSlots];
    // At most kSlots, said to the compiler too (GCC 12 warned at -O3 of sort's larger paths
    // reaching past the array of a small node).
    const int n = std::min<int>(node.count, kSlots);
    for (int e = 0; e < n; ++e) {
      order[e] = std::uint8_t(e);
      keys[e] = key(node, e, k);
    }
    std::sort(order, order + n, [&](int x, int y) { return keys[x] < keys[y]; });
  }

  // The bounds from the clock on of entries order[from, to) of node, as bound() takes them.
  Box_ union_of(const Node& node, const std::uint8_t* order, int from, int to) const {
    const double c = rel_clock();
    Box_ b;
    for (int i = 0; i < D; ++i) {
      AxisBounds f = AxisBounds::of(node.box, i, order[from], c);
      for (int k = from + 1; k < to; ++k)
        f.add(node.box, i, order[k], c);
      f.write(b, i, c);
    }
    return b;
  }

  // Pick_Worst: removes the entries whose absence shrinks the node's cost most and reinserts
  // them. Each order is sorted once and serves both ends: the `taken` greatest entries
  // (descending) and the `taken` least (ascending). Costs that overflow to inf (or NaN, from
  // inf * 0) gain nothing: when no order does better, the first is taken.
  void pick_worst(std::uint32_t n, std::uint32_t& reinserted) {
    Node& node = nodes_[n];
    const int total = node.count;
    const int taken = std::max(1, int(0.3 * total));
    std::uint8_t order[M + 1], best_order[M + 1];
    double best_gain = -std::numeric_limits<double>::infinity();
    bool chosen = false;
    for (int k = 0; k < 4 * D; ++k) {
      order_by(node, k, order);
      for (bool descending : {true, false}) {
        const double rest = descending ? cost(union_of(node, order, 0, total - taken))
                                       : cost(union_of(node, order, taken, total));
        const double gain = std::isnan(rest) ? -std::numeric_limits<double>::infinity() : -rest;
        if (!chosen || gain > best_gain) {
          chosen = true;
          best_gain = gain;
          // The taken entries first.
          if (descending)
            std::reverse_copy(order, order + total, best_order);
          else
            std::copy(order, order + total, best_order);
        }
      }
    }
    // Take the chosen entries out, keep the rest in place.
    Item out[M + 1];
    bool leaving[M + 1] = {};
    for (int e = 0; e < taken; ++e) {
      leaving[best_order[e]] = true;
      out[e] = take(node, best_order[e]);
    }
    int kept = 0;
    for (int e = 0; e < total; ++e)
      if (!leaving[e]) put(node, kept++, take(node, e));
    node.count = std::uint8_t(kept);
    const int level = node.level;
    tighten_upwards(n);
    for (int e = 0; e < taken; ++e)
      insert_entry(out[e], level, reinserted);
  }

  // Recomputes the bounds of n and its ancestors from their entries at the clock.
  void tighten_upwards(std::uint32_t n) {
    for (std::uint32_t x = n; nodes_[x].parent != kNone; x = nodes_[x].parent)
      nodes_[nodes_[x].parent].box[slot_in_parent(x)] = bound(nodes_[x]);
  }

  // Splits n along the sort order and cut of least summed cost. Costs that overflow to inf (or
  // NaN, from inf * 0) are the worst: when no distribution does better, the first is taken.
  void split(std::uint32_t n, std::uint32_t& reinserted) {
    Node& node = nodes_[n];
    const int total = node.count;
    std::uint8_t order[M + 1], best_order[M + 1];
    int best_cut = 0;
    double best = std::numeric_limits<double>::infinity();
    Box_ prefix[M + 1], suffix[M + 1];
    for (int k = 0; k < 4 * D; ++k) {
      order_by(node, k, order);
      prefix[0] = node.box[order[0]];
      for (int e = 1; e < total; ++e)
        (prefix[e] = prefix[e - 1]).enclose(node.box[order[e]], rel_clock());
      suffix[total - 1] = node.box[order[total - 1]];
      for (int e = total - 2; e >= 0; --e)
        (suffix[e] = suffix[e + 1]).enclose(node.box[order[e]], rel_clock());
      for (int cut = kMinFill; cut <= total - kMinFill; ++cut) {
        double c = cost(prefix[cut - 1]) + cost(suffix[cut]);
        if (std::isnan(c)) c = std::numeric_limits<double>::infinity();
        if (best_cut == 0 || c < best) {
          best = c;
          best_cut = cut;
          std::copy(order, order + total, best_order);
        }
      }
    }
    const std::uint32_t sib = nodes_.allocate(kName);
    Node& a = nodes_[n];  // allocation may have moved the pool
    Node& b = nodes_[sib];
    b.level = a.level;
    b.count = 0;
    b.grouped = 0;
    a.grouped = 0;
    Item items[M + 1];
    for (int e = 0; e < total; ++e)
      items[e] = take(a, best_order[e]);
    a.count = 0;
    for (int e = 0; e < total; ++e) {
      Node& to = e < best_cut ? a : b;
      put(to, to.count++, items[e]);
    }
    for (int e = 0; e < b.count; ++e)
      adopt(sib, e);
    if (n == root_) {
      const std::uint32_t r = nodes_.allocate(kName);
      Node& root = nodes_[r];
      root.parent = kNone;
      root.level = std::uint8_t(nodes_[n].level + 1);
      root.count = 2;
      root.grouped = 0;
      root.box[0] = bound(nodes_[n]);
      root.child[0] = n;
      root.box[1] = bound(nodes_[sib]);
      root.child[1] = sib;
      nodes_[n].parent = r;
      nodes_[sib].parent = r;
      root_ = r;
      return;
    }
    const std::uint32_t p = nodes_[n].parent;
    nodes_[p].box[slot_in_parent(n)] = bound(nodes_[n]);
    Node& parent = nodes_[p];
    parent.box[parent.count] = bound(nodes_[sib]);
    parent.child[parent.count] = sib;
    ++parent.count;
    nodes_[sib].parent = p;
    tighten_upwards(p);
    if (parent.count > M) overflow(p, reinserted);
  }

  void remove_slot(std::uint32_t s) {
    const std::uint32_t leaf = obj_leaf_[s];
    Node& node = nodes_[leaf];
    int e = 0;
    while (node.child[e] != s)
      ++e;
    put(node, e, take(node, node.count - 1));
    --node.count;
    map_.erase(obj_id_[s]);
    obj_leaf_[s] = kNone;
    free_slots_.push_back(s);
    --count_;
    condense(leaf);
  }

  // Writes the new report over the old one when the leaf's bounds, as its parent records
  // them, hold it from the clock on (compared without slack); the leaf's bounds are then
  // recomputed, which can only shrink them. False when it does not fit.
  bool update_in_place(std::uint32_t s, const Motion<D>& m) {
    const std::uint32_t leaf = obj_leaf_[s];
    const double clock = std::max(clock_, m.t), c = clock - epoch_;
    const Box_ b = Box_::of(m, epoch_);
    const bool root = nodes_[leaf].parent == kNone;
    int slot = 0;
    if (!root) {
      slot = slot_in_parent(leaf);
      const Box_& bound = nodes_[nodes_[leaf].parent].box[slot];
      for (int i = 0; i < D; ++i)
        if (bound.vlo[i] > b.vlo[i] || bound.vhi[i] < b.vhi[i] ||
            bound.lo_at(i, c) > b.lo_at(i, c) || bound.hi_at(i, c) < b.hi_at(i, c))
          return false;
    }
    clock_ = clock;
    for (int i = 0; i < D; ++i) {
      mag_ = std::max({mag_, std::abs(b.lo[i]), std::abs(m.p[i])});
      vmag_ = std::max(vmag_, std::abs(b.vlo[i]));
    }
    Node& node = nodes_[leaf];
    int e = 0;
    while (node.child[e] != s)
      ++e;
    put(node, e, {b, s, m, node.id[e]});
    obj_motion_[s] = m;
    if (!root) nodes_[node.parent].box[slot] = bound(node);
    if constexpr (Policy::kRegroups) maybe_regroup(leaf);
    return true;
  }

  // The area of b at the clock.
  double area_now(const Box_& b) const {
    double a = 1;
    for (int i = 0; i < D; ++i)
      a *= b.hi_at(i, rel_clock()) - b.lo_at(i, rel_clock());
    return a;
  }

  // Regrouping policies: walks from the leaf's parent to the root and regroups the first node
  // whose box at the clock has grown past Policy::ratio times its area when it was last
  // grouped (a node not yet measured is measured now).
  void maybe_regroup(std::uint32_t leaf) {
    for (std::uint32_t x = nodes_[leaf].parent; x != kNone; x = nodes_[x].parent) {
      const double now = area_now(bound(nodes_[x]));
      Node& node = nodes_[x];
      if (!(node.grouped > 0)) {
        node.grouped = now;
        continue;
      }
      if (now > Policy::ratio(params_) * node.grouped) return regroup(x);
    }
  }

  // Deals the entries of x's children out again among as many new children, tiled by
  // Sort-Tile-Recursive on their centres at the clock, so that each child is tight now.
  void regroup(std::uint32_t x) {
    ++regroups_;
    thread_local std::vector<Item> items;
    items.clear();
    const int k = nodes_[x].count;
    const int level = nodes_[x].level - 1;
    for (int e = 0; e < k; ++e) {
      const std::uint32_t ch = nodes_[x].child[e];
      for (int i = 0; i < nodes_[ch].count; ++i)
        items.push_back(take(nodes_[ch], i));
      nodes_.release(ch);
    }
    std::vector<std::size_t> groups(k + 1);
    for (int g = 0; g <= k; ++g)
      groups[g] = items.size() * g / k;
    const double c = rel_clock();
    detail::str_tile<D>(
        items.data(), std::span<const std::size_t>(groups),
        [c](const Item& it, int axis) { return it.box.lo_at(axis, c) + it.box.hi_at(axis, c); });
    for (int g = 0; g < k; ++g) {
      const std::uint32_t n = nodes_.allocate(kName);
      Node& nd = nodes_[n];
      nd.parent = x;
      nd.level = std::uint8_t(level);
      nd.count = 0;
      for (std::size_t i = groups[g]; i < groups[g + 1]; ++i) {
        put(nd, nd.count, items[i]);
        adopt(n, nd.count++);
      }
      nd.grouped = area_now(bound(nd));
      nodes_[x].box[g] = bound(nd);
      nodes_[x].child[g] = n;
    }
    nodes_[x].grouped = area_now(bound(nodes_[x]));
    tighten_upwards(x);
  }

  // Dissolves underfull nodes from n up, tightens the rest of the path, reinserts orphans.
  void condense(std::uint32_t n) {
    struct Orphan {
      Item item;
      int level;
    };
    thread_local std::vector<Orphan> orphans;
    orphans.clear();
    std::uint32_t x = n;
    while (x != root_) {
      const std::uint32_t p = nodes_[x].parent;
      Node& node = nodes_[x];
      const int e = slot_in_parent(x);
      if (node.count < kMinFill) {
        for (int i = 0; i < node.count; ++i)
          orphans.push_back({take(node, i), node.level});
        Node& parent = nodes_[p];
        put(parent, e, take(parent, parent.count - 1));
        --parent.count;
        nodes_.release(x);
      } else {
        nodes_[p].box[e] = bound(node);
      }
      x = p;
    }
    // Higher levels first, so that their subtrees find a level to go to.
    std::sort(orphans.begin(), orphans.end(),
              [](const Orphan& a, const Orphan& b) { return a.level > b.level; });
    for (const Orphan& o : orphans) {
      std::uint32_t reinserted = 0;
      insert_entry(o.item, o.level, reinserted);
    }
    // A root with one child hands over to it; an empty leaf root goes.
    while (nodes_[root_].level > 0 && nodes_[root_].count == 1) {
      const std::uint32_t old = root_;
      root_ = nodes_[old].child[0];
      nodes_[root_].parent = kNone;
      nodes_.release(old);
    }
    if (count_ == 0) {
      nodes_.clear();
      root_ = kNone;
    }
  }

  template <class F>
  QueryStats scan(const MovingWindow<D>& w, F& visit) const {
    QueryStats st;
    st.nodes_visited = 1;
    for (std::uint32_t s = 0; s < obj_id_.size(); ++s) {
      if (obj_leaf_[s] == kNone) continue;
      ++st.entries_tested;
      if (!inside(obj_motion_[s], w)) continue;
      ++st.results;
      if (!visit(obj_id_[s], obj_motion_[s])) break;
    }
    return st;
  }

  void validate_node(std::uint32_t n, std::vector<bool>& seen, std::size_t& objects) const {
    const std::string who(kName);
    if (seen[n]) throw Error(who + ": node " + std::to_string(n) + " is reachable twice");
    seen[n] = true;
    const Node& node = nodes_[n];
    if (node.count > M) throw Error(who + ": node over capacity");
    if (n != root_ && node.count < kMinFill) throw Error(who + ": node under the minimum fill");
    if (n == root_ && node.level > 0 && node.count < 2) throw Error(who + ": root with one child");
    const double c = rel_clock();
    // Entry costs kept for Choose_Path at the clock are those of the entries' boxes.
    if (node.box.costed_at == c)
      for (int e = 0; e < node.count; ++e) {
        double now;
        grown_costs(node.box, e, e + 1, Taken::nothing(), c, &now);
        const double kept = node.box.cost[e];
        if (!(node.box.stale >> e & 1) && kept != now && !(std::isnan(kept) && std::isnan(now)))
          throw Error(who + ": node " + std::to_string(n) + " keeps a stale entry cost");
      }
    if (n != root_) {
      const Box_& mine = nodes_[node.parent].box[slot_in_parent(n)];
      for (int e = 0; e < node.count; ++e)
        if (!mine.encloses(node.box[e], c))
          throw Error(who + ": an entry of node " + std::to_string(n) + " escapes its bound");
    }
    for (int e = 0; e < node.count; ++e) {
      if (node.level == 0) {
        const std::uint32_t s = node.child[e];
        if (s >= obj_id_.size() || obj_leaf_[s] != n)
          throw Error(who + ": an object does not point back to its leaf");
        if (!node.box[e].encloses(Box_::of(obj_motion_[s], epoch_), c))
          throw Error(who + ": an object's entry does not hold its report");
        ++objects;
      } else {
        const std::uint32_t ch = node.child[e];
        if (nodes_[ch].parent != n) throw Error(who + ": a child does not point to its parent");
        if (nodes_[ch].level + 1 != node.level) throw Error(who + ": levels are inconsistent");
        validate_node(ch, seen, objects);
      }
    }
  }

  void swap(MovingRTree& other) noexcept {
    std::swap(params_, other.params_);
    nodes_.swap(other.nodes_);
    std::swap(root_, other.root_);
    obj_id_.swap(other.obj_id_);
    obj_motion_.swap(other.obj_motion_);
    obj_leaf_.swap(other.obj_leaf_);
    free_slots_.swap(other.free_slots_);
    cells_.swap(other.cells_);
    cells_tmp_.swap(other.cells_tmp_);
    level_.swap(other.level_);
    up_.swap(other.up_);
    std::swap(map_, other.map_);
    std::swap(count_, other.count_);
    std::swap(epoch_, other.epoch_);
    std::swap(clock_, other.clock_);
    std::swap(max_choose_nodes_, other.max_choose_nodes_);
    std::swap(regroups_, other.regroups_);
    std::swap(mag_, other.mag_);
    std::swap(vmag_, other.vmag_);
  }
  Params params_;
  Pool nodes_;
  std::uint32_t root_ = kNone;
  // The object table by slot, on huge pages: build() reads it in tiling order, scattered.
  detail::LargeVector<Id> obj_id_;
  detail::LargeVector<Motion<D>> obj_motion_;
  detail::LargeVector<std::uint32_t> obj_leaf_;  // kNone: a free slot
  std::vector<std::uint32_t> free_slots_;
  // Scratch of build, kept so that a tree rebuilt every tick touches no new pages.
  std::vector<detail::CellItem> cells_, cells_tmp_;
  std::vector<Item> level_, up_;
  detail::IdMap map_;
  std::size_t count_ = 0;
  double epoch_ = 0;
  double clock_ = -std::numeric_limits<double>::infinity();
  std::size_t max_choose_nodes_ = 0;
  std::size_t regroups_ = 0;
  double mag_ = 0;   // largest |coordinate| of an object's report or entry at the epoch
  double vmag_ = 0;  // largest |velocity| component
};

}  // namespace detail
}  // namespace loci
