// LargeAllocator: an allocator for big arrays (a join's boxes and tile lists, a radix sort's
// buffers, node pools, object tables), which asks the kernel to back blocks of 1 MB or more
// with transparent huge pages (madvise(MADV_HUGEPAGE), where the system leaves huge pages to
// programs that ask). Touching fresh memory costs a page fault per 4 KB page otherwise; on the
// virtual machines a library runs on, that can cost more than the work done on the memory
// (0.45 s for 154 MB, against 0.01 s with huge pages, measured on the development machine).
// Smaller blocks come from operator new. Elsewhere than Linux it is std::allocator.
#pragma once

#include <cstddef>
#include <cstdlib>
#include <new>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace loci::detail {

template <class T>
struct LargeAllocator {
  using value_type = T;
  static constexpr std::size_t kHuge = std::size_t(2) << 20;
  static constexpr std::size_t kThreshold = std::size_t(1) << 20;

  LargeAllocator() = default;
  template <class U>
  LargeAllocator(const LargeAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    if (n > std::size_t(-1) / sizeof(T)) throw std::bad_array_new_length();
    const std::size_t bytes = n * sizeof(T);
#if defined(__linux__)
    if (bytes >= kThreshold) {
      const std::size_t rounded = (bytes + kHuge - 1) / kHuge * kHuge;
      void* p = std::aligned_alloc(kHuge, rounded);
      if (!p) throw std::bad_alloc();
      madvise(p, rounded, MADV_HUGEPAGE);  // advice only: ignored where unsupported
      return static_cast<T*>(p);
    }
#endif
    return static_cast<T*>(::operator new(bytes));
  }

  void deallocate(T* p, std::size_t n) noexcept {
#if defined(__linux__)
    if (n * sizeof(T) >= kThreshold) {
      std::free(p);
      return;
    }
#endif
    ::operator delete(p);
  }

  template <class U>
  friend bool operator==(const LargeAllocator&, const LargeAllocator<U>&) noexcept {
    return true;
  }
};

template <class T>
using LargeVector = std::vector<T, LargeAllocator<T>>;

}  // namespace loci::detail
