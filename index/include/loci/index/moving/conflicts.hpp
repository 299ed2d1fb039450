// Conflicts: every pair of moving points that comes within a distance D during a horizon.
//
// find_conflicts(objects, D, now, H, visit) reports each pair (i, j), i < j indices into
// `objects`, whose distance is at most D at some time of [now, now + H], with its closest
// approach (tcpa clamped to the horizon, dcpa, and the entry and exit times of the D-circle;
// geom/motion.hpp closest_approach, which alone decides). It throws InvalidArgument, naming
// the object, for one whose velocity exceeds 1e150 or whose position leaves +-1e150 during
// the horizon (the differences of such values could overflow and lose pairs).
//
// Broad phase. Two objects within D of each other at time s lie, at s, in boxes of half-side
// D/2 around their positions that meet (the L-infinity distance is at most the Euclidean
// one); so the boxes they sweep over any slice of the horizon containing s, grown by D/2,
// meet too. The horizon is cut into `slices` equal slices; for each slice the grown swept
// boxes go through a sort-and-sweep broad phase (broadphase/sweep_prune.hpp, entry_pairs:
// positions and velocities are copied into the sweep's order, so that a run's candidates
// are read from neighbouring memory), each candidate pair gets a quick test without division
// or branch (its closest approach from the positions at `now`, with a margin for rounding),
// and the pairs that pass get the exact closest-approach test. A pair is reported from the slice
// that holds its entry time t_enter only, so pairs found in several slices are reported once
// without a set of seen pairs; at its entry time the pair is within D, so that slice's boxes
// meet and the pair is not missed. Boxes are grown by a hair more than D/2 so that rounding in
// the positions (relative to the coordinates and to the distance moved since the report,
// since a slice's boxes start from the report and the exact test from the positions at now)
// cannot lose a pair that touches the D-circle, and the last slice ends at
// now + H rounded up (window_end), so that rounding in the time cannot either.
//
// More slices mean smaller boxes (fewer candidates) but one more sort per slice; slices = 0
// picks the count from a cost model of the two (auto_slices), at most 16.
//
// ConflictMonitor keeps the answer of a stream: after a batch of new reports it recomputes
// only the pairs that involve the objects that reported, and repeats the full computation
// when the clock passes the slack it computed ahead (see its comment).
//
// Complexity: O(slices (n log n + candidates)) time, O(n) memory, which a thread keeps for
// its next search up to 131,072 objects (see find_conflicts below). Thread-safety: the
// function is reentrant; a ConflictMonitor needs exclusive access to update.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "loci/geom/motion.hpp"
#include "loci/index/broadphase/detail/proxy_table.hpp"
#include "loci/index/broadphase/sweep_prune.hpp"
#include "loci/index/detail/hilbert.hpp"
#include "loci/index/detail/large_alloc.hpp"
#include "loci/index/detail/radix_sort.hpp"
#include "loci/index/detail/scratch.hpp"
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

// The box a point sweeps over [t0, t1], grown by `grow` on every side. `from` is the time
// whose positions the exact test measures from (t0 by default): the box is padded for the
// rounding of the positions at t0 and t1 and of those at `from` carried forward, which differ
// from each other by rounding that grows with the times elapsed since the report (a report
// long before `from` moved over many steps), not only with the coordinates, and for the
// rounding of the absolute times themselves.
template <int D>
Box<D> grown_sweep(const Motion<D>& m, double t0, double t1, double grow, double from) {
  const Point<D> a = position(m, t0), b = position(m, t1);
  Box<D> box = Box<D>::of_point(a);
  box.expand(b);
  // Times elapsed since the report and since `from`, and the times themselves: the exact
  // test's entry time, now + a time from now, rounds to a step of the clock there (2^-22 s
  // near 1.7e9), so a pair entering just after t1 can be given the slice ending at t1.
  const double elapsed = std::abs(from - m.t) + std::abs(t0 - m.t) + std::abs(t1 - m.t) +
                         std::abs(t1 - from) + std::abs(t0) + std::abs(t1);
  for (int i = 0; i < D; ++i) {
    // A hair over `grow`, relative to the coordinates and the distances moved, so that
    // rounding never shrinks it.
    const double pad =
        grow * (1 + 1e-12) + 4 * std::numeric_limits<double>::epsilon() *
                                 (std::max(std::abs(box.min[i]), std::abs(box.max[i])) +
                                  std::abs(m.v[i]) * elapsed + std::abs(m.p[i]));
    box.min[i] -= pad;
    box.max[i] += pad;
  }
  return box;
}
template <int D>
Box<D> grown_sweep(const Motion<D>& m, double t0, double t1, double grow) {
  return grown_sweep(m, t0, t1, grow, t0);
}

// start + length rounded up, never below the exact sum: at epoch-second times the sum rounds
// to a step of 2^-22 s, and a box swept to a rounded-down end would leave out the last
// instants of the window that closest_approach, measuring time from start, still searches.
inline double window_end(double start, double length) {
  const double t = start + length;
  return t - start < length ? std::nextafter(t, std::numeric_limits<double>::infinity()) : t;
}

// The slice count that minimizes a cost model of the broad phase: each slice sorts every
// object (about 100 ns each), and each candidate pair of each slice costs about 5 ns; a
// slice's candidates are estimated from the density of the fleet and the grown boxes' mean
// extents per axis, D + (mean distance moved along the axis) / slices.
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
    const double candidates = 0.5 * n * std::min(n, density * overlap);  // in one slice
    const double cost = double(s) * (100 * n + 5 * candidates);
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
  // Beyond, the search's sums of times would overflow (a horizon of 9e307 did).
  if (horizon > 1e300) throw InvalidArgument("conflict horizon must be at most 1e300");
  if (!std::isfinite(now)) throw InvalidArgument("conflict time is NaN or infinite");
  if (!std::isfinite(now + horizon))
    throw InvalidArgument("conflict time plus horizon is beyond the range of doubles");
}

namespace detail {
// An object's position at some time and its velocity: what a quick test of a pair reads.
template <int D>
struct Kinematics {
  Point<D> p, v;
};

// Closest approaches square differences of positions and velocities: every object must stay
// within +-kMaxCoordinate over [t0, t1] (it moves linearly: checked at both ends), or the
// arithmetic could overflow and lose pairs; out_of_range throws the error naming `who`.
template <int D>
bool stays_in_range(const Motion<D>& m, double t0, double t1) {
  return within_coordinate_range(position(m, t0)) && within_coordinate_range(position(m, t1));
}
[[noreturn]] inline void out_of_range(const std::string& who) {
  throw InvalidArgument("conflicts: " + who + " moves beyond 1e150 in the time searched");
}

// The quick test of a candidate pair: true when the closest approach over [0, horizon] of q
// relative to p is clearly beyond reach (reach2 its square), by more than rounding can
// explain. No division and no branch: with d and w the relative position and velocity, the
// least squared distance over the horizon is |d|^2 when d.w >= 0 (moving apart), |d + wH|^2
// when the closest approach is past H, and |d|^2 - (d.w)^2 / |w|^2 otherwise, compared
// multiplied by |w|^2 and with a slack of 1e-14 |d|^2 |w|^2 that covers its rounding while
// the products are normal numbers (about 10 ulps of |d|^2 |w|^2 in 3D); an overflow makes it
// false (not apart), and so do products near the subnormal range, where they lose their
// relative precision (and a |w|^2 of 0 sends the exact test to u = 0): not decided here.
template <int D>
[[gnu::always_inline]] inline bool clearly_apart(const Kinematics<D>& p, const Kinematics<D>& q,
                                                 double reach2, double horizon) {
  double dw, ww, dd, ee;
  for (int k = 0; k < D; ++k) {
    const double d = q.p[k] - p.p[k], w = q.v[k] - p.v[k];
    const double e = d + w * horizon;
    dw = k ? dw + d * w : d * w;
    ww = k ? ww + w * w : w * w;
    dd = k ? dd + d * d : d * d;
    ee = k ? ee + e * e : e * e;
  }
  const double ddww = dd * ww;
  const bool apart_now = dd > reach2, apart_end = ee > reach2;
  const bool apart_mid = ddww - dw * dw - 1e-14 * ddww > reach2 * ww;
  const bool receding = dw >= 0, past = -dw >= horizon * ww;
  const bool normal = (ww >= 0x1p-1000) & (dd >= 0x1p-1000) & (ddww >= 0x1p-960);
  return (receding & apart_now) | (!receding & normal & past & apart_end) |
         (!receding & normal & !past & apart_mid);
}

#if defined(__SSE2__)
// clearly_apart of p with q0 and with q1 at once, the same operations in the same order on
// two lanes (so the same answers, as long as the compiler fuses no multiply and add of the
// one-lane test: baseline x86-64 has no fused instruction; where a build allows them, the two
// may round differently, and each stays sound on its own): bit 0 for q0, bit 1 for q1.
// Inlined into the loop over a run, so that its constants stay in registers.
template <int D>
[[gnu::always_inline]] inline int clearly_apart2(const Kinematics<D>& p, const Kinematics<D>& q0,
                                                 const Kinematics<D>& q1, double reach2,
                                                 double horizon) {
  const __m128d h = _mm_set1_pd(horizon);
  __m128d dw = _mm_setzero_pd(), ww = dw, dd = dw, ee = dw;  // set at k = 0
  for (int k = 0; k < D; ++k) {
    const __m128d d = _mm_sub_pd(_mm_set_pd(q1.p[k], q0.p[k]), _mm_set1_pd(p.p[k]));
    const __m128d w = _mm_sub_pd(_mm_set_pd(q1.v[k], q0.v[k]), _mm_set1_pd(p.v[k]));
    const __m128d e = _mm_add_pd(d, _mm_mul_pd(w, h));
    dw = k ? _mm_add_pd(dw, _mm_mul_pd(d, w)) : _mm_mul_pd(d, w);
    ww = k ? _mm_add_pd(ww, _mm_mul_pd(w, w)) : _mm_mul_pd(w, w);
    dd = k ? _mm_add_pd(dd, _mm_mul_pd(d, d)) : _mm_mul_pd(d, d);
    ee = k ? _mm_add_pd(ee, _mm_mul_pd(e, e)) : _mm_mul_pd(e, e);
  }
  const __m128d r2 = _mm_set1_pd(reach2);
  const __m128d ddww = _mm_mul_pd(dd, ww);
  const __m128d apart_now = _mm_cmpgt_pd(dd, r2), apart_end = _mm_cmpgt_pd(ee, r2);
  const __m128d apart_mid = _mm_cmpgt_pd(
      _mm_sub_pd(_mm_sub_pd(ddww, _mm_mul_pd(dw, dw)), _mm_mul_pd(_mm_set1_pd(1e-14), ddww)),
      _mm_mul_pd(r2, ww));
  const __m128d receding = _mm_cmpge_pd(dw, _mm_setzero_pd());
  const __m128d past = _mm_cmpge_pd(_mm_xor_pd(dw, _mm_set1_pd(-0.0)), _mm_mul_pd(h, ww));
  // dd and ww are never NaN (sums of squares, of differences that may overflow to infinity
  // but never meet infinities of both signs): the least of the two is at least 2^-1000
  // exactly when both are.
  const __m128d normal = _mm_and_pd(_mm_cmpge_pd(_mm_min_pd(ww, dd), _mm_set1_pd(0x1p-1000)),
                                    _mm_cmpge_pd(ddww, _mm_set1_pd(0x1p-960)));
  const __m128d approaching =
      _mm_or_pd(_mm_and_pd(past, apart_end), _mm_andnot_pd(past, apart_mid));
  const __m128d apart = _mm_or_pd(_mm_and_pd(receding, apart_now),
                                  _mm_andnot_pd(receding, _mm_and_pd(normal, approaching)));
  return _mm_movemask_pd(apart);
}
#endif
}  // namespace detail

// Throws InvalidArgument, naming the object as who(i) does, for the first object a conflict
// search refuses: a velocity beyond 1e150 (as check_motion refuses it in a report: the relative
// velocity of two objects could overflow, even over a horizon of 0), any other report
// check_motion refuses (a NaN or infinite value, a time or position beyond 1e150; in its
// words), or a position leaving +-1e150 during [now, now + horizon]. Every object is checked,
// however few.
template <int D, class Name>
void check_conflict_objects(std::span<const Motion<D>> objects, double now, double horizon,
                            Name&& who) {
  for (std::size_t i = 0; i < objects.size(); ++i) {
    const Motion<D>& m = objects[i];
    if (!within_coordinate_range(m.v) || !(std::abs(m.t) <= kMaxCoordinate) ||
        !within_coordinate_range(m.p)) [[unlikely]] {
      if (std::isfinite(m.t) && is_finite(m.p) && is_finite(m.v) && !within_coordinate_range(m.v))
        throw InvalidArgument("conflicts: " + who(i) + " has a velocity beyond 1e150");
      try {
        check_motion(m, ("conflicts: " + who(i)).c_str());
      } catch (const InvalidGeometry& e) {
        throw InvalidArgument(e.what());
      }
    }
    if (!detail::stays_in_range(m, now, now + horizon)) detail::out_of_range(who(i));
  }
}

// The broad phase and buffers of conflict searches, kept between calls so that a search
// repeated every tick reuses its memory (and the broad phase its proxies).
template <int D>
class ConflictFinder {
 public:
  ConflictFinder() = default;
  ConflictFinder(const ConflictFinder&) = default;
  ConflictFinder& operator=(const ConflictFinder&) = default;
  // Moving leaves `other` empty, as if default-constructed.
  ConflictFinder(ConflictFinder&& other) noexcept : ConflictFinder() { swap(other); }
  ConflictFinder& operator=(ConflictFinder&& other) noexcept {
    ConflictFinder(std::move(other)).swap(*this);
    return *this;
  }
  template <ConflictVisitor F>
  QueryStats find(std::span<const Motion<D>> objects, double within, double now, double horizon,
                  F&& visit, std::size_t slices = 0) {
    check_conflict_query(within, now, horizon);
    check_objects(objects, now, horizon);
    if (slices == 0) slices = detail::auto_slices(objects, within, horizon);
    QueryStats st;
    if (objects.size() < 2) return st;
    if (objects.size() >= kNone) throw InvalidArgument("find_conflicts: too many objects");
    prepare(objects, now, horizon);
    const std::size_t n = objects.size();
    // Proxy k holds slot k of the broad phase, whatever the searches before: a fleet smaller
    // than the last is added afresh (the memory kept) rather than leaving freed slots, which
    // the sweep would walk on every later search and which would reorder its ties.
    if (n < held_) {
      broad_.clear();
      held_ = 0;
    }
    broad_.reserve(n);
    // Pairs whose closest approach computed from the positions at `now` is clearly beyond D
    // (detail::clearly_apart) are dropped before the exact test, which alone decides the
    // rest. d and w are computed as the exact test computes them, whose own rounding the
    // margin of `reach` covers.
    const double reach = within * (1 + 1e-9) + 1e-9 * scale_;
    const double reach2 = reach * reach;
    const double step = horizon / double(slices);
    for (std::size_t s = 0; s < slices; ++s) {
      const double t0 = now + step * double(s);
      const double t1 =
          s + 1 == slices ? detail::window_end(now, horizon) : now + step * double(s + 1);
      for (std::uint32_t k = 0; k < n; ++k) {
        // The reports in proxy order, read in sequence.
        const Box<D> b = detail::grown_sweep(motion_[k], t0, t1, 0.5 * within, now);
        if (k < held_) {
          broad_.move(k, b);
        } else {
          broad_.add(k, b);
          held_ = k + 1;  // counted as added, should a later add throw
        }
      }
      bool go = true;
      const Id* proxy = nullptr;
      detail::Kinematics<D>* kin = nullptr;
      std::uint32_t* near = nullptr;
      // Positions at `now` and velocities copied into the sweep's order, so that the tests
      // of a run's candidates read neighbouring memory.
      auto lay_out = [&](std::span<const Id> ids) {
        proxy = ids.data();
        kin_.resize(ids.size());
        near_.resize(ids.size());
        kin = kin_.data();
        near = near_.data();
        for (std::size_t e = 0; e < ids.size(); ++e) {
          if (ids[e] == SweepPrune<D>::kSeparator) continue;
          const Motion<D>& m = motion_[ids[e]];
          kin[e] = {position(m, now), m.v};
        }
      };
      auto run = [&](std::size_t e, std::span<const std::uint32_t> partners) {
        st.entries_tested += partners.size();
        const detail::Kinematics<D> p = kin[e];
        // The quick test over the run, its survivors left-packed into near.
        std::size_t kept = 0, h = 0;
#if defined(__SSE2__)
        for (; h + 2 <= partners.size(); h += 2) {
          const std::uint32_t f0 = partners[h], f1 = partners[h + 1];
          const int apart = detail::clearly_apart2(p, kin[f0], kin[f1], reach2, horizon);
          near[kept] = f0;
          kept += std::size_t(~apart & 1);
          near[kept] = f1;
          kept += std::size_t(~apart >> 1 & 1);
        }
#endif
        for (; h < partners.size(); ++h) {
          near[kept] = partners[h];
          kept += !detail::clearly_apart(p, kin[partners[h]], reach2, horizon);
        }
        for (std::size_t h = 0; h < kept; ++h) {
          std::size_t a = e, b = near[h];
          std::uint32_t i = order_[proxy[a]], j = order_[proxy[b]];
          if (j < i) std::swap(i, j), std::swap(a, b);
          // objects[i] and objects[j], from their positions at `now` and velocities: what
          // closest_approach(objects[i], objects[j], now, horizon, within) computes.
          const auto ap =
              closest_approach_at(kin[a].p, kin[a].v, kin[b].p, kin[b].v, now, horizon, within);
          if (!ap) continue;
          // Reported from the slice holding the entry time only.
          const bool first = s == 0 || ap->t_enter > t0;
          const bool last = s + 1 == slices || ap->t_enter <= t1;
          if (!first || !last) continue;
          ++st.results;
          if (!(go = visit(i, j, *ap))) return false;
        }
        return true;
      };
      const QueryStats bs = broad_.entry_pairs(lay_out, run);
      st.nodes_visited += bs.nodes_visited;
      if (!go) break;
    }
    return st;
  }

 private:
  static void check_objects(std::span<const Motion<D>> objects, double now, double horizon) {
    check_conflict_objects<D>(objects, now, horizon, [](std::size_t i) {
      return "object " + std::to_string(i) + " of the input";
    });
  }

  // Numbers the objects in Hilbert order of their positions at mid-horizon, so that the pairs
  // the broad phase reports (neighbours in space) read neighbouring memory.
  void prepare(std::span<const Motion<D>> objects, double now, double horizon) {
    const std::size_t n = objects.size();
    motion_.resize(n);
    Box<D> extent = Box<D>::empty();
    for (const Motion<D>& m : objects)
      extent.expand(position(m, now + 0.5 * horizon));
    const detail::HilbertGrid<D> grid(extent);
    keyed_.resize(n);
    for (std::uint32_t i = 0; i < n; ++i)
      keyed_[i] = {grid.key(position(objects[i], now + 0.5 * horizon)), i};
    detail::radix_sort(
        keyed_, 0, D * detail::hilbert_bits<D>(), [](const detail::KeyedIndex& e) { return e.key; },
        spare_);
    order_.resize(n);
    scale_ = 0;
    for (std::uint32_t k = 0; k < n; ++k) {
      const std::uint32_t i = keyed_[k].index;
      order_[k] = i;
      motion_[k] = objects[i];
      const Point<D> at_now = position(objects[i], now);
      for (int a = 0; a < D; ++a)
        scale_ = std::max(scale_, std::abs(at_now[a]) + std::abs(motion_[k].v[a]) * horizon);
    }
  }

  void swap(ConflictFinder& other) noexcept {
    std::swap(broad_, other.broad_);
    std::swap(held_, other.held_);
    keyed_.swap(other.keyed_);
    spare_.swap(other.spare_);
    order_.swap(other.order_);
    motion_.swap(other.motion_);
    kin_.swap(other.kin_);
    near_.swap(other.near_);
    std::swap(scale_, other.scale_);
  }
  SweepPrune<D> broad_;
  std::size_t held_ = 0;  // proxies 0 .. held_ - 1 are in broad_
  // Large arrays, so that a search made once does not spend its time faulting pages in.
  detail::LargeVector<detail::KeyedIndex> keyed_, spare_;  // Hilbert sort, and its second buffer
  detail::LargeVector<std::uint32_t> order_;               // input index by proxy number
  detail::LargeVector<Motion<D>> motion_;                  // the reports by proxy number
  // Positions at `now` and velocities by entry of the sweep.
  detail::LargeVector<detail::Kinematics<D>> kin_;
  detail::LargeVector<std::uint32_t> near_;  // a run's partners that pass the quick test
  double scale_ = 0;                         // largest coordinate magnitude reached
};

// The one-off search leases its thread's idle ConflictFinder (detail/scratch.hpp), so that
// calls repeated on a thread reuse its buffers instead of faulting in fresh pages (300 to 350
// bytes an object in 2D, measured); a finder that served more than kLeasedObjects objects is
// freed at the end of the call instead, so that what a thread keeps stays under about 60 MB
// (per level of nesting, when visitors search too). The answer and the order of the visits
// do not depend on the searches before.
namespace detail {
inline constexpr std::size_t kLeasedObjects = std::size_t(1) << 17;
}

template <int D, ConflictVisitor F>
QueryStats find_conflicts(std::span<const Motion<D>> objects, double within, double now,
                          double horizon, F&& visit, std::size_t slices = 0) {
  detail::Lease<ConflictFinder<D>> finder;
  if (objects.size() > detail::kLeasedObjects) finder.drop();
  return finder->find(objects, within, now, horizon, visit, slices);
}

// The conflicts among objects named by ids (ids[i] names objects[i]), sorted by (a, b).
template <int D>
std::vector<Conflict> find_conflicts(std::span<const Id> ids, std::span<const Motion<D>> objects,
                                     double within, double now, double horizon) {
  if (ids.size() != objects.size())
    throw InvalidArgument("find_conflicts: ids and objects differ in length");
  check_conflict_query(within, now, horizon);
  check_conflict_objects<D>(objects, now, horizon,
                            [&](std::size_t i) { return "id " + std::to_string(ids[i]); });
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
// [b, b + H + slack] (find_conflicts), each with its closest approach over that span, and the
// grown swept boxes of the span in a packed R-tree (packed_rtree.hpp). After a batch of
// reports, refresh(now) with now <= b + slack forgets the kept pairs of the objects that
// reported and looks for their new pairs with one query each: the pairs of the others cannot
// have changed, since their reports did not and [now, now + H] lies inside the span already
// searched. Objects that reported since b have stale boxes in the packed tree, which queries
// skip; their current boxes are packed afresh into a small tree at each refresh, which
// queries look at too. Once now passes b + slack, refresh computes everything again from now.
// Each tree entry carries the object's position at b and velocity (the packed tree's entries
// in its packed order, read by packed position), so that a query reads its candidates' motions from
// the leaf's neighbourhood rather than from wherever their slots lie; a candidate gets the quick
// test of find_conflicts (clearly_apart) before the exact one. Times within the span are
// kept from b, so that at epoch-second times the window's end is not rounded to the clock's
// step (2^-22 s near 1.7e9) where closest_approach, measuring from now, does not round it.
//
// conflicts(visit) then reports, from the kept pairs, those within D during [now, now + H]
// without computing them again: the distance of two linear motions is convex in time, so
// over [now, now + H] it is least at the span's time of closest approach clamped to that
// window, and the pair is within D from max(t_enter, now) to min(t_exit, now + H). Only a pair
// whose closest approach falls outside the window needs its distance at the window's end,
// and only a pair within rounding of D (1e-9 of the coordinates' magnitude) is decided by
// closest_approach at now, as find_conflicts decides it; so the pairs are exactly those of a
// computation from scratch, and the times and distances agree with it to rounding.
//
// A report that would carry its object beyond +-1e150 during the span searched makes refresh
// throw InvalidArgument naming the id, before anything changes: the reports stay pending (as
// between any report and the next refresh, conflicts() leaves out the pairs of objects with a
// pending report) until the object reports again or is removed.
//
// Cost: a full computation as find_conflicts over the longer span; an incremental refresh
// O(reported x (log n + candidates)); conflicts() O(kept pairs), reading them in order. A
// pair of an object that reported is forgotten by a version check, not found and erased;
// forgotten pairs are swept out when they would be a quarter of those kept. Objects are named
// by the caller's ids. Thread-safety: one thread at a time.
template <int D>
class ConflictMonitor {
 public:
  ConflictMonitor(double within, double horizon, double slack)
      : within_(within), horizon_(horizon), slack_(slack) {
    check_conflict_query(within, 0, horizon);
    if (!std::isfinite(slack) || slack < 0)
      throw InvalidArgument("conflict monitor slack must be a finite number >= 0");
  }
  // Moving leaves `other` empty, with its parameters and no object.
  ConflictMonitor(ConflictMonitor&& other) noexcept
      : ConflictMonitor(other.within_, other.horizon_, other.slack_) {
    swap(other);
  }
  ConflictMonitor& operator=(ConflictMonitor&& other) noexcept {
    ConflictMonitor(std::move(other)).swap(*this);
    return *this;
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
        version_.push_back(0);
        degree_.push_back(0);
        at_base_.emplace_back();
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
    if (!computed_ || now < base_ || now > base_ + slack_) return recompute(now);
    const double t1 = detail::window_end(base_, horizon_ + slack_);
    // Every new report is checked before anything changes.
    for (std::uint32_t s : dirty_list_)
      if (alive_[s] && !detail::stays_in_range(motion_[s], base_, t1))
        detail::out_of_range("id " + std::to_string(ids_[s]));
    now_ = now;
    ++incremental_;
    QueryStats st;
    dirty_seen_.resize(ids_.size(), 0);
    moved_.resize(ids_.size(), 0);
    for (std::uint32_t s : dirty_list_) {
      // Its kept pairs are forgotten: their versions no longer match.
      forgotten_ += degree_[s];
      degree_[s] = 0;
      dirty_[s] = 0;
      if (!moved_[s]) {
        moved_[s] = 1;
        recent_.push_back(s);
        if (s < entry_of_.size() && entry_of_[s] != kNone) packed_entry_[entry_of_[s]].stale = 1;
      }
      if (!alive_[s]) {
        free_.push_back(s);
        continue;
      }
      widen(motion_[s], t1 - base_);
      at_base_[s] = {position(motion_[s], base_), motion_[s].v};
    }
    if (forgotten_ > kept_.size() / 4) sweep();
    // The objects that reported since the base, in a small packed tree made afresh.
    recent_entry_.clear();
    std::vector<Box<D>> boxes;
    for (std::uint32_t s : recent_)
      if (alive_[s]) {
        recent_entry_.push_back({at_base_[s], s, 0});
        boxes.push_back(detail::grown_sweep(motion_[s], base_, t1, 0.5 * keep_));
      }
    recent_tree_ = PackedRTree<D>::build(boxes);
    const double span = t1 - base_, keep2 = keep_ * keep_;
    for (std::uint32_t s : dirty_list_) {
      if (!alive_[s]) continue;
      const detail::Kinematics<D>& x = at_base_[s];
      const Box<D> b = detail::grown_sweep(motion_[s], base_, t1, 0.5 * keep_);
      // The candidates of both trees are gathered, then given the quick test two at a time.
      near_.clear();
      st += packed_.query_packed(
          b,
          [&](std::size_t pos, const Box<D>&) {
            // Entries of objects that reported since the base are stale.
            const Entry& e = packed_entry_[pos];
            if (!e.stale && e.slot != s) near_.push_back(&e);
            return true;
          },
          [&](std::size_t pos) { __builtin_prefetch(packed_entry_.data() + pos); });
      st += recent_tree_.query(b, [&](Id k, const Box<D>&) {
        const Entry& e = recent_entry_[k];
        if (e.slot != s) near_.push_back(&e);
        return true;
      });
      // comes_within(motion_[s], motion_[t], base_, span, keep_), from the positions at the
      // base; the quick test first drops the pairs clearly beyond.
      auto exact = [&](const Entry& e) {
        // A pair of two reporting objects is taken from the first of them looked at.
        if (dirty_seen_[e.slot]) return;
        if (detail::closest_at(x.p, x.v, e.at.p, e.at.v, span).dcpa <= keep_)
          keep(s, e.slot, x, e.at);
      };
      std::size_t h = 0;
#if defined(__SSE2__)
      for (; h + 2 <= near_.size(); h += 2) {
        const int apart = detail::clearly_apart2(x, near_[h]->at, near_[h + 1]->at, keep2, span);
        if (!(apart & 1)) exact(*near_[h]);
        if (!(apart & 2)) exact(*near_[h + 1]);
      }
#endif
      for (; h < near_.size(); ++h)
        if (!detail::clearly_apart(x, near_[h]->at, keep2, span)) exact(*near_[h]);
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
    const double end = now_ + horizon_;
    // The window in time from the base, where its end is not rounded to the step of
    // epoch-second times (2^-22 s near 1.7e9), as closest_approach measures it from now.
    const double from = now_ - base_, to = from + horizon_;
    const double lo = within_ - margin_, hi = within_ + margin_;
    for (const Kept& k : kept_) {
      if (version_[k.s] != k.vs || version_[k.t] != k.vt) continue;  // forgotten
      std::optional<Approach> ap;
      if (k.dcpa <= within_) {
        // Least distance over the window: at the span's closest approach clamped to it.
        const double u = std::clamp(k.u, from, to);
        // Back in absolute time: the window's own ends where clamped (as a computation from
        // scratch reports them), never a rounding outside the window.
        const double tc = u == from ? now_ : u == to ? end : std::clamp(base_ + u, now_, end);
        double d = k.dcpa;
        if (u != k.u) {
          // From the pair's relative motion, kept with it (the reports are not looked up).
          double dd = 0;
          for (int a = 0; a < D; ++a) {
            const double c = k.d[a] + k.w[a] * u;
            dd += c * c;
          }
          d = std::sqrt(dd);
        }
        if (d > hi) continue;
        if (d < lo)
          ap = Approach{tc, d, std::min(std::max(k.t_enter, now_), tc),
                        std::max(std::min(k.t_exit, end), tc)};
      }
      if (!ap) {  // within rounding of D (or kept within keep_ only): decided as from scratch
        const bool st = ids_[k.s] < ids_[k.t];
        ap = closest_approach(motion_[st ? k.s : k.t], motion_[st ? k.t : k.s], now_, horizon_,
                              within_);
        if (!ap) continue;
      }
      if (!visit(k.a, k.b, *ap)) return;
    }
  }
  std::vector<Conflict> conflicts() const {
    std::vector<Conflict> out;
    conflicts([&](Id a, Id b, const Approach& ap) { return out.push_back({a, b, ap}), true; });
    sort_conflicts(out);
    return out;
  }

 private:
  // A kept pair, by slots, with the versions of their reports when it was found, its ids, its
  // closest approach within D over the span (dcpa = infinity when it comes within keep_ only)
  // and its relative motion: conflicts() reads the pairs in sequence and looks nothing up but
  // the versions (and the reports of a pair within rounding of D).
  struct Kept {
    std::uint32_t s, t, vs, vt;
    Id a, b;   // the ids of s and t, a < b
    double u;  // the time of closest approach over the span, from the base
    double dcpa, t_enter, t_exit;
    Point<D> d, w;  // t's position at the base and velocity less s's
  };
  // An object in a packed tree: its kinematics at the base, its slot, and whether it has
  // reported since (its box stale).
  struct Entry {
    detail::Kinematics<D> at;
    std::uint32_t slot, stale;
  };

  void mark(std::uint32_t s) {
    // After 2^32 reports and removals the slot's count comes round to the versions its kept
    // pairs were found with, which would make them look current again: they go first.
    if (++version_[s] == 0) drop_pairs_of(s);
    if (!dirty_[s]) {
      dirty_[s] = 1;
      dirty_list_.push_back(s);
    }
  }
  // Kept pairs are those within keep_, a hair more than D (relative to the magnitudes seen),
  // so that a pair within D at a later `now` is never lost to rounding at the base time.
  void widen(const Motion<D>& m, double span) {
    // The report's own magnitudes too: a position extrapolated from a report long before the
    // base is rounded at the size of the report's position and travel, not of the result.
    const Point<D> p = position(m, base_);
    const double age = std::abs(base_ - m.t);
    for (int a = 0; a < D; ++a)
      scale_ =
          std::max(scale_, std::abs(p[a]) + std::abs(m.p[a]) + std::abs(m.v[a]) * (span + age));
    keep_ = within_ * (1 + 1e-9) + 1e-9 * scale_;
    margin_ = 0.5 * (keep_ - within_);
  }
  // Keeps the pair of slots s and t, x and y their kinematics at the base (at_base_).
  void keep(std::uint32_t s, std::uint32_t t, const detail::Kinematics<D>& x,
            const detail::Kinematics<D>& y) {
    Kept k{};
    k.s = s, k.t = t, k.vs = version_[s], k.vt = version_[t];
    k.a = std::min(ids_[s], ids_[t]), k.b = std::max(ids_[s], ids_[t]);
    k.dcpa = std::numeric_limits<double>::infinity();
    // closest_approach(motion_[s], motion_[t], base_, horizon_ + slack_, within_), its times
    // from the base
    if (auto ap = closest_approach_at(x.p, x.v, y.p, y.v, 0.0, horizon_ + slack_, within_))
      k.u = ap->tcpa, k.dcpa = ap->dcpa, k.t_enter = base_ + ap->t_enter,
      k.t_exit = base_ + ap->t_exit;
    for (int a = 0; a < D; ++a)
      k.d[a] = y.p[a] - x.p[a], k.w[a] = y.v[a] - x.v[a];
    kept_.push_back(k);
    ++degree_[s];
    ++degree_[t];
  }
  // Drops every kept pair of slot s, and the forgotten pairs.
  void drop_pairs_of(std::uint32_t s) {
    std::erase_if(kept_, [&](const Kept& k) { return k.s == s || k.t == s; });
    sweep();
  }
  // Drops the forgotten pairs.
  void sweep() {
    std::erase_if(kept_,
                  [&](const Kept& k) { return version_[k.s] != k.vs || version_[k.t] != k.vt; });
    std::fill(degree_.begin(), degree_.end(), 0);
    for (const Kept& k : kept_)
      ++degree_[k.s], ++degree_[k.t];
    forgotten_ = 0;
  }

  QueryStats recompute(double now) {
    const double span = horizon_ + slack_;
    // Every report is checked before anything changes.
    for (std::uint32_t s = 0; s < ids_.size(); ++s)
      if (alive_[s] && !detail::stays_in_range(motion_[s], now, now + span))
        detail::out_of_range("id " + std::to_string(ids_[s]));
    now_ = now;
    ++full_;
    computed_ = true;
    base_ = now;
    for (std::uint32_t s : dirty_list_) {
      dirty_[s] = 0;
      if (!alive_[s]) free_.push_back(s);
    }
    dirty_list_.clear();
    dirty_seen_.assign(ids_.size(), 0);
    std::vector<std::uint32_t> live;
    std::vector<Motion<D>> dense;
    recent_.clear();
    recent_tree_ = {};
    moved_.assign(ids_.size(), 0);
    scale_ = 0;
    kept_.clear();
    std::fill(degree_.begin(), degree_.end(), 0);
    forgotten_ = 0;
    for (std::uint32_t s = 0; s < ids_.size(); ++s) {
      if (!alive_[s]) continue;
      live.push_back(s);
      dense.push_back(motion_[s]);
      at_base_[s] = {position(motion_[s], now), motion_[s].v};
      widen(motion_[s], span);
    }
    // The packed tree's entries laid out in its packed order, so that the entries of a leaf,
    // and the motions of the candidates a query reads, lie side by side.
    {
      std::vector<Box<D>> boxes;
      boxes.reserve(live.size());
      const double end = detail::window_end(now, span);
      for (std::uint32_t s : live)
        boxes.push_back(detail::grown_sweep(motion_[s], now, end, 0.5 * keep_));
      packed_ = PackedRTree<D>::build(boxes);
      packed_entry_.resize(live.size());
      entry_of_.assign(ids_.size(), kNone);
      for (std::size_t pos = 0; pos < live.size(); ++pos) {
        const std::uint32_t s = live[packed_.item_at(pos)];
        packed_entry_[pos] = {at_base_[s], s, 0};
        entry_of_[s] = std::uint32_t(pos);
      }
    }
    const QueryStats st =
        finder_.find(std::span<const Motion<D>>(dense), keep_, now, span,
                     [&](std::uint32_t i, std::uint32_t j, const Approach&) {
                       keep(live[i], live[j], at_base_[live[i]], at_base_[live[j]]);
                       return true;
                     });
    // Room for the pairs refreshes add before the next sweep, so that the table is not moved
    // (and its pages faulted in again) in the middle of a stream.
    kept_.reserve(kept_.size() + kept_.size() / 2 + 1024);
    return st;
  }

  void swap(ConflictMonitor& other) noexcept {
    std::swap(within_, other.within_);
    std::swap(horizon_, other.horizon_);
    std::swap(slack_, other.slack_);
    std::swap(base_, other.base_);
    std::swap(now_, other.now_);
    std::swap(scale_, other.scale_);
    std::swap(keep_, other.keep_);
    std::swap(margin_, other.margin_);
    std::swap(computed_, other.computed_);
    std::swap(full_, other.full_);
    std::swap(incremental_, other.incremental_);
    ids_.swap(other.ids_);
    motion_.swap(other.motion_);
    alive_.swap(other.alive_);
    dirty_.swap(other.dirty_);
    dirty_seen_.swap(other.dirty_seen_);
    moved_.swap(other.moved_);
    dirty_list_.swap(other.dirty_list_);
    free_.swap(other.free_);
    version_.swap(other.version_);
    degree_.swap(other.degree_);
    kept_.swap(other.kept_);
    at_base_.swap(other.at_base_);
    std::swap(forgotten_, other.forgotten_);
    std::swap(slots_, other.slots_);
    std::swap(count_, other.count_);
    std::swap(packed_, other.packed_);
    packed_entry_.swap(other.packed_entry_);
    entry_of_.swap(other.entry_of_);
    recent_.swap(other.recent_);
    recent_entry_.swap(other.recent_entry_);
    std::swap(recent_tree_, other.recent_tree_);
    near_.swap(other.near_);
    std::swap(finder_, other.finder_);
  }
  double within_, horizon_, slack_;
  double base_ = 0, now_ = 0, scale_ = 0, keep_ = 0, margin_ = 0;
  bool computed_ = false;
  std::size_t full_ = 0, incremental_ = 0;
  std::vector<Id> ids_;
  std::vector<Motion<D>> motion_;
  std::vector<std::uint8_t> alive_, dirty_, dirty_seen_, moved_;
  std::vector<std::uint32_t> dirty_list_, free_;
  std::vector<std::uint32_t> version_;  // reports and removals of each slot, counted
  std::vector<std::uint32_t> degree_;   // kept pairs of each slot since the last sweep
  detail::LargeVector<Kept> kept_;      // on huge pages: 96 bytes a pair in 2D, tens of megabytes
  std::vector<detail::Kinematics<D>> at_base_;  // by slot
  std::size_t forgotten_ = 0;  // kept pairs whose versions no longer match, at most
  detail::IdMap slots_;
  std::size_t count_ = 0;
  PackedRTree<D> packed_;                    // grown swept boxes at the base
  detail::LargeVector<Entry> packed_entry_;  // by packed position of packed_
  std::vector<std::uint32_t> entry_of_;      // by slot: its packed position, or kNone
  std::vector<std::uint32_t> recent_;        // objects that reported since the base, by slot
  std::vector<Entry> recent_entry_;          // those alive, by entry of recent_tree_
  PackedRTree<D> recent_tree_;               // their grown swept boxes
  std::vector<const Entry*> near_;           // a query's candidates
  ConflictFinder<D> finder_;
};

}  // namespace loci
