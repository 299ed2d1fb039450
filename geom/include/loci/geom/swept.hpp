// Swept boxes and exact contact intervals of linearly moving boxes and spheres.
//
// Motion is linear: an object given at time 0 with velocity v is at x + v t at time t. The
// box swept over [t0, t1] is the union of the box at t0 and the box at t1 (for a box, the
// convex hull of the two is contained in their bounding box, and that bounding box is the
// smallest box containing the motion). A broad phase that indexes swept boxes cannot miss a
// pair that meets in between, which is how fast objects stop tunnelling through thin ones.
//
// Contact interval. Two moving objects are in contact over the set of times where they meet
// (closed: touching counts). For convex objects under linear motion the set is one interval
// [enter, exit], clipped here to the query's [t0, t1]:
//
// - boxes: on each axis the closed boxes overlap while a.min + va t <= b.max + vb t and
//   b.min + vb t <= a.max + va t, two linear inequalities in t whose solutions are half-lines
//   (or everything / nothing when the relative velocity on that axis is zero: parallel
//   motion). The contact interval is the intersection of the 2 D half-lines with [t0, t1],
//   the slab method of ray-box intersection applied to the relative motion;
// - spheres (circles in 2D): |d + v t| <= r, with d and v the relative position and velocity
//   and r the sum of the radii, is the quadratic |v|^2 t^2 + 2 (d.v) t + |d|^2 - r^2 <= 0.
//   Its roots are computed in the cancellation-free form (Numerical Recipes 5.6); |v| = 0 is
//   either always or never in contact.
//
// The arithmetic is IEEE double: times are exact up to the rounding of a few operations
// (relative error of a few ulps away from grazing contact, where the roots of the quadratic
// are ill-conditioned by nature). Objects already in contact at t0 get enter == t0.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "loci/geom/box.hpp"
#include "loci/geom/point.hpp"

namespace loci {

// A closed time interval of contact; empty when there is no contact.
struct ContactInterval {
  double enter = std::numeric_limits<double>::infinity();
  double exit = -std::numeric_limits<double>::infinity();

  constexpr bool empty() const { return !(enter <= exit); }
  static constexpr ContactInterval none() { return {}; }
  friend constexpr bool operator==(const ContactInterval&, const ContactInterval&) = default;
};

// The box b (at time 0) moved by v t.
template <int D>
constexpr Box<D> moved_box(const Box<D>& b, const Point<D>& v, double t) {
  Box<D> m = b;
  for (int a = 0; a < D; ++a) {
    m.min[a] += v[a] * t;
    m.max[a] += v[a] * t;
  }
  return m;
}

namespace detail {
// x + v t rounded up (`up`) or down, not to nearest: the product's and the sum's rounding
// errors are found exactly (fma, and the two-sum of Knuth), and only a bound they leave on the
// wrong side is moved out, by at most their size, so that an exact bound stays as it is.
inline double moved_bound(double x, double v, double t, bool up) {
  const double p = v * t, e = std::fma(v, t, -p);
  const double s = x + p, bp = s - x, r = (x - (s - bp)) + (p - bp);  // x + p = s + r
  const double rest = r + e;  // the exact value is s + r + e; its sign is rest's
  if (up ? !(rest > 0) : !(rest < 0)) return s;
  const double slack = 0x1p-52 * (std::abs(p) + std::abs(s)) + 0x1p-1074;
  return up ? std::nextafter(s + slack, INFINITY) : std::nextafter(s - slack, -INFINITY);
}
}  // namespace detail

// The smallest box containing b (at time 0, velocity v) over [t0, t1], its bounds rounded
// outward where x + v t is not a double: it holds the motion exactly (rounded to nearest, a
// bound fell an ulp short of where the box is at t1, and a broad phase on swept boxes missed
// a pair box_contact() finds touching there).
template <int D>
Box<D> swept_box(const Box<D>& b, const Point<D>& v, double t0, double t1) {
  Box<D> s;
  for (int a = 0; a < D; ++a) {
    s.min[a] = std::min(detail::moved_bound(b.min[a], v[a], t0, false),
                        detail::moved_bound(b.min[a], v[a], t1, false));
    s.max[a] = std::max(detail::moved_bound(b.max[a], v[a], t0, true),
                        detail::moved_bound(b.max[a], v[a], t1, true));
  }
  return s;
}

// Times in [t0, t1] when box a (velocity va) and box b (velocity vb), both given at time 0,
// meet.
template <int D>
ContactInterval box_contact(const Box<D>& a, const Point<D>& va, const Box<D>& b,
                            const Point<D>& vb, double t0, double t1) {
  double enter = t0, exit = t1;
  for (int k = 0; k < D; ++k) {
    const double v = va[k] - vb[k];
    // On axis k the boxes overlap while g1 + v t <= 0 and g2 - v t <= 0, v being the
    // relative velocity.
    const double g1 = a.min[k] - b.max[k];
    const double g2 = b.min[k] - a.max[k];
    if (v == 0) {
      if (g1 > 0 || g2 > 0) return ContactInterval::none();
      continue;
    }
    // Solved for t: between -g1 / v and g2 / v, in an order set by the sign of v.
    const double ta = -g1 / v, tb = g2 / v;
    if (v > 0) {
      enter = std::max(enter, tb);
      exit = std::min(exit, ta);
    } else {
      enter = std::max(enter, ta);
      exit = std::min(exit, tb);
    }
    if (enter > exit) return ContactInterval::none();
  }
  return {enter, exit};
}

// Times in [t0, t1] when the sphere (circle in 2D) at ca with radius ra and velocity va meets
// the one at cb, rb, vb, all given at time 0.
template <int D>
ContactInterval sphere_contact(const Point<D>& ca, double ra, const Point<D>& va,
                               const Point<D>& cb, double rb, const Point<D>& vb, double t0,
                               double t1) {
  Point<D> rel, vel;
  double r = ra + rb, len = r, speed = 0;
  for (int k = 0; k < D; ++k) {
    rel[k] = ca[k] - cb[k];
    vel[k] = va[k] - vb[k];
    len = std::max(len, std::abs(rel[k]));
    speed = std::max(speed, std::abs(vel[k]));
  }
  // The discriminant below is of the fourth degree: lengths far from 1, or speeds far from a
  // length per unit of time, would overflow or underflow it and lose the roots. Lengths are
  // then scaled by a power of two near their largest, and time by another so that speeds
  // come near a length per unit of time (velocities take the time unit first, so that neither
  // product leaves the range of doubles); both are exact, and the roots are scaled back
  // exactly. Ratios of speed to length beyond 2^1000 stay out of reach.
  double unit = 1;  // the time unit of the equation solved
  if (len > 0 && (len > 0x1p100 || len < 0x1p-100 ||
                  (speed > 0 && (speed > len * 0x1p100 || speed * 0x1p100 < len)))) {
    const int el = std::max(std::ilogb(len), -1000);
    const int gap = speed > 0 ? std::clamp(std::ilogb(speed) - el, -1000, 1000) : 0;
    const double f = std::ldexp(1.0, -el);
    unit = std::ldexp(1.0, -gap);
    r *= f;
    for (int k = 0; k < D; ++k)
      rel[k] *= f, vel[k] = vel[k] * unit * f;
  }
  double dd = 0, dv = 0, vv = 0;
  for (int k = 0; k < D; ++k) {
    dd += rel[k] * rel[k];
    dv += rel[k] * vel[k];
    vv += vel[k] * vel[k];
  }
  const double c = dd - r * r;
  double enter, exit;
  if (vv == 0) {
    if (c > 0) return ContactInterval::none();
    enter = t0, exit = t1;
  } else {
    // vv t^2 + 2 dv t + c <= 0; discriminant / 4.
    const double disc = dv * dv - vv * c;
    if (disc < 0) return ContactInterval::none();
    const double q = -(dv + std::copysign(std::sqrt(disc), dv));
    double r1 = q / vv * unit;
    double r2 = (q != 0 ? c / q : q / vv) * unit;
    if (r1 > r2) std::swap(r1, r2);
    enter = std::max(t0, r1);
    exit = std::min(t1, r2);
  }
  if (enter > exit) return ContactInterval::none();
  return {enter, exit};
}

}  // namespace loci
