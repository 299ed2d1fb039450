// FlatGeometry: a feature's geometry as flat arrays of points and parts, and the exact tests
// that refine index candidates into answers (DESIGN.md section 4).
//
// A layer's features arrive from GDAL in many shapes (points, lines, polygons with holes,
// multi-geometries, collections). For refinement only three kinds of part matter: isolated
// points, line strings, and polygon rings, the latter grouped by the polygon they bound so
// that holes are handled by crossing parity. Keeping them as one vector of points plus part
// ranges costs one allocation per feature and keeps the tests simple loops.
//
// Predicates are exact: a geometry meets a box, a segment or a point when one of its points
// lies in it, one of its edges meets it (loci's exact box/segment and segment/segment tests),
// or one of its polygons contains a point of it (crossing parity decided with the exact
// orientation predicate; a point on a ring is caught by the edge test, not by parity).
// Touching counts. Distances are computed in floating point and are 0 inside a polygon.
// Thread-safety: plain values; the functions are pure.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "loci/geom/box.hpp"
#include "loci/geom/segment.hpp"
#include "loci/index/detail/y_bands.hpp"

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
// Euclidean distance from p to the nearest point of the geometry (0 inside a polygon).
double distance(const FlatGeometry& g, const Point2& p);

// Where the closed segment s first meets g, as the parameter t in [0, 1] of the point
// s.a + t (s.b - s.a) (0 when s starts inside or on g); nothing when they do not meet. Whether
// and where they meet is decided exactly (the meeting point of two segments is rounded to
// doubles); t is computed from that point in floating point.
std::optional<double> first_meet(const FlatGeometry& g, const Segment2& s);
// The same for one segment e of linework.
std::optional<double> first_meet(const Segment2& e, const Segment2& s);

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
// lie in a (pieces running along a's edges do), and when b has polygons no vertex of a may lie
// strictly inside them (a hole of a, or a notch, inside b). The vertex tests are exact; the
// middle of a piece is rounded, which can matter only for pieces shorter than the rounding.
bool covers(const FlatGeometry& a, const FlatGeometry& b);

// A geometry prepared for many point tests: its edges bucketed by y (index/detail/
// y_bands.hpp), so that a test costs the edges near the point's y instead of all of them (what
// GEOS's prepared polygons do for point-in-polygon). It refers to `g`, which must outlive it;
// one test at a time (it keeps scratch parity state).
class PreparedGeometry {
 public:
  explicit PreparedGeometry(const FlatGeometry& g);
  // The answer of meets(g, Box2::of_point(p)).
  bool meets(const Point2& p) const;
  std::size_t memory_bytes() const;

 private:
  struct Edge {
    std::uint32_t first;    // the edge runs from points[first] to points[first + 1]
    std::uint32_t polygon;  // rings: the polygon it bounds; kNotRing otherwise
  };
  static constexpr std::uint32_t kNotRing = 0xffffffffu;
  static constexpr std::uint32_t kPoint = 0xfffffffeu;  // an isolated point: first only
  const FlatGeometry* g_;
  std::vector<Edge> edges_;
  detail::YBands bands_;
  mutable std::vector<std::uint8_t> parity_;
  mutable std::vector<std::uint32_t> touched_;
};

// Crossing parity of the horizontal ray from p towards +x against the edge a-b, decided
// exactly; half-open in y so that a ray through a vertex counts once.
bool ray_crosses(const Point2& a, const Point2& b, const Point2& p);

}  // namespace loci::io
