// RTree<D, Split, M>: Guttman's R-tree (SIGMOD 1984) with the linear or quadratic split.
//
// An entry descends into the child whose box needs the least enlargement to take it (ties:
// the smaller box). An overfull node (M + 1 entries) is split in two:
// - QuadraticSplit picks as seeds the pair that would waste the most area together, then
//   repeatedly assigns the entry with the strongest preference for one group; O(M^2).
// - LinearSplit picks as seeds the pair with the greatest normalised separation along any
//   axis, then assigns the others in order to the group needing least enlargement; O(M).
// Both respect the minimum fill by handing the rest to a group that would fall short.
// The API is BasicRTree's, below; deletion, bulk loading and queries are shared with the
// R*-tree (detail/dynamic_rtree.hpp). Thread-safety: const member functions may run
// concurrently; insert, erase and update need exclusive access.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <utility>

#include "loci/index/detail/dynamic_rtree.hpp"
#include "loci/index/detail/split_groups.hpp"

namespace loci {

namespace detail {

// Moves the entries flagged for group A to the front; returns their count.
template <int D>
int gather_first(Entry<D>* e, int n, const bool* in_a) {
  Entry<D> tmp[65];
  int a = 0, b = n;
  for (int i = 0; i < n; ++i) {
    if (in_a[i])
      tmp[a++] = e[i];
    else
      tmp[--b] = e[i];
  }
  std::copy(tmp, tmp + n, e);
  return a;
}

// Distributes the entries not yet assigned; `next` picks the one to place now.
template <int D, class PickNext>
int distribute(Entry<D>* e, int n, int min_fill, int seed_a, int seed_b, PickNext next) {
  bool assigned[65] = {};
  bool in_a[65] = {};
  assigned[seed_a] = assigned[seed_b] = true;
  in_a[seed_a] = true;
  Box<D> a = e[seed_a].box, b = e[seed_b].box;
  int count_a = 1, count_b = 1;
  for (int left = n - 2; left > 0; --left) {
    if (count_a + left == min_fill || count_b + left == min_fill) {
      const bool to_a = count_a + left == min_fill;
      for (int i = 0; i < n; ++i)
        if (!assigned[i]) assigned[i] = true, in_a[i] = to_a;
      break;
    }
    const int i = next(assigned, a, b);
    assigned[i] = true;
    if (prefer_first(a, count_a, b, count_b, e[i].box)) {
      in_a[i] = true;
      a.expand(e[i].box);
      ++count_a;
    } else {
      b.expand(e[i].box);
      ++count_b;
    }
  }
  return gather_first(e, n, in_a);
}

}  // namespace detail

struct QuadraticSplit {
  template <int D>
  static int split(Entry<D>* e, int n, int min_fill) {
    // Contents of large boxes overflow to inf, and inf - inf is NaN, which compares greater
    // than nothing: the seeds then stay the first pair and pick_next falls back to the first
    // unassigned entry, so the split is still a partition, just not Guttman's choice.
    int sa = 0, sb = 1;
    double worst = -std::numeric_limits<double>::infinity();
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j) {
        const double waste =
            merged(e[i].box, e[j].box).content() - e[i].box.content() - e[j].box.content();
        if (waste > worst) worst = waste, sa = i, sb = j;
      }
    auto pick_next = [&](const bool* assigned, const Box<D>& a, const Box<D>& b) {
      int best = -1;
      double pref = -1;
      for (int i = 0; i < n; ++i) {
        if (assigned[i]) continue;
        if (best < 0) best = i;
        const double d =
            std::fabs(detail::enlargement(a, e[i].box) - detail::enlargement(b, e[i].box));
        if (d > pref) pref = d, best = i;
      }
      return best;
    };
    return detail::distribute<D>(e, n, min_fill, sa, sb, pick_next);
  }
};

struct LinearSplit {
  template <int D>
  static int split(Entry<D>* e, int n, int min_fill) {
    int sa = 0, sb = 1;
    double best = -std::numeric_limits<double>::infinity();
    for (int axis = 0; axis < D; ++axis) {
      int highest_low = 0, lowest_high = 0;
      double lo = e[0].box.min[axis], hi = e[0].box.max[axis];
      for (int i = 1; i < n; ++i) {
        if (e[i].box.min[axis] > e[highest_low].box.min[axis]) highest_low = i;
        if (e[i].box.max[axis] < e[lowest_high].box.max[axis]) lowest_high = i;
        lo = std::min(lo, e[i].box.min[axis]);
        hi = std::max(hi, e[i].box.max[axis]);
      }
      if (highest_low == lowest_high) lowest_high = highest_low == 0 ? 1 : 0;
      const double width = hi - lo;
      const double sep =
          (e[highest_low].box.min[axis] - e[lowest_high].box.max[axis]) / (width > 0 ? width : 1.0);
      if (sep > best) best = sep, sa = lowest_high, sb = highest_low;
    }
    auto pick_next = [&](const bool* assigned, const Box<D>&, const Box<D>&) {
      int i = 0;
      while (assigned[i])
        ++i;
      return i;
    };
    return detail::distribute<D>(e, n, min_fill, sa, sb, pick_next);
  }
};

template <class Split>
struct GuttmanInsertion {
  static constexpr bool forced_reinsert = false;

  template <int D, int M>
  static int choose_subtree(const detail::SoaBoxes<D, M>& boxes, int count, int /*level*/,
                            const Box<D>& b) {
    return detail::least_enlargement(boxes, count, b);
  }

  template <int D>
  static int split(Entry<D>* e, int n, int min_fill) {
    return Split::template split<D>(e, n, min_fill);
  }
};

// BasicRTree<D, M, Policy>: an insertion-built R-tree of node capacity M whose subtree choice,
// split and overflow treatment come from Policy (GuttmanInsertion<Split> here,
// RStarInsertion in rstar_tree.hpp). This is the API of RTree and RStarTree; the machinery
// shared by every policy is detail/dynamic_rtree.hpp.
template <int D, int M, class Policy>
class BasicRTree : private detail::DynamicRTree<D, M, Policy> {
  using Base = detail::DynamicRTree<D, M, Policy>;

 public:
  static constexpr int dimension = D;
  static constexpr int max_entries = M;
  static constexpr int min_entries = Base::min_entries;  // 40% of M

  BasicRTree() = default;

  // Builds a tree from (box, id) pairs by top-down STR tiling with near-equal node sizes, so
  // every node respects the minimum fill. Throws InvalidGeometry on a bad box.
  static BasicRTree bulk_load(std::span<const std::pair<Box<D>, Id>> entries) {
    return BasicRTree(Base::bulk_load(entries));
  }

  using Base::bounds;  // the root's box
  using Base::empty;
  using Base::height;        // levels, 1 for a lone leaf
  using Base::memory_bytes;  // the node pool's capacity
  using Base::size;

  // insert(box, id): throws InvalidGeometry on a NaN, infinite or inverted box.
  // erase(box, id): removes one entry with exactly this box and id; false when there is none.
  // update(old_box, new_box, id): erase then insert; false (and no change) when not there.
  using Base::erase;
  using Base::insert;
  using Base::update;

  // query(window, visit, relation = intersects) -> QueryStats: visit(id, box) for each entry
  // in the relation with the window, until it returns false; query(window, relation) ->
  // std::vector<Id>. nearest(p, k, visit) -> QueryStats: visit(id, box, distance) for the k
  // entries nearest p, nearest first; nearest(p, k) -> std::vector<Neighbor>. Throw
  // InvalidGeometry on a bad window or point, InvalidArgument for k = 0.
  using Base::browse;
  using Base::nearest;
  using Base::query;

  // Throws loci::Error describing the first broken invariant.
  using Base::validate;

 private:
  explicit BasicRTree(Base&& tree) : Base(std::move(tree)) {}
};

template <int D, class Split = QuadraticSplit, int M = 16>
using RTree = BasicRTree<D, M, GuttmanInsertion<Split>>;

static_assert(DynamicBoxIndex<RTree<2>> && NearestIndex<RTree<2>>);

using RTree2 = RTree<2>;
using RTree3 = RTree<3>;

}  // namespace loci
