// The canonical nodes of a slot range in a bottom-up (implicit, array-backed) segment tree.
//
// With `leaves` leaves stored at indices [leaves, 2 * leaves) and node v's children at 2v and
// 2v + 1, the slots [first, last] are covered by at most 2 log2(leaves) disjoint nodes, found
// by walking both ends of the range up one level at a time. Every segment tree in loci stores
// an interval at exactly these nodes.
#pragma once

#include <cstddef>

namespace loci::detail {

template <class F>
void for_each_canonical_node(std::size_t leaves, std::size_t first, std::size_t last, F&& f) {
  std::size_t l = first + leaves, r = last + leaves + 1;
  while (l < r) {
    if (l & 1) f(l++);
    if (r & 1) f(--r);
    l >>= 1;
    r >>= 1;
  }
}

}  // namespace loci::detail
