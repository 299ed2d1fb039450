// StarTree<D>: a self-adjusting index of moving points after the STAR-tree of Procopiuc,
// Agarwal and Har-Peled ("STAR-Tree: An Efficient Self-Adjusting Index for Moving Objects",
// ALENEX 2002, LNCS 2409).
//
// What the paper sets out (its abstract; the full text was not available when this was
// written, so no section of it is followed line by line): an R*-tree over moving points that
// needs no horizon and "re-organizes itself locally whenever its query performance
// deteriorates", trading update time against query time. The policy implemented here:
//
// - No horizon. Choose_Path, Pick_Worst and splits (the machinery of detail/moving_rtree.hpp)
//   minimize the area of boxes at the tree's clock, as an R*-tree of the current positions
//   would; nothing assumes how far ahead queries will look.
// - Local reorganization when a node deteriorates. Every node remembers the area its box had
//   when it was last grouped. After each update, the nodes on the updated leaf's path are
//   measured; the first whose box at the clock has grown past `regroup_ratio` times that area
//   (its children drifting apart as their objects move) has its grandchildren dealt out again
//   among as many new children, tiled by Sort-Tile-Recursive on their centres now, so that
//   its children are tight again. A node's query cost is proportional to that area (the
//   probability that a window visits it), so the ratio bounds how far a node's cost may drift
//   before it is repaired: a smaller ratio buys windows with update time.
// - Not implemented: the paper's storage/query trade-off (several time-parameterized boxes
//   per node approximating the true, piecewise-linear extent of moving points).
//
// Queries, updates, in-place updates, packing (build) and exactness are those of every
// moving R-tree here (moving_index.hpp). Thread-safety: const members may run concurrently.
#pragma once

#include <cmath>

#include "loci/index/moving/detail/moving_rtree.hpp"

namespace loci {

template <int D>
struct StarParams {
  double regroup_ratio = 2;    // a node is regrouped when its area at the clock passes this
                               // multiple of its area when last grouped (> 1)
  double pack_lookahead = 60;  // build(): velocities weigh as far as they spread over this time
  bool in_place_updates = true;
};

namespace detail {
template <int D>
struct StarPolicy {
  using Params = StarParams<D>;
  static constexpr const char* kName = "StarTree";
  static constexpr bool kRegroups = true;
  static double horizon(const Params&) { return 0; }
  static Point<D> extent(const Params&) { return Point<D>{}; }
  static double lookahead(const Params& p) { return p.pack_lookahead; }
  static double ratio(const Params& p) { return p.regroup_ratio; }
  static void check(const Params& p) {
    if (!(p.regroup_ratio > 1) || !std::isfinite(p.regroup_ratio))
      throw InvalidArgument("StarTree: the regroup ratio must be a finite number > 1");
    if (!(p.pack_lookahead >= 0) || !std::isfinite(p.pack_lookahead))
      throw InvalidArgument("StarTree: the packing lookahead must be a finite number >= 0");
  }
};
}  // namespace detail

template <int D, int M = 32>
class StarTree : public detail::MovingRTree<D, M, detail::StarPolicy<D>> {
 public:
  using detail::MovingRTree<D, M, detail::StarPolicy<D>>::MovingRTree;
};

static_assert(MovingIndex<StarTree<2>>);
static_assert(MovingIndex<StarTree<3>>);

}  // namespace loci
