// Best-first nearest-neighbour traversal (Hjaltason and Samet, "Distance Browsing in Spatial
// Databases", TODS 1999), shared by every tree.
//
// One priority queue holds both subtrees and entries, keyed by the squared distance from the
// query point to their boxes. Popping an entry reports it: no entry still queued or below a
// queued subtree can be nearer, so results come out nearest first and the traversal stops as
// soon as the visitor has what it wants. The tree supplies `expand(ref, push)`, which pushes
// the children of the subtree `ref`, and `entry_box(ref)`.
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
  bool is_entry;
  // std heaps are max-heaps: the nearest item must compare greatest.
  friend bool operator<(const QueueItem& a, const QueueItem& b) { return a.d2 > b.d2; }
};

class BestFirstQueue {
 public:
  explicit BestFirstQueue(std::vector<QueueItem>& heap) : heap_(heap) {}
  void push_subtree(double d2, std::uint64_t ref) {
    heap_.push_back({d2, ref, 0, false});
    std::push_heap(heap_.begin(), heap_.end());
  }
  void push_entry(double d2, std::uint64_t ref, Id id) {
    heap_.push_back({d2, ref, id, true});
    std::push_heap(heap_.begin(), heap_.end());
  }

 private:
  std::vector<QueueItem>& heap_;
};

// Runs the traversal from `root_ref`; `visit(id, ref, distance)` returns false to stop.
template <class Expand, class Visit>
QueryStats best_first(std::uint64_t root_ref, std::size_t k, Expand&& expand, Visit&& visit) {
  QueryStats stats;
  if (k == 0) return stats;
  Scratch<QueueItem> scratch;
  auto& heap = *scratch;
  BestFirstQueue queue(heap);
  queue.push_subtree(0.0, root_ref);
  while (!heap.empty()) {
    std::pop_heap(heap.begin(), heap.end());
    const QueueItem top = heap.back();
    heap.pop_back();
    if (top.is_entry) {
      ++stats.results;
      if (!visit(top.id, top.ref, std::sqrt(top.d2)) || stats.results == k) break;
    } else {
      ++stats.nodes_visited;
      stats.entries_tested += expand(top.ref, queue);
    }
  }
  return stats;
}

}  // namespace loci::detail
