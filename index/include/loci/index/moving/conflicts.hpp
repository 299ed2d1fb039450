// Conflicts: every pair of moving points that comes within a distance D during a horizon.
//
// find_conflicts(objects, D, now, H, visit) reports each pair (i, j), i < j indices into
// `objects`, whose distance is at most D at some time of [now, now + H], with its closest
// approach (tcpa clamped to the horizon, dcpa, and the entry and exit times of the D-circle;
// geom/motion.hpp closest_approach, which alone decides).
//
// Broad phase. Two objects within D of each other at time s lie, at s, in boxes of half-side
// D/2 around their positions that meet (the L-infinity distance is at most the Euclidean
// one); so the boxes they sweep over any slice of the horizon containing s, grown by D/2,
// meet too. The horizon is cut into `slices` equal slices; for each slice the grown swept
// boxes go through a sort-and-sweep broad phase (broadphase/sweep_prune.hpp), and each
// candidate pair gets the exact closest-approach test. A pair is reported from the slice that
// holds its entry time t_enter only, so pairs found in several slices are reported once
// without a set of seen pairs; at its entry time the pair is within D, so that slice's boxes
// meet and the pair is not missed. Boxes are grown by a hair more than D/2 so that rounding in
// the positions cannot lose a pair that touches the D-circle.
//
// More slices mean smaller boxes (fewer candidates) but one more sort per slice; slices = 0
// picks the count from a cost model of the two (auto_slices), at most 16.
//
// ConflictMonitor keeps the answer of a stream: after a batch of new reports it recomputes
// only the pairs that involve the objects that reported, and repeats the full computation
// when the clock passes the slack it computed ahead (see its comment).
//
// Complexity: O(slices (n log n + candidates)) time, O(n) memory. Thread-safety: the
// function is reentrant; a ConflictMonitor needs exclusive access to update.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "loci/geom/motion.hpp"
#include "loci/index/broadphase/detail/proxy_table.hpp"
#include "loci/index/broadphase/dynamic_aabb_tree.hpp"
#include "loci/index/broadphase/sweep_prune.hpp"
#include "loci/index/detail/hilbert.hpp"
#include "loci/index/detail/radix_sort.hpp"
#include "loci/index/packed_rtree.hpp"
#include "loci/index/query.hpp"

namespace loci {

// One conflict, by the caller's ids, a < b.
struct Conflict {
  Id a;
  Id b;
  Approach approach;
};

// Orders conflicts by (a, b), the order every list of conflicts is given in.
inline void sort_conflicts(std::vector<Conflict>& v) {
  std::sort(v.begin(), v.end(), [](const Conflict& x, const Conflict& y) {
    return x.a != y.a ? x.a < y.a : x.b < y.b;
  });
}

// visitor(i, j, approach) with i < j; false stops.
template <class F>
concept ConflictVisitor = Visitor<F, std::uint32_t, std::uint32_t, const Approach&>;

namespace detail {

// The box a point sweeps over [t0, t1], grown by `grow` on every side.
template <int D>
Box<D> grown_sweep(const Motion<D>& m, double t0, double t1, double grow) {
  const Point<D> a = position(m, t0), b = position(m, t1);
  Box<D> box = Box<D>::of_point(a);
  box.expand(b);
  for (int i = 0; i < D; ++i) {
    // A hair over `grow`, relative to the coordinates, so that rounding never shrinks it.
    const double pad =
        grow * (1 + 1e-12) + 4 * std::numeric_limits<double>::epsilon() *
                                 std::max(std::abs(box.min[i]), std::abs(box.max[i]));
    box.min[i] -= pad;
    box.max[i] += pad;
  }
  return box;
}

// The slice count that minimizes a cost model of the broad phase: each slice sorts every
// object (about 100 ns each), and each candidate pair costs about 5 ns; candidates are
// estimated from the density of the fleet and the grown boxes' mean extents per axis,
// D + (mean distance moved along the axis) / slices.
template <int D>
std::size_t auto_slices(std::span<const Motion<D>> objects, double within, double horizon) {
  if (objects.size() < 2 || horizon <= 0) return 1;
  Box<D> extent = Box<D>::empty();
  double moved[D] = {};
  for (const Motion<D>& m : objects) {
    extent.expand(m.p);
    for (int i = 0; i < D; ++i)
      moved[i] += std::abs(m.v[i]) * horizon;
  }
  const double n = double(objects.size());
  double volume = 1;
  for (int i = 0; i < D; ++i) {
    moved[i] /= n;
    volume *= std::max(extent.extent(i) + moved[i], within + 1e-300);
  }
  const double density = n / volume;
  std::size_t best = 1;
  double best_cost = std::numeric_limits<double>::infinity();
  for (std::size_t s = 1; s <= 16; ++s) {
    double overlap = 1;
    for (int i = 0; i < D; ++i)
      overlap *= 2 * (within + moved[i] / double(s));
    const double candidates = 0.5 * n * std::min(n, density * overlap);
    const double cost = 100 * n * double(s) + 5 * candidates;
    if (cost < best_cost) best_cost = cost, best = s;
  }
  return best;
}

}  // namespace detail

// Throws InvalidArgument for a negative or non-finite distance or horizon, or a non-finite now.
inline void check_conflict_query(double within, double now, double horizon) {
  if (!std::isfinite(within) || within < 0)
    throw InvalidArgument("conflict distance must be a finite number >= 0");
  if (!std::isfinite(horizon) || horizon < 0)
    throw InvalidArgument("conflict horizon must be a finite number >= 0");
  if (!std::isfinite(now)) throw InvalidArgument("conflict time is NaN or infinite");
}

// The broad phase and buffers of conflict searches, kept between calls so that a search
// repeated every tick reuses its memory (and the broad phase its proxies).
template <int D>
class ConflictFinder {
 public:
  template <ConflictVisitor F>
  QueryStats find(std::span<const Motion<D>> objects, double within, double now, double horizon,
                  F&& visit, std::size_t slices = 0) {
    check_conflict_query(within, now, horizon);
    if (slices == 0) slices = detail::auto_slices(objects, within, horizon);
    QueryStats st;
    if (objects.size() < 2) return st;
    if (objects.size() >= kNone) throw InvalidArgument("find_conflicts: too many objects");
    prepare(objects, now, horizon);
    const std::size_t n = objects.size();
    // Pairs whose closest approach computed from the positions at `now` is clearly beyond D
    // (by more than rounding can explain) are dropped before the exact test, which alone
    // decides the rest.
    const double reach = within * (1 + 1e-9) + 1e-9 * scale_;
    const double reach2 = reach * reach;
    auto clearly_apart = [&](std::uint32_t a, std::uint32_t b) {
      double dw = 0, ww = 0, dd = 0;
      Point<D> d{}, w{};
      for (int k = 0; k < D; ++k) {
        d[k] = at_now_[b][k] - at_now_[a][k];
        w[k] = motion_[b].v[k] - motion_[a].v[k];
        dw += d[k] * w[k];
        ww += w[k] * w[k];
      }
      const double u = std::min(std::max(-dw / std::max(ww, 1e-300), 0.0), horizon);
      for (int k = 0; k < D; ++k) {
        const double c = d[k] + w[k] * u;
        dd += c * c;
      }
      return dd > reach2;
    };
    const double step = horizon / double(slices);
    for (std::size_t s = 0; s < slices; ++s) {
      const double t0 = now + step * double(s);
      const double t1 = s + 1 == slices ? now + horizon : now + step * double(s + 1);
      for (std::uint32_t k = 0; k < n; ++k) {
        const Box<D> b = detail::grown_sweep(objects[order_[k]], t0, t1, 0.5 * within);
        if (k < held_)
          broad_.move(k, b);
        else
          broad_.add(k, b);
      }
      for (std::size_t k = n; k < held_; ++k)
        broad_.remove(k);
      held_ = n;
      bool go = true;
      const QueryStats bs = broad_.pairs([&](Id a, Id b) {
        ++st.entries_tested;
        if (clearly_apart(std::uint32_t(a), std::uint32_t(b))) return true;
        std::uint32_t i = order_[a], j = order_[b];
        if (j < i) std::swap(i, j), std::swap(a, b);
        // The same reports as objects[i] and objects[j], copied in proxy order.
        const auto ap = closest_approach(motion_[a], motion_[b], now, horizon, within);
        if (!ap) return true;
        // Reported from the slice holding the entry time only.
        const bool first = s == 0 || ap->t_enter > t0;
        const bool last = s + 1 == slices || ap->t_enter <= t1;
        if (!first || !last) return true;
        ++st.results;
        return go = visit(i, j, *ap);
      });
      st.nodes_visited += bs.nodes_visited;
      if (!go) break;
    }
    return st;
  }

 private:
  // Numbers the objects in Hilbert order of their positions at mid-horizon, so that the pairs
  // the broad phase reports (neighbours in space) read neighbouring memory.
  void prepare(std::span<const Motion<D>> objects, double now, double horizon) {
    const std::size_t n = objects.size();
    at_now_.resize(n);
    motion_.resize(n);
    Box<D> extent = Box<D>::empty();
    for (const Motion<D>& m : objects)
      extent.expand(position(m, now + 0.5 * horizon));
    const detail::HilbertGrid<D> grid(extent);
    keyed_.resize(n);
    for (std::uint32_t i = 0; i < n; ++i)
      keyed_[i] = {grid.key(position(objects[i], now + 0.5 * horizon)), i};
    detail::radix_sort(keyed_, D * detail::hilbert_bits<D>());
    order_.resize(n);
    scale_ = 0;
    for (std::uint32_t k = 0; k < n; ++k) {
      const std::uint32_t i = keyed_[k].index;
      order_[k] = i;
      at_now_[k] = position(objects[i], now);
      motion_[k] = objects[i];
      for (int a = 0; a < D; ++a)
        scale_ = std::max(scale_, std::abs(at_now_[k][a]) + std::abs(motion_[k].v[a]) * horizon);
    }
  }

  SweepPrune<D> broad_;
  std::size_t held_ = 0;  // proxies 0 .. held_ - 1 are in broad_
  std::vector<detail::KeyedIndex> keyed_;
  std::vector<std::uint32_t> order_;  // input index by proxy number
  std::vector<Point<D>> at_now_;      // positions at `now` by proxy number
  std::vector<Motion<D>> motion_;     // the reports by proxy number
  double scale_ = 0;                  // largest coordinate magnitude reached
};

template <int D, ConflictVisitor F>
QueryStats find_conflicts(std::span<const Motion<D>> objects, double within, double now,
                          double horizon, F&& visit, std::size_t slices = 0) {
  ConflictFinder<D> finder;
  return finder.find(objects, within, now, horizon, visit, slices);
}

// The conflicts among objects named by ids (ids[i] names objects[i]), sorted by (a, b).
template <int D>
std::vector<Conflict> find_conflicts(std::span<const Id> ids, std::span<const Motion<D>> objects,
                                     double within, double now, double horizon) {
  if (ids.size() != objects.size())
    throw InvalidArgument("find_conflicts: ids and objects differ in length");
  std::vector<Conflict> out;
  find_conflicts<D>(objects, within, now, horizon,
                    [&](std::uint32_t i, std::uint32_t j, const Approach& ap) {
                      Id a = ids[i], b = ids[j];
                      if (b < a) std::swap(a, b);
                      out.push_back({a, b, ap});
                      return true;
                    });
  sort_conflicts(out);
  return out;
}

// ConflictMonitor<D>: the conflicts of a fleet kept up to date as reports stream in.
//
// It computes ahead: at a full computation at time b it keeps every pair within D during
// [b, b + H + slack] (find_conflicts), and the grown swept boxes of that span in a packed
// R-tree (packed_rtree.hpp). After a batch of reports, refresh(now) with now <= b + slack
// drops the kept pairs of the objects that reported and looks for their new pairs with one
// query each: the pairs of the others cannot have changed, since their reports did not and
// [now, now + H] lies inside the span already searched. Objects that reported since b have
// stale boxes in the packed tree, which queries skip; their current boxes are in a small
// dynamic AABB tree (broadphase/dynamic_aabb_tree.hpp) that queries look at too. Once now passes
// b + slack, refresh computes everything again from now. conflicts(visit) then reports, from
// the kept pairs, those within D during [now, now + H], with the same closest approach as
// find_conflicts at now (each kept pair is tested again at now, so answers are identical to a
// computation from scratch).
//
// Cost: a full computation as find_conflicts over the longer span; an incremental refresh
// O(reported x (log n + candidates)); conflicts() O(kept pairs). Objects are named by the
// caller's ids. Thread-safety: one thread at a time.
template <int D>
class ConflictMonitor {
 public:
  ConflictMonitor(double within, double horizon, double slack)
      : within_(within), horizon_(horizon), slack_(slack) {
    check_conflict_query(within, 0, horizon);
    if (!std::isfinite(slack) || slack < 0)
      throw InvalidArgument("conflict monitor slack must be a finite number >= 0");
  }

  // A new report for id (added when new); the latest given replaces the earlier.
  void report(Id id, const Motion<D>& m) {
    check_motion(m);
    std::uint32_t s = slots_.find(id);
    if (s == kNone) {
      if (!free_.empty()) {
        s = free_.back();
        free_.pop_back();
      } else {
        s = std::uint32_t(ids_.size());
        ids_.push_back(0);
        motion_.emplace_back();
        alive_.push_back(0);
        dirty_.push_back(0);
        adj_.emplace_back();
      }
      ids_[s] = id;
      alive_[s] = 1;
      slots_.insert(id, s, ++count_);
    }
    motion_[s] = m;
    mark(s);
  }

  bool remove(Id id) {
    const std::uint32_t s = slots_.find(id);
    if (s == kNone) return false;
    slots_.erase(id);
    alive_[s] = 0;
    --count_;
    mark(s);
    return true;
  }

  std::size_t size() const { return count_; }
  // Full computations and incremental refreshes done so far.
  std::size_t full_computations() const { return full_; }
  std::size_t incremental_refreshes() const { return incremental_; }

  // Brings the kept pairs up to time now.
  QueryStats refresh(double now) {
    if (!std::isfinite(now)) throw InvalidArgument("conflict time is NaN or infinite");
    now_ = now;
    if (!computed_ || now < base_ || now > base_ + slack_) return recompute(now);
    ++incremental_;
    QueryStats st;
    const double t1 = base_ + horizon_ + slack_;
    dirty_seen_.resize(ids_.size(), 0);
    for (std::uint32_t s : dirty_list_)
      if (alive_[s]) widen(motion_[s], t1 - base_);
    // Drop every kept pair of the objects that reported.
    for (std::uint32_t s : dirty_list_) {
      for (std::uint32_t t : adj_[s])
        std::erase(adj_[t], s);
      adj_[s].clear();
    }
    moved_.resize(ids_.size(), 0);
    for (std::uint32_t s : dirty_list_) {
      dirty_[s] = 0;
      moved_[s] = 1;
      if (!alive_[s]) {
        recent_.remove(s);
        free_.push_back(s);
        continue;
      }
      const Box<D> b = detail::grown_sweep(motion_[s], base_, t1, 0.5 * keep_);
      if (recent_.contains(s))
        recent_.move(s, b);
      else
        recent_.add(s, b);
    }
    for (std::uint32_t s : dirty_list_) {
      if (!alive_[s]) continue;
      const Box<D> b = detail::grown_sweep(motion_[s], base_, t1, 0.5 * keep_);
      auto candidate = [&](Id other, const Box<D>&) {
        const auto t = std::uint32_t(other);
        // A pair of two reporting objects is taken from the first of them looked at.
        if (t == s || dirty_seen_[t]) return true;
        if (closest_approach(motion_[s], motion_[t], base_, t1 - base_, keep_)) link(s, t);
        return true;
      };
      st += packed_.query(b, [&](Id k, const Box<D>& ob) {
        // Boxes of objects that reported since the base are stale here.
        const std::uint32_t other = packed_slot_[k];
        return moved_[other] ? true : candidate(other, ob);
      });
      st += recent_.query(b, candidate);
      dirty_seen_[s] = 1;
    }
    for (std::uint32_t s : dirty_list_)
      dirty_seen_[s] = 0;
    dirty_list_.clear();
    return st;
  }

  // The conflicts during [now, now + H] (now as given to the last refresh), by ids, a < b.
  template <class F>
  void conflicts(F&& visit) const {
    for (std::uint32_t s = 0; s < adj_.size(); ++s)
      for (std::uint32_t t : adj_[s]) {
        if (t < s) continue;
        const bool sa = ids_[s] < ids_[t];
        const Motion<D>& a = sa ? motion_[s] : motion_[t];
        const Motion<D>& b = sa ? motion_[t] : motion_[s];
        if (auto ap = closest_approach(a, b, now_, horizon_, within_))
          if (!visit(sa ? ids_[s] : ids_[t], sa ? ids_[t] : ids_[s], *ap)) return;
      }
  }
  std::vector<Conflict> conflicts() const {
    std::vector<Conflict> out;
    conflicts([&](Id a, Id b, const Approach& ap) { return out.push_back({a, b, ap}), true; });
    sort_conflicts(out);
    return out;
  }

 private:
  void mark(std::uint32_t s) {
    if (!dirty_[s]) {
      dirty_[s] = 1;
      dirty_list_.push_back(s);
    }
  }
  // Kept pairs are those within keep_, a hair more than D (relative to the magnitudes seen),
  // so that a pair within D at a later `now` is never lost to rounding at the base time.
  void widen(const Motion<D>& m, double span) {
    const Point<D> p = position(m, base_);
    for (int a = 0; a < D; ++a)
      scale_ = std::max(scale_, std::abs(p[a]) + std::abs(m.v[a]) * span);
    keep_ = within_ * (1 + 1e-9) + 1e-9 * scale_;
  }
  void link(std::uint32_t s, std::uint32_t t) {
    adj_[s].push_back(t);
    adj_[t].push_back(s);
  }

  QueryStats recompute(double now) {
    ++full_;
    computed_ = true;
    base_ = now;
    const double span = horizon_ + slack_;
    for (std::uint32_t s : dirty_list_) {
      dirty_[s] = 0;
      if (!alive_[s]) free_.push_back(s);
    }
    dirty_list_.clear();
    dirty_seen_.assign(ids_.size(), 0);
    std::vector<std::uint32_t> live;
    std::vector<Motion<D>> dense;
    recent_.clear();
    moved_.assign(ids_.size(), 0);
    scale_ = 0;
    for (std::uint32_t s = 0; s < ids_.size(); ++s) {
      adj_[s].clear();
      if (!alive_[s]) continue;
      live.push_back(s);
      dense.push_back(motion_[s]);
      widen(motion_[s], span);
    }
    // The packed tree names entries by their index in `boxes`, packed_slot_ maps it back.
    std::vector<Box<D>> boxes;
    boxes.reserve(live.size());
    for (std::uint32_t s : live)
      boxes.push_back(detail::grown_sweep(motion_[s], now, now + span, 0.5 * keep_));
    packed_ = PackedRTree<D>::build(boxes);
    packed_slot_ = live;
    return finder_.find(std::span<const Motion<D>>(dense), keep_, now, span,
                        [&](std::uint32_t i, std::uint32_t j, const Approach&) {
                          link(live[i], live[j]);
                          return true;
                        });
  }

  double within_, horizon_, slack_;
  double base_ = 0, now_ = 0, scale_ = 0, keep_ = 0;
  bool computed_ = false;
  std::size_t full_ = 0, incremental_ = 0;
  std::vector<Id> ids_;
  std::vector<Motion<D>> motion_;
  std::vector<std::uint8_t> alive_, dirty_, dirty_seen_, moved_;
  std::vector<std::uint32_t> dirty_list_, free_;
  std::vector<std::vector<std::uint32_t>> adj_;  // kept pairs, both ways
  detail::IdMap slots_;
  std::size_t count_ = 0;
  PackedRTree<D> packed_;                   // grown swept boxes at the base
  std::vector<std::uint32_t> packed_slot_;  // slot of each entry of packed_
  DynamicAabbTree<D> recent_;               // the same for objects that reported since the base
  ConflictFinder<D> finder_;
};

}  // namespace loci
