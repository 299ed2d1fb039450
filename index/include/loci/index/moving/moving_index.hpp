// The moving-object contract: what every structure in moving/ takes, answers and promises.
//
// A moving index holds one report per object, Motion{t, p, v} (geom/motion.hpp): the object
// is at p at time t and moves with constant velocity v. Objects are named by the caller's
// 64-bit ids:
//
//   insert(id, m)    a new object; throws InvalidArgument when the id is already held
//   update(id, m)    the object's new report (inserted when the id is new); the index keeps
//                    only the latest report it is given, whatever its time: which report is
//                    in force at a time is decided by Fleet (fleet.hpp), which keeps history
//   erase(id)        false when the id is not held
//
// Queries, exact under linear motion (the object's trajectory really meets the query, not
// just a bounding box), each with a visitor returning false to stop:
//
//   query(w, visit)          every object inside the MovingWindow w at some time of
//                            [w.t1, w.t2]: a timeslice (t1 == t2), a window over an interval,
//                            or a window that itself moves; visit(id, motion)
//   nearest(p, s, k, visit)  the k objects nearest the point p at time s, nearest first (ties
//                            in any order), visit(id, motion, distance); k = 0 throws
//                            InvalidArgument, as it does for the static indexes
//   for_each(visit)          every object, in the structure's order
//
// The trees (TprTree, StarTree) also browse(p, s, visit): the objects in increasing distance
// from p at time s, visit(id, motion, distance), one at a time until it returns false
// (distance browsing, as the static trees' browse(); no k fixed in advance).
//
// Times. Queries may ask about any time. The trees keep bounds that hold from their clock
// (the latest report time they were given) onwards; a query reaching back before the clock
// is still answered exactly, by looking at every object (the cost of a scan).
//
// Each query returns a QueryStats counted as in query.hpp (nodes_visited, entries_tested:
// node bounds and objects examined, results). Structures model MovingIndex below and end with
// a static_assert that they do, so fleets, conflicts and benchmarks switch between them with
// one template parameter.
#pragma once

#include <algorithm>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <limits>
#include <utility>
#include <vector>

#include "loci/geom/motion.hpp"
#include "loci/index/query.hpp"

namespace loci {

template <class F, int D>
concept MotionVisitor = Visitor < F,
        Id, const Motion<D>
& > ;

template <class F, int D>
concept MotionNearestVisitor = Visitor < F,
        Id, const Motion<D>
&, double > ;

namespace detail {
template <int D>
struct MotionProbe {
  bool operator()(Id, const Motion<D>&) const;
};
template <int D>
struct MotionNearestProbe {
  bool operator()(Id, const Motion<D>&, double) const;
};
}  // namespace detail

namespace detail {
// Nearest-n at time s: s must lie within +-kMaxCoordinate, as report times do (so that s - t
// never overflows), and a distance that overflows a double is refused rather than reported.
// Positions at s may lie beyond kMaxCoordinate; while the distances ranked stay finite the order is
// exact (an object whose squared distance overflows is farther than every one that does not), so
// only an answer that would report an overflowed distance throws.
inline void check_nearest_time(double s) {
  check_coordinate(s, "nearest time");
  if (!(std::abs(s) <= kMaxCoordinate)) throw InvalidArgument("nearest time is beyond 1e150");
}
inline void check_nearest_count(std::size_t k) {
  if (k == 0) throw InvalidArgument("nearest-n query needs k >= 1");
}
inline void check_nearest_distance(double d) {
  if (!(d < std::numeric_limits<double>::infinity()))
    throw InvalidArgument(
        "nearest: an answer lies too far for its distance to fit a double (positions beyond "
        "1e150 at the time asked)");
}

// The k smallest of the squared distances d2(i), i < n, into `best` nearest first, as (d2, i):
// the nearest-n of the scans (`best` is the caller's, leased scratch: nothing allocated per
// call in steady state).
template <class D2>
void k_smallest(std::size_t n, std::size_t k, D2&& d2,
                std::vector<std::pair<double, std::size_t>>& best) {
  best.clear();  // a max-heap of the k best so far, worst on top
  for (std::size_t i = 0; i < n && k > 0; ++i) {
    const double d = d2(i);
    if (best.size() < k) {
      best.push_back({d, i});
      std::push_heap(best.begin(), best.end());
    } else if (d < best.front().first) {
      std::pop_heap(best.begin(), best.end());
      best.back() = {d, i};
      std::push_heap(best.begin(), best.end());
    }
  }
  std::sort_heap(best.begin(), best.end());
}
}  // namespace detail

template <class T>
concept MovingIndex = Index<T> && requires(T& t, const T& c, Id id, const Motion<T::dimension>& m,
                                           const MovingWindow<T::dimension>& w,
                                           const Point<T::dimension>& p, double s, std::size_t k) {
  t.insert(id, m);
  t.update(id, m);
  { t.erase(id) } -> std::same_as<bool>;
  { c.contains(id) } -> std::same_as<bool>;
  { c.clock() } -> std::same_as<double>;
  { c.query(w, detail::MotionProbe<T::dimension>{}) } -> std::same_as<QueryStats>;
  { c.query(w) } -> std::same_as<std::vector<Id>>;
  { c.nearest(p, s, k, detail::MotionNearestProbe<T::dimension>{}) } -> std::same_as<QueryStats>;
  { c.nearest(p, s, k) } -> std::same_as<std::vector<Neighbor>>;
  c.for_each(detail::MotionProbe<T::dimension>{});
};

}  // namespace loci
