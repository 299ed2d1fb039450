// Best-first nearest-neighbour traversal (Hjaltason and Samet, "Distance Browsing in Spatial
// Databases", TODS 1999), shared by every tree, in two forms: best_first() for a fixed k and
// browse() for an incremental walk that stops when its visitor does.
//
// Subtrees wait in a priority queue keyed by the squared distance from the query point to
// their boxes and are expanded nearest first. Entries do not enter that queue: they go to a
// bounded max-heap of the k best seen so far, and once it is full a subtree or entry farther
// than its worst member is dropped at once. The traversal ends when the nearest waiting
// subtree is farther than the k-th best entry, so no entry that could rank among the first k
// is missed; the k entries are then reported nearest first. Keeping entries out of the queue
// makes the queue NodeSize times smaller than a queue of everything. For the usual small k the
// best entries are kept as a sorted array (an insertion moves a few elements, and the result
// needs no final sort); past kSortedLimit a heap bounds the cost of each insertion. The tree
// supplies `expand(ref, sink)`, which hands the children of subtree `ref` to the sink.
//
// Before the queue starts, a greedy dive follows the nearest child from the root down to a
// leaf and takes its entries. The siblings met on the way down are only set aside; once the
// leaf has bounded the k-th distance, those farther than the bound are dropped and the rest
// become the queue. Without the dive the first descent would heap-insert every child of every
// node it passes, which dominates the cost of a small-k query.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include <vector>

#include "loci/geom/error.hpp"
#include "loci/index/detail/scratch.hpp"
#include "loci/index/query.hpp"

namespace loci::detail {

// Squared distances overflow beyond about 1e154 (coordinates beyond 1e150 are refused by the
// layers, SQL and moving indexes for that reason). While the distances ranked stay finite the
// order is exact (an overflowed one is farther than every finite one), so only an answer
// whose own distance overflowed is refused, rather than reported at infinity in no order.
// browse() hands such entries on last, at distance infinity, for its visitor to judge.
inline void check_answer_distance(double d2) {
  if (!(d2 < INFINITY))
    throw InvalidArgument(
        "nearest: an answer lies too far for its distance to fit a double (coordinates beyond "
        "1e150)");
}

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
  static constexpr std::size_t kSortedLimit = 64;

  BestFirstSink(std::vector<QueueItem>& subtrees, std::vector<QueueItem>& best, std::size_t k)
      : subtrees_(subtrees), best_(best), k_(k), sorted_(k <= kSortedLimit) {}

  // Squared distance beyond which nothing can enter the result.
  double bound() const { return bound_; }

  void push_subtree(double d2, std::uint64_t ref) {
    if (diving_) {
      if (d2 < dive_d2_) dive_d2_ = d2, dive_index_ = subtrees_.size();
      subtrees_.push_back({d2, ref, 0});
      return;
    }
    if (d2 > bound_) return;
    subtrees_.push_back({d2, ref, 0});
    std::push_heap(subtrees_.begin(), subtrees_.end(), NearerFirst{});
  }

  void push_entry(double d2, std::uint64_t ref, Id id) {
    if (d2 >= bound_ && best_.size() == k_) return;
    if (sorted_) {
      if (best_.size() < k_) best_.emplace_back();
      std::size_t i = best_.size() - 1;  // the slot to fill: new, or the worst one dropped
      for (; i > 0 && best_[i - 1].d2 > d2; --i)
        best_[i] = best_[i - 1];
      best_[i] = {d2, ref, id};
      if (best_.size() == k_) bound_ = best_.back().d2;
      return;
    }
    if (best_.size() == k_) {
      std::pop_heap(best_.begin(), best_.end(), FartherFirst{});
      best_.back() = {d2, ref, id};
    } else {
      best_.push_back({d2, ref, id});
    }
    std::push_heap(best_.begin(), best_.end(), FartherFirst{});
    if (best_.size() == k_) bound_ = best_.front().d2;
  }

  // Hands over a node's children at once: d2[i] for i < count, ref_of(i) (and id_of(i) for
  // entries). Children beyond the bound are skipped by one comparison each, before any
  // per-child work.
  template <class RefOf>
  void push_subtrees(const double* d2, int count, RefOf ref_of) {
    for (std::uint64_t m = within_bound(d2, count); m; m &= m - 1) {
      const int i = std::countr_zero(m);
      push_subtree(d2[i], ref_of(i));
    }
  }
  template <class RefOf, class IdOf>
  void push_entries(const double* d2, int count, RefOf ref_of, IdOf id_of) {
    for (std::uint64_t m = within_bound(d2, count); m; m &= m - 1) {
      const int i = std::countr_zero(m);
      push_entry(d2[i], ref_of(i), id_of(i));
    }
  }

  // Diving: push_subtree sets children aside unordered and notes the nearest, which
  // take_dive_child() removes again for the dive to descend into.
  void start_dive_step() {
    diving_ = true;
    dive_d2_ = INFINITY;
    dive_index_ = kNoChild;
  }
  bool take_dive_child(std::uint64_t& ref) {
    if (dive_index_ == kNoChild) return false;
    ref = subtrees_[dive_index_].ref;
    subtrees_[dive_index_] = subtrees_.back();
    subtrees_.pop_back();
    return true;
  }
  // Keeps the set-aside subtrees that can still matter, as the queue.
  void end_dive() {
    diving_ = false;
    std::erase_if(subtrees_, [&](const QueueItem& q) { return q.d2 > bound_; });
    std::make_heap(subtrees_.begin(), subtrees_.end(), NearerFirst{});
  }

  // The best entries, nearest first.
  void finish() {
    if (!sorted_) std::sort_heap(best_.begin(), best_.end(), FartherFirst{});
  }

 private:
  std::vector<QueueItem>& subtrees_;
  std::vector<QueueItem>& best_;
  std::size_t k_;
  bool sorted_;
  double bound_ = INFINITY;
  std::uint64_t within_bound(const double* d2, int count) const {
    std::uint64_t m = 0;
    const double b = bound_;
    for (int i = 0; i < count; ++i)
      m |= std::uint64_t(d2[i] <= b) << i;
    return m;
  }

  static constexpr std::size_t kNoChild = ~std::size_t(0);
  bool diving_ = false;
  double dive_d2_ = INFINITY;
  std::size_t dive_index_ = kNoChild;
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
  std::uint64_t ref = root_ref;
  do {
    sink.start_dive_step();
    ++stats.nodes_visited;
    stats.entries_tested += expand(ref, sink);
  } while (sink.take_dive_child(ref));
  sink.end_dive();

  while (!subtrees.empty()) {
    std::pop_heap(subtrees.begin(), subtrees.end(), NearerFirst{});
    const QueueItem top = subtrees.back();
    subtrees.pop_back();
    if (top.d2 > sink.bound()) break;
    ++stats.nodes_visited;
    stats.entries_tested += expand(top.ref, sink);
  }
  sink.finish();
  if (!best.empty()) check_answer_distance(best.back().d2);  // the farthest, before any answer
  for (const QueueItem& e : best) {
    ++stats.results;
    if (!visit(e.id, e.ref, std::sqrt(e.d2))) break;
  }
  return stats;
}

// Distance browsing. Here nodes and entries do share one priority queue, as in Hjaltason and
// Samet's incremental algorithm: an entry popped from the queue is nearer than everything still
// waiting (a subtree's key is a lower bound on all it holds), so it is reported at once, and
// the caller decides after each answer whether it wants another. That is what a query whose k
// is not known in advance needs: the layer queries refine candidates by exact geometry and stop
// when the next box distance exceeds the k-th exact distance. At equal keys entries come before
// subtrees, so answers are not held back by ties. There is no bound to prune with: the sink
// takes everything it is handed.
struct BrowseItem {
  double d2;
  std::uint64_t ref;
  Id id;
  bool subtree;
};

struct BrowseNearerFirst {
  bool operator()(const BrowseItem& a, const BrowseItem& b) const {
    return a.d2 != b.d2 ? a.d2 > b.d2 : a.subtree && !b.subtree;
  }
};

class BrowseSink {
 public:
  explicit BrowseSink(std::vector<BrowseItem>& queue) : queue_(queue) {}

  void push_subtree(double d2, std::uint64_t ref) { push({d2, ref, 0, true}); }
  void push_entry(double d2, std::uint64_t ref, Id id) { push({d2, ref, id, false}); }
  template <class RefOf>
  void push_subtrees(const double* d2, int count, RefOf ref_of) {
    for (int i = 0; i < count; ++i)
      push_subtree(d2[i], ref_of(i));
  }
  template <class RefOf, class IdOf>
  void push_entries(const double* d2, int count, RefOf ref_of, IdOf id_of) {
    for (int i = 0; i < count; ++i)
      push_entry(d2[i], ref_of(i), id_of(i));
  }

 private:
  void push(const BrowseItem& item) {
    queue_.push_back(item);
    std::push_heap(queue_.begin(), queue_.end(), BrowseNearerFirst{});
  }
  std::vector<BrowseItem>& queue_;
};

// Reports entries in increasing distance from the point `expand` measures against, starting
// from subtree `root_ref`, until `visit(id, ref, distance)` returns false or the tree is done.
template <class Expand, class Visit>
QueryStats browse(std::uint64_t root_ref, Expand&& expand, Visit&& visit) {
  QueryStats stats;
  Scratch<BrowseItem> scratch;
  auto& queue = *scratch;
  BrowseSink sink(queue);
  queue.push_back({0.0, root_ref, 0, true});
  while (!queue.empty()) {
    std::pop_heap(queue.begin(), queue.end(), BrowseNearerFirst{});
    const BrowseItem top = queue.back();
    queue.pop_back();
    if (top.subtree) {
      ++stats.nodes_visited;
      stats.entries_tested += expand(top.ref, sink);
      continue;
    }
    ++stats.results;
    if (!visit(top.id, top.ref, std::sqrt(top.d2))) break;
  }
  return stats;
}

}  // namespace loci::detail
