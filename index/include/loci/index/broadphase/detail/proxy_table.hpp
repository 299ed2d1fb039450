// ProxyTable<D>: the proxies of a broad phase, addressed by 32-bit slots.
//
// Each proxy is a caller's id and its current (tight) box, kept in flat arrays indexed by
// slot; removed slots go on a free list and are reused by later adds, so slots stay dense and
// a structure's per-slot arrays (tree leaves, sort positions, flags) stay small.
//
// Ids map to slots through IdMap: a plain array for ids that are small compared with the
// number of proxies (array indices, the common case, cost one load), a hash map for the
// rest. An id lives in exactly one of the two.
#pragma once

#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "loci/geom/box.hpp"
#include "loci/geom/error.hpp"
#include "loci/index/query.hpp"

namespace loci::detail {

class IdMap {
 public:
  std::uint32_t find(Id id) const {
    if (id < dense_.size() && dense_[id] != kNone) return dense_[id];
    if (sparse_.empty()) return kNone;
    const auto it = sparse_.find(id);
    return it == sparse_.end() ? kNone : it->second;
  }
  // `count` is the number of ids held after this one; it bounds the dense array's growth.
  void insert(Id id, std::uint32_t slot, std::size_t count) {
    if (id < dense_.size() || id <= 4 * count + 1024) {
      if (id >= dense_.size())
        dense_.resize(std::max<std::size_t>(id + 1, dense_.size() * 2), kNone);
      dense_[id] = slot;
    } else {
      sparse_.emplace(id, slot);
    }
  }
  void erase(Id id) {
    if (id < dense_.size() && dense_[id] != kNone)
      dense_[id] = kNone;
    else
      sparse_.erase(id);
  }
  void clear() {
    dense_.clear();
    sparse_.clear();
  }

 private:
  std::vector<std::uint32_t> dense_;  // slot by id, kNone where absent (4 bytes an id)
  std::unordered_map<Id, std::uint32_t> sparse_;
};

template <int D>
class ProxyTable {
 public:
  std::uint32_t find(Id id) const { return map_.find(id); }

  // Slot of `id`, throwing InvalidArgument naming `owner` when it is not held.
  std::uint32_t slot_of(Id id, const char* owner) const {
    const std::uint32_t s = map_.find(id);
    if (s == kNone)
      throw InvalidArgument(std::string(owner) + ": no proxy with id " + std::to_string(id));
    return s;
  }

  void reserve(std::size_t n) {
    ids_.reserve(n);
    boxes_.reserve(n);
    alive_.reserve(n);
  }

  // A fresh slot for (id, box). Throws InvalidGeometry for a bad box and InvalidArgument when
  // the id is already held or slots run out.
  std::uint32_t add(Id id, const Box<D>& b, const char* owner) {
    check_box(b, "proxy box");
    if (map_.find(id) != kNone)
      throw InvalidArgument(std::string(owner) + ": id " + std::to_string(id) + " is already held");
    std::uint32_t s;
    if (!free_.empty()) {
      s = free_.back();
      free_.pop_back();
    } else {
      if (ids_.size() + 1 >= kNone)
        throw InvalidArgument(std::string(owner) + ": too many proxies");
      s = std::uint32_t(ids_.size());
      ids_.push_back(0);
      boxes_.push_back(Box<D>::empty());
      alive_.push_back(0);
    }
    ids_[s] = id;
    boxes_[s] = b;
    alive_[s] = 1;
    ++count_;
    map_.insert(id, s, count_);
    return s;
  }

  void remove(std::uint32_t s) {
    map_.erase(ids_[s]);
    alive_[s] = 0;
    boxes_[s] = Box<D>::empty();
    free_.push_back(s);
    --count_;
  }

  void clear() {
    ids_.clear();
    boxes_.clear();
    alive_.clear();
    free_.clear();
    map_.clear();
    count_ = 0;
  }

  Id id(std::uint32_t s) const { return ids_[s]; }
  const Box<D>& box(std::uint32_t s) const { return boxes_[s]; }
  void set_box(std::uint32_t s, const Box<D>& b) { boxes_[s] = b; }
  bool alive(std::uint32_t s) const { return alive_[s] != 0; }

  std::size_t size() const { return count_; }
  // Slots handed out so far, alive or free: the length of per-slot arrays.
  std::uint32_t slots() const { return std::uint32_t(ids_.size()); }
  const std::vector<Box<D>>& boxes() const { return boxes_; }

  // Throws Error naming `owner` when the id map, the free list and the counts disagree.
  void validate(const char* owner) const {
    const std::string who(owner);
    std::size_t alive = 0;
    for (std::uint32_t s = 0; s < slots(); ++s) {
      if (!alive_[s]) continue;
      ++alive;
      if (!is_valid(boxes_[s]))
        throw Error(who + ": proxy " + std::to_string(ids_[s]) + " has an invalid box");
      if (map_.find(ids_[s]) != s)
        throw Error(who + ": id " + std::to_string(ids_[s]) + " does not map to its slot");
    }
    if (alive != count_) throw Error(who + ": proxy count disagrees with the live slots");
    if (alive + free_.size() != slots())
      throw Error(who + ": free slots and live slots do not add up");
    for (std::uint32_t s : free_)
      if (s >= slots() || alive_[s]) throw Error(who + ": a free slot is alive");
  }

  // Visits every live proxy meeting w (the linear scan behind the sweep and grid queries).
  // Throws InvalidGeometry on a NaN, infinite or inverted window, whose tests would otherwise
  // report every proxy or an arbitrary few.
  template <class F>
  QueryStats scan(const Box<D>& w, F&& visit) const {
    check_box(w, "query window");
    QueryStats st;
    st.nodes_visited = 1;
    for (std::uint32_t s = 0; s < slots(); ++s) {
      if (!alive_[s]) continue;
      ++st.entries_tested;
      if (!intersects(boxes_[s], w)) continue;
      ++st.results;
      if (!visit(ids_[s], boxes_[s])) break;
    }
    return st;
  }

 private:
  std::vector<Id> ids_;              // caller's id by slot (8 bytes)
  std::vector<Box<D>> boxes_;        // current box by slot, empty when free (16 D bytes)
  std::vector<std::uint8_t> alive_;  // 1 while the slot holds a proxy
  std::vector<std::uint32_t> free_;  // free slots, reused last-in first-out
  IdMap map_;
  std::size_t count_ = 0;
};

}  // namespace loci::detail
