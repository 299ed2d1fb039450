// Brute-force answers about moving objects against a solid polygonal layer, for checking
// BspTree: point in solid (boundary included), and the exact first contact of a moving circle
// or axis-aligned box with the polygons (the Minkowski sum of the solid and the object, met by
// the moving reference point), over every edge.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <vector>

#include "loci/geom/predicates.hpp"
#include "loci/index/broadphase/bsp_tree.hpp"

namespace loci::test {

inline constexpr double kNever = std::numeric_limits<double>::infinity();

// Calls f(a, b) for every edge of every ring of the polygons.
template <class F>
void for_each_edge(std::span<const BspPolygon> polys, F&& f) {
  auto ring = [&](const std::vector<Point2>& r) {
    for (std::size_t i = 0; i < r.size(); ++i) {
      const Point2& a = r[i];
      const Point2& b = r[(i + 1) % r.size()];
      if (!(a == b)) f(a, b);
    }
  };
  for (const BspPolygon& p : polys) {
    ring(p.outer);
    for (const auto& h : p.holes)
      ring(h);
  }
}

inline bool on_segment(const Point2& p, const Point2& a, const Point2& b) {
  return std::min(a[0], b[0]) <= p[0] && p[0] <= std::max(a[0], b[0]) &&
         std::min(a[1], b[1]) <= p[1] && p[1] <= std::max(a[1], b[1]) &&
         orientation(a, b, p) == Orientation::collinear;
}

// Whether p is in the closed solid: on an edge, or inside a polygon by crossing parity over
// its rings (exact orientation tests).
inline bool in_solid(std::span<const BspPolygon> polys, const Point2& p) {
  for (const BspPolygon& poly : polys) {
    bool inside = false, boundary = false;
    auto ring = [&](const std::vector<Point2>& r) {
      for (std::size_t i = 0; i < r.size(); ++i) {
        const Point2& a = r[i];
        const Point2& b = r[(i + 1) % r.size()];
        if (on_segment(p, a, b)) boundary = true;
        if ((a[1] > p[1]) != (b[1] > p[1])) {
          // Crossing to the right of p: p is left of the upward edge.
          const Point2& lo = a[1] < b[1] ? a : b;
          const Point2& hi = a[1] < b[1] ? b : a;
          if (orientation(lo, hi, p) == Orientation::counterclockwise) inside = !inside;
        }
      }
    };
    ring(poly.outer);
    for (const auto& h : poly.holes)
      ring(h);
    if (boundary || inside) return true;
  }
  return false;
}

inline double segment_distance(const Point2& p, const Point2& a, const Point2& b) {
  const double ux = b[0] - a[0], uy = b[1] - a[1];
  const double l2 = ux * ux + uy * uy;
  double s = l2 > 0 ? ((p[0] - a[0]) * ux + (p[1] - a[1]) * uy) / l2 : 0;
  s = std::clamp(s, 0.0, 1.0);
  return std::hypot(p[0] - a[0] - s * ux, p[1] - a[1] - s * uy);
}

// First t in [0, 1] at which p0 + t d comes within r of segment a-b (a capsule), given that
// p0 is not within r of it; kNever when it does not.
inline double capsule_entry(const Point2& p0, const Point2& d, const Point2& a, const Point2& b,
                            double r) {
  double best = kNever;
  const double dd = d[0] * d[0] + d[1] * d[1];
  for (const Point2& c : {a, b}) {
    const double mx = p0[0] - c[0], my = p0[1] - c[1];
    const double bq = mx * d[0] + my * d[1];
    const double cq = mx * mx + my * my - r * r;
    if (dd == 0) continue;
    const double disc = bq * bq - dd * cq;
    if (disc < 0) continue;
    const double t = (-bq - std::sqrt(disc)) / dd;
    if (t >= 0 && t <= 1) best = std::min(best, t);
  }
  const double ux = b[0] - a[0], uy = b[1] - a[1];
  const double len = std::hypot(ux, uy);
  if (len > 0) {
    const double cx = ux / len, cy = uy / len;  // along
    const double wx = -cy, wy = cx;             // across
    const double h0 = wx * (p0[0] - a[0]) + wy * (p0[1] - a[1]);
    const double hd = wx * d[0] + wy * d[1];
    const double q0 = cx * (p0[0] - a[0]) + cy * (p0[1] - a[1]);
    const double qd = cx * d[0] + cy * d[1];
    if (hd != 0) {
      for (const double target : {r, -r}) {
        const double t = (target - h0) / hd;
        if (!(t >= 0 && t <= 1)) continue;
        const double q = q0 + t * qd;
        if (q >= 0 && q <= len) best = std::min(best, t);
      }
    }
  }
  return best;
}

// Exact first contact (fraction of the move) of a circle of radius r moving from `from` to
// `to` with the solid; 0 when it starts in contact, kNever when it never meets it. Every edge
// is examined; those whose box is farther than r from the box of the move are passed over.
inline double first_contact_circle(std::span<const BspPolygon> polys, const Point2& from,
                                   const Point2& to, double r) {
  if (in_solid(polys, from)) return 0;
  const double x0 = std::min(from[0], to[0]) - r, x1 = std::max(from[0], to[0]) + r;
  const double y0 = std::min(from[1], to[1]) - r, y1 = std::max(from[1], to[1]) + r;
  auto near_move = [&](const Point2& a, const Point2& b) {
    return std::max(a[0], b[0]) >= x0 && std::min(a[0], b[0]) <= x1 && std::max(a[1], b[1]) >= y0 &&
           std::min(a[1], b[1]) <= y1;
  };
  bool touching = false;
  for_each_edge(polys, [&](const Point2& a, const Point2& b) {
    if (!touching && near_move(a, b) && segment_distance(from, a, b) <= r) touching = true;
  });
  if (touching) return 0;
  const Point2 d{to[0] - from[0], to[1] - from[1]};
  double best = kNever;
  for_each_edge(polys, [&](const Point2& a, const Point2& b) {
    if (near_move(a, b)) best = std::min(best, capsule_entry(from, d, a, b, r));
  });
  return best;
}

// First t in [0, 1] at which the box of half-extents `half` centred at p0 + t d meets the
// segment a-b (separating axes x, y and the segment's normal); kNever when it does not.
inline double box_segment_entry(const Point2& p0, const Point2& d, const Point2& half,
                                const Point2& a, const Point2& b) {
  double lo = 0, hi = 1;
  // Keeps the t where c0 + t cd lies in [mn, mx].
  auto keep = [&](double c0, double cd, double mn, double mx) {
    if (cd == 0) {
      if (c0 < mn || c0 > mx) lo = 2;
      return;
    }
    double t0 = (mn - c0) / cd, t1 = (mx - c0) / cd;
    if (t0 > t1) std::swap(t0, t1);
    lo = std::max(lo, t0);
    hi = std::min(hi, t1);
  };
  keep(p0[0], d[0], std::min(a[0], b[0]) - half[0], std::max(a[0], b[0]) + half[0]);
  keep(p0[1], d[1], std::min(a[1], b[1]) - half[1], std::max(a[1], b[1]) + half[1]);
  const double ux = b[0] - a[0], uy = b[1] - a[1];
  const double len = std::hypot(ux, uy);
  if (len > 0) {
    const double wx = -uy / len, wy = ux / len;
    const double rad = std::fabs(wx) * half[0] + std::fabs(wy) * half[1];
    const double s = wx * a[0] + wy * a[1];
    keep(wx * p0[0] + wy * p0[1], wx * d[0] + wy * d[1], s - rad, s + rad);
  }
  return lo <= hi ? lo : kNever;
}

// Exact first contact of a moving axis-aligned box with the solid, as first_contact_circle.
inline double first_contact_box(std::span<const BspPolygon> polys, const Point2& from,
                                const Point2& to, const Point2& half) {
  if (in_solid(polys, from)) return 0;
  const Point2 d{to[0] - from[0], to[1] - from[1]};
  double best = kNever;
  for_each_edge(polys, [&](const Point2& a, const Point2& b) {
    best = std::min(best, box_segment_entry(from, d, half, a, b));
  });
  return best;
}

}  // namespace loci::test
