// Helpers for node-split algorithms: two growing groups of entries and the enlargement
// arithmetic Guttman's splits use to decide where an entry goes.
#pragma once

#include "loci/geom/box.hpp"

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

}  // namespace loci::detail
