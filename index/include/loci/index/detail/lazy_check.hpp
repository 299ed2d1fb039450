// LazyCheck: memory read in place from a file whose fixed-size chunks carry checksums (a
// memory-mapped index). A structure adopting such memory calls touch() before it reads
// bytes; each chunk is verified the first time anything in it is read, so opening the file
// costs the same whatever its size, and no answer ever comes from bytes that were not
// verified. The check itself (which hash, what message) belongs to the file format: a
// subclass says how to verify chunk c, throwing loci::Error when it is corrupt.
// Thread-safe: two threads may verify the same chunk at once, harmlessly.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>

namespace loci::detail {

class LazyCheck {
 public:
  // The chunks are [base + c * 2^shift, base + (c + 1) * 2^shift) within [base, base + size).
  LazyCheck(const std::byte* base, std::size_t size, unsigned shift)
      : base_(base),
        size_(size),
        shift_(shift),
        chunks_(size == 0 ? 0 : ((size - 1) >> shift) + 1),
        verified_(new std::atomic<bool>[chunks_]) {
    for (std::size_t c = 0; c < chunks_; ++c)
      verified_[c].store(false, std::memory_order_relaxed);
  }
  virtual ~LazyCheck() = default;
  LazyCheck(const LazyCheck&) = delete;
  LazyCheck& operator=(const LazyCheck&) = delete;

  // Verifies the chunks holding [p, p + n) that were not verified yet. Bytes outside the
  // checked range are not this object's concern.
  // The common case, bytes within one chunk verified already, costs a few instructions.
  [[gnu::always_inline]] void touch(const void* p, std::size_t n) const {
    const auto* b = static_cast<const std::byte*>(p);
    if (b < base_ || n == 0) return;
    const std::size_t off = std::size_t(b - base_);
    if (off >= size_) return;
    const std::size_t c = off >> shift_;
    if (off + n <= size_ && ((off + n - 1) >> shift_) == c &&
        verified_[c].load(std::memory_order_acquire)) [[likely]]
      return;
    touch_range(off, n);
  }
  // Verifies every chunk (loci check).
  void touch_all() const {
    for (std::size_t c = 0; c < chunks_; ++c)
      if (!verified_[c].load(std::memory_order_acquire)) verify_once(c);
  }
  std::size_t chunks() const { return chunks_; }
  std::size_t verified() const {
    std::size_t n = 0;
    for (std::size_t c = 0; c < chunks_; ++c)
      n += verified_[c].load(std::memory_order_relaxed);
    return n;
  }

 protected:
  // Throws loci::Error when chunk c (of `bytes` bytes at `data`) is corrupt.
  virtual void verify(std::size_t c, const std::byte* data, std::size_t bytes) const = 0;

 private:
  [[gnu::noinline]] void touch_range(std::size_t off, std::size_t n) const {
    const std::size_t last = std::min(off + n - 1, size_ - 1) >> shift_;
    for (std::size_t c = off >> shift_; c <= last; ++c)
      if (!verified_[c].load(std::memory_order_acquire)) verify_once(c);
  }
  void verify_once(std::size_t c) const {
    const std::size_t first = c << shift_;
    verify(c, base_ + first, std::min(size_ - first, std::size_t(1) << shift_));
    verified_[c].store(true, std::memory_order_release);
  }

  const std::byte* base_;
  std::size_t size_;
  unsigned shift_;
  std::size_t chunks_;
  std::unique_ptr<std::atomic<bool>[]> verified_;
};

}  // namespace loci::detail
