// Helpers for insertion-built R-trees: the enlargement arithmetic Guttman's splits use to
// decide where an entry goes, and the least-enlargement choice of a subtree.
#pragma once

#include <limits>

#include "loci/geom/box.hpp"
#include "loci/index/detail/soa_boxes.hpp"

namespace loci::detail {

template <int D>
double enlargement(const Box<D>& group, const Box<D>& add) {
  return merged(group, add).content() - group.content();
}

// Guttman's rule for an entry that could go to either group: least enlargement, then smaller
// content, then fewer entries. Returns true for group A.
template <int D>
bool prefer_first(const Box<D>& a, int count_a, const Box<D>& b, int count_b, const Box<D>& e) {
  const double da = enlargement(a, e), db = enlargement(b, e);
  if (da != db) return da < db;
  if (a.content() != b.content()) return a.content() < b.content();
  return count_a <= count_b;
}

// Guttman's ChooseLeaf step: the child whose box needs the least enlargement to take b, ties
// to the smaller box. The R*-tree uses it above the leaves' parents.
template <int D, int M>
int least_enlargement(const SoaBoxes<D, M>& boxes, int count, const Box<D>& b) {
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

}  // namespace loci::detail
