// Sort-and-sweep joins of 2D boxes: every intersecting pair within one set (self_join) or
// between two sets (join), closed boxes (touching counts), each pair once.
//
// Method ("box pruning", the one-shot form of sweep-and-prune; Baraff's thesis, 1992, and the
// collision lecture in ../shared/references): the boxes are ordered by their minimum x with a
// radix sort on order-preserving 64-bit keys and copied, in that order, into four flat arrays
// (structure of arrays). Sweeping left to right, box i is compared with the boxes that start at
// or after it while they start no later than i ends; only those can overlap i on x, and the
// y test decides. The work is O(n log n) for the sort (linear, in fact, for the radix sort)
// plus the number of x-overlapping pairs, which for map linework (short segments) is a small
// multiple of the answer. The two-set join interleaves two such sweeps: each box of A scans the
// boxes of B that start within its x-range, and each box of B the boxes of A that start
// strictly after it and within its range, so a pair is met exactly once.
//
// Compared with a synchronized traversal of two packed R-trees, the sweep reads memory in
// order and has no per-node overhead; its weakness is long boxes, which scan far. The sweep
// runs along x, or along y where that compares far fewer pairs (sweep_axis: all the segments
// of a north-south line share one x, and a sweep along x would compare every pair). Visitors are
// called as `bool visit(Id i, Id j)` (indices into the inputs; for self_join i < j) and return
// false to stop. Thread-safety: pure functions of their inputs.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "loci/geom/box.hpp"
#include "loci/index/detail/large_alloc.hpp"
#include "loci/index/detail/radix_sort.hpp"
#include "loci/index/query.hpp"

namespace loci {

namespace detail {

// Boxes in sweep order, structure of arrays, with their input indices.
struct SweepBoxes {
  LargeVector<double> min_x, max_x, min_y, max_y;
  LargeVector<std::uint32_t> index;

  // Swept along `axis`: for axis 1 the fields named x hold y and those named y hold x.
  SweepBoxes(std::span<const Box<2>> boxes, int axis) {
    const int x = axis, y = 1 - axis;
    LargeVector<KeyedIndex> order(boxes.size());
    for (std::size_t i = 0; i < boxes.size(); ++i)
      order[i] = {ordered_key(boxes[i].min[x]), std::uint32_t(i)};
    radix_sort(order, 64);
    const std::size_t n = boxes.size();
    min_x.resize(n + 1);
    max_x.resize(n);
    min_y.resize(n);
    max_y.resize(n);
    index.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      const Box<2>& b = boxes[order[k].index];
      min_x[k] = b.min[x], max_x[k] = b.max[x], min_y[k] = b.min[y], max_y[k] = b.max[y];
      index[k] = order[k].index;
    }
    min_x[n] = INFINITY;  // sentinel: every scan stops at the end without a bounds test
  }
  std::size_t size() const { return index.size(); }
};

// The axis to sweep along: x, unless the sweep along y would compare far fewer pairs. A box
// compares the boxes starting within its range on the sweep axis; on a sample of the boxes
// (every eighth box or sparser, at most 512) that count is taken exactly per axis, by binary
// search in the sample's sorted starts: a small fixed cost beside the sort. Linework along one
// axis (a meridian's segments all at one x, a polygon's long straight side) makes the sweep
// across it quadratic, and along it short.
inline int sweep_axis(std::span<const Box<2>> a, std::span<const Box<2>> b) {
  const std::size_t n = a.size() + b.size();
  if (n < 256) return 0;
  const std::size_t step = std::max<std::size_t>(8, (n + 511) / 512);
  std::array<double, 512> starts;
  std::size_t cost[2] = {0, 0};
  for (int d = 0; d < 2; ++d) {
    std::size_t m = 0;
    for (std::size_t i = 0; i < n; i += step)
      starts[m++] = (i < a.size() ? a[i] : b[i - a.size()]).min[d];
    std::sort(starts.begin(), starts.begin() + m);
    for (std::size_t i = 0; i < n; i += step) {
      const Box<2>& box = i < a.size() ? a[i] : b[i - a.size()];
      cost[d] += std::size_t(std::upper_bound(starts.begin(), starts.begin() + m, box.max[d]) -
                             std::lower_bound(starts.begin(), starts.begin() + m, box.min[d]));
    }
  }
  return 2 * cost[1] < cost[0] ? 1 : 0;
}

}  // namespace detail

// Calls visit(i, j), i < j, for every pair of intersecting boxes. Throws InvalidGeometry on a
// NaN, infinite or inverted box; InvalidArgument for 2^32 boxes or more.
template <PairVisitor Visit>
QueryStats self_join(std::span<const Box<2>> boxes, Visit&& visit) {
  if (boxes.size() >= kNone) throw InvalidArgument("self_join takes at most 2^32 - 2 boxes");
  for (std::size_t i = 0; i < boxes.size(); ++i)
    if (!is_valid(boxes[i])) check_box(boxes[i], ("box " + std::to_string(i)).c_str());
  const detail::SweepBoxes s(boxes, detail::sweep_axis(boxes, {}));
  QueryStats stats;
  stats.nodes_visited = 1;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double hi = s.max_x[i], lo_y = s.min_y[i], hi_y = s.max_y[i];
    for (std::size_t j = i + 1; s.min_x[j] <= hi; ++j) {
      ++stats.entries_tested;
      if (s.min_y[j] > hi_y || s.max_y[j] < lo_y) continue;
      ++stats.results;
      const Id a = s.index[i], b = s.index[j];
      if (!visit(std::min(a, b), std::max(a, b))) return stats;
    }
  }
  return stats;
}

// Calls visit(i, j) for every box i of `a` intersecting box j of `b`. Throws as self_join.
template <PairVisitor Visit>
QueryStats join(std::span<const Box<2>> a, std::span<const Box<2>> b, Visit&& visit) {
  if (a.size() >= kNone || b.size() >= kNone)
    throw InvalidArgument("join takes at most 2^32 - 2 boxes a side");
  for (auto side : {a, b})
    for (std::size_t i = 0; i < side.size(); ++i)
      if (!is_valid(side[i])) check_box(side[i], ("box " + std::to_string(i)).c_str());
  const int axis = detail::sweep_axis(a, b);
  const detail::SweepBoxes sa(a, axis), sb(b, axis);
  QueryStats stats;
  stats.nodes_visited = 2;
  // Each box of one side scans the boxes of the other that start inside its x-range: from A,
  // those starting at or after it; from B, those starting strictly after it. A pair's later
  // starter is found by the earlier one, ties by the box of A.
  std::size_t ia = 0, ib = 0;
  while (ia < sa.size() || ib < sb.size()) {
    const bool from_a = ib == sb.size() || (ia < sa.size() && sa.min_x[ia] <= sb.min_x[ib]);
    const detail::SweepBoxes& own = from_a ? sa : sb;
    const detail::SweepBoxes& other = from_a ? sb : sa;
    const std::size_t i = from_a ? ia++ : ib++;
    const std::size_t start = from_a ? ib : ia;
    const double hi = own.max_x[i], lo_y = own.min_y[i], hi_y = own.max_y[i];
    for (std::size_t j = start; other.min_x[j] <= hi; ++j) {
      ++stats.entries_tested;
      if (other.min_y[j] > hi_y || other.max_y[j] < lo_y) continue;
      ++stats.results;
      if (!(from_a ? visit(Id(own.index[i]), Id(other.index[j]))
                   : visit(Id(other.index[j]), Id(own.index[i]))))
        return stats;
    }
  }
  return stats;
}

}  // namespace loci
