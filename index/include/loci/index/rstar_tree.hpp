// RStarTree<D, M>: the R*-tree of Beckmann, Kriegel, Schneider and Seeger ("The R*-tree: an
// efficient and robust access method for points and rectangles", SIGMOD 1990).
//
// Against Guttman's tree it changes three decisions:
// - ChooseSubtree: where the children are leaves, the entry goes to the child whose
//   enlargement adds the least overlap with its siblings (ties: least area enlargement, then
//   least area); higher up, least area enlargement.
// - Overflow: the first time a level overflows during one insertion, the 30% of entries whose
//   centres are farthest from the node's centre are removed and inserted again (close
//   reinsert); only later overflows split.
// - Split: the axis is the one whose sorted distributions have the least total margin; the
//   distribution along it is the one with least overlap between the two groups (ties: least
//   total area). Prefix and suffix bounds make each axis O(M) after sorting.
// The API is BasicRTree's (rtree.hpp); deletion, bulk loading and queries are shared with
// Guttman's tree (detail/dynamic_rtree.hpp). Thread-safety: const member functions may run
// concurrently; insert, erase and update need exclusive access.
#pragma once

#include <algorithm>
#include <limits>

#include "loci/index/detail/dynamic_rtree.hpp"
#include "loci/index/detail/split_groups.hpp"
#include "loci/index/rtree.hpp"

namespace loci {

struct RStarInsertion {
  static constexpr bool forced_reinsert = true;

  template <int D, int M>
  static int choose_subtree(const detail::SoaBoxes<D, M>& boxes, int count, int level,
                            const Box<D>& b) {
    if (level == 1) return least_overlap_growth(boxes, count, b);
    return detail::least_enlargement(boxes, count, b);
  }

  template <int D>
  static int split(Entry<D>* e, int n, int min_fill);

 private:
  // Sum over j != i of overlap(box_i + b, box_j) - overlap(box_i, box_j).
  template <int D, int M>
  static double overlap_growth(const detail::SoaBoxes<D, M>& boxes, int count, int i,
                               const Box<D>& grown) {
    const Box<D> old = boxes.box(i);
    double total = 0;
    for (int j = 0; j < count; ++j) {
      double after = 1, before = 1;
      for (int a = 0; a < D; ++a) {
        const double lo = boxes.lo[a][j], hi = boxes.hi[a][j];
        after *= std::max(0.0, std::min(hi, grown.max[a]) - std::max(lo, grown.min[a]));
        before *= std::max(0.0, std::min(hi, old.max[a]) - std::max(lo, old.min[a]));
      }
      total += after - before;
    }
    // j == i adds nothing: grown covers old, so both overlaps are content(old).
    return total;
  }

  template <int D, int M>
  static int least_overlap_growth(const detail::SoaBoxes<D, M>& boxes, int count, const Box<D>& b) {
    // A child that already contains b grows nothing: the smallest such child wins.
    int inside = -1;
    double inside_content = std::numeric_limits<double>::infinity();
    for (int i = 0; i < count; ++i) {
      const Box<D> c = boxes.box(i);
      if (contains(c, b) && c.content() < inside_content) inside = i, inside_content = c.content();
    }
    if (inside >= 0) return inside;
    int best = 0;
    double best_overlap = std::numeric_limits<double>::infinity();
    double best_grow = best_overlap, best_content = best_overlap;
    for (int i = 0; i < count; ++i) {
      const Box<D> c = boxes.box(i);
      const Box<D> grown = merged(c, b);
      const double content = c.content();
      const double grow = grown.content() - content;
      const double ov = overlap_growth(boxes, count, i, grown);
      if (ov < best_overlap ||
          (ov == best_overlap &&
           (grow < best_grow || (grow == best_grow && content < best_content))))
        best = i, best_overlap = ov, best_grow = grow, best_content = content;
    }
    return best;
  }
};

template <int D>
int RStarInsertion::split(Entry<D>* e, int n, int min_fill) {
  const int distributions = n - 2 * min_fill + 1;  // first group sizes min_fill .. n - min_fill
  Box<D> prefix[65], suffix[65];
  auto sweep = [&](const Entry<D>* s) {
    prefix[0] = s[0].box;
    for (int i = 1; i < n; ++i)
      prefix[i] = merged(prefix[i - 1], s[i].box);
    suffix[n - 1] = s[n - 1].box;
    for (int i = n - 2; i >= 0; --i)
      suffix[i] = merged(suffix[i + 1], s[i].box);
  };
  auto by = [](int axis, bool upper) {
    return [=](const Entry<D>& x, const Entry<D>& y) {
      const double kx = upper ? x.box.max[axis] : x.box.min[axis];
      const double ky = upper ? y.box.max[axis] : y.box.min[axis];
      if (kx != ky) return kx < ky;
      return (upper ? x.box.min[axis] : x.box.max[axis]) <
             (upper ? y.box.min[axis] : y.box.max[axis]);
    };
  };

  // ChooseSplitAxis: least sum of margins over all distributions of both sortings.
  int axis = 0;
  double best_margin = std::numeric_limits<double>::infinity();
  Entry<D> sorted[65];
  for (int a = 0; a < D; ++a) {
    double margin = 0;
    for (bool upper : {false, true}) {
      std::copy(e, e + n, sorted);
      std::sort(sorted, sorted + n, by(a, upper));
      sweep(sorted);
      for (int k = 0; k < distributions; ++k) {
        const int first = min_fill + k;
        margin += prefix[first - 1].margin() + suffix[first].margin();
      }
    }
    if (margin < best_margin) best_margin = margin, axis = a;
  }

  // ChooseSplitIndex: least overlap, then least total content, along that axis.
  double best_overlap = std::numeric_limits<double>::infinity(), best_content = best_overlap;
  bool best_upper = false;
  int best_first = min_fill;
  for (bool upper : {false, true}) {
    std::copy(e, e + n, sorted);
    std::sort(sorted, sorted + n, by(axis, upper));
    sweep(sorted);
    for (int k = 0; k < distributions; ++k) {
      const int first = min_fill + k;
      const double ov = overlap(prefix[first - 1], suffix[first]);
      const double content = prefix[first - 1].content() + suffix[first].content();
      if (ov < best_overlap || (ov == best_overlap && content < best_content))
        best_overlap = ov, best_content = content, best_upper = upper, best_first = first;
    }
  }
  std::sort(e, e + n, by(axis, best_upper));
  return best_first;
}

// The API is BasicRTree's (rtree.hpp).
template <int D, int M = 16>
using RStarTree = BasicRTree<D, M, RStarInsertion>;

static_assert(DynamicBoxIndex<RStarTree<2>> && NearestIndex<RStarTree<2>>);

using RStarTree2 = RStarTree<2>;
using RStarTree3 = RStarTree<3>;

}  // namespace loci
