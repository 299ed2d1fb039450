// RegionQuadtree: the region quadtree of a planar region (Klinger, 1971; Samet, "The Quadtree
// and Related Hierarchical Data Structures", ACM Computing Surveys 1984), with MX boundary
// cells (Hunter and Steiglitz, 1979) for regions that are not given as pixels: the cells a map
// layer covers, at a chosen resolution.
//
// Structure. A square region is cut recursively into four equal quadrants, down to at most
// `levels` cuts (a 2^levels x 2^levels grid of finest cells). Every leaf is a maximal block of
// one cover: `outside` (the block does not meet the region), `inside` (the block lies in the
// region) or `boundary` (only at the finest level: the region's boundary passes through the
// cell, the MX quadtree's black pixel). Four sibling leaves of the same non-boundary cover
// are always merged into their parent, so the tree of a region at a given resolution is
// unique. The region is described by a classifier, `Cover classify(const Box2& cell)`, that
// says whether a closed cell lies outside, inside, or meets the boundary; a cell it calls
// `boundary` is split. A classifier may be conservative (call a cell boundary that is not):
// its children are then classified and merged back. from_raster() gives the textbook region
// quadtree of a binary image, where no cell is ever boundary.
//
// Cells are addressed by grid coordinates: cell (x, y) at level l covers the finest cells
// [x 2^(levels - l), (x + 1) 2^(levels - l)) on the x axis, likewise y. Coordinates are
// computed from the finest grid only, min + i * (side / 2^levels), so a child shares its edges
// with its parent and siblings exactly.
//
// Layout. One flat vector of 32-bit words, 4 bytes a node: an internal node holds the index
// of its first child (the four children are consecutive: bit 0 of the child's number selects
// the upper x half, bit 1 the upper y half, as in PrQuadtree), a leaf holds kLeaf + cover.
// Nodes are in depth-first order, so a window query reads memory forwards.
//
// Queries: cover_at(point) (point location; a point on a shared edge belongs to the cell above
// or right of it), query(window) for the non-outside leaves meeting a closed window, area and
// leaf counts per cover, visit_cells() for drawing, and the cell-wise union and intersection
// of two trees on the same grid (map overlay: boundary meets boundary stays boundary).
//
// Invariants (checked by validate()): every node reachable once and every word used; child
// groups in range; boundary leaves only at the finest level; no internal node whose four
// children are leaves of one non-boundary cover.
//
// Complexity: build calls the classifier once per node, O(4 * leaves); the leaf count of a
// region is proportional to its boundary's length in finest cells (Hunter's theorem). Point
// location O(levels); window query O(levels + cells reported + their ancestors).
//
// Thread-safety: immutable after build; any number of concurrent queries.
#pragma once

#include <algorithm>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "loci/geom/box.hpp"
#include "loci/geom/error.hpp"
#include "loci/index/detail/scratch.hpp"
#include "loci/index/query.hpp"

namespace loci {

enum class Cover : std::uint8_t { outside = 0, inside = 1, boundary = 2 };

inline const char* to_string(Cover c) {
  switch (c) {
    case Cover::inside:
      return "inside";
    case Cover::boundary:
      return "boundary";
    default:
      return "outside";
  }
}

// A leaf of a RegionQuadtree: its block, cover, level and grid coordinates at that level.
struct QuadCell {
  Box2 box;
  Cover cover;
  int level;
  std::uint32_t x, y;
};

template <class F>
concept CellVisitor = Visitor<F, const QuadCell&>;

template <class F>
concept CellClassifier = std::is_invocable_r_v<Cover, F&, const Box2&>;

class RegionQuadtree {
 public:
  static constexpr int kMaxLevels = 30;

  RegionQuadtree() = default;
  RegionQuadtree(const RegionQuadtree&) = default;
  RegionQuadtree& operator=(const RegionQuadtree&) = default;
  // Moving leaves `other` empty, as if default-constructed.
  RegionQuadtree(RegionQuadtree&& other) noexcept : RegionQuadtree() { swap(other); }
  RegionQuadtree& operator=(RegionQuadtree&& other) noexcept {
    RegionQuadtree(std::move(other)).swap(*this);
    return *this;
  }

  // The tree of the region that `classify` describes over the square `region` (a given box
  // is extended to a square from its min corner), cut at most `levels` times.
  // Throws InvalidArgument for levels outside [0, 30] or a region too small to be cut that
  // often in double precision, InvalidGeometry for a NaN, infinite or empty region.
  template <CellClassifier Classify>
  static RegionQuadtree build(const Box2& region, int levels, Classify&& classify) {
    RegionQuadtree t(region, levels);
    auto by_cell = [&](std::uint32_t x, std::uint32_t y, int l) {
      return Cover(classify(t.block(x, y, l)));
    };
    t.grow(0, 0, 0, 0, by_cell);
    return t;
  }

  // The region quadtree of a binary image: pixel (c, r) of a `width` x `height` raster, row 0
  // at the bottom, is the finest cell (c, r) of `region`, inside where pixels[r * width + c]
  // is non-zero. The raster may be smaller than the 2^levels grid: the rest is outside.
  // Throws InvalidArgument when the raster is larger than the grid or `pixels` too short.
  static RegionQuadtree from_raster(const Box2& region, int levels,
                                    std::span<const std::uint8_t> pixels, std::size_t width,
                                    std::size_t height);

  int levels() const { return levels_; }
  Box2 region() const { return {origin_, {grid(0, 1u << levels_), grid(1, 1u << levels_)}}; }
  // The block of cell (x, y) at `level`, 0 <= level <= levels(), x and y below 2^level;
  // throws InvalidArgument otherwise.
  Box2 cell_box(std::uint32_t x, std::uint32_t y, int level) const {
    if (level < 0 || level > levels_ || x >> level != 0 || y >> level != 0)
      throw InvalidArgument("cell_box: no cell (" + std::to_string(x) + ", " + std::to_string(y) +
                            ") at level " + std::to_string(level) + " of a tree of " +
                            std::to_string(levels_) + " levels");
    return block(x, y, level);
  }
  std::size_t node_count() const { return std::max<std::size_t>(nodes_.size(), 1); }
  std::size_t memory_bytes() const { return nodes_.size() * sizeof(std::uint32_t); }
  // Leaves of cover c, and their total area.
  std::size_t count(Cover c) const;
  double area(Cover c) const;

  // The cover of the leaf holding p; outside for a point outside the region.
  // Throws InvalidGeometry for a NaN or infinite point.
  Cover cover_at(const Point2& p) const;

  // Calls visit(cell) for every inside or boundary leaf meeting the closed window, in
  // depth-first order; stops when it returns false. Throws InvalidGeometry on a bad window.
  template <CellVisitor Visit>
  QueryStats query(const Box2& window, Visit&& visit) const;
  std::vector<QuadCell> query(const Box2& window) const {
    std::vector<QuadCell> out;
    query(window, [&](const QuadCell& c) { return out.push_back(c), true; });
    return out;
  }

  // Calls f(cell) for every leaf, outside ones too, in depth-first order.
  template <class F>
  void visit_cells(F&& f) const {
    walk([&](const QuadCell& c) { return f(c), true; }, [](const Box2&) { return true; });
  }

  // Cell-wise overlay of two trees on the same region and levels: inside where either
  // (unite) or both (intersect) are inside, boundary where a boundary cell is not settled by
  // the other tree's cover. Throws InvalidArgument when the grids differ.
  static RegionQuadtree unite(const RegionQuadtree& a, const RegionQuadtree& b);
  static RegionQuadtree intersect(const RegionQuadtree& a, const RegionQuadtree& b);

  // Throws loci::Error describing the first broken invariant.
  void validate() const;

 private:
  static constexpr std::uint32_t kLeaf = 0xfffffff0u;  // kLeaf + cover

  static bool is_leaf(std::uint32_t w) { return w >= kLeaf; }
  static Cover cover_of(std::uint32_t w) { return Cover(w - kLeaf); }
  static std::uint32_t leaf(Cover c) { return kLeaf + std::uint32_t(c); }
  // Node n's word; a tree without nodes (default-constructed or moved from) is one outside leaf.
  std::uint32_t word(std::uint32_t n) const {
    return nodes_.empty() ? leaf(Cover::outside) : nodes_[n];
  }

  RegionQuadtree(const Box2& region, int levels);

  double grid(int axis, std::uint32_t i) const { return origin_[axis] + double(i) * step_; }
  // cell_box without its checks, for the tree's own cells.
  Box2 block(std::uint32_t x, std::uint32_t y, int level) const {
    const int s = levels_ - level;
    return {{grid(0, x << s), grid(1, y << s)}, {grid(0, (x + 1) << s), grid(1, (y + 1) << s)}};
  }

  // Fills node n, cell (x, y) at level l, then merges four equal leaves into n;
  // classify(x, y, l) gives the cover of a cell.
  template <class Classify>
  void grow(std::uint32_t n, std::uint32_t x, std::uint32_t y, int l, Classify& classify) {
    const Cover c = classify(x, y, l);
    if (c != Cover::boundary || l == levels_) {
      nodes_[n] = leaf(c);
      return;
    }
    if (nodes_.size() > kLeaf - 4) throw InvalidArgument("RegionQuadtree node pool is full");
    const std::uint32_t g = std::uint32_t(nodes_.size());
    nodes_.resize(g + 4, kLeaf);
    nodes_[n] = g;
    for (std::uint32_t k = 0; k < 4; ++k)
      grow(g + k, 2 * x + (k & 1), 2 * y + (k >> 1), l + 1, classify);
    merge_children(n);
  }
  // Turns n into a leaf when its four children are leaves of one non-boundary cover; they are
  // then the last four words of the pool (nothing below them was allocated).
  void merge_children(std::uint32_t n) {
    const std::uint32_t g = nodes_[n];
    const std::uint32_t w = nodes_[g];
    if (!is_leaf(w) || cover_of(w) == Cover::boundary) return;
    for (std::uint32_t k = 1; k < 4; ++k)
      if (nodes_[g + k] != w) return;
    nodes_[n] = w;
    nodes_.resize(g);
  }

  // Depth-first over the leaves whose blocks `descend` accepts; emit(cell) false stops.
  // Returns the number of nodes visited.
  template <class Emit, class Descend>
  std::size_t walk(Emit&& emit, Descend&& descend) const;

  template <class Combine>
  static RegionQuadtree overlay(const RegionQuadtree& a, const RegionQuadtree& b, Combine combine);
  template <class Combine>
  void overlay_at(const RegionQuadtree& a, std::uint32_t na, const RegionQuadtree& b,
                  std::uint32_t nb, std::uint32_t n, Combine& combine);
  // Copies the subtree of `src` at node s into node n of this tree.
  void copy_subtree(const RegionQuadtree& src, std::uint32_t s, std::uint32_t n);

  void swap(RegionQuadtree& other) noexcept {
    std::swap(origin_, other.origin_);
    std::swap(step_, other.step_);
    std::swap(levels_, other.levels_);
    nodes_.swap(other.nodes_);
  }
  Point2 origin_{0, 0};
  double step_ = 1;  // side of a finest cell
  int levels_ = 0;
  std::vector<std::uint32_t> nodes_;  // node 0 is the root; none: a single outside leaf
};

inline RegionQuadtree::RegionQuadtree(const Box2& region, int levels) : levels_(levels) {
  check_box(region, "quadtree region");
  if (levels < 0 || levels > kMaxLevels)
    throw InvalidArgument("quadtree levels must be in [0, " + std::to_string(kMaxLevels) +
                          "], got " + std::to_string(levels));
  const double side = std::max(region.extent(0), region.extent(1));
  if (!(side > 0)) throw InvalidGeometry("quadtree region is empty: " + to_string(region));
  origin_ = region.min;
  step_ = std::ldexp(side, -levels);
  // consecutive grid lines must stay distinct after rounding, everywhere in the region
  const double far = std::max({std::abs(origin_[0]), std::abs(origin_[1]),
                               std::abs(origin_[0] + side), std::abs(origin_[1] + side)});
  const double ulp = std::nextafter(far, std::numeric_limits<double>::infinity()) - far;
  if (!(step_ > 4 * ulp) || !std::isfinite(origin_[0] + side) || !std::isfinite(origin_[1] + side))
    throw InvalidArgument("quadtree region " + to_string(region) + " cannot be cut " +
                          std::to_string(levels) + " times in double precision");
  nodes_.assign(1, leaf(Cover::outside));
}

inline RegionQuadtree RegionQuadtree::from_raster(const Box2& region, int levels,
                                                  std::span<const std::uint8_t> pixels,
                                                  std::size_t width, std::size_t height) {
  RegionQuadtree t(region, levels);
  const std::size_t cells = std::size_t(1) << levels;
  if (width > cells || height > cells)
    throw InvalidArgument("raster of " + std::to_string(width) + " x " + std::to_string(height) +
                          " pixels is larger than the " + std::to_string(cells) + " x " +
                          std::to_string(cells) + " grid");
  if (pixels.size() < width * height)
    throw InvalidArgument("raster has " + std::to_string(pixels.size()) + " pixels, expected " +
                          std::to_string(width * height));
  // summed-area table: the inside pixels of any block in four lookups
  std::vector<std::uint64_t> sum((width + 1) * (height + 1), 0);
  for (std::size_t r = 0; r < height; ++r)
    for (std::size_t c = 0; c < width; ++c)
      sum[(r + 1) * (width + 1) + c + 1] = sum[r * (width + 1) + c + 1] +
                                           sum[(r + 1) * (width + 1) + c] -
                                           sum[r * (width + 1) + c] + (pixels[r * width + c] != 0);
  auto classify_cell = [&](std::uint32_t x, std::uint32_t y, int l) {
    const int s = levels - l;
    const std::size_t c0 = std::size_t(x) << s, r0 = std::size_t(y) << s;
    const std::size_t c1 = std::min(c0 + (std::size_t(1) << s), width);
    const std::size_t r1 = std::min(r0 + (std::size_t(1) << s), height);
    if (c0 >= c1 || r0 >= r1) return Cover::outside;
    const std::uint64_t in = sum[r1 * (width + 1) + c1] - sum[r0 * (width + 1) + c1] -
                             sum[r1 * (width + 1) + c0] + sum[r0 * (width + 1) + c0];
    if (in == 0) return Cover::outside;
    const std::uint64_t all = std::uint64_t(1) << (2 * s);
    return in == all ? Cover::inside : Cover::boundary;
  };
  t.grow(0, 0, 0, 0, classify_cell);
  return t;
}

inline std::size_t RegionQuadtree::count(Cover c) const {
  if (nodes_.empty()) return c == Cover::outside;
  std::size_t n = 0;
  for (std::uint32_t w : nodes_)
    n += w == leaf(c);
  return n;
}

inline double RegionQuadtree::area(Cover c) const {
  double a = 0;
  visit_cells([&](const QuadCell& cell) {
    if (cell.cover == c) a += cell.box.content();
  });
  return a;
}

inline Cover RegionQuadtree::cover_at(const Point2& p) const {
  check_point(p, "query point");
  const Box2 r = region();
  if (!intersects(r, p)) return Cover::outside;
  // finest cell holding p, by comparisons against the grid lines themselves
  std::uint32_t idx[2];
  const std::uint32_t cells = 1u << levels_;
  for (int a = 0; a < 2; ++a) {
    auto i = std::uint32_t(std::clamp((p[a] - origin_[a]) / step_, 0.0, double(cells - 1)));
    while (i > 0 && p[a] < grid(a, i))
      --i;
    while (i + 1 < cells && p[a] >= grid(a, i + 1))
      ++i;
    idx[a] = i;
  }
  std::uint32_t n = 0;
  for (int l = 0; !is_leaf(word(n)); ++l) {
    const int s = levels_ - l - 1;
    n = nodes_[n] + ((idx[0] >> s) & 1) + 2 * ((idx[1] >> s) & 1);
  }
  return cover_of(word(n));
}

template <class Emit, class Descend>
std::size_t RegionQuadtree::walk(Emit&& emit, Descend&& descend) const {
  struct Frame {
    std::uint32_t node, x, y;
    int level;
  };
  detail::Scratch<Frame> scratch;
  auto& stack = *scratch;
  std::size_t visited = 0;
  stack.push_back({0, 0, 0, 0});
  while (!stack.empty()) {
    const Frame f = stack.back();
    stack.pop_back();
    const Box2 box = block(f.x, f.y, f.level);
    if (!descend(box)) continue;
    ++visited;
    const std::uint32_t w = word(f.node);
    if (is_leaf(w)) {
      if (!emit(QuadCell{box, cover_of(w), f.level, f.x, f.y})) break;
      continue;
    }
    for (int k = 3; k >= 0; --k)
      stack.push_back({w + std::uint32_t(k), 2 * f.x + (k & 1), 2 * f.y + (k >> 1), f.level + 1});
  }
  return visited;
}

template <CellVisitor Visit>
QueryStats RegionQuadtree::query(const Box2& window, Visit&& visit) const {
  check_box(window, "query window");
  QueryStats s;
  s.nodes_visited = walk(
      [&](const QuadCell& c) {
        if (c.cover == Cover::outside) return true;
        ++s.results;
        return bool(visit(c));
      },
      [&](const Box2& b) { return ++s.entries_tested, intersects(b, window); });
  return s;
}

inline void RegionQuadtree::copy_subtree(const RegionQuadtree& src, std::uint32_t s,
                                         std::uint32_t n) {
  const std::uint32_t w = src.word(s);
  if (is_leaf(w)) {
    nodes_[n] = w;
    return;
  }
  const std::uint32_t g = std::uint32_t(nodes_.size());
  nodes_.resize(g + 4, kLeaf);
  nodes_[n] = g;
  for (std::uint32_t k = 0; k < 4; ++k)
    copy_subtree(src, w + k, g + k);
}

template <class Combine>
void RegionQuadtree::overlay_at(const RegionQuadtree& a, std::uint32_t na, const RegionQuadtree& b,
                                std::uint32_t nb, std::uint32_t n, Combine& combine) {
  const std::uint32_t wa = a.word(na), wb = b.word(nb);
  if (is_leaf(wa) && is_leaf(wb)) {
    nodes_[n] = leaf(combine(cover_of(wa), cover_of(wb)));
    return;
  }
  // One side is a leaf above the finest level, so not a boundary leaf: its cover either
  // decides the result alone (inside for a union, outside for an intersection) or lets the
  // other side through unchanged (its subtree is copied).
  for (const auto& [leaf_tree, lw, other, on] :
       {std::tuple{&a, wa, &b, nb}, std::tuple{&b, wb, &a, na}}) {
    if (!is_leaf(lw)) continue;
    const Cover c = cover_of(lw);
    if (combine(c, Cover::outside) == combine(c, Cover::inside)) {
      nodes_[n] = leaf(combine(c, Cover::outside));
      return;
    }
    copy_subtree(*other, on, n);
    return;
  }
  const std::uint32_t g = std::uint32_t(nodes_.size());
  nodes_.resize(g + 4, kLeaf);
  nodes_[n] = g;
  for (std::uint32_t k = 0; k < 4; ++k)
    overlay_at(a, wa + k, b, wb + k, g + k, combine);
  merge_children(n);
}

template <class Combine>
RegionQuadtree RegionQuadtree::overlay(const RegionQuadtree& a, const RegionQuadtree& b,
                                       Combine combine) {
  if (a.levels_ != b.levels_ || !(a.origin_ == b.origin_) || a.step_ != b.step_)
    throw InvalidArgument("quadtree overlay needs two trees on the same region and levels");
  RegionQuadtree t = a;
  t.nodes_.assign(1, kLeaf);
  t.overlay_at(a, 0, b, 0, 0, combine);
  return t;
}

inline RegionQuadtree RegionQuadtree::unite(const RegionQuadtree& a, const RegionQuadtree& b) {
  return overlay(a, b, [](Cover x, Cover y) {
    if (x == Cover::inside || y == Cover::inside) return Cover::inside;
    return x == Cover::boundary || y == Cover::boundary ? Cover::boundary : Cover::outside;
  });
}

inline RegionQuadtree RegionQuadtree::intersect(const RegionQuadtree& a, const RegionQuadtree& b) {
  return overlay(a, b, [](Cover x, Cover y) {
    if (x == Cover::outside || y == Cover::outside) return Cover::outside;
    return x == Cover::inside && y == Cover::inside ? Cover::inside : Cover::boundary;
  });
}

inline void RegionQuadtree::validate() const {
  auto fail = [](const std::string& what) { throw Error("RegionQuadtree invalid: " + what); };
  if (nodes_.empty()) return;  // a single outside leaf
  std::vector<bool> seen(nodes_.size(), false);
  std::vector<std::pair<std::uint32_t, int>> stack{{0, 0}};
  seen[0] = true;
  while (!stack.empty()) {
    const auto [n, l] = stack.back();
    stack.pop_back();
    const std::uint32_t w = nodes_[n];
    const std::string at = " at node " + std::to_string(n);
    if (is_leaf(w)) {
      if (w > leaf(Cover::boundary)) fail("unknown cover" + at);
      if (cover_of(w) == Cover::boundary && l != levels_)
        fail("boundary leaf above the finest level" + at);
      continue;
    }
    if (l >= levels_) fail("node below the finest level" + at);
    if (w <= n || w > nodes_.size() - 4) fail("child group out of range" + at);
    bool mergeable = is_leaf(nodes_[w]) && cover_of(nodes_[w]) != Cover::boundary;
    for (std::uint32_t k = 0; k < 4; ++k) {
      if (seen[w + k]) fail("child reachable twice" + at);
      seen[w + k] = true;
      mergeable = mergeable && nodes_[w + k] == nodes_[w];
      stack.push_back({w + k, l + 1});
    }
    if (mergeable) fail("four equal leaves not merged" + at);
  }
  if (std::count(seen.begin(), seen.end(), false)) fail("unreachable nodes in the pool");
}

}  // namespace loci
