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

// Stable sort of the n items at a whose cells (at `shift`) share their top bits, by the
// Low bits below those; b is scratch of n items.
template <int Low>
void sort_low_bits(CellItem* a, std::size_t n, int shift, CellItem* b) {
  constexpr std::uint64_t kMask = (std::uint64_t(1) << Low) - 1;
  const auto low = [shift](const CellItem& x) { return (x.cells >> shift) & kMask; };
  if (n <= 32) {  // insertion sort
    for (std::size_t i = 1; i < n; ++i) {
      const CellItem x = a[i];
      std::size_t j = i;
      for (; j > 0 && low(a[j - 1]) > low(x); --j)
        a[j] = a[j - 1];
      a[j] = x;
    }
    return;
  }
  std::size_t next[(1 << Low) + 1] = {};
  for (std::size_t i = 0; i < n; ++i)
    ++next[low(a[i]) + 1];
  for (int j = 1; j <= (1 << Low); ++j)
    next[j] += next[j - 1];
  for (std::size_t i = 0; i < n; ++i)
    b[next[low(a[i])]++] = a[i];
  std::copy(b, b + n, a);
}

// The same tiling as str_tile, over keys quantized to cell_bits<D>() bits an axis (a grid of
// 2^16 cells over each axis's range for D <= 4, so that items closer than 1/65536 of the range
// may tie), found by counting instead of selecting, so the whole tiling costs O(n D) and reads
// 16-byte items sequentially; what rebuilding a moving index every tick needs. Each level
// distributes its range into 256 buckets by the top 8 bits of the axis's cell (a stable
// counting sort into `tmp`) and brings the buckets back; only a bucket that a boundary of the
// level cuts is sorted by the remaining bits on the way. Every slab, and in the end every
// group, then holds the items a full stable sort of the level would give it; within a slab
// only the top bits are in order. `tmp` is scratch, resized as needed.
template <int D>
void str_tile_cells(CellItem* base, std::span<const std::size_t> groups, std::vector<CellItem>& tmp,
                    int axis = 0) {
  constexpr int kBits = cell_bits<D>();
  static_assert(D >= 1 && kBits >= 8 && kBits <= 16, "at most 8 axes");
  constexpr int kLow = kBits - 8;  // the bits below the top 8
  const std::size_t k = groups.size() - 1;
  if (k <= 1) return;
  const std::size_t lo = groups.front(), n = groups.back() - lo;
  CellItem* const a = base + lo;
  const int shift = kBits * axis;
  constexpr std::uint64_t kMask = (std::uint64_t(1) << kBits) - 1;
  const auto cell = [shift](const CellItem& x) { return (x.cells >> shift) & kMask; };
  const auto by_cell = [&](const CellItem& x, const CellItem& y) { return cell(x) < cell(y); };
  // The level's slabs: runs of per_slab groups, single groups on the last axis.
  const bool last = axis == D - 1;
  const std::size_t slabs =
      last ? k : static_cast<std::size_t>(std::ceil(std::pow(double(k), 1.0 / (D - axis)) - 1e-9));
  const std::size_t per_slab = (k + slabs - 1) / slabs;
  if (n <= 64) {
    std::stable_sort(a, a + n, by_cell);
  } else {
    if (tmp.size() < n) tmp.resize(n);
    CellItem* const b = tmp.data();
    std::size_t start[257] = {};  // start[j]: first offset of bucket j; start[256] = n
    for (std::size_t i = 0; i < n; ++i)
      ++start[(cell(a[i]) >> kLow) + 1];
    for (int j = 1; j <= 256; ++j)
      start[j] += start[j - 1];
    std::size_t next[256];
    std::copy_n(start, 256, next);
    for (std::size_t i = 0; i < n; ++i)
      b[next[cell(a[i]) >> kLow]++] = a[i];
    std::copy(b, b + n, a);
    // Each boundary of the level inside a bucket (not at its start) has the bucket sorted.
    if constexpr (kLow > 0) {
      std::size_t sorted_end = 0;  // end of the last bucket sorted
      for (std::size_t f = per_slab; f < k; f += per_slab) {
        const std::size_t c = groups[f] - lo;
        if (c < sorted_end) continue;
        const std::size_t* j = std::upper_bound(start, start + 257, c);  // start[j-1] <= c
        if (j[-1] == c) continue;
        sort_low_bits<kLow>(a + j[-1], j[0] - j[-1], shift, b);
        sorted_end = j[0];
      }
    }
  }
  if (last) return;  // consecutive groups are the tiles
  for (std::size_t first = 0; first < k; first += per_slab) {
    const std::size_t count = std::min(per_slab, k - first);
    str_tile_cells<D>(base, groups.subspan(first, count + 1), tmp, axis + 1);
  }
}

}  // namespace loci::detail
