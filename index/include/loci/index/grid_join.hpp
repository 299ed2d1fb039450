// Tiled sort-and-sweep joins of 2D boxes: every intersecting pair within one set
// (grid_self_join) or between two sets (grid_join), closed boxes, each pair once; the same
// answers as sweep_join.hpp, for inputs with long boxes.
//
// Method (partition-based spatial merge, Patel and DeWitt, SIGMOD 1996): the extent of the
// boxes is cut into a grid of tiles holding about kBoxesPerTile boxes each on average; a box is
// listed in every tile it overlaps, and each tile is swept on its own (sweep_join.hpp's method).
// A pair met in several tiles is reported only in the tile holding its reference point, the
// lower-left corner of the two boxes' intersection (max of the minima), which lies in both
// boxes and so in a tile both are listed in. The one-dimensional sweep compares a box with
// every box starting within its x-range; a long box (a straight border, a meridian) makes that
// range cover a large part of the data. In a tile it covers at most the tile's boxes. On the
// 4.8 million segments of a world coastline the plain sweep compares 492 million x-overlapping
// pairs to find 9.8 million intersecting ones.
//
// The lists are built with one radix sort on min x (shared with the plain sweep) and one
// counting pass over the tiles, so every tile's list is already in sweep order. When listing
// would replicate the boxes more than kMaxListing times over (most boxes span most of the
// extent), the plain sweep is used instead. Visitors as in sweep_join.hpp: `bool visit(Id i,
// Id j)`, i < j for the self-join, return false to stop; pairs come tile by tile.
// Thread-safety: pure functions of their inputs.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "loci/geom/box.hpp"
#include "loci/index/detail/large_alloc.hpp"
#include "loci/index/sweep_join.hpp"

namespace loci {

namespace detail {

// A grid of tiles over a box, and every input box listed in the tiles it overlaps, in order of
// min x within each tile (structure of arrays).
class TileLists {
 public:
  static constexpr std::size_t kBoxesPerTile = 48;
  static constexpr std::size_t kMaxListing = 4;

  // One grid for all the sets (a join needs the same tiles on both sides).
  static Box<2> extent(std::initializer_list<std::span<const Box<2>>> sets) {
    Box<2> e = Box<2>::empty();
    for (auto set : sets)
      for (const Box<2>& b : set)
        e.expand(b);
    return e;
  }

  TileLists(std::span<const Box<2>> boxes, const Box<2>& extent, std::size_t total) {
    const std::size_t tiles = std::max<std::size_t>(1, total / kBoxesPerTile);
    // Half extents: finite boxes can lie further apart than a double reaches, and an extent of
    // inf would make the grid NaN tiles wide. Halves never overflow and, above the denormals,
    // give the same ratios and scales as whole extents. A position whose distance from the
    // extent's minimum overflows saturates in the last tile, as col() and row() clamp.
    const double w = extent.max[0] / 2 - extent.min[0] / 2;
    const double h = extent.max[1] / 2 - extent.min[1] / 2;
    if (w > 0 && h > 0) {
      const double nx = std::sqrt(double(tiles) * w / h);
      nx_ = std::uint32_t(std::clamp(std::round(nx), 1.0, 4096.0));
      ny_ = std::uint32_t(std::clamp(std::round(double(tiles) / nx_), 1.0, 4096.0));
    } else if (w > 0) {
      nx_ = std::uint32_t(std::clamp<std::size_t>(tiles, 1, 1 << 16));
    } else if (h > 0) {
      ny_ = std::uint32_t(std::clamp<std::size_t>(tiles, 1, 1 << 16));
    }
    x0_ = extent.min[0], y0_ = extent.min[1];
    sx_ = w > 0 ? nx_ / 2.0 / w : 0, sy_ = h > 0 ? ny_ / 2.0 / h : 0;
    // Count the listings; give up on tiling when boxes span too many tiles.
    start_.assign(std::size_t(nx_) * ny_ + 1, 0);
    std::size_t listed = 0;
    for (const Box<2>& b : boxes) {
      const std::uint32_t c0 = col(b.min[0]), c1 = col(b.max[0]);
      const std::uint32_t r0 = row(b.min[1]), r1 = row(b.max[1]);
      listed += std::size_t(c1 - c0 + 1) * (r1 - r0 + 1);
      if (listed > kMaxListing * boxes.size() + 64) {
        tiled_ = false;
        return;
      }
      for (std::uint32_t r = r0; r <= r1; ++r)
        for (std::uint32_t c = c0; c <= c1; ++c)
          ++start_[tile(c, r) + 1];
    }
    for (std::size_t t = 1; t < start_.size(); ++t)
      start_[t] += start_[t - 1];
    // Boxes in order of min x, then dealt into their tiles: each list stays in that order.
    LargeVector<KeyedIndex> order(boxes.size());
    for (std::size_t i = 0; i < boxes.size(); ++i)
      order[i] = {ordered_key(boxes[i].min[0]), std::uint32_t(i)};
    radix_sort(order, 64);
    min_x.resize(listed + 1);
    max_x.resize(listed);
    min_y.resize(listed);
    max_y.resize(listed);
    index.resize(listed);
    std::vector<std::uint32_t> fill(start_.begin(), start_.end() - 1);
    for (const KeyedIndex& k : order) {
      const Box<2>& b = boxes[k.index];
      const std::uint32_t c0 = col(b.min[0]), c1 = col(b.max[0]);
      const std::uint32_t r0 = row(b.min[1]), r1 = row(b.max[1]);
      for (std::uint32_t r = r0; r <= r1; ++r)
        for (std::uint32_t c = c0; c <= c1; ++c) {
          const std::uint32_t at = fill[tile(c, r)]++;
          min_x[at] = b.min[0], max_x[at] = b.max[0], min_y[at] = b.min[1], max_y[at] = b.max[1];
          index[at] = k.index;
        }
    }
    min_x[listed] = INFINITY;  // sentinel for the scan of the last tile
  }

  bool tiled() const { return tiled_; }
  std::uint32_t columns() const { return nx_; }
  std::uint32_t rows() const { return ny_; }
  std::uint32_t col(double x) const {
    const double f = (x - x0_) * sx_;
    return f > 0 ? std::min(nx_ - 1, std::uint32_t(std::min(f, 4294967295.0))) : 0;
  }
  std::uint32_t row(double y) const {
    const double f = (y - y0_) * sy_;
    return f > 0 ? std::min(ny_ - 1, std::uint32_t(std::min(f, 4294967295.0))) : 0;
  }
  std::size_t tile(std::uint32_t c, std::uint32_t r) const { return std::size_t(r) * nx_ + c; }
  std::size_t begin(std::size_t t) const { return start_[t]; }
  std::size_t end(std::size_t t) const { return start_[t + 1]; }

  LargeVector<double> min_x, max_x, min_y, max_y;
  LargeVector<std::uint32_t> index;

 private:
  bool tiled_ = true;
  std::uint32_t nx_ = 1, ny_ = 1;
  double x0_ = 0, y0_ = 0, sx_ = 0, sy_ = 0;
  std::vector<std::size_t> start_;
};

inline void check_boxes(std::span<const Box<2>> boxes) {
  for (std::size_t i = 0; i < boxes.size(); ++i)
    if (!is_valid(boxes[i])) check_box(boxes[i], ("box " + std::to_string(i)).c_str());
}

}  // namespace detail

// The self-join's pairs reported in tile rows [row_begin, row_end) of `t`, a grid of the
// boxes (t.tiled()). Tiles are independent: threads may take disjoint ranges of rows.
template <PairVisitor Visit>
QueryStats grid_self_join(const detail::TileLists& t, std::uint32_t row_begin,
                          std::uint32_t row_end, Visit&& visit) {
  QueryStats stats;
  for (std::uint32_t r = row_begin; r < row_end; ++r)
    for (std::uint32_t c = 0; c < t.columns(); ++c) {
      const std::size_t tile = t.tile(c, r);
      ++stats.nodes_visited;
      for (std::size_t i = t.begin(tile), e = t.end(tile); i < e; ++i) {
        const double hi = t.max_x[i], lo_y = t.min_y[i], hi_y = t.max_y[i];
        // The list ends where the next tile's begins: its min x may be smaller, so bound j.
        for (std::size_t j = i + 1; j < e && t.min_x[j] <= hi; ++j) {
          ++stats.entries_tested;
          if (t.min_y[j] > hi_y || t.max_y[j] < lo_y) continue;
          // Report in the tile of the reference point only (min_x[j] >= min_x[i]).
          if (t.col(t.min_x[j]) != c || t.row(std::max(lo_y, t.min_y[j])) != r) continue;
          ++stats.results;
          const Id a = t.index[i], b = t.index[j];
          if (!visit(std::min(a, b), std::max(a, b))) return stats;
        }
      }
    }
  return stats;
}

// Calls visit(i, j), i < j, for every pair of intersecting boxes. Throws InvalidGeometry on a
// NaN, infinite or inverted box; InvalidArgument for 2^32 boxes or more.
template <PairVisitor Visit>
QueryStats grid_self_join(std::span<const Box<2>> boxes, Visit&& visit) {
  if (boxes.size() >= kNone) throw InvalidArgument("grid_self_join takes at most 2^32 - 2 boxes");
  detail::check_boxes(boxes);
  const detail::TileLists t(boxes, detail::TileLists::extent({boxes}), boxes.size());
  if (!t.tiled()) return self_join(boxes, std::forward<Visit>(visit));
  return grid_self_join(t, 0, t.rows(), visit);
}

// The two-set join's pairs reported in tile rows [row_begin, row_end) of grids `ta` and `tb`
// of the two sets, made over the same extent and total (both tiled).
template <PairVisitor Visit>
QueryStats grid_join(const detail::TileLists& ta, const detail::TileLists& tb,
                     std::uint32_t row_begin, std::uint32_t row_end, Visit&& visit) {
  QueryStats stats;
  for (std::uint32_t r = row_begin; r < row_end; ++r)
    for (std::uint32_t c = 0; c < ta.columns(); ++c) {
      const std::size_t tile = ta.tile(c, r);
      ++stats.nodes_visited;
      // The two lists of the tile interleaved by min x, as join() does for whole sets: a pair's
      // later starter is found by the earlier one, ties by the box of A.
      std::size_t ia = ta.begin(tile), ib = tb.begin(tile);
      const std::size_t ea = ta.end(tile), eb = tb.end(tile);
      while (ia < ea || ib < eb) {
        const bool from_a = ib == eb || (ia < ea && ta.min_x[ia] <= tb.min_x[ib]);
        const detail::TileLists& own = from_a ? ta : tb;
        const detail::TileLists& other = from_a ? tb : ta;
        const std::size_t i = from_a ? ia++ : ib++;
        const std::size_t end = from_a ? eb : ea;
        const double hi = own.max_x[i], lo_y = own.min_y[i], hi_y = own.max_y[i];
        for (std::size_t j = from_a ? ib : ia; j < end && other.min_x[j] <= hi; ++j) {
          ++stats.entries_tested;
          if (other.min_y[j] > hi_y || other.max_y[j] < lo_y) continue;
          if (ta.col(other.min_x[j]) != c || ta.row(std::max(lo_y, other.min_y[j])) != r) continue;
          ++stats.results;
          if (!(from_a ? visit(Id(own.index[i]), Id(other.index[j]))
                       : visit(Id(other.index[j]), Id(own.index[i]))))
            return stats;
        }
      }
    }
  return stats;
}

// Calls visit(i, j) for every box i of `a` intersecting box j of `b`. Throws as grid_self_join.
template <PairVisitor Visit>
QueryStats grid_join(std::span<const Box<2>> a, std::span<const Box<2>> b, Visit&& visit) {
  if (a.size() >= kNone || b.size() >= kNone)
    throw InvalidArgument("grid_join takes at most 2^32 - 2 boxes a side");
  detail::check_boxes(a);
  detail::check_boxes(b);
  const Box<2> extent = detail::TileLists::extent({a, b});
  const detail::TileLists ta(a, extent, a.size() + b.size());
  const detail::TileLists tb(b, extent, a.size() + b.size());
  if (!ta.tiled() || !tb.tiled()) return join(a, b, std::forward<Visit>(visit));
  return grid_join(ta, tb, 0, ta.rows(), visit);
}

}  // namespace loci
