// Hilbert-curve keys for points on a 2^B grid in D dimensions.
//
// Follows J. Skilling, "Programming the Hilbert curve" (AIP Conf. Proc. 707, 2004): the
// coordinates are turned in place into the "transposed" Hilbert index by undoing the excess
// rotations bit plane by bit plane, Gray-encoding, and then reading the bits out interleaved.
// Works for any D; loci uses B = 32 / D rounded down for 2D (16) and 21 for 3D, so keys fit in
// 64 bits. Points close on the curve are close in space, which is what packing needs.
//
// For 2D a faster table-driven form is used. The four orientations a Hilbert sub-curve can
// take (identity, transpose, anti-transpose, half turn) map a cell's coordinate bits onto the
// base curve, which visits (0,0), (0,1), (1,1), (1,0) and turns its first quadrant by a
// transpose and its last by an anti-transpose. These maps commute, so the state after a step
// is the product of the state and the quadrant's turn. A 4 x 256 table does four such steps
// (a nibble of x and y) at once, so a 16-bit key costs four look-ups.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "loci/geom/box.hpp"

namespace loci::detail {

template <int D>
constexpr int hilbert_bits() {
  return D == 2 ? 16 : 21;
}

namespace hilbert2 {

// Orientation states: 0 identity, 1 transpose, 2 anti-transpose, 3 half turn.
constexpr unsigned apply(unsigned state, unsigned x, unsigned y, unsigned& cx, unsigned& cy) {
  switch (state) {
    case 1:
      cx = y, cy = x;
      break;
    case 2:
      cx = 1 - y, cy = 1 - x;
      break;
    case 3:
      cx = 1 - x, cy = 1 - y;
      break;
    default:
      cx = x, cy = y;
  }
  return 0;
}
// Product in the Klein four-group {I, S, A, R}: S*A = R, S*R = A, A*R = S.
constexpr unsigned compose(unsigned a, unsigned b) {
  return a ^ b;
}

struct Step {
  std::uint8_t digits;  // four base-4 digits, most significant first
  std::uint8_t state;
};

constexpr std::array<Step, 4 * 256> make_table() {
  // digit and turn of each quadrant of the base curve
  constexpr unsigned kDigit[2][2] = {{0, 1}, {3, 2}};  // [cx][cy]
  constexpr unsigned kTurn[2][2] = {{1, 0}, {2, 0}};   // (0,0): transpose, (1,0): anti-transpose
  std::array<Step, 4 * 256> t{};
  for (unsigned s0 = 0; s0 < 4; ++s0)
    for (unsigned xy = 0; xy < 256; ++xy) {
      unsigned s = s0, digits = 0;
      for (int b = 3; b >= 0; --b) {
        unsigned cx = 0, cy = 0;
        apply(s, (xy >> (4 + b)) & 1u, (xy >> b) & 1u, cx, cy);
        digits = (digits << 2) | kDigit[cx][cy];
        s = compose(s, kTurn[cx][cy]);
      }
      t[s0 * 256 + xy] = {std::uint8_t(digits), std::uint8_t(s)};
    }
  return t;
}

inline constexpr std::array<Step, 4 * 256> kTable = make_table();

}  // namespace hilbert2

// 2D key of a cell on the 2^16 grid.
inline std::uint64_t hilbert_key_2d(std::uint32_t x, std::uint32_t y) {
  std::uint32_t key = 0;
  unsigned state = 0;
  for (int shift = 12; shift >= 0; shift -= 4) {
    const unsigned xy = (((x >> shift) & 15u) << 4) | ((y >> shift) & 15u);
    const hilbert2::Step st = hilbert2::kTable[state * 256 + xy];
    key = (key << 8) | st.digits;
    state = st.state;
  }
  return key;
}

// Any D, by Skilling's transform.
template <int D>
std::uint64_t hilbert_key_generic(std::uint32_t (&x)[D]) {
  constexpr int kBits = hilbert_bits<D>();
  const std::uint32_t top = 1u << (kBits - 1);
  for (std::uint32_t q = top; q > 1; q >>= 1) {
    const std::uint32_t p = q - 1;
    for (int i = 0; i < D; ++i) {
      if (x[i] & q) {
        x[0] ^= p;
      } else {
        const std::uint32_t t = (x[0] ^ x[i]) & p;
        x[0] ^= t;
        x[i] ^= t;
      }
    }
  }
  for (int i = 1; i < D; ++i)
    x[i] ^= x[i - 1];
  std::uint32_t t = 0;
  for (std::uint32_t q = top; q > 1; q >>= 1)
    if (x[D - 1] & q) t ^= q - 1;
  for (int i = 0; i < D; ++i)
    x[i] ^= t;

  std::uint64_t key = 0;
  for (int b = kBits - 1; b >= 0; --b)
    for (int i = 0; i < D; ++i)
      key = (key << 1) | ((x[i] >> b) & 1u);
  return key;
}

}  // namespace loci::detail

namespace loci::detail {

template <int D>
std::uint64_t hilbert_key(std::uint32_t (&x)[D]) {
  if constexpr (D == 2)
    return hilbert_key_2d(x[0], x[1]);
  else
    return hilbert_key_generic<D>(x);
}

}  // namespace loci::detail

namespace loci::detail {

// Keys of points on the 2^hilbert_bits<D>() grid laid over `extent` (what packing and
// quadtree building sort by). A flat axis maps to cell 0; points outside the extent, and NaN
// ones, map to its border cells.
//
// Coordinates are halved before they are measured: the extent of finite coordinates can
// overflow (-1e308 to 1e308) where that of their halves cannot, and above the denormals halves
// give exactly the keys whole coordinates give. An extent so narrow that kMax / extent
// overflows (below about 4e-304) is measured 2^1000 times wider, also exactly. Whatever the
// extent, no NaN or infinity reaches the conversion to integers.
template <int D>
class HilbertGrid {
 public:
  explicit HilbertGrid(const Box<D>& extent) {
    for (int a = 0; a < D; ++a) {
      const double half = extent.max[a] / 2 - extent.min[a] / 2;
      magnify_[a] = half > 0 && !std::isfinite(kMax / half) ? 0x1p1000 : 1.0;
      scale_[a] = half > 0 ? kMax / (half * magnify_[a]) : 0.0;
      half_min_[a] = extent.min[a] / 2;
    }
  }
  std::uint64_t key(const Point<D>& p) const {
    std::uint32_t x[D];
    for (int a = 0; a < D; ++a) {
      const double q = (p[a] / 2 - half_min_[a]) * magnify_[a] * scale_[a];
      x[a] = static_cast<std::uint32_t>(q > 0 ? std::min(q, kMax) : 0.0);
    }
    return hilbert_key<D>(x);
  }

 private:
  static constexpr double kMax = double((1u << hilbert_bits<D>()) - 1);
  Point<D> half_min_;
  double magnify_[D], scale_[D];
};

}  // namespace loci::detail
