// Linear motion: a moving point's report, where it is at a time, when a moving point is inside
// a moving window, and the closest point of approach (CPA) of two moving points.
//
// A report Motion{t, p, v} says the object is at p at time t and moves with constant velocity
// v (per time unit) until its next report (DESIGN.md section 5). position(m, s) = p + v (s - t)
// holds before t too: the indexes extrapolate both ways, and which report is in force at a
// time is the fleet's business (index/moving/fleet.hpp).
//
// Time. Times are doubles on the caller's clock (epoch seconds are fine); every formula here
// works on differences `s - t` taken first, so a timestamp of 1.7e9 with sub-second motion
// loses nothing beyond the rounding of that one subtraction (1.7e9 has an ulp of 2.4e-7 s).
//
// Moving window. A MovingWindow is a closed box whose bounds move linearly from `from` at t1
// to `to` at t2; a timeslice is t1 == t2 with from == to, a window over an interval has
// from == to, and a window that moves (Saltenis et al.'s moving query, a trapezoid in
// space-time) has from != to. A moving point meets it when at some time s in [t1, t2] the
// point lies in the window at s. Each of the 2 D constraints lo_i(s) <= x_i(s) <= hi_i(s) is
// linear in s, so its solution set is a half-line, everything or nothing; their intersection
// with [t1, t2] is one interval (LinearSpan below), empty when the point never meets the
// window. The same test bounds a node's time-parameterized box (see tpr_box.hpp).
//
// Closest approach. For two moving points with relative position d and relative velocity w at
// a common time s0, the squared distance |d + w u|^2 (u = s - s0) is a convex quadratic in u.
// Over a horizon [s0, s0 + H] its minimum is at u* = clamp(-(d.w) / |w|^2, 0, H) (u* = 0
// when w = 0: the distance never changes), which gives tcpa = s0 + u* and dcpa. The pair
// conflicts at distance D when dcpa <= D; the D-circle's entry and exit times are the roots of
// |d + w u|^2 = D^2, computed cancellation-free (sphere_contact of swept.hpp) and clipped to
// the horizon. dcpa decides membership, so a pair is reported exactly when its closest
// distance over the horizon is at most D as computed in doubles; the interval is then never
// empty (when rounding leaves the roots a hair apart at a grazing pass, both become tcpa).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "loci/geom/box.hpp"
#include "loci/geom/point.hpp"
#include "loci/geom/swept.hpp"

namespace loci {

// A report: at time t the object is at p and moves with velocity v.
template <int D>
struct Motion {
  double t;
  Point<D> p;
  Point<D> v;
  friend constexpr bool operator==(const Motion&, const Motion&) = default;
};

using Motion2 = Motion<2>;

// Where the object reported by m is at time s.
template <int D>
constexpr Point<D> position(const Motion<D>& m, double s) {
  const double dt = s - m.t;
  Point<D> q = m.p;
  for (int i = 0; i < D; ++i)
    q[i] += m.v[i] * dt;
  return q;
}

namespace detail {
// The message of check_motion for a report it refuses; kept out of line.
template <int D>
[[gnu::noinline, gnu::cold]] void refuse_motion(const Motion<D>& m, const char* what) {
  if (!std::isfinite(m.t)) throw InvalidGeometry(std::string(what) + " has a NaN or infinite time");
  if (!(std::abs(m.t) <= kMaxCoordinate))
    throw InvalidGeometry(std::string(what) + " has a time beyond 1e150");
  check_point(m.p, what);
  check_point(m.v, what);
  throw InvalidGeometry(std::string(what) + " has a position or velocity beyond 1e150");
}
}  // namespace detail

// Throws InvalidGeometry naming `what` for a NaN or infinite time, position or velocity, or
// values beyond kMaxCoordinate (times too: differences of times then never overflow).
template <int D>
void check_motion(const Motion<D>& m, const char* what = "report") {
  // Every value within the limits, tested without branches (a NaN fails each comparison).
  unsigned ok = std::abs(m.t) <= kMaxCoordinate;
  for (int i = 0; i < D; ++i)
    ok &=
        unsigned(std::abs(m.p[i]) <= kMaxCoordinate) & unsigned(std::abs(m.v[i]) <= kMaxCoordinate);
  if (!ok) [[unlikely]]
    detail::refuse_motion(m, what);
}

// A closed interval of times, built by intersecting linear constraints a + b s <= 0.
struct LinearSpan {
  double lo;
  double hi;

  constexpr bool empty() const { return !(lo <= hi); }

  // Keeps the times where a + b (s - origin) <= 0.
  constexpr void keep(double a, double b, double origin) {
    if (b == 0) {
      if (a > 0) hi = -std::numeric_limits<double>::infinity();
      return;
    }
    const double root = origin - a / b;
    if (b > 0)
      hi = std::min(hi, root);
    else
      lo = std::max(lo, root);
  }
};

// A window whose bounds move linearly from `from` at t1 to `to` at t2 (t1 <= t2). The
// velocities of its bounds are worked out once, when it is made, since every test of an
// object or a node against the window needs them; the window is a value, built whole.
template <int D>
struct MovingWindow {
  Box<D> from;
  Box<D> to;
  double t1;
  double t2;

  constexpr MovingWindow(const Box<D>& from_, const Box<D>& to_, double t1_, double t2_)
      : from(from_),
        to(to_),
        t1(t1_),
        t2(t2_),
        vmin_(rate(from_.min, to_.min)),
        vmax_(rate(from_.max, to_.max)) {}

  static constexpr MovingWindow at(const Box<D>& b, double t) { return {b, b, t, t}; }
  static constexpr MovingWindow during(const Box<D>& b, double t1, double t2) {
    return {b, b, t1, t2};
  }

  // Velocity of the bounds (zero for a fixed window or a timeslice).
  constexpr const Point<D>& vmin() const { return vmin_; }
  constexpr const Point<D>& vmax() const { return vmax_; }

  // The smallest box containing the window over [t1, t2].
  constexpr Box<D> hull() const { return merged(from, to); }

 private:
  constexpr Point<D> rate(const Point<D>& a, const Point<D>& b) const {
    Point<D> r{};
    if (t2 > t1)
      for (int i = 0; i < D; ++i)
        r[i] = (b[i] - a[i]) / (t2 - t1);
    return r;
  }

  Point<D> vmin_, vmax_;
};

// Throws InvalidGeometry for NaN or infinite bounds or times, an inverted box or t1 > t2, and
// for a window that moves but cannot be followed in doubles: two boxes at one time
// (t1 == t2), an interval t2 - t1 that overflows, or bounds whose speed does.
template <int D>
void check_window(const MovingWindow<D>& w) {
  if (!std::isfinite(w.t1) || !std::isfinite(w.t2))
    throw InvalidGeometry("window has a NaN or infinite time");
  if (w.t1 > w.t2) throw InvalidGeometry("window's time interval is inverted (t1 > t2)");
  if (!is_valid(w.from) || !is_valid(w.to))
    throw InvalidGeometry("window has a NaN, infinite or inverted bound");
  if (w.from == w.to) return;
  if (w.t1 == w.t2)
    throw InvalidGeometry("window at one time (t1 == t2) has two boxes (from != to)");
  if (!std::isfinite(w.t2 - w.t1))
    throw InvalidGeometry("moving window's interval t2 - t1 overflows a double");
  if (!is_finite(w.vmin()) || !is_finite(w.vmax()))
    throw InvalidGeometry("moving window's bounds move faster than a double holds");
}

// The times in [w.t1, w.t2] at which the box [lo + vlo (s - t), hi + vhi (s - t)] meets the
// window (closed). A moving point is the box with lo == hi and vlo == vhi.
template <int D>
LinearSpan moving_box_meets(const Point<D>& lo, const Point<D>& vlo, const Point<D>& hi,
                            const Point<D>& vhi, double t, const MovingWindow<D>& w) {
  // Solved in time from t, the box's reference time, and only then placed in absolute time:
  // a root a small fraction of an ulp of an epoch-second time from t (a point 1e-8 beyond the
  // window's edge at t1, moving away, leaves it 1e-8 s before t1) rounded onto t1 in absolute
  // time, and the point met a window it never enters.
  LinearSpan span{w.t1 - t, w.t2 - t};
  const Point<D>& wvmin = w.vmin();
  const Point<D>& wvmax = w.vmax();
  for (int i = 0; i < D && !span.empty(); ++i) {
    // Window bounds at time t (the box's reference time), extrapolated from t1.
    const double wlo = w.from.min[i] + wvmin[i] * (t - w.t1);
    const double whi = w.from.max[i] + wvmax[i] * (t - w.t1);
    // lo(s) <= whi(s):  (lo - whi) + (vlo - wvmax) (s - t) <= 0
    span.keep(lo[i] - whi, vlo[i] - wvmax[i], 0.0);
    // wlo(s) <= hi(s):  (wlo - hi) + (wvmin - vhi) (s - t) <= 0
    span.keep(wlo - hi[i], wvmin[i] - vhi[i], 0.0);
  }
  if (span.empty())
    return {std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  // Rounding is monotonic and so is the clamp: a span that is not empty stays so.
  return {std::clamp(t + span.lo, w.t1, w.t2), std::clamp(t + span.hi, w.t1, w.t2)};
}

// The times in [w.t1, w.t2] at which the moving point m lies in the window.
template <int D>
LinearSpan meets(const Motion<D>& m, const MovingWindow<D>& w) {
  return moving_box_meets(m.p, m.v, m.p, m.v, m.t, w);
}

// Whether the moving point m lies in the window at some time of [w.t1, w.t2]: the exact
// predicate of every moving query. A timeslice of a fixed window tests position(m, t1) in the
// box (the arithmetic the vectorized scans repeat); anything else, the linear constraints.
template <int D>
bool inside(const Motion<D>& m, const MovingWindow<D>& w) {
  if (w.t1 == w.t2 && w.from == w.to) return intersects(w.from, position(m, w.t1));
  return !meets(m, w).empty();
}

// Closest approach of two moving points over [s0, s0 + horizon].
struct Approach {
  double tcpa;     // time of closest approach, in [s0, s0 + horizon]
  double dcpa;     // distance then
  double t_enter;  // first time the distance is <= the threshold (s0 when already inside)
  double t_exit;   // last time it is, within the horizon
};

namespace detail {
// The relative position d of b from a at s0, their relative velocity w, the time u in
// [0, horizon] after s0 when they are closest, and the distance then.
template <int D>
struct Closest {
  Point<D> d, w;
  double u, dcpa;
};
// The same from the positions pa, pb at s0 and the velocities va, vb.
template <int D>
Closest<D> closest_at(const Point<D>& pa, const Point<D>& va, const Point<D>& pb,
                      const Point<D>& vb, double horizon) {
  Closest<D> c;
  double dw = 0, ww = 0;
  for (int i = 0; i < D; ++i) {
    c.d[i] = pb[i] - pa[i];
    c.w[i] = vb[i] - va[i];
    dw += c.d[i] * c.w[i];
    ww += c.w[i] * c.w[i];
  }
  c.u = ww > 0 ? std::clamp(-dw / ww, 0.0, horizon) : 0.0;
  double dd = 0;
  for (int i = 0; i < D; ++i) {
    const double e = c.d[i] + c.w[i] * c.u;
    dd += e * e;
  }
  c.dcpa = std::sqrt(dd);
  return c;
}
template <int D>
Closest<D> closest(const Motion<D>& a, const Motion<D>& b, double s0, double horizon) {
  return closest_at(position(a, s0), a.v, position(b, s0), b.v, horizon);
}
}  // namespace detail

// Whether a and b come within `within` of each other during [s0, s0 + horizon]: exactly
// when closest_approach(a, b, s0, horizon, within) has a value, without its times.
template <int D>
bool comes_within(const Motion<D>& a, const Motion<D>& b, double s0, double horizon,
                  double within) {
  return detail::closest(a, b, s0, horizon).dcpa <= within;
}

// The closest approach over [s0, s0 + horizon] of two points at pa and pb at time s0 moving
// with velocities va and vb, when it is at most `within`; nullopt otherwise. horizon >= 0,
// within >= 0.
template <int D>
std::optional<Approach> closest_approach_at(const Point<D>& pa, const Point<D>& va,
                                            const Point<D>& pb, const Point<D>& vb, double s0,
                                            double horizon, double within) {
  const detail::Closest<D> c = detail::closest_at(pa, va, pb, vb, horizon);
  const double u = c.u, dcpa = c.dcpa;
  if (!(dcpa <= within)) return std::nullopt;
  const Point<D> zero{};
  const ContactInterval in = sphere_contact(c.d, within, c.w, zero, 0.0, zero, 0.0, horizon);
  // The interval holds u in exact arithmetic; rounding at a grazing pass may leave it empty
  // or a hair off, and then it is widened to include u.
  const double enter = in.empty() ? u : std::min(in.enter, u);
  const double exit = in.empty() ? u : std::max(in.exit, u);
  return Approach{s0 + u, dcpa, s0 + enter, s0 + exit};
}

// The closest approach of a and b over [s0, s0 + horizon] when it is at most `within`;
// nullopt otherwise. horizon >= 0, within >= 0.
template <int D>
std::optional<Approach> closest_approach(const Motion<D>& a, const Motion<D>& b, double s0,
                                         double horizon, double within) {
  return closest_approach_at(position(a, s0), a.v, position(b, s0), b.v, s0, horizon, within);
}

}  // namespace loci
