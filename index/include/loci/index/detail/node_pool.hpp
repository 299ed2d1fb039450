// NodePool<T, Link, Group>: the node storage of every dynamic structure.
//
// Nodes live in one vector (on huge pages once large: large_alloc.hpp) and are named by
// 32-bit indices, so a structure is copied, moved or saved as plain arrays and a node costs
// no pointer. Released nodes form a free list threaded through the nodes themselves: while
// a node is free, its member `Link` (a field the structure does not need in a free node, such
// as a child or parent link) holds the index of the next free node, or kNone. Allocation pops
// the list or appends; no node is given up before clear() (which keeps the memory), so
// indices stay valid for the structure's life.
//
// Group > 1 hands out runs of Group consecutive nodes (the 2^D children of a quadtree node,
// say); the free list then links the first node of each released run. A run's contents on
// allocation are whatever the last user left: the structure initialises what it takes.
//
// validate_free() walks the free list and marks what it finds, so a structure's validate()
// can check that every node is either reachable once or free once (no leaks, no sharing).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "loci/geom/error.hpp"
#include "loci/index/detail/large_alloc.hpp"
#include "loci/index/query.hpp"

namespace loci::detail {

template <class T, std::uint32_t T::*Link, std::uint32_t Group = 1>
class NodePool {
  static_assert(Group >= 1);

 public:
  NodePool() = default;
  NodePool(const NodePool&) = default;
  NodePool& operator=(const NodePool&) = default;
  // Moving leaves `other` empty: no node, an empty free list.
  NodePool(NodePool&& other) noexcept { swap(other); }
  NodePool& operator=(NodePool&& other) noexcept {
    NodePool(std::move(other)).swap(*this);
    return *this;
  }
  void swap(NodePool& other) noexcept {
    nodes_.swap(other.nodes_);
    std::swap(free_, other.free_);
    std::swap(free_runs_, other.free_runs_);
  }

  // Index of the first node of a fresh run of Group nodes. Throws InvalidArgument, naming
  // `owner`, when 32-bit indices would run out.
  std::uint32_t allocate(const char* owner) {
    if (free_ != kNone) {
      const std::uint32_t n = free_;
      free_ = nodes_[n].*Link;
      --free_runs_;
      return n;
    }
    if (nodes_.size() + Group >= kNone)
      throw InvalidArgument(std::string(owner) + " node pool is full (2^32 - 2 nodes)");
    nodes_.resize(nodes_.size() + Group);
    return std::uint32_t(nodes_.size() - Group);
  }
  // Gives back the run starting at n; its nodes must no longer be reachable.
  void release(std::uint32_t n) {
    nodes_[n].*Link = free_;
    free_ = n;
    ++free_runs_;
  }

  T& operator[](std::uint32_t n) { return nodes_[n]; }
  const T& operator[](std::uint32_t n) const { return nodes_[n]; }

  // Nodes held, in use or free.
  std::size_t size() const { return nodes_.size(); }
  std::size_t in_use() const { return nodes_.size() - std::size_t(free_runs_) * Group; }
  bool contains(std::uint32_t n) const { return n < nodes_.size(); }
  void reserve(std::size_t nodes) { nodes_.reserve(nodes); }
  void clear() {
    nodes_.clear();
    free_ = kNone;
    free_runs_ = 0;
  }
  std::size_t memory_bytes() const { return nodes_.capacity() * sizeof(T); }

  // Marks the free nodes in `seen` (sized size()); returns false when the free list leaves
  // the pool, meets a node already marked, or disagrees with its count.
  bool validate_free(std::vector<bool>& seen) const {
    std::uint32_t runs = 0;
    for (std::uint32_t f = free_; f != kNone; f = nodes_[f].*Link, ++runs) {
      if (runs >= free_runs_ || std::size_t(f) + Group > nodes_.size()) return false;
      for (std::uint32_t g = 0; g < Group; ++g) {
        if (seen[f + g]) return false;
        seen[f + g] = true;
      }
    }
    return runs == free_runs_;
  }

 private:
  LargeVector<T> nodes_;
  std::uint32_t free_ = kNone;   // first node of the first free run
  std::uint32_t free_runs_ = 0;  // length of the free list
};

}  // namespace loci::detail
