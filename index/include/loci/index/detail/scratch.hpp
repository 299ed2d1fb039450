// Lease<T>: a T leased from a per-thread pool of idle ones, so that a call repeated on a thread
// reuses what the previous call built (its buffers above all) instead of allocating and
// faulting in fresh memory. An empty pool makes a new T. Leases nest (a visitor may run another
// query on the same thread, which leases a second T). At the end of the lease the T goes back
// to the pool, unless drop() was called (a holder that would keep too much memory) or the
// lease ends by an exception, which may have left the T half-changed: then it is destroyed.
//
// Scratch<T>: a lease of a std::vector<T>, given back cleared but with its capacity kept.
#pragma once

#include <exception>
#include <memory>
#include <vector>

namespace loci::detail {

template <class T>
class Lease {
 public:
  Lease() : exceptions_(std::uncaught_exceptions()) {
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
    if (!p || !keep_ || std::uncaught_exceptions() != exceptions_) return;
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
  Lease<std::vector<T>> lease_;
};

}  // namespace loci::detail
