// Every pair of intersecting segments, within one set of linework or between two, with where
// they meet: the "which roads cross which rivers" and "where does this coastline cross itself"
// questions, on the segments of lines and polygon rings.
//
// Method: a tiled sort-and-sweep join of the segments' boxes (grid_join.hpp: long segments,
// such as straight borders, scan their tile instead of the whole x-range) gives the candidate
// pairs, and the exact segment intersection (geom/segment_intersection.hpp) decides each one,
// so the answer is exact: touching counts, collinear overlaps are reported with their two
// ends, near-parallel segments are decided as the real numbers decide. On map linework the
// boxes of short segments overlap rarely, so the sweep costs little more than its sort and the
// exact test runs on few candidates.
//
// Within one set, consecutive segments of a line or ring always share their common vertex; the
// caller's `adjacent(i, j)` names such pairs, and a pair of adjacent segments is reported only
// when they meet somewhere else too (a spike that doubles back along itself is a collinear
// overlap and is reported). Visitors are called as `bool visit(Id i, Id j, const
// SegmentIntersection& x)` with indices into the inputs (i < j within one set) and return
// false to stop. Thread-safety: pure functions of their inputs.
#pragma once

#include <atomic>
#include <exception>
#include <mutex>
#include <span>
#include <thread>
#include <type_traits>
#include <vector>

#include "loci/geom/segment_intersection.hpp"
#include "loci/index/detail/large_alloc.hpp"
#include "loci/index/grid_join.hpp"
#include "loci/index/query.hpp"

namespace loci {

template <class F>
concept IntersectionVisitor = Visitor<F, Id, Id, const SegmentIntersection&>;

namespace detail {
inline LargeVector<Box<2>> segment_boxes(std::span<const Segment<2>> segs) {
  LargeVector<Box<2>> boxes(segs.size());
  for (std::size_t i = 0; i < segs.size(); ++i) {
    const Segment<2>& s = segs[i];
    // The message is made only for a bad segment.
    if (!is_finite(s.a) || !is_finite(s.b))
      check_segment(s, ("segment " + std::to_string(i)).c_str());
    boxes[i] = s.box();
  }
  return boxes;
}

// True when adjacent segments s and t meet only at a vertex they share.
inline bool only_at_shared_vertex(const Segment<2>& s, const Segment<2>& t,
                                  const SegmentIntersection& x) {
  if (x.kind != SegmentMeet::point) return false;
  return (x.a == s.a || x.a == s.b) && (x.a == t.a || x.a == t.b);
}
}  // namespace detail

namespace detail {
// Calls work(row, k) for every row < rows on `threads` threads (k the thread), a row at a
// time to whichever thread is free, until one returns false. The first exception thrown in a
// thread is rethrown here once all have stopped.
template <class Work>
void for_rows(std::uint32_t rows, unsigned threads, Work&& work) {
  std::atomic<std::uint32_t> next{0};
  std::atomic<bool> stop{false};
  std::exception_ptr error;
  std::mutex error_lock;
  auto run = [&](unsigned k) {
    try {
      for (std::uint32_t r; !stop.load(std::memory_order_relaxed) && (r = next++) < rows;)
        if (!work(r, k)) stop = true;
    } catch (...) {
      stop = true;
      const std::lock_guard<std::mutex> hold(error_lock);
      if (!error) error = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  for (unsigned k = 1; k < threads; ++k)
    pool.emplace_back(run, k);
  run(0);
  for (auto& t : pool)
    t.join();
  if (error) std::rethrow_exception(error);
}

inline unsigned thread_count(unsigned threads) {
  return threads ? threads : std::max(1u, std::thread::hardware_concurrency());
}

inline void add(QueryStats& to, const QueryStats& s) {
  to.nodes_visited += s.nodes_visited;
  to.entries_tested += s.entries_tested;
  to.results += s.results;
}
}  // namespace detail

// segment_intersections (below) on `threads` threads (0: one per core): the rows of the grid's
// tiles (grid_join.hpp) are dealt to the threads one at a time. visitor_of(k), called once per
// thread k < threads before the search, gives the visitor thread k calls (and only it); a
// visitor returning false stops every thread soon after. Pairs come in no set order.
template <class Adjacent, class VisitorOf>
QueryStats segment_intersections_parallel(std::span<const Segment<2>> segs, Adjacent&& adjacent,
                                          unsigned threads, VisitorOf&& visitor_of) {
  threads = detail::thread_count(threads);
  const detail::LargeVector<Box<2>> boxes = detail::segment_boxes(segs);
  auto decide = [&](auto& visit, QueryStats& stats, char& stopped) {
    return [&](Id i, Id j) {
      ++stats.entries_tested;
      const SegmentIntersection x = intersection(segs[i], segs[j]);
      if (x.kind == SegmentMeet::none) return true;
      if (adjacent(i, j) && detail::only_at_shared_vertex(segs[i], segs[j], x)) return true;
      ++stats.results;
      return !(stopped = !visit(i, j, x));
    };
  };
  const detail::TileLists t(boxes, detail::TileLists::extent({boxes}), boxes.size());
  QueryStats stats;
  std::vector<char> stopped(threads, 0);
  if (!t.tiled() || threads == 1) {
    auto&& visit = visitor_of(0u);
    const QueryStats sweep = t.tiled()
                                 ? grid_self_join(t, 0, t.rows(), decide(visit, stats, stopped[0]))
                                 : self_join(boxes, decide(visit, stats, stopped[0]));
    stats.nodes_visited = sweep.entries_tested;  // box pairs the sweep compared
    return stats;
  }
  std::vector<std::decay_t<decltype(visitor_of(0u))>> visitors;
  for (unsigned k = 0; k < threads; ++k)
    visitors.push_back(visitor_of(k));
  std::vector<QueryStats> per(threads), sweep(threads);
  detail::for_rows(t.rows(), threads, [&](std::uint32_t r, unsigned k) {
    detail::add(sweep[k], grid_self_join(t, r, r + 1, decide(visitors[k], per[k], stopped[k])));
    return !stopped[k];
  });
  for (unsigned k = 0; k < threads; ++k) {
    detail::add(stats, per[k]);
    stats.nodes_visited += sweep[k].entries_tested;
  }
  return stats;
}

template <class VisitorOf>
QueryStats segment_intersections_parallel(std::span<const Segment<2>> a,
                                          std::span<const Segment<2>> b, unsigned threads,
                                          VisitorOf&& visitor_of) {
  threads = detail::thread_count(threads);
  const detail::LargeVector<Box<2>> boxes_a = detail::segment_boxes(a),
                                    boxes_b = detail::segment_boxes(b);
  auto decide = [&](auto& visit, QueryStats& stats, char& stopped) {
    return [&](Id i, Id j) {
      ++stats.entries_tested;
      const SegmentIntersection x = intersection(a[i], b[j]);
      if (x.kind == SegmentMeet::none) return true;
      ++stats.results;
      return !(stopped = !visit(i, j, x));
    };
  };
  const Box<2> extent = detail::TileLists::extent({boxes_a, boxes_b});
  const detail::TileLists ta(boxes_a, extent, boxes_a.size() + boxes_b.size());
  const detail::TileLists tb(boxes_b, extent, boxes_a.size() + boxes_b.size());
  const bool tiled = ta.tiled() && tb.tiled();
  QueryStats stats;
  std::vector<char> stopped(threads, 0);
  if (!tiled || threads == 1) {
    auto&& visit = visitor_of(0u);
    const QueryStats sweep = tiled
                                 ? grid_join(ta, tb, 0, ta.rows(), decide(visit, stats, stopped[0]))
                                 : join(boxes_a, boxes_b, decide(visit, stats, stopped[0]));
    stats.nodes_visited = sweep.entries_tested;
    return stats;
  }
  std::vector<std::decay_t<decltype(visitor_of(0u))>> visitors;
  for (unsigned k = 0; k < threads; ++k)
    visitors.push_back(visitor_of(k));
  std::vector<QueryStats> per(threads), sweep(threads);
  detail::for_rows(ta.rows(), threads, [&](std::uint32_t r, unsigned k) {
    detail::add(sweep[k], grid_join(ta, tb, r, r + 1, decide(visitors[k], per[k], stopped[k])));
    return !stopped[k];
  });
  for (unsigned k = 0; k < threads; ++k) {
    detail::add(stats, per[k]);
    stats.nodes_visited += sweep[k].entries_tested;
  }
  return stats;
}

// All intersecting pairs i < j of `segs` except adjacent ones meeting only at their shared
// vertex. `stats.entries_tested` counts the exact tests. Throws InvalidGeometry on a NaN or
// infinite coordinate.
template <class Adjacent, IntersectionVisitor Visit>
QueryStats segment_intersections(std::span<const Segment<2>> segs, Adjacent&& adjacent,
                                 Visit&& visit) {
  return segment_intersections_parallel(segs, adjacent, 1,
                                        [&](unsigned) -> Visit& { return visit; });
}

// All intersecting pairs (i of a, j of b). Throws InvalidGeometry on a NaN or infinite
// coordinate.
template <IntersectionVisitor Visit>
QueryStats segment_intersections(std::span<const Segment<2>> a, std::span<const Segment<2>> b,
                                 Visit&& visit) {
  return segment_intersections_parallel(a, b, 1, [&](unsigned) -> Visit& { return visit; });
}

}  // namespace loci
