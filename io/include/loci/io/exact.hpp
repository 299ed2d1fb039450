// FlatGeometry: a feature's geometry as flat arrays of points and parts, and the exact tests
// that refine index candidates into answers (DESIGN.md section 4).
//
// A layer's features arrive from GDAL in many shapes (points, lines, polygons with holes,
// multi-geometries, collections). For refinement only three kinds of part matter: isolated
// points, line strings, and polygon rings, the latter grouped by the polygon they bound so
// that holes are handled polygon by polygon. Keeping them as one vector of points plus part
// ranges costs one allocation per feature and keeps the tests simple loops.
//
// Predicates are exact: a geometry meets a box, a segment or a point when one of its points
// lies in it, one of its edges meets it (loci's exact box/segment and segment/segment tests),
// or one of its polygons contains a point of it (crossing parity decided with the exact
// orientation predicate; a point on a ring is caught by the edge test, not by parity). Parity
// is kept polygon by polygon (a polygon's rings by the even-odd rule), and a point is inside
// the feature when it is inside any of its polygons: also where polygons of one feature
// overlap (a collection of overlapping polygons, faces of a surface overlapping in plan, an
// invalid multi-polygon), whichever way the rings run and wherever an invalid polygon's holes
// lie.
// Touching counts. Distances are computed in floating point and are 0 inside a polygon; a
// point's distance is 0 exactly when the point lies on the geometry, and whether it is within
// a distance is decided exactly.
// Thread-safety: plain values; the functions are pure.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "loci/geom/box.hpp"
#include "loci/geom/segment.hpp"

namespace loci::io {

enum class PartKind : std::uint8_t { point, line, ring };

struct Part {
  std::uint32_t begin;  // first point in FlatGeometry::points
  std::uint32_t end;    // one past the last
  PartKind kind;
  std::uint32_t polygon;  // rings only: which polygon of the feature the ring bounds
};

struct FlatGeometry {
  std::vector<Point2> points;
  std::vector<Part> parts;
  std::uint32_t polygons = 0;  // number of polygons; rings name them 0..polygons-1

  bool empty() const { return points.empty(); }
  Box2 envelope() const;
};

// True when the geometry and the closed box share at least one point.
bool meets(const FlatGeometry& g, const Box2& box);
// True when the geometry and the closed segment share at least one point.
bool meets(const FlatGeometry& g, const Segment2& s);
// Euclidean distance from p to the nearest point of the geometry (0 inside a polygon), in
// floating point except where p lies within rounding of an edge: 0 exactly when p lies on g.
double distance(const FlatGeometry& g, const Point2& p);
// True when the geometry comes within distance d (>= 0) of p, decided exactly.
bool within_distance(const FlatGeometry& g, const Point2& p, double d);

// Where the closed segment s first meets g, as the parameter t in [0, 1] of the point
// s.a + t (s.b - s.a) (0 when s starts inside or on g); nothing when they do not meet. Whether
// and where they meet is decided exactly (the meeting point of two segments is rounded to
// doubles); t is computed from that point in floating point.
std::optional<double> first_meet(const FlatGeometry& g, const Segment2& s);
// first_meet's parameter with the point itself: an input point where s starts on g or meets it
// at a vertex or along an overlap, else the true crossing rounded to the nearest doubles (as
// loci intersections reports it), not s.a + t (s.b - s.a) rounded again.
struct Meet {
  double t;
  Point2 at;
};
std::optional<Meet> first_meeting(const FlatGeometry& g, const Segment2& s);
// The same for one segment e of linework.
std::optional<Meet> first_meeting(const Segment2& e, const Segment2& s);

// True when the geometries share at least one point (closed: touching counts). Their edges
// (isolated points as edges of length zero) are joined by sort-and-sweep on their boxes and
// tested exactly, stopping at the first pair that meets; without one, a geometry lies inside
// the other's polygon or apart from it, and one of its points decides which.
bool meets(const FlatGeometry& a, const FlatGeometry& b);
// The distance between a and b (0 when they meet) when it is at most d, nothing otherwise;
// only edge pairs whose boxes come within d are measured.
std::optional<double> distance_within(const FlatGeometry& a, const FlatGeometry& b, double d);

// True when every point of b lies in a, a's boundary included (OGC's "covers"). b's edges
// are cut where a's linework meets them; every vertex of b and the middle of every piece must
// lie in a (pieces running along a's edges do). When b has polygons, no point of the boundary
// of a's area may lie strictly inside them (the middle of a piece of a ring edge cut by b's
// edges and a's other polygons' edges: a hole or notch of a inside b; a piece whose both sides
// a's polygons hold, inside another polygon or along an edge two polygons share from either
// side, is not that boundary); then the inside of each polygon of b
// lies wholly in a or wholly outside (a hole of a filled exactly by b), and one point strictly
// inside it decides. The vertex tests are exact, and so are the middles of pieces: the real
// point, not its rounding, where the other geometry passes within rounding of it (b's edge
// running a hair inside a's, the rounded middle may lie outside). The cut parameters and the
// inside point are rounded, which can matter only for pieces or polygons thinner than the
// rounding.
bool covers(const FlatGeometry& a, const FlatGeometry& b);

// Where a point lies with respect to a geometry: outside it, on its boundary (a point, an
// edge of a line or ring), or strictly inside one of its polygons.
enum class Location : std::uint8_t { outside, boundary, inside };

class OddPolygons;

// A geometry prepared for many point tests: a grid of cells over its envelope, each listing
// the edges whose boxes overlap it, and for each cell what the edges entirely to its right
// contribute to the crossing parity of each polygon for a ray from any point of the cell (the
// polygons odd along the whole row, and a few y values, each with its polygon; see exact.cpp).
// A test reads one cell: its edges decide exactly (boundary, crossings within the cell) and
// its values at most the point's y give the rest, so that the cost is
// the edges near the point, not those along its whole row (what GEOS's prepared polygons scan,
// through an interval tree on y). The pair tests below take prepared geometries so that a
// feature met by many others (a joined layer) is prepared once and each pair costs the edges
// near the other's envelope, not the product of the sizes. It refers to `g`, which must
// outlive it. Thread-safety: const member functions may run concurrently.
class PreparedGeometry {
 public:
  explicit PreparedGeometry(const FlatGeometry& g);
  const FlatGeometry& geometry() const { return *g_; }
  const Box2& envelope() const { return envelope_; }
  // Exact.
  Location locate(const Point2& p) const;
  // The answer of meets(g, Box2::of_point(p)).
  bool meets(const Point2& p) const { return locate(p) != Location::outside; }
  // True when an edge or point of g comes within delta of p in x and in y (exact).
  bool near_boundary(const Point2& p, double delta) const;
  // Where the real point s.a + t (s.b - s.a) lies (not its rounding by point_at), exactly:
  // the rounded point decides unless g passes within rounding of it.
  Location locate_at(const Segment2& s, double t) const;
  // For the real point p = s.a + t (s.b - s.a), 0 < t < 1, on a ring edge s of g: whether g's
  // polygons hold the points beside p on both sides of s's line, near enough. Then p lies
  // inside g's area although rings run through it (an edge two adjacent polygons share, or one
  // of two that overlap inside the other). Exact; false also where a ring edge passes through p
  // across s's line.
  bool holds_both_sides(const Segment2& s, double t) const;
  std::size_t memory_bytes() const;

 private:
  struct Edge {
    std::uint32_t first;    // the edge runs from points[first] to points[first + 1]
    std::uint32_t polygon;  // rings: the polygon the ring bounds
    std::uint32_t kind;     // kRing, kLine, or kPoint (an isolated point: first only)
  };
  static constexpr std::uint32_t kRing = 0, kLine = 1, kPoint = 2;
  std::uint32_t col(double x) const;
  std::uint32_t row(double y) const;
  void build(std::size_t cells);
  // Toggles in `odd` the polygons of the ring edges whose boxes start right of column c, by
  // their ends below a point at height y (exactly: `below(v)`, asked only of ends within `hair`
  // of y) of row r1, or of row r0 = r1 - 1 within rounding of r1's lower border.
  template <class Below>
  void right_of(std::uint32_t r0, std::uint32_t r1, std::uint32_t c, double y, double hair,
                Below below, OddPolygons& odd) const;
  // f(edge) for each edge listed in the cells of rows r0..r1 and columns c0..c1, once, until f
  // returns false.
  template <class F>
  void each_edge_in(std::uint32_t r0, std::uint32_t r1, std::uint32_t c0, std::uint32_t c1,
                    F&& f) const;

  const FlatGeometry* g_;
  Box2 envelope_;
  std::vector<Edge> edges_;
  double sx_ = 0, sy_ = 0;  // cells per unit
  std::uint32_t nx_ = 1, ny_ = 1;
  std::vector<std::uint32_t> cell_start_, cell_edges_;  // CSR: the edges meeting each cell
  std::vector<std::uint32_t> value_start_;              // CSR into values_, per cell
  std::vector<double> values_;
  std::vector<std::uint32_t> value_polygons_;     // per value: its polygon
  std::vector<std::uint32_t> base_start_, base_;  // CSR, per cell: the polygons odd along
                                                  // the whole row right of it
};

// The pair tests above on prepared geometries (the same answers).
bool meets(const PreparedGeometry& a, const PreparedGeometry& b);
bool covers(const PreparedGeometry& a, const PreparedGeometry& b);
std::optional<double> distance_within(const PreparedGeometry& a, const PreparedGeometry& b,
                                      double d);
// The distance between a and b, at most `bound` (returned when they are farther apart): 0
// when they meet, else every vertex of each browses the other's edges in a packed R-tree,
// nearest first, so that two geometries far apart relative to their sizes cost
// O((n + m) log) rather than every pair of edges.
double distance(const PreparedGeometry& a, const PreparedGeometry& b, double bound);

// Crossing parity of the horizontal ray from p towards +x against the edge a-b, decided
// exactly; half-open in y so that a ray through a vertex counts once.
bool ray_crosses(const Point2& a, const Point2& b, const Point2& p);

// The polygons of one feature whose rings a ray crosses an odd number of times: the crossings
// are noted as they come (toggle()), and the ray's start is inside the feature when one
// polygon was crossed an odd number of times (any(), which sorts what was noted).
class OddPolygons {
 public:
  void toggle(std::uint32_t polygon) {
    if (n_ < small_.size())
      small_[n_] = polygon;
    else
      more_.push_back(polygon);
    ++n_;
  }
  bool any();

 private:
  std::size_t n_ = 0;
  std::array<std::uint32_t, 16> small_;  // the first crossings, without allocating
  std::vector<std::uint32_t> more_;      // the rest
};

}  // namespace loci::io
