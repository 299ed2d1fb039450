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
#include <cstdint>
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

namespace loci::detail {

// An item of str_tile_cells: its key on each of up to D axes quantized to cell_bits<D>() bits
// (axis a in bits [a B, a B + B)), and the caller's index.
struct CellItem {
  std::uint64_t cells;
  std::uint32_t index;
};

// Bits an axis gets in CellItem::cells: 16, or fewer when D axes would not fit in 64 bits.
template <int D>
constexpr int cell_bits() {
  return 64 / D < 16 ? 64 / D : 16;
}

// The same tiling as str_tile, over keys quantized to cell_bits<D>() bits an axis (a grid of
// 2^16 cells over each axis's range for D <= 4, so that items closer than 1/65536 of the range
// may tie), found by sorting instead of selecting: each level is one stable counting sort of
// 8-bit passes, so the whole tiling costs O(n D) and reads 16-byte items sequentially. What
// rebuilding a moving index every tick needs. `tmp` is scratch, resized as needed.
template <int D>
void str_tile_cells(CellItem* base, std::span<const std::size_t> groups, std::vector<CellItem>& tmp,
                    int axis = 0) {
  constexpr int kBits = cell_bits<D>();
  static_assert(D >= 1 && kBits >= 8, "at most 8 axes");
  const std::size_t k = groups.size() - 1;
  if (k <= 1) return;
  const std::size_t lo = groups.front(), n = groups.back() - lo;
  CellItem* const a = base + lo;
  const int shift = kBits * axis;
  constexpr std::uint64_t kMask = (std::uint64_t(1) << kBits) - 1;
  if (n <= 64) {
    std::stable_sort(a, a + n, [&](const CellItem& x, const CellItem& y) {
      return ((x.cells >> shift) & kMask) < ((y.cells >> shift) & kMask);
    });
  } else {
    // Two passes of 8 bits (the second of kBits - 8): the result lands back in place.
    static_assert(kBits <= 16);
    if (tmp.size() < n) tmp.resize(n);
    CellItem* const b = tmp.data();
    for (int pass = 0; pass < 2; ++pass) {
      CellItem* const from = pass == 0 ? a : b;
      CellItem* const to = pass == 0 ? b : a;
      const int s = shift + 8 * pass;
      const std::uint64_t mask = pass == 0 ? 0xff : (std::uint64_t(1) << (kBits - 8)) - 1;
      std::size_t count[256] = {};
      for (std::size_t i = 0; i < n; ++i)
        ++count[(from[i].cells >> s) & mask];
      std::size_t sum = 0;
      for (std::size_t& c : count) {
        const std::size_t m = c;
        c = sum;
        sum += m;
      }
      for (std::size_t i = 0; i < n; ++i)
        to[count[(from[i].cells >> s) & mask]++] = from[i];
    }
  }
  if (axis == D - 1) return;  // sorted along the last axis: consecutive groups are the tiles
  const auto slabs =
      static_cast<std::size_t>(std::ceil(std::pow(double(k), 1.0 / (D - axis)) - 1e-9));
  const std::size_t per_slab = (k + slabs - 1) / slabs;
  for (std::size_t first = 0; first < k; first += per_slab) {
    const std::size_t count = std::min(per_slab, k - first);
    str_tile_cells<D>(base, groups.subspan(first, count + 1), tmp, axis + 1);
  }
}

}  // namespace loci::detail
