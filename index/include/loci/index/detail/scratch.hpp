// Scratch<T>: a reusable buffer leased from a per-thread pool, so that queries allocate
// nothing once a thread has warmed up. Leases nest (a visitor may run another query on the
// same thread); each lease returns its buffer, cleared but with its capacity kept.
#pragma once

#include <memory>
#include <vector>

namespace loci::detail {

template <class T>
class Scratch {
 public:
  Scratch() {
    auto& p = pool();
    if (p.empty()) {
      buf_ = std::make_unique<std::vector<T>>();
    } else {
      buf_ = std::move(p.back());
      p.pop_back();
    }
  }
  ~Scratch() {
    buf_->clear();
    pool().push_back(std::move(buf_));
  }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;

  std::vector<T>& operator*() { return *buf_; }
  std::vector<T>* operator->() { return buf_.get(); }

 private:
  static std::vector<std::unique_ptr<std::vector<T>>>& pool() {
    thread_local std::vector<std::unique_ptr<std::vector<T>>> p;
    return p;
  }
  std::unique_ptr<std::vector<T>> buf_;
};

}  // namespace loci::detail
