// Time-parameterized bounding boxes (TPBRs), the bounds of the TPR-tree family.
//
// A TPBR bounds a set of moving points from some time on: on each axis a lower bound moving
// with velocity vlo and an upper bound moving with vhi, lo(r) = lo + vlo r and
// hi(r) = hi + vhi r, r being time relative to the tree's epoch (a time fixed at the tree's
// first report, so that epoch-second timestamps become small numbers). Enclosing children at
// relative time c takes the smallest of their lower bounds at c and the smallest of their
// lower velocities (and the largest of each for the upper bound), which contains every child
// for all r >= c: minimal at c, conservative after it (Saltenis et al., SIGMOD 2000).
//
// The TPR*-tree's cost of a TPBR (Tao, Papadias and Sun, VLDB 2003, section 4): the area of
// the region the box sweeps over the horizon [c, c + H] after being grown by the expected
// query extent, the probability that a uniformly placed query of that extent issued during the
// horizon visits the node. As in the authors' formulation, the swept region is the box at c
// plus, per axis, a prism between the box's faces at c and at c + H:
//   A = prod_i e_i(c) + sum_i 1/2 (prod_{j != i} e_j(c) + prod_{j != i} e_j(c + H)) s_i H
// with e_i the grown extent and s_i the speed at which the box's extent along axis i advances
// into new space (vhi when both bounds move up, -vlo when both move down, vhi - vlo when they
// spread apart). Expected queries here do not move, so the box's own velocities are the
// relative ones.
//
// Rounding. Bounds are re-expressed at the epoch each time they change, which costs a few
// ulps; tests against a TPBR therefore allow a slack of 1e-12 of the magnitudes involved, so
// that a child on its parent's boundary is never pruned (the exact test on the object decides).
#pragma once

#include <algorithm>
#include <cmath>

#include "loci/geom/motion.hpp"

namespace loci::detail {

template <int D>
struct Tpbr {
  Point<D> lo, hi;    // bounds at relative time 0 (the epoch)
  Point<D> vlo, vhi;  // velocities of the bounds

  static Tpbr of(const Motion<D>& m, double epoch) {
    Tpbr b;
    const double dt = epoch - m.t;
    for (int i = 0; i < D; ++i) {
      b.lo[i] = b.hi[i] = m.p[i] + m.v[i] * dt;
      b.vlo[i] = b.vhi[i] = m.v[i];
    }
    return b;
  }
  double lo_at(int i, double r) const { return lo[i] + vlo[i] * r; }
  double hi_at(int i, double r) const { return hi[i] + vhi[i] * r; }

  // Grows to contain e from relative time c on.
  void enclose(const Tpbr& e, double c) {
    for (int i = 0; i < D; ++i) {
      const double l = std::min(lo_at(i, c), e.lo_at(i, c));
      const double h = std::max(hi_at(i, c), e.hi_at(i, c));
      vlo[i] = std::min(vlo[i], e.vlo[i]);
      vhi[i] = std::max(vhi[i], e.vhi[i]);
      lo[i] = l - vlo[i] * c;
      hi[i] = h - vhi[i] * c;
    }
  }

  // Whether this contains e (within rounding) from relative time c on.
  bool encloses(const Tpbr& e, double c) const {
    for (int i = 0; i < D; ++i) {
      const double tol = slack(i, c) + e.slack(i, c);
      if (lo_at(i, c) > e.lo_at(i, c) + tol || hi_at(i, c) < e.hi_at(i, c) - tol) return false;
      if (vlo[i] > e.vlo[i] || vhi[i] < e.vhi[i]) return false;
    }
    return true;
  }

  // The rounding allowance of tests at relative times up to |r|.
  double slack(int i, double r) const {
    return 1e-12 * (std::abs(lo[i]) + std::abs(hi[i]) +
                    (std::abs(vlo[i]) + std::abs(vhi[i])) * std::abs(r)) +
           1e-300;
  }
};

// The TPR* cost of b: the area swept over [c, c + horizon] by b grown by `extent`.
template <int D>
double swept_cost(const Tpbr<D>& b, double c, double horizon, const Point<D>& extent) {
  double e1[D], e2[D], s[D];
  for (int i = 0; i < D; ++i) {
    e1[i] = b.hi_at(i, c) - b.lo_at(i, c) + extent[i];
    e2[i] = e1[i] + (b.vhi[i] - b.vlo[i]) * horizon;
    const double vl = b.vlo[i], vh = b.vhi[i];
    s[i] = vl > 0 ? vh : vh < 0 ? -vl : vh - vl;
  }
  double area = 1;
  for (int i = 0; i < D; ++i)
    area *= e1[i];
  for (int i = 0; i < D; ++i) {
    double up = 1, down = 1;
    for (int j = 0; j < D; ++j)
      if (j != i) up *= e1[j], down *= e2[j];
    area += 0.5 * (up + down) * s[i] * horizon;
  }
  return area;
}

// The times of the window w (absolute times, epoch given) at which b may hold a point in it:
// empty means no point b bounds from relative time c on meets w, when w.t1 >= epoch + c.
// `extra` widens the rounding slack (the owner's allowance for what b's magnitudes miss).
template <int D>
bool tpbr_meets(const Tpbr<D>& b, double epoch, const MovingWindow<D>& w, double extra = 0) {
  const double r1 = w.t1 - epoch, r2 = w.t2 - epoch;
  const Point<D>& wvmin = w.vmin();
  const Point<D>& wvmax = w.vmax();
  LinearSpan span{r1, r2};
  const double reach = std::max(std::abs(r1), std::abs(r2));
  for (int i = 0; i < D; ++i) {
    const double tol = b.slack(i, reach) + extra +
                       1e-12 * (std::abs(w.from.min[i]) + std::abs(w.from.max[i]) +
                                std::abs(w.to.min[i]) + std::abs(w.to.max[i]));
    // lo(r) <= whi(r) and wlo(r) <= hi(r), at r = r1 + u.
    span.keep(b.lo_at(i, r1) - w.from.max[i] - tol, b.vlo[i] - wvmax[i], r1);
    span.keep(w.from.min[i] - b.hi_at(i, r1) - tol, wvmin[i] - b.vhi[i], r1);
    if (span.empty()) return false;
  }
  return true;
}

// Squared distance from q to the box b spans at relative time r, less the rounding slack
// (widened by `extra`, as for tpbr_meets).
template <int D>
double tpbr_distance2(const Tpbr<D>& b, double r, const Point<D>& q, double extra = 0) {
  double d2 = 0;
  for (int i = 0; i < D; ++i) {
    const double tol = b.slack(i, r) + extra;
    const double lo = b.lo_at(i, r) - tol, hi = b.hi_at(i, r) + tol;
    const double d = q[i] < lo ? lo - q[i] : q[i] > hi ? q[i] - hi : 0;
    d2 += d * d;
  }
  return d2;
}

}  // namespace loci::detail
