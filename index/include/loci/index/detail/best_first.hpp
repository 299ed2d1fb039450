// Best-first nearest-neighbour traversal (Hjaltason and Samet, "Distance Browsing in Spatial
// Databases", TODS 1999), shared by every tree.
//
// Subtrees wait in a priority queue keyed by the squared distance from the query point to
// their boxes and are expanded nearest first. Entries do not enter that queue: they go to a
// bounded max-heap of the k best seen so far, and once it is full a subtree or entry farther
// than its worst member is dropped at once. The traversal ends when the nearest waiting
// subtree is farther than the k-th best entry, so no entry that could rank among the first k
// is missed; the k entries are then reported nearest first. Keeping entries out of the queue
// makes the queue NodeSize times smaller than a queue of everything. The tree supplies
// `expand(ref, sink)`, which hands the children of subtree `ref` to the sink.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "loci/index/detail/scratch.hpp"
#include "loci/index/query.hpp"

namespace loci::detail {

struct QueueItem {
  double d2;
  std::uint64_t ref;  // the tree's handle of a subtree or an entry
  Id id;              // the entry's id; unused for subtrees
};

struct NearerFirst {
  bool operator()(const QueueItem& a, const QueueItem& b) const { return a.d2 > b.d2; }
};
struct FartherFirst {
  bool operator()(const QueueItem& a, const QueueItem& b) const { return a.d2 < b.d2; }
};

class BestFirstSink {
 public:
  BestFirstSink(std::vector<QueueItem>& subtrees, std::vector<QueueItem>& best, std::size_t k)
      : subtrees_(subtrees), best_(best), k_(k) {}

  // Squared distance beyond which nothing can enter the result.
  double bound() const { return best_.size() < k_ ? INFINITY : best_.front().d2; }

  void push_subtree(double d2, std::uint64_t ref) {
    if (d2 > bound()) return;
    subtrees_.push_back({d2, ref, 0});
    std::push_heap(subtrees_.begin(), subtrees_.end(), NearerFirst{});
  }
  void push_entry(double d2, std::uint64_t ref, Id id) {
    if (best_.size() < k_) {
      best_.push_back({d2, ref, id});
      std::push_heap(best_.begin(), best_.end(), FartherFirst{});
    } else if (d2 < best_.front().d2) {
      std::pop_heap(best_.begin(), best_.end(), FartherFirst{});
      best_.back() = {d2, ref, id};
      std::push_heap(best_.begin(), best_.end(), FartherFirst{});
    }
  }

 private:
  std::vector<QueueItem>& subtrees_;
  std::vector<QueueItem>& best_;
  std::size_t k_;
};

// Runs the traversal from `root_ref`; `visit(id, ref, distance)` returns false to stop.
template <class Expand, class Visit>
QueryStats best_first(std::uint64_t root_ref, std::size_t k, Expand&& expand, Visit&& visit) {
  QueryStats stats;
  if (k == 0) return stats;
  Scratch<QueueItem> subtree_scratch, best_scratch;
  auto& subtrees = *subtree_scratch;
  auto& best = *best_scratch;
  BestFirstSink sink(subtrees, best, k);
  subtrees.push_back({0.0, root_ref, 0});
  while (!subtrees.empty()) {
    std::pop_heap(subtrees.begin(), subtrees.end(), NearerFirst{});
    const QueueItem top = subtrees.back();
    subtrees.pop_back();
    if (top.d2 > sink.bound()) break;
    ++stats.nodes_visited;
    stats.entries_tested += expand(top.ref, sink);
  }
  std::sort_heap(best.begin(), best.end(), FartherFirst{});
  for (const QueueItem& e : best) {
    ++stats.results;
    if (!visit(e.id, e.ref, std::sqrt(e.d2))) break;
  }
  return stats;
}

}  // namespace loci::detail
