// Sort-Tile-Recursive tiling (Leutenegger, Lopez and Edgington, ICDE 1997), applied top-down.
//
// str_tile() reorders a range of items so that consecutive groups, whose boundaries the caller
// gives, are spatial tiles: the range is cut into ceil(k^(1/D)) slabs along the first axis
// (each holding whole groups), every slab into slabs along the next axis, and so on, the last
// axis cutting single groups. Only order statistics are needed, so each cut is an
// nth_element and the whole tiling costs O(n log k). Applied from the root down with group
// sizes that are multiples of the subtree capacity, it yields a packed tree in which only the
// last node of each level is partly filled (the implicit layout PackedRTree needs); with
// near-equal group sizes it yields a bulk-loaded dynamic tree whose nodes all respect the
// minimum fill (the top-down variant is also known as OMT).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>
#include <vector>

namespace loci::detail {

// Reorders [base + cuts.front(), base + cuts.back()) so that every element before cuts[i] is
// no greater on `axis` than any element after it.
template <class Item, class Less>
void select_cuts(Item* base, std::span<const std::size_t> cuts, Less less) {
  if (cuts.size() <= 2) return;
  const std::size_t mid = cuts.size() / 2;
  std::nth_element(base + cuts.front(), base + cuts[mid], base + cuts.back(), less);
  select_cuts(base, cuts.first(mid + 1), less);
  select_cuts(base, cuts.subspan(mid), less);
}

// `groups` holds k + 1 increasing offsets into base; `coord(item, axis)` gives the key.
template <int D, class Item, class Coord>
void str_tile(Item* base, std::span<const std::size_t> groups, Coord coord, int axis = 0) {
  const std::size_t k = groups.size() - 1;
  if (k <= 1) return;
  auto less = [&](const Item& a, const Item& b) { return coord(a, axis) < coord(b, axis); };
  if (axis == D - 1) {
    select_cuts(base, groups, less);
    return;
  }
  const auto slabs =
      static_cast<std::size_t>(std::ceil(std::pow(double(k), 1.0 / (D - axis)) - 1e-9));
  const std::size_t per_slab = (k + slabs - 1) / slabs;
  std::size_t slab_cuts_buf[66];
  std::vector<std::size_t> slab_cuts_vec;
  std::size_t* slab_cuts = slab_cuts_buf;
  const std::size_t nslabs = (k + per_slab - 1) / per_slab;
  if (nslabs + 1 > 66) {
    slab_cuts_vec.resize(nslabs + 1);
    slab_cuts = slab_cuts_vec.data();
  }
  for (std::size_t s = 0; s < nslabs; ++s)
    slab_cuts[s] = groups[s * per_slab];
  slab_cuts[nslabs] = groups[k];
  select_cuts(base, std::span<const std::size_t>(slab_cuts, nslabs + 1), less);
  for (std::size_t s = 0; s < nslabs; ++s) {
    const std::size_t first = s * per_slab;
    const std::size_t count = std::min(per_slab, k - first);
    str_tile<D>(base, groups.subspan(first, count + 1), coord, axis + 1);
  }
}

}  // namespace loci::detail
