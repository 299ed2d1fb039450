// TprTree<D>: the TPR*-tree of Tao, Papadias and Sun ("The TPR*-Tree: An Optimized
// Spatio-Temporal Access Method for Predictive Queries", VLDB 2003), in main memory.
//
// What it is. An R-tree over moving points whose node bounds are time-parameterized boxes
// (moving/detail/tpbr.hpp): each bound moves with the extreme velocity of what it holds, so a
// node keeps bounding its points as they move, without updates. The TPR-tree (Saltenis et al.
// 2000) chose insertion paths and splits with R*-tree heuristics integrated over time; the
// TPR* version replaces them with one cost, the area a node's box sweeps over the horizon
// after being grown by the expected query extent (the probability that a query issued during
// the horizon visits the node), and uses it everywhere:
//
// - Choose_Path (section 5.1): the insertion path is the one with the least total increase of
//   that cost over all its nodes, over the whole tree. The paper finds it best-first (partial
//   paths in a priority queue keyed by the increase so far; increases are never negative, so
//   the first node of the target level taken from the queue ends the best path). Here the
//   greedy descent of R-trees (the cheapest entry of each node) gives a first path, and only
//   partial paths cheaper than it enter the queue: a path of the same least cost (among equal
//   ones the greedy path), with the queue holding a few paths instead of every child of every
//   node opened. Each node keeps its entries'
//   own costs at the current time, so an increase costs one evaluation, not two.
// - Pick_Worst (section 5.2): on the first overflow of a level during one insertion, the
//   entries whose removal shrinks the node's cost most are reinserted instead of splitting:
//   for each of the 4 D orders (lower or upper end, position at now or velocity, per axis) the
//   30% of entries at the extreme are taken out, and the order whose removal gains most wins.
// - Split: over the same 4 D orders and every distribution leaving at least 40% of the
//   entries on each side, the one with the least summed cost of the two groups.
// - Deletion as in R-trees: the leaf is found at once through an id -> leaf table (the
//   secondary index that makes main-memory updates cheap, Sidlauskas et al. 2009); nodes left
//   below 40% are dissolved and their entries reinserted; every node on the path gets its
//   bounds recomputed from its entries at the current time (tightening). An update is an
//   erasure and an insertion, except (TprParams::in_place_updates, on by default) when the new
//   report stays inside the bounds its leaf already has from the clock on: then it is written
//   over the old one and only the leaf's bounds are recomputed (the bottom-up update of Lee,
//   Hsu, Jensen, Cui and Teo, VLDB 2003). A vessel reporting where its last report put it,
//   on a course within its leaf's velocity bounds, costs O(M) instead of a Choose_Path.
//
// Parameters (TprParams): the horizon H over which costs are integrated (the paper's
// H = update interval + how far ahead queries look) and the expected query extent per axis.
//
// Layout, time and the shared machinery: moving/detail/moving_rtree.hpp.
//
// Complexity: insertion O(explored nodes x M) (the best-first search is usually a few paths);
// erasure O(log n) plus reinsertion of dissolved nodes; window queries O(log n + visited);
// nearest-n best-first (detail/best_first.hpp) over the boxes at the query time. Memory
// about (6 D + 4) x 8 bytes a slot of a node (the box, its kept cost, the child, and in
// leaves the report and id), nodes 40% to 100% full.
//
// Thread-safety: const members may run concurrently with each other.
#pragma once

#include <cmath>

#include "loci/index/moving/detail/moving_rtree.hpp"

namespace loci {

template <int D>
struct TprParams {
  double horizon = 60;      // H: how far ahead costs are integrated
  Point<D> query_extent{};  // expected side lengths of query windows
  // An update whose new report stays inside its leaf's bounds is written in place (see the
  // header); false: every update is an erasure and an insertion, as in the paper.
  bool in_place_updates = true;
};

namespace detail {
template <int D>
struct TprStarPolicy {
  using Params = TprParams<D>;
  static constexpr const char* kName = "TprTree";
  static constexpr bool kRegroups = false;
  static double horizon(const Params& p) { return p.horizon; }
  static Point<D> extent(const Params& p) { return p.query_extent; }
  static double lookahead(const Params& p) { return p.horizon; }
  static double ratio(const Params&) { return 0; }
  static void check(const Params& p) {
    if (!(p.horizon >= 0) || !std::isfinite(p.horizon))
      throw InvalidArgument("TprTree: the horizon must be a finite number >= 0");
    for (int i = 0; i < D; ++i)
      if (!(p.query_extent[i] >= 0) || !std::isfinite(p.query_extent[i]))
        throw InvalidArgument("TprTree: query extents must be finite numbers >= 0");
  }
};
}  // namespace detail

template <int D, int M = 32>
class TprTree : public detail::MovingRTree<D, M, detail::TprStarPolicy<D>> {
 public:
  using detail::MovingRTree<D, M, detail::TprStarPolicy<D>>::MovingRTree;
};

static_assert(MovingIndex<TprTree<2>>);
static_assert(MovingIndex<TprTree<3>>);

}  // namespace loci
