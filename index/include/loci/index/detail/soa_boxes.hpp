// SoaBoxes<D, N>: the boxes of one node's N children, stored structure-of-arrays.
//
// lo[axis][i] and hi[axis][i] hold child i's box, so testing a window against all N children
// is 2*D comparisons over contiguous doubles, which the compiler turns into a few vector
// instructions. Unused slots hold the empty box (+inf, -inf), which fails every intersection
// test, so the loops run over all N slots without a count. An odd N is padded with one slot
// that is always empty, so that the loops take two slots a step. Shared by every R-tree
// variant.
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>
#include <limits>
#include <type_traits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "loci/geom/box.hpp"

namespace loci::detail {

template <int D, int N>
struct SoaBoxes {
  static_assert(N >= 2 && N <= 64, "node fan-out must be in [2, 64]");
  // Slots stored: N, rounded up to even.
  static constexpr int kSlots = (N + 1) / 2 * 2;
  using Mask = std::conditional_t<(kSlots <= 32), std::uint32_t, std::uint64_t>;

  double lo[D][kSlots];
  double hi[D][kSlots];

  void clear() {
    for (int a = 0; a < D; ++a)
      for (int i = 0; i < kSlots; ++i) {
        lo[a][i] = std::numeric_limits<double>::infinity();
        hi[a][i] = -std::numeric_limits<double>::infinity();
      }
  }

  // Asks for the whole node to be brought into cache: a query that will visit it soon
  // overlaps the memory latency with the work on the nodes before it.
  void prefetch() const {
    const char* p = reinterpret_cast<const char*>(this);
    for (std::size_t off = 0; off < sizeof(SoaBoxes); off += 64)
      __builtin_prefetch(p + off);
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
    return mask([](auto lo_v, auto hi_v, auto wmin,
                   auto wmax) { return both(less_equal(lo_v, wmax), less_equal(wmin, hi_v)); },
                w);
  }

  // Bit i set when child i lies inside w.
  Mask inside(const Box<D>& w) const {
    return mask([](auto lo_v, auto hi_v, auto wmin,
                   auto wmax) { return both(less_equal(wmin, lo_v), less_equal(hi_v, wmax)); },
                w);
  }

  // Bit i set when child i contains w.
  Mask containing(const Box<D>& w) const {
    return mask([](auto lo_v, auto hi_v, auto wmin,
                   auto wmax) { return both(less_equal(lo_v, wmin), less_equal(wmax, hi_v)); },
                w);
  }

  // out[i] = squared distance from p to child i, for all kSlots slots (empty ones give +inf):
  // `out` holds kSlots doubles.
  // At most one of lo - p and p - hi is positive, so their clamped sum is the gap on an axis.
  void squared_distances(const Point<D>& p, double* out) const {
#if defined(__SSE2__)
    const __m128d zero = _mm_setzero_pd();
    __m128d pv[D];
    for (int a = 0; a < D; ++a)
      pv[a] = _mm_set1_pd(p[a]);
    for (int i = 0; i < kSlots; i += 2) {
      __m128d sum = zero;
      for (int a = 0; a < D; ++a) {
        const __m128d below = _mm_max_pd(_mm_sub_pd(_mm_loadu_pd(&lo[a][i]), pv[a]), zero);
        const __m128d above = _mm_max_pd(_mm_sub_pd(pv[a], _mm_loadu_pd(&hi[a][i])), zero);
        const __m128d gap = _mm_add_pd(below, above);
        sum = _mm_add_pd(sum, _mm_mul_pd(gap, gap));
      }
      _mm_storeu_pd(out + i, sum);
    }
#else
    for (int i = 0; i < kSlots; ++i)
      out[i] = squared_distance(i, p);
#endif
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

 private:
  // One comparison step on two lanes (SSE2) or one lane (portable); `Test` combines the four
  // operands of an axis into a lane mask, and the axes are and-ed together.
#if defined(__SSE2__)
  using Lane = __m128d;
  static constexpr int kLanes = 2;
  static Lane load(const double* p) {
    return _mm_loadu_pd(p);
  }
  static Lane splat(double v) {
    return _mm_set1_pd(v);
  }
  static Lane less_equal(Lane a, Lane b) {
    return _mm_cmple_pd(a, b);
  }
  static Lane both(Lane a, Lane b) {
    return _mm_and_pd(a, b);
  }
  static unsigned bits(Lane a) {
    return unsigned(_mm_movemask_pd(a));
  }
#else
  using Lane = bool;
  static constexpr int kLanes = 1;
  static double load(const double* p) {
    return *p;
  }
  static double splat(double v) {
    return v;
  }
  static Lane less_equal(double a, double b) {
    return a <= b;
  }
  static Lane both(Lane a, Lane b) {
    return a && b;
  }
  static unsigned bits(Lane a) {
    return unsigned(a);
  }
#endif

  template <class Test>
  Mask mask(Test test, const Box<D>& w) const {
    static_assert(kSlots % kLanes == 0);
    decltype(splat(0.0)) wmin[D], wmax[D];
    for (int a = 0; a < D; ++a)
      wmin[a] = splat(w.min[a]), wmax[a] = splat(w.max[a]);
    Mask m = 0;
    for (int i = 0; i < kSlots; i += kLanes) {
      auto acc = test(load(&lo[0][i]), load(&hi[0][i]), wmin[0], wmax[0]);
      for (int a = 1; a < D; ++a)
        acc = both(acc, test(load(&lo[a][i]), load(&hi[a][i]), wmin[a], wmax[a]));
      m |= Mask(bits(acc)) << i;
    }
    return m;
  }
};

template <class Mask>
inline int pop_lowest(Mask& m) {
  const int i = std::countr_zero(m);
  m &= m - 1;
  return i;
}

template <class Mask>
inline int pop_highest(Mask& m) {
  const int i = std::bit_width(m) - 1;
  m &= ~(Mask(1) << i);
  return i;
}

}  // namespace loci::detail
