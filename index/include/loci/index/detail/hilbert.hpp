// Hilbert-curve keys for points on a 2^B grid in D dimensions.
//
// Follows J. Skilling, "Programming the Hilbert curve" (AIP Conf. Proc. 707, 2004): the
// coordinates are turned in place into the "transposed" Hilbert index by undoing the excess
// rotations bit plane by bit plane, Gray-encoding, and then reading the bits out interleaved.
// Works for any D; loci uses B = 32 / D rounded down for 2D (16) and 21 for 3D, so keys fit in
// 64 bits. Points close on the curve are close in space, which is what packing needs.
#pragma once

#include <cstdint>

namespace loci::detail {

template <int D>
constexpr int hilbert_bits() {
  return D == 2 ? 16 : 21;
}

template <int D>
std::uint64_t hilbert_key(std::uint32_t (&x)[D]) {
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
