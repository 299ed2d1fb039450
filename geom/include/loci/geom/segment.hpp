// Segment<D>: the closed straight segment between two points, and the exact tests on it.
//
// Box-segment intersection is exact: in 2D a segment meets a box when their bounding boxes
// meet and the box's corners are not all strictly on one side of the segment's line (the
// separating-axis theorem has no other candidate axis); in 3D the candidate axes are the box
// axes and the cross products of the segment with them, each of which lies in a coordinate
// plane, so the segment meets the box exactly when its three axis-plane projections meet the
// projected rectangles. Segment-segment intersection is decided by exact orientations, with
// touching and collinear overlap counted as intersecting. Distances are plain floating point,
// except the 2D point-segment ones below: compared with a distance exactly, and recomputed
// exactly (then rounded) where the point lies within rounding of the segment, so that a point
// on a segment is at distance 0 and no other is.
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>

#include "loci/geom/box.hpp"
#include "loci/geom/predicates.hpp"

namespace loci {

template <int D>
struct Segment {
  static constexpr int dimension = D;

  Point<D> a;
  Point<D> b;

  constexpr Box<D> box() const {
    Box<D> r{a, a};
    r.expand(b);
    return r;
  }
  friend constexpr bool operator==(const Segment&, const Segment&) = default;
};

using Segment2 = Segment<2>;
using Segment3 = Segment<3>;

template <int D>
void check_segment(const Segment<D>& s, const char* what = "segment") {
  check_point(s.a, what);
  check_point(s.b, what);
}

namespace detail {

// The 2D test on the projection of box and segment onto the plane of axes (u, v).
template <int D>
bool projected_box_segment(const Box<D>& box, const Segment<D>& s, int u, int v) {
  const Point<2> a{s.a[u], s.a[v]};
  const Point<2> b{s.b[u], s.b[v]};
  if (a == b) return true;  // the bounding-box test already placed the point inside
  const Point<2> corners[4] = {{box.min[u], box.min[v]},
                               {box.max[u], box.min[v]},
                               {box.max[u], box.max[v]},
                               {box.min[u], box.max[v]}};
  bool left = false;
  bool right = false;
  for (const auto& c : corners) {
    const Orientation o = orientation(a, b, c);
    if (o == Orientation::collinear) return true;
    (o == Orientation::counterclockwise ? left : right) = true;
    if (left && right) return true;
  }
  return false;
}

}  // namespace detail

template <int D>
bool intersects(const Box<D>& box, const Segment<D>& s) {
  if (!intersects(box, s.box())) return false;
  if constexpr (D == 2) {
    return detail::projected_box_segment(box, s, 0, 1);
  } else {
    return detail::projected_box_segment(box, s, 0, 1) &&
           detail::projected_box_segment(box, s, 1, 2) &&
           detail::projected_box_segment(box, s, 0, 2);
  }
}

template <int D>
bool intersects(const Segment<D>& s, const Box<D>& box) {
  return intersects(box, s);
}

// Exact: shared endpoints, touching and collinear overlap all count.
inline bool intersects(const Segment<2>& s, const Segment<2>& t) {
  if (!intersects(s.box(), t.box())) return false;
  const int o1 = sign(orientation(s.a, s.b, t.a));
  const int o2 = sign(orientation(s.a, s.b, t.b));
  const int o3 = sign(orientation(t.a, t.b, s.a));
  const int o4 = sign(orientation(t.a, t.b, s.b));
  // Not strictly separated by either line: if the lines are distinct they cross at a point of
  // both segments; if they coincide, the intersecting bounding boxes mean the segments overlap.
  return o1 * o2 <= 0 && o3 * o4 <= 0;
}

template <int D>
double squared_distance(const Point<D>& p, const Segment<D>& s) {
  double len2 = 0;
  double dot = 0;
  for (int i = 0; i < D; ++i) {
    const double d = s.b[i] - s.a[i];
    len2 += d * d;
    dot += (p[i] - s.a[i]) * d;
  }
  if constexpr (D == 2) {
    // Beside the segment, the distance to its line from the cross product of differences:
    // its error scales with |p - a|, where the projected point a + t (b - a) carries the
    // rounding of the absolute coordinates (1e-9 at 1e7, a millionth of a distance of 1e-3).
    if (dot > 0 && dot < len2) {
      const double c = (p[0] - s.a[0]) * (s.b[1] - s.a[1]) - (p[1] - s.a[1]) * (s.b[0] - s.a[0]);
      return c * (c / len2);
    }
  }
  double t = 0;
  if (len2 > 0) t = std::clamp(dot / len2, 0.0, 1.0);
  double r = 0;
  for (int i = 0; i < D; ++i) {
    const double q = s.a[i] + t * (s.b[i] - s.a[i]);
    const double d = p[i] - q;
    r += d * d;
  }
  return r;
}

// The point s.a + t (s.b - s.a), in floating point, and exactly an end point at t = 0 and 1.
inline Point<2> point_at(const Segment<2>& s, double t) {
  if (t == 0) return s.a;
  if (t == 1) return s.b;
  return {s.a[0] + t * (s.b[0] - s.a[0]), s.a[1] + t * (s.b[1] - s.a[1])};
}

// Exact tests on the real point s.a + t (s.b - s.a) rather than on its rounding by point_at:
// the sign of its coordinate `axis` minus v, and the orientation of a, b and it. For a point
// inside a segment that other geometry passes within rounding of (a piece between the
// crossings of two nearly collinear edges), where the rounded point may lie on the wrong side.
int compare_coordinate_at(const Segment<2>& s, double t, int axis, double v);
Orientation orientation_at(const Point<2>& a, const Point<2>& b, const Segment<2>& s, double t);
// A bound on the distance in x and in y between point_at(s, t), t in [0, 1], and the real point.
inline double point_at_rounding(const Segment<2>& s) {
  return 1e-15 * (std::fabs(s.a[0]) + std::fabs(s.a[1]) + std::fabs(s.b[0]) + std::fabs(s.b[1])) +
         1e-300;
}

namespace detail {
// The exact squared distance from p to s, rounded to a double (0 only when p lies on s).
double squared_distance_exact(const Point<2>& p, const Segment<2>& s);
// The sign of |p s|^2 - d^2, decided exactly.
int compare_distance_exact(const Point<2>& p, const Segment<2>& s, double d);

// A bound on the rounding error of sqrt(squared_distance(p, s)): a few dozen units in the last
// place of the largest coordinate involved (the projection is computed from absolute
// coordinates, so the error scales with them, not with the distance), and at least 1e-150,
// below which the squares lose their digits to underflow.
inline double distance_rounding(const Point<2>& p, const Segment<2>& s) {
  return 1e-14 * (std::fabs(p[0]) + std::fabs(p[1]) + std::fabs(s.a[0]) + std::fabs(s.a[1]) +
                  std::fabs(s.b[0]) + std::fabs(s.b[1])) +
         1e-150;
}
}  // namespace detail

// The square of the distance below which accurate_squared_distance measures exactly, for p and
// any segment within `extent`: a bound on its zone for all of them at once.
inline double near_zone_squared(const Point<2>& p, const Box<2>& extent) {
  const double zone = 1e-10 * (std::fabs(p[0]) + std::fabs(p[1]) + 4 * magnitude(extent)) + 1e-146;
  return zone * zone;
}

// squared_distance(p, s), recomputed exactly (then rounded) where p lies within 1e-10 of the
// coordinates' magnitude of s, where rounding could be much of it: 0 exactly when p lies on s,
// and positive otherwise.
inline double accurate_squared_distance(const Point<2>& p, const Segment<2>& s) {
  const double d2 = squared_distance(p, s);
  const double zone = 1e4 * detail::distance_rounding(p, s);
  return d2 > zone * zone ? d2 : detail::squared_distance_exact(p, s);
}

// The sign of the distance from p to the closed segment s minus d (d finite and >= 0), decided
// exactly: -1 nearer than d, 0 at exactly d, +1 farther. Floating point decides when the
// distance is clearly apart from d.
inline int compare_distance(const Point<2>& p, const Segment<2>& s, double d) {
  const double got = std::sqrt(squared_distance(p, s));
  const double margin = detail::distance_rounding(p, s) + 4e-16 * d;
  if (got > d + margin) return 1;
  if (got < d - margin) return -1;
  return detail::compare_distance_exact(p, s, d);
}

}  // namespace loci
