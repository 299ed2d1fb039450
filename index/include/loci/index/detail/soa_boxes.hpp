// SoaBoxes<D, N>: the boxes of one node's N children, stored structure-of-arrays.
//
// lo[axis][i] and hi[axis][i] hold child i's box, so testing a window against all N children
// is 2*D comparisons over contiguous doubles, which the compiler turns into a few vector
// instructions. Unused slots hold the empty box (+inf, -inf), which fails every intersection
// test, so the loops run over all N slots without a count. Shared by every R-tree variant.
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>
#include <limits>
#include <type_traits>

#include "loci/geom/box.hpp"

namespace loci::detail {

template <int D, int N>
struct SoaBoxes {
  static_assert(N >= 2 && N <= 64, "node fan-out must be in [2, 64]");
  using Mask = std::conditional_t<(N <= 32), std::uint32_t, std::uint64_t>;

  double lo[D][N];
  double hi[D][N];

  void clear() {
    for (int a = 0; a < D; ++a)
      for (int i = 0; i < N; ++i) {
        lo[a][i] = std::numeric_limits<double>::infinity();
        hi[a][i] = -std::numeric_limits<double>::infinity();
      }
  }

  Box<D> box(int i) const {
    Box<D> b;
    for (int a = 0; a < D; ++a) {
      b.min[a] = lo[a][i];
      b.max[a] = hi[a][i];
    }
    return b;
  }

  void set(int i, const Box<D>& b) {
    for (int a = 0; a < D; ++a) {
      lo[a][i] = b.min[a];
      hi[a][i] = b.max[a];
    }
  }

  void expand(int i, const Box<D>& b) {
    for (int a = 0; a < D; ++a) {
      lo[a][i] = std::min(lo[a][i], b.min[a]);
      hi[a][i] = std::max(hi[a][i], b.max[a]);
    }
  }

  // Bounds of the first `count` slots.
  Box<D> bounds(int count) const {
    Box<D> b = Box<D>::empty();
    for (int a = 0; a < D; ++a)
      for (int i = 0; i < count; ++i) {
        b.min[a] = std::min(b.min[a], lo[a][i]);
        b.max[a] = std::max(b.max[a], hi[a][i]);
      }
    return b;
  }

  // Bit i set when child i meets w.
  Mask intersecting(const Box<D>& w) const {
    Mask m = 0;
    for (int i = 0; i < N; ++i) {
      bool hit = true;
      for (int a = 0; a < D; ++a)
        hit &= (lo[a][i] <= w.max[a]) & (hi[a][i] >= w.min[a]);
      m |= Mask(hit) << i;
    }
    return m;
  }

  // Bit i set when child i lies inside w.
  Mask inside(const Box<D>& w) const {
    Mask m = 0;
    for (int i = 0; i < N; ++i) {
      bool in = true;
      for (int a = 0; a < D; ++a)
        in &= (lo[a][i] >= w.min[a]) & (hi[a][i] <= w.max[a]);
      m |= Mask(in) << i;
    }
    return m;
  }

  // Bit i set when child i contains w.
  Mask containing(const Box<D>& w) const {
    Mask m = 0;
    for (int i = 0; i < N; ++i) {
      bool c = true;
      for (int a = 0; a < D; ++a)
        c &= (lo[a][i] <= w.min[a]) & (hi[a][i] >= w.max[a]);
      m |= Mask(c) << i;
    }
    return m;
  }

  double squared_distance(int i, const Point<D>& p) const {
    double s = 0;
    for (int a = 0; a < D; ++a) {
      const double below = lo[a][i] - p[a];
      const double above = p[a] - hi[a][i];
      const double d = below > 0 ? below : (above > 0 ? above : 0.0);
      s += d * d;
    }
    return s;
  }
};

template <class Mask>
inline int pop_lowest(Mask& m) {
  const int i = std::countr_zero(m);
  m &= m - 1;
  return i;
}

}  // namespace loci::detail
