// RTree<D, Split, M>: Guttman's R-tree (SIGMOD 1984) with the linear or quadratic split.
//
// An entry descends into the child whose box needs the least enlargement to take it (ties:
// the smaller box). An overfull node (M + 1 entries) is split in two:
// - QuadraticSplit picks as seeds the pair that would waste the most area together, then
//   repeatedly assigns the entry with the strongest preference for one group; O(M^2).
// - LinearSplit picks as seeds the pair with the greatest normalised separation along any
//   axis, then assigns the others in order to the group needing least enlargement; O(M).
// Both respect the minimum fill by handing the rest to a group that would fall short.
// Deletion, bulk loading, queries and thread-safety: see detail/dynamic_rtree.hpp.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

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
    int best = 0;
    double best_grow = std::numeric_limits<double>::infinity(), best_content = best_grow;
    for (int i = 0; i < count; ++i) {
      const Box<D> c = boxes.box(i);
      const double content = c.content();
      const double grow = merged(c, b).content() - content;
      if (grow < best_grow || (grow == best_grow && content < best_content))
        best = i, best_grow = grow, best_content = content;
    }
    return best;
  }

  template <int D>
  static int split(Entry<D>* e, int n, int min_fill) {
    return Split::template split<D>(e, n, min_fill);
  }
};

template <int D, class Split = QuadraticSplit, int M = 16>
using RTree = detail::DynamicRTree<D, M, GuttmanInsertion<Split>>;

using RTree2 = RTree<2>;
using RTree3 = RTree<3>;

}  // namespace loci
