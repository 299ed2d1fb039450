// Lease<T>: a T leased from a per-thread pool of idle ones, so that a call repeated on a thread
// reuses what the previous call built (its buffers above all) instead of allocating and
// faulting in fresh memory. An empty pool makes a new T. Leases nest (a visitor may run another
// query on the same thread, which leases a second T). At the end of the lease the T goes back
// to the pool, unless drop() was called (a holder that would keep too much memory) or the
// lease ends by an exception, which may have left the T half-changed: then it is destroyed
// (kWatchExceptions; a holder that resets its T itself on every return may leave it off, and
// skip asking the runtime twice a lease whether an exception is under way).
//
// FixedStack<T, N>: at most N values held in place (on the caller's stack), for a buffer whose
// size the structure bounds: no lease and no allocation at all.
//
// Scratch<T>: a lease of a std::vector<T>, given back cleared but with its capacity kept (so
// whatever an exception left in it is dropped too: it does not watch exceptions). Queries take
// one or two on every call, so a lease costs a pool's pop and push and nothing else.
#pragma once

#include <array>
#include <cassert>
#include <cstddef>
#include <exception>
#include <memory>
#include <vector>

namespace loci::detail {

template <class T, bool kWatchExceptions = true>
class Lease {
 public:
  Lease() : exceptions_(kWatchExceptions ? std::uncaught_exceptions() : 0) {
    std::vector<std::unique_ptr<T>>* p = pool();
    if (!p || p->empty()) {
      obj_ = std::make_unique<T>();
    } else {
      obj_ = std::move(p->back());
      p->pop_back();
    }
  }
  ~Lease() {
    std::vector<std::unique_ptr<T>>* p = pool();
    if (!p || !keep_) return;
    if (kWatchExceptions && std::uncaught_exceptions() != exceptions_) return;
    try {
      p->push_back(std::move(obj_));
    } catch (...) {  // no room in the pool: the T is destroyed instead
    }
  }
  Lease(const Lease&) = delete;
  Lease& operator=(const Lease&) = delete;

  // The T is destroyed at the end of the lease rather than kept.
  void drop() { keep_ = false; }

  T& operator*() { return *obj_; }
  T* operator->() { return obj_.get(); }

 private:
  // The thread's pool; null once the thread's exit has destroyed it (a lease taken from the
  // destructor of another thread-local or static object then has a T of its own). The flag
  // is a plain bool, which no destructor ends, so it can be read at any time.
  struct Pool {
    std::vector<std::unique_ptr<T>> idle;
    ~Pool() { gone() = true; }
  };
  static bool& gone() {
    thread_local bool g = false;
    return g;
  }
  static std::vector<std::unique_ptr<T>>* pool() {
    if (gone()) return nullptr;
    thread_local Pool p;
    return &p.idle;
  }
  std::unique_ptr<T> obj_;
  int exceptions_;
  bool keep_ = true;
};

template <class T>
class Scratch {
 public:
  Scratch() = default;
  ~Scratch() { lease_->clear(); }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;

  std::vector<T>& operator*() { return *lease_; }
  std::vector<T>* operator->() { return &*lease_; }

 private:
  Lease<std::vector<T>, false> lease_;
};

template <class T, std::size_t N>
class FixedStack {
 public:
  void push_back(const T& v) {
    assert(size_ < N);
    items_[size_++] = v;
  }
  void pop_back() { --size_; }
  T& back() { return items_[size_ - 1]; }
  bool empty() const { return size_ == 0; }
  std::size_t size() const { return size_; }
  void clear() { size_ = 0; }
  const T* begin() const { return items_.data(); }
  const T* end() const { return items_.data() + size_; }

 private:
  std::array<T, N> items_;  // left uninitialised: only the first size_ are ever read
  std::size_t size_ = 0;
};

}  // namespace loci::detail
