// BspTree: a solid-leaf BSP tree over a static polygonal layer, traced by moving objects of
// any size with dynamic plane shifting (Melax, "Dynamic Plane Shifting BSP Traversal",
// Graphics Interface 2000).
//
// What it answers. The layer (for example the land polygons of a map) is solid; a moving
// object (a vessel of some radius, a box) travels in a straight line from `from` to `to`.
// trace() gives the first impact: the fraction t of the move, the reference point there and
// the plane it hit (its normal points out of the solid). slide() continues a blocked move
// along the wall it hit, as navigation does. overlaps() asks whether an object at rest meets
// the solid. One tree serves every object size: nothing is built per radius.
//
// The tree. Built from the polygons' edges, each turned so that the solid lies on its left,
// the solid of a polygon being what the even-odd rule over its rings encloses
// (detail/even_odd_edges.hpp). Each node's plane is the line of one edge
// (an autopartition); its normal points out of the solid ("front", f(x) = n.x - d > 0). The
// splitter is the best of a few candidates by (3 x edges cut + imbalance). Edges are kept as
// pieces [s0, s1] of their original edge, and the side of an edge is decided by the exact
// orientation predicate (geom/predicates.hpp) on the original end points; an end of a piece
// that a line cut is that crossing, whose side is decided exactly too (crossing_orientation),
// so that pieces never drift across a line through rounding (where three lines meet, as they
// do on integer grids, rounded fractions left slivers across). Collinear edges facing the
// same way lie on the node's plane and are done; collinear edges facing the other way (a
// border shared by two polygons) go to the front side. A side left without edges is a leaf,
// solid or empty as a whole since no boundary crosses it. Behind the splitter it is solid
// (the splitter's own polygon covers it). In front it is empty unless another polygon covers
// it, which happens where polygons overlap (neighbouring countries in real data do, by
// rounding). A cell with room is decided at a point well inside it, located by crossing
// parity against all the polygons (edges bucketed in bands of y). A thinner one is decided
// from the splitter's piece, located against the other polygons just in front of the line at
// the real point just past the piece's start (its crossing with the line that cut it there,
// or the edge's end), exactly: no rounded point, which may fall on the wrong side of the
// nearly collinear edges that bound a thin cell, and no point inside the piece, which may be
// too short to hold a double. A polygon with an edge along the line there (told by the edge's
// end points) covers the front when that edge faces the other way (a border of three edges or
// more, of a duplicated polygon or an island filling a hole, of which the edges that cancel
// pair off). Deciding from the piece keeps thin cells right; a front cell of no area (the
// splitter on its own border) is empty. Polygons may overlap and share borders. A ring's
// orientation is the sign of its area or, for a sliver whose rounded area may have the wrong
// sign, the exact turn at its lowest leftmost vertex.
//
// Cells. The cell of a node, the root box clipped by the planes on its path, is a convex
// polygon whose corners are crossings of the edges' lines (and the box's sides); which
// corners lie on which side of a splitter is decided exactly (crossing_orientation on the
// lines' end points, filtered by the corner rounded), and each new corner is the crossing of
// two lines computed afresh to within 2e-15 of the magnitudes (in rationals where floating
// point cannot promise that). Rounding therefore never loses a cell nor moves its corners
// along its sides: where two nearly opposite lines meet (edges of two polygons along one line
// through a shared vertex, parted by rounding), the solid cell between them, a spike an ulp
// wide, keeps its tip, which is bevelled as any corner (its turn, near pi, taken as the
// convex cell's turn whatever the sign the rounded normals give).
//
// Plane shifting. An object occupies x + K (K a convex shape around its reference point x).
// It meets a convex solid cell C exactly when x lies in C + (-K), which is contained in the
// cell whose every plane is moved outward by the support of -K in the plane's normal:
// h_K(-n) for a cell behind the plane, h_K(n) for one in front (a circle of radius r: r; a
// box of half-extents e: |n.x| e.x + |n.y| e.y). The traversal therefore sends to the back
// subtree the part of the segment where f <= h_K(-n) and to the front subtree the part where
// f >= -h_K(n): the two parts overlap, both are followed (nearest first, the far one cut at
// the best impact so far), and any part that reaches a solid leaf is an impact at its start.
// The node whose plane raised that start is the plane of impact. Cost per trace: O(depth)
// for a point, more nodes as the object grows (the paper's figure 6).
//
// Bevels and the error they leave. Shifting the planes of a cell moves its corners further
// than the object reaches: at a corner where the outward normals turn by an angle theta, the
// shifted corner sits at r / cos(theta / 2) from the original one instead of r, and thin
// wedge-shaped cells, which a BSP creates wherever a splitting line cuts the solid at a
// shallow angle, protrude far. As the paper does, solid leaves are bevelled at build time:
// the cell polygon is known (the root box clipped by the planes on the path), and at every
// corner whose normals turn by more than `bevel_angle` extra planes through the corner, with
// normals spread evenly across the turn, are inserted as nodes below the leaf (empty in
// front, solid behind). The cell does not change; its shifted copy loses its spikes. With all
// turns at most alpha, the shifted cell lies within distance R / cos(alpha / 2) of the cell,
// R the largest support of K. Hence the guarantee, for every move:
//   - no impact is missed: the reported t is never later than the exact first contact of K
//     (the union of the shifted cells contains the Minkowski sum of solid and -K);
//   - no impact is invented beyond the bevel error: the reported t is never earlier than the
//     exact first contact of a disc of radius R / cos(alpha / 2).
// With the default alpha = 30 degrees that disc is 3.5% larger than R (for a circle, than
// its radius); the paper's games used 90-95 degrees (41% and more). Arithmetic is double
// precision: the times carry the rounding of a few operations on the coordinates, and every
// cell is grown by 1e-14 of the magnitudes involved (the query's and the layer's), so that a
// point of the boundary (a vertex, a point of a slanted edge, whose planes are rounded)
// touches, as it does exactly.
//
// Layout: nodes in one flat array (plane and two children, 32 bytes), children encoded as
// node indices or the two leaf codes. Built once, immutable: all queries are const and may
// run concurrently.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <span>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "loci/geom/box.hpp"
#include "loci/geom/error.hpp"
#include "loci/geom/point.hpp"
#include "loci/geom/predicates.hpp"
#include "loci/geom/segment.hpp"
#include "loci/geom/segment_intersection.hpp"
#include "loci/index/detail/even_odd_edges.hpp"
#include "loci/index/detail/scratch.hpp"
#include "loci/index/detail/y_bands.hpp"
#include "loci/index/query.hpp"

namespace loci {

// A polygon of the solid layer: the outer ring and its holes, each ring a closed chain of
// vertices in either orientation (the first vertex may or may not be repeated at the end).
struct BspPolygon {
  std::vector<Point2> outer;
  std::vector<std::vector<Point2>> holes;
};

struct BspParams {
  // Largest turn, in radians, between the outward normals of neighbouring faces of a solid
  // cell after bevelling; in (0, pi]. Smaller is more exact and grows the tree.
  double bevel_angle = std::numbers::pi / 6;
  // Splitters scored at each node (more: a smaller, better balanced tree, a slower build).
  std::uint32_t candidates = 8;
};

// Shapes traced through the tree: the support function h(n) = max over the shape of n.v,
// v relative to the shape's reference point.
template <class S>
concept BspShape = requires(const S& s, const Point2& n) {
  { s.support(n) } -> std::convertible_to<double>;
};

// A point (a ray or line of sight).
struct BspPoint {
  double support(const Point2&) const { return 0; }
};
// A circle of radius r centred on the reference point.
struct BspCircle {
  double r;
  double support(const Point2&) const { return r; }
};
// An axis-aligned box of half-extents `half` centred on the reference point.
struct BspBox {
  Point2 half;
  double support(const Point2& n) const {
    return std::fabs(n[0]) * half[0] + std::fabs(n[1]) * half[1];
  }
};
// A convex polygon given by its vertices relative to the reference point.
struct BspConvex {
  std::vector<Point2> vertices;
  double support(const Point2& n) const {
    double h = -std::numeric_limits<double>::infinity();
    for (const Point2& v : vertices)
      h = std::max(h, n[0] * v[0] + n[1] * v[1]);
    return h;
  }
};

// The first impact of a move.
struct BspHit {
  bool hit = false;
  double t = 1;                 // fraction of the move at impact (1 when none)
  Point2 point{};               // reference point at impact (the end of the move when none)
  Point2 normal{};              // plane of impact, pointing out of the solid; 0 if inside
  bool started_inside = false;  // the object met the solid where it started
};

// Where a move continued along the walls it met ends.
struct BspSlide {
  Point2 position{};   // final reference point
  int contacts = 0;    // walls met (each one turned the rest of the move along it)
  bool stuck = false;  // the move could not continue (a corner, or started inside)
};

class BspTree {
 public:
  static constexpr std::int32_t kEmpty = -1;
  static constexpr std::int32_t kSolid = -2;

  BspTree() = default;
  BspTree(const BspTree&) = default;
  BspTree& operator=(const BspTree&) = default;
  // Moving leaves `other` empty, as if default-constructed.
  BspTree(BspTree&& other) noexcept : BspTree() { swap(other); }
  BspTree& operator=(BspTree&& other) noexcept {
    BspTree(std::move(other)).swap(*this);
    return *this;
  }

  // The tree of the union of `polygons`. Throws InvalidGeometry on a coordinate that is NaN,
  // infinite or beyond kMaxCoordinate (1e150: the root cell's margin and the exact tests'
  // areas stay finite), a ring with fewer than three distinct vertices or no area, or a
  // polygon two of whose edges cross or run along each other (rings may touch at points;
  // detail/even_odd_edges.hpp), InvalidArgument on bad parameters. A polygon is what the
  // even-odd rule over its rings encloses; polygons may overlap one another.
  static BspTree build(std::span<const BspPolygon> polygons, const BspParams& params = {});

  // First impact of `shape` moving from `from` to `to` (straight, at constant speed). Throws
  // InvalidGeometry for an end or a shape's vertex or extent that is NaN, infinite or beyond
  // kMaxCoordinate (the move's length then stays finite).
  template <BspShape S>
  BspHit trace(const Point2& from, const Point2& to, const S& shape,
               QueryStats* stats = nullptr) const {
    check_point(from, "trace start");
    check_point(to, "trace end");
    check_shape(shape);
    BspHit out;
    out.point = to;
    if (root_ == kEmpty) return out;
    const Point2 delta{to[0] - from[0], to[1] - from[1]};
    // Planes carry rounding (unit normals, bevels through computed corners): every cell is
    // grown by 1e-14 of the magnitudes involved (the move's, the plane's offset and the
    // layer's coordinates, whose rounding moves a plane near the origin too), so that a point
    // on the boundary (a vertex, a point of a slanted edge) counts as touching, as it does
    // exactly.
    const double scale = reach_ + std::max({std::fabs(from[0]), std::fabs(from[1]),
                                            std::fabs(to[0]), std::fabs(to[1])});
    double best = std::numeric_limits<double>::infinity();
    Point2 best_normal{};
    bool best_plane = false;
    using Item = TraceItem;
    detail::Scratch<Item> lease;
    std::vector<Item>& stack = *lease;
    stack.push_back({root_, 0.0, 1.0, {}, false});
    QueryStats local;
    while (!stack.empty()) {
      const Item it = stack.back();
      stack.pop_back();
      if (!(it.t0 < best)) continue;
      if (it.node == kEmpty) continue;
      if (it.node == kSolid) {
        best = it.t0;
        best_normal = it.normal;
        best_plane = it.has_plane;
        continue;
      }
      ++local.nodes_visited;
      const Node& n = nodes_[static_cast<std::size_t>(it.node)];
      const Point2 nn{n.nx, n.ny};
      const double f0 = n.nx * from[0] + n.ny * from[1] - n.d;
      const double fd = n.nx * delta[0] + n.ny * delta[1];
      const double slack = 1e-14 * (scale + std::fabs(n.d));
      const double up = shape.support(Point2{-n.nx, -n.ny}) + slack;  // back cells grow by this
      const double down = shape.support(nn) + slack;                  // front cells grow by this
      // Back part: f0 + t fd <= up; front part: f0 + t fd >= -down.
      Item back{n.back, it.t0, it.t1, it.normal, it.has_plane};
      Item front{n.front, it.t0, it.t1, it.normal, it.has_plane};
      clip(f0 - up, fd, back, nn, true);
      clip(f0 + down, fd, front, Point2{-n.nx, -n.ny}, false);
      const bool back_ok = back.t0 <= back.t1 && back.t0 < best;
      const bool front_ok = front.t0 <= front.t1 && front.t0 < best;
      // Nearest first: pushed last.
      if (back_ok && front_ok) {
        if (back.t0 <= front.t0) {
          stack.push_back(front);
          stack.push_back(back);
        } else {
          stack.push_back(back);
          stack.push_back(front);
        }
      } else if (back_ok) {
        stack.push_back(back);
      } else if (front_ok) {
        stack.push_back(front);
      }
    }
    if (stats) *stats += local;
    if (best <= 1) {
      out.hit = true;
      out.t = best;
      out.point = Point2{from[0] + best * delta[0], from[1] + best * delta[1]};
      out.started_inside = !best_plane;
      out.normal = best_plane ? best_normal : Point2{};
      if (stats) ++stats->results;
    }
    return out;
  }

  // Whether `shape` placed at `at` meets the solid (touching counts).
  template <BspShape S>
  bool overlaps(const Point2& at, const S& shape) const {
    return trace(at, at, shape).hit;
  }

  // Whether p lies in the solid (its boundary included).
  bool solid(const Point2& p) const { return overlaps(p, BspPoint{}); }

  // The move from `from` to `to`, continued along each wall met: at an impact the object
  // stops just short of it (by `gap`, a small length; by default a 1e-9 relative share of the
  // coordinates) and the rest of the move, less its part into the wall, goes on from there.
  // At most `max_contacts` walls are followed; a move that starts inside the solid, or
  // whose rest runs into a corner, stops (stuck).
  template <BspShape S>
  BspSlide slide(const Point2& from, const Point2& to, const S& shape, int max_contacts = 4,
                 double gap = -1) const {
    BspSlide out;
    Point2 pos = from;
    Point2 rest{to[0] - from[0], to[1] - from[1]};
    for (int i = 0;; ++i) {
      const Point2 end{pos[0] + rest[0], pos[1] + rest[1]};
      const BspHit h = trace(pos, end, shape);
      if (!h.hit) {
        pos = end;
        break;
      }
      if (h.started_inside || i == max_contacts) {
        out.stuck = true;
        break;
      }
      ++out.contacts;
      const double len = std::hypot(rest[0], rest[1]);
      const double g = gap >= 0 ? gap
                                : 1e-9 * std::max({1.0, std::fabs(pos[0]), std::fabs(pos[1]),
                                                   std::fabs(end[0]), std::fabs(end[1])});
      // Back along the move (outside the shifted solid, which it entered at h.t).
      const double tb = std::max(0.0, h.t - g / len);
      pos = Point2{pos[0] + tb * rest[0], pos[1] + tb * rest[1]};
      Point2 r{rest[0] * (1 - tb), rest[1] * (1 - tb)};
      const double into = r[0] * h.normal[0] + r[1] * h.normal[1];
      if (into < 0) r = Point2{r[0] - into * h.normal[0], r[1] - into * h.normal[1]};
      rest = r;
      if (rest[0] == 0 && rest[1] == 0) break;
    }
    out.position = pos;
    return out;
  }

  bool empty() const { return root_ == kEmpty; }
  // Edges of the layer (after dropping repeated vertices).
  std::size_t edges() const { return edges_; }
  // Nodes, bevel nodes included.
  std::size_t node_count() const { return nodes_.size(); }
  std::size_t bevel_count() const { return bevels_; }
  std::size_t solid_leaves() const { return solid_leaves_; }
  std::size_t depth() const { return depth_; }
  std::size_t memory_bytes() const { return nodes_.capacity() * sizeof(Node); }

  // Throws loci::Error naming the first broken invariant: children in range, every node
  // reached once from the root, unit normals and finite planes, bevel nodes with an empty
  // front.
  void validate() const;

 private:
  struct Node {
    double nx, ny, d;    // plane n.x = d, n unit, pointing out of the solid (24 bytes)
    std::int32_t back;   // child behind the plane (node index or kEmpty / kSolid)
    std::int32_t front;  // child in front
  };

  // A part [t0, t1] of the move on its way down to `node`.
  struct TraceItem {
    std::int32_t node;
    double t0, t1;
    Point2 normal;   // the plane that raised t0 (when has_plane)
    bool has_plane;  // false: t0 is the start of the move
  };

  // Cuts item's [t0, t1] to where g + t fd <= 0 (keep_below) or >= 0, recording `normal` as
  // the plane of entry when the start rises.
  static void clip(double g, double fd, TraceItem& item, const Point2& normal, bool keep_below) {
    const double s = keep_below ? 1.0 : -1.0;
    const double a = s * g, b = s * fd;  // keep where a + t b <= 0
    if (b == 0) {
      if (a > 0) item.t1 = -1, item.t0 = 2;
      return;
    }
    const double tc = -a / b;
    if (b > 0) {
      item.t1 = std::min(item.t1, tc);
    } else if (tc > item.t0) {
      item.t0 = tc;
      item.normal = normal;
      item.has_plane = true;
    }
  }

  // A shape's extent along each axis (its support one way plus the other) must be a finite
  // number >= 0: a NaN or negative radius or half-extent, or a polygon without vertices, is
  // refused rather than traced as a point or a hole.
  template <class S>
  static void check_shape(const S& shape) {
    if constexpr (requires { shape.vertices; })
      for (const Point2& v : shape.vertices)
        check_point(v, "traced polygon's vertex");
    for (const Point2& n : {Point2{1, 0}, Point2{0, 1}}) {
      const double a = shape.support(n), b = shape.support(Point2{-n[0], -n[1]});
      if (!std::isfinite(a) || !std::isfinite(b) || !(a + b >= 0))
        throw InvalidGeometry("traced shape has a NaN, infinite or negative extent");
      if (!(std::abs(a) <= kMaxCoordinate && std::abs(b) <= kMaxCoordinate))
        throw InvalidGeometry("traced shape reaches beyond 1e150");
    }
  }
  static void check_point(const Point2& p, const char* what) {
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]))
      throw InvalidGeometry(std::string(what) + " has a non-finite coordinate");
    if (!within_coordinate_range(p))
      throw InvalidGeometry(std::string(what) + " has a coordinate beyond 1e150");
  }

  void swap(BspTree& other) noexcept {
    nodes_.swap(other.nodes_);
    std::swap(root_, other.root_);
    std::swap(edges_, other.edges_);
    std::swap(bevels_, other.bevels_);
    std::swap(solid_leaves_, other.solid_leaves_);
    std::swap(depth_, other.depth_);
    std::swap(reach_, other.reach_);
  }
  std::vector<Node> nodes_;
  std::int32_t root_ = kEmpty;
  std::size_t edges_ = 0;
  std::size_t bevels_ = 0;
  std::size_t solid_leaves_ = 0;
  std::size_t depth_ = 0;
  double reach_ = 0;  // the largest magnitude of the layer's coordinates
};

namespace detail {

// An edge of the layer, oriented with the solid on its left, and the plane of its line.
struct BspEdge {
  Point2 a, b;
  double nx, ny, d;  // unit normal to the right (out of the solid), n.a = d
  std::uint32_t polygon;
};

// The crossing of the line through s0, s1 with the line through l0, l1 (not parallel), with a
// bound on its distance from the exact crossing: a shared end point exactly, else in floating
// point, within 2e-15 of the magnitudes (the orientations that place it along a line are
// evaluated in double-double, so that nearly parallel lines do not lose it), else, for lines
// parallel to some 1e-16, in rationals and rounded.
inline std::pair<Point2, double> bsp_crossing(const Point2& s0, const Point2& s1, const Point2& l0,
                                              const Point2& l1) {
  if (s0 == l0 || s0 == l1) return {s0, 0.0};
  if (s1 == l0 || s1 == l1) return {s1, 0.0};
  constexpr double eps = 0x1p-53;
  // The orientation of x against u-w as hi + lo, off by at most 1e-30 m (m = |left| +
  // |right|): the differences split exactly, the main products' rounding recovered by fma.
  struct Det {
    double hi, lo, m;
  };
  const auto det = [&](const Point2& u, const Point2& w, const Point2& x) {
    const Pair dx = two_diff(w[0], u[0]), dy = two_diff(w[1], u[1]);
    const Pair ex = two_diff(x[0], u[0]), ey = two_diff(x[1], u[1]);
    const double left = dx.hi * ey.hi, right = dy.hi * ex.hi;
    const double left_lo =
        std::fma(dx.hi, ey.hi, -left) + (dx.hi * ey.lo + dx.lo * ey.hi + dx.lo * ey.lo);
    const double right_lo =
        std::fma(dy.hi, ex.hi, -right) + (dy.hi * ex.lo + dy.lo * ex.hi + dy.lo * ex.lo);
    const Pair d = two_sum(left, -right);
    return Det{d.hi, d.lo + (left_lo - right_lo), std::fabs(left) + std::fabs(right)};
  };
  const double mag =
      std::max({std::fabs(s0[0]), std::fabs(s0[1]), std::fabs(s1[0]), std::fabs(s1[1]),
                std::fabs(l0[0]), std::fabs(l0[1]), std::fabs(l1[0]), std::fabs(l1[1])});
  // x = a + u (b - a), u = oa / (oa - ob) for oa, ob the orientations of a, b against c-d;
  // with the bound on the distance from the real crossing (infinite when oa - ob is not sure
  // to be far from 0).
  const auto along = [&](const Point2& a, const Point2& b, const Point2& c, const Point2& d) {
    const Det oa = det(c, d, a), ob = det(c, d, b);
    const Pair dh = two_sum(oa.hi, -ob.hi);
    const double dlo = dh.lo + (oa.lo - ob.lo);
    const double den = dh.hi + dlo, num = oa.hi + oa.lo;
    const double eden = 1e-30 * (oa.m + ob.m) +
                        2 * eps * (std::fabs(oa.lo) + std::fabs(ob.lo) + std::fabs(dh.lo)) +
                        eps * std::fabs(den);
    if (!(std::fabs(den) > 2 * eden))
      return std::pair{Point2{}, std::numeric_limits<double>::infinity()};
    const double u = num / den;
    const double enum_ = 1e-30 * oa.m + eps * std::fabs(num);
    const double du = (enum_ + std::fabs(u) * eden) / (std::fabs(den) - eden) + eps * std::fabs(u);
    const Point2 e{b[0] - a[0], b[1] - a[1]};
    const Point2 x{a[0] + u * e[0], a[1] + u * e[1]};
    const double len = std::fabs(e[0]) + std::fabs(e[1]);
    return std::pair{x, 1.01 * (du * len + 3 * eps * std::fabs(u) * len +
                                eps * (std::fabs(x[0]) + std::fabs(x[1])))};
  };
  const auto good = [&](const std::pair<Point2, double>& r) {
    return r.second <= 2e-15 * std::max({mag, std::fabs(r.first[0]), std::fabs(r.first[1])});
  };
  // (Below 1e-100 the products of differences may lose digits to underflow.)
  if (mag > 1e-100) {
    if (auto r = along(s0, s1, l0, l1); good(r)) return r;
    if (auto r = along(l0, l1, s0, s1); good(r)) return r;
  }
  const Point2 x = crossing_point(Segment<2>{s0, s1}, Segment<2>{l0, l1});
  return {x, 1.01 * eps * (std::fabs(x[0]) + std::fabs(x[1]))};
}

// The point of a piece of an edge l just past its start (the edge's end a, or the edge's
// crossing with the line of edge m), towards b: the tests below are those on the real point
// start + e (b - a) for e > 0 small enough, exact. The start, a double or a crossing, is
// tested exactly (filtered by its rounding x, within err of it); where it lies on the line or
// the coordinate tested, the direction of the edge decides.
struct BspPieceStart {
  const BspEdge& l;
  const BspEdge* m;  // null: the start is l.a
  Point2 x;
  double err;

  BspPieceStart(const BspEdge& edge, const BspEdge* cut) : l(edge), m(cut), x(edge.a), err(0) {
    if (m) std::tie(x, err) = bsp_crossing(l.a, l.b, m->a, m->b);
  }
  // The sign of orientation(p, q, point).
  int orient(const Point2& p, const Point2& q) const {
    const double dx = q[0] - p[0], dy = q[1] - p[1];
    const double left = dx * (x[1] - p[1]), right = dy * (x[0] - p[0]);
    const double det = left - right;
    const double bound = 3.3306690738754716e-16 * (std::fabs(left) + std::fabs(right)) +
                         1.01 * err * (std::fabs(dx) + std::fabs(dy));
    if (det > bound) return 1;
    if (-det > bound) return -1;
    const int s =
        sign(m ? crossing_orientation(l.a, l.b, m->a, m->b, p, q) : orientation(p, q, l.a));
    // On the line p-q, which l crosses there (or runs along: 0): towards b.
    return s != 0 ? s : sign(orientation(p, q, l.b));
  }
  // The sign of the point's coordinate on `axis` minus v.
  int coord(int axis, double v) const {
    if (x[axis] - v > err) return 1;
    if (v - x[axis] > err) return -1;
    int s = 0;
    if (!m)
      s = (l.a[axis] > v) - (l.a[axis] < v);
    else if (axis == 1)  // against the line y = v
      s = sign(crossing_orientation(l.a, l.b, m->a, m->b, Point2{0, v}, Point2{1, v}));
    else  // against the line x = v, upwards: left of it is x < v
      s = -sign(crossing_orientation(l.a, l.b, m->a, m->b, Point2{v, 0}, Point2{v, 1}));
    return s != 0 ? s : (l.b[axis] > l.a[axis]) - (l.b[axis] < l.a[axis]);
  }
};

// Whether a point of a splitter's line lies, just in front of that line, inside any of the
// polygons but the splitter's: by crossing parity of the ray towards +x against each polygon's
// edges (half-open in y), the edges bucketed in horizontal bands. The point is the real point
// of a piece of the splitter's edge just past its start (BspPieceStart), not a point rounded,
// which may lie on the wrong side of other geometry passing within rounding of it (across a
// thin cell between two nearly collinear edges), nor the middle of a piece too short to hold
// a double; each test is exact. A polygon with the point inside one of its edges that lies on
// the splitter's line covers the front there when that edge faces the other way (a shared
// border whose edges did not all cancel: a duplicated polygon, an island filling a hole), and
// not when it faces the same way; such an edge is told by its end points, exactly, and the
// point's place along the line.
class BspPointLocator {
 public:
  BspPointLocator(const std::vector<BspEdge>& edges, std::uint32_t polygons, const Box2& bounds)
      : edges_(edges),
        parity_(polygons, 0),
        bands_(
            edges.size(),
            [&](std::size_t i) {
              return std::pair{std::min(edges[i].a[1], edges[i].b[1]),
                               std::max(edges[i].a[1], edges[i].b[1])};
            },
            bounds.min[1], bounds.max[1], std::clamp<std::size_t>(edges.size() / 8, 1, 1 << 14)) {}

  enum class Cover { no, yes, undecided };
  // The splitter's front is to the right of a -> b.
  Cover inside_other(const BspEdge& splitter, const BspPieceStart& at) {
    const std::uint32_t except = splitter.polygon;
    bool any = false;
    touched_.clear();
    auto touch = [&](std::uint32_t q) {
      if (!parity_[q]) touched_.push_back(q);
    };
    // The sign of v minus the point's coordinate on `axis`.
    const auto above = [&](int axis, double v) { return -at.coord(axis, v); };
    // Along the splitter's line, whether a direction runs the splitter's way (its dominant
    // axis: exact signs of differences).
    const bool along_x =
        std::abs(splitter.b[0] - splitter.a[0]) >= std::abs(splitter.b[1] - splitter.a[1]);
    const auto forward = [&](const Point2& from, const Point2& to) {
      return along_x ? (to[0] > from[0]) == (splitter.b[0] > splitter.a[0])
                     : (to[1] > from[1]) == (splitter.b[1] > splitter.a[1]);
    };
    // Where the point lies along the splitter's line (its coordinate on the dominant axis).
    const int axis = along_x ? 0 : 1;
    // The edges whose range in y may hold the point's y (once each).
    const double y0 = at.x[1] - at.err, y1 = at.x[1] + at.err;
    std::span<const std::uint32_t> near = bands_.at(y0, y1);
    if (bands_.band_of(y0) != bands_.band_of(y1)) {
      near_.assign(near.begin(), near.end());
      std::sort(near_.begin(), near_.end());
      near_.erase(std::unique(near_.begin(), near_.end()), near_.end());
      near = near_;
    }
    for (const std::uint32_t k : near) {
      const BspEdge& e = edges_[k];
      if (e.polygon == except) continue;
      const Point2& lo = e.a[1] < e.b[1] ? e.a : e.b;
      const Point2& hi = e.a[1] < e.b[1] ? e.b : e.a;
      const int ylo = above(1, lo[1]), yhi = above(1, hi[1]);
      if (ylo > 0 || yhi < 0) continue;
      // An edge on the splitter's line is told by its end points, exactly, and the point's
      // place along it. Just in front of the line it is never crossed.
      if (orientation(splitter.a, splitter.b, e.a) == Orientation::collinear &&
          orientation(splitter.a, splitter.b, e.b) == Orientation::collinear) {
        const int ua = above(axis, e.a[axis]), ub = above(axis, e.b[axis]);
        if ((ua > 0 && ub > 0) || (ua < 0 && ub < 0)) continue;
        touch(e.polygon);
        parity_[e.polygon] |= 2;  // on its boundary
        // Inside the edge, facing the other way: the polygon (on the edge's left) lies in
        // front of the splitter there.
        if (ua != 0 && ub != 0) parity_[e.polygon] |= forward(e.a, e.b) ? 16 : 8;
        continue;
      }
      const int o = at.orient(lo, hi);
      if (o == 0) {
        if (above(0, std::min(lo[0], hi[0])) <= 0 && above(0, std::max(lo[0], hi[0])) >= 0) {
          touch(e.polygon);
          parity_[e.polygon] |= 2;  // on its boundary
        }
        continue;
      }
      if (yhi == 0 || o < 0) continue;
      touch(e.polygon);
      parity_[e.polygon] ^= 1;
      parity_[e.polygon] |= 4;  // touched
    }
    bool undecided = false;
    for (const std::uint32_t q : touched_) {
      const std::uint8_t f = parity_[q];
      any = any || f == 5 || (f & 8) != 0;
      undecided = undecided || ((f & 2) != 0 && (f & 24) == 0);
      parity_[q] = 0;
    }
    return any ? Cover::yes : undecided ? Cover::undecided : Cover::no;
  }

  // Whether p lies inside any of the polygons, by crossing parity against all their edges;
  // undecided when p lies on one.
  Cover inside_any(const Point2& p) {
    bool on = false, any = false;
    touched_.clear();
    for (const std::uint32_t k : bands_.at(p[1])) {
      const BspEdge& e = edges_[k];
      const Point2& lo = e.a[1] < e.b[1] ? e.a : e.b;
      const Point2& hi = e.a[1] < e.b[1] ? e.b : e.a;
      if (p[1] < lo[1] || p[1] > hi[1]) continue;
      const Orientation o = orientation(lo, hi, p);
      if (o == Orientation::collinear) {
        on = on || (std::min(lo[0], hi[0]) <= p[0] && p[0] <= std::max(lo[0], hi[0]));
        continue;
      }
      if (p[1] == hi[1] || o != Orientation::counterclockwise) continue;
      if (!parity_[e.polygon]) touched_.push_back(e.polygon);
      parity_[e.polygon] = (parity_[e.polygon] ^ 1) | 4;
    }
    for (const std::uint32_t q : touched_) {
      any = any || parity_[q] == 5;
      parity_[q] = 0;
    }
    return on ? Cover::undecided : any ? Cover::yes : Cover::no;
  }

 private:
  const std::vector<BspEdge>& edges_;
  std::vector<std::uint8_t> parity_;
  std::vector<std::uint32_t> touched_, near_;
  YBands bands_;
};
// A piece [s0, s1] of an edge (points a + s (b - a)), what is left of it inside a cell. Each
// end is the edge's own end point or the edge's crossing with the line of edge c0 (c1), which
// cut it: s0 and s1 are rounded, the ends are known exactly.
struct BspPiece {
  static constexpr std::uint32_t kOwnEnd = ~std::uint32_t{0};
  std::uint32_t edge;
  double s0, s1;
  std::uint32_t c0 = kOwnEnd, c1 = kOwnEnd;
};
// The lines that bound cells, each through two exact points: those of the edges (by index),
// then the four sides of the root box (counter-clockwise from its lower side).
struct BspLines {
  const std::vector<BspEdge>& edges;
  std::array<Point2, 4> corner;  // the root box's, counter-clockwise from its lower left
  bool box(std::uint32_t i) const { return i >= edges.size(); }
  const Point2& a(std::uint32_t i) const { return box(i) ? corner[i - edges.size()] : edges[i].a; }
  const Point2& b(std::uint32_t i) const {
    return box(i) ? corner[(i - edges.size() + 1) % 4] : edges[i].b;
  }
};

// A vertex of a convex cell (counter-clockwise) and the cell's side from it to the next
// vertex. The vertex is the crossing of the line of the side before it with that of its side
// (BspLines); p is that crossing rounded, within err of it (0: exact).
struct BspCellVertex {
  Point2 p;
  double err;
  Point2 n;            // the side's outward normal (its plane's)
  std::uint32_t in;    // the line of the side before the vertex
  std::uint32_t side;  // the line of the side from it
};

// The side of the line of edge li a cell vertex lies on: +1 in front (n.p > d), -1 behind, 0
// on it, decided exactly. The rounded plane decides unless the vertex lies within its rounding
// (the plane's, some 1e-15 of the magnitudes, and the vertex's err) of it.
inline int bsp_vertex_side(const BspCellVertex& v, const BspLines& lines, std::uint32_t li) {
  const BspEdge& l = lines.edges[li];
  const double f = l.nx * v.p[0] + l.ny * v.p[1] - l.d;
  const double bound = v.err + 1e-14 * (std::fabs(v.p[0]) + std::fabs(v.p[1]) + std::fabs(l.a[0]) +
                                        std::fabs(l.a[1]));
  if (f > bound) return 1;
  if (f < -bound) return -1;
  // Front is to the right of a -> b.
  if (v.err == 0) return -sign(orientation(l.a, l.b, v.p));
  return -sign(detail::crossing_orientation_exact(lines.a(v.in), lines.b(v.in), lines.a(v.side),
                                                  lines.b(v.side), l.a, l.b));
}

inline double bsp_signed_area(const std::vector<Point2>& r) {
  double a = 0;
  for (std::size_t i = 0, n = r.size(); i < n; ++i) {
    const Point2& p = r[i];
    const Point2& q = r[(i + 1) % n];
    a += p[0] * q[1] - q[0] * p[1];
  }
  return a / 2;
}

// The ring without repeated vertices, counter-clockwise when `ccw`, else clockwise.
inline std::vector<Point2> bsp_ring(const std::vector<Point2>& in, bool ccw,
                                    const std::string& what) {
  std::vector<Point2> r;
  r.reserve(in.size());
  for (const Point2& p : in) {
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]))
      throw InvalidGeometry(what + " has a non-finite coordinate");
    if (!within_coordinate_range(p)) throw InvalidGeometry(what + " has a coordinate beyond 1e150");
    if (r.empty() || !(r.back() == p)) r.push_back(p);
  }
  while (r.size() > 1 && r.front() == r.back())
    r.pop_back();
  if (r.size() < 3) throw InvalidGeometry(what + " has fewer than three distinct vertices");
  const double area = bsp_signed_area(r);
  if (std::isnan(area)) throw InvalidGeometry(what + " has no area");
  // The sign of the rounded area, unless rounding may have decided it (a sliver, such as three
  // nearly collinear points, whose area may even round to 0): then the turn at the lowest of
  // the leftmost vertices, exactly; a ring with neither has no area.
  double mag = 0;
  for (std::size_t i = 0, n = r.size(); i < n; ++i) {
    const Point2& p = r[i];
    const Point2& q = r[(i + 1) % n];
    mag += std::fabs(p[0] * q[1]) + std::fabs(q[0] * p[1]);
  }
  bool counterclockwise = area > 0;
  if (std::fabs(area) <= static_cast<double>(r.size() + 2) * 1.2e-16 * mag) {
    const auto low = static_cast<std::size_t>(
        std::min_element(r.begin(), r.end(),
                         [](const Point2& p, const Point2& q) {
                           return p[0] < q[0] || (p[0] == q[0] && p[1] < q[1]);
                         }) -
        r.begin());
    const int turn =
        sign(orientation(r[(low + r.size() - 1) % r.size()], r[low], r[(low + 1) % r.size()]));
    if (turn != 0)
      counterclockwise = turn > 0;
    else if (area == 0)
      throw InvalidGeometry(what + " has no area");
  }
  if (counterclockwise != ccw) std::reverse(r.begin(), r.end());
  return r;
}

// The part of a convex cell behind the line of edge l (s = 1) or in front of it (s = -1), its
// new side on that line facing s n. Which vertices lie on which side is decided exactly
// (bsp_vertex_side), so that nearly opposite lines (the edges of a thin spike meeting at a
// vertex) leave the cell they bound, however thin, rather than rounding it away or moving its
// corners along the lines; each new corner is the crossing of a side's line with l, computed
// to within 2e-15 of the magnitudes (bsp_crossing), not from corners computed before.
inline std::vector<BspCellVertex> bsp_clip_cell(const std::vector<BspCellVertex>& cell,
                                                const BspLines& lines, std::uint32_t li, int s) {
  std::vector<BspCellVertex> out;
  const std::size_t m = cell.size();
  if (m == 0) return out;
  out.reserve(m + 1);
  const BspEdge& l = lines.edges[li];
  const Point2 side{s * l.nx, s * l.ny};
  // The side of each vertex (s times bsp_vertex_side: > 0 clipped away), of P and of Q.
  const int first = s * bsp_vertex_side(cell[0], lines, li);
  int wq = first;
  for (std::size_t i = 0; i < m; ++i) {
    const BspCellVertex& P = cell[i];
    const int wp = wq;
    wq = i + 1 < m ? s * bsp_vertex_side(cell[i + 1], lines, li) : first;
    if (wp <= 0) {
      out.push_back(P);
      // Leaving from a vertex on the line: its side is the line from here.
      if (wp == 0 && wq > 0) {
        out.back().n = side;
        out.back().side = li;
      }
    }
    if (wp * wq < 0) {
      const auto [x, err] = bsp_crossing(lines.a(P.side), lines.b(P.side), l.a, l.b);
      if (wp < 0)  // leaving: the new side starts here
        out.push_back({x, err, side, P.side, li});
      else  // entering: the rest of side P-Q
        out.push_back({x, err, P.n, li, P.side});
    }
  }
  if (out.size() < 3) out.clear();
  return out;
}

}  // namespace detail

inline BspTree BspTree::build(std::span<const BspPolygon> polygons, const BspParams& params) {
  if (!(params.bevel_angle > 0 && params.bevel_angle <= std::numbers::pi))
    throw InvalidArgument("BspTree: bevel_angle must lie in (0, pi]");
  if (params.candidates == 0) throw InvalidArgument("BspTree: candidates must be at least 1");
  using detail::BspCellVertex;
  using detail::BspEdge;
  using detail::BspPiece;

  // Edges, the solid on their left: the inside of each polygon by the even-odd rule over its
  // rings (a hole outside its outer ring is an island, a hole in a hole too), as the layer
  // queries read polygons; edges a polygon has twice cancel.
  Box2 bounds = Box2::empty();
  std::vector<std::vector<Point2>> rings;
  std::vector<detail::PolygonRing> of;
  auto add_ring = [&](const std::vector<Point2>& ring, const std::string& what, std::size_t polygon,
                      std::size_t index) {
    rings.push_back(detail::bsp_ring(ring, true, what));
    for (const Point2& p : rings.back())
      bounds.expand(p);
    of.push_back({{}, static_cast<std::uint32_t>(polygon), static_cast<std::uint32_t>(index)});
  };
  for (std::size_t i = 0; i < polygons.size(); ++i) {
    const std::string what = "polygon " + std::to_string(i);
    add_ring(polygons[i].outer, what + " outer ring", i, 0);
    for (std::size_t h = 0; h < polygons[i].holes.size(); ++h)
      add_ring(polygons[i].holes[h], what + " hole " + std::to_string(h), i, h + 1);
  }
  for (std::size_t i = 0; i < of.size(); ++i)
    of[i].vertices = rings[i];
  std::vector<BspEdge> edges;
  for (const detail::PolygonEdge& e : detail::even_odd_edges(of)) {
    const double dx = e.b[0] - e.a[0], dy = e.b[1] - e.a[1];
    const double len = std::hypot(dx, dy);
    const double nx = dy / len, ny = -dx / len;
    edges.push_back({e.a, e.b, nx, ny, nx * e.a[0] + ny * e.a[1], e.polygon});
  }
  // Every edge, for locating points against the polygons.
  const std::vector<BspEdge> all_edges = edges;

  // A border shared by two polygons appears as an edge and its reverse, inside the union:
  // both go.
  {
    std::vector<std::uint32_t> order(edges.size());
    for (std::uint32_t i = 0; i < order.size(); ++i)
      order[i] = i;
    auto less = [](const Point2& p, const Point2& q) {
      return p[0] < q[0] || (p[0] == q[0] && p[1] < q[1]);
    };
    // The edge's end points, the smaller first.
    auto lo = [&](std::uint32_t i) {
      const BspEdge& e = edges[i];
      return less(e.a, e.b) ? std::array{e.a[0], e.a[1], e.b[0], e.b[1]}
                            : std::array{e.b[0], e.b[1], e.a[0], e.a[1]};
    };
    std::sort(order.begin(), order.end(), [&](std::uint32_t x, std::uint32_t y) {
      return lo(x) < lo(y) || (lo(x) == lo(y) && x < y);
    });
    std::vector<char> gone(edges.size(), 0);
    for (std::size_t i = 0; i < order.size();) {
      std::size_t j = i;
      while (j < order.size() && lo(order[j]) == lo(order[i]))
        ++j;
      std::vector<std::uint32_t> fwd, bwd;
      for (std::size_t k = i; k < j; ++k)
        (less(edges[order[k]].a, edges[order[k]].b) ? fwd : bwd).push_back(order[k]);
      for (std::size_t k = 0; k < std::min(fwd.size(), bwd.size()); ++k)
        gone[fwd[k]] = gone[bwd[k]] = 1;
      i = j;
    }
    std::size_t w = 0;
    for (std::size_t i = 0; i < edges.size(); ++i)
      if (!gone[i]) edges[w++] = edges[i];
    edges.resize(w);
  }

  BspTree tree;
  tree.edges_ = edges.size();
  if (edges.empty()) return tree;
  tree.reach_ = magnitude(bounds);
  detail::BspPointLocator locator(all_edges, static_cast<std::uint32_t>(polygons.size()), bounds);

  // The root cell: the layer's bounds with a wide margin (solid cells never reach it).
  const double margin =
      std::max(bounds.max[0] - bounds.min[0], bounds.max[1] - bounds.min[1]) + 1.0;
  const double x0 = bounds.min[0] - margin, x1 = bounds.max[0] + margin;
  const double y0 = bounds.min[1] - margin, y1 = bounds.max[1] + margin;
  const detail::BspLines lines{edges,
                               {Point2{x0, y0}, Point2{x1, y0}, Point2{x1, y1}, Point2{x0, y1}}};
  std::vector<BspCellVertex> root_cell;
  {
    const std::array<Point2, 4> normal{Point2{0, -1}, Point2{1, 0}, Point2{0, 1}, Point2{-1, 0}};
    const auto box = static_cast<std::uint32_t>(edges.size());
    for (std::uint32_t i = 0; i < 4; ++i)
      root_cell.push_back({lines.corner[i], 0.0, normal[i], box + (i + 3) % 4, box + i});
  }

  // Side of a piece against the line of edge l: +1 behind (solid side), -1 in front, decided
  // on the original end points by the exact orientation predicate.
  auto side_of = [&](const BspEdge& l, const Point2& p) { return sign(orientation(l.a, l.b, p)); };
  // The same for an end of a piece of edge e: `own` for the edge's own end point, else the
  // side of e's crossing with the line of edge `cut`.
  auto end_side = [&](const BspEdge& l, const BspEdge& e, int own, std::uint32_t cut) {
    if (cut == BspPiece::kOwnEnd) return own;
    const BspEdge& m = edges[cut];
    return sign(crossing_orientation(e.a, e.b, m.a, m.b, l.a, l.b));
  };

  struct Work {
    std::int32_t parent;  // -1: the root
    bool front;           // which child of parent
    std::vector<BspPiece> pieces;
    std::vector<BspCellVertex> cell;
    std::size_t depth;
  };
  std::vector<Work> work;
  {
    std::vector<BspPiece> all(edges.size());
    for (std::uint32_t i = 0; i < all.size(); ++i)
      all[i] = {i, 0.0, 1.0};
    work.push_back({-1, false, std::move(all), std::move(root_cell), 1});
  }

  auto set_child = [&](std::int32_t parent, bool front, std::int32_t child) {
    if (parent < 0)
      tree.root_ = child;
    else if (front)
      tree.nodes_[static_cast<std::size_t>(parent)].front = child;
    else
      tree.nodes_[static_cast<std::size_t>(parent)].back = child;
  };

  // A solid leaf: bevel planes at the corners of its cell where the normals turn by more
  // than the bevel angle, as a chain of nodes ending in kSolid.
  const double alpha = params.bevel_angle;
  auto solid_leaf = [&](const std::vector<BspCellVertex>& cell, std::size_t depth) {
    ++tree.solid_leaves_;
    std::int32_t first = kSolid;
    std::int32_t last = -1;
    std::size_t chain = 0;
    const std::size_t m = cell.size();
    for (std::size_t i = 0; i < m; ++i) {
      const BspCellVertex& prev = cell[(i + m - 1) % m];
      const BspCellVertex& cur = cell[i];
      if (lines.box(prev.side) || lines.box(cur.side)) continue;
      const Point2 a = prev.n, b = cur.n;
      // The cell is convex: the normals turn counter-clockwise by less than pi at each corner
      // (a turn near pi, at the tip of a spike, may round to either sign of the cross product).
      const double turn =
          std::atan2(std::fabs(a[0] * b[1] - a[1] * b[0]), a[0] * b[0] + a[1] * b[1]);
      if (!(turn > alpha)) continue;
      const int parts = static_cast<int>(std::ceil(turn / alpha * (1 - 1e-12)));
      const double start = std::atan2(a[1], a[0]);
      for (int j = 1; j < parts; ++j) {
        const double phi = start + turn * j / parts;
        const double nx = std::cos(phi), ny = std::sin(phi);
        const auto k = static_cast<std::int32_t>(tree.nodes_.size());
        tree.nodes_.push_back({nx, ny, nx * cur.p[0] + ny * cur.p[1], kSolid, kEmpty});
        ++tree.bevels_;
        ++chain;
        if (last < 0)
          first = k;
        else
          tree.nodes_[static_cast<std::size_t>(last)].back = k;
        last = k;
      }
    }
    tree.depth_ = std::max(tree.depth_, depth + chain);
    return first;
  };

  const std::uint32_t cands = params.candidates;
  while (!work.empty()) {
    Work w = std::move(work.back());
    work.pop_back();
    std::vector<BspPiece>& pieces = w.pieces;

    // The splitter: the best scored of a few pieces spread over the list.
    std::size_t best = 0;
    if (pieces.size() > 1) {
      const std::size_t tries = std::min<std::size_t>(cands, pieces.size());
      double best_score = std::numeric_limits<double>::infinity();
      for (std::size_t c = 0; c < tries; ++c) {
        const std::size_t ci = c * pieces.size() / tries;
        const BspEdge& l = edges[pieces[ci].edge];
        std::size_t nf = 0, nb = 0, ns = 0;
        for (const BspPiece& q : pieces) {
          if (q.edge == pieces[ci].edge) continue;
          const BspEdge& e = edges[q.edge];
          const int sa = side_of(l, e.a), sb = side_of(l, e.b);
          if (sa == 0 && sb == 0) {
            ++nf;
          } else if (sa >= 0 && sb >= 0) {
            ++nb;
          } else if (sa <= 0 && sb <= 0) {
            ++nf;
          } else {
            ++ns;
          }
        }
        const double score = 3.0 * static_cast<double>(ns) +
                             std::fabs(static_cast<double>(nf) - static_cast<double>(nb));
        if (score < best_score) best_score = score, best = ci;
      }
    }
    const BspPiece splitter = pieces[best];
    const std::uint32_t li = splitter.edge;
    const BspEdge& l = edges[li];

    std::vector<BspPiece> back, front;
    for (const BspPiece& q : pieces) {
      if (q.edge == li) continue;
      const BspEdge& e = edges[q.edge];
      const int sa = side_of(l, e.a), sb = side_of(l, e.b);
      if (sa == 0 && sb == 0) {
        // On the line: done when facing the same way, else a shared border seen from the
        // other side.
        if (e.nx * l.nx + e.ny * l.ny < 0) front.push_back(q);
      } else if (sa >= 0 && sb >= 0) {
        back.push_back(q);
      } else if (sa <= 0 && sb <= 0) {
        front.push_back(q);
      } else {
        // The edge crosses the line: the sides of the piece's ends, exactly (an end cut by a
        // line through the crossing lies on the line), not by comparing rounded fractions,
        // which would leave slivers of the piece across the line where three lines meet.
        const int t0 = end_side(l, e, sa, q.c0);
        const int t1 = end_side(l, e, sb, q.c1);
        if (t0 >= 0 && t1 >= 0) {
          back.push_back(q);
        } else if (t0 <= 0 && t1 <= 0) {
          front.push_back(q);
        } else {
          const double fa = l.nx * e.a[0] + l.ny * e.a[1] - l.d;
          const double fb = l.nx * e.b[0] + l.ny * e.b[1] - l.d;
          // (Both ends within rounding of the line: fa / (fa - fb) may be NaN.)
          const double r = fa / (fa - fb);
          const double sc = r > q.s0 ? std::min(r, q.s1) : q.s0;
          (t0 > 0 ? back : front).push_back({q.edge, q.s0, sc, q.c0, li});
          (t0 > 0 ? front : back).push_back({q.edge, sc, q.s1, li, q.c1});
        }
      }
    }
    pieces.clear();
    pieces.shrink_to_fit();

    const auto k = static_cast<std::int32_t>(tree.nodes_.size());
    tree.nodes_.push_back({l.nx, l.ny, l.d, kEmpty, kEmpty});
    set_child(w.parent, w.front, k);
    std::vector<BspCellVertex> back_cell = detail::bsp_clip_cell(w.cell, lines, li, 1);
    std::vector<BspCellVertex> front_cell = detail::bsp_clip_cell(w.cell, lines, li, -1);
    if (front.empty()) {
      // Empty unless another polygon covers the splitter's piece. A front cell of no area (the
      // splitter on the cell's own border, a shared border seen from the other side: clipped
      // away exactly) stays empty, so that it claims no point of the line beyond the polygons;
      // a thin one, however thin, is decided as any other (it may be all there is of a
      // polygon, a sliver between two nearly collinear edges).
      double scale = 0;
      for (const detail::BspCellVertex& v : front_cell)
        scale = std::max({scale, std::abs(v.p[0]), std::abs(v.p[1])});
      bool covered = false;
      if (!front_cell.empty()) {
        using Cover = detail::BspPointLocator::Cover;
        // Where the cell has room, a point well inside it decides, located against all the
        // polygons: the mean of its corners, if it lies inside every side by 1e-12 of the
        // magnitudes (the sides carry the rounding of the clipping only, far less). No
        // boundary crosses the cell, and none passes near that point.
        Cover c = Cover::undecided;
        Point2 centre{0, 0};
        for (const detail::BspCellVertex& v : front_cell)
          centre = Point2{centre[0] + v.p[0], centre[1] + v.p[1]};
        const auto corners = static_cast<double>(front_cell.size());
        centre = Point2{centre[0] / corners, centre[1] / corners};
        double inside = std::numeric_limits<double>::infinity();
        for (const detail::BspCellVertex& v : front_cell)
          inside = std::min(inside, v.n[0] * (v.p[0] - centre[0]) + v.n[1] * (v.p[1] - centre[1]));
        if (inside > 1e-12 * scale) c = locator.inside_any(centre);
        // Else the piece: the real point of it just past its start (not a point rounded,
        // which may fall outside a thin cell; BspPieceStart), exactly.
        if (c == Cover::undecided)
          c = locator.inside_other(
              l, detail::BspPieceStart(
                     l, splitter.c0 == BspPiece::kOwnEnd ? nullptr : &edges[splitter.c0]));
        covered = c == Cover::yes;
      }
      std::int32_t leaf = kEmpty;
      if (covered) leaf = solid_leaf(front_cell, w.depth + 1);
      tree.nodes_[static_cast<std::size_t>(k)].front = leaf;
      tree.depth_ = std::max(tree.depth_, w.depth + 1);
    } else {
      work.push_back({k, true, std::move(front), std::move(front_cell), w.depth + 1});
    }
    if (back.empty()) {
      const std::int32_t leaf = solid_leaf(back_cell, w.depth + 1);
      tree.nodes_[static_cast<std::size_t>(k)].back = leaf;
    } else {
      work.push_back({k, false, std::move(back), std::move(back_cell), w.depth + 1});
    }
  }
  tree.nodes_.shrink_to_fit();
  return tree;
}

inline void BspTree::validate() const {
  if (root_ == kEmpty) {
    if (!nodes_.empty()) throw Error("BspTree: nodes but no root");
    return;
  }
  std::vector<char> seen(nodes_.size(), 0);
  std::vector<std::int32_t> stack{root_};
  std::size_t reached = 0;
  while (!stack.empty()) {
    const std::int32_t i = stack.back();
    stack.pop_back();
    if (i == kEmpty || i == kSolid) continue;
    if (i < 0 || static_cast<std::size_t>(i) >= nodes_.size())
      throw Error("BspTree: child index " + std::to_string(i) + " out of range");
    if (seen[static_cast<std::size_t>(i)])
      throw Error("BspTree: node " + std::to_string(i) + " reached twice");
    seen[static_cast<std::size_t>(i)] = 1;
    ++reached;
    const Node& n = nodes_[static_cast<std::size_t>(i)];
    if (!std::isfinite(n.d) || !(std::fabs(std::hypot(n.nx, n.ny) - 1) < 1e-9))
      throw Error("BspTree: node " + std::to_string(i) + " has a bad plane");
    if (n.back == kEmpty && n.front == kEmpty)
      throw Error("BspTree: node " + std::to_string(i) + " separates nothing");
    stack.push_back(n.back);
    stack.push_back(n.front);
  }
  if (reached != nodes_.size())
    throw Error("BspTree: " + std::to_string(nodes_.size() - reached) +
                " nodes not reached from the root");
}

}  // namespace loci
