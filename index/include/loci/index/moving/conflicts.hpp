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
// picks the count from the motion: about one slice per D of the mean distance moved over the
// horizon, at most 16.
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
#include <span>
#include <vector>

#include "loci/geom/motion.hpp"
#include "loci/index/broadphase/sweep_prune.hpp"
#include "loci/index/query.hpp"

namespace loci {

// One conflict, by the caller's ids, a < b.
struct Conflict {
  Id a;
  Id b;
  Approach approach;
};

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

template <int D>
std::size_t auto_slices(std::span<const Motion<D>> objects, double within, double horizon) {
  if (objects.empty() || horizon <= 0) return 1;
  double speed = 0;
  for (const Motion<D>& m : objects) {
    double s = 0;
    for (int i = 0; i < D; ++i)
      s += m.v[i] * m.v[i];
    speed += std::sqrt(s);
  }
  const double moved = speed / double(objects.size()) * horizon;
  const double want = moved / std::max(within, 1e-300);
  return std::size_t(std::clamp(std::floor(want), 1.0, 16.0));
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

template <int D, ConflictVisitor F>
QueryStats find_conflicts(std::span<const Motion<D>> objects, double within, double now,
                          double horizon, F&& visit, std::size_t slices = 0) {
  check_conflict_query(within, now, horizon);
  if (slices == 0) slices = detail::auto_slices(objects, within, horizon);
  QueryStats st;
  if (objects.size() < 2) return st;
  SweepPrune<D> broad;
  const double step = horizon / double(slices);
  for (std::size_t s = 0; s < slices; ++s) {
    const double t0 = now + step * double(s);
    const double t1 = s + 1 == slices ? now + horizon : now + step * double(s + 1);
    for (std::uint32_t i = 0; i < objects.size(); ++i) {
      const Box<D> b = detail::grown_sweep(objects[i], t0, t1, 0.5 * within);
      if (s == 0)
        broad.add(i, b);
      else
        broad.move(i, b);
    }
    bool go = true;
    const QueryStats bs = broad.pairs([&](Id a, Id b) {
      ++st.entries_tested;
      const auto i = std::uint32_t(a), j = std::uint32_t(b);
      const auto ap = closest_approach(objects[i], objects[j], now, horizon, within);
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
  std::sort(out.begin(), out.end(), [](const Conflict& x, const Conflict& y) {
    return x.a != y.a ? x.a < y.a : x.b < y.b;
  });
  return out;
}

}  // namespace loci
