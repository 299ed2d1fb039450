// LSD radix sort on a range of key bits, 11 bits a pass.
//
// Packing sorts a million space-filling-curve keys per build; a comparison sort spends most
// of the build there, while three counting passes (2D keys are 32 bits) touch each pair three
// times. Stable, so equal keys keep their input order and builds are deterministic.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <vector>

#include "loci/index/detail/scratch.hpp"

namespace loci::detail {

struct KeyedIndex {
  std::uint64_t key;
  std::uint32_t index;
};

// Up to this many elements radix_sort sorts by insertion (stable too, and allocation-free).
inline constexpr std::size_t kInsertionSortMax = 128;

// Sorts v by bits [first_bit, first_bit + bits) of key_of(element) (first_bit + bits <= 64;
// the last digit also reads the bits just above them, which callers leave at 0), using `tmp` as the
// second buffer (kept by a caller that sorts every tick, so that its memory is not faulted in
// again). One pass counts every digit; each digit then costs one scatter pass. Nothing is
// allocated when `tmp` is large enough already, nor for kInsertionSortMax elements or fewer.
template <class T, class A, class KeyOf>
void radix_sort(std::vector<T, A>& v, int first_bit, int bits, KeyOf key_of,
                std::vector<T, A>& tmp) {
  constexpr int kDigit = 11;
  constexpr std::size_t kBuckets = std::size_t(1) << kDigit;
  constexpr int kMaxPasses = (64 + kDigit - 1) / kDigit;
  bits = std::min(bits, 64 - first_bit);  // no shift reaches 64
  const int passes = std::min((bits + kDigit - 1) / kDigit, kMaxPasses);
  if (v.size() < 2 || passes <= 0) return;
  if (v.size() <= kInsertionSortMax) {
    // A few keys: the counts' set-up (a 16 kB table a digit) would cost more than the sort.
    // The bits the digits read, the last digit's spill above first_bit + bits included.
    const int top = std::min(64, first_bit + passes * kDigit);
    const std::uint64_t mask = top >= 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << top) - 1;
    const auto digits = [&](const T& x) { return (key_of(x) & mask) >> first_bit; };
    for (std::size_t i = 1; i < v.size(); ++i) {
      T x = v[i];
      const std::uint64_t k = digits(x);
      std::size_t j = i;
      for (; j > 0 && digits(v[j - 1]) > k; --j)
        v[j] = v[j - 1];
      v[j] = x;
    }
    return;
  }
  Scratch<std::array<std::size_t, kBuckets>> lease;  // the digit counts, leased per thread
  auto& count = *lease;
  count.resize(static_cast<std::size_t>(passes));  // a leased vector comes empty: zeroed
  for (const auto& x : v) {
    const std::uint64_t k = key_of(x);
    for (int p = 0; p < passes; ++p)
      ++count[std::size_t(p)][(k >> (first_bit + p * kDigit)) & (kBuckets - 1)];
  }
  tmp.resize(v.size());
  for (int p = 0; p < passes; ++p) {
    const int shift = first_bit + p * kDigit;
    auto& c = count[std::size_t(p)];
    // A digit every key shares orders nothing: skip its pass.
    if (c[(key_of(v[0]) >> shift) & (kBuckets - 1)] == v.size()) continue;
    std::size_t sum = 0;
    for (auto& b : c) {
      const std::size_t n = b;
      b = sum;
      sum += n;
    }
    for (const auto& x : v)
      tmp[c[(key_of(x) >> shift) & (kBuckets - 1)]++] = x;
    v.swap(tmp);
  }
}
template <class T, class A, class KeyOf>
void radix_sort(std::vector<T, A>& v, int first_bit, int bits, KeyOf key_of) {
  std::vector<T, A> tmp;
  radix_sort(v, first_bit, bits, key_of, tmp);
}

// A 64-bit key whose unsigned order is the order of the doubles (no NaN): negative numbers
// have every bit flipped, the others only the sign bit.
inline std::uint64_t ordered_key(double x) {
  const std::uint64_t bits = std::bit_cast<std::uint64_t>(x);
  return bits >> 63 ? ~bits : bits | (std::uint64_t(1) << 63);
}

template <class A>
void radix_sort(std::vector<KeyedIndex, A>& v, int bits) {
  radix_sort(v, 0, bits, [](const KeyedIndex& k) { return k.key; });
}

}  // namespace loci::detail
